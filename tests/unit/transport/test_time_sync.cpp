// Time across hosts (transport/time_sync.h) over LCM's memq:// provider: a client whose clock is
// off by +40 ms or -25 ms (injected, as the two skewed anchor hosts of the multi-host test) learns
// its offset from the reference and stamps in the reference clock.
#include <gtest/gtest.h>

#include "transport/lcm_node.h"
#include "transport/replay/clock.h"
#include "transport/time_sync.h"

using namespace meshnav;
using namespace meshnav::transport;

TEST(TimeSync, InjectedClockOffsetsAreEstimatedAndCorrected) {
  LcmNode node("time_sync_test", "memq://");
  serveTimeSync(node);
  for (double offset_s : {0.040, -0.025}) {
    TimeSyncClient client(node, "client " + std::to_string(offset_s), Duration::fromSec(offset_s));
    EXPECT_FALSE(client.offset());
    const Timestamp local = Timestamp::fromUtime(client.localNow());
    EXPECT_EQ(client.toReference(local), local);  // unsynchronized: unchanged, counted
    ASSERT_TRUE(client.synchronize(5, Duration{0}, Duration::fromSec(2.0)));
    // memq delivers within microseconds: the estimate is the injected offset to well under 1 ms.
    EXPECT_NEAR(*client.offset() / 1e6, -offset_s, 1e-3);
    EXPECT_LE(*client.errorBound(), 1000);
    const Timestamp stamped = client.toReference(Timestamp::fromUtime(client.localNow()));
    EXPECT_NEAR(stamped.us, replay::wallUtimeNow(), 2000);
  }
  EXPECT_EQ(node.diagnostics().get("time_sync:unsynchronized"), 2);
  EXPECT_EQ(node.diagnostics().get("time_sync:bad_exchange"), 0);
}

TEST(TimeSync, RepliesToOtherClientsAreIgnored) {
  LcmNode node("time_sync_test", "memq://");
  serveTimeSync(node);
  TimeSyncClient a(node, "a", Duration::fromSec(0.040));
  TimeSyncClient b(node, "b", Duration::fromSec(-0.025));
  ASSERT_TRUE(a.synchronize(3, Duration{0}, Duration::fromSec(2.0)));
  EXPECT_FALSE(b.offset());  // a's replies went to a only
  ASSERT_TRUE(b.synchronize(3, Duration{0}, Duration::fromSec(2.0)));
  EXPECT_NEAR(*a.offset() / 1e6, -0.040, 1e-3);
  EXPECT_NEAR(*b.offset() / 1e6, 0.025, 1e-3);
}
