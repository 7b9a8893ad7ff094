#pragma once
/// @file protocol.hpp
/// The viewer's WebSocket protocol, independent of any network code so that it can be tested on
/// its own. Every message is one JSON object (text frame).
///
/// Server → page:
///   {"type":"hello","write":bool,"max_message":N,"view":VIEW,"recent":[RECORD...]}   on connect
///   {"type":"update","t":T,"running":B,"states":{ADDRESS:[STATE,OUTSTANDING]...},"records":[RECORD...]}
///   {"type":"time","t":T,"running":B}                                   clock only, ≤ 4 per second
///   {"type":"reply","id":ID,"op":OP,...}  /  {"type":"error","id":ID,"error":TEXT}
/// Page → server ("id", a number or string, is optional and echoed in the reply):
///   {"op":"view"}                       → reply with "view"
///   {"op":"explain","address":A}        → reply with "address","state","conditions":[...]
///   {"op":"generate","event":E,"target":MACHINE,"token":K}
///   {"op":"broadcast","event":E,"token":K}
///   {"op":"inject","filter":F,"samples":[[...]...],"token":K}        shallow injection
///   {"op":"inject","signal":S,"samples":[[...]...],"token":K}        deep injection
///   {"op":"reset","target":A,"reason":TEXT,"token":K}
///   {"op":"replay","action":"play"|"pause"|"next"}                   a replay's controls (no token:
///   {"op":"replay","action":"seek","t":SECONDS}                       they change what is shown,
///   {"op":"replay","action":"speed","speed":X}                        never the system or its log)
/// VIEW = {"system","description","t","running","state","coordinators":[{"name","address","state",
/// "status","components":[{"name","address","state","outstanding","machines":[{"address","kind",
/// "name","state","outstanding"}]}]}],"connections":[{"required","provided"}],"clock":CLOCK[,"replay":REPLAY]}.
/// CLOCK = {"base":"simulated"} (times are scenario seconds) or {"base":"host","wall_offset_ms":X}
/// (a live system: wall-clock time = t * 1000 + X ms since the Unix epoch). REPLAY (a replay only,
/// also in every "update" and "time") = {"start","end","period","playing","speed","busy"}; when a
/// replay goes back in time every page gets a new "hello". STATES holds only the addresses whose state or outstanding
/// event changed since the previous update; coordinator addresses are "coordinator:NAME", and a
/// coordinator's "outstanding" is its status ("" in-process; "unreachable", "lost", ... live).
/// RECORD is record_to_json()'s format.
///
/// A malformed message (not JSON, not an object, unknown op or key, wrong type, too long) gets an
/// error reply saying what is wrong and changes nothing. Write operations are refused unless the
/// protocol was created with write access, and then unless the message carries the token.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <string_view>
#include <utility>

#include "safecass/viewer/source.hpp"

namespace safecass::viewer {

struct ProtocolOptions {
  bool allow_write = false;
  std::string token;                    ///< required in every write request when allow_write
  std::size_t max_message = 64 * 1024;  ///< longer messages are refused
  std::size_t recent = 100;             ///< records kept for the "recent" list of new pages
};

/// The records shown in the page's side list (transitions, resets, injections); events without
/// a transition are left out.
bool listed_record(std::string_view record_json);

class Protocol {
public:
  /// `source` must outlive the protocol. A write-enabled protocol needs a non-empty token.
  Protocol(ViewSource& source, ProtocolOptions options);

  /// The first message to a new page.
  std::string hello() const;
  /// Handles one message from a page and returns the reply (never throws; a bad message gets an
  /// "error" reply and changes nothing).
  std::string handle(std::string_view message);
  /// Polls the source and returns the message to push to every page: an "update" when states
  /// changed or records arrived, else a "time" message when the last message is 250 ms old, else
  /// "" (nothing to say). `now_ms` is a monotonic wall-clock time in milliseconds.
  std::string update(long long now_ms);

  /// The VIEW object of the current picture.
  std::string view_json() const;

  bool write_enabled() const noexcept { return options_.allow_write; }

private:
  std::string refuse_write(std::string_view id, std::string_view op, std::string_view token) const;

  ViewSource& source_;
  ProtocolOptions options_;
  std::map<std::string, std::pair<State, std::string>> sent_;  ///< last state pushed per address
  std::deque<std::string> recent_;
  long long last_time_ms_ = -1000000;
  std::uint64_t generation_ = 0;    ///< the source's generation the pages were last greeted with
  std::uint64_t view_version_ = 0;  ///< the source's view_version() when the states were last compared
  std::string last_replay_;         ///< the replay status last pushed
  /// The hazards' coverage last pushed (ViewSource::coverage()), and when it was last judged.
  std::vector<introspect::HazardCoverage> sent_coverage_;
  long long coverage_ms_ = -1000000;
};

}  // namespace safecass::viewer
