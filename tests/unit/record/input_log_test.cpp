// The input recording (record/input_log.hpp, input_recorder.hpp): what the recorder writes reads
// back whole and in order; a file cut anywhere is read up to its last whole record; malformed
// files are refused with the record and byte; losses (an overwritten buffer, a full queue, a write
// error) are counted, marked and said; rotation bounds the disk and keeps each segment readable.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "filter_fixture.hpp"
#include "safecass/record/input_log.hpp"
#include "safecass/record/input_recorder.hpp"

namespace safecass {
namespace {

using ::testing::HasSubstr;

std::string scratch(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "safecass_input_log_" + std::to_string(::getpid());
  ::mkdir(dir.c_str(), 0700);
  return dir + "/" + name;
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void spit(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f << bytes;
}

/// A system with a scalar input C.x, a vector input C.v and a computed signal C.n (Norm of C.v).
class InputRecording : public test::FilterFixture {
protected:
  InputRecording() {
    x_ = signal("x");
    v_ = signal("v", 3);
    make("Norm", {{"input_signal", std::string("v")}, {"output_signal", std::string("n")}});
  }
  void at(double t) { clock_.set(seconds_to_time(t)); }
  Signal* x_;
  Signal* v_;
};

/// An action's texts and sample count: "EVT_X|C.s_A||0".
std::string action_fields(const introspect::Action& action) {
  return std::visit(
      [](const auto& a) -> std::string {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, introspect::GenerateEvent>) {
          return a.event + "|" + a.target + "||0";
        } else if constexpr (std::is_same_v<A, introspect::BroadcastEvent>) {
          return a.event + "|||0";
        } else if constexpr (std::is_same_v<A, introspect::ResetState>) {
          return a.target + "|" + a.who + "|" + a.why + "|0";
        } else if constexpr (std::is_same_v<A, introspect::InjectShallow>) {
          return a.filter + "|||" + std::to_string(a.samples.size());
        } else if constexpr (std::is_same_v<A, introspect::InjectDeep>) {
          return a.signal + "|||" + std::to_string(a.samples.size());
        } else {
          return a.signal + " (a sample: never an action record)";
        }
      },
      action);
}

/// Everything a reader yields, as text: "S C.x 0.5 [1]", "A reset 2 BMM|scenario|why|0", "L 0 2", "E 2".
std::string read_all(const std::string& path, std::string* error = nullptr, bool* truncated = nullptr) {
  auto r = InputLogReader::open(path);
  if (!r) {
    if (error) *error = r.error().message;
    return {};
  }
  std::string out;
  for (;;) {
    const auto item = (*r)->next();
    char buf[256];
    switch (item) {
      case InputLogReader::Item::Sample: {
        std::snprintf(buf, sizeof buf, "S %s %g [", (*r)->signal_name((*r)->signal()).c_str(),
                      to_seconds((*r)->time()));
        out += buf;
        for (std::size_t i = 0; i < (*r)->width(); ++i) out += (i ? " " : "") + std::to_string((*r)->values()[i]);
        out += "]\n";
        break;
      }
      case InputLogReader::Item::Action: {
        std::snprintf(buf, sizeof buf, "A %s %g ", std::string(introspect::action_name((*r)->action())).c_str(),
                      to_seconds((*r)->mark_time()));
        out += buf + action_fields((*r)->action()) + "\n";
        break;
      }
      case InputLogReader::Item::Loss:
        out += "L " + std::to_string((*r)->loss_signal()) + " " + std::to_string((*r)->lost()) + "\n";
        break;
      case InputLogReader::Item::End:
        std::snprintf(buf, sizeof buf, "E %g\n", to_seconds((*r)->mark_time()));
        out += buf;
        break;
      case InputLogReader::Item::Eof:
        if (truncated) *truncated = (*r)->truncated();
        return out;
      case InputLogReader::Item::Error:
        if (error) *error = (*r)->error();
        return out;
    }
  }
}

TEST_F(InputRecording, EverySampleOfAnInputSignalAndEveryActionReadsBackInOrderWithItsTime) {
  const std::string path = scratch("order.inputs");
  InputRecorderOptions o;
  o.period = std::chrono::milliseconds(1);
  auto rec = InputRecorder::open(monitor_, path, o);
  ASSERT_TRUE(rec) << rec.error().message;
  at(0.0);
  x_->push(seconds_to_time(0.0), 1.5);
  const double v[3] = {1, 2, 3};
  v_->push(seconds_to_time(0.0), v);
  (*rec)->drain();
  at(0.001);
  x_->push(seconds_to_time(0.001), 2.5);
  const Time t = seconds_to_time(0.001);
  (*rec)->applied(introspect::GenerateEvent{"EVT_X", "C.s_A"}, t);  // drains first: the sample comes before it
  (*rec)->applied(introspect::PushSample{"C.x", {9.0}}, t);         // a sample is read from its signal, not here
  (*rec)->applied(introspect::ResetState{"C", "scenario", "why not"}, t);
  (*rec)->applied(introspect::InjectShallow{"f", {{1.0}, {2.0}}}, t);
  (*rec)->close(seconds_to_time(0.002));

  std::string error;
  EXPECT_EQ(read_all(path, &error),
            "S C.x 0 [1.500000]\n"
            "S C.v 0 [1.000000 2.000000 3.000000]\n"
            "S C.x 0.001 [2.500000]\n"
            "A generate 0.001 EVT_X|C.s_A||0\n"
            "A reset 0.001 C|scenario|why not|0\n"
            "A inject 0.001 f|||2\n"
            "E 0.002\n");
  EXPECT_EQ(error, "");
  const InputRecordStatus s = (*rec)->status();
  EXPECT_EQ(s.samples, 3u);
  EXPECT_EQ(s.actions, 3u);
  EXPECT_TRUE(s.complete());
  EXPECT_TRUE(describe_losses(s).empty());
  auto r = InputLogReader::open(path);
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)->header().period, std::chrono::milliseconds(1));
  EXPECT_EQ((*r)->header().system, "test");
}

TEST_F(InputRecording, AComputedSignalIsNotRecordedOnlyTheInputsItComesFrom) {
  const std::string path = scratch("computed.inputs");
  auto rec = InputRecorder::open(monitor_, path);
  ASSERT_TRUE(rec);
  monitor_.signals().find("C.n")->push(Time{0}, 4.0);
  (*rec)->close(Time{0});
  EXPECT_EQ(read_all(path), "E 0\n");
}

TEST_F(InputRecording, AFileCutAtAnyByteIsReadUpToItsLastWholeRecordAndSaysItWasCut) {
  const std::string path = scratch("whole.inputs");
  auto rec = InputRecorder::open(monitor_, path);
  ASSERT_TRUE(rec);
  for (int i = 0; i < 20; ++i) {
    at(i * 0.001);
    x_->push(seconds_to_time(i * 0.001), i);
    if (i % 7 == 0) (*rec)->applied(introspect::GenerateEvent{"EVT_X", "C.s_A"}, seconds_to_time(i * 0.001));
    (*rec)->drain();
  }
  (*rec)->close(seconds_to_time(0.02));
  const std::string bytes = slurp(path);
  const std::string full = read_all(path);
  const std::size_t header = bytes.find('\n') + 1;
  for (std::size_t cut = header; cut < bytes.size(); ++cut) {
    const std::string part = scratch("cut.inputs");
    spit(part, bytes.substr(0, cut));
    std::string error;
    bool truncated = false;
    const std::string got = read_all(part, &error, &truncated);
    ASSERT_EQ(error, "") << "cut at " << cut;
    ASSERT_EQ(full.compare(0, got.size(), got), 0) << "cut at " << cut << ": not a prefix:\n" << got;
    EXPECT_NE(got, full) << "cut at " << cut;
    // A cut that falls between two records is not a torn record.
    (void)truncated;
  }
}

TEST(InputLogReader, AFileThatIsNotARecordingIsRefusedAtItsFirstLine) {
  const std::string path = scratch("not.inputs");
  spit(path, "time,JR3.Fz\n0,1\n");
  auto r = InputLogReader::open(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message,
            path + ":1: not a SAFECASS input recording (the first line must start with \"SAFECASS-INPUTS 1\")");
  spit(path, "SAFECASS-INPUTS 7 period_ns=1\n");
  r = InputLogReader::open(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message,
            path + ":1: recording format version 7 is not supported (this safecass reads version 1)");
}

TEST(InputLogReader, AnUnknownRecordIsAnErrorWithItsIndexAndByteOffset) {
  std::string bytes;
  input_log::put_header(bytes, InputLogHeader{});
  const std::size_t header = bytes.size();
  input_log::put_signal(bytes, 0, 1, "C.x");
  input_log::put_time(bytes, Time{5});
  bytes += '\x7f';
  const std::string path = scratch("tag.inputs");
  spit(path, bytes);
  std::string error;
  read_all(path, &error);
  EXPECT_EQ(error, path + ": record 3 (byte " + std::to_string(header + 7 + 3 + 9) + "): unknown record tag 0x7f");
}

TEST(InputLogReader, ASignalWhoseTimeGoesBackIsAnError) {
  std::string bytes;
  input_log::put_header(bytes, InputLogHeader{});
  input_log::put_signal(bytes, 0, 1, "C.x");
  const double one = 1.0;
  input_log::put_time(bytes, seconds_to_time(0.5));
  input_log::put_sample(bytes, 0, &one, 1);
  input_log::put_time(bytes, seconds_to_time(0.25));
  input_log::put_sample(bytes, 0, &one, 1);
  const std::string path = scratch("back.inputs");
  spit(path, bytes);
  std::string error;
  read_all(path, &error);
  EXPECT_THAT(error, HasSubstr(": record 5 (byte "));
  EXPECT_THAT(error, HasSubstr("time goes back for signal C.x: 0.250000 s after 0.500000 s"));
}

TEST(InputLogReader, ASampleOfAnUndeclaredSignalIsAnError) {
  std::string bytes;
  input_log::put_header(bytes, InputLogHeader{});
  input_log::put_time(bytes, Time{0});
  const double one = 1.0;
  input_log::put_sample(bytes, 3, &one, 1);
  const std::string path = scratch("undeclared.inputs");
  spit(path, bytes);
  std::string error;
  read_all(path, &error);
  EXPECT_THAT(error, HasSubstr("sample of signal id 3, which was never declared"));
}

TEST(InputLogReader, ALossOfAnUndeclaredSignalIsAnError) {
  // Found by input_log_fuzz: the reader handed out a loss naming signal id 7 of a file that
  // declares none, and a reader of its name (signal_name(7)) read past the table.
  std::string bytes;
  input_log::put_header(bytes, InputLogHeader{});
  input_log::put_loss(bytes, Time{0}, 7, 3);
  input_log::put_loss(bytes, Time{0}, 0xffff, 2);
  const std::string path = scratch("undeclared-loss.inputs");
  spit(path, bytes);
  std::string error;
  read_all(path, &error);
  EXPECT_THAT(error, HasSubstr(": record 1 (byte "));
  EXPECT_THAT(error, HasSubstr("loss of signal id 7, which was never declared"));
}

TEST(InputLogReader, AnInjectionHoldingAnEmptySampleReadsBack) {
  // Found by input_log_fuzz once UBSan's reports stopped the run: an injected sample of no values
  // was copied from a null pointer (memcpy of 0 bytes into an empty vector's data()).
  std::string bytes;
  input_log::put_header(bytes, InputLogHeader{});
  input_log::put_action(bytes, introspect::InjectShallow{"f", {{}, {1.0}}}, Time{0});
  input_log::put_end(bytes, Time{0});
  const std::string path = scratch("empty-sample.inputs");
  spit(path, bytes);
  std::string error;
  EXPECT_EQ(read_all(path, &error), "A inject 0 f|||2\nE 0\n");
  EXPECT_EQ(error, "");
}

TEST_F(InputRecording, SamplesOverwrittenBeforeTheRecorderReadThemAreCountedMarkedAndSaid) {
  const std::string path = scratch("lost.inputs");
  auto rec = InputRecorder::open(monitor_, path);
  ASSERT_TRUE(rec);
  // The history buffer holds 1023 readable samples; 3000 pushed between two drains lose 1977.
  for (int i = 0; i < 3000; ++i) x_->push(Time{i}, i);
  (*rec)->close(Time{3000});
  const InputRecordStatus s = (*rec)->status();
  EXPECT_EQ(s.lost, 3000u - 1023u);
  EXPECT_EQ(s.samples, 1023u);
  EXPECT_FALSE(s.complete());
  EXPECT_THAT(read_all(path), HasSubstr("L 0 1977\n"));
  const auto losses = describe_losses(s);
  ASSERT_EQ(losses.size(), 1u);
  EXPECT_EQ(losses[0], "input recording '" + path +
                           "': 1977 samples lost: overwritten in their signal's history buffer before the recorder "
                           "read them (a loss record marks where)");
  EXPECT_THAT(record_status_json(s), HasSubstr("\"lost\":1977,"));
}

TEST_F(InputRecording, AWriteErrorIsKeptCountedAndSaidAndTheSystemGoesOn) {
  auto rec = InputRecorder::open(monitor_, "/dev/full");
  ASSERT_TRUE(rec) << rec.error().message;
  for (int i = 0; i < 100; ++i) {
    x_->push(Time{i}, i);
    (*rec)->drain();
  }
  (*rec)->close(Time{100});
  const InputRecordStatus s = (*rec)->status();
  EXPECT_EQ(s.write_error, "No space left on device");
  EXPECT_EQ(s.unwritten, 100u);
  EXPECT_FALSE(s.complete());
  EXPECT_THAT(describe_losses(s)[0], HasSubstr("write error: No space left on device; 100 samples were not written"));
}

TEST_F(InputRecording, AFileThatCannotBeCreatedIsAnIoErrorWithPathAndReason) {
  auto rec = InputRecorder::open(monitor_, "/nonexistent-dir/x.inputs");
  ASSERT_FALSE(rec);
  EXPECT_EQ(rec.error().message, "cannot write input recording '/nonexistent-dir/x.inputs': No such file or directory");
}

TEST_F(InputRecording, SamplesThatFindTheQueueToTheDiskFullAreDroppedCountedAndMarked) {
  // The recording goes into a pipe nobody reads yet: the writer blocks, the queue (8 KiB) fills.
  int fds[2];
  ASSERT_EQ(::pipe2(fds, O_CLOEXEC), 0);
  ASSERT_EQ(::fcntl(fds[1], F_SETFL, O_NONBLOCK), 0);
  const std::string filler(4096, 'x');
  while (::write(fds[1], filler.data(), filler.size()) > 0) {
  }
  ASSERT_EQ(errno, EAGAIN);
  std::string text;
  std::thread reader;
  std::uint64_t dropped = 0;
  {
    InputRecorderOptions o;
    o.queue_bytes = 8192;
    // The header must get through before the pipe is full: read it in a moment.
    reader = std::thread([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      char buffer[65536];
      for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;)
        text.append(buffer, static_cast<std::size_t>(n));
    });
    auto rec = InputRecorder::open(monitor_, "/proc/self/fd/" + std::to_string(fds[1]), o);
    ASSERT_TRUE(rec) << rec.error().message;
    ::close(fds[1]);
    const double v[3] = {0, 0, 0};
    std::uint64_t pushed = 0;
    for (int i = 0; i < 200000; ++i) {
      v_->push(Time{i}, v);
      ++pushed;
      if (i % 100 == 0) (*rec)->drain();
    }
    (*rec)->close(Time{200000});
    reader.join();
    const InputRecordStatus s = (*rec)->status();
    EXPECT_GT(s.dropped, 0u);
    dropped = s.dropped;
    EXPECT_EQ(s.samples + s.dropped, pushed) << "every sample is in the file or counted as dropped";
    EXPECT_FALSE(s.complete());
    EXPECT_THAT(describe_losses(s).back(), HasSubstr(" samples dropped: the queue to the disk was full"));
  }
  ::close(fds[0]);
  // The stream says where, and how many.
  const std::string path = scratch("pipe.inputs");
  ASSERT_NE(text.find("SAFECASS-INPUTS"), std::string::npos);
  spit(path, text.substr(text.find("SAFECASS-INPUTS")));  // after the filler that blocked the pipe
  const std::string items = read_all(path);
  std::uint64_t marked = 0;
  for (std::size_t at = items.find("L 65535 "); at != std::string::npos; at = items.find("L 65535 ", at + 1)) {
    marked += std::stoull(items.substr(at + 8));
  }
  EXPECT_EQ(marked, dropped) << "the stream marks every dropped sample";
  EXPECT_THAT(items, HasSubstr("E 0.0002\n")) << "the end is never dropped";
}

TEST_F(InputRecording, WithAByteLimitTheFileRotatesEachSegmentReadsAloneAndOldOnesAreDeleted) {
  const std::string path = scratch("rotate.inputs");
  InputRecorderOptions o;
  o.limits.max_bytes = 8192;
  o.limits.keep = 2;
  auto rec = InputRecorder::open(monitor_, path, o);
  ASSERT_TRUE(rec);
  // A hundred samples share each time, so that segments start between samples of one time: each
  // restates it.
  for (int i = 0; i < 5000; ++i) {
    x_->push(Time{i / 100}, i);
    if (i % 10 == 0) (*rec)->drain();
  }
  (*rec)->close(Time{5000});
  const InputRecordStatus s = (*rec)->status();
  EXPECT_GT(s.rotations, 3u);
  EXPECT_EQ(s.discarded, s.rotations - 2);
  EXPECT_TRUE(s.write_error.empty());
  for (const std::string& p : {path, path + ".1", path + ".2"}) {
    struct stat st {};
    ASSERT_EQ(::stat(p.c_str(), &st), 0) << p;
    EXPECT_LE(st.st_size, 8192) << p;
    std::string error;
    const std::string items = read_all(p, &error);
    EXPECT_EQ(error, "") << p;
    // A rotated segment holds samples; the open one may hold only the end record when the last
    // rotation came just before close (the writer thread's batching decides, not the test).
    if (p != path) {
      EXPECT_THAT(items, HasSubstr("S C.x ")) << p;
    }
  }
  struct stat st {};
  EXPECT_NE(::stat((path + ".3").c_str(), &st), 0) << "at most keep=2 old segments";
  EXPECT_THAT(read_all(path), HasSubstr("E 5e-06\n"));
}

/// One run of its own system (a recorder reads its signals' whole history): samples x and v at
/// one time, recorded either drained together or with the writer writing between them.
class OneRun final : public InputRecording {
public:
  void TestBody() override {}
  std::string record(const std::string& path, bool write_between) {
    auto rec = InputRecorder::open(monitor_, path);
    EXPECT_TRUE(rec) << rec.error().message;
    const double v[3] = {1, 2, 3};
    x_->push(Time{7}, 1.0);
    (*rec)->drain();
    if (write_between) {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while ((*rec)->status().samples == 0 && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      EXPECT_EQ((*rec)->status().samples, 1u) << "the writer wrote the first sample alone";
    }
    v_->push(Time{7}, v);
    (*rec)->close(Time{8});
    return slurp(path);
  }
};

TEST_F(InputRecording, TheSameRunRecordsTheSameBytesWhereverTheWriterCutsItsChunks) {
  // The writer writes on its own clock: where it cuts depends on the machine, not on the run.
  const std::string together = OneRun().record(scratch("together.inputs"), false);
  const std::string apart = OneRun().record(scratch("apart.inputs"), true);
  EXPECT_EQ(apart, together) << "a chunk restates the time only where a reader needs it";
}

TEST_F(InputRecording, WhatWasDrainedIsOnTheDiskSoonWithoutClosing) {
  const std::string path = scratch("flush.inputs");
  auto rec = InputRecorder::open(monitor_, path);
  ASSERT_TRUE(rec);
  const std::size_t header = slurp(path).size();
  x_->push(Time{0}, 1.0);
  (*rec)->drain();
  // The writer writes at least every 50 ms; allow a busy machine a second.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (slurp(path).size() == header && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_THAT(read_all(path), HasSubstr("S C.x 0 [1.000000]"));
  (*rec)->close(Time{0});
}

TEST(InputRecorderPath, TheInputsGoNextToTheHistory) {
  EXPECT_EQ(InputRecorder::path_for_history("build/run.jsonl"), "build/run.inputs");
  EXPECT_EQ(InputRecorder::path_for_history("h"), "h.inputs");
}

}  // namespace
}  // namespace safecass
