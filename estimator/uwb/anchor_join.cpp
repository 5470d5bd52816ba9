/// @file anchor_join.cpp
/// @brief AnchorJoin: a calibrated anchor into the filter (anchor_join.h).

#include "estimator/uwb/anchor_join.h"

#include <spdlog/spdlog.h>

#include "estimator/filter/joint_set_bound.h"

namespace meshnav::estimator {

AnchorJoin::AnchorJoin(const UwbOptions& options, bool dah, const SystemSetup& setup, Diagnostics& diag)
    : options_(options), dah_(dah), setup_(setup), diag_(diag) {}

std::string AnchorJoin::apply(const AnchorInit& a, FusionStrategy& f, std::shared_ptr<const UwbNetwork>& network,
                              bool log) {
  auto net = std::make_shared<UwbNetwork>(*network);
  // An id holds one instance: a tag's, the IMU's, the baro's, or a height bias already added.
  const bool height = f.state().values<HeightBiasKind>().count(a.id) > 0;
  if (net->isTag(a.id)) return " is a tag";
  if (setup_.isSensorInstanceId(a.id) || height)
    return " is the IMU's, the baro's, the UWB clock's or the height sensor's (imu_id, baro_id, uwb_clock_id, "
           "height_id in setup.yaml)";
  net->removeDevice(a.id);  // an exactly known anchor becomes an estimated one
  net->setCalibrated(a.id, true);
  for (PairBias b : a.biases) {
    if (b.a != a.id && b.b != a.id) b.b = a.id;
    net->setPairBias(b);
  }
  network = std::move(net);
  // The anchor's γ with an uncertainty become states after its position (issue 10), with the
  // calibration's joint covariance: a γ error and the position error along that reference's
  // direction are strongly correlated, and fixing γ would let repeated ranges average away an
  // error that is constant.
  BiasState biases;
  std::vector<Eigen::Index> rows = {0, 1, 2};  // rows of the joint [p, γ_1..γ_n] kept
  std::vector<double> gamma;
  if (options_.estimate_anchor_biases) {
    for (size_t i = 0; i < a.biases.size(); ++i) {
      const PairBias& b = a.biases[i];
      const SensorId peer = b.a == a.id ? b.b : b.a;
      if (peer == a.id || b.sigma_gamma_m <= 0.0 || biases.index(peer) >= 0) continue;
      biases.peers.push_back(peer);
      gamma.push_back(b.gamma_m);
      rows.push_back(3 + static_cast<Eigen::Index>(i));
    }
  }
  biases.gamma_m = Eigen::Map<const Eigen::VectorXd>(gamma.data(), static_cast<Eigen::Index>(gamma.size()));
  AnchorInit marginal = a;
  if (!options_.anchor_bias_joint_covariance) marginal.cov_gamma_p_m2.resize(0, 0), marginal.cov_gamma_m2.resize(0, 0);
  const Eigen::MatrixXd J = marginal.jointCovariance();
  Eigen::MatrixXd cov(rows.size(), rows.size());
  for (size_t r = 0; r < rows.size(); ++r)
    for (size_t c = 0; c < rows.size(); ++c) cov(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = J(rows[r], rows[c]);
  f.addInstance<AnchorKind>(a.id, AnchorState{a.p_AinG, biases}, cov);
  joinSet(a.id, f, *network);
  if (log) {
    diag_.count("anchor_init");
    spdlog::info("estimator: anchor {} added at t={} p_AinG=[{:.3f}, {:.3f}, {:.3f}] with {} pair biases, {} as states{}",
                 a.id, formatSeconds(a.t), a.p_AinG.x(), a.p_AinG.y(), a.p_AinG.z(), a.biases.size(),
                 biases.peers.size(),
                 biases.peers.empty() ? ""
                 : a.hasJointCovariance() && options_.anchor_bias_joint_covariance ? " (joint covariance)"
                                                                                        : " (independent of the position)");
  }
  return "";
}

void AnchorJoin::joinSet(SensorId id, FusionStrategy& f, const UwbNetwork& network) {
  const std::string& mode = options_.dah_joint_anchors;
  if (!dah_ || mode == "none") return;
  const Timestamp t = f.state().t;
  if (!batch_t_ || *batch_t_ != t) batch_.clear();
  batch_t_ = t;
  batch_.push_back(id);
  std::vector<SensorId> set = batch_;
  if (mode == "all")
    for (const auto& [other, value] : f.state().values<AnchorKind>())
      if (network.isCalibrated(other)) set.push_back(other);
  if (options_.dah_joint_tag_biases)  // merges every batch into one set with the tags' γ
    for (const auto& [tag, value] : f.state().values<TagBiasKind>()) set.push_back(tag);
  if (options_.dah_joint_imu) {
    // With the IMU the biases of its vertical aids (baro, height sensor) and the UWB clock's offset:
    // a range correlates them with every member through the pose, and left outside they would keep
    // each member's DAH correction (and its cost) on every update of the set.
    set.push_back(f.state().imu_id);
    for (const auto& [baro, value] : f.state().values<BaroBiasKind>()) set.push_back(baro);
    for (const auto& [height, value] : f.state().values<HeightBiasKind>()) set.push_back(height);
    for (const auto& [clock, value] : f.state().values<ClockOffsetKind>()) set.push_back(clock);
  }
  f.joinJointSet(set);
  boundJointSetAnchors(f, id, options_.dah_joint_max_anchors);
}

}  // namespace meshnav::estimator
