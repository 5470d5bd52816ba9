/// @file fuzz_lcm_messages.cpp
/// @brief Fuzz target: the bytes of one LCM message, decoded as every message type of
/// lcmtypes/ that a process subscribes to, as LcmNode does (a throwing or failing decode is a
/// counted decode error), then converted with fromLcm (InvalidMessage: a counted invalid message).
/// What converts must convert back: toLcm, encode, decode and fromLcm again without a refusal.
/// Decoding goes through decodeAnyVersion (transport/wire_versions.h), so the seeds of the
/// previous version (pre36_*.bin, and the regression seeds recorded with it) fuzz its upgrade.
#include <vector>

#include "fuzz/support/fuzz_target.h"
#include "transport/convert.h"
#include "transport/wire_versions.h"

using namespace meshnav;
using namespace meshnav::transport;

namespace {

/// Decodes like LcmNode::decode: false when the bytes are not a `Msg` (any exception included).
template <class Msg>
bool decodeAs(const uint8_t* data, size_t size, Msg& msg) {
  try {
    return decodeAnyVersion(data, size, msg) >= 0;
  } catch (const std::exception&) {
    return false;
  }
}

template <class Msg>
void fuzzType(const uint8_t* data, size_t size) {
  Msg msg;
  if (!decodeAs(data, size, msg)) return;
  using Plain = decltype(fromLcm(msg));
  Plain plain;
  try {
    plain = fromLcm(msg);
  } catch (const InvalidMessage&) {
    return;  // counted as "<CHANNEL>:invalid_message" by the process runtime
  } catch (const std::exception& e) {
    fuzz::fail(std::string(Msg::getTypeName()) + ": fromLcm threw other than InvalidMessage: " + e.what());
  }
  const Msg again = toLcm(plain);
  const int n = again.getEncodedSize();
  fuzz::require(n > 0, std::string(Msg::getTypeName()) + ": converted message has no encoded size");
  std::vector<uint8_t> buf(static_cast<size_t>(n));
  fuzz::require(again.encode(buf.data(), 0, n) == n, std::string(Msg::getTypeName()) + ": re-encoding failed");
  Msg decoded;
  fuzz::require(decodeAs(buf.data(), buf.size(), decoded), std::string(Msg::getTypeName()) + ": re-encoded bytes do not decode");
  try {
    (void)fromLcm(decoded);
  } catch (const std::exception& e) {
    fuzz::fail(std::string(Msg::getTypeName()) + ": a converted message is refused after a round trip: " + e.what());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzzType<imu_t>(data, size);
  fuzzType<baro_t>(data, size);
  fuzzType<height_t>(data, size);
  fuzzType<range_t>(data, size);
  fuzzType<flight_state_t>(data, size);
  fuzzType<ground_truth_t>(data, size);
  fuzzType<pose_t>(data, size);
  fuzzType<anchor_estimate_t>(data, size);
  fuzzType<pair_bias_t>(data, size);
  fuzzType<anchor_init_t>(data, size);
  fuzzType<estimator_status_t>(data, size);
  fuzzType<estimator_cmd_t>(data, size);
  fuzzType<calib_cmd_t>(data, size);
  fuzzType<calib_status_t>(data, size);
  fuzzType<mission_status_t>(data, size);
  fuzzType<anchors_t>(data, size);
  return 0;
}
