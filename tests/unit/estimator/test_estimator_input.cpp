/// The canonical processing order of the estimator's inputs (estimator/node/estimator_input.h):
/// by time, then by kind in the explicit InputKind table (not the variant's index), then by ids.
/// Out-of-sequence re-processing and every replay rely on it, so it is pinned here.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "estimator/node/estimator_input.h"

namespace meshnav::estimator {
namespace {

/// Every alternative of EstimatorInput has an InputKind entry, and no two share a rank.
template <size_t... I>
constexpr bool ranksDistinct(std::index_sequence<I...>) {
  constexpr int ranks[] = {InputKind<std::variant_alternative_t<I, EstimatorInput>>::rank...};
  for (size_t i = 0; i < sizeof...(I); ++i)
    for (size_t j = i + 1; j < sizeof...(I); ++j)
      if (ranks[i] == ranks[j]) return false;
  return true;
}
static_assert(ranksDistinct(std::make_index_sequence<std::variant_size_v<EstimatorInput>>{}));

/// A default sample of kind T at time t.
template <class T>
T at(Timestamp t) {
  T x{};
  x.t = t;
  return x;
}

std::vector<EstimatorInput> oneOfEachAt(Timestamp t) {
  // Deliberately not in the canonical order, nor in the variant's order.
  return {at<HeightSample>(t), at<EstimatorCommand>(t), at<RangeSample>(t), at<AnchorInit>(t),
          at<BaroSample>(t),   at<ImuSample>(t),        at<FlightStateSample>(t)};
}

void sortCanonically(std::vector<EstimatorInput>& v) {
  std::stable_sort(v.begin(), v.end(),
                   [](const EstimatorInput& x, const EstimatorInput& y) { return inputOrder(x) < inputOrder(y); });
}

std::vector<std::string> names(const std::vector<EstimatorInput>& v) {
  std::vector<std::string> out;
  for (const auto& in : v) out.push_back(inputKindName(in));
  return out;
}

TEST(EstimatorInput, KindsAtEqualTimeFollowTheTable) {
  auto v = oneOfEachAt(Timestamp::fromSec(1.0));
  sortCanonically(v);
  const std::vector<std::string> expected = {"FLIGHT_STATE", "IMU",           "BARO",  "RANGE",
                                             "ANCHOR_INIT",  "ESTIMATOR_CMD", "HEIGHT"};
  EXPECT_EQ(names(v), expected);
  for (size_t k = 0; k < v.size(); ++k) EXPECT_EQ(inputKindRank(v[k]), static_cast<int>(k));
}

TEST(EstimatorInput, TimeComesBeforeKindAndIdsBreakTies) {
  std::vector<EstimatorInput> v;
  RangeSample late;
  late.t = Timestamp::fromSec(2.0);
  late.id_initiator = 100;
  late.id_responder = 101;
  RangeSample early_b = late;
  early_b.t = Timestamp::fromSec(1.0);
  early_b.id_responder = 103;
  RangeSample early_a = early_b;
  early_a.id_responder = 102;
  v = {late, at<FlightStateSample>(Timestamp::fromSec(2.0)), early_b, at<HeightSample>(Timestamp::fromSec(1.0)),
       early_a};
  sortCanonically(v);
  EXPECT_EQ(names(v), (std::vector<std::string>{"RANGE", "RANGE", "HEIGHT", "FLIGHT_STATE", "RANGE"}));
  EXPECT_EQ(std::get<RangeSample>(v[0]).id_responder, 102);
  EXPECT_EQ(std::get<RangeSample>(v[1]).id_responder, 103);
}

TEST(EstimatorInput, MergedDatasetIsInCanonicalOrder) {
  Dataset ds;
  for (int k = 0; k < 3; ++k) {
    const Timestamp t = Timestamp::fromSec(0.01 * k);
    ds.imu.push_back(at<ImuSample>(t));
    ds.heights.push_back(at<HeightSample>(t));
    ds.baro.push_back(at<BaroSample>(t));
    ds.flight_states.push_back(at<FlightStateSample>(t));
  }
  const auto merged = mergeInTimeOrder(ds);
  ASSERT_EQ(merged.size(), 12u);
  for (size_t k = 0; k < merged.size(); ++k) {
    EXPECT_EQ(inputTime(merged[k]), Timestamp::fromSec(0.01 * static_cast<double>(k / 4)));
    EXPECT_EQ(inputKindName(merged[k]), std::string(std::vector<const char*>{"FLIGHT_STATE", "IMU", "BARO", "HEIGHT"}[k % 4]));
  }
}

}  // namespace
}  // namespace meshnav::estimator
