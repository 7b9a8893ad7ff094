// The bus model is the code (docs/verify.md "The bus"): SPIN's random simulations of
// verify/bus/bus.pml, for every pattern of robodoc's deployment, drive the real receiver classes
// (PeerFreshness, Liveness, Members, incarnation_out_of_bounds) through the same steps as the
// node's glue (node.cpp believe/on_update/declare_lost), and every decision the model prints (each
// message believed, refused, unproven or covered; each proof taken, refused or too late; each loss
// and recovery) must be the classes' decision. The Prover's network part (its connection and
// certificate checks) needs Ice and is covered by the Wire tests; its one timing rule, a proof
// answered later than a period is refused, is mirrored here.

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "receiver.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/verify/bus.hpp"

namespace safecass::middleware {
namespace {

constexpr std::int64_t kTick = 50'000'000;           // ns: half of robodoc's 100 ms period
constexpr std::int64_t kBase = 1'000'000'000'000;    // the receiver's steady clock at tick 0
constexpr std::int64_t kRemote = 7'000'000'000'000;  // the provider's steady clock at tick 0
constexpr int kTicksPerPeriod = 2;
constexpr int kWildIncarnation = 9;  // the model's WILDINC
constexpr int kNone = 255;           // the model's NONE

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  for (std::string x; in >> x;) w.push_back(x);
  return w;
}

/// One simulation replayed into the receiver classes. The provider is "robot", running component
/// "P" with streams P.s0 and P.s1; another member, "mallory", runs "M".
class Replay {
public:
  Replay(const verify::BusPattern& pattern, const spec::SystemSpec& system)
      : pattern_(pattern),
        members_(system),
        bound_(std::chrono::milliseconds(pattern.bound_ticks * kTick / 1'000'000)) {
    restart_receiver();
  }

  /// Feeds one "@ ..." line; returns false with `why` on the first decision that differs.
  bool feed(const std::string& line, std::string& why) {
    const auto w = words(line);
    if (w.empty()) return true;
    const std::string& k = w[0];
    if (k == "tick") {
      watch();
      ++tick_;
    } else if (k == "pstart") {
      inc_ = std::stoi(w[1]);
      beats_[inc_].clear();
      latest_[inc_] = {0, 0};
    } else if (k == "beat") {
      beats_[inc_].push_back(tick_);
    } else if (k == "pub") {
      ++latest_[inc_][std::stoul(w[1])];
    } else if (k == "rstart") {
      restart_receiver();
    } else if (k == "hb") {
      on_heartbeat(std::stoi(w[1]), std::stoi(w[2]), {std::stoi(w[3]), std::stoi(w[4])}, w[5] == "1");
    } else if (k == "st") {
      on_update(std::stoi(w[1]), std::stoi(w[2]), std::stoul(w[3]), std::stoi(w[4]), std::stoi(w[5]));
    } else if (k == "proof") {
      on_proof(std::stoi(w[1]), std::stoi(w[3]), w[4] == "1");
    } else if (k == "v" || k == "lost" || k == "recovered") {
      model_.push_back(k == "v" ? w[1] : k);
    }
    if (model_.size() > ours_.size()) return true;  // the decision of the next message is the model's first
    for (std::size_t i = checked_; i < model_.size(); ++i) {
      if (model_[i] != ours_[i]) {
        why = "decision " + std::to_string(i) + " at tick " + std::to_string(tick_) + ": the model says '" + model_[i] +
              "', the classes '" + ours_[i] + "' (line '" + line + "'); the model:";
        for (const std::string& d : model_) why += " " + d;
        why += "; the classes:";
        for (const std::string& d : ours_) why += " " + d;
        return false;
      }
    }
    checked_ = model_.size();
    return true;
  }
  /// Every decision both made, in order; false when the classes made one the model did not.
  bool finish(std::string& why) const {
    if (ours_.size() != model_.size()) {
      why = "the classes made " + std::to_string(ours_.size()) + " decisions, the model " +
            std::to_string(model_.size()) + "; the model:";
      for (const std::string& d : model_) why += " " + d;
      why += "; the classes:";
      for (const std::string& d : ours_) why += " " + d;
      return false;
    }
    return true;
  }
  std::size_t decisions() const { return model_.size(); }

private:
  struct Held {
    std::int64_t incarnation = 0;
    std::int64_t seq = 0;
    bool behind = false;
  };

  std::int64_t now() const { return kBase + tick_ * kTick; }
  static std::string stream(std::size_t s) { return state_stream(s == 0 ? "P.s0" : "P.s1"); }
  /// The provider's state streams, both followed whatever the run simulates (a stream never sent
  /// on stays at 0); slot s is stream s.
  static const StateStreams& provider_streams() {
    static const StateStreams streams = StateStreams::of({"P.s0", "P.s1"});
    return streams;
  }
  /// A heartbeat of the provider (or the one a proof carries) listing `listed`.
  static wire::Heartbeat provider_beat(std::int64_t incarnation, std::int64_t seq,
                                       const std::array<std::int64_t, 2>& listed) {
    wire::Heartbeat beat;
    beat.coordinator = "robot";
    beat.incarnation = incarnation;
    beat.seq = seq;
    beat.states = {listed[0], listed[1]};
    beat.statesId = provider_streams().id;
    return beat;
  }
  /// The model's incarnation k as a start time: sane ones in the past, in order; WILDINC beyond
  /// the margin.
  std::int64_t incarnation(int k) const {
    if (k == kWildIncarnation) return wall_ + 2 * std::chrono::nanoseconds(kIncarnationMargin).count();
    return wall_ - std::int64_t{1'000'000'000'000} + k * std::int64_t{1'000'000'000};
  }
  /// A stream number as the model holds it (distance below the latest of incarnation `k`, plus
  /// one; 0 far ahead; NONE nothing) as the number the provider sent.
  std::int64_t number(int k, std::size_t s, int relative) const {
    const auto it = latest_.find(k);
    const std::int64_t latest = it == latest_.end() ? 0 : it->second[s];
    if (relative == kNone) return 0;
    if (relative == 0) return latest + kMaxSeqJump + 1;
    return latest - (relative - 1);
  }
  std::int64_t beat_number(int k, int sent_tick) const {
    const auto it = beats_.find(k);
    std::int64_t n = 0;
    if (it != beats_.end()) {
      for (const int t : it->second) n += t <= sent_tick ? 1 : 0;
    }
    return n;
  }

  void restart_receiver() {
    fresh_ = PeerFreshness{};
    fresh_.follow(provider_streams());
    // The model's wait for a settling provider: it holds while fewer than SL ticks have passed.
    live_ = Liveness{std::chrono::milliseconds((verify::kBusSettleLimitTicks - 1) * kTick / 1'000'000)};
    held_[0] = held_[1] = Held{};
    behind_ = 0;
    watched_since_ = now();
    if (pattern_.watch_start) live_.start_lost(now());
  }

  /// `settling`: the heartbeat lists losses of the provider's own (Heartbeat::settling).
  void believe(std::int64_t incarnation, std::int64_t sent, const std::array<std::int64_t, 2>& listed, bool settling) {
    std::string behind;
    for (std::size_t s = 0; s < streams(); ++s) {
      Held& h = held_[s];
      const std::int64_t have = h.incarnation == incarnation ? h.seq : 0;
      const bool is_behind = listed[s] > have;
      if (is_behind != h.behind) is_behind ? ++behind_ : --behind_;
      h.behind = is_behind;
      if (is_behind && behind.empty()) behind = stream(s);
    }
    if (live_.believed(now(), sent, behind, bound_, settling)) ours_.push_back("recovered");
  }
  std::size_t streams() const { return simulated_streams_; }

  void on_heartbeat(int k, int age, std::array<int, 2> relative, bool settling) {
    const std::int64_t real = incarnation(k);
    if (!incarnation_out_of_bounds("a heartbeat", "robot", real).empty()) {
      ours_.push_back("refuse");
      return;
    }
    const int sent_tick = tick_ - age;
    std::string why;
    const std::array<std::int64_t, 2> listed{number(k, 0, relative[0]), number(k, 1, relative[1])};
    switch (fresh_.heartbeat(provider_beat(real, beat_number(k, sent_tick), listed), why)) {
      case PeerFreshness::Verdict::Refuse: ours_.push_back("refuse"); return;
      case PeerFreshness::Verdict::Unproven: ours_.push_back("unproven"); return;
      case PeerFreshness::Verdict::Covered: ours_.push_back("covered"); return;
      case PeerFreshness::Verdict::Accept: ours_.push_back("accept"); break;
    }
    believe(real, fresh_.sent_at(kRemote + sent_tick * kTick, now()), listed, settling);
  }

  void on_update(int who, int k, std::size_t s, int relative, int) {
    if (!members_.runs(who == 0 ? "robot" : "mallory", "P")) {
      ours_.push_back("refuse");
      return;
    }
    const std::int64_t real = incarnation(k);
    const std::int64_t seq = number(k, s, relative);
    std::int64_t missed = 0;
    std::string why;
    switch (fresh_.stream(PeerFreshness::Slot{s}, real, seq, missed, why)) {
      case PeerFreshness::Verdict::Refuse: ours_.push_back("refuse"); return;
      case PeerFreshness::Verdict::Covered:
      case PeerFreshness::Verdict::Unproven: ours_.push_back("unproven"); return;
      case PeerFreshness::Verdict::Accept: ours_.push_back("accept"); break;
    }
    Held& h = held_[s];
    h.incarnation = real;
    h.seq = seq;
    if (h.behind) {
      h.behind = false;
      if (--behind_ == 0) live_.caught_up();
    }
  }

  void on_proof(int k, int asked_ago, bool settling) {
    const std::int64_t asked = now() - asked_ago * kTick;
    if (asked_ago > kTicksPerPeriod) {  // Prover: an answer later than a period is refused
      ours_.push_back("late");
      return;
    }
    const std::int64_t real = incarnation(k);
    if (!incarnation_out_of_bounds("a proof", "robot", real).empty()) {
      ours_.push_back("refuse");
      return;
    }
    wire::Heartbeat beat = provider_beat(real, static_cast<std::int64_t>(beats_[k].size()),
                                         {streams() > 0 ? latest_[k][0] : 0, streams() > 1 ? latest_[k][1] : 0});
    beat.time = kRemote + tick_ * kTick;
    std::string why;
    if (!fresh_.proven(beat, why, asked)) {
      ours_.push_back("refuse");
      return;
    }
    ours_.push_back("accept");
    believe(real, asked, {latest_[k][0], latest_[k][1]}, settling);
  }

  void watch() {
    const bool watched = pattern_.watch_start || live_.last_beat() != 0;
    if (!watched || live_.check(now(), watched_since_, bound_, "start").empty()) return;
    ours_.push_back("lost");
    if (pattern_.forget) {
      fresh_.forget();
    } else {
      fresh_.doubt();
    }
  }

public:
  std::size_t simulated_streams_ = 1;

private:
  const verify::BusPattern& pattern_;
  /// The wall clock when the run began: the incarnations' start times are read against it.
  const std::int64_t wall_ =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  Members members_;
  std::chrono::milliseconds bound_;
  PeerFreshness fresh_;
  Liveness live_;
  std::array<Held, 2> held_;
  std::size_t behind_ = 0;
  std::int64_t watched_since_ = 0;
  int tick_ = 0;
  int inc_ = 1;
  std::map<int, std::vector<int>> beats_;
  std::map<int, std::array<std::int64_t, 2>> latest_{{1, {0, 0}}};
  std::vector<std::string> model_, ours_;
  std::size_t checked_ = 0;
};

spec::SystemSpec deployment() {
  const char* text = R"({ "safecass": 1, "system": "conformance",
    "components": [ { "component": "P", "interfaces": { "provided": ["s0", "s1"], "required": [] } },
                    { "component": "M", "interfaces": { "provided": [], "required": [] } } ],
    "connections": [], "coordinators": { "robot": ["P"], "mallory": ["M"] } })";
  FilterRegistry registry;
  register_builtin_filters(registry);
  spec::LoadResult r = spec::load_system_from_text(text, "conformance.json", registry);
  EXPECT_TRUE(r.ok());
  return r.system ? *r.system : spec::SystemSpec{};
}

TEST(BusConformance, TheReceiverClassesDecideEveryMessageProofAndLossAsTheModelDoesInItsRandomRuns) {
  const spec::SystemSpec system = deployment();
  FilterRegistry registry;
  register_builtin_filters(registry);
  spec::LoadResult robodoc =
      spec::load_system(std::string(SAFECASS_SOURCE_DIR) + "/examples/robodoc/robodoc.json", registry);
  ASSERT_TRUE(robodoc.ok());
  auto patterns = verify::bus_patterns(*robodoc.system, verify::BusOptions{});
  ASSERT_TRUE(patterns) << patterns.error().message;
  // Every fault and attack, a dozen times a run: a simulation has no state space to outgrow. Few
  // long runs rather than many short ones: starting SPIN (reading and building the model) takes
  // about 45 ms, 8,000 steps 1 ms more. A run of 32,000 steps passes about 150 ticks (75 periods),
  // so a dozen of each fault keeps their density of three in 8,000 steps.
  verify::BusFaultClass all;
  all.name = "conformance";
  all.crash = all.cut = all.unsubscribe = all.broker = all.flip = all.replay = all.forge = all.wild =
      all.receiver_restart = all.drop = all.settle = 12;
  constexpr unsigned kRuns = 50;  // per pattern: 250 runs over robodoc's five, 8 million steps
  constexpr std::size_t kSteps = 32'000;
  std::size_t decisions = 0, runs = 0;
  std::map<std::string, std::size_t> kinds;
  for (const verify::BusPattern& pattern : *patterns) {
    for (const bool two : {false, true}) {
      if (two && pattern.streams < 2) continue;
      all.two_streams = two;
      std::string failed;  // the first run the receiver classes decided otherwise than the model
      auto simulated = verify::simulate_bus(
          pattern, all, kRuns, kSteps, verify::BusOptions{}, [&](unsigned seed, std::vector<std::string>& lines) {
            Replay replay(pattern, system);
            replay.simulated_streams_ = two ? 2 : std::min<std::size_t>(pattern.streams, 1);
            // The run stops after a number of steps, maybe between a message and its verdict: it
            // is read up to its last whole tick.
            while (!lines.empty() && lines.back() != "tick") lines.pop_back();
            std::string why;
            bool same = true;
            for (const std::string& line : lines) {
              if (same = replay.feed(line, why); !same) break;
              const auto w = words(line);
              if (!w.empty() && (w[0] == "v" || w[0] == "lost" || w[0] == "recovered"))
                ++kinds[w[0] == "v" ? w[1] : w[0]];
            }
            if (same) same = replay.finish(why);
            if (!same) failed = pattern.pairs.front() + ", seed " + std::to_string(seed) + ": " + why;
            decisions += replay.decisions();
            ++runs;
            return failed.empty();
          });
      ASSERT_TRUE(simulated) << simulated.error().message;
      ASSERT_EQ(failed, "");
    }
  }
  EXPECT_GT(decisions, 10'000u);
  for (const char* kind : {"accept", "refuse", "unproven", "covered", "late", "lost", "recovered"}) {
    EXPECT_GT(kinds[kind], 0u) << "no decision '" << kind << "' in " << runs << " runs: the runs miss a rule";
  }
  RecordProperty("runs", static_cast<int>(runs));
  RecordProperty("decisions", static_cast<int>(decisions));
}

}  // namespace
}  // namespace safecass::middleware
