/// view_server: the live web view (docs/view.md). Subscribes POSE, GROUND_TRUTH, ANCHORS, RANGE,
/// ESTIMATOR_STATUS, CALIB_STATUS, MISSION_STATUS and CONTROL_STATUS on LCM (or plays them from `--log FILE`,
/// paced by the log's event times / `--speed`), gathers them in a view::ViewState, and serves the
/// page of view/web/ and its state endpoint over HTTP on `--host` (127.0.0.1) `--port`.
///
/// Endpoints: GET / (the page, view/web/), GET /api/state?pe=&pn=&te=&tn=&re=&rn= (the JSON of
/// ViewState::json for a page holding those track epochs and rows), POST /api/perf (with --perf:
/// the page's frame counts, printed as a `perf:` line on stdout: docs/view.md, "Measured"). On a
/// loopback --host, a request whose Host header is not 127.0.0.1, localhost or [::1] with the port
/// is refused (403): another site's page cannot read the view through DNS rebinding.
///
/// A log is played through an in-process LCM (memq://) into the same typed subscriptions as live
/// data, so a malformed or foreign message in it is decoded, refused and counted the same way.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <thread>

#include "common/setup.h"
#include "controller/process/control_messages.h"
#include "transport/channels.h"
#include "transport/process_main.h"
#include "transport/stop_signal.h"
#include "view/view_state.h"

// Last: it includes <resolv.h>, whose macro `_res` would rename a parameter of Eigen's headers.
#include <httplib.h>

namespace {

using namespace meshnav;

struct ServerOptions {
  std::string host = "127.0.0.1";
  int port = 8037;
  std::string log_path;
  double speed = 1.0;
  std::string setup_path;
  std::string web_dir = MESHNAV_VIEW_WEB_DIR;
  bool perf = false;
};

void declareOptions(Cli& cli, ServerOptions& o) {
  cli.option("host", o.host, "address to serve on (127.0.0.1: this machine only; 0.0.0.0: every network)");
  cli.option("port", o.port, "TCP port (0: any free port; the URL is printed)")->check(CLI::Range(0, 65535));
  cli.optional("log", o.log_path, "play this .lcmlog instead of listening to LCM")->type_name("FILE");
  cli.option("speed", o.speed, "playback speed factor of --log (0: as fast as possible)")->check(cli::nonNegative());
  cli.optional("setup", o.setup_path,
               "setup.yaml: tag lever arms for the range residuals and the known anchors (without it: lever arms 0)")
      ->type_name("FILE");
  cli.option("web", o.web_dir, "folder of the page (index.html, view.js)")->type_name("DIR");
  cli.flag("perf", o.perf, "print the frame reports of a page opened with ?perf=1 (POST /api/perf) as `perf:` lines");
}

/// What a log holds: checked before anything is served, so that a missing, empty or garbled file
/// is refused with its reason.
struct LogSummary {
  int64_t events = 0;
  int64_t first_utime = 0;
  int64_t last_utime = 0;
  std::map<std::string, int64_t> channels;
};

/// The summary of `path`, or an exception saying why it cannot be played.
LogSummary scanLog(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw std::runtime_error("--log " + path + ": no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw std::runtime_error("--log " + path + ": not a regular file");
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("--log " + path + ": cannot be opened for reading");
  LogSummary s;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (s.events == 0) s.first_utime = ev->timestamp;
    s.last_utime = std::max(s.last_utime, ev->timestamp);
    ++s.events;
    ++s.channels[ev->channel];
  }
  if (s.events == 0)
    throw std::runtime_error("--log " + path + ": no LCM event in it (empty, or not an .lcmlog: garbled or another format)");
  return s;
}

/// Every channel the view shows and the ViewState call it goes to. A new channel is one line here
/// (a status channel: ViewState::onStatusFields with its name/value lines).
void subscribeView(transport::LcmNode& lcm, std::mutex& mutex, view::ViewState& view) {
  auto on = [&](auto channel, auto call) {
    lcm.subscribe(channel, [&mutex, &view, call](const auto& msg) {
      std::lock_guard lock(mutex);
      call(view, msg);
    });
  };
  on(channels::kPose, [](view::ViewState& v, const PoseEstimate& m) { v.onPose(m); });
  on(channels::kGroundTruth, [](view::ViewState& v, const PoseSample& m) { v.onGroundTruth(m); });
  on(channels::kAnchors, [](view::ViewState& v, const std::vector<AnchorEstimate>& m) { v.onAnchors(m); });
  on(channels::kRange, [](view::ViewState& v, const RangeSample& m) { v.onRange(m); });
  on(channels::kEstimatorStatus, [](view::ViewState& v, const EstimatorStatus& m) { v.onEstimatorStatus(m); });
  on(channels::kCalibStatus, [](view::ViewState& v, const CalibStatus& m) { v.onCalibStatus(m); });
  on(channels::kMissionStatus, [](view::ViewState& v, const MissionStatus& m) { v.onMissionStatus(m); });
  on(channels::kControlStatus, [](view::ViewState& v, const control_status_t& m) {
    if (controller::invalidReason(m).empty())
      v.onStatusFields("CONTROL_STATUS", Timestamp{m.utime}, controller::statusFields(m));
  });
}

/// Plays `path` into `lcm` (memq://), paced by the events' time stamps divided by `speed` (0: no
/// pacing), until its end or a stop; `progress` gets the fraction of the log's time span played.
void playLog(const std::string& path, const LogSummary& summary, double speed, transport::LcmNode& lcm,
             const std::function<void(double)>& progress) {
  lcm::LogFile log(path, "r");
  const auto wall_start = std::chrono::steady_clock::now();
  const double span_us = std::max<double>(1.0, static_cast<double>(summary.last_utime - summary.first_utime));
  auto last_progress = wall_start;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (transport::StopSignal::requested()) return;
    const double log_us = static_cast<double>(ev->timestamp - summary.first_utime);
    if (speed > 0.0) {
      const auto due = wall_start + std::chrono::microseconds(static_cast<int64_t>(log_us / speed));
      while (std::chrono::steady_clock::now() < due) {
        if (transport::StopSignal::requested()) return;
        std::this_thread::sleep_until(std::min(due, std::chrono::steady_clock::now() + std::chrono::milliseconds(50)));
      }
    }
    lcm.lcm().publish(ev->channel, ev->data, static_cast<unsigned>(ev->datalen));
    while (lcm.spinOnce(0) > 0) {
    }
    if (const auto now = std::chrono::steady_clock::now(); now - last_progress > std::chrono::milliseconds(100)) {
      progress(std::clamp(log_us / span_us, 0.0, 1.0));
      last_progress = now;
    }
  }
  progress(1.0);
}

/// True for an address of this machine only.
bool isLoopback(const std::string& host) { return host == "127.0.0.1" || host == "localhost" || host == "::1"; }

/// Served on a loopback address, a request must name it in its Host header: a page of another site
/// that a browser resolves to 127.0.0.1 (DNS rebinding) is refused.
bool hostAllowed(const httplib::Request& req, int port) {
  const std::string host = req.get_header_value("Host");
  const std::string p = ":" + std::to_string(port);
  return host == "127.0.0.1" + p || host == "localhost" + p || host == "[::1]" + p;
}

/// Reads a non-negative integer query parameter (absent or bad: `fallback`).
int64_t param(const httplib::Request& req, const char* name, int64_t fallback) {
  if (!req.has_param(name)) return fallback;
  try {
    return std::stoll(req.get_param_value(name));
  } catch (const std::exception&) {
    return fallback;
  }
}

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process(
      "view_server",
      "The live web view (docs/view.md): serves a page on http://HOST:PORT/ that shows, live, the estimated path "
      "with its covariance, the truth when it is on the bus, the anchors with their calibration state and "
      "uncertainty ellipses, the estimator's health, per-anchor range residuals and every status channel. Data "
      "from LCM (--lcm-url), or from an .lcmlog played back (--log, --speed). Serves this machine only unless "
      "--host says otherwise.");
  return process.run<ServerOptions>(argc, argv, declareOptions, [&](ServerOptions& o) {
    if (!std::filesystem::is_regular_file(std::filesystem::path(o.web_dir) / "index.html"))
      throw std::runtime_error("--web " + o.web_dir + ": no index.html in it");
    std::optional<LogSummary> summary;
    if (!o.log_path.empty()) summary = scanLog(o.log_path);

    std::mutex mutex;
    view::ViewState view;
    if (!o.setup_path.empty()) view.setSetup(loadSetup(o.setup_path));
    view::ViewSource source;
    source.mode = summary ? "log" : "live";
    source.speed = o.speed;

    // A log plays through an LCM of this process only; live data comes from --lcm-url.
    std::unique_ptr<transport::LcmNode> memq;
    if (summary) memq = std::make_unique<transport::LcmNode>("view_server", "memq://", process.channelPrefix());
    transport::LcmNode& lcm = summary ? *memq : process.lcm();
    source.description = summary ? o.log_path : lcm.url();
    view.setSource(source);
    subscribeView(lcm, mutex, view);

    httplib::Server server;
    if (!server.set_mount_point("/", o.web_dir)) throw std::runtime_error("--web " + o.web_dir + ": cannot be served");
    server.Get("/api/state", [&](const httplib::Request& req, httplib::Response& res) {
      view::ViewCursor c;
      c.path_epoch = param(req, "pe", -1);
      c.path_rows = static_cast<size_t>(std::max<int64_t>(0, param(req, "pn", 0)));
      c.truth_epoch = param(req, "te", -1);
      c.truth_rows = static_cast<size_t>(std::max<int64_t>(0, param(req, "tn", 0)));
      c.residual_epoch = param(req, "re", -1);
      c.residual_rows = static_cast<size_t>(std::max<int64_t>(0, param(req, "rn", 0)));
      std::string body;
      {
        std::lock_guard lock(mutex);
        view.setTransportCounters(lcm.diagnostics().snapshot());
        body = view.json(c);
      }
      res.set_header("Cache-Control", "no-store");
      res.set_content(body, "application/json");
    });
    server.Post("/api/perf", [&](const httplib::Request& req, httplib::Response& res) {
      if (!o.perf) {
        res.status = 404;
        return;
      }
      std::string line = req.body.substr(0, 2000);
      for (char& ch : line)
        if (ch == '\n' || ch == '\r') ch = ' ';
      std::printf("perf: %s\n", line.c_str());
      std::fflush(stdout);
      res.status = 204;
    });
    server.set_payload_max_length(64 * 1024);

    int port = o.port;
    if (port == 0) {
      port = server.bind_to_any_port(o.host);
      if (port < 0) throw std::runtime_error("cannot listen on " + o.host + " (any port)");
    } else if (!server.bind_to_port(o.host, port)) {
      throw std::runtime_error("cannot listen on " + o.host + ":" + std::to_string(port) +
                               " (in use, or not an address of this machine); try --port 0");
    }
    if (isLoopback(o.host)) {
      server.set_pre_routing_handler([port](const httplib::Request& req, httplib::Response& res) {
        if (hostAllowed(req, port)) return httplib::Server::HandlerResponse::Unhandled;
        res.status = 403;
        res.set_content("the view answers requests for 127.0.0.1 or localhost only\n", "text/plain");
        return httplib::Server::HandlerResponse::Handled;
      });
    } else {
      spdlog::warn("serving on {}: the view can be reached from other machines", o.host);
    }
    std::thread http([&] { server.listen_after_bind(); });
    const std::string shown = o.host.find(':') != std::string::npos ? "[" + o.host + "]" : o.host;  // IPv6
    std::printf("view: http://%s:%d/\n", shown.c_str(), port);
    std::fflush(stdout);

    int rc = 0;
    if (summary) {
      spdlog::info("playing {} ({} events, {:.1f} s) at {}x", o.log_path, summary->events,
                   (summary->last_utime - summary->first_utime) * 1e-6, o.speed);
      playLog(o.log_path, *summary, o.speed, lcm, [&](double f) {
        std::lock_guard lock(mutex);
        source.progress = f;
        source.done = f >= 1.0;
        view.setSource(source);
      });
      if (!transport::StopSignal::requested()) {
        std::printf("view: played %s to its end; serving until stopped (Ctrl-C)\n", o.log_path.c_str());
        std::fflush(stdout);
      }
      while (!transport::StopSignal::requested()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    } else {
      spdlog::info("LCM {}; serving the view", lcm.url());
      rc = lcm.spin();
    }
    server.stop();
    http.join();
    {
      std::lock_guard lock(mutex);
      if (const auto c = view.counters(); !c.empty()) spdlog::info("view counters: {}", transport::formatCounters(c));
      if (lcm.diagnostics().total() > 0) spdlog::warn("counters: {}", lcm.diagnostics().summary());
    }
    return rc;
  });
}
