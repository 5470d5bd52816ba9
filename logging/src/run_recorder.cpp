#include "logging/run_recorder.h"

#include "common/atomic_file.h"

#include "common/anchor_init_io.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/dataset.h"
#include "logging/torn_tail.h"

namespace meshnav::logging {
namespace fs = std::filesystem;

namespace {

void writeYaml(const YAML::Emitter& e, const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& out) { out << e.c_str() << "\n"; });
}

}  // namespace

RunRecorder::RunRecorder(const std::string& out_dir, bool append) : out_dir_(out_dir), append_(append) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir + ": cannot create folder: " + ec.message());
  if (append) {
    for (const char* name : {"estimate.csv", "anchors.csv"}) {
      const std::string path = (fs::path(out_dir) / name).string();
      if (const int64_t cut = cutTornLine(path); cut > 0)
        diag_.report(std::string(name) + ":torn_row_cut",
                     fmt::format("{}: cut a half-written last row of {} bytes (the previous logger was killed "
                                 "while writing it)",
                                 path, cut));
    }
  }
  // A fresh run: an earlier run's smoothed file would be scored as this one's if no POSE_SMOOTHED
  // comes (lag 0, never initialized).
  if (!append) fs::remove(fs::path(out_dir) / "estimate_smoothed.csv", ec);
  estimate_ = std::make_unique<EstimateCsvWriter>((fs::path(out_dir) / "estimate.csv").string(), append);
  anchors_ = std::make_unique<AnchorsCsvWriter>((fs::path(out_dir) / "anchors.csv").string(), append);
  const fs::path inits = fs::path(out_dir) / "anchor_init.yaml";
  if (append && fs::exists(inits)) anchor_inits_ = readAnchorInitsYaml(inits.string());
}

RunRecorder::~RunRecorder() = default;

void RunRecorder::countMessage(const std::string& channel, int64_t bytes, int64_t wall_utime) {
  auto& c = channels_[channel];
  if (c.messages == 0) c.first_wall_utime = wall_utime;
  ++c.messages;
  c.bytes += bytes;
  c.last_wall_utime = wall_utime;
}

void RunRecorder::onPose(const PoseEstimate& e) {
  estimate_->write(e);
  ++n_poses_;
}

void RunRecorder::onPoseSmoothed(const PoseEstimate& e) {
  if (!smoothed_) {
    const std::string path = (fs::path(out_dir_) / "estimate_smoothed.csv").string();
    const bool append = append_ && fs::exists(path);
    if (append)
      if (const int64_t cut = cutTornLine(path); cut > 0)
        diag_.report("estimate_smoothed.csv:torn_row_cut",
                     fmt::format("{}: cut a half-written last row of {} bytes (the previous logger was killed "
                                 "while writing it)",
                                 path, cut));
    smoothed_ = std::make_unique<EstimateCsvWriter>(path, append);
  }
  smoothed_->write(e);
  ++n_smoothed_;
}

void RunRecorder::onAnchors(const std::vector<AnchorEstimate>& anchors) {
  for (const auto& a : anchors) {
    anchors_->write(a);
    ++n_anchor_rows_;
  }
}

void RunRecorder::onAnchorInit(const AnchorInit& a) {
  anchor_inits_.push_back(a);
  // Through a temporary renamed over it (common/atomic_file.h): whenever the logger is killed, the
  // file holds every ANCHOR_INIT of the previous rewrite or of this one, never half of it.
  writeAnchorInitsYaml(anchor_inits_, (fs::path(out_dir_) / "anchor_init.yaml").string());
}

void RunRecorder::onGroundTruth(const PoseSample& p) { ground_truth_.push_back(p); }

void RunRecorder::flush() {
  estimate_->flush();
  if (smoothed_) smoothed_->flush();
  anchors_->flush();
}

void RunRecorder::finish(const Diagnostics& process_diag) {
  if (finished_) return;
  finished_ = true;
  flush();
  const fs::path dir(out_dir_);

  if (!anchor_inits_.empty()) writeAnchorInitsYaml(anchor_inits_, (dir / "anchor_init.yaml").string());
  if (!ground_truth_.empty()) writeTumCsv(ground_truth_, (dir / "groundtruth.csv").string());

  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "channels" << YAML::Value << YAML::BeginMap;
  for (const auto& [name, c] : channels_) {
    const double span = (c.last_wall_utime - c.first_wall_utime) * 1e-6;
    e << YAML::Key << name << YAML::Value << YAML::Flow << YAML::BeginMap;
    e << YAML::Key << "messages" << YAML::Value << c.messages;
    e << YAML::Key << "bytes" << YAML::Value << c.bytes;
    e << YAML::Key << "rate_hz" << YAML::Value << (span > 0 ? (c.messages - 1) / span : 0.0);
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  e << YAML::Key << "files" << YAML::Value << YAML::Flow << YAML::BeginMap;
  e << YAML::Key << "estimate_rows" << YAML::Value << n_poses_;
  e << YAML::Key << "estimate_smoothed_rows" << YAML::Value << n_smoothed_;
  e << YAML::Key << "anchor_rows" << YAML::Value << n_anchor_rows_;
  e << YAML::Key << "anchor_inits" << YAML::Value << anchor_inits_.size();
  e << YAML::Key << "ground_truth_rows" << YAML::Value << ground_truth_.size();
  e << YAML::EndMap;
  if (last_estimator_status_) {
    const auto& s = *last_estimator_status_;
    e << YAML::Key << "estimator_status" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "t" << YAML::Value << s.t.sec();
    e << YAML::Key << "initialized" << YAML::Value << s.initialized;
    e << YAML::Key << "strategy" << YAML::Value << s.strategy;
    e << YAML::Key << "health" << YAML::Value << s.health;
    e << YAML::Key << "uwb_clock_offset_s" << YAML::Comment("UWB stamps' delay against the IMU clock")
      << YAML::Value << s.uwb_clock_offset_s;
    e << YAML::Key << "uwb_clock_offset_sigma_s" << YAML::Comment("0: setup.yaml's constant") << YAML::Value
      << s.uwb_clock_offset_sigma_s;
    e << YAML::Key << "counters" << YAML::Value << YAML::BeginMap;
    for (const auto& [k, v] : s.counters) e << YAML::Key << k << YAML::Value << v;
    e << YAML::EndMap;
    e << YAML::Key << "mean_step_us" << YAML::Value << YAML::BeginMap;
    for (const auto& [k, v] : s.mean_step_us) e << YAML::Key << k << YAML::Value << v;
    e << YAML::EndMap;
    e << YAML::Key << "instances" << YAML::Value << YAML::BeginSeq;
    for (const auto& i : s.instances) {
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "id" << YAML::Value << i.id << YAML::Key << "type"
        << YAML::Value << i.type << YAML::Key << "n_updates" << YAML::Value << i.n_updates << YAML::Key
        << "n_rejected" << YAML::Value << i.n_rejected << YAML::EndMap;
    }
    e << YAML::EndSeq << YAML::EndMap;
  }
  if (last_calib_status_) {
    const auto& s = *last_calib_status_;
    e << YAML::Key << "calib_status" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "t" << YAML::Value << s.t.sec();
    e << YAML::Key << "anchors" << YAML::Value << YAML::BeginSeq;
    for (const auto& a : s.anchors) {
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "id" << YAML::Value << a.id << YAML::Key << "state"
        << YAML::Value << a.state << YAML::Key << "n_ranges" << YAML::Value << a.n_ranges << YAML::Key << "n_refs"
        << YAML::Value << a.n_refs << YAML::Key << "reason" << YAML::Value << a.reason << YAML::EndMap;
    }
    e << YAML::EndSeq;
    e << YAML::Key << "counters" << YAML::Value << YAML::BeginMap;
    for (const auto& [k, v] : s.counters) e << YAML::Key << k << YAML::Value << v;
    e << YAML::EndMap << YAML::EndMap;
  }
  if (last_mission_status_) {
    const auto& s = *last_mission_status_;
    e << YAML::Key << "mission_status" << YAML::Value << YAML::Flow << YAML::BeginMap;
    e << YAML::Key << "t" << YAML::Value << s.t.sec();
    e << YAML::Key << "step_index" << YAML::Value << s.step_index;
    e << YAML::Key << "n_steps" << YAML::Value << s.n_steps;
    e << YAML::Key << "text" << YAML::Value << s.text;
    e << YAML::EndMap;
  }
  e << YAML::Key << "logger_counters" << YAML::Value << YAML::BeginMap;
  Diagnostics counters;
  counters.merge(process_diag);
  counters.merge(diag_);
  for (const auto& [k, v] : counters.snapshot()) e << YAML::Key << k << YAML::Value << v;
  e << YAML::EndMap;
  e << YAML::EndMap;
  writeYaml(e, (dir / "summary.yaml").string());
}

std::string RunRecorder::summaryText() const {
  std::ostringstream s;
  s << "recorded into " << out_dir_ << ": " << n_poses_ << " poses, " << n_anchor_rows_ << " anchor rows, "
    << anchor_inits_.size() << " anchor inits\n";
  for (const auto& [name, c] : channels_)
    s << fmt::format("  {:<17} {:>8} msgs {:>11} bytes\n", name, c.messages, c.bytes);
  if (last_estimator_status_) {
    const auto& st = *last_estimator_status_;
    s << "  estimator: t=" << formatSeconds(st.t) << " s, " << (st.initialized ? "initialized" : "NOT initialized")
      << ", strategy " << st.strategy << ", counters:";
    for (const auto& [k, v] : st.counters) s << ' ' << k << '=' << v;
    s << '\n';
  }
  return s.str();
}

}  // namespace meshnav::logging
