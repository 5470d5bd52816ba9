#pragma once
/// @file link_faults.h
/// @brief The fault model of one network link for the multi-host tests (scripts/multihost_netns.sh,
/// meshnav_netem_switch), free of sockets: what `tc netem` does, for machines whose kernel has no
/// netem (this project's own: "Specified qdisc kind is unknown"). Parameters use netem's words:
///
///   loss P%  delay D [J]  duplicate P%  reorder P%
///
/// A datagram is lost with probability `loss`; otherwise it is delivered once, and a second time
/// with probability `duplicate` (the copy with its own delay). Its delay is D + U(−J, J) (netem's
/// default jitter without a distribution table), at least 0, so datagrams overtake each other
/// when J > 0; with probability `reorder` it goes at once instead (netem's `reorder`: those
/// overtake every delayed one). Times are µs; units accepted: us, ms, s.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace meshnav::netem {

struct LinkFaults {
  double loss = 0.0;       ///< probability a datagram is lost [0, 1]
  double duplicate = 0.0;  ///< probability a delivered datagram comes twice [0, 1]
  double reorder = 0.0;    ///< probability a datagram skips the delay [0, 1]
  int64_t delay_us = 0;    ///< mean one-way delay [µs]
  int64_t jitter_us = 0;   ///< half-width of the uniform delay spread [µs]

  /// Parses netem's words ("loss 20% delay 20ms 10ms duplicate 1% reorder 5%"; "" = no fault).
  /// Throws std::invalid_argument naming the word for anything else or a value out of range.
  static LinkFaults parse(const std::string& spec);
  std::string toString() const;
  bool none() const { return loss == 0 && duplicate == 0 && reorder == 0 && delay_us == 0 && jitter_us == 0; }
};

/// Draws the deliveries of datagrams over one link.
class LinkEmulator {
 public:
  LinkEmulator(LinkFaults faults, uint64_t seed) : faults_(faults), rng_(seed) {}
  /// Delays [µs] after which a datagram sent now arrives: empty (lost), one, or two (duplicated).
  std::vector<int64_t> deliveries();
  const LinkFaults& faults() const { return faults_; }

 private:
  int64_t delay();
  LinkFaults faults_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> u_{0.0, 1.0};
};

/// The channel of an LCM udpm datagram ("LC02" short message, or the first fragment "LC03" of a
/// long one); "" for a later fragment (fragment_no > 0); "?" when the bytes are not LCM's.
std::string lcmChannelOf(const uint8_t* data, size_t size);

}  // namespace meshnav::netem
