// Refusals: a clear status and reason, never an estimate.
#include <gtest/gtest.h>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/synthetic_scene.h"

using namespace meshnav::calib;

namespace {
void expectRefused(const CalibrationResult& r, CalibrationStatus st, const std::string& word) {
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.status, st) << toString(r.status) << ": " << r.reason;
  EXPECT_NE(r.reason.find(word), std::string::npos) << r.reason;
  EXPECT_EQ(r.p_AinG, Eigen::Vector3d::Zero());  // no estimate leaks out
  EXPECT_EQ(r.n_inliers, 0);
}
}  // namespace

TEST(Refusal, TooFewMeasurements) {
  SyntheticSceneConfig cfg;
  cfg.n_ranges = 20;
  const auto sc = makeSyntheticScene(cfg);
  expectRefused(AnchorCalibrator({}).calibrate(106, sc.observations), CalibrationStatus::TooFewMeasurements, "usable ranges");
  expectRefused(AnchorCalibrator({}).calibrate(106, {}), CalibrationStatus::TooFewMeasurements, "usable ranges");
}

TEST(Refusal, TooFewDistinctReferencePositions) {
  // 300 ranges from tags at only 4 places of the spiral.
  SyntheticSceneConfig cfg;
  cfg.sigma_d_m = 0.05;
  auto sc = makeSyntheticScene(cfg);
  std::vector<CalibObservation> obs;
  int k = 0;
  for (const auto& o : sc.observations) {
    if (o.ref_id != 100) continue;
    CalibObservation c = o;
    const auto& src = sc.observations[static_cast<size_t>((k++ % 4) * 60)];
    c.p_RinG = src.p_RinG;
    obs.push_back(c);
    obs.push_back(c);
  }
  ASSERT_GE(obs.size(), 200u);
  expectRefused(AnchorCalibrator({}).calibrate(106, obs), CalibrationStatus::TooFewReferencePositions, "distinct");
}

TEST(Refusal, CollinearReferences) {
  SyntheticSceneConfig cfg;
  cfg.path = SyntheticPath::Line;
  cfg.known_anchors = false;
  cfg.n_ranges = 400;
  // Tags on a straight line with a constant lever arm: both lie on parallel lines, merge to one.
  auto sc = makeSyntheticScene(cfg);
  std::vector<CalibObservation> obs;
  for (const auto& o : sc.observations)
    if (o.ref_id == 100) obs.push_back(o);
  expectRefused(AnchorCalibrator({}).calibrate(106, obs), CalibrationStatus::DegenerateGeometry, "collinear");
}

TEST(Refusal, CoplanarReferences) {
  SyntheticSceneConfig cfg;
  cfg.path = SyntheticPath::Planar;
  const auto sc = makeSyntheticScene(cfg);
  expectRefused(AnchorCalibrator({}).calibrate(106, sc.observations), CalibrationStatus::DegenerateGeometry, "coplanar");
}

TEST(Refusal, OnlyStationaryReferences) {
  SyntheticSceneConfig cfg;
  cfg.path = SyntheticPath::Hover;
  const auto sc = makeSyntheticScene(cfg);
  for (bool ransac : {true, false}) {
    CalibratorOptions o;
    o.ransac = ransac;
    expectRefused(AnchorCalibrator(o).calibrate(106, sc.observations), CalibrationStatus::DegenerateGeometry,
                  "no moving reference");
  }
}

TEST(Refusal, ReferenceWithTooFewRangesIsIgnoredNotFatal) {
  SyntheticSceneConfig cfg;
  auto sc = makeSyntheticScene(cfg);
  auto obs = sc.observations;
  CalibObservation lone = obs.front();
  lone.ref_id = 999;
  obs.push_back(lone);
  const auto r = AnchorCalibrator({}).calibrate(106, obs);
  ASSERT_TRUE(r.ok()) << r.reason;
  for (const auto& ref : r.references) EXPECT_NE(ref.ref_id, 999);
  EXPECT_FALSE(r.inliers.back());
}
