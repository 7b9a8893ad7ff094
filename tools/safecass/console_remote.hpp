#pragma once
// `safecass console --ice` and `safecass timeline --ice`: the console's commands and the timeline
// page against a live coordinator process, through the middleware's RemoteClient (DESIGN §6
// "against a live system through the middleware"). Built only with SAFECASS_WITH_ICE.
//
// The remote console shares the in-process console's parser, completion, usage lines and `help`
// (console_shell.hpp) and prints the same shapes where the coordinator's answers carry the same
// data. Differences, all documented in docs/tools.md ("Console against a live coordinator"):
// `time` is in-process only; `watch SECONDS` prints the coordinator's records as the bus pushes them;
// history lines carry no severity and no root sample; `filter info` shows no ranges or signal sizes.

#include <memory>
#include <string>

#include "console.hpp"
#include "safecass/core/expected.hpp"

namespace safecass::tools {

/// A console on coordinator `args.coordinator`, found through IceStorm at `args.ice` (HOST:PORT)
/// within `args.timeout_ms`; writes carry the token read from `args.token_file` (when given).
/// The names TAB completes (components, machines, events, filters, signals) are fetched once here.
/// Errors: Parse (a malformed --ice), Io (an unreadable token file; IceStorm or the coordinator
/// unreachable or silent within the timeout).
[[nodiscard]] Expected<std::unique_ptr<Console>> connect_console(const ConsoleArgs& args);

/// `safecass timeline --ice HOST:PORT --coordinator NAME --html OUT`: the page of
/// `safecass timeline` drawn from the live history of one coordinator (every state and event
/// history it holds, fetched through the middleware). 0 the page was written; 2 the coordinator
/// cannot be reached or OUT cannot be written.
/// `keys`, `tls`, `read_token_file`: as the console's --keys, --tls and --read-token-file.
int run_timeline_ice(const std::string& ice, const std::string& coordinator, const std::string& html_out,
                     int timeout_ms, const std::string& keys = {}, const std::string& tls = {},
                     const std::string& read_token_file = {});

}  // namespace safecass::tools
