// The `safecass` command: one entry point, one subcommand per tool.
// Exit codes: 0 ok, 1 a check failed, 2 usage, input or I/O error.

#include <CLI/CLI.hpp>

#include <cstdio>

#include "commands.hpp"
#include "console.hpp"
#include "safecass/timeline/timeline.hpp"
#include "spec_commands.hpp"
#include "verify_command.hpp"
#ifdef SAFECASS_WITH_ICE
#include "console_remote.hpp"
#include "middleware_commands.hpp"
#endif
#ifdef SAFECASS_WITH_VIEWER
#include "viewer_command.hpp"
#endif

int main(int argc, char** argv) {
  CLI::App app{"SAFECASS: safety architecture for component-based robot systems"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "safecass " SAFECASS_VERSION);
  int code = 0;

  auto* demo = app.add_subcommand("demo", "Run the demonstration of the core model");
  demo->callback([&] { code = safecass::tools::run_demo(); });

  std::vector<std::string> validate_files;
  bool validate_json = false;
  auto* validate =
      app.add_subcommand("validate", "Check system/component specifications; report every problem as file:line:col");
  validate->add_option("SYSTEM", validate_files, "system or component files")->required();
  validate->add_flag("--json", validate_json, "one JSON object per diagnostic");
  bool validate_verbose = false;
  validate->add_flag("-v,--verbose", validate_verbose, "also print notes: what was accepted and ignored (2016 keys)");
  validate->callback([&] { code = run_validate(validate_files, validate_json, validate_verbose); });

  auto* schema = app.add_subcommand("schema", "Print the JSON Schema of specification files");
  schema->callback([&] { code = run_schema(); });

  safecass::tools::RunArgs run_args;
  auto* run = app.add_subcommand("run", "Run a system in-process in simulated time, driven by a scenario");
  run->add_option("SYSTEM", run_args.system, "system file (default: the scenario's \"system\")");
  run->add_option("--scenario,-s", run_args.scenario, "scenario file (required unless --coordinator)");
  run->add_flag("--json", run_args.json, "one JSON object per line (byte-identical across runs)");
  run->add_option(
      "--record", run_args.record,
      "write the whole history (JSON lines) to this file; a write error or dropped records are said on "
      "stderr (and with --json in a last {\"kind\":\"recorder\"} line) and make the exit code 2; the inputs "
      "(samples and actions) are recorded next to it (FILE.jsonl -> FILE.inputs; docs/record-format.md)");
  run->add_option("--record-inputs", run_args.record_inputs,
                  "record the inputs to this file instead of next to --record (\"-\": do not record them)");
  run->add_option("--max-bytes", run_args.max_bytes,
                  "rotate each recording at this many bytes (FILE -> FILE.1 .. FILE.3, the oldest deleted) instead of "
                  "filling the disk")
      ->check(CLI::Range(std::uint64_t{4096}, std::uint64_t{1} << 62));
#ifdef SAFECASS_WITH_ICE
  safecass::tools::add_middleware_options(*run, run_args);
  safecass::tools::add_supervisor_command(app, code);
  safecass::tools::add_keys_command(app, code);
#endif
  run->callback([&] { code = safecass::tools::run_run(run_args); });

  safecass::tools::TestArgs test_args;
  auto* test = app.add_subcommand("test", "Run scenarios and report pass/fail with event and transition coverage");
  test->add_option("SCENARIO", test_args.scenarios, "scenario files")->required();
  test->add_option("--junit", test_args.junit, "write JUnit XML to this file");
  test->callback([&] { code = safecass::tools::run_test(test_args); });

  safecass::tools::add_replay_command(app, code);
  safecass::tools::add_analyze_command(app, code);

  safecass::tools::TraceArgs trace_args;
  auto* trace = app.add_subcommand(
      "trace", "Hazard traceability: hazard -> events -> filters -> reaction -> scenarios -> verify, with the gaps");
  trace->add_option("SYSTEM", trace_args.system, "system file")->required();
  trace->add_option("--scenarios,-s", trace_args.scenarios,
                    "scenario files to run (their \"system\" is replaced by SYSTEM)");
  trace->add_option("--html", trace_args.html,
                    "write the report (one self-contained page, printable to PDF) to this file");
  trace->add_option("--csv", trace_args.csv, "write one row per hazard x event x filter (RFC 4180) to this file");
  trace->add_option("--verify", trace_args.verify,
                    "the output of `safecass verify --json` (default: verification \"not run\")");
  trace->add_flag("--json", trace_args.json, "the matrix as one JSON document on stdout");
  trace->add_flag("--strict", trace_args.strict, "exit 1 on a gap of warning severity too");
  trace->callback([&] { code = safecass::tools::run_trace(trace_args); });

  safecass::tools::add_console_command(app, code);
  safecass::tools::add_verify_command(app, code);
#ifdef SAFECASS_WITH_VIEWER
  safecass::tools::add_viewer_command(app, code);
#endif

  std::string timeline_history;
  std::string timeline_html;
  auto* timeline = app.add_subcommand(
      "timeline", "Draw a recorded history as Normal/Warning/Error swimlanes in one static HTML page");
  std::string timeline_ice;
  std::string timeline_coordinator;
  std::string timeline_keys, timeline_tls, timeline_read_token;
  timeline->add_option("HISTORY", timeline_history,
                       "history file (JSON lines, from `safecass run --record`); not with --ice");
  timeline->add_option("--html", timeline_html, "write the page to this file")->required();
  timeline->add_option(
      "--ice", timeline_ice,
      "draw the live history of a coordinator instead: IceStorm at HOST:PORT (locator:HOST:PORT: replicated)");
  timeline->add_option("--coordinator", timeline_coordinator, "with --ice: the coordinator's name");
  timeline->add_option("--keys", timeline_keys, "with --ice: the system's bus keys (default $SAFECASS_KEYS)");
  timeline->add_option("--tls", timeline_tls, "with --ice: mutual TLS; DIR holds ca.pem and console.pem/.key");
  timeline->add_option("--read-token-file", timeline_read_token, "with --ice: the coordinator's read credential file");
  timeline->callback([&] {
    if (timeline_ice.empty() && timeline_coordinator.empty()) {
      if (timeline_history.empty()) {
        std::fprintf(stderr, "timeline: HISTORY (or --ice HOST:PORT --coordinator NAME) is required\n");
        code = 2;
        return;
      }
      code = safecass::timeline::run_timeline(timeline_history, timeline_html);
      return;
    }
    if (timeline_ice.empty() || timeline_coordinator.empty() || !timeline_history.empty()) {
      std::fprintf(stderr, "timeline: --ice HOST:PORT and --coordinator NAME go together, without HISTORY\n");
      code = 2;
      return;
    }
#ifdef SAFECASS_WITH_ICE
    code = safecass::tools::run_timeline_ice(timeline_ice, timeline_coordinator, timeline_html, 2000, timeline_keys,
                                             timeline_tls, timeline_read_token);
#else
    std::fprintf(stderr,
                 "timeline: --ice needs the middleware, and this safecass was built without it (SAFECASS_WITH_ICE)\n");
    code = 2;
#endif
  });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int exit = app.exit(e);
    return exit == 0 ? 0 : 2;
  }
  return code;
}
