// libFuzzer target for the console's command lines (`safecass console`, interactive and -c: the
// commands of tools/safecass/console.cpp run by Console::execute over robodoc in-process, with
// write access). Any bytes: as the line a terminal hands over (when it holds no line end), then
// as the text of `-c`, split by split_commands and run command by command as the batch does
// (when it holds a ';' or a line end). Beyond "no crash, no sanitizer report": a command that
// fails says why and changes nothing (DESIGN §7): the states, the filters and the end of the
// history are the same before and after it. `watch` is left out: it advances simulated time by
// design (up to an hour of ticks a line, too slow for a fuzzer).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "console.hpp"

namespace {

safecass::tools::Console& console() {
  static const std::unique_ptr<safecass::tools::Console> instance = [] {
    auto opened = safecass::tools::Console::open(SAFECASS_SOURCE_DIR "/examples/robodoc/robodoc.json", "",
                                                 safecass::tools::ConsoleOptions{false, true});
    if (!opened) __builtin_trap();
    return std::move(*opened);
  }();
  return *instance;
}

/// What a command could change: every state, every filter, the last records of the history.
std::string snapshot(safecass::tools::Console& c) {
  return c.execute("state list").out + c.execute("filter list").out + c.execute("event history 5").out;
}

bool is_watch(std::string_view line) {
  const std::size_t first = line.find_first_not_of(" \t");
  return first != std::string_view::npos && line.substr(first).starts_with("watch");
}

/// Runs one command; false when it said "quit".
bool run(safecass::tools::Console& c, std::string_view line) {
  if (is_watch(line)) return true;
  const std::string before = snapshot(c);
  const safecass::tools::ConsoleReply reply = c.execute(line);
  if (!reply.ok) {
    if (reply.err.empty()) __builtin_trap();      // a failure says why
    if (snapshot(c) != before) __builtin_trap();  // and changes nothing
  }
  return !reply.quit;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  safecass::tools::Console& c = console();
  if (text.find('\n') == std::string::npos) run(c, text);  // one line, as the terminal hands it over
  if (text.find_first_of(";\n") != std::string::npos) {    // the text of -c
    for (const std::string& command : safecass::tools::split_commands(text)) {
      if (!run(c, command)) break;
    }
  }
  return 0;
}
