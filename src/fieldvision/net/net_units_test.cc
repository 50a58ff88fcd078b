// Messages (round trip, refusals by reason) and the NTP-style clock estimate.
#include <gtest/gtest.h>
#include <cstring>

#include "fieldvision/net/clock_sync.h"
#include "fieldvision/net/endpoint.h"
#include "fieldvision/net/fuse.h"
#include "fieldvision/net/messages.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::net {
namespace {

MessageError::Reason ReasonOf(const std::string& bytes) {
  try {
    Decode(bytes.data(), bytes.size());
  } catch (const MessageError& e) {
    return e.reason();
  }
  ADD_FAILURE() << "accepted: " << bytes;
  return MessageError::Reason::kMalformed;
}

TEST(Endpoint, AddressesAsTheCommandsTakeThem) {
  EXPECT_EQ(EndpointProblem("tcp://127.0.0.1:8480", false), "");
  EXPECT_EQ(EndpointProblem("tcp://[::1]:8480", false), "");
  EXPECT_EQ(EndpointProblem("ipc:///tmp/fuse", false), "");
  EXPECT_EQ(EndpointProblem("tcp://127.0.0.1:*", true), "");
  EXPECT_EQ(EndpointProblem("tcp://127.0.0.1:0", true), "");
  for (const char* bad : {"tcp://127.0.0.1:*", "tcp://127.0.0.1:0", "tcp://h:65536",
                          "tcp://h:99999", "tcp://:80", "tcp://h", "udp://h:80", "ipc://", ""}) {
    EXPECT_NE(EndpointProblem(bad, false), "") << bad;
  }
  EXPECT_NE(EndpointProblem("tcp://h:99999", false).find("'tcp://h:99999'"), std::string::npos);
}

TEST(Messages, FrameRoundTripsExactly) {
  FrameMessage f;
  f.camera = "cam2";
  f.session = "abc";
  f.frame = 17;
  f.time_s = 1764612345.123456789;
  f.origin = "device";
  f.has_offset = true;
  f.offset_s = -0.0801234567;
  recon::BallObservation o;
  o.centre_px = {100.25, 33.125};
  o.radius_px = 4.5;
  o.sigma_px = 0.3;
  o.score = 0.9;
  f.candidates = {o, o};
  f.candidates[1].weak = true;
  const std::string bytes = Encode(f);
  const Message m = Decode(bytes.data(), bytes.size());
  const auto* back = std::get_if<FrameMessage>(&m);
  ASSERT_NE(back, nullptr);
  EXPECT_EQ(back->camera, "cam2");
  EXPECT_EQ(back->frame, 17);
  EXPECT_EQ(back->time_s, f.time_s);
  EXPECT_EQ(back->offset_s, f.offset_s);
  EXPECT_TRUE(back->has_offset);
  ASSERT_EQ(back->candidates.size(), 2u);
  EXPECT_EQ(back->candidates[0].centre_px, o.centre_px);
  EXPECT_TRUE(back->candidates[1].weak);
  EXPECT_LT(back->queued_s, 0);  // not sent
  f.queued_s = 0.0125;
  f.process_s = 0.003;
  const std::string timed = Encode(f);
  const Message m2 = Decode(timed.data(), timed.size());
  EXPECT_EQ(std::get<FrameMessage>(m2).queued_s, 0.0125);
  EXPECT_EQ(std::get<FrameMessage>(m2).process_s, 0.003);
}

TEST(Messages, FlightRoundTripsExactly) {
  FlightMessage f;
  f.index = 3;
  f.start = "hit";
  f.end = "bounce";
  f.t_start_s = 1.25;
  f.t_end_s = 2.5;
  f.origin_m[0] = -1.5;
  f.landing_m[1] = 7.25;
  f.apex_m[2] = 3.125;
  f.v0_mps[0] = 12.5;
  f.landing_extrapolated = true;
  f.model = "drag";
  f.samples = 75;
  const std::string bytes = Encode(f);
  const Message m = Decode(bytes.data(), bytes.size());
  const auto* back = std::get_if<FlightMessage>(&m);
  ASSERT_NE(back, nullptr);
  EXPECT_EQ(back->index, 3);
  EXPECT_EQ(back->end, "bounce");
  EXPECT_EQ(back->origin_m[0], -1.5);
  EXPECT_EQ(back->landing_m[1], 7.25);
  EXPECT_EQ(back->apex_m[2], 3.125);
  EXPECT_EQ(back->v0_mps[0], 12.5);
  EXPECT_TRUE(back->landing_extrapolated);
  EXPECT_EQ(back->model, "drag");
  EXPECT_EQ(back->samples, 75);
  std::string bad = bytes;
  bad.replace(bad.find("\"origin_m\":["), 12, "\"origin_m\":[1,");  // four numbers
  EXPECT_THROW(Decode(bad.data(), bad.size()), MessageError);
}

TEST(Messages, SkipRoundTripsAndBadTimingsAreRefused) {
  SkipMessage k{"cam1", "s1", 15, 1764612345.5, "system", 0.25, true, 2};
  const std::string bytes = Encode(k);
  const Message m = Decode(bytes.data(), bytes.size());
  const auto* back = std::get_if<SkipMessage>(&m);
  ASSERT_NE(back, nullptr);
  EXPECT_EQ(back->frame, 15);
  EXPECT_EQ(back->time_s, k.time_s);
  EXPECT_EQ(back->skipped, 2);
  EXPECT_TRUE(back->has_offset);
  EXPECT_EQ(back->offset_s, 0.25);
  const std::string negative =
      R"({"v":1,"type":"frame","camera":"c","session":"s","frame":1,"time_s":1,"origin":"device",)"
      R"("clock":"system","candidates":[],"process_s":-1})";
  EXPECT_THROW(Decode(negative.data(), negative.size()), MessageError);
}

// A clock reply says whether the fusion node sends hints (nodes reading a file go in step with
// them); a reply of an older fusion node, without the field, says no.
TEST(Messages, PongTellsWhetherHintsAreSent) {
  const PongMessage pong{1.0, 2.0, 3.0, true};
  const std::string bytes = Encode(pong);
  const Message back = Decode(bytes.data(), bytes.size());
  ASSERT_TRUE(std::holds_alternative<PongMessage>(back));
  EXPECT_TRUE(std::get<PongMessage>(back).hints);
  const std::string old = R"({"v":1,"type":"pong","t0_s":1,"t1_s":2,"t2_s":3})";
  EXPECT_FALSE(std::get<PongMessage>(Decode(old.data(), old.size())).hints);
  const std::string bad = R"({"v":1,"type":"pong","t0_s":1,"t1_s":2,"t2_s":3,"hints":1})";
  EXPECT_THROW(Decode(bad.data(), bad.size()), MessageError);
}

// A clock reply tells a node it is refused and why (absent: accepted; an older node ignores it).
TEST(Messages, PongTellsARefusedNodeWhy) {
  const PongMessage pong{1.0, 2.0, 3.0, true, "it has no camera 'c9'", false};
  const std::string bytes = Encode(pong);
  const PongMessage back = std::get<PongMessage>(Decode(bytes.data(), bytes.size()));
  EXPECT_EQ(back.refused, "it has no camera 'c9'");
  EXPECT_FALSE(back.refused_for_now);
  EXPECT_EQ(Encode(PongMessage{1.0, 2.0, 3.0}).find("refused"), std::string::npos);
  for (const char* bad : {R"({"v":1,"type":"pong","t0_s":1,"t1_s":2,"t2_s":3,"refused":""})",
                          R"({"v":1,"type":"pong","t0_s":1,"t1_s":2,"t2_s":3,"refused":3})",
                          R"({"v":1,"type":"pong","t0_s":1,"t1_s":2,"t2_s":3,"refused":"x",)"
                          R"("refused_for_now":"yes"})"}) {
    EXPECT_THROW(Decode(bad, std::strlen(bad)), MessageError) << bad;
  }
}

TEST(Messages, HintRoundTripsAndABadRadiusIsRefused) {
  const HintMessage h{1764612345.25, 1.5, -2.25, 0.75, 0.11};
  const std::string bytes = Encode(h);
  const Message m = Decode(bytes.data(), bytes.size());
  const auto* back = std::get_if<HintMessage>(&m);
  ASSERT_NE(back, nullptr);
  EXPECT_EQ(back->time_s, h.time_s);
  EXPECT_EQ(back->x_m, h.x_m);
  EXPECT_EQ(back->y_m, h.y_m);
  EXPECT_EQ(back->z_m, h.z_m);
  EXPECT_EQ(back->radius_m, h.radius_m);
  EXPECT_EQ(ReasonOf(R"({"v":1,"type":"hint","time_s":1,"x_m":0,"y_m":0,"z_m":1,"radius_m":0})"),
            MessageError::Reason::kMalformed);
  EXPECT_EQ(ReasonOf(R"({"v":1,"type":"hint","time_s":1,"x_m":0,"y_m":0,"radius_m":0.1})"),
            MessageError::Reason::kMalformed);
  // A frame without a position: no position keys, read back as lost.
  HintMessage lost;
  lost.time_s = 12.5;
  lost.lost = true;
  const std::string lost_bytes = Encode(lost);
  EXPECT_EQ(lost_bytes.find("x_m"), std::string::npos) << lost_bytes;
  const Message lm = Decode(lost_bytes.data(), lost_bytes.size());
  const auto* lost_back = std::get_if<HintMessage>(&lm);
  ASSERT_NE(lost_back, nullptr);
  EXPECT_TRUE(lost_back->lost);
  EXPECT_EQ(lost_back->time_s, 12.5);
  EXPECT_FALSE(std::get<HintMessage>(m).lost);
  EXPECT_EQ(ReasonOf(R"({"v":1,"type":"hint","time_s":1,"lost":false})"),
            MessageError::Reason::kMalformed);
}

TEST(Messages, RefusalsSayWhy) {
  using R = MessageError::Reason;
  EXPECT_EQ(ReasonOf(std::string(kMaxMessageBytes + 1, '{')), R::kOversized);
  EXPECT_EQ(ReasonOf(R"({"v":2,"type":"ping","camera":"a","session":"b","t0_s":1})"), R::kVersion);
  EXPECT_EQ(ReasonOf(R"({"type":"ping"})"), R::kMalformed);
  EXPECT_EQ(ReasonOf("[1,2]"), R::kMalformed);
  EXPECT_EQ(ReasonOf(R"({"v":1,"type":"teleport"})"), R::kMalformed);
  EXPECT_EQ(ReasonOf(R"({"v":1,"type":"ping","camera":"a","session":"b","t0_s":"x"})"),
            R::kMalformed);
  EXPECT_EQ(ReasonOf(R"({"v":1,"type":"frame","camera":"a","session":"b","frame":1,)"
                     R"("time_s":1,"origin":"device","clock":"system","candidates":[{"u":1}]})"),
            R::kMalformed);
}

TEST(ClockSync, ShortestRoundTripGivesTheOffset) {
  testing::SeededRng rng(5);
  const double true_offset = 0.0803;  // fuse - node
  ClockSync sync(16);
  EXPECT_FALSE(sync.Estimate());
  double node_t = 1000.0;
  for (int i = 0; i < 16; ++i) {
    // Asymmetric queueing delays up to 20 ms each way; one exchange is nearly free of them.
    const double up = i == 9 ? 1e-4 : rng.Uniform(0.0, 0.02);
    const double down = i == 9 ? 1e-4 : rng.Uniform(0.0, 0.02);
    const double t0 = node_t;
    const double t1 = t0 + up + true_offset;
    const double t2 = t1 + 1e-4;
    const double t3 = t2 - true_offset + down;
    EXPECT_TRUE(sync.Add(t0, t1, t2, t3));
    node_t += 0.5;
  }
  EXPECT_FALSE(sync.Add(10, 11, 10.5, 12));  // replied before it was received
  const auto e = sync.Estimate();
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->offset_s, true_offset, 1e-4);
  EXPECT_NEAR(e->round_trip_s, 2e-4, 1e-9);
}

TEST(FuseStages, SenderOfNamesCameraAndSessionOfNodeMessages) {
  FrameMessage f;
  f.camera = "left";
  f.session = "s1";
  EXPECT_EQ(SenderOf(f), (std::pair<std::string, std::string>{"left", "s1"}));
  ByeMessage b;
  b.camera = "right";
  b.session = "s2";
  EXPECT_EQ(SenderOf(b), (std::pair<std::string, std::string>{"right", "s2"}));
  EXPECT_FALSE(SenderOf(PongMessage{}).has_value());
  EXPECT_FALSE(SenderOf(BallMessage{}).has_value());
  EXPECT_FALSE(SenderOf(HintMessage{}).has_value());
}

}  // namespace
}  // namespace fv::net
