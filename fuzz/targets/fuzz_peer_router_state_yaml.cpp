/// @file fuzz_peer_router_state_yaml.cpp
/// @brief Fuzz target: the peer_router's restart journal peer_router_state.yaml (docs/formats.md)
/// through readPeerRouterState for a fleet of v0, v1, v2. Refusals are std::runtime_error; an
/// accepted journal holds one provenance per vehicle, none about itself, and a restore of it
/// into a router never throws.
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/scratch_file.h"
#include "pipeline/peer_range_router.h"
#include "pipeline/peer_router_state.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("peer_router_state.yaml");
  static const std::vector<std::string> names{"v0", "v1", "v2"};
  file.write(data, size);
  fuzz::refusalsAllowed([&] {
    const pipeline::PeerRouterState s = pipeline::readPeerRouterState(file.path(), names);
    fuzz::require(s.provenance.size() == names.size(), "peer_router_state.yaml: not one provenance per vehicle");
    for (size_t v = 0; v < s.provenance.size(); ++v)
      for (const auto& [u, since] : s.provenance[v])
        fuzz::require(u < names.size() && u != v, "peer_router_state.yaml: an entry of no vehicle or of itself");
    pipeline::PeerRangeRouter router(pipeline::PeerRangeRoutingOptions{}, names.size());
    router.restoreProvenance(s.provenance, s.t);
  });
  return 0;
}
