// The recorder: a write error (a full disk) and records dropped by its bounded queue are counted,
// kept with their reason and said; the monitored system goes on either way.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <limits>
#include <string>
#include <thread>

#include "core_test_support.hpp"
#include "safecass/record/recorder.hpp"

namespace safecass {
namespace {

using test::Gcm;
using ::testing::HasSubstr;

/// A component with one error onset and its completion; `rounds` faults raised and cleared make
/// four records each (event, transition, event, transition) and a component transition each way.
struct Robot : Gcm {
  Robot() {
    component("JR3");
    pair("EVT_FORCE_ERROR", 100, State::Error);
  }
  void faults(int rounds) {
    for (int i = 0; i < rounds; ++i) {
      gen("EVT_FORCE_ERROR", "JR3.s_A");
      gen("/EVT_FORCE_ERROR", "JR3.s_A");
    }
  }
};

TEST(Recorder, AWriteErrorIsKeptWithItsReasonAndTheSystemKeepsRunning) {
  Robot m;
  auto recorder = Recorder::open(m.co, "/dev/full");
  ASSERT_TRUE(recorder) << recorder.error().message;
  m.faults(3);
  m.gen("EVT_FORCE_ERROR", "JR3.s_A");
  EXPECT_EQ(m.at("JR3"), State::Error) << "monitoring goes on whatever the recorder's file does";
  (*recorder)->close();
  const RecordStatus s = (*recorder)->status();
  EXPECT_EQ(s.path, "/dev/full");
  EXPECT_EQ(s.write_error, std::strerror(ENOSPC));
  EXPECT_EQ(s.written, 0u);
  EXPECT_GT(s.unwritten, 0u);
  EXPECT_FALSE(s.complete());
  const auto losses = describe_losses(s);
  ASSERT_EQ(losses.size(), 1u);
  EXPECT_THAT(losses[0], HasSubstr("history file '/dev/full': write error after 0 records: No space left on device"));
  EXPECT_THAT(losses[0], HasSubstr(std::to_string(s.unwritten) + " records were not written"));
  EXPECT_THAT(record_status_json(s),
              HasSubstr("\"write_error\":true,\"error\":\"No space left on device\",\"complete\":false"));
}

TEST(Recorder, AFileThatCannotBeCreatedIsAnIoErrorWithPathAndReason) {
  Robot m;
  auto recorder = Recorder::open(m.co, "/nonexistent-dir/h.jsonl");
  ASSERT_FALSE(recorder);
  EXPECT_EQ(recorder.error().code, ErrorCode::Io);
  EXPECT_EQ(recorder.error().message,
            "cannot write history file '/nonexistent-dir/h.jsonl': No such file or directory");
}

TEST(Recorder, AHistoryWithNothingLostIsCompleteAndSaysNothing) {
  Robot m;
  const std::string path = ::testing::TempDir() + "/recorder_complete_" + std::to_string(::getpid()) + ".jsonl";
  auto recorder = Recorder::open(m.co, path);
  ASSERT_TRUE(recorder) << recorder.error().message;
  m.faults(2);
  (*recorder)->close();
  const RecordStatus s = (*recorder)->status();
  EXPECT_TRUE(s.complete());
  EXPECT_GT(s.written, 0u);
  EXPECT_TRUE(describe_losses(s).empty());
  EXPECT_THAT(record_status_json(s),
              HasSubstr("\"dropped\":0,\"unwritten\":0,\"write_error\":false,\"complete\":true}"));
  ::unlink(path.c_str());
}

TEST(Recorder, RecordsDroppedByAFullQueueAreCountedSaidAndMarkedInTheFile) {
  // The history goes into a pipe that nobody reads yet: the writer blocks on its first line, the
  // queue (4 records) fills, and every further record is dropped.
  int fds[2];
  ASSERT_EQ(::pipe2(fds, O_CLOEXEC), 0);
  ASSERT_EQ(::fcntl(fds[1], F_SETFL, O_NONBLOCK), 0);
  const std::string filler(4096, 'x');
  while (::write(fds[1], filler.data(), filler.size()) > 0) {
  }
  ASSERT_EQ(errno, EAGAIN);

  Robot m;
  std::uint64_t produced = 0;
  m.co.subscribe([&produced](const Record&) { ++produced; });
  auto recorder = Recorder::open(m.co, "/proc/self/fd/" + std::to_string(fds[1]), 4);
  ASSERT_TRUE(recorder) << recorder.error().message;
  ::close(fds[1]);  // the recorder has its own descriptor of the pipe
  m.faults(50);
  EXPECT_EQ(m.at("JR3"), State::Normal);

  std::string text;
  std::thread reader([&] {
    char buffer[65536];
    for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<std::size_t>(n));
  });
  (*recorder)->close();
  reader.join();
  ::close(fds[0]);

  const RecordStatus s = (*recorder)->status();
  EXPECT_TRUE(s.write_error.empty()) << s.write_error;
  EXPECT_GT(s.dropped, 0u);
  EXPECT_EQ(s.written + s.dropped, produced) << "every record is either in the file or counted as dropped";
  EXPECT_FALSE(s.complete());
  // The file says where records are missing, and how many.
  std::uint64_t marked = 0;
  for (std::size_t at = text.find("{\"kind\":\"overflow\",\"dropped\":"); at != std::string::npos;
       at = text.find("{\"kind\":\"overflow\",\"dropped\":", at + 1)) {
    marked += std::stoull(text.substr(at + std::strlen("{\"kind\":\"overflow\",\"dropped\":")));
  }
  EXPECT_EQ(marked, s.dropped);
  const auto losses = describe_losses(s);
  ASSERT_EQ(losses.size(), 1u);
  EXPECT_THAT(losses[0], HasSubstr(std::to_string(s.dropped) + " records dropped: the recorder's queue was full"));
  EXPECT_THAT(record_status_json(s), HasSubstr("\"dropped\":" + std::to_string(s.dropped) + ","));
}

TEST(Recorder, ANonFiniteSampleValueIsWrittenAsValidJsonThatKeepsItsValue) {
  Robot m;
  Record r;
  r.kind = RecordKind::Event;
  r.machine = m.machine("JR3.s_A");
  r.component = m.comp("JR3");
  r.event = m.id("EVT_FORCE_ERROR");
  r.root.event = r.event;
  r.root.origin = r.machine;
  r.root.sample.signal = m.co.intern("JR3.Force");
  r.root.sample.value = std::numeric_limits<double>::infinity();
  EXPECT_THAT(record_to_json(r, m.co), HasSubstr("\"value\":\"inf\""));
  r.root.sample.value = -std::numeric_limits<double>::infinity();
  EXPECT_THAT(record_to_json(r, m.co), HasSubstr("\"value\":\"-inf\""));
  r.root.sample.value = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(record_to_json(r, m.co), HasSubstr("\"value\":\"nan\""));
}

TEST(Recorder, ARemoteRootIsWrittenWithItsOriginInItsOwnProcessNotTheStandInItArrivedThrough) {
  // A live client records mirrors of a provider's root: the history names the true root cause
  // (the origin interned when the root arrived), as an in-process run of the same system does.
  Robot m;
  Record r;
  r.kind = RecordKind::Transition;
  r.machine = m.machine("JR3.s_A");
  r.component = m.comp("JR3");
  r.from = State::Normal;
  r.to = State::Error;
  r.root.event = m.id("EVT_FORCE_ERROR");
  r.root.origin = r.machine;  // the stand-in machine the root arrived through
  r.root.remote = 0;
  r.root.remote_origin = m.co.intern("SENSOR.s_A");
  EXPECT_THAT(record_to_json(r, m.co), HasSubstr("\"root\":{\"event\":\"EVT_FORCE_ERROR\",\"origin\":\"SENSOR.s_A\""));
  EXPECT_THAT(record_to_text(r, m.co), HasSubstr("<- SENSOR.s_A:EVT_FORCE_ERROR"));
}

}  // namespace
}  // namespace safecass
