// The peer_router's restart journal (pipeline/peer_router_state.h): what is written is read back;
// a file of another fleet or a broken one is refused naming the file and the key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pipeline/peer_router_state.h"

using namespace meshnav;
using namespace meshnav::pipeline;

namespace {

const std::vector<std::string> kNames{"uav1", "uav2", "rover"};

struct TempDir {
  TempDir() {
    char tmpl[] = "/tmp/meshnav_peer_router_state_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string file(const std::string& text) const {
    const std::string f = path + "/peer_router_state.yaml";
    std::ofstream(f) << text;
    return f;
  }
  std::string path;
};

/// The message readPeerRouterState throws for `text`.
std::string refusal(const std::string& text) {
  TempDir d;
  const std::string f = d.file(text);
  try {
    readPeerRouterState(f, kNames);
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(f), std::string::npos) << what;
    return what;
  }
  ADD_FAILURE() << "not refused:\n" << text;
  return {};
}

}  // namespace

TEST(PeerRouterState, WhatIsWrittenIsReadBack) {
  TempDir d;
  PeerRouterState s;
  s.t = Timestamp::fromUtime(63'250'001);
  s.provenance.resize(3);
  s.provenance[0][1] = Timestamp::fromUtime(61'250'000);
  s.provenance[0][2] = Timestamp::fromUtime(60'000'007);
  s.provenance[2][0] = Timestamp::fromUtime(-5);
  const std::string f = d.path + "/journal.yaml";
  writePeerRouterState(f, s, kNames);
  const PeerRouterState r = readPeerRouterState(f, kNames);
  EXPECT_EQ(r.t, s.t);
  EXPECT_EQ(r.provenance, s.provenance);
  EXPECT_THROW(writePeerRouterState(f, s, {"uav1", "uav2"}), std::runtime_error);  // another fleet's size
}

TEST(PeerRouterState, AnotherFleetsOrABrokenFileIsRefusedNamingTheKey) {
  const std::string ok_head = "layout: 1\nt_us: 1000\n";
  EXPECT_NE(refusal(ok_head + "holds: {uav1: {ghost: 10}}\n").find("holds.uav1.ghost"), std::string::npos);
  EXPECT_NE(refusal(ok_head + "holds: {ghost: {}}\n").find("holds.ghost"), std::string::npos);
  EXPECT_NE(refusal(ok_head + "holds: {uav1: {uav2: soon}}\n").find("holds.uav1.uav2"), std::string::npos);
  EXPECT_NE(refusal(ok_head + "holds: {uav1: {uav1: 10}}\n").find("holds.uav1.uav1"), std::string::npos);
  EXPECT_NE(refusal(ok_head + "holds: {uav1: [uav2]}\n").find("holds.uav1"), std::string::npos);
  EXPECT_NE(refusal(ok_head + "holds: {}\nextra: 1\n").find("extra"), std::string::npos);
  EXPECT_NE(refusal(ok_head + "holds: {uav1: {uav2: 1001}}\n").find("holds.uav1.uav2"), std::string::npos);  // after t_us
  EXPECT_NE(refusal("layout: 1\nt_us: 9000000000000000000\nholds: {}\n").find("t_us"), std::string::npos);
  EXPECT_NE(refusal(ok_head + "holds: {uav1: {uav2: -9000000000000000000}}\n").find("holds.uav1.uav2"), std::string::npos);
  EXPECT_NE(refusal("layout: 2\nt_us: 1000\nholds: {}\n").find("layout"), std::string::npos);
  EXPECT_NE(refusal("layout: 1\nholds: {}\n").find("t_us"), std::string::npos);
  EXPECT_NE(refusal(ok_head).find("holds"), std::string::npos);
  EXPECT_THROW(readPeerRouterState("/nonexistent/peer_router_state.yaml", kNames), std::runtime_error);
  // Vehicles left out hold nothing.
  TempDir d;
  const PeerRouterState r = readPeerRouterState(d.file(ok_head + "holds: {uav2: {rover: 900}}\n"), kNames);
  ASSERT_EQ(r.provenance.size(), 3u);
  EXPECT_TRUE(r.provenance[0].empty());
  EXPECT_EQ(r.provenance[1].at(2), Timestamp::fromUtime(900));
}
