/// @file meshnav_range_stats.cpp
/// @brief Range error statistics per ordered pair (constant bias, noise std), as the paper's range
/// evaluation toolbox computes them, on the real recording or on a simulated dataset.

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/atomic_file.h"
#include "common/cli_main.h"
#include "common/dataset.h"
#include "common/setup.h"
#include "eval/plotting.h"
#include "eval/range_dataset.h"
#include "eval/range_statistics.h"
#include "eval/reference_statistics.h"
#include "eval/report.h"

namespace fs = std::filesystem;
using namespace meshnav;
using namespace meshnav::eval;

namespace {

/// The command line of meshnav_range_stats (RangeStatsOptions holds the defaults).
struct RangeStatsCli {
  RangeStatsOptions stats;
  std::string dataset, reference, method, yaml, plots;
  double max_dt_s = 0.05;
};

void declareOptions(Cli& cli, RangeStatsCli& c) {
  cli.optional("dataset", c.dataset,
               "a recording like shared/data/real-t1-a3-loiter (*_ranges.csv measured, true_ranges*.csv true "
               "tag-to-anchor distances, config.yaml abs_anchor_positions, optional reference_statistics.yaml), or a "
               "meshnav dataset (ranges.csv, groundtruth.csv, setup.yaml tag lever arms, truth.yaml all anchors and "
               "true pair biases)")
      ->type_name("DIR")
      ->required();
  cli.optional("reference", c.reference, "toolbox statistics to compare with (default DIR/reference_statistics.yaml)")
      ->type_name("FILE");
  cli.optional("method", c.method,
               "histogram: the toolbox's filtered histogram (reproduces its tables; its sigma is about half the true "
               "sigma for Gaussian noise); clip: median/MAD start, iterated 3 sigma clipping (recovers a simulated "
               "gamma, sigma_d); gate: plain mean/std after the gate. Default: histogram when a reference is "
               "compared, else clip")
      ->type_name("NAME")
      ->check(CLI::IsMember({"histogram", "clip", "gate"}));
  cli.option("max-error", c.stats.max_error_m, "gross outlier gate |z - d| <= M [m]")
      ->type_name("M")->check(cli::positive());
  cli.option("bins", c.stats.histogram_bins, "histogram bins")->type_name("N")->check(CLI::Range(1, 100000));
  cli.option("inlier-fraction", c.stats.inlier_fraction, "assumed inlier fraction of the histogram filter")
      ->type_name("F")->check(CLI::Range(0.0, 1.0));
  cli.option("max-dt", c.max_dt_s, "largest time difference to the nearest true range sample [s]")
      ->type_name("S")->check(cli::positive());
  cli.optional("yaml", c.yaml, "write the statistics as YAML")->type_name("FILE");
  cli.optional("plots", c.plots, "write range_errors.csv and one error histogram PNG per pair into DIR")
      ->type_name("DIR");
  cli.app().footer(
      "Bias convention: gamma = mean(z - d), measured minus true (range model z = beta d + gamma). The toolbox's "
      "reference table holds the opposite sign (d - z); it is converted for the comparison.");
}

void writeStatsYaml(const std::map<std::pair<SensorId, SensorId>, PairRangeStats>& stats,
                    const RangeStatsOptions& o, const std::string& path) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "method" << YAML::Value
      << (o.method == BiasMethod::Histogram ? "histogram" : o.method == BiasMethod::Clip ? "clip" : "gate");
  out << YAML::Key << "max_error_m" << YAML::Value << o.max_error_m;
  out << YAML::Key << "convention" << YAML::Value << "bias = mean(measured - true) [m]";
  out << YAML::Key << "pairs" << YAML::Value << YAML::BeginSeq;
  for (const auto& [key, s] : stats) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "id1" << YAML::Value << s.id1 << YAML::Key << "id2" << YAML::Value << s.id2;
    out << YAML::Key << "n_ranges" << YAML::Value << s.n_ranges;
    out << YAML::Key << "n_with_truth" << YAML::Value << s.n_with_truth;
    out << YAML::Key << "n_used" << YAML::Value << s.estimate.n_used;
    out << YAML::Key << "bias_m" << YAML::Value << formatNumber(s.estimate.bias_m, 4);
    out << YAML::Key << "std_m" << YAML::Value << formatNumber(s.estimate.std_m, 4);
    out << YAML::Key << "window_m" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << formatNumber(s.estimate.lower_m, 4) << formatNumber(s.estimate.upper_m, 4) << YAML::EndSeq;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  writeFileAtomically(path, [&](std::ostream& f) { f << out.c_str() << "\n"; });
}

int run(const RangeStatsCli& cli) {
  const fs::path dir = cli.dataset;
  if (!fs::is_directory(dir)) {
    spdlog::error("{} is not a directory", dir.string());
    return 1;
  }
  RangeStatsOptions opt = cli.stats;
  const std::string ref_path =
      !cli.reference.empty() ? cli.reference
                             : (fs::exists(dir / "reference_statistics.yaml") ? (dir / "reference_statistics.yaml").string()
                                                                               : "");
  const std::string method = !cli.method.empty() ? cli.method : ref_path.empty() ? "clip" : "histogram";
  opt.method = method == "histogram" ? BiasMethod::Histogram : method == "gate" ? BiasMethod::Gate : BiasMethod::Clip;

  Diagnostics diag;
  diag.max_logged_per_kind = 2;  // real recordings hold hundreds of absurd ranges; all are counted
  RangeEvaluationInput in = loadRangeEvaluationInput(dir.string(), diag, cli.max_dt_s);
  const auto& ranges = in.ranges;
  const auto& truth = in.truth;
  const auto& truth_pairs = in.truth_pairs;
  spdlog::info("{}: {} ranges", in.kind, ranges.size());

  const auto stats = computeRangeStatistics(ranges, truth, opt, diag);
  std::map<std::pair<SensorId, SensorId>, ReferencePairStats> reference;
  if (!ref_path.empty()) {
    try {
      reference = readReferenceStatistics(ref_path);
    } catch (const std::exception& ex) {
      spdlog::warn("reference not used: {}", ex.what());
    }
  }

  std::cout << "\nRange errors e = z − d per ordered pair (" << method << " method, gate |e| ≤ "
            << formatNumber(opt.max_error_m, 2) << " m)\n\n"
            << makeRangeStatsTable(stats, reference, truth_pairs).plain();
  if (!reference.empty()) {
    double max_db = 0.0, max_ds = 0.0;
    for (const auto& [key, s] : stats)
      if (auto it = reference.find(key); it != reference.end()) {
        max_db = std::max(max_db, std::abs(s.estimate.bias_m - it->second.toGamma()));
        max_ds = std::max(max_ds, std::abs(s.estimate.std_m - it->second.noise_m));
      }
    std::cout << "\nreference " << ref_path << " (its bias table holds d − z; shown as γ = −table)\n"
              << "max |Δγ| = " << formatNumber(max_db, 3) << " m, max |Δσ| = " << formatNumber(max_ds, 3)
              << " m (reference rounded to 0.01 m)\n";
  }
  const std::string d = diag.summary();
  if (!d.empty()) std::cout << "input diagnostics: " << d << "\n";

  if (!cli.yaml.empty()) {
    writeStatsYaml(stats, opt, cli.yaml);
    spdlog::info("wrote {}", cli.yaml);
  }
  if (!cli.plots.empty()) {
    const fs::path out = cli.plots;
    fs::create_directories(out);
    const fs::path csv = out / "range_errors.csv";
    writeFileAtomically(csv.string(), [&](std::ostream& f) {
      f << "id1,id2,t,error_m,bias_m,std_m,lower_m,upper_m\n";
      f.setf(std::ios::fixed);
      f.precision(6);
      for (const auto& [key, s] : stats)
        for (size_t i = 0; i < s.errors_m.size(); ++i)
          f << s.id1 << "," << s.id2 << "," << s.t_s[i] << "," << s.errors_m[i] << "," << s.estimate.bias_m << ","
            << s.estimate.std_m << "," << s.estimate.lower_m << "," << s.estimate.upper_m << "\n";
    });
    if (runPlotScript("plot_range_hist.py",
                      {"--errors", csv.string(), "--out", out.string(), "--max-error", formatNumber(opt.max_error_m, 3)}))
      spdlog::info("histograms written to {}", out.string());
  }
  return stats.empty() ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  return cliMain<RangeStatsCli>(argc, argv, "meshnav_range_stats",
                                "Per ordered pair range bias and noise against true distances.", declareOptions,
                                [](const Cli&, RangeStatsCli& c) { return run(c); });
}
