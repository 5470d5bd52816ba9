/// @file run_smoother.cpp
/// @brief The whole-recording smoother over a filter run (run_smoother.h).

#include "smoother/run_smoother.h"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "common/anchor_init_io.h"
#include "common/estimate_io.h"
#include "common/pose_interpolation.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/so3.h"
#include "estimator/uwb/range_error_correlation.h"

namespace fs = std::filesystem;

namespace meshnav::smoother {

FilterRun readFilterRun(const std::string& dir, Diagnostics& diag) {
  FilterRun run;
  const fs::path d(dir);
  if (!fs::exists(d / "estimate.csv")) throw std::runtime_error(dir + ": no estimate.csv (not a run folder)");
  run.poses = readEstimateCsv((d / "estimate.csv").string(), diag);
  std::sort(run.poses.begin(), run.poses.end(), [](const PoseEstimate& a, const PoseEstimate& b) { return a.t < b.t; });
  if (fs::exists(d / "anchors.csv"))
    for (const auto& a : readAnchorsCsv((d / "anchors.csv").string(), diag)) run.anchors[a.id] = a.p_AinG;
  if (fs::exists(d / "calibration.yaml")) run.calibrations = readAnchorInitsYaml((d / "calibration.yaml").string());
  if (fs::exists(d / "status.txt")) {
    try {
      const YAML::Node s = YAML::LoadFile((d / "status.txt").string());
      if (s["uwb_clock_offset_s"]) {
        run.uwb_clock_offset_s = s["uwb_clock_offset_s"].as<double>();
        run.has_clock_offset = std::isfinite(run.uwb_clock_offset_s);
        if (!run.has_clock_offset) run.uwb_clock_offset_s = 0.0;
      }
    } catch (const std::exception& e) {
      diag.report("status.txt:unreadable", (d / "status.txt").string() + ": " + e.what() + " (UWB clock delay 0)");
    }
  } else {
    diag.report("status.txt:missing", (d / "status.txt").string() +
                                          " does not exist: the UWB clock delay is setup.yaml's (uwb_clock.offset_s)");
  }
  return run;
}

namespace {

using estimator::so3::logMap;

/// The range model's constants for the tag–anchor pairs (file comment of smoothing_problem.h):
/// setup pair_biases first, then a calibrated anchor's biases, else an unlisted pair with the
/// estimator's model γ = c_tag + e_pair.
struct RangeModelSource {
  const FilterRun& run;
  estimator::EstimatorOptions est;
  double sigma_gamma_unlisted = 0.1;  ///< the setup's noise.sigma_gamma, else the estimator's [m]
  double tau_s = 0.1;                 ///< the setup's noise.range_correlation_time, else the estimator's [s]

  RangeModelSource(const SystemSetup& s, const FilterRun& r, const std::string& config) : run(r) {
    if (!config.empty()) est = estimator::EstimatorOptions::fromYaml(config);
    est.applySetupNoise(s.noise);
    sigma_gamma_unlisted = s.noise.sigma_gamma_m.value_or(est.uwb.uncalibrated_gamma_sigma_m);
    tau_s = s.noise.range_correlation_time_s.value_or(est.uwb.range_error_correlation_s);
  }

  std::optional<PairBias> calibrated(SensorId tag, SensorId anchor) const {
    for (const auto& c : run.calibrations)
      if (c.id == anchor)
        for (const auto& b : c.biases)
          if (b.a == tag || b.b == tag) return b;
    return std::nullopt;
  }
};

}  // namespace

SmoothedRun smoothRun(const Dataset& ds, const FilterRun& run, const RunSmootherOptions& o,
                      const std::function<void(const std::string&)>& progress) {
  SmoothedRun out;
  if (run.poses.size() < 2) throw std::runtime_error("smoother: the run has fewer than two poses");
  if (ds.imu.size() < 2) throw std::runtime_error("smoother: the dataset has no IMU samples");
  if (!(o.knot_period_s > 0.0) || !(o.chunk_s > o.overlap_s) || o.overlap_s < 0.0)
    throw std::invalid_argument("smoother: knot period must be > 0 and chunk longer than overlap");
  const RangeModelSource model(ds.setup, run, o.estimator_config);
  estimator::EstimatorOptions est = model.est;
  const Duration dt_clock = Duration::fromSec(run.has_clock_offset ? run.uwb_clock_offset_s
                                                                   : ds.setup.uwb_clock.offset_s);
  const Timestamp span0 = std::max(run.poses.front().t, ds.imu.front().t);
  const Timestamp span1 = std::min(run.poses.back().t, ds.imu.back().t);
  if (!(span0 < span1)) throw std::runtime_error("smoother: the run's poses and the IMU do not overlap");

  // Ranges in the IMU clock, sorted.
  std::vector<RangeSample> ranges = ds.ranges;
  for (auto& r : ranges) r.t = r.t - dt_clock;
  std::sort(ranges.begin(), ranges.end(), [](const RangeSample& a, const RangeSample& b) { return a.t < b.t; });

  const Duration chunk = Duration::fromSec(o.chunk_s), overlap = Duration::fromSec(o.overlap_s);
  const Duration period = Duration::fromSec(o.knot_period_s);
  Timestamp s = span0;
  int chunk_index = 0;
  while (s < span1) {
    Timestamp e = s + chunk;
    // The last chunk takes a remainder shorter than the overlap or than a knot period (a chunk needs
    // two knots).
    if (e > span1 || span1 - e < std::max(overlap, period)) e = span1;
    const bool final_chunk = e == span1;
    const Timestamp out_end = final_chunk ? span1 : e - overlap;
    ChunkReport report;
    report.t0_s = s.sec();
    report.t1_s = e.sec();

    SmoothingProblem pr;
    // IMU of the chunk (one sample beyond each end for the interpolation).
    {
      auto lo = std::lower_bound(ds.imu.begin(), ds.imu.end(), s, [](const ImuSample& x, Timestamp t) { return x.t < t; });
      auto hi = std::upper_bound(ds.imu.begin(), ds.imu.end(), e, [](Timestamp t, const ImuSample& x) { return t < x.t; });
      if (lo != ds.imu.begin()) --lo;
      if (hi != ds.imu.end()) ++hi;
      pr.imu.assign(lo, hi);
    }
    // The gap's accelerometer density is the estimator's; its gyro density is the smoother's own
    // (o.gap_sigma_gyro_rad_s): the filter leaves attitude uninflated in a gap for a reason of its
    // own (a tilt that range updates would use to explain position), which a fit with both ends of
    // the gap does not have.
    pr.imu_noise = ImuNoiseDensities{est.imu.acc_noise_density, est.imu.gyro_noise_density, est.imu.max_dt_s,
                                     est.imu.gap_sigma_acc_m_s2, o.gap_sigma_gyro_rad_s};
    for (size_t i = 1; i < pr.imu.size(); ++i)
      if ((pr.imu[i].t - pr.imu[i - 1].t).sec() > est.imu.max_dt_s) ++report.imu_gaps;
    pr.acc_bias_rw = est.imu.acc_bias_rw;
    pr.gyro_bias_rw = est.imu.gyro_bias_rw;
    pr.acc_bias_sigma = ds.setup.noise.imu_acc_bias_sigma.value_or(est.init.sigma_bias_acc_m_s2);
    pr.gyro_bias_sigma = ds.setup.noise.imu_gyro_bias_sigma.value_or(est.init.sigma_bias_gyro_rad_s);

    // Knots, initial values from the filter.
    std::vector<Timestamp> times;
    for (Timestamp t = s; t < e; t = t + period) times.push_back(t);
    if (times.empty() || times.back() != e) times.push_back(e);
    if (times.size() >= 2 && (times.back() - times[times.size() - 2]).sec() < 0.25 * o.knot_period_s)
      times.erase(times.end() - 2);
    std::optional<PoseEstimate> last;
    for (Timestamp t : times) {
      auto pe = interpolateEstimate(run.poses, t, Duration::fromSec(1.0));
      if (!pe && last) pe = last;
      if (!pe) pe = run.poses.front();
      last = pe;
      NavState x;
      x.t = t;
      x.p_IinG = pe->p_IinG;
      x.q_ItoG = pe->q_ItoG.normalized();
      pr.knots.push_back(x);
    }
    // Re-initializations of the filter inside the chunk: attitude before the last one from the gyro.
    Timestamp last_jump = s;
    {
      auto a = std::lower_bound(run.poses.begin(), run.poses.end(), s,
                                [](const PoseEstimate& p, Timestamp t) { return p.t < t; });
      for (; a != run.poses.end() && a + 1 != run.poses.end() && (a + 1)->t <= e; ++a) {
        const auto& b = *(a + 1);
        if ((b.t - a->t).sec() > 0.5) continue;
        const ImuIncrement g = preintegrate(pr.imu, a->t, b.t, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                            pr.imu_noise);
        const Eigen::Matrix3d rel = a->q_ItoG.toRotationMatrix().transpose() * b.q_ItoG.toRotationMatrix();
        if (logMap(Eigen::Matrix3d(g.dR.transpose() * rel)).norm() > o.reinit_jump_rad) {
          ++report.reinit_jumps;
          last_jump = b.t;
        }
      }
    }
    if (report.reinit_jumps > 0) {
      size_t j = 0;
      while (j < pr.knots.size() && pr.knots[j].t < last_jump) ++j;
      if (j < pr.knots.size()) {
        for (size_t k = j; k-- > 0;) {
          const ImuIncrement g = preintegrate(pr.imu, pr.knots[k].t, pr.knots[k + 1].t, Eigen::Vector3d::Zero(),
                                              Eigen::Vector3d::Zero(), pr.imu_noise);
          pr.knots[k].q_ItoG = Eigen::Quaterniond(pr.knots[k + 1].q_ItoG.toRotationMatrix() * g.dR.transpose()).normalized();
        }
      }
    }
    // Landed knots (flight_state.csv): the last state at or before each knot.
    if (!ds.flight_states.empty()) {
      pr.rest_sigma_vel_m_s = est.zupt.sigma_vel_m_s;
      pr.rest_sigma_rate_rad_s = est.zupt.sigma_gyro_rad_s;
      for (const auto& k : pr.knots) {
        auto f = std::upper_bound(ds.flight_states.begin(), ds.flight_states.end(), k.t,
                                  [](Timestamp t, const FlightStateSample& x) { return t < x.t; });
        pr.at_rest.push_back(f != ds.flight_states.begin() && (f - 1)->landed);
      }
    }
    // Velocities by central differences of the initial positions.
    for (size_t k = 0; k < pr.knots.size(); ++k) {
      const size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, pr.knots.size() - 1);
      const double dt = (pr.knots[b].t - pr.knots[a].t).sec();
      if (dt > 0.0) pr.knots[k].v_IinG = (pr.knots[b].p_IinG - pr.knots[a].p_IinG) / dt;
      if (!pr.at_rest.empty() && pr.at_rest[k]) pr.knots[k].v_IinG.setZero();
    }
    // Gravity's direction in G by the data: R f averages −g over the chunk.
    {
      Eigen::Vector3d mean_f = Eigen::Vector3d::Zero();
      for (const auto& k : pr.knots) mean_f += k.q_ItoG * interpolateImu(pr.imu, k.t).acc_m_s2;
      mean_f /= static_cast<double>(pr.knots.size());
      report.gravity_z_sign = mean_f.z() > 0.0 ? -1.0 : 1.0;
      pr.gravity_G = Eigen::Vector3d(0.0, 0.0, report.gravity_z_sign * est.gravity_m_s2);
    }
    // The filter's belief at the chunk's start, unless the filter abandoned it later in the chunk.
    if (report.reinit_jumps == 0) {
      if (auto pe = interpolateEstimate(run.poses, s, Duration::fromSec(1.0))) {
        const bool pd = pe->cov_p_m2.allFinite() && pe->cov_theta_rad2.allFinite() &&
                        pe->cov_p_m2.llt().info() == Eigen::Success &&
                        pe->cov_theta_rad2.llt().info() == Eigen::Success && pe->cov_p_m2.trace() > 0.0;
        if (pd) pr.first_pose_prior = PosePrior{pe->p_IinG, pe->q_ItoG, pe->cov_p_m2, pe->cov_theta_rad2};
      }
    }
    // Heights of a downward rangefinder (the floor at z = 0: only with z up).
    if (est.height.enabled && report.gravity_z_sign < 0.0) {
      pr.p_IH = ds.setup.height_p_IH;
      pr.height_tilt_correction = est.height.tilt_correction;
      pr.height_bias_sigma_m = est.height.init_bias_sigma_m;
      const double max_tilt = est.height.max_tilt_deg * M_PI / 180.0;
      for (const auto& h : ds.heights) {
        if (h.t < s || h.t > e || !(h.range_m >= est.height.min_range_m)) continue;
        const size_t k = static_cast<size_t>(
            std::upper_bound(pr.knots.begin(), pr.knots.end(), h.t, [](Timestamp t, const NavState& x) { return t < x.t; }) -
            pr.knots.begin());
        const Eigen::Vector3d z_I = pr.knots[k == 0 ? 0 : k - 1].q_ItoG * Eigen::Vector3d::UnitZ();
        if (std::acos(std::clamp(z_I.z(), -1.0, 1.0)) > max_tilt) continue;
        pr.heights.push_back(SmootherHeight{h.t, h.range_m, est.height.sigma_m});
      }
    }
    // Ranges of the chunk.
    std::map<SensorId, int> anchor_unknown_index;
    std::map<std::pair<SensorId, SensorId>, int> pair_unknown;
    std::map<SensorId, int> common_unknown;
    estimator::RangeErrorCorrelation correlation(model.tau_s);
    auto r0 = std::lower_bound(ranges.begin(), ranges.end(), s, [](const RangeSample& r, Timestamp t) { return r.t < t; });
    // An anchor's position: exactly known (setup), else an unknown of the fit (estimate_anchors),
    // else the run's final estimate of it (a calibrated or a known-but-uncertain one), else an
    // uncertain one's setup position, its σ per axis added to the range's noise.
    struct AnchorRef {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      int unknown = -1;
      double sigma_m = 0.0;
    };
    auto anchorRef = [&](SensorId id) -> std::optional<AnchorRef> {
      const auto f = ds.setup.abs_anchor_positions.find(id);
      const auto g = run.anchors.find(id);
      const auto u = ds.setup.abs_anchor_sigmas_m.find(id);
      const bool uncertain = u != ds.setup.abs_anchor_sigmas_m.end() && u->second > 0.0;  // σ 0: exact
      if (f != ds.setup.abs_anchor_positions.end() && !uncertain) return AnchorRef{f->second};
      if (o.estimate_anchors && o.use_run_anchors && (g != run.anchors.end() || uncertain)) {
        AnchorRef a{g != run.anchors.end() ? g->second : f->second};
        auto [it, fresh] = anchor_unknown_index.emplace(id, static_cast<int>(pr.anchors.size()));
        if (fresh)
          pr.anchors.push_back(AnchorUnknown{id, a.p, uncertain ? f->second : Eigen::Vector3d::Zero(),
                                             uncertain ? u->second : 0.0});
        a.unknown = it->second;
        return a;
      }
      if (o.use_run_anchors && g != run.anchors.end()) return AnchorRef{g->second};
      // An uncertain anchor at its setup position: its σ added to each range's noise (a constant
      // error taken as white, overconfident over many ranges; estimate_anchors fits it instead).
      // Not with known_anchors_only: only the exactly known anchors then.
      if (o.use_run_anchors && f != ds.setup.abs_anchor_positions.end()) return AnchorRef{f->second, -1, u->second};
      return std::nullopt;
    };
    for (auto it = r0; it != ranges.end() && it->t <= e; ++it) {
      const RangeSample& r = *it;
      const bool i_tag = ds.setup.rel_tag_positions.count(r.id_initiator) > 0;
      const bool r_tag = ds.setup.rel_tag_positions.count(r.id_responder) > 0;
      const double z = o.use_corrected_range ? r.range_corr_m : r.range_m;
      if ((i_tag && r_tag) || !std::isfinite(z)) {
        ++out.n_ranges_skipped;
        continue;
      }
      SmootherRange sr;
      sr.t = r.t;
      sr.z_m = z;
      double sigma_anchors2 = 0.0;
      if (!i_tag && !r_tag) {
        // Anchor–anchor (the mesh): information only about anchors that are unknowns of the fit.
        const auto a = anchorRef(r.id_initiator), b = anchorRef(r.id_responder);
        if (!o.estimate_anchors || !a || !b || (a->unknown < 0 && b->unknown < 0)) {
          ++out.n_ranges_skipped;
          continue;
        }
        sr.anchor = r.id_initiator;
        sr.p_AinG = a->p;
        sr.anchor_unknown = a->unknown;
        sr.anchor_b = r.id_responder;
        sr.p_BinG = b->p;
        sr.anchor_b_unknown = b->unknown;
        sigma_anchors2 = a->sigma_m * a->sigma_m + b->sigma_m * b->sigma_m;
      } else {
        sr.tag = i_tag ? r.id_initiator : r.id_responder;
        sr.anchor = i_tag ? r.id_responder : r.id_initiator;
        const auto a = anchorRef(sr.anchor);
        if (!a) {
          ++out.n_ranges_skipped;
          continue;
        }
        sr.p_TinI = ds.setup.rel_tag_positions.at(sr.tag);
        sr.p_AinG = a->p;
        sr.anchor_unknown = a->unknown;
        sigma_anchors2 = a->sigma_m * a->sigma_m;
      }
      const SensorId a_id = sr.tag != 0 ? sr.tag : sr.anchor_b;
      double sigma = ds.setup.noise.sigma_range_m.value_or(r.R_m2 > 0.0 ? std::sqrt(r.R_m2) : est.uwb.sigma_range_m);
      const auto key = pairKey(a_id, sr.anchor);
      std::optional<PairBias> pb = ds.setup.findPairBias(a_id, sr.anchor);
      // A calibration's γ came from these ranges: with the anchors fitted here (a bundle
      // adjustment) the pair takes the uncalibrated prior instead, so that no range counts twice.
      if (!pb && !o.estimate_anchors) pb = model.calibrated(a_id, sr.anchor);
      if (!pb && !o.estimate_anchors) pb = model.calibrated(sr.anchor, a_id);
      if (pb) {
        sr.beta = pb->beta;
        sigma = pb->sigma_m;
        if (pb->sigma_gamma_m > 0.0) {
          auto [f, fresh] = pair_unknown.emplace(key, static_cast<int>(pr.range_biases.size()));
          if (fresh) pr.range_biases.push_back(RangeBiasUnknown{pb->gamma_m, pb->sigma_gamma_m});
          sr.gamma_unknown = f->second;
        } else {
          sr.gamma_fixed_m = pb->gamma_m;
        }
      } else if (model.sigma_gamma_unlisted > 0.0) {
        auto [f, fresh] = pair_unknown.emplace(key, static_cast<int>(pr.range_biases.size()));
        if (fresh) pr.range_biases.push_back(RangeBiasUnknown{0.0, model.sigma_gamma_unlisted});
        sr.gamma_unknown = f->second;
        if (sr.tag != 0) {  // a tag's pairs share its common offset (docs/uwb_bias_model.md)
          auto [c, cfresh] = common_unknown.emplace(sr.tag, static_cast<int>(pr.range_biases.size()));
          if (cfresh) pr.range_biases.push_back(RangeBiasUnknown{0.0, est.uwb.uncalibrated_common_gamma_sigma_m});
          sr.common_unknown = c->second;
        }
      }
      // A pair's errors are correlated over τ: a range Δt after the pair's previous one carries
      // (1 − ρ)/(1 + ρ) of an independent one's information, ρ = exp(−Δt/τ), as in the filter
      // (RangeErrorCorrelation); the robust loss keeps its scale on the range's own σ.
      const double inflation = correlation.inflation(a_id, sr.anchor, r.t);
      correlation.noteRange(a_id, sr.anchor, r.t);
      sr.sigma_m = std::sqrt(sigma * sigma + sigma_anchors2);
      sr.noise_inflation = std::sqrt(inflation);
      sr.sigma_m *= sr.noise_inflation;
      pr.ranges.push_back(sr);
    }
    out.n_ranges_used += static_cast<int>(pr.ranges.size());

    BatchSmootherOptions solver = o.solver;  // the estimator's NLOS mixture (run_smoother.h)
    solver.nlos_fraction = o.nlos_fraction.value_or(est.uwb.nlos_fraction);
    solver.nlos_offset_m = est.uwb.nlos_min_excess_m;
    solver.nlos_scale_m = est.uwb.nlos_mean_excess_m;
    BatchSmoother smoother(solver);
    auto res = smoother.solve(pr, [&](int pass, int passes, const std::string& line) {
      if (progress) {
        std::ostringstream m;
        m << "chunk " << chunk_index + 1 << " [" << s.sec() - span0.sec() << ", " << e.sec() - span0.sec()
          << "] s, " << pr.knots.size() << " knots, " << pr.ranges.size() << " ranges, " << pass << "/" << passes
          << ": " << line;
        progress(m.str());
      }
    });
    // Poses at the filter's times.
    auto a = std::lower_bound(run.poses.begin(), run.poses.end(), s,
                              [](const PoseEstimate& p, Timestamp t) { return p.t < t; });
    for (; a != run.poses.end() && (a->t < out_end || (final_chunk && a->t <= out_end)); ++a) {
      const SmoothedKnot k = stateAt(res.knots, pr.imu, pr.gravity_G, a->t);
      PoseEstimate pe;
      pe.t = a->t;
      pe.p_IinG = k.x.p_IinG;
      pe.v_IinG = k.x.v_IinG;
      pe.q_ItoG = k.x.q_ItoG;
      pe.bias_gyro_rad_s = k.x.bias_gyro_rad_s;
      pe.bias_acc_m_s2 = k.x.bias_acc_m_s2;
      pe.cov_p_m2 = k.cov_p_m2;
      pe.cov_theta_rad2 = k.cov_theta_rad2;
      out.poses.push_back(pe);
    }
    res.knots.clear();
    for (const auto& a : res.anchors) {
      AnchorEstimate ae;
      ae.t = e;
      ae.id = a.id;
      ae.p_AinG = a.p_AinG;
      ae.cov_p_m2 = a.cov_p_m2;
      auto it = std::find_if(out.anchors.begin(), out.anchors.end(), [&](const AnchorEstimate& x) { return x.id == a.id; });
      if (it == out.anchors.end()) out.anchors.push_back(ae);
      else *it = ae;
    }
    report.result = std::move(res);
    out.chunks.push_back(std::move(report));
    if (final_chunk) break;
    s = out_end;
    ++chunk_index;
  }
  return out;
}

}  // namespace meshnav::smoother
