// Replay throughput (docs/benchmarks.md, "Replay"): samples per second from a SAFECASS input
// recording and from a CSV log, read alone and fed through a system. The log: 20 scalar signals
// at 1 kHz (one sample of each per millisecond), 60 s of it = 1.2 million samples; the system: 4
// components × 5 signals, each judged by a Threshold filter every 1 ms tick. The target: one hour
// of such a log (72 million samples) replays in under 40 s on one core. Rates are per CPU second
// of the benchmark's thread (the machine is shared; wall-clock time is noisier).

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/record/input_log.hpp"
#include "safecass/replay/replay.hpp"
#include "safecass/replay/source.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/load.hpp"

namespace safecass {
namespace {

constexpr int kComponents = 4;
constexpr int kPerComponent = 5;
constexpr int kSignals = kComponents * kPerComponent;
constexpr int kSeconds = 60;
constexpr int kTicks = kSeconds * 1000;
constexpr std::int64_t kSamples = std::int64_t{kTicks} * kSignals;

std::string dir() {
  static const std::string d = [] {
    char t[] = "/tmp/safecass-bench-replay-XXXXXX";
    const char* made = ::mkdtemp(t);
    return std::string(made != nullptr ? made : ".");
  }();
  return d;
}

std::string name(int s) { return "C" + std::to_string(s / kPerComponent) + ".s" + std::to_string(s % kPerComponent); }
double value(int tick, int s) { return 10.0 + 5.0 * std::sin(tick * 0.001 + s); }  // never above the limit

const std::string& system_file() {
  static const std::string path = [] {
    std::string text = "{ \"safecass\": 1, \"system\": \"bench\", \"components\": [\n";
    for (int c = 0; c < kComponents; ++c) {
      const std::string C = "C" + std::to_string(c);
      text += std::string(c ? ",\n" : "") + "{ \"component\": \"" + C + "\", \"period\": 0.001, \"interfaces\": {},\n" +
              "  \"signals\": [";
      for (int k = 0; k < kPerComponent; ++k)
        text += std::string(k ? ", " : "") + "{ \"name\": \"s" + std::to_string(k) + "\" }";
      text += "],\n  \"event\": [ { \"name\": \"EVT_" + C +
              "\", \"severity\": 50, \"state_transition\": [\"N2E\"] },\n" + "             { \"name\": \"/EVT_" + C +
              "\", \"severity\": 50, \"state_transition\": [\"E2N\"] } ],\n  \"filter\": [";
      for (int k = 0; k < kPerComponent; ++k) {
        text += std::string(k ? ",\n" : "\n") + "    { \"name\": \"limit_" + C + "_" + std::to_string(k) +
                "\", \"class_name\": \"Threshold\", \"target\": { \"type\": \"s_A\", \"component\": \"" + C +
                "\" }, \"argument\": { \"input_signal\": \"s" + std::to_string(k) + "\", \"threshold\": 100.0, " +
                "\"event_onset\": \"EVT_" + C + "\", \"event_completion\": \"/EVT_" + C + "\" } }";
      }
      text += " ] }";
    }
    text += "],\n \"connections\": [] }\n";
    const std::string p = dir() + "/bench.json";
    std::ofstream(p) << text;
    return p;
  }();
  return path;
}

const std::string& recording_file() {
  static const std::string path = [] {
    const std::string p = dir() + "/bench.inputs";
    std::ofstream f(p, std::ios::binary);
    std::string out;
    InputLogHeader h;
    h.period = std::chrono::milliseconds(1);
    input_log::put_header(out, h);
    for (int s = 0; s < kSignals; ++s) input_log::put_signal(out, static_cast<std::uint16_t>(s), 1, name(s));
    for (int t = 0; t < kTicks; ++t) {
      input_log::put_time(out, std::chrono::milliseconds(t));
      for (int s = 0; s < kSignals; ++s) {
        const double v = value(t, s);
        input_log::put_sample(out, static_cast<std::uint16_t>(s), &v, 1);
      }
      if (out.size() > (1 << 20)) {
        f << out;
        out.clear();
      }
    }
    input_log::put_end(out, std::chrono::milliseconds(kTicks - 1));
    f << out;
    return p;
  }();
  return path;
}

const std::string& csv_file() {
  static const std::string path = [] {
    const std::string p = dir() + "/bench.csv";
    std::FILE* f = std::fopen(p.c_str(), "w");
    std::fprintf(f, "time");
    for (int s = 0; s < kSignals; ++s) std::fprintf(f, ",%s", name(s).c_str());
    std::fprintf(f, "\n");
    for (int t = 0; t < kTicks; ++t) {
      std::fprintf(f, "%.3f", t * 0.001);
      for (int s = 0; s < kSignals; ++s) std::fprintf(f, ",%.6f", value(t, s));
      std::fprintf(f, "\n");
    }
    std::fclose(f);
    return p;
  }();
  return path;
}

/// The bench system, composed as `safecass replay` composes it (for binding a source).
struct BenchSystem {
  FilterRegistry registry;
  std::unique_ptr<runner::ScenarioRunner> runner;
  BenchSystem() {
    register_builtin_filters(registry);
    spec::LoadResult sys = spec::load_system(system_file(), registry);
    spec::Scenario sc;
    sc.system = system_file();
    runner = std::move(*runner::ScenarioRunner::open(std::move(sc), std::move(*sys.system), registry));
  }
};

void read_all(benchmark::State& state, const std::function<std::unique_ptr<InputSource>()>& open) {
  (void)recording_file();  // the logs are written once, before anything is timed
  (void)csv_file();
  BenchSystem sys;
  std::int64_t total = 0;
  for (auto _ : state) {
    auto src = open();
    if (!src->bind(sys.runner->monitor())) state.SkipWithError("bind failed");
    std::int64_t n = 0;
    for (InputItem i = src->next(); i.kind != InputItem::Kind::End; i = src->next()) {
      if (i.kind == InputItem::Kind::Error) {
        state.SkipWithError(src->error().c_str());
        break;
      }
      benchmark::DoNotOptimize(i.values);
      ++n;
    }
    if (n != kSamples) state.SkipWithError("wrong sample count");
    total += n;
  }
  state.SetItemsProcessed(total);
  state.counters["samples/s"] = benchmark::Counter(static_cast<double>(total), benchmark::Counter::kIsRate);
}

// Reading alone: the recording's samples, decoded and bound to their signals.
void BM_ReplayRecordingRead(benchmark::State& state) {
  read_all(state, [] { return replay::open_recording(std::move(*InputLogReader::open(recording_file()))); });
}
BENCHMARK(BM_ReplayRecordingRead)->Unit(benchmark::kMillisecond);

// Reading alone: the CSV's cells parsed and bound to their signals.
void BM_ReplayCsvRead(benchmark::State& state) {
  read_all(state, [] { return std::move(*replay::open_csv(csv_file())); });
}
BENCHMARK(BM_ReplayCsvRead)->Unit(benchmark::kMillisecond);

/// `safecass replay bench.json --input LOG`, whole: both passes (check, then feed), every tick of
/// the system (20 threshold filters per millisecond), transitions printed to /dev/null.
void replay_whole(benchmark::State& state, const std::string& log) {
  (void)system_file();
  FilterRegistry registry;
  register_builtin_filters(registry);
  std::FILE* devnull = std::fopen("/dev/null", "w");
  for (auto _ : state) {
    replay::ReplayOptions o;
    o.system = system_file();
    o.input = log;
    o.out = devnull;
    o.err = devnull;
    if (replay::run_replay(o, registry) != 0) state.SkipWithError("replay failed");
  }
  std::fclose(devnull);
  state.SetItemsProcessed(state.iterations() * kSamples);
  state.counters["samples/s"] =
      benchmark::Counter(static_cast<double>(state.iterations() * kSamples), benchmark::Counter::kIsRate);
  // Seconds to replay one hour of this log (20 signals at 1 kHz) at this rate: an iteration is
  // kSeconds of log.
  state.counters["s_per_hour"] = benchmark::Counter(static_cast<double>(state.iterations()) * kSeconds / 3600.0,
                                                    benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_ReplayRecording(benchmark::State& state) {
  (void)recording_file();
  replay_whole(state, recording_file());
}
BENCHMARK(BM_ReplayRecording)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_ReplayCsv(benchmark::State& state) {
  (void)csv_file();
  replay_whole(state, csv_file());
}
BENCHMARK(BM_ReplayCsv)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace safecass
