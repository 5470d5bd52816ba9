#include "estimator/uwb/range_model.h"

namespace meshnav::estimator {
namespace {

/// The UWB stamps' delay against the IMU clock δ_u [s]: the ClockOffsetKind state (one per
/// estimator) when there is one, else setup's constant.
struct ClockOffset {
  double delay_s = 0.0;
  std::optional<SensorId> state_id;
};

ClockOffset clockOffset(const NominalState& x, const UwbNetwork& net) {
  const auto& c = x.values<ClockOffsetKind>();
  if (!c.empty()) return {c.begin()->second, c.begin()->first};
  return {net.clockOffsetPrior_s(), std::nullopt};
}

/// One end of a range: where it is and how it depends on the state.
struct End {
  enum class Kind { Tag, StateAnchor, ExactAnchor } kind = Kind::ExactAnchor;
  SensorId id = 0;
  Eigen::Vector3d p_inG = Eigen::Vector3d::Zero();
  const Eigen::Vector3d* p_TinI = nullptr;  // tags only
  /// Tags only: the lever arm as it stood δ_u earlier, l = p_TinI − δ_u [ω̂]× p_TinI (ω̂ = ω − b_ω),
  /// and the tag's velocity v_T = v_IinG + R_ItoG (ω̂ × p_TinI) in G [m/s].
  Eigen::Vector3d lever_then = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_TinG = Eigen::Vector3d::Zero();
};

std::optional<End> resolve(SensorId id, const RangeMeasurement& z, const NominalState& x, const UwbNetwork& net,
                           double delay_s) {
  End e;
  e.id = id;
  if (const Eigen::Vector3d* lever = net.tagLeverArm(id)) {
    // The tag where it was when the range was measured, δ_u before its stamp (first order in δ_u).
    const Eigen::Vector3d omega = z.omega_IinI_rad_s - x.imu.bias_gyro_rad_s;
    e.kind = End::Kind::Tag;
    e.p_TinI = lever;
    e.lever_then = *lever - delay_s * omega.cross(*lever);
    e.v_TinG = x.imu.v_IinG + x.imu.q_ItoG * omega.cross(*lever);
    e.p_inG = x.imu.p_IinG - delay_s * x.imu.v_IinG + x.imu.q_ItoG * e.lever_then;
    return e;
  }
  const auto& anchors = x.values<AnchorKind>();
  if (auto it = anchors.find(id); it != anchors.end()) {
    e.kind = End::Kind::StateAnchor;
    e.p_inG = it->second.p_AinG;
    return e;
  }
  if (const Eigen::Vector3d* p = net.exactAnchor(id)) {
    e.kind = End::Kind::ExactAnchor;
    e.p_inG = *p;
    return e;
  }
  return std::nullopt;
}

/// Where the estimated γ of the pair (a, b) lives: the instance that holds it and its row in that
/// instance's error state. An estimated anchor's own γ towards the other end comes first (the
/// newest knowledge of the pair: its calibration), then a tag's γ towards the other end.
struct GammaState {
  SensorId owner = 0;
  int row = 0;          ///< row in the owner's error state
  bool anchor = false;  ///< owner is an anchor instance (rows 3..), else a tag instance
  double value = 0.0;
};

std::optional<GammaState> gammaState(SensorId a, SensorId b, const NominalState& x) {
  for (auto [owner, peer] : {std::make_pair(a, b), std::make_pair(b, a)}) {
    auto it = x.values<AnchorKind>().find(owner);
    if (it == x.values<AnchorKind>().end()) continue;
    const int i = it->second.biases.index(peer);
    if (i >= 0) return GammaState{owner, 3 + i, true, it->second.biases.gamma_m(i)};
  }
  for (auto [tag, peer] : {std::make_pair(a, b), std::make_pair(b, a)}) {
    auto it = x.values<TagBiasKind>().find(tag);
    if (it == x.values<TagBiasKind>().end()) continue;
    const int i = it->second.index(peer);
    if (i >= 0) return GammaState{tag, i, false, it->second.gamma_m(i)};
  }
  return std::nullopt;
}

/// γ of the pair: the estimated one if it is a state, else the dictionary's.
double pairGamma(const PairBias& pb, const std::optional<GammaState>& gs) { return gs ? gs->value : pb.gamma_m; }

/// Error-state dimension of an estimated anchor (3 + its γ states).
int anchorDim(SensorId id, const NominalState& x) {
  return 3 + static_cast<int>(x.values<AnchorKind>().at(id).biases.peers.size());
}

}  // namespace

RangeModel::Status RangeModel::classify(const RangeMeasurement& z, const NominalState& x, const UwbNetwork& net) {
  auto endKind = [&](SensorId id) -> std::optional<End::Kind> {
    if (net.isTag(id)) return End::Kind::Tag;
    if (x.values<AnchorKind>().count(id)) return End::Kind::StateAnchor;
    if (net.exactAnchor(id)) return End::Kind::ExactAnchor;
    return std::nullopt;
  };
  const auto a = endKind(z.a), b = endKind(z.b);
  if (!a || !b) return Status::UnknownId;
  if (*a == End::Kind::Tag && *b == End::Kind::Tag) return Status::TagTag;
  if (*a == End::Kind::ExactAnchor && *b == End::Kind::ExactAnchor) return Status::NoState;
  return Status::Ok;
}

std::optional<std::pair<double, double>> RangeModel::predict(const RangeMeasurement& z, const NominalState& x,
                                                             const UwbNetwork& net) {
  const double delay_s = clockOffset(x, net).delay_s;
  const auto a = resolve(z.a, z, x, net, delay_s), b = resolve(z.b, z, x, net, delay_s);
  if (!a || !b) return std::nullopt;
  const PairBias pb = net.pairBias(z.a, z.b);
  const double d = (b->p_inG - a->p_inG).norm();
  return std::make_pair(pb.beta * d + pairGamma(pb, gammaState(z.a, z.b, x)), d);
}

RangeModel::Status RangeModel::linearize(const RangeMeasurement& z, const NominalState& x, const UwbNetwork& net,
                                         Linearization* out) {
  const ClockOffset clock = clockOffset(x, net);
  auto a = resolve(z.a, z, x, net, clock.delay_s), b = resolve(z.b, z, x, net, clock.delay_s);
  if (!a || !b) return Status::UnknownId;
  if (a->kind == End::Kind::Tag && b->kind == End::Kind::Tag) return Status::TagTag;
  if (a->kind == End::Kind::ExactAnchor && b->kind == End::Kind::ExactAnchor) return Status::NoState;
  // Order the ends so that a tag, if any, is the near end.
  if (b->kind == End::Kind::Tag) std::swap(a, b);
  const Eigen::Vector3d delta = b->p_inG - a->p_inG;
  const double d = delta.norm();
  if (d < 1e-6) return Status::Degenerate;
  const Eigen::RowVector3d u = (delta / d).transpose();
  const PairBias pb = net.pairBias(z.a, z.b);
  const double sigma = net.rangeSigma(z.a, z.b, z.R_m2);
  const auto gs = gammaState(z.a, z.b, x);
  // An estimated γ carries its uncertainty in the state; a dictionary γ inflates the noise.
  const double var_gamma = gs ? 0.0 : pb.sigma_gamma_m * pb.sigma_gamma_m;

  Linearization& lin = *out;
  lin.blocks.clear();
  lin.residual = Eigen::VectorXd::Constant(1, z.z_m - (pb.beta * d + pairGamma(pb, gs)));
  lin.R = Eigen::MatrixXd::Constant(1, 1, sigma * sigma + var_gamma + d * d * pb.sigma_beta * pb.sigma_beta);
  if (a->kind == End::Kind::Tag) {
    // p_T = p_IinG − δ_u v_IinG + R_ItoG (p_TinI − δ_u [ω − b_ω]× p_TinI), ∂h/∂p_T = −β uᵀ.
    const Eigen::Matrix3d R_ItoG = x.imu.q_ItoG.toRotationMatrix();
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(1, ImuErr::kDim);
    H.block<1, 3>(0, ImuErr::kP) = -pb.beta * u;
    H.block<1, 3>(0, ImuErr::kV) = pb.beta * clock.delay_s * u;
    H.block<1, 3>(0, ImuErr::kTheta) = pb.beta * u * R_ItoG * so3::skew(a->lever_then);
    H.block<1, 3>(0, ImuErr::kBg) = pb.beta * clock.delay_s * u * R_ItoG * so3::skew(*a->p_TinI);
    lin.blocks.push_back({x.imu_id, std::move(H)});
    if (clock.state_id)  // ∂h/∂δ_u = β uᵀ v_T: the tag was −δ_u v_T from where the stamp puts it
      lin.blocks.push_back({*clock.state_id, Eigen::MatrixXd::Constant(1, 1, pb.beta * u.dot(a->v_TinG.transpose()))});
  }
  // An estimated anchor's block: ±β uᵀ on its position, zero on its γ states (but the pair's).
  auto anchorBlock = [&](SensorId id, double sign) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(1, anchorDim(id, x));
    H.leftCols<3>() = sign * pb.beta * u;
    if (gs && gs->anchor && gs->owner == id) H(0, gs->row) = 1.0;  // ∂z/∂δγ = 1
    lin.blocks.push_back({id, std::move(H)});
  };
  if (a->kind == End::Kind::StateAnchor) anchorBlock(a->id, -1.0);
  if (b->kind == End::Kind::StateAnchor) anchorBlock(b->id, 1.0);
  if (gs && !gs->anchor) {  // a tag's γ: ∂z/∂δγ = 1
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(1, x.values<TagBiasKind>().at(gs->owner).gamma_m.size());
    H(0, gs->row) = 1.0;
    lin.blocks.push_back({gs->owner, std::move(H)});
  }
  return Status::Ok;
}

const char* RangeModel::statusName(Status s) {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::UnknownId: return "unknown_id";
    case Status::NoState: return "range_no_state";
    case Status::TagTag: return "range_tag_tag";
    case Status::Degenerate: return "range_degenerate";
  }
  return "?";
}

}  // namespace meshnav::estimator
