// The receiver's freshness rules (middleware/src/receiver.hpp, DESIGN §7 "The bus, precisely"),
// without a bus: what one receiver believes of one peer's process.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "auth.hpp"
#include "bus_link.hpp"
#include "receiver.hpp"
#include "safecass/middleware/keys.hpp"

namespace safecass::middleware {
namespace {

using Verdict = PeerFreshness::Verdict;

constexpr std::int64_t kRun = 1'000'000;  // a proven process's incarnation

/// The robot's state streams, as every receiver's system file gives them.
const StateStreams& robot_streams() {
  static const StateStreams streams = StateStreams::of({"JR3.ForceData"});
  return streams;
}

/// A receiver that follows the robot's state streams.
PeerFreshness following() {
  PeerFreshness peer;
  peer.follow(robot_streams());
  return peer;
}

/// A heartbeat of the robot (or the one a proof carries): number `seq`, its stream at `state_sent`.
wire::Heartbeat proof(std::int64_t incarnation, std::int64_t seq, std::int64_t state_sent) {
  wire::Heartbeat beat;
  beat.coordinator = "robot";
  beat.incarnation = incarnation;
  beat.seq = seq;
  beat.states = {state_sent};
  beat.statesId = robot_streams().id;
  return beat;
}
wire::Heartbeat beat(std::int64_t incarnation, std::int64_t seq) { return proof(incarnation, seq, 0); }

constexpr PeerFreshness::Slot kForceData{0};

TEST(PeerFreshness, NothingOfAPeerIsTakenBeforeItsProcessIsProvenNotEvenOfIncarnationZero) {
  PeerFreshness peer = following();
  std::string why;
  std::int64_t missed = 0;
  for (std::int64_t incarnation : {std::int64_t{0}, std::int64_t{-1}, kRun}) {
    EXPECT_EQ(peer.heartbeat(beat(incarnation, 1), why), Verdict::Unproven) << incarnation;
    EXPECT_EQ(peer.stream(kForceData, incarnation, 1, missed, why), Verdict::Unproven) << incarnation;
    EXPECT_EQ(peer.process(incarnation, why), Verdict::Unproven) << incarnation;
  }
}

TEST(PeerFreshness, AfterAProofOnlyThatProcessIsTakenAnOlderOneIsRefusedANewerOneIsUnproven) {
  PeerFreshness peer = following();
  std::string why;
  ASSERT_TRUE(peer.proven(proof(kRun, 7, 0), why)) << why;
  EXPECT_EQ(peer.process(kRun, why), Verdict::Accept);
  EXPECT_EQ(peer.heartbeat(beat(kRun, 8), why), Verdict::Accept);
  EXPECT_EQ(peer.heartbeat(beat(kRun, 8), why), Verdict::Refuse) << "a repeated heartbeat is a replay";
  EXPECT_EQ(peer.heartbeat(beat(kRun, 7), why), Verdict::Refuse) << "at or below the proof's number";
  EXPECT_EQ(peer.process(kRun - 1, why), Verdict::Refuse);
  EXPECT_NE(why.find("is older than"), std::string::npos) << why;
  EXPECT_EQ(peer.process(kRun + 1, why), Verdict::Unproven) << "a restart is believed once it is proven";
  EXPECT_FALSE(peer.proven(proof(kRun - 1, 50, 0), why)) << "a proof of an older process";
  EXPECT_EQ(peer.incarnation(), kRun);
}

TEST(PeerFreshness, AHeartbeatNumberedAsTheProofSaysArrivingAfterItIsDroppedWithoutBlameUntilANewerIsTaken) {
  PeerFreshness peer = following();
  std::string why;
  ASSERT_TRUE(peer.proven(proof(kRun, 7, 0), why)) << why;
  EXPECT_EQ(peer.heartbeat(beat(kRun, 7), why), Verdict::Covered)
      << "the heartbeat sent with the proof, arriving after it";
  EXPECT_EQ(peer.heartbeat(beat(kRun, 6), why), Verdict::Covered) << "an older one still on its way";
  EXPECT_EQ(peer.heartbeat(beat(kRun, 8), why), Verdict::Accept);
  EXPECT_EQ(peer.heartbeat(beat(kRun, 7), why), Verdict::Refuse)
      << "once a newer one is taken, an older one is a replay";
  EXPECT_EQ(peer.heartbeat(beat(kRun, 8), why), Verdict::Refuse);
  ASSERT_TRUE(peer.proven(proof(kRun, 5, 0), why)) << "a slower proof of the same process";
  EXPECT_EQ(peer.heartbeat(beat(kRun, 8), why), Verdict::Refuse) << "a proof older than what was taken covers nothing";
}

TEST(PeerFreshness, AStreamMessageAtOrBelowTheProofsCountIsDroppedWithoutBlameAndTheNextIsTaken) {
  PeerFreshness peer = following();
  std::string why;
  std::int64_t missed = 0;
  ASSERT_TRUE(peer.proven(proof(kRun, 1, 5), why)) << why;
  EXPECT_EQ(peer.stream(kForceData, kRun, 5, missed, why), Verdict::Unproven) << "sent before the proof";
  EXPECT_EQ(peer.stream(kForceData, kRun, 6, missed, why), Verdict::Accept);
  EXPECT_EQ(missed, 0);
  EXPECT_EQ(peer.stream(kForceData, kRun, 6, missed, why), Verdict::Refuse) << "taken once: a repeat is a replay";
  EXPECT_EQ(peer.stream(kForceData, kRun, 9, missed, why), Verdict::Accept);
  EXPECT_EQ(missed, 2) << "7 and 8 skipped";
  EXPECT_EQ(peer.last(kForceData), 9);
}

TEST(PeerFreshness, AStreamCannotJumpMoreThanTwoToTheTwentyAheadEvenFromItsOwnProcess) {
  PeerFreshness peer = following();
  std::string why;
  std::int64_t missed = 0;
  ASSERT_TRUE(peer.proven(proof(kRun, 1, 0), why)) << why;
  EXPECT_EQ(peer.stream(kForceData, kRun, kMaxSeqJump + 1, missed, why), Verdict::Refuse);
  EXPECT_NE(why.find("jumps more than"), std::string::npos) << why;
  EXPECT_EQ(peer.stream(kForceData, kRun, 1, missed, why), Verdict::Accept) << "the stream is not frozen";
}

TEST(PeerFreshness, AProcessDeclaredLostIsBelievedAgainOnlyOnANewProofOfIt) {
  PeerFreshness peer = following();
  std::string why;
  std::int64_t missed = 0;
  ASSERT_TRUE(peer.proven(proof(kRun, 7, 3), why)) << why;
  EXPECT_EQ(peer.heartbeat(beat(kRun, 8), why), Verdict::Accept);
  peer.doubt();
  EXPECT_EQ(peer.heartbeat(beat(kRun, 9), why), Verdict::Unproven) << "a heartbeat it never sent us may be a recording";
  EXPECT_EQ(peer.stream(kForceData, kRun, 4, missed, why), Verdict::Unproven);
  EXPECT_EQ(peer.process(kRun - 1, why), Verdict::Refuse) << "an older process stays refused";
  ASSERT_TRUE(peer.proven(proof(kRun, 10, 4), why)) << why;
  EXPECT_EQ(peer.heartbeat(beat(kRun, 11), why), Verdict::Accept) << "proven again";
}

TEST(PeerFreshness, HeartbeatsAreDatedAgainstTheQuestionOfTheLastProofNeverLaterThanNow) {
  PeerFreshness peer = following();
  std::string why;
  EXPECT_EQ(peer.sent_at(123, 5000), 5000) << "no proof dated yet: now";
  wire::Heartbeat answer = proof(kRun, 7, 0);
  answer.time = 90'000;  // the sender's clock when it answered
  ASSERT_TRUE(peer.proven(answer, why, 1000)) << why;
  EXPECT_EQ(peer.sent_at(90'500, 9000), 1500) << "500 after the answer, dated 500 after the question";
  EXPECT_EQ(peer.sent_at(99'000, 2000), 2000) << "never later than now";
}

TEST(PeerFreshness, TakenIsWhatCameFromTheProcessNotWhatItsProofListed) {
  PeerFreshness peer = following();
  std::string why;
  std::int64_t missed = 0;
  ASSERT_TRUE(peer.proven(proof(kRun, 7, 5), why)) << why;
  EXPECT_EQ(peer.last(kForceData), 5);
  EXPECT_EQ(peer.taken(kForceData), 0) << "listed, not received";
  EXPECT_EQ(peer.stream(kForceData, kRun, 6, missed, why), Verdict::Accept);
  EXPECT_EQ(peer.taken(kForceData), 6);
}

TEST(PeerFreshness, ANewProcessStartsEveryStreamAgainAndTheOlderOneIsRefused) {
  PeerFreshness peer = following();
  std::string why;
  std::int64_t missed = 0;
  ASSERT_TRUE(peer.proven(proof(kRun, 1, 5), why)) << why;
  EXPECT_EQ(peer.stream(kForceData, kRun, 8, missed, why), Verdict::Accept);
  peer.doubt();
  EXPECT_EQ(peer.stream(kForceData, kRun, 9, missed, why), Verdict::Unproven) << "lost: believed again only on a proof";
  ASSERT_TRUE(peer.proven(proof(kRun + 1, 1, 2), why)) << why;
  EXPECT_EQ(peer.taken(kForceData), 0) << "a new process: nothing of it taken yet";
  EXPECT_EQ(peer.stream(kForceData, kRun + 1, 2, missed, why), Verdict::Unproven) << "at the new proof's count";
  EXPECT_EQ(peer.stream(kForceData, kRun + 1, 3, missed, why), Verdict::Accept);
  EXPECT_EQ(peer.stream(kForceData, kRun, 9, missed, why), Verdict::Refuse) << "the older process";
}

// A heartbeat lists numbers, not names (wire::Heartbeat::states): their order is the one both
// sides derive from the system file, sorted by interface, and the list's id travels with them.
TEST(StateStreams, AreTheInterfacesSortedWithAnIdThatChangesWithTheListAndNotWithItsOrder) {
  const StateStreams a = StateStreams::of({"JR3.Status", "JR3.ForceData", "ARM.Pose"});
  EXPECT_EQ(a.ifaces, (std::vector<std::string>{"ARM.Pose", "JR3.ForceData", "JR3.Status"}));
  EXPECT_EQ(StateStreams::of({"ARM.Pose", "JR3.Status", "JR3.ForceData"}).id, a.id)
      << "the order given does not matter";
  EXPECT_NE(StateStreams::of({"ARM.Pose", "JR3.ForceData"}).id, a.id) << "one interface fewer";
  EXPECT_NE(StateStreams::of({"ARM.Pose", "JR3.ForceData", "JR3.Status2"}).id, a.id) << "one renamed";
  EXPECT_NE(StateStreams::of({"ARM.PoseJR3.ForceData", "JR3.Status"}).id,
            StateStreams::of({"ARM.Pose", "JR3.ForceDataJR3.Status"}).id)
      << "names are delimited";
  EXPECT_NE(StateStreams::of({}).id, 0) << "an empty list has an id too (the supervisor's heartbeats)";
}

TEST(StateStreams, OfACoordinatorAreTheInterfacesItsComponentsProvideAsTheSystemFileGivesThem) {
  spec::SystemSpec system;
  spec::ComponentSpec jr3;
  jr3.name = "JR3";
  jr3.provided = {"Status", "ForceData"};
  spec::ComponentSpec control;
  control.name = "CONTROL";
  control.provided = {"Command"};
  spec::ComponentSpec ui;
  ui.name = "UI";
  system.components = {jr3, control, ui};
  system.coordinators = {{"robot", {"JR3", "CONTROL"}}, {"ui", {"UI"}}};
  const Members members(system);
  EXPECT_EQ(members.state_streams("robot").ifaces,
            (std::vector<std::string>{"CONTROL.Command", "JR3.ForceData", "JR3.Status"}));
  EXPECT_EQ(members.state_streams("robot").id, StateStreams::of({"JR3.Status", "JR3.ForceData", "CONTROL.Command"}).id);
  EXPECT_TRUE(members.state_streams("ui").ifaces.empty());
  EXPECT_EQ(members.state_streams("ui").id, StateStreams::of({}).id);
}

// A receiver whose system file gives the coordinator other interfaces than the coordinator's own
// would read one interface's number as another's: it believes nothing of that process instead
// (lost, toward safe), and says why.
TEST(PeerFreshness, AHeartbeatOrProofOfAnotherListOfStateStreamsIsRefusedSoNoNumberIsReadAsAnotherInterfaces) {
  PeerFreshness peer = following();
  std::string why;
  wire::Heartbeat other = proof(kRun, 7, 3);
  other.statesId = StateStreams::of({"JR3.ForceData", "JR3.Status"}).id;
  other.states = {3, 4};
  EXPECT_FALSE(peer.proven(other, why));
  EXPECT_NE(why.find("another system file?"), std::string::npos) << why;
  EXPECT_EQ(peer.incarnation(), 0) << "nothing believed";
  ASSERT_TRUE(peer.proven(proof(kRun, 7, 3), why)) << why;
  other.seq = 8;
  EXPECT_EQ(peer.heartbeat(other, why), Verdict::Refuse);
  EXPECT_NE(why.find("lists 2 state stream(s)"), std::string::npos) << why;
  wire::Heartbeat short_list = beat(kRun, 9);
  short_list.states.clear();  // the right id, too few numbers
  EXPECT_EQ(peer.heartbeat(short_list, why), Verdict::Refuse) << why;
  EXPECT_EQ(peer.heartbeat(beat(kRun, 10), why), Verdict::Accept) << "its own list still is";
  PeerFreshness tool;  // follows no state stream: checks no list
  EXPECT_TRUE(tool.proven(other, why)) << why;
}

TEST(PeerFreshness, AStateBatchOfAnotherListOfStreamsIsRefusedAndAnUpdateNamesOnlyAPositionInItsSignersList) {
  PeerFreshness peer;
  const StateStreams robot = StateStreams::of({"A.p", "B.p", "C.p"});
  EXPECT_NE(peer.other_streams(robot.id), "") << "a receiver that follows no list reads no batch by position";
  peer.follow(robot);
  EXPECT_EQ(peer.other_streams(robot.id), "");
  const std::string why = peer.other_streams(StateStreams::of({"A.p", "C.p"}).id);
  EXPECT_NE(why.find("number the state streams of a list of id"), std::string::npos) << why;
  EXPECT_NE(why.find("another system file?"), std::string::npos) << why;
  ASSERT_TRUE(peer.slot(std::int64_t{2}));
  EXPECT_EQ(peer.iface(*peer.slot(std::int64_t{2})), "C.p");
  EXPECT_EQ(peer.slot(std::int64_t{0})->index, peer.slot("A.p")->index) << "the same slot by name and by position";
  EXPECT_FALSE(peer.slot(std::int64_t{3})) << "one past the list";
  EXPECT_FALSE(peer.slot(std::int64_t{-1}));
  EXPECT_FALSE(peer.slot(std::int64_t{1} << 40));
  EXPECT_EQ(peer.size(), 3U);
}

TEST(PeerFreshness, AheadNamesEachStreamAHeartbeatListsAboveWhatCameFromTheProcess) {
  PeerFreshness peer;
  peer.follow(StateStreams::of({"A.p", "B.p", "C.p"}));
  std::string why;
  std::int64_t missed = 0;
  wire::Heartbeat answer = beat(kRun, 1);
  answer.statesId = StateStreams::of({"A.p", "B.p", "C.p"}).id;
  answer.states = {2, 0, 4};
  ASSERT_TRUE(peer.proven(answer, why)) << why;
  ASSERT_EQ(peer.stream(*peer.slot("C.p"), kRun, 5, missed, why), Verdict::Accept) << why;
  wire::Heartbeat later = answer;
  later.seq = 2;
  later.states = {2, 1, 5};
  std::vector<std::pair<std::string, std::int64_t>> behind;
  peer.ahead(later, [&](PeerFreshness::Slot s, std::int64_t listed) { behind.emplace_back(peer.iface(s), listed); });
  EXPECT_EQ(behind, (std::vector<std::pair<std::string, std::int64_t>>{{"A.p", 2}, {"B.p", 1}}))
      << "A.p listed by the proof but never received; B.p sent since; C.p received";
  EXPECT_FALSE(peer.slot("D.p").has_value());
}

constexpr std::int64_t kMs = 1'000'000;  // steady ns
constexpr std::chrono::milliseconds kBound{300};
constexpr std::chrono::nanoseconds kRound{1000 * kMs};  // a subscription round

TEST(Liveness, APeerNeverHeardFromIsLostOnceTheBoundHasPassedSinceTheWatchBegan) {
  Liveness live;
  EXPECT_EQ(live.check(1000 * kMs, 0, kBound, "start"), "") << "nothing is watched before the watch begins";
  EXPECT_EQ(live.check(1300 * kMs, 1000 * kMs, kBound, "start"), "") << "at the bound, not yet";
  EXPECT_EQ(live.check(1301 * kMs, 1000 * kMs, kBound, "start"),
            "no heartbeat for 300 ms (never proven alive since start)");
  EXPECT_TRUE(live.lost());
  EXPECT_EQ(live.check(2000 * kMs, 1000 * kMs, kBound, "start"), "") << "a loss is said once";
}

/// A heartbeat sent and believed at `t` (no delay on the way).
bool beat(Liveness& live, std::int64_t t, std::string_view behind = "") { return live.believed(t, t, behind, kBound); }

TEST(Liveness, APeerSilentForLongerThanTheBoundIsLostAndABelievedHeartbeatBringsItBack) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs));
  EXPECT_EQ(live.last_beat(), 100 * kMs);
  EXPECT_EQ(live.check(400 * kMs, 1, kBound, "start"), "");
  EXPECT_EQ(live.check(401 * kMs, 1, kBound, "start"), "no heartbeat for 300 ms");
  EXPECT_TRUE(live.lost());
  EXPECT_TRUE(beat(live, 500 * kMs)) << "back: the owner clears its loss event";
  EXPECT_FALSE(live.lost());
  EXPECT_FALSE(beat(live, 600 * kMs)) << "said once";
}

TEST(Liveness, AHeartbeatCountsFromWhenItWasSentSoOneHeldBackOnTheWayBuysNoTime) {
  Liveness live;
  EXPECT_FALSE(live.believed(350 * kMs, 100 * kMs, "", kBound)) << "sent at 100 ms, held back until 350 ms";
  EXPECT_EQ(live.last_beat(), 100 * kMs);
  EXPECT_EQ(live.check(401 * kMs, 1, kBound, "start"), "no heartbeat for 300 ms")
      << "lost a bound after it was sent, not after it came";
  EXPECT_FALSE(live.believed(402 * kMs, 90 * kMs, "", kBound)) << "an older one moves nothing";
  EXPECT_EQ(live.last_beat(), 100 * kMs);
}

TEST(Liveness, ALossEndsOnlyOnAHeartbeatSentWithinTheBound) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs));
  EXPECT_FALSE(live.check(401 * kMs, 1, kBound, "start").empty());
  EXPECT_FALSE(live.believed(1000 * kMs, 650 * kMs, "", kBound)) << "sent 350 ms ago: a recording, no sign of life";
  EXPECT_TRUE(live.lost());
  EXPECT_TRUE(live.believed(1000 * kMs, 750 * kMs, "", kBound)) << "sent 250 ms ago: back";
}

TEST(Liveness, AStreamItsHeartbeatsShowAheadNotCaughtUpWithinTheBoundIsLostAsASilentPeerIs) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs, "state:P.a"));
  EXPECT_FALSE(beat(live, 200 * kMs, "state:P.a"));
  EXPECT_FALSE(beat(live, 350 * kMs, "state:P.a"));
  EXPECT_EQ(live.check(400 * kMs, 1, kBound, "start"), "") << "behind since 100 ms: not yet past the bound";
  EXPECT_EQ(live.check(401 * kMs, 1, kBound, "start"), "its heartbeats list state of P.a not received for 300 ms")
      << "heartbeats kept coming: behind, not silent, and lost all the same";
  EXPECT_FALSE(beat(live, 450 * kMs, "state:P.a")) << "still behind: still lost";
  EXPECT_TRUE(live.lost());
  EXPECT_TRUE(beat(live, 500 * kMs)) << "caught up: back";
}

TEST(Liveness, AStreamFirstShownAheadIsBehindSinceTheHeartbeatBelievedBeforeIt) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs));
  EXPECT_FALSE(beat(live, 300 * kMs, "state:P.a")) << "the update was sent after 100 ms: behind since then";
  EXPECT_EQ(live.check(400 * kMs, 1, kBound, "start"), "");
  EXPECT_EQ(live.check(401 * kMs, 1, kBound, "start"), "its heartbeats list state of P.a not received for 300 ms")
      << "heartbeats lost on the way do not restart the stream's clock";
}

TEST(Liveness, ALossIsKeptWhileThePeerSettlesItsOwnLossesSoTheViewChangesOnceAfterAHeal) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs));
  EXPECT_FALSE(live.check(401 * kMs, 1, kBound, "start").empty());
  // Back, caught up and fresh, but clearing losses of its own: its state is about to change.
  EXPECT_FALSE(live.believed(1000 * kMs, 1000 * kMs, "", kBound, true)) << "settling: still lost";
  EXPECT_FALSE(live.believed(1100 * kMs, 1100 * kMs, "", kBound, true));
  EXPECT_TRUE(live.lost());
  EXPECT_TRUE(live.believed(1200 * kMs, 1200 * kMs, "", kBound, false)) << "settled: back, in one step";
  EXPECT_FALSE(live.lost());
  EXPECT_FALSE(live.believed(1300 * kMs, 1300 * kMs, "", kBound, true)) << "not lost: settling changes nothing";
  EXPECT_FALSE(live.lost());
}

TEST(Liveness, APeerThatNeverSettlesIsBackAfterTheSettleLimitSoAMutualWaitEnds) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs));
  EXPECT_FALSE(live.check(401 * kMs, 1, kBound, "start").empty());
  const std::int64_t first = 1000 * kMs;
  const std::int64_t limit = std::chrono::nanoseconds(Liveness::kSettleLimit).count();
  EXPECT_EQ(limit, 5000 * kMs);
  EXPECT_FALSE(live.believed(first, first, "", kBound, true)) << "the wait starts here";
  EXPECT_FALSE(live.believed(first + limit, first + limit, "", kBound, true)) << "at the limit, not yet";
  EXPECT_TRUE(live.believed(first + limit + 1, first + limit + 1, "", kBound, true)) << "past it: back";
  // A later loss waits afresh.
  EXPECT_FALSE(live.check(first + limit + 1 + 301 * kMs, 1, kBound, "start").empty());
  const std::int64_t again = first + limit + 1000 * kMs;
  EXPECT_FALSE(live.believed(again, again, "", kBound, true)) << "a new loss's wait starts at its own heal";
}

TEST(Liveness, SettlingNeverEndsALossThatTheOtherRulesKeep) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs));
  EXPECT_FALSE(live.check(401 * kMs, 1, kBound, "start").empty());
  EXPECT_FALSE(live.believed(1000 * kMs, 1000 * kMs, "state:P.a", kBound, false)) << "behind: lost";
  EXPECT_FALSE(live.believed(5000 * kMs, 4000 * kMs, "", kBound, false)) << "a heartbeat sent 1 s ago: lost";
  EXPECT_TRUE(live.lost());
}

TEST(Liveness, CaughtUpClearsTheStreamsBehindUntilTheNextHeartbeatSaysOtherwise) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs, "state:P.a"));
  EXPECT_FALSE(beat(live, 300 * kMs, "state:P.a")) << "behind since 100 ms";
  live.caught_up();
  EXPECT_EQ(live.check(401 * kMs, 1, kBound, "start"), "") << "caught up by the update, before any heartbeat";
  EXPECT_FALSE(live.lost());
}

TEST(Liveness, TheWatchIsDueOneNanosecondPastTheBoundAfterTheLastHeartbeatAndCheckFindsTheLossExactlyThen) {
  Liveness live;
  constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(live.due(0, kBound, kRound), kNever) << "not watched yet: nothing is due";
  EXPECT_EQ(live.due(1000 * kMs, kBound, kRound), 1300 * kMs + 1)
      << "never heard from: the bound after the watch began";
  EXPECT_FALSE(beat(live, 1100 * kMs));
  const std::int64_t due = live.due(1000 * kMs, kBound, kRound);
  EXPECT_EQ(due, 1400 * kMs + 1);
  EXPECT_EQ(live.check(due - 1, 1000 * kMs, kBound, "start"), "") << "not a nanosecond before it is due";
  EXPECT_EQ(live.check(due, 1000 * kMs, kBound, "start"), "no heartbeat for 300 ms");
  EXPECT_EQ(live.due(1000 * kMs, kBound, kRound), due + kRound.count()) << "lost: only its renewal, a round on";
  EXPECT_TRUE(beat(live, 1500 * kMs));
  EXPECT_EQ(live.due(1000 * kMs, kBound, kRound), 1800 * kMs + 1);
}

TEST(Liveness, APeerStillLostASubscriptionRoundAfterItsLossBeganIsRenewedEachRoundUntilItIsBack) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs));
  EXPECT_EQ(live.renew_due(5000 * kMs, kRound), 0u) << "not lost: nothing to renew";
  ASSERT_NE(live.check(401 * kMs, 1, kBound, "start"), "") << "lost at 401 ms: the owner renews as the loss begins";
  EXPECT_EQ(live.due(1, kBound, kRound), 1401 * kMs) << "lost: the next renewal is due a round after the loss";
  EXPECT_EQ(live.renew_due(1400 * kMs, kRound), 0u) << "not a nanosecond before the round";
  EXPECT_EQ(live.renew_due(1401 * kMs, kRound), 1u) << "the first renewal of this loss: the owner says it";
  EXPECT_EQ(live.renew_due(1401 * kMs, kRound), 0u) << "said once a round";
  EXPECT_EQ(live.due(1, kBound, kRound), 2401 * kMs);
  EXPECT_EQ(live.renew_due(2500 * kMs, kRound), 2u) << "still lost: again, quietly";
  EXPECT_TRUE(beat(live, 2600 * kMs)) << "back";
  EXPECT_EQ(live.renew_due(9000 * kMs, kRound), 0u) << "back: nothing to renew";
  ASSERT_NE(live.check(2901 * kMs, 1, kBound, "start"), "");
  EXPECT_EQ(live.renew_due(3901 * kMs, kRound), 1u) << "a new loss counts its renewals afresh";
}

TEST(Liveness, ANewcomerHoldingAPeerLostFromItsStartRenewsItsSubscriptionsARoundLater) {
  // No loss begins for a peer held lost from the start: a member that took the newcomer's
  // subscriptions before the peer was proven would otherwise keep it lost for as long as it holds them.
  Liveness live;
  live.start_lost(1000 * kMs);
  EXPECT_EQ(live.check(5000 * kMs, 1000 * kMs, kBound, "start"), "") << "already lost: no loss begins";
  EXPECT_EQ(live.due(1000 * kMs, kBound, kRound), 2000 * kMs);
  EXPECT_EQ(live.renew_due(1999 * kMs, kRound), 0u);
  EXPECT_EQ(live.renew_due(2000 * kMs, kRound), 1u);
}

TEST(Liveness, AStreamBehindIsDueTheBoundAfterItFellBehindAndWhatComesOnlyMovesTheDueTimeLater) {
  Liveness live;
  EXPECT_FALSE(beat(live, 100 * kMs));
  const std::int64_t first = live.due(1, kBound, kRound);
  EXPECT_FALSE(beat(live, 200 * kMs, "state:P.a"));
  const std::int64_t behind = live.due(1, kBound, kRound);
  EXPECT_EQ(behind, 400 * kMs + 1) << "behind since the heartbeat before, at 100 ms";
  EXPECT_GE(behind, first) << "a new duty starts no earlier than the one before it";
  EXPECT_FALSE(beat(live, 400 * kMs, "state:P.a"));
  EXPECT_EQ(live.due(1, kBound, kRound), behind) << "still behind since 100 ms: due then, although beats keep coming";
  live.caught_up();
  EXPECT_EQ(live.due(1, kBound, kRound), 700 * kMs + 1) << "caught up: due a bound after the last heartbeat";
  EXPECT_EQ(live.check(700 * kMs, 1, kBound, "start"), "");
  EXPECT_EQ(live.check(700 * kMs + 1, 1, kBound, "start"), "no heartbeat for 300 ms");
}

// ---- EventStream: one follower's bookkeeping, for every receiver --------------------------------

using Took = EventStream::Took;
using Range = EventStream::Range;
constexpr std::int64_t kGrace = 250'000'000;  // ns

/// take() without a gap pushed out; a Late record's range is checked by the tests that need it.
Took take(EventStream& s, std::int64_t seq, std::int64_t now = 0) {
  std::optional<Range> range;
  const Took t = s.take(seq, now, range);
  EXPECT_EQ(range.has_value(), t == Took::Late) << "seq " << seq;
  return t;
}

TEST(EventStream, ARecordAfterASkippedRangeOpensAGapThatTheRecordsOfTheRangeFillInAnyOrder) {
  EventStream s;
  s.join(10);
  EXPECT_EQ(take(s, 11), Took::Next);
  EXPECT_EQ(take(s, 15), Took::Next);  // 12..14 did not come (yet)
  EXPECT_TRUE(s.has_gaps());
  EXPECT_EQ(s.last(), 15);
  EXPECT_EQ(take(s, 13), Took::Filled);
  EXPECT_EQ(take(s, 14), Took::Filled);
  EXPECT_EQ(take(s, 12), Took::Filled);
  EXPECT_FALSE(s.has_gaps());
  EXPECT_EQ(take(s, 13), Took::Again) << "received already: a duplicate or a replay";
}

TEST(EventStream, AGapStillOpenAfterTheGraceIsMissedOnceAndARecordOfItThatStillComesIsLateSaidOnce) {
  EventStream s;
  s.join(0);
  EXPECT_EQ(take(s, 5, 1'000), Took::Next);  // 1..4 missing
  EXPECT_FALSE(s.overdue(1'000 + kGrace - 1, kGrace)) << "within the grace: it may be on its way";
  const auto missed = s.overdue(1'000 + kGrace, kGrace);
  ASSERT_TRUE(missed);
  EXPECT_EQ(EventStream::text(*missed), "1..4");
  EXPECT_FALSE(s.overdue(1'000 + 2 * kGrace, kGrace)) << "missed once";
  std::optional<Range> range;
  EXPECT_EQ(s.take(3, 0, range), Took::Late);
  ASSERT_TRUE(range);
  EXPECT_EQ(EventStream::text(*range), "1..4") << "the range said late is the one said missed";
  EXPECT_EQ(take(s, 4), Took::LateAgain) << "its range was said to be late already";
  EXPECT_EQ(take(s, 3), Took::Again);
}

TEST(EventStream, WhatTheHeartbeatTwoBeforeListedAndThatHasNotComeIsMissedOnceAndTheStreamGoesOnAfterIt) {
  EventStream s;
  s.join(3);
  EXPECT_FALSE(s.heard(5));  // lists 4..5: on their way
  EXPECT_FALSE(s.heard(6)) << "one heartbeat later they may still be on the other topic";
  EXPECT_EQ(take(s, 4), Took::Next);
  const auto missed = s.heard(6);  // the heartbeat two before listed 5, which never came
  ASSERT_TRUE(missed);
  EXPECT_EQ(EventStream::text(*missed), "5");
  EXPECT_EQ(s.last(), 5);
  EXPECT_EQ(take(s, 6), Took::Next);
  EXPECT_FALSE(s.heard(6)) << "missed once";
  EXPECT_EQ(take(s, 5), Took::Late) << "what still comes of a missed range is taken, and said late";
  EXPECT_FALSE(s.heard(6));
}

TEST(EventStream, WhatWasSentBeforeTheJoinIsNotTakenAndAJumpBeyondTheLimitIsRefused) {
  EventStream s;
  s.join(100);
  EXPECT_EQ(take(s, 100), Took::Early);
  EXPECT_EQ(take(s, 7), Took::Early);
  EXPECT_EQ(take(s, 101 + kMaxSeqJump), Took::TooFar);
  EXPECT_EQ(s.last(), 100) << "a refused number moves nothing";
  EXPECT_EQ(take(s, 100 + kMaxSeqJump), Took::Next);
}

TEST(EventStream, MoreOpenGapsThanTheLimitPushTheOldestOutAsMissed) {
  EventStream s;
  s.join(0);
  for (std::size_t i = 0; i < EventStream::kMaxGaps; ++i)
    EXPECT_EQ(take(s, 2 * static_cast<std::int64_t>(i) + 2), Took::Next);
  std::optional<Range> pushed_out;
  EXPECT_EQ(s.take(2 * static_cast<std::int64_t>(EventStream::kMaxGaps) + 2, 0, pushed_out), Took::Next);
  ASSERT_TRUE(pushed_out);
  EXPECT_EQ(EventStream::text(*pushed_out), "1") << "the oldest gap, missed at once";
  EXPECT_EQ(take(s, 1), Took::Late);
  EXPECT_EQ(take(s, 3), Took::Filled);
}

TEST(EventStream, RecordsReadFromTheHistoryCloseEveryGapBelowThem) {
  EventStream s;
  s.join(0);
  EXPECT_EQ(take(s, 3), Took::Next);
  EXPECT_EQ(take(s, 9), Took::Next);  // gaps 1..2 and 4..8
  s.caught_up(5);
  EXPECT_TRUE(s.has_gaps()) << "6..8 not read yet";
  EXPECT_EQ(take(s, 4), Took::Again);
  EXPECT_EQ(take(s, 7), Took::Filled);
  s.caught_up(12);
  EXPECT_FALSE(s.has_gaps());
  EXPECT_EQ(s.last(), 12);
  EXPECT_EQ(take(s, 13), Took::Next);
}

TEST(IncarnationBounds, AnIncarnationNotPositiveOrMoreThanAMinuteAheadOfTheClockIsRefused) {
  EXPECT_TRUE(incarnation_out_of_bounds("a heartbeat", "robot", new_incarnation()).empty());
  EXPECT_FALSE(incarnation_out_of_bounds("a heartbeat", "robot", 0).empty());
  EXPECT_FALSE(incarnation_out_of_bounds("a heartbeat", "robot", new_incarnation() + 61'000'000'000).empty());
}

/// Two members' keys (robot, ui) and a communicator to encode with.
struct Members2 {
  std::shared_ptr<Ice::Communicator> ic = Ice::initialize();
  std::optional<Keyring> keys;
  std::optional<Signer> robot;
  Members2() {
    spec::SystemSpec system;
    system.name = "two";
    system.coordinators = {{"robot", {"JR3"}}, {"ui", {"PENDANT"}}};
    const std::string dir = ::testing::TempDir() + "safecass-receiver-keys-" + std::to_string(::getpid());
    EXPECT_TRUE(create_bus_keys(system, dir, KeyOptions::replacing()));
    auto k = Keyring::load(dir);
    EXPECT_TRUE(k);
    keys = std::move(*k);
    auto s = Signer::load(dir, "robot", *keys);
    EXPECT_TRUE(s);
    robot = std::move(*s);
  }
  ~Members2() { ic->destroy(); }
  wire::Signed beat(const std::string& coordinator, std::int64_t incarnation) const {
    wire::Heartbeat h;
    h.coordinator = coordinator;
    h.incarnation = incarnation;
    h.seq = 1;
    return robot->sign(kKindHeartbeat, encode(ic, h));
  }
};

TEST(OpenHeartbeat, AHeartbeatIsOpenedOnlySignedAsAHeartbeatNamingItsSignerAndOfAnIncarnationWithinBounds) {
  Members2 m;
  ASSERT_TRUE(m.robot);
  const OpenedHeartbeat good = open_heartbeat(*m.keys, m.ic, m.beat("robot", new_incarnation()));
  EXPECT_TRUE(good.why.empty()) << good.why;
  EXPECT_EQ(good.beat.coordinator, "robot");

  const OpenedHeartbeat other = open_heartbeat(*m.keys, m.ic, m.beat("ui", new_incarnation()));
  EXPECT_NE(other.why.find("naming 'ui' signed by 'robot'"), std::string::npos) << other.why;
  EXPECT_EQ(other.source, "robot");

  wire::Signed tampered = m.beat("robot", new_incarnation());
  tampered.body.back() ^= 1;
  const OpenedHeartbeat forged = open_heartbeat(*m.keys, m.ic, tampered);
  EXPECT_NE(forged.why.find("a heartbeat signed 'robot'"), std::string::npos) << forged.why;

  wire::Signed as_state = m.robot->sign("state", m.beat("robot", new_incarnation()).body);
  EXPECT_FALSE(open_heartbeat(*m.keys, m.ic, as_state).why.empty()) << "another kind";

  // Out of bounds: refused under a source of its own, so that no other refusal hides it.
  for (const std::int64_t incarnation : {std::int64_t{0}, std::int64_t{INT64_MAX - 1}}) {
    const OpenedHeartbeat far = open_heartbeat(*m.keys, m.ic, m.beat("robot", incarnation));
    EXPECT_NE(far.why.find("incarnation"), std::string::npos) << far.why;
    EXPECT_EQ(far.source, "robot/incarnation");
  }
}

}  // namespace
// Missed records are said, all of them (a rate limit that dropped a line would lose records
// unreported after a broker failover, when gaps come in bursts), in at most one line a second.
TEST(MissedRecords, EveryMissedRecordIsSaidTheFirstRangeAtOnceAndThoseOfTheSameSecondSummedInTheNextLine) {
  constexpr std::int64_t kSecond = MissedRecords::kInterval;
  MissedRecords m;
  EXPECT_EQ(m.due_at(), std::numeric_limits<std::int64_t>::max()) << "nothing waits";
  EXPECT_FALSE(m.take(0, "robot"));
  m.add(Range{5, 10});
  EXPECT_EQ(m.take(100, "robot"), "6 event record(s) of 'robot' missed (seq 5..10)") << "the first: at once";
  m.add(Range{20, 22});
  m.add(Range{23, 23});  // adjoins the range before it
  m.add(Range{30, 30});
  EXPECT_EQ(m.due_at(), 100 + kSecond);
  EXPECT_FALSE(m.take(100 + kSecond - 1, "robot")) << "within the second of the last line: waits";
  EXPECT_EQ(m.take(100 + kSecond, "robot"), "5 event record(s) of 'robot' missed (seq 20..23, 30)")
      << "none left unsaid";
  EXPECT_FALSE(m.take(100 + 5 * kSecond, "robot")) << "said once";
}

TEST(MissedRecords, ManyRangesAreCountedExactlyAndListedUpToALimitAndWhatWaitsIsSaidWhenTheReceiverStops) {
  MissedRecords m;
  m.add(Range{1, 1});
  ASSERT_TRUE(m.take(0, "robot"));  // the first line: the next waits a second
  for (std::int64_t i = 0; i < 20; ++i) m.add(Range{10 + 2 * i, 10 + 2 * i});
  EXPECT_FALSE(m.take(1, "robot"));
  const auto line = m.take(1, "robot", true);
  ASSERT_TRUE(line) << "the receiver stops: what waits is said now";
  EXPECT_EQ(*line, "20 event record(s) of 'robot' missed (seq 10, 12, 14, 16, 18, 20, 22, 24 and 12 more range(s))");
}

}  // namespace safecass::middleware

namespace safecass::middleware {
namespace {

// Nothing from outside reaches a log unbounded (DESIGN §7): one line per source per second, and at
// most DropLog::kLinesPerSecond lines a second in all, however many sources a flood names; the
// next line says how many were suppressed, and every refusal is counted.
TEST(DropLogTest, AFloodFromManySourcesLogsAtMostTheTotalBudgetPerSecondAndCountsEveryRefusal) {
  std::vector<std::string> lines;
  DropLog log([&](const std::string& line) { lines.push_back(line); });
  for (int i = 0; i < 1000; ++i) log.drop("source-" + std::to_string(i % 300), "refused message " + std::to_string(i));
  EXPECT_EQ(log.count(), 1000u);
  EXPECT_EQ(lines.size(), DropLog::kLinesPerSecond);
  // A note (not a refusal) is rate-limited the same way and not counted.
  log.note("peer/republish", "asked it to republish");
  EXPECT_EQ(log.count(), 1000u);
  EXPECT_EQ(lines.size(), DropLog::kLinesPerSecond) << "the budget of this second is spent";
}

TEST(DropLogTest, TheFirstLineAfterTheBudgetSaysHowManyLinesWereSuppressed) {
  std::vector<std::string> lines;
  DropLog log([&](const std::string& line) { lines.push_back(line); });
  for (std::uint64_t i = 0; i < DropLog::kLinesPerSecond + 5; ++i) log.drop("s" + std::to_string(i), "refused");
  ASSERT_EQ(lines.size(), DropLog::kLinesPerSecond);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // the next second of the budget
  log.drop("another", "refused");
  ASSERT_EQ(lines.size(), DropLog::kLinesPerSecond + 1);
  EXPECT_NE(lines.back().find("(5 more line(s) of every source suppressed: at most 8 a second)"), std::string::npos)
      << lines.back();
}

TEST(DropLogTest, WhatTheLimitHeldBackIsSaidOnceItsSecondIsOverWhenNoLaterLineOfItsSourceSaidIt) {
  std::vector<std::string> lines;
  DropLog log([&](const std::string& line) { lines.push_back(line); });
  const std::int64_t start =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  constexpr std::int64_t kSecond = 1'000'000'000;
  for (int i = 0; i < 4; ++i) log.drop("robot/records", "refused a record");
  log.note("robot", "a note");
  log.flush("supervisor", start);
  ASSERT_EQ(lines.size(), 2u) << "within the second: held back still";
  log.flush("supervisor", start + 2 * kSecond);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines.back(), "supervisor: lines held back by the rate limit and not said since: 3 from 'robot/records'");
  log.flush("supervisor", start + 4 * kSecond);
  EXPECT_EQ(lines.size(), 3u) << "said once";
  EXPECT_EQ(log.count(), 4u);
}

}  // namespace
}  // namespace safecass::middleware

namespace safecass::middleware {
namespace {

// Found by tests/fuzz/wire_events_fuzz.cpp: a member's sealed event batch of 31 bytes declared
// 33,554,431 messages; Ice 3.7's 32-bit check of size x minimum size wrapped, and the receiver
// built a vector of 13 GB before reading the first message. A sequence of structs declaring more
// elements than the bytes left can hold is now refused (ice_sequences.hpp), allocating nothing.
TEST(Decode, ABatchDeclaringMoreMessagesThanItsBytesCanHoldIsRefusedWithoutBuildingThem) {
  const std::shared_ptr<Ice::Communicator> ice = Ice::initialize();
  const Ice::ByteSeq body{0xff, 0xff, 0xff, 0xff, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                          0x02, 0xff, 0x09, 0x00, 0x73, 0x61, 0x76, 0x65, 0x2d, 0xff, 0xff,
                          0x60, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x05};
  wire::EventMessageSeq batch;
  EXPECT_FALSE(decode(ice, body, batch));
  EXPECT_TRUE(batch.empty());
  // A genuine batch still decodes.
  wire::EventMessage m{};  // every field set: an enum left undefined does not encode
  m.coordinator = "robot";
  m.seq = 1;
  const wire::EventMessageSeq sent{m, m};
  wire::EventMessageSeq received;
  ASSERT_TRUE(decode(ice, encode(ice, sent), received));
  EXPECT_EQ(received.size(), 2U);
  EXPECT_EQ(received[1].coordinator, "robot");
  ice->destroy();
}

}  // namespace
}  // namespace safecass::middleware

namespace safecass::middleware {
namespace {

// Ice 3.7 checks a sequence's declared size as start + size x minimum size in 32 bits, which wraps
// for a size near 2^31: a byte, double or string sequence declaring that many elements must be
// refused, not read past the message or allocated.
Ice::ByteSeq with_huge_size(Ice::ByteSeq prefix, std::int32_t size) {
  prefix.push_back(0xff);
  for (int k = 0; k < 4; ++k)
    prefix.push_back(static_cast<Ice::Byte>((static_cast<std::uint32_t>(size) >> (8 * k)) & 0xff));
  for (int k = 0; k < 16; ++k) prefix.push_back(0x41);
  return prefix;
}

TEST(Decode, ASignedMessageWhoseBodyDeclaresNearlyTwoGigabytesIsRefused) {
  const std::shared_ptr<Ice::Communicator> ice = Ice::initialize();
  for (std::int32_t size : {0x7fffffff, 0x7ffffff0, 0x7fffff00}) {
    wire::Signed m;
    EXPECT_FALSE(decode(ice, with_huge_size({0x01, 0x61, 0x01, 0x62}, size), m)) << size;
  }
  ice->destroy();
}

TEST(Decode, AParameterWhoseNumbersOrTextsDeclareTooManyIsRefused) {
  const std::shared_ptr<Ice::Communicator> ice = Ice::initialize();
  for (std::int32_t size : {0x20000000, 0x40000000, 0x60000000, 0x7fffffff, 0x7ffffff0}) {
    // kind "a", number 0.0, flag false, text "", then the texts' size
    Ice::ByteSeq texts{0x01, 0x61, 0, 0, 0, 0, 0, 0, 0, 0, 0x00, 0x00};
    wire::ParamValue v;
    EXPECT_FALSE(decode(ice, with_huge_size(texts, size), v)) << size;
    Ice::ByteSeq numbers = texts;
    numbers.push_back(0x00);  // no texts, then the numbers' size
    EXPECT_FALSE(decode(ice, with_huge_size(numbers, size), v)) << size;
  }
  ice->destroy();
}

TEST(Decode, ABatchDecodedIntoAReusedOneHoldsOnlyTheNewBatch) {
  const std::shared_ptr<Ice::Communicator> ice = Ice::initialize();
  wire::StateUpdate a{1, 1, wire::Level::Error, {}, 5};
  a.roots.push_back(wire::Root{"EVT_FORCE", "JR3.s_A", 7, wire::Level::Error, "f", "force", 2.5, 6, false, {"JR3"}});
  wire::StateUpdate b = a;
  b.stream = 2;
  const wire::StateUpdate c{0, 2, wire::Level::Normal, {}, 9};
  wire::StateBatch batch;
  ASSERT_TRUE(decode(ice, encode(ice, wire::StateBatch{"robot", kRun, 11, {a, b, a}}), batch));
  ASSERT_EQ(batch.updates.size(), 3U);
  ASSERT_TRUE(decode(ice, encode(ice, wire::StateBatch{"robot", kRun, 11, {c}}), batch));
  ASSERT_EQ(batch.updates.size(), 1U);
  EXPECT_EQ(batch.updates[0], c);  // no root, no field of the earlier batch's first update is left
  ice->destroy();
}

wire::Signed signed_heartbeat(std::int64_t seq) {
  wire::Signed m;
  m.signer = "robot";
  m.kind = std::string(kKindHeartbeat);
  m.body = {static_cast<Ice::Byte>(seq), 2, 3};
  m.signature.assign(64, static_cast<Ice::Byte>(seq));
  return m;
}

TEST(SentHeartbeats, AHeartbeatComingBackIsKnownOnlyAsOneOfTheLastSentByteForByte) {
  SentHeartbeats sent;
  EXPECT_FALSE(sent.holds(wire::Signed{}));  // nothing sent: an empty message is not one
  for (std::int64_t k = 1; k <= 10; ++k) sent.sent(signed_heartbeat(k));
  // The last kKept are known, the older ones are not (late or replayed: no news).
  for (std::int64_t k = 1; k <= 10; ++k)
    EXPECT_EQ(sent.holds(signed_heartbeat(k)), k > 10 - static_cast<std::int64_t>(SentHeartbeats::kKept)) << k;
  EXPECT_FALSE(sent.holds(wire::Signed{}));
  // A sent one with any field changed is not one of them: it is checked as any heartbeat.
  wire::Signed other_body = signed_heartbeat(10);
  other_body.body.back() = 4;
  wire::Signed other_signer = signed_heartbeat(10);
  other_signer.signer = "ui";
  wire::Signed other_signature = signed_heartbeat(10);
  other_signature.signature[63] ^= 1;
  wire::Signed other_kind = signed_heartbeat(10);
  other_kind.kind = "proof";
  for (const wire::Signed& m : {other_body, other_signer, other_signature, other_kind}) EXPECT_FALSE(sent.holds(m));
}

}  // namespace
}  // namespace safecass::middleware
