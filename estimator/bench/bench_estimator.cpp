/// @file bench_estimator.cpp
/// @brief Google Benchmark of the estimator (`./meshnav bench estimator` runs it with repetitions).
/// <strategy> ∈ {centralized, dp, dah}, <anchors> = estimated (3-state) anchors besides the exact
/// 101–104, on the real 15-state IMU instance with two tags and the baro, in steady state after a
/// 5 s warm-up flight (IMU 200 Hz, baro 20 Hz, one range per 10 ms slot cycling through the
/// tag–anchor pairs and the anchor ring i → i+1):
///  - Propagate/<s>/<n>: one 5 ms IMU propagation;
///  - RangeUpdate/<s>/<n>: one tag–anchor range (linearize + update);
///  - AnchorRangeUpdate/<s>/<n>: one anchor–anchor range;
///  - RangeUpdateGamma/dah/<n>: RangeUpdate with every estimated anchor carrying its γ towards
///    101–104 as states (7-state anchors, issue 10; a-priori σ_γ 0.02 m in the setup);
///  - RangeUpdateJointSet/dah/<n>: RangeUpdate to the first 5 estimated anchors, which form one DAH
///    joint set with the IMU (issue 10, uwb.dah_joint_anchors): the cost of the set, not of <n>;
///  - RangeUpdateJointSetAll/dah/<n>: every estimated anchor joined the set of the IMU and the
///    baro bias one after the other, as the node joins calibrated anchors without a bound
///    (`uwb.dah_joint_max_anchors: 0`); ranges cycle through all <n> anchors;
///  - RangeUpdateJointSetBounded/dah/<n>: the same joins with the node's default bound
///    (boundJointSetAnchors, `uwb.dah_joint_max_anchors`: the most refined anchors leave the set);
///  - RangeUpdateJointSetBound<b>/dah/<n>: the same with the bound b ∈ {3, 5, 6} (n ∈ {5, 100}: the
///    ratio 100 ÷ 5 of docs/modular_estimator.md, "Bounding the set");
///  - DelayedRangeUpdate/<s>/<n>: through EstimatorNode, one IMU sample plus one range arriving
///    50 ms late (rewind to the snapshot before it, re-process 50 ms of inputs);
///  - Micro/<s>/<N>: reference scenario (a 6-state p, v body at 100 Hz, N stationary 3-state
///    anchors, body–anchor ranges at 10 Hz each, ring i → i+1 ranges, σ 0.1 m): one range update;
///  - Sequence/<s>: a whole simulated paper sequence (seed 1) through EstimatorNode (needs the
///    simulator library), counter realtime_factor, and pose_latency_p99_us / pose_latency_max_us
///    (wall time from an IMU sample's onInput to its POSE);
///  - SequenceFixedLag/<s>: the same with the fixed-lag smoother (a POSE_SMOOTHED sink): its cost
///    is the ratio of the two CPU times, its effect on POSE the latency counters;
///  - SequenceFlyBy/<s>, SequenceFlyByFixedLag/<s>: both with the S2 fly-by anchors joining at 80
///    and 100 s (each join re-runs the stored history): the paper scenario's estimator;
///  - AlignerSolve/<window_s>: one in-motion alignment (MotionAligner::solve: the multi-start
///    Levenberg–Marquardt fit of IMU and tag–anchor ranges) over the last <window_s> seconds of
///    that sequence before t = 52 s, in flight; the node runs it while uninitialized, lost or
///    degraded, and on real recordings it is most of a run's time (needs the simulator library).
///    The ranges go in as measured (the simulated pair biases, up to ±0.4 m, not subtracted as
///    the node does), with default MotionAlignerOptions (no flight volume); the same aligner is
///    solved every iteration, so after the first one it starts at the gyro bias it fitted, as the
///    node's repeated initialization tries do. A cost figure, not an accuracy one.
/// Covariances are restored from the warm-up snapshot every 1000 iterations (outside the timing).

#include <benchmark/benchmark.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <random>

#include "estimator/core/strategy_list.h"
#include "estimator/filter/dense_ekf_update.h"
#include "estimator/filter/factorized_covariance.h"
#include "estimator/filter/joint_set_bound.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/node/estimator_node.h"
#include "estimator/init/motion_aligner.h"
#include "estimator/testing/synthetic_scenario.h"
#include "estimator/uwb/range_model.h"
#ifdef MESHNAV_BENCH_WITH_SIM
#include "sim/scenario_simulator.h"
#endif

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

constexpr int kAnchorCounts[] = {5, 10, 20, 50, 100};
/// Every strategy of the build (estimator/core/strategy_list.h); the names are literals, so
/// null-terminated.
std::vector<const char*> listedStrategies() {
  std::vector<const char*> names;
  for (const auto& entry : kStrategyList) names.push_back(entry.name.data());
  return names;
}
constexpr int kRestoreEvery = 1000;

/// The warm-up flight as a stream of inputs (synthetic trajectory, exact readings + small range noise).
class FlightStream {
 public:
  /// `anchor_gammas`: every estimated anchor gets a-priori pair biases (σ_γ 0.02 m) towards 101–104.
  FlightStream(int n_est, double landed_s = 1.5, bool anchor_gammas = false)
      : opts_(options(n_est, landed_s)), traj_(landed_s, 0.5) {
    setup_ = synthetic::syntheticSetup(opts_);
    anchors_ = synthetic::syntheticAnchors(n_est);
    if (anchor_gammas)
      for (const auto& [id, p] : anchors_)
        if (setup_.abs_anchor_sigmas_m.count(id))
          for (SensorId k : {101, 102, 103, 104}) setup_.pair_biases.push_back(PairBias{id, k, 0.05, 1.0, 0.1, 0.02, 0.0});
    for (const auto& [id, p] : anchors_) ids_.push_back(id);
    for (SensorId tag : {100, 105})
      for (SensorId a : ids_) pairs_.emplace_back(tag, a);
    for (size_t i = 0; i < ids_.size(); ++i) pairs_.emplace_back(ids_[i], ids_[(i + 1) % ids_.size()]);
  }
  static synthetic::SyntheticOptions options(int n_est, double landed_s) {
    synthetic::SyntheticOptions o;
    o.n_estimated_anchors = n_est;
    o.landed_s = landed_s;
    o.yaw0_deg = 0.5 * 180.0 / M_PI;
    return o;
  }
  const SystemSetup& setup() const { return setup_; }
  const synthetic::SyntheticTrajectory& trajectory() const { return traj_; }
  ImuSample imu(double t) const { return traj_.imu(t); }
  Eigen::Vector3d where(SensorId id, double t) const {
    auto it = setup_.rel_tag_positions.find(id);
    if (it != setup_.rel_tag_positions.end()) return traj_.position(t) + traj_.rotation(t) * it->second;
    return anchors_.at(id);
  }
  RangeSample range(size_t k, double t) {
    const auto [a, b] = pairs_[k % pairs_.size()];
    PairBias pb{a, b, 0.0, 1.0, 0.1, 0.0, 0.0};
    if (auto p = setup_.findPairBias(a, b)) pb = *p;
    RangeSample r;
    r.t = Timestamp::fromSec(t);
    r.id_initiator = a;
    r.id_responder = b;
    r.type_initiator = setup_.isTag(a) ? UwbType::Tag : UwbType::Anchor;
    r.type_responder = setup_.isTag(b) ? UwbType::Tag : UwbType::Anchor;
    r.range_m = pb.beta * (where(a, t) - where(b, t)).norm() + pb.gamma_m + 0.05 * n01_(rng_);
    r.range_corr_m = r.range_m;
    r.R_m2 = 0.01;
    return r;
  }
  /// Inputs of [t0, t1): IMU every 5 ms, baro every 50 ms, a range every 10 ms.
  std::vector<EstimatorInput> inputs(double t0, double t1) {
    std::vector<EstimatorInput> v;
    if (t0 == 0.0) {
      v.emplace_back(FlightStateSample{Timestamp{}, true});
      v.emplace_back(FlightStateSample{Timestamp::fromSec(opts_.landed_s), false});
    }
    for (int k = static_cast<int>(std::lround(t0 * 200)); k < std::lround(t1 * 200); ++k) {
      const double t = k / 200.0;
      v.emplace_back(imu(t));
      if (k % 10 == 0) {
        const double h = (traj_.position(t) + traj_.rotation(t) * setup_.baro_p_IP).z();
        v.emplace_back(BaroSample{Timestamp::fromSec(t), 101325.0 * std::pow(1.0 - 2.25577e-5 * h, 5.25588)});
      }
      if (k % 2 == 1) v.emplace_back(range(slot_++, t));
    }
    std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return inputOrder(a) < inputOrder(b); });
    return v;
  }
  size_t nPairs() const { return pairs_.size(); }
  const std::vector<SensorId>& anchorIds() const { return ids_; }

 private:
  synthetic::SyntheticOptions opts_;
  synthetic::SyntheticTrajectory traj_;
  SystemSetup setup_;
  std::map<SensorId, Eigen::Vector3d> anchors_;
  std::vector<SensorId> ids_;
  std::vector<std::pair<SensorId, SensorId>> pairs_;
  size_t slot_ = 0;
  std::mt19937 rng_{7};
  std::normal_distribution<double> n01_{0.0, 1.0};
};

EstimatorOptions benchOptions(const std::string& strategy) {
  EstimatorOptions o;
  o.strategy = strategy;
  o.uwb.estimate_setup_anchor_biases = true;  // the anchors' γ are states when the setup has them
  o.window_s = 0.5;
  o.uwb.gate_probability = 0.0;
  o.baro.gate_probability = 0.0;
  return o;
}

/// A node after a 5 s warm-up flight (initialized from the setup's initial pose, flying).
std::unique_ptr<EstimatorNode> warmNode(const std::string& strategy, FlightStream& fs, double until_s = 5.0) {
  auto node = std::make_unique<EstimatorNode>(benchOptions(strategy), fs.setup());
  for (const auto& in : fs.inputs(0.0, until_s)) node->onInput(in);
  if (!node->initialized()) throw std::runtime_error("bench: node did not initialize");
  return node;
}

struct Warm {
  std::unique_ptr<FlightStream> stream;
  std::unique_ptr<FusionStrategy> filter;
  UwbNetwork net;
};

Warm warmFilter(const std::string& strategy, int n, bool anchor_gammas = false) {
  Warm w;
  w.stream = std::make_unique<FlightStream>(n, 1.5, anchor_gammas);
  w.filter = warmNode(strategy, *w.stream)->filter()->clone();
  w.net = UwbNetwork(w.stream->setup(), 0.1);
  return w;
}

void Propagate(benchmark::State& state, std::string strategy, int n) {
  Warm w = warmFilter(strategy, n);
  auto f = w.filter->clone();
  const Eigen::Vector3d acc(0.1, -0.2, 9.81), gyro(0.01, 0.02, 0.1);
  const Timestamp t0 = f->state().t;
  Timestamp t = t0;
  int64_t k = 0;
  for (auto _ : state) {
    if (++k % kRestoreEvery == 0) {
      state.PauseTiming();
      f = w.filter->clone();
      t = t0;
      state.ResumeTiming();
    }
    t = t + Duration::fromMs(5);
    f->propagate(acc, gyro, t);
    benchmark::DoNotOptimize(f->state().imu.p_IinG.data());
  }
  state.counters["state_dim"] = f->layout().dim();
}

/// `joint_set` > 0: the IMU and the first `joint_set` estimated anchors form a set, ranges to those
/// only. `grow_max_anchors` ≥ 0: every estimated anchor joins the set of the IMU and the baro bias
/// in turn, as EstimatorNode::joinAnchorSet does, bounded to that many anchors (0: no bound).
void Update(benchmark::State& state, std::string strategy, int n, bool anchor_anchor, bool anchor_gammas,
            int joint_set, int grow_max_anchors) {
  Warm w = warmFilter(strategy, n, anchor_gammas);
  const auto& ids = w.stream->anchorIds();
  std::vector<SensorId> est(ids.end() - n, ids.end());  // the estimated anchors 106…
  if (joint_set > 0) {  // the IMU and the first `joint_set` estimated anchors; ranges to those only
    est.resize(static_cast<size_t>(std::min(joint_set, n)));
    std::vector<SensorId> set = est;
    set.push_back(w.filter->state().imu_id);
    w.filter->joinJointSet(set);
  }
  if (grow_max_anchors >= 0) {
    int in_set = 0;
    for (SensorId a : est) {
      w.filter->joinJointSet({a, w.filter->state().imu_id, w.stream->setup().baro_id});
      in_set += 1 - boundJointSetAnchors(*w.filter, a, grow_max_anchors);
    }
    state.counters["anchors_in_set"] = in_set;
  }
  auto f = w.filter->clone();
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 0.05);
  int64_t k = 0;
  for (auto _ : state) {
    if (++k % kRestoreEvery == 0) {
      state.PauseTiming();
      f = w.filter->clone();
      state.ResumeTiming();
    }
    const size_t i = static_cast<size_t>(k) % est.size();
    RangeMeasurement z;
    z.a = anchor_anchor ? est[i] : 100;
    z.b = anchor_anchor ? est[(i + 1) % est.size()] : est[i];
    z.R_m2 = 0.01;
    z.z_m = RangeModel::predict(z, f->state(), w.net)->first + n01(rng);
    Linearization lin;
    RangeModel::linearize(z, f->state(), w.net, &lin);
    benchmark::DoNotOptimize(f->update(lin, 0.0));
  }
  state.counters["state_dim"] = f->layout().dim();
}

void DelayedRangeUpdate(benchmark::State& state, std::string strategy, int n) {
  FlightStream fs(n);
  auto node = warmNode(strategy, fs);
  double t = 5.0;
  size_t slot = 0;
  for (auto _ : state) {
    node->onImu(fs.imu(t));
    node->onRange(fs.range(slot++, t - 0.05));  // 50 ms late
    t += 0.005;
  }
  state.counters["out_of_sequence"] = static_cast<double>(node->diagnostics().get("out_of_sequence"));
  state.counters["history"] = static_cast<double>(node->historySize());
}

/// Micro reference scenario over the covariance core (6-state body id 1, anchors 2…N+1).
struct MicroScenario {
  int N;
  Eigen::Matrix<double, 6, 6> Phi, Q;
  std::vector<Eigen::Vector3d> anchors;
  Eigen::Vector3d p = Eigen::Vector3d(0.5, 0.2, 1.0);
  explicit MicroScenario(int n) : N(n) {
    const double dt = 0.01, q = 0.1;
    Phi.setIdentity();
    Phi.topRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * dt;
    Q.setZero();
    Q.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * q * dt * dt * dt / 3.0;
    Q.topRightCorner<3, 3>() = Q.bottomLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * q * dt * dt / 2.0;
    Q.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * q * dt;
    for (int i = 0; i < N; ++i) {
      const double a = 2.0 * M_PI * i / N;
      anchors.emplace_back(4.0 * std::cos(a), 4.0 * std::sin(a), 0.5 + 2.0 * (i % 3));
    }
  }
  /// Range body–anchor i (ring = false) or anchor i → i+1 (ring = true) at the true positions.
  Linearization range(int i, bool ring) const {
    const Eigen::Vector3d a = ring ? anchors[i] : p, b = ring ? anchors[(i + 1) % N] : anchors[i];
    const Eigen::RowVector3d u = (b - a).normalized().transpose();
    Linearization lin;
    lin.residual = Eigen::VectorXd::Constant(1, 0.03);
    lin.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
    Eigen::MatrixXd Ha = Eigen::MatrixXd::Zero(1, ring ? 3 : 6);
    Ha.leftCols<3>() = -u;
    lin.blocks.push_back({ring ? 2 + i : 1, Ha});
    lin.blocks.push_back({2 + (ring ? (i + 1) % N : i), Eigen::MatrixXd(u)});
    return lin;
  }
};

/// Dense reference (centralized) for the micro scenario.
struct DenseMicro {
  StateLayout layout;
  Eigen::MatrixXd P;
  void add(SensorId id, InstanceKind k, const Eigen::MatrixXd& c) {
    const int n = layout.dim();
    layout.add(id, k, static_cast<int>(c.rows()));
    Eigen::MatrixXd Pn = Eigen::MatrixXd::Zero(layout.dim(), layout.dim());
    Pn.topLeftCorner(n, n) = P;
    Pn.bottomRightCorner(c.rows(), c.rows()) = c;
    P = Pn;
  }
  void propagate(const Eigen::Matrix<double, 6, 6>& F, const Eigen::Matrix<double, 6, 6>& Q, Timestamp) {
    P.topRows<6>() = (F * P.topRows<6>()).eval();
    P.leftCols<6>() = (P.leftCols<6>() * F.transpose()).eval();
    P.topLeftCorner<6, 6>() += Q;
  }
  void update(const Linearization& lin, Timestamp) { denseEkfUpdate(P, layout, lin, 0.0, true); }
};

struct FactorMicro {
  FactorizedCovariance cov;
  explicit FactorMicro(FactorizedCovariance::Mode m) : cov(m, true) {}
  void add(SensorId id, InstanceKind k, const Eigen::MatrixXd& c) { cov.add(id, k, c, Timestamp{}); }
  void propagate(const Eigen::Matrix<double, 6, 6>& F, const Eigen::Matrix<double, 6, 6>& Q, Timestamp t) {
    cov.propagate(1, F, Q, t);
  }
  void update(const Linearization& lin, Timestamp t) { cov.update(lin, 0.0, t); }
};

template <typename F>
void runMicro(benchmark::State& state, F f0, int N) {
  MicroScenario sc(N);
  f0.add(1, kindOf<ImuKind>, Eigen::MatrixXd::Identity(6, 6) * 0.01);  // the "body" (kind only names it)
  for (int i = 0; i < N; ++i) f0.add(2 + i, kindOf<AnchorKind>, Eigen::MatrixXd::Identity(3, 3) * 0.04);
  // Warm-up: 10 s at 100 Hz, every anchor ranged at 10 Hz (one body–anchor and one ring range per
  // step, cycling), so that everything is correlated.
  Timestamp t;
  int k = 0;
  for (; k < 1000; ++k) {
    t = t + Duration::fromMs(10);
    f0.propagate(sc.Phi, sc.Q, t);
    for (int j = 0; j < std::max(1, N / 10); ++j) {
      f0.update(sc.range((k * std::max(1, N / 10) + j) % N, false), t);
      f0.update(sc.range((k * std::max(1, N / 10) + j) % N, true), t);
    }
  }
  F f = f0;
  int64_t it = 0;
  for (auto _ : state) {
    if (++it % kRestoreEvery == 0) {
      state.PauseTiming();
      f = f0;
      state.ResumeTiming();
    }
    f.update(sc.range(static_cast<int>(it / 2 % N), it % 2 == 1), t);
  }
}

void Micro(benchmark::State& state, std::string strategy, int N) {
  if (strategy == "centralized")
    runMicro(state, DenseMicro{}, N);
  else
    runMicro(state, FactorMicro(strategy == "dp" ? FactorizedCovariance::Mode::DP : FactorizedCovariance::Mode::DAH),
             N);
}

#ifdef MESHNAV_BENCH_WITH_SIM
const Dataset& paperSequence() {
  static const Dataset ds = [] {
    sim::SimulationOptions so;
    so.seed = 1;
    return sim::ScenarioSimulator(so).run().dataset;
  }();
  return ds;
}

/// The sequence's inputs; with `flyby` the fly-by anchors the setup does not know (106–110) join
/// as the calibrator's ANCHOR_INITs would in S2 (config/missions/paper_s2.yaml: 106–108 at 80 s,
/// 109–110 at 100 s), at their true position 0.05 m off with σ 0.06 m: each join re-runs the
/// filter over the stored history (refine.rerun_on_anchor_join), the estimator's main extra cost.
std::vector<EstimatorInput> sequenceInputs(const Dataset& ds, bool flyby) {
  std::vector<EstimatorInput> inputs = mergeInTimeOrder(ds);
  if (!flyby || !ds.truth) return inputs;
  for (const auto& [id, p] : ds.truth->anchor_positions) {
    if (ds.setup.abs_anchor_positions.count(id)) continue;
    AnchorInit a;
    a.t = Timestamp::fromSec(id <= 108 ? 80.0 : 100.0);
    a.id = id;
    a.p_AinG = p + Eigen::Vector3d(0.05, -0.03, 0.02);
    a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.06 * 0.06;
    const auto at = std::lower_bound(inputs.begin(), inputs.end(), a.t,
                                     [](const EstimatorInput& in, Timestamp t) { return inputTime(in) < t; });
    inputs.insert(at, a);
  }
  return inputs;
}

/// `fixed_lag`: with a POSE_SMOOTHED sink, so the fixed-lag smoother runs (SequenceFixedLag/<s>).
/// `flyby`: anchors join (sequenceInputs; SequenceFlyBy/<s>, SequenceFlyByFixedLag/<s>).
/// Counters pose_latency_p99_us / _max_us: the wall time from an IMU sample's onInput to its POSE.
void Sequence(benchmark::State& state, std::string strategy, bool fixed_lag, bool flyby) {
  const Dataset& ds = paperSequence();
  const auto inputs = sequenceInputs(ds, flyby);
  EstimatorOptions o;
  o.strategy = strategy;
  size_t smoothed = 0;
  std::vector<double> latency_us;
  for (auto _ : state) {
    latency_us.clear();
    std::chrono::steady_clock::time_point t_in;
    EstimatorSinks sinks;
    sinks.pose = [&](const PoseEstimate&) {
      latency_us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t_in).count());
    };
    if (fixed_lag) sinks.pose_smoothed = [&](const PoseEstimate&) { ++smoothed; };
    EstimatorNode node(o, ds.setup, sinks);
    for (const auto& in : inputs) {
      t_in = std::chrono::steady_clock::now();
      node.onInput(in);
    }
    node.flushSmoothed();
    benchmark::DoNotOptimize(node.pose());
  }
  const double dur = (inputTime(inputs.back()) - inputTime(inputs.front())).sec();
  state.counters["inputs"] = static_cast<double>(inputs.size());
  state.counters["realtime_factor"] =
      benchmark::Counter(dur * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  if (!latency_us.empty()) {
    std::sort(latency_us.begin(), latency_us.end());
    state.counters["pose_latency_p99_us"] = latency_us[latency_us.size() * 99 / 100];
    state.counters["pose_latency_max_us"] = latency_us.back();
  }
  if (fixed_lag) state.counters["smoothed_per_iteration"] = static_cast<double>(smoothed) / static_cast<double>(state.iterations());
}

void AlignerSolve(benchmark::State& state, double window_s) {
  const Dataset& ds = paperSequence();
  constexpr double kEnd_s = 52.0;
  MotionAlignerOptions o;
  o.window_s = window_s;
  MotionAligner aligner(o, ds.setup.rel_tag_positions);
  for (const ImuSample& s : ds.imu)
    if (s.t.sec() >= kEnd_s - window_s - 0.1 && s.t.sec() <= kEnd_s) aligner.addImu(s);
  int n_ranges = 0;
  for (const RangeSample& r : ds.ranges) {
    if (r.t.sec() < kEnd_s - window_s || r.t.sec() > kEnd_s) continue;
    const bool tag_first = ds.setup.rel_tag_positions.count(r.id_initiator) > 0;
    const SensorId tag = tag_first ? r.id_initiator : r.id_responder, anchor = tag_first ? r.id_responder : r.id_initiator;
    if (!ds.setup.rel_tag_positions.count(tag) || !ds.setup.abs_anchor_positions.count(anchor)) continue;
    aligner.addRange({r.t, tag, anchor, ds.setup.abs_anchor_positions.at(anchor), r.range_m, 0.1});
    ++n_ranges;
  }
  bool aligned = false;
  for (auto _ : state) {
    const auto res = aligner.solve(Eigen::Vector3d::Zero());
    aligned = res.has_value();
    benchmark::DoNotOptimize(res);
  }
  state.counters["ranges"] = n_ranges;
  state.counters["aligned"] = aligned ? 1 : 0;
}
#endif

void registerAll() {
  for (const char* s : listedStrategies())
    for (int n : kAnchorCounts) {
      const std::string tail = std::string(s) + "/" + std::to_string(n);
      benchmark::RegisterBenchmark(("Propagate/" + tail).c_str(), Propagate, s, n);
      benchmark::RegisterBenchmark(("RangeUpdate/" + tail).c_str(), Update, s, n, false, false, 0, -1);
      benchmark::RegisterBenchmark(("AnchorRangeUpdate/" + tail).c_str(), Update, s, n, true, false, 0, -1);
      benchmark::RegisterBenchmark(("DelayedRangeUpdate/" + tail).c_str(), DelayedRangeUpdate, s, n);
    }
  for (int n : kAnchorCounts)
    benchmark::RegisterBenchmark(("RangeUpdateGamma/dah/" + std::to_string(n)).c_str(), Update, "dah", n, false, true,
                                 0, -1);
  for (int n : kAnchorCounts)
    benchmark::RegisterBenchmark(("RangeUpdateJointSet/dah/" + std::to_string(n)).c_str(), Update, "dah", n, false,
                                 false, 5, -1);
  for (int n : kAnchorCounts)
    benchmark::RegisterBenchmark(("RangeUpdateJointSetAll/dah/" + std::to_string(n)).c_str(), Update, "dah", n, false,
                                 false, 0, 0);
  for (int n : kAnchorCounts)
    benchmark::RegisterBenchmark(("RangeUpdateJointSetBounded/dah/" + std::to_string(n)).c_str(), Update, "dah", n,
                                 false, false, 0, EstimatorOptions{}.uwb.dah_joint_max_anchors);
  for (int bound : {3, 5, 6})
    for (int n : {5, 100})
      benchmark::RegisterBenchmark(
          ("RangeUpdateJointSetBound" + std::to_string(bound) + "/dah/" + std::to_string(n)).c_str(), Update, "dah",
          n, false, false, 0, bound);
  for (const char* s : listedStrategies())
    for (int N : {2, 5, 10, 20})
      benchmark::RegisterBenchmark(("Micro/" + std::string(s) + "/" + std::to_string(N)).c_str(), Micro, s, N);
#ifdef MESHNAV_BENCH_WITH_SIM
  for (const char* s : listedStrategies())
    for (bool flyby : {false, true})
      for (bool fixed_lag : {false, true})
        benchmark::RegisterBenchmark(
            (std::string(flyby ? "SequenceFlyBy" : "Sequence") + (fixed_lag ? "FixedLag/" : "/") + s).c_str(), Sequence,
            s, fixed_lag, flyby)
            ->Unit(benchmark::kMillisecond);
  for (double w : {6.0, 12.0})
    benchmark::RegisterBenchmark(("AlignerSolve/" + std::to_string(static_cast<int>(w))).c_str(), AlignerSolve, w)
        ->Unit(benchmark::kMillisecond);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  registerAll();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
