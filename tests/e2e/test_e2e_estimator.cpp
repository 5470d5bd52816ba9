/// End to end: simulate the paper scenario, run meshnav_run (centralized EKF, DP and DAH) and
/// compare estimate.csv with the ground truth: seed 1 with the known anchors 101–104 only, and
/// seed 10 with 106–110 given as known-but-uncertain (σ 0.3 m) and refined online; and a simulated
/// fleet of two vehicles sharing one anchor map (`meshnav_run --fleet`).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "common/dataset.h"
#include "common/estimate_io.h"
#include "tests/support/test_util.h"

using namespace meshnav;
namespace fs = std::filesystem;

namespace {

int run(const std::string& cmd) {
  std::cout << "$ " << cmd << std::endl;
  return std::system(cmd.c_str());
}

struct PoseMetrics {
  double rmse_p_m = 0.0, rmse_q_deg = 0.0, anees_p = 0.0;
  int n = 0;
};

/// `min_flight_s`: the data must cover at least this long (ground truth at 60 Hz, estimate at 200 Hz).
PoseMetrics comparePoses(const std::string& name, const fs::path& data, const fs::path& out, double min_flight_s = 100.0);

/// Simulates `seed` (extra meshnav_sim args), runs meshnav_run (extra args) and compares
/// estimate.csv with the ground truth at every ground-truth sample.
PoseMetrics runSequence(const std::string& name, int seed, const std::string& sim_args, const std::string& run_args) {
  // A private folder (unique name: parallel jobs and checkouts stay apart), removed at the end;
  // MESHNAV_KEEP_TEST_FILES=1 keeps it to look at the logs.
  const meshnav::test::TempDir tmp("e2e_estimator_" + name);
  const fs::path& dir = tmp.path();
  const fs::path data = dir / "data", out = dir / "run";
  EXPECT_EQ(run(std::string(MESHNAV_SIM_BIN) + " --seed " + std::to_string(seed) + " " + sim_args + " --out " +
                data.string() + " > " + (dir / "sim.log").string() + " 2>&1"),
            0);
  EXPECT_EQ(run(std::string(MESHNAV_RUN_BIN) + " " + run_args + " --dataset " + data.string() + " --out " +
                out.string() + " > " + (dir / "run.log").string() + " 2>&1"),
            0);
  return comparePoses(name + ", seed " + std::to_string(seed), data, out);
}

/// Checks that the run folder `out` holds every output and compares its estimate.csv with the
/// ground truth of the dataset folder `data` at every ground-truth sample.
PoseMetrics comparePoses(const std::string& name, const fs::path& data, const fs::path& out, double min_flight_s) {
  for (const char* f : {"estimate.csv", "anchors.csv", "timings.csv", "status.txt"})
    EXPECT_TRUE(fs::exists(out / f)) << f;

  PoseMetrics m;
  Diagnostics diag;
  const auto truth = readTumCsv((data / "groundtruth.csv").string(), diag);
  const auto est = readEstimateCsv((out / "estimate.csv").string(), diag);
  EXPECT_GT(static_cast<double>(truth.size()), 50.0 * min_flight_s);
  EXPECT_GT(static_cast<double>(est.size()), 200.0 * min_flight_s);
  EXPECT_EQ(diag.total(), 0) << diag.summary();
  if (est.empty()) return m;

  // Nearest estimate (IMU rate) to every ground-truth sample.
  double sq_p = 0.0, sq_q = 0.0, nees = 0.0;
  size_t j = 0;
  for (const auto& gt : truth) {
    while (j + 1 < est.size() && est[j + 1].t <= gt.t) ++j;
    size_t k = j;
    if (j + 1 < est.size() && (est[j + 1].t - gt.t).us < (gt.t - est[j].t).us) k = j + 1;
    if (std::abs((est[k].t - gt.t).us) > 5000) continue;
    const Eigen::Vector3d dp = est[k].p_IinG - gt.p_IinG;
    const Eigen::AngleAxisd dq(est[k].q_ItoG.conjugate() * gt.q_ItoG);
    sq_p += dp.squaredNorm();
    sq_q += dq.angle() * dq.angle();
    nees += dp.dot(est[k].cov_p_m2.ldlt().solve(dp));
    ++m.n;
  }
  EXPECT_GT(m.n, 50.0 * min_flight_s);
  if (m.n == 0) return m;
  m.rmse_p_m = std::sqrt(sq_p / m.n);
  m.rmse_q_deg = std::sqrt(sq_q / m.n) * 180.0 / M_PI;
  m.anees_p = nees / m.n;
  std::cout << name << ": position RMSE " << m.rmse_p_m << " m, orientation RMSE " << m.rmse_q_deg
            << " deg, position ANEES " << m.anees_p << " (" << m.n << " samples)" << std::endl;
  return m;
}

void runAndCheck(const std::string& strategy) {
  const PoseMetrics m = runSequence(strategy, 1, "", "--strategy " + strategy);
  EXPECT_LE(m.rmse_p_m, 0.15);
  // The target: orientation RMSE <= 3 deg.
  EXPECT_LE(m.rmse_q_deg, 3.0);
  EXPECT_GE(m.anees_p, 1.0);
  EXPECT_LE(m.anees_p, 6.0);
}

}  // namespace

TEST(EndToEnd, CentralizedEkfOnSimulatedSeed1) { runAndCheck("centralized"); }
TEST(EndToEnd, DpOnSimulatedSeed1) { runAndCheck("dp"); }
TEST(EndToEnd, DahOnSimulatedSeed1) { runAndCheck("dah"); }

// Issue 3's scenario on one sequence: 101–104 exact, 106–110 uncertain (σ 0.3 m), no calibration.
// DP and DAH both accurate and consistent; DAH close to DP. And why DAH leaves ranges between two
// estimated anchors out by default: fusing them (seed 10) makes it overconfident (ANEES 16 measured).
TEST(EndToEnd, UncertainAnchorsDpAndDahOnSimulatedSeed10) {
  const std::string sim = "--uncertain-anchors 0.3", base = "--no-calibration --strategy ";
  const PoseMetrics dp = runSequence("uncertain_dp", 10, sim, base + "dp");
  const PoseMetrics dah = runSequence("uncertain_dah", 10, sim, base + "dah");
  for (const PoseMetrics* m : {&dp, &dah}) {
    EXPECT_LE(m->rmse_p_m, 0.15);
    EXPECT_LE(m->rmse_q_deg, 3.0);
    EXPECT_GE(m->anees_p, 1.0);
    EXPECT_LE(m->anees_p, 6.0);
  }
  EXPECT_LE(dah.rmse_p_m, 1.15 * dp.rmse_p_m);

  // The same DAH run fusing the estimated anchors' mutual ranges.
  const meshnav::test::TempDir tmp("e2e_dah_fuse_pairs");
  const fs::path cfg = tmp / "config.yaml";
  ASSERT_EQ(run(std::string(MESHNAV_RUN_BIN) + " --print-config > " + cfg.string()), 0);
  std::ifstream in(cfg);
  std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "dah_fuse_estimated_anchor_pairs: false";
  const size_t at = yaml.find(key);
  ASSERT_NE(at, std::string::npos);
  yaml.replace(at, key.size(), "dah_fuse_estimated_anchor_pairs: true");
  std::ofstream(cfg) << yaml;
  const PoseMetrics fused = runSequence("uncertain_dah_fused", 10, sim, base + "dah --config " + cfg.string());
  EXPECT_GT(fused.anees_p, 2.0 * dah.anees_p) << "fusing them should be visibly overconfident";
}

// `meshnav_sim --fleet 2` and `meshnav_run --fleet`: two vehicles in one hall among the same
// anchors, one calibrator for both (mission S2: 106–110 calibrated at 80 s and 100 s). Each vehicle
// gets its own run folder with every output, each estimates its pose as well as a single vehicle
// does (the bounds of runAndCheck), and both end up fusing the five calibrated anchors close to
// their true positions. `meshnav_eval --fleet` scores both in one table with their mean, the same
// figures as each vehicle's own evaluation, and refuses a fleet whose vehicle has no run folder. A
// fleet file naming a missing dataset key is refused with file and key.
TEST(EndToEnd, FleetOfTwoSimulatedVehiclesSharesOneAnchorMap) {
  const meshnav::test::TempDir tmp("e2e_fleet");
  const fs::path data = tmp / "data", out = tmp / "run";
  ASSERT_EQ(run(std::string(MESHNAV_SIM_BIN) + " --fleet 2 --seed 2 --out " + data.string() + " > " +
                (tmp / "sim.log").string() + " 2>&1"),
            0);
  ASSERT_TRUE(fs::exists(data / "fleet.yaml"));
  ASSERT_EQ(run(std::string(MESHNAV_RUN_BIN) + " --fleet " + (data / "fleet.yaml").string() + " --mission " +
                MESHNAV_SOURCE_DIR + "/config/missions/paper_s2.yaml --out " + out.string() + " > " +
                (tmp / "run.log").string() + " 2>&1"),
            0);
  EXPECT_TRUE(fs::exists(out / "calibration.yaml"));
  for (const char* v : {"v0", "v1"}) {
    const PoseMetrics m = comparePoses(std::string("fleet vehicle ") + v, data / v, out / v);
    EXPECT_LE(m.rmse_p_m, 0.15) << v;
    EXPECT_LE(m.rmse_q_deg, 3.0) << v;
    EXPECT_GE(m.anees_p, 1.0) << v;
    EXPECT_LE(m.anees_p, 6.0) << v;

    Diagnostics diag;
    const Dataset ds = readDataset((data / v).string(), diag, true);
    ASSERT_TRUE(ds.truth.has_value());
    std::map<SensorId, AnchorEstimate> last;
    for (const auto& a : readAnchorsCsv((out / v / "anchors.csv").string(), diag)) last[a.id] = a;
    EXPECT_EQ(diag.total(), 0) << diag.summary();
    for (SensorId id : {106, 107, 108, 109, 110}) {
      ASSERT_TRUE(last.count(id)) << v << " never fused anchor " << id;
      const double err = (last[id].p_AinG - ds.truth->anchor_positions.at(id)).norm();
      std::cout << v << ": anchor " << id << " final error " << err << " m" << std::endl;
      EXPECT_LE(err, 0.15) << v << " anchor " << id;
    }
  }

  // meshnav_eval --fleet: one row per vehicle (its RMSE as scored above, to the table's 3 decimals)
  // and the mean row; exit 1 when a vehicle's run folder is missing.
  const fs::path eval_log = tmp / "eval_fleet.log";
  ASSERT_EQ(run(std::string(MESHNAV_EVAL_BIN) + " --fleet " + (data / "fleet.yaml").string() + " --run " +
                out.string() + " --no-plots --no-baseline > " + eval_log.string() + " 2>&1"),
            0);
  {
    std::ifstream in(eval_log);
    std::map<std::string, double> rmse;
    for (std::string line; std::getline(in, line);) {
      std::istringstream row(line);
      std::string name;
      double v = 0.0;
      if (row >> name >> v && (name == "v0" || name == "v1" || name == "mean")) rmse[name] = v;
    }
    ASSERT_EQ(rmse.size(), 3u) << "eval --fleet printed no row per vehicle and mean";
    const double r0 = comparePoses("v0", data / "v0", out / "v0").rmse_p_m;
    const double r1 = comparePoses("v1", data / "v1", out / "v1").rmse_p_m;
    EXPECT_NEAR(rmse["v0"], r0, 0.002);
    EXPECT_NEAR(rmse["v1"], r1, 0.002);
    EXPECT_NEAR(rmse["mean"], 0.5 * (r0 + r1), 0.002);
  }
  fs::rename(out / "v1", tmp / "v1_moved");
  EXPECT_NE(run(std::string(MESHNAV_EVAL_BIN) + " --fleet " + (data / "fleet.yaml").string() + " --run " +
                out.string() + " --no-plots --no-baseline > " + eval_log.string() + " 2>&1"),
            0);
  {
    std::ifstream in(eval_log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("vehicle v1"), std::string::npos) << text;
  }
  fs::rename(tmp / "v1_moved", out / "v1");

  const fs::path bad = tmp / "bad_fleet.yaml";
  std::ofstream(bad) << "vehicles:\n  - {name: v0, dataset: data/v0}\n  - {name: v1}\n";
  const fs::path log = tmp / "bad.log";
  EXPECT_NE(run(std::string(MESHNAV_RUN_BIN) + " --fleet " + bad.string() + " --out " + (tmp / "bad").string() +
                " > " + log.string() + " 2>&1"),
            0);
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(bad.string()), std::string::npos) << text;
  EXPECT_NE(text.find("vehicles[1].dataset"), std::string::npos) << text;
}

namespace {

/// Position error RMSE and mean NEES of meshnav_eval's errors.csv rows with t in [t0, t1].
std::pair<double, double> windowErrors(const fs::path& errors_csv, double t0, double t1) {
  std::ifstream in(errors_csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::istringstream h(line);
    for (std::string c; std::getline(h, c, ',');) header.push_back(c);
  }
  const auto col = [&](const std::string& name) {
    return static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const size_t it = col("t"), ie = col("ep_norm_m"), in_ = col("nees_p");
  double se = 0.0, nees = 0.0;
  int n = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::istringstream row(line);
    for (std::string c; std::getline(row, c, ',');) f.push_back(c);
    if (f.size() != header.size()) continue;
    const double t = std::stod(f[it]);
    if (t < t0 || t > t1) continue;
    se += std::pow(std::stod(f[ie]), 2);
    nees += std::stod(f[in_]);
    ++n;
  }
  if (n == 0) return {std::nan(""), std::nan("")};
  return {std::sqrt(se / n), nees / n};
}

}  // namespace

// Inter-vehicle ranges (docs/fleet.md): three vehicles that range to each other at 10 Hz; vehicle
// v1 hears no anchor from 60 s to 80 s. With its neighbours' ranges its error over the outage stays
// within 0.30 m at a consistent NEES; without them (--no-inter-vehicle-ranges) it drifts beyond
// 1 m. The other vehicles are no worse than 0.15 m either way.
TEST(EndToEnd, FleetNeighboursCarryAVehicleThroughAnAnchorOutage) {
  const meshnav::test::TempDir tmp("e2e_fleet_outage");
  const fs::path data = tmp / "data";
  ASSERT_EQ(run(std::string(MESHNAV_SIM_BIN) + " --fleet 3 --seed 1 --inter-vehicle-hz 10 --out " + data.string() +
                " > " + (tmp / "sim.log").string() + " 2>&1"),
            0);
  {  // v1's tag–anchor ranges of 60–80 s removed
    const fs::path ranges = data / "v1" / "ranges.csv";
    std::ifstream in(ranges);
    std::ostringstream kept;
    int removed = 0;
    std::string line;
    std::getline(in, line);
    kept << line << "\n";
    while (std::getline(in, line)) {
      const double t = std::stod(line.substr(0, line.find(',')));
      const bool tag_anchor = line.find(",T,A,") != std::string::npos || line.find(",A,T,") != std::string::npos;
      if (t >= 60.0 && t <= 80.0 && tag_anchor) {
        ++removed;
        continue;
      }
      kept << line << "\n";
    }
    in.close();
    std::ofstream(ranges) << kept.str();
    ASSERT_GT(removed, 500);
  }
  std::map<std::string, std::pair<double, double>> outage;
  for (const std::string mode : {"with", "without"}) {
    const fs::path out = tmp / mode;
    const std::string extra = mode == "without" ? " --no-inter-vehicle-ranges" : "";
    ASSERT_EQ(run(std::string(MESHNAV_RUN_BIN) + " --fleet " + (data / "fleet.yaml").string() + " --mission " +
                  MESHNAV_SOURCE_DIR + "/config/missions/paper_s2.yaml --allow-lost --out " + out.string() + extra +
                  " > " + (tmp / (mode + ".log")).string() + " 2>&1"),
              0)
        << mode;
    ASSERT_EQ(run(std::string(MESHNAV_EVAL_BIN) + " --fleet " + (data / "fleet.yaml").string() + " --run " +
                  out.string() + " --no-plots --no-baseline > " + (tmp / (mode + "_eval.log")).string() + " 2>&1"),
              0)
        << mode;
    outage[mode] = windowErrors(out / "v1" / "errors.csv", 60.0, 80.0);
    std::cout << mode << " inter-vehicle ranges: v1 over the outage RMSE " << outage[mode].first << " m, mean NEES "
              << outage[mode].second << std::endl;
    for (const char* v : {"v0", "v2"}) EXPECT_LE(comparePoses(mode + " " + v, data / v, out / v).rmse_p_m, 0.15) << mode << v;
  }
  EXPECT_LE(outage["with"].first, 0.30);
  EXPECT_LE(outage["with"].second, 6.0);
  EXPECT_GE(outage["without"].first, 1.0) << "the outage should be beyond the filter alone";
}

// Issue 38's outage target among a hundred anchors (docs/fleet.md "Scale"): five vehicles in TDMA
// cells with the frame's peer phase, seed 11; vehicle v0 hears no anchor from 60 s to 80 s. Its
// neighbours carry it: RMSE over the outage <= 0.30 m at a mean NEES <= 6, from >= 100 peer ranges
// fused in it (peer ranges go only from vehicles with anchors to one without:
// docs/decisions/016-fleet-sharing.md); the others stay within 0.12 m.
TEST(EndToEnd, HundredAnchorsOutageNeighboursHoldAVehicleWithoutAnchors) {
  const meshnav::test::TempDir tmp("e2e_scaled_outage");
  const fs::path data = tmp / "data", out = tmp / "run";
  ASSERT_EQ(run(std::string(MESHNAV_SIM_BIN) + " --vehicles 5 --anchors 100 --hall 40,40,10 --seed 11 --outage 0,60,80 --out " +
                data.string() + " > " + (tmp / "sim.log").string() + " 2>&1"),
            0);
  ASSERT_EQ(run(std::string(MESHNAV_RUN_BIN) + " --fleet " + (data / "fleet.yaml").string() + " --mission " +
                (data / "mission.yaml").string() + " --config " + MESHNAV_SOURCE_DIR +
                "/config/fleet_scale.yaml --allow-lost --out " + out.string() + " > " + (tmp / "run.log").string() +
                " 2>&1"),
            0);
  ASSERT_EQ(run(std::string(MESHNAV_EVAL_BIN) + " --fleet " + (data / "fleet.yaml").string() + " --run " + out.string() +
                " --no-plots --no-baseline > " + (tmp / "eval.log").string() + " 2>&1"),
            0);
  const auto [rmse, nees] = windowErrors(out / "v0" / "errors.csv", 60.0, 80.0);
  std::cout << "v0 over its outage: RMSE " << rmse << " m, mean NEES " << nees << std::endl;
  EXPECT_LE(rmse, 0.30);
  EXPECT_LE(nees, 6.0);
  std::ifstream log(tmp / "run.log");
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  const auto at = text.find("inter_vehicle_range_to:v0=");
  ASSERT_NE(at, std::string::npos) << "no peer range fused in v0";
  EXPECT_GE(std::stoi(text.substr(at + std::string("inter_vehicle_range_to:v0=").size())), 100);
  for (const char* v : {"v1", "v2", "v3", "v4"}) EXPECT_LE(comparePoses(v, data / v, out / v).rmse_p_m, 0.12) << v;
}


// A small scaled fleet (docs/scenarios.md "A hundred anchors in TDMA cells"): three vehicles among
// 36 anchors (7 fly-by) in TDMA cells of a 24 x 24 x 8 m hall, 45 s, run as one fleet with the
// generated mission and config/fleet_scale.yaml. Every vehicle ends localized to the paper's
// accuracy, the fly-by anchors are calibrated from the tags of more than one vehicle and every
// vehicle ends with them near the truth.
TEST(EndToEnd, ScaledFleetInTdmaCellsCalibratesFlyByAnchorsFromSeveralVehicles) {
  const meshnav::test::TempDir tmp("e2e_scaled_fleet");
  const fs::path data = tmp / "data", out = tmp / "run";
  ASSERT_EQ(run(std::string(MESHNAV_SIM_BIN) + " --vehicles 3 --anchors 36 --hall 24,24,8 --seed 2 --duration 45 --out " +
                data.string() + " > " + (tmp / "sim.log").string() + " 2>&1"),
            0);
  ASSERT_TRUE(fs::exists(data / "mission.yaml"));
  ASSERT_EQ(run(std::string(MESHNAV_RUN_BIN) + " --fleet " + (data / "fleet.yaml").string() + " --mission " +
                (data / "mission.yaml").string() + " --config " + MESHNAV_SOURCE_DIR + "/config/fleet_scale.yaml --out " +
                out.string() + " > " + (tmp / "run.log").string() + " 2>&1"),
            0);
  // The calibrated anchors and the vehicles whose tags were references (tag id / 1000).
  std::map<SensorId, std::set<int>> from;
  {
    std::ifstream in(out / "calibration.yaml");
    SensorId id = 0;
    for (std::string line; std::getline(in, line);) {
      if (const auto k = line.find("- id: "); k != std::string::npos) id = std::stoi(line.substr(k + 6));
      if (const auto k = line.find("ref_ids: ["); k != std::string::npos) {
        std::istringstream refs(line.substr(k + 10));
        for (std::string r; std::getline(refs, r, ',');) {
          const int ref = std::stoi(r);
          if (ref % 1000 == 100 || ref % 1000 == 105) from[id].insert(ref / 1000);
        }
      }
    }
  }
  EXPECT_GE(from.size(), 5u) << "fly-by anchors calibrated (of 7)";
  int several = 0;
  for (const auto& [id, vehicles] : from) several += vehicles.size() >= 2 ? 1 : 0;
  EXPECT_GE(several, 1) << "no anchor was calibrated from two vehicles' tags";
  for (const char* v : {"v0", "v1", "v2"}) {
    const PoseMetrics m = comparePoses(std::string("scaled fleet vehicle ") + v, data / v, out / v, 40.0);
    EXPECT_LE(m.rmse_p_m, 0.15) << v;
    EXPECT_GE(m.anees_p, 1.0) << v;
    EXPECT_LE(m.anees_p, 6.0) << v;
    Diagnostics diag;
    const Dataset ds = readDataset((data / v).string(), diag, true);
    ASSERT_TRUE(ds.truth.has_value());
    EXPECT_EQ(ds.setup.abs_anchor_positions.size(), 29u);
    std::map<SensorId, AnchorEstimate> last;
    for (const auto& a : readAnchorsCsv((out / v / "anchors.csv").string(), diag)) last[a.id] = a;
    for (const auto& [id, vehicles] : from) {
      ASSERT_TRUE(last.count(id)) << v << " never fused anchor " << id;
      const double err = (last[id].p_AinG - ds.truth->anchor_positions.at(id)).norm();
      std::cout << v << ": anchor " << id << " (from " << vehicles.size() << " vehicles) final error " << err << " m"
                << std::endl;
      EXPECT_LE(err, 0.3) << v << " anchor " << id;
    }
  }
}
