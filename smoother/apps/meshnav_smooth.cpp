/// @file meshnav_smooth.cpp
/// @brief The whole-recording smoother: reads a dataset and a filter run folder (meshnav run),
/// writes estimate_smoothed.csv (estimate.csv's columns) and smoother.yaml into the run folder.
/// docs/smoother.md.

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>

#include "common/atomic_file.h"
#include "common/cli_main.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "smoother/run_smoother.h"

using namespace meshnav;
using namespace meshnav::smoother;
namespace fs = std::filesystem;

namespace {

constexpr char kDescription[] =
    "Smooths a recording after a filter run: every pose given the IMU and the ranges on both sides of it (a "
    "least-squares fit of knots tied by preintegrated IMU increments, ranges under a robust loss, the unknown range "
    "biases), chunk by chunk with the filter's belief as each chunk's prior. Reads --dataset and --run (a meshnav run "
    "folder: estimate.csv, anchors.csv, status.txt), writes RUN/estimate_smoothed.csv (the columns of estimate.csv) "
    "and RUN/smoother.yaml. Exit status 0: done; 1: an input or output failed, or a chunk did not converge or has no "
    "covariance (a direction the data does not fix); 2: bad command line.";

struct SmoothCli {
  std::string dataset, run, out;
  RunSmootherOptions o;
  std::string loss = "cauchy";
  bool known_anchors_only = false;
  bool keep_run_anchors = false;
};

void declareOptions(Cli& cli, SmoothCli& c) {
  cli.optional("dataset", c.dataset, "dataset folder the run was made on")->type_name("DIR")->required();
  cli.optional("run", c.run, "run folder of meshnav run (estimate.csv, anchors.csv, status.txt)")
      ->type_name("DIR")
      ->required();
  cli.optional("out", c.out, "smoothed poses (default RUN/estimate_smoothed.csv)")->type_name("FILE");
  cli.option("knot-period", c.o.knot_period_s, "spacing of the smoother's knots [s]")->check(cli::positive());
  cli.option("chunk", c.o.chunk_s, "data solved at once [s]")->check(cli::positive());
  cli.option("overlap", c.o.overlap_s, "future data the last pose of a chunk has seen [s]")->check(CLI::NonNegativeNumber);
  cli.option("loss", c.loss, "robust loss of the ranges")->check(CLI::IsMember({"cauchy", "huber"}));
  cli.option("loss-scale", c.o.solver.loss_scale_sigmas, "scale of the loss in range sigma [-]")->check(cli::positive());
  cli.option("passes", c.o.solver.passes, "solves per chunk, re-integrated at the solved biases")->check(CLI::Range(1, 20));
  cli.flag("corrected-range", c.o.use_corrected_range, "fit range_corr instead of range_raw");
  cli.optional("config", c.o.estimator_config,
               "the estimator options file the run was made with (meshnav run --config): its IMU, range, ZUPT and "
               "height models (default: the estimator's defaults)")
      ->type_name("FILE");
  cli.flag("keep-run-anchors", c.keep_run_anchors,
           "take the anchors the run estimated (calibrated, uncertain) as it left them (anchors.csv) instead of "
           "fitting them with the trajectory (the default, a bundle adjustment written to RUN/anchors_smoothed.csv)");
  cli.flag("known-anchors-only", c.known_anchors_only,
           "use only the setup's known anchors, not the ones the run estimated (for calibrating those on the "
           "smoothed path)");
  cli.option("threads", c.o.solver.threads, "solver threads")->check(CLI::Range(1, 64));
}

int run(SmoothCli& c) {
  c.o.use_run_anchors = !c.known_anchors_only;
  c.o.estimate_anchors = !c.keep_run_anchors;
  c.o.solver.range_loss = c.loss == "huber" ? BatchSmootherOptions::Loss::Huber : BatchSmootherOptions::Loss::Cauchy;
  Diagnostics diag;
  const Dataset ds = readDataset(c.dataset, diag);
  const FilterRun fr = readFilterRun(c.run, diag);
  spdlog::info("{}: {} poses of the filter, {} IMU samples, {} ranges; UWB clock delay {} s", c.run, fr.poses.size(),
               ds.imu.size(), ds.ranges.size(), fr.uwb_clock_offset_s);
  const SmoothedRun sm = smoothRun(ds, fr, c.o, [](const std::string& line) { spdlog::info("{}", line); });
  const std::string out = c.out.empty() ? (fs::path(c.run) / "estimate_smoothed.csv").string() : c.out;
  {
    EstimateCsvWriter w(out);
    for (const auto& p : sm.poses) w.write(p);
    w.flush();
  }
  if (!sm.anchors.empty()) {
    const std::string path = (fs::path(c.run) / "anchors_smoothed.csv").string();
    AnchorsCsvWriter w(path);
    for (const auto& a : sm.anchors) w.write(a);
    w.flush();
    spdlog::info("wrote {} ({} anchors)", path, sm.anchors.size());
  }
  bool ok = true;
  YAML::Emitter y;
  y << YAML::BeginMap << YAML::Key << "poses" << YAML::Value << sm.poses.size();
  y << YAML::Key << "ranges_used" << YAML::Value << sm.n_ranges_used;
  y << YAML::Key << "ranges_skipped" << YAML::Value << sm.n_ranges_skipped;
  y << YAML::Key << "chunks" << YAML::Value << YAML::BeginSeq;
  for (const auto& ch : sm.chunks) {
    const auto& r = ch.result;
    ok = ok && r.converged && r.covariance_ok;
    y << YAML::Flow << YAML::BeginMap << YAML::Key << "t0_s" << YAML::Value << ch.t0_s << YAML::Key << "t1_s"
      << YAML::Value << ch.t1_s << YAML::Key << "converged" << YAML::Value << r.converged << YAML::Key
      << "covariance_ok" << YAML::Value << r.covariance_ok << YAML::Key << "imu_chi2_per_dof" << YAML::Value
      << r.imu_chi2_per_dof << YAML::Key << "height_bias_m" << YAML::Value << r.height_bias_m << YAML::Key
      << "heights" << YAML::Value << r.n_heights << YAML::Key << "gravity_z_sign" << YAML::Value << ch.gravity_z_sign << YAML::Key
      << "filter_reinitializations" << YAML::Value << ch.reinit_jumps << YAML::Key << "imu_gaps" << YAML::Value
      << ch.imu_gaps << YAML::Key << "ranges" << YAML::Value
      << r.n_ranges << YAML::Key << "range_outliers" << YAML::Value << r.n_range_outliers << YAML::Key
      << "range_nlos" << YAML::Value << r.n_range_nlos << YAML::Key
      << "range_rms_inliers_m" << YAML::Value << r.range_rms_inliers_m << YAML::Key << "message" << YAML::Value
      << r.message << YAML::EndMap;
    if (ch.imu_gaps > 0)
      spdlog::warn("chunk [{}, {}] s: {} IMU gap(s), bridged by the gap noise model", ch.t0_s, ch.t1_s, ch.imu_gaps);
    if (!r.converged) spdlog::error("chunk [{}, {}] s did not converge: {}", ch.t0_s, ch.t1_s, r.message);
    if (!r.covariance_ok)
      spdlog::error("chunk [{}, {}] s: no covariance ({}); its rows carry NaN, which readers of estimate.csv skip",
                    ch.t0_s, ch.t1_s, r.message);
  }
  y << YAML::EndSeq << YAML::EndMap;
  writeFileAtomically((fs::path(c.run) / "smoother.yaml").string(),
                      [&](std::ostream& f) { f << y.c_str() << "\n"; });
  spdlog::info("wrote {} ({} poses)", out, sm.poses.size());
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return cliMain<SmoothCli>(argc, argv, "meshnav_smooth", kDescription, declareOptions,
                            [](const Cli&, SmoothCli& c) { return run(c); });
}
