#!/usr/bin/env bash
# Command-line behaviour of `safecass`: exit codes, messages, determinism, reports.
# Usage: cli_test.sh CASE SAFECASS_BINARY   (run from the source root)
set -u
case_name=$1
safecass=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
expect_code() { # expected actual what
  [ "$1" = "$2" ] || fail "$3: exit code $2, expected $1"
}

case $case_name in
  run_json_is_byte_identical)
    "$safecass" run --scenario examples/robodoc/story.json --json >"$tmp/a" 2>/dev/null; expect_code 0 $? "first run"
    "$safecass" run --scenario examples/robodoc/story.json --json >"$tmp/b" 2>/dev/null; expect_code 0 $? "second run"
    [ -s "$tmp/a" ] || fail "no output"
    cmp -s "$tmp/a" "$tmp/b" || fail "two runs differ"
    # Every line is one JSON object.
    bad=$(grep -cv '^{.*}$' "$tmp/a"); [ "$bad" = 0 ] || fail "$bad lines are not JSON objects"
    ;;
  run_failed_expectation_names_it_time_and_actual_state)
    "$safecass" run --scenario tests/data/scenarios/failing.json >/dev/null 2>"$tmp/err"; expect_code 1 $? "failing scenario"
    grep -q 'tests/data/scenarios/failing.json:10:30: expectation failed at t=0.500000: CONTROL is Error, expected Normal \[/steps/2/expect\]' "$tmp/err" \
      || fail "message: $(cat "$tmp/err")"
    ;;
  run_unknown_names_are_input_errors_with_positions)
    "$safecass" run --scenario tests/data/scenarios/unknown_names.json >/dev/null 2>"$tmp/err"; expect_code 2 $? "unknown names"
    grep -q "unknown_names.json:5:30: error: no signal 'JR3.Torque'" "$tmp/err" || fail "signal: $(cat "$tmp/err")"
    grep -q "unknown_names.json:6:32: error: no event 'EVT_NOPE'" "$tmp/err" || fail "event: $(cat "$tmp/err")"
    grep -q "unknown_names.json:7:30: error: .*Nope" "$tmp/err" || fail "address: $(cat "$tmp/err")"
    ;;
  run_malformed_scenario_reports_every_problem)
    "$safecass" run --scenario tests/data/scenarios/malformed.json >/dev/null 2>"$tmp/err"; expect_code 2 $? "malformed"
    grep -q 'malformed.json:5:13: error: "at" must be a number, not string' "$tmp/err" || fail "at: $(cat "$tmp/err")"
    ;;
  run_missing_scenario_is_an_io_error)
    "$safecass" run --scenario "$tmp/none.json" >/dev/null 2>"$tmp/err"; expect_code 2 $? "missing file"
    grep -q "none.json:1:1: error: cannot read file '$tmp/none.json': no such file" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    ;;
  run_scenario_must_be_a_regular_file_of_at_most_64_MiB)
    # A device, a FIFO (no writer: opening it must not wait for one), a directory, a sparse file
    # over the limit: each refused at once with what and where, exit code 2, nothing run.
    mkfifo "$tmp/fifo.json"
    truncate -s $(( (64 << 20) + 1 )) "$tmp/big.json"
    for input in /dev/zero "$tmp/fifo.json" "$tmp" "$tmp/big.json"; do
      timeout 20 "$safecass" run --scenario "$input" >"$tmp/out" 2>"$tmp/err"; code=$?
      [ $code = 124 ] && fail "$input: hung"
      expect_code 2 $code "$input"
      [ -s "$tmp/out" ] && fail "$input: something ran: $(cat "$tmp/out")"
      grep -q "^$input:1:1: error: cannot read file '$input': " "$tmp/err" || fail "$input: $(cat "$tmp/err")"
    done
    grep -q "larger than 64 MiB (67108865 bytes)" "$tmp/err" || fail "size: $(cat "$tmp/err")"
    timeout 20 "$safecass" run --scenario /dev/zero 2>&1 | grep -q "not a regular file (a character device)" || fail "device"
    timeout 20 "$safecass" run --scenario "$tmp/fifo.json" 2>&1 | grep -q "not a regular file (a FIFO)" || fail "fifo"
    timeout 20 "$safecass" run --scenario "$tmp" 2>&1 | grep -q "not a regular file (a directory)" || fail "directory"
    ;;
  run_injection_of_a_number_out_of_range_is_an_input_error)
    # JSON has no NaN or infinity; a number too large for a double is refused where it is written.
    printf '{ "system": "%s/examples/force_sensor/force_sensor.json", "duration": 0.1,\n  "steps": [ { "at": 0.01, "inject": { "filter": "force_limit", "values": [1e999] } } ] }\n' "$PWD" >"$tmp/s.json"
    "$safecass" run --scenario "$tmp/s.json" >/dev/null 2>"$tmp/err"; expect_code 2 $? "1e999"
    grep -q "s.json:2:.*: error: number 1e999 is out of range" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    ;;
  run_record_write_error_is_said_and_fails_after_the_whole_run)
    # (--record-inputs -: no inputs recording, which would go next to /dev/full)
    "$safecass" run --scenario examples/force_sensor/scenario.json --record /dev/full --record-inputs - >"$tmp/out" 2>"$tmp/err"
    expect_code 2 $? "record to /dev/full"
    grep -q "history file '/dev/full': write error after 0 records: No space left on device; [1-9][0-9]* records were not written" "$tmp/err" \
      || fail "message: $(cat "$tmp/err")"
    grep -q "scenario.json: 10 expectations checked, 0 failed; the history file is incomplete" "$tmp/out" || fail "the run went on: $(cat "$tmp/out")"
    # --json: the same records, then the recorder's status as a last line.
    "$safecass" run --scenario examples/force_sensor/scenario.json --json >"$tmp/plain" 2>/dev/null; expect_code 0 $? "plain"
    "$safecass" run --scenario examples/force_sensor/scenario.json --json --record /dev/full --record-inputs - >"$tmp/json" 2>/dev/null
    expect_code 2 $? "json to /dev/full"
    head -n -1 "$tmp/json" | cmp -s - "$tmp/plain" || fail "the run's output changed"
    tail -n 1 "$tmp/json" | grep -q '^{"kind":"recorder","path":"/dev/full","written":0,"dropped":0,"unwritten":[1-9][0-9]*,"write_error":true,"error":"No space left on device","complete":false}$' \
      || fail "status line: $(tail -n 1 "$tmp/json")"
    # A history written in full says so too, and changes nothing else.
    "$safecass" run --scenario examples/force_sensor/scenario.json --json --record "$tmp/h.jsonl" >"$tmp/json" 2>"$tmp/err"
    expect_code 0 $? "record to a file"
    [ -s "$tmp/err" ] && fail "stderr: $(cat "$tmp/err")"
    n=$(wc -l <"$tmp/h.jsonl")
    tail -n 1 "$tmp/json" | grep -q "^{\"kind\":\"recorder\",\"path\":\"$tmp/h.jsonl\",\"written\":$n,\"dropped\":0,\"unwritten\":0,\"write_error\":false,\"complete\":true}\$" \
      || fail "status line: $(tail -n 1 "$tmp/json") ($n lines)"
    ;;
  replay_of_a_recorded_run_prints_the_same_transitions_and_history_byte_for_byte)
    # The demo's story, recorded (history + inputs), replayed through the same system.
    "$safecass" run --scenario examples/robodoc/story.json --record "$tmp/run.jsonl" >"$tmp/run.txt" 2>"$tmp/err"
    expect_code 0 $? "run"
    [ -s "$tmp/run.inputs" ] || fail "no inputs recorded next to the history"
    head -c 16 "$tmp/run.inputs" | grep -q '^SAFECASS-INPUTS ' || fail "not a recording: $(head -c 40 "$tmp/run.inputs")"
    "$safecass" replay examples/robodoc/robodoc.json --input "$tmp/run.inputs" --record "$tmp/replay.jsonl" >"$tmp/replay.txt" 2>"$tmp/err"
    expect_code 0 $? "replay: $(cat "$tmp/err")"
    grep -q "JR3.s_A  Warning -> Error" "$tmp/replay.txt" || fail "no force error in the replay"
    head -n -1 "$tmp/run.txt" | cmp - "$tmp/replay.txt" || fail "the replay printed other transitions than the run"
    cmp "$tmp/run.jsonl" "$tmp/replay.jsonl" || fail "the replay's history differs from the run's"
    cmp "$tmp/run.inputs" "$tmp/replay.inputs" || fail "the replay's own inputs recording differs from the run's"
    # The same with --json.
    "$safecass" run --scenario examples/robodoc/story.json --json --record "$tmp/j.jsonl" >"$tmp/run.json" 2>/dev/null
    "$safecass" replay examples/robodoc/robodoc.json --input "$tmp/j.inputs" --json >"$tmp/replay.json" 2>/dev/null
    expect_code 0 $? "replay --json"
    head -n -2 "$tmp/run.json" | cmp - "$tmp/replay.json" || fail "--json: the replay printed other records than the run"
    ;;
  run_killed_leaves_a_recording_every_record_of_which_replays)
    # A long run killed with SIGKILL while it records: the inputs replay up to their last whole record.
    # 9e7 ticks: far longer than the test waits, however fast the machine.
    printf '{ "system": "%s/examples/robodoc/robodoc.json", "period": 0.001, "duration": 90000,
  "steps": [ { "at": 0, "ramp": { "signal": "JR3.Fz", "from": 5, "to": 45, "until": 90000 } } ] }
' "$PWD" >"$tmp/long.json"
    "$safecass" run --scenario "$tmp/long.json" --record "$tmp/long.jsonl" >/dev/null 2>&1 &
    pid=$!
    # Killed once it has recorded something (at most 10 s), while it is still running.
    for _ in $(seq 100); do
      [ "$(stat -c %s "$tmp/long.inputs" 2>/dev/null || echo 0)" -gt 65536 ] && break
      sleep 0.1
    done
    kill -0 $pid 2>/dev/null || fail "the run ended before it could be killed"
    kill -9 $pid; wait $pid 2>/dev/null
    [ -s "$tmp/long.inputs" ] || fail "nothing was recorded before the kill (flushed at least every 100 ms)"
    "$safecass" replay examples/robodoc/robodoc.json --input "$tmp/long.inputs" >"$tmp/out" 2>"$tmp/err"
    expect_code 0 $? "replay of a killed run's recording: $(cat "$tmp/err")"
    grep -Eq "note: .*long.inputs: the recording (ends inside a record|has no end record)" "$tmp/err" || fail "the cut is not said: $(cat "$tmp/err")"
    grep -q "replayed [1-9][0-9]* samples" "$tmp/err" || fail "nothing replayed: $(cat "$tmp/err")"
    # The history of the killed run: every line but the last is whole JSON.
    head -n -1 "$tmp/long.jsonl" | while IFS= read -r line; do
      case $line in '{'*'}') ;; *) fail "torn history line: $line" ;; esac
    done
    ;;
  run_max_bytes_rotates_the_recordings_instead_of_filling_the_disk)
    "$safecass" run --scenario examples/robodoc/story.json --record "$tmp/r.jsonl" --max-bytes 16384 --json >"$tmp/out" 2>"$tmp/err"
    expect_code 0 $? "run with --max-bytes: $(cat "$tmp/err")"
    for f in "$tmp/r.inputs" "$tmp/r.inputs.1" "$tmp/r.jsonl" "$tmp/r.jsonl.1"; do
      [ -f "$f" ] || fail "no $f"
      [ "$(stat -c %s "$f")" -le 16384 ] || fail "$f is larger than 16384 bytes"
    done
    [ -e "$tmp/r.inputs.4" ] && fail "more than 3 old segments kept"
    grep -q '"kind":"input_recorder".*"rotations":[1-9]' "$tmp/out" || fail "rotations not reported: $(grep input_recorder "$tmp/out")"
    # Each segment replays on its own.
    "$safecass" replay examples/robodoc/robodoc.json --input "$tmp/r.inputs.1" >/dev/null 2>"$tmp/err"
    expect_code 0 $? "replay of a rotated segment: $(cat "$tmp/err")"
    ;;
  replay_diff_names_where_a_lower_force_limit_changes_the_states)
    "$safecass" run --scenario examples/robodoc/story.json --record "$tmp/s.jsonl" >/dev/null 2>&1
    "$safecass" replay --diff tests/data/replay/robodoc_low_limit.json examples/robodoc/robodoc.json --input "$tmp/s.inputs" >"$tmp/out" 2>"$tmp/err"
    expect_code 1 $? "diff: $(cat "$tmp/err")"
    grep -q "^  0.452000 .. 0.486000 s  B Error, A Warning  first cause (B): JR3.s_A:EVT_FORCE_ERROR" "$tmp/out" || fail "interval: $(cat "$tmp/out")"
    "$safecass" replay --diff examples/robodoc/robodoc.json examples/robodoc/robodoc.json --input "$tmp/s.inputs" >"$tmp/out" 2>"$tmp/err"
    expect_code 0 $? "diff of a system with itself"
    ;;
  replay_refuses_a_time_its_clock_cannot_hold)
    # --from, --to and --period become nanoseconds in 64 bits: beyond 4e9 s, or NaN, they are
    # refused with the option and the value, before the log is opened (it does not exist here).
    for option in "--from 1e300" "--to nan" "--period 5e9" "--period -1" "--from -inf"; do
      # shellcheck disable=SC2086
      "$safecass" replay examples/robodoc/robodoc.json --input "$tmp/none.inputs" $option >"$tmp/out" 2>"$tmp/err"
      expect_code 2 $? "replay $option: $(cat "$tmp/err")"
      grep -q -- "${option%% *}" "$tmp/err" || fail "replay $option: the option is not named: $(cat "$tmp/err")"
    done
    grep -q "at most 4e9" "$tmp/err" || fail "no bound said: $(cat "$tmp/err")"
    ;;
  run_records_history_as_json_lines)
    "$safecass" run --scenario examples/force_sensor/scenario.json --record "$tmp/h.jsonl" >/dev/null; expect_code 0 $? "run"
    [ -s "$tmp/h.jsonl" ] || fail "empty history"
    grep -q '"kind":"injection"' "$tmp/h.jsonl" || fail "no injection in history"
    grep -q '"outcome":"raised","component":"FORCE_SENSOR","machine":"FORCE_SENSOR.s_A","event":"EVT_FORCE_ERROR"' "$tmp/h.jsonl" || fail "no onset"
    ;;
  run_token_file_is_never_written_over_a_file_that_is_not_ours)
    # Refused before anything is connected, so no IceStorm is needed (port 1: nothing listens).
    "$safecass" run --help 2>/dev/null | grep -q -- --coordinator || { echo "skipped: built without the middleware"; exit 0; }
    printf '{"budget": 12}\n' >"$tmp/important.json"; chmod 0644 "$tmp/important.json"
    "$safecass" run examples/robodoc/robodoc.json --coordinator robot --ice 127.0.0.1:1 --allow-write \
      --token-file "$tmp/important.json" >/dev/null 2>"$tmp/err"
    expect_code 2 $? "token file over important.json"
    grep -q "token file $tmp/important.json: exists and is not a SAFECASS token file of yours (mode 0644, not 0600): refusing to overwrite it" "$tmp/err" \
      || fail "message: $(cat "$tmp/err")"
    [ "$(cat "$tmp/important.json")" = '{"budget": 12}' ] || fail "important.json was changed"
    ln -s "$tmp/important.json" "$tmp/link.token"
    "$safecass" run examples/robodoc/robodoc.json --coordinator robot --ice 127.0.0.1:1 --allow-write \
      --token-file "$tmp/link.token" >/dev/null 2>"$tmp/err"
    expect_code 2 $? "token file through a link"
    grep -q "is a symbolic link" "$tmp/err" || fail "link: $(cat "$tmp/err")"
    [ "$(cat "$tmp/important.json")" = '{"budget": 12}' ] || fail "important.json was changed through the link"
    ;;
  run_coordinator_refuses_a_scenario_with_unknown_names_before_it_starts)
    # A live coordinator checks every name of its scenario against the whole system first, as a
    # simulated run does, instead of skipping the steps it cannot apply. Nothing is connected
    # (port 1: nothing listens), so the refusal comes before the middleware.
    "$safecass" run --help 2>/dev/null | grep -q -- --coordinator || { echo "skipped: built without the middleware"; exit 0; }
    "$safecass" run examples/robodoc/robodoc.json --coordinator robot --ice 127.0.0.1:1 --duration 1 \
      --scenario tests/data/scenarios/unknown_names.json >/dev/null 2>"$tmp/err"
    expect_code 2 $? "live scenario with unknown names"
    grep -q "unknown_names.json:5:30: error: no signal 'JR3.Torque'" "$tmp/err" || fail "signal: $(cat "$tmp/err")"
    grep -q "unknown_names.json:6:32: error: no event 'EVT_NOPE'" "$tmp/err" || fail "event: $(cat "$tmp/err")"
    ;;
  test_reports_pass_fail_coverage_and_junit)
    "$safecass" test examples/force_sensor/scenario.json tests/data/scenarios/failing.json --junit "$tmp/j.xml" >"$tmp/out" 2>/dev/null
    expect_code 1 $? "one failing scenario"
    grep -q '^PASS   examples/force_sensor/scenario.json' "$tmp/out" || fail "pass line: $(cat "$tmp/out")"
    grep -q '^FAIL   tests/data/scenarios/failing.json' "$tmp/out" || fail "fail line"
    grep -q '1 of 2 scenarios passed' "$tmp/out" || fail "summary"
    grep -q 'events fired' "$tmp/out" || fail "coverage"
    grep -q 'defined transitions never taken' "$tmp/out" || fail "never-taken list"
    grep -q '<testsuite name="safecass" tests="2" failures="1">' "$tmp/j.xml" || fail "junit: $(cat "$tmp/j.xml")"
    grep -q '<failure message=' "$tmp/j.xml" || fail "junit failure element"
    ;;
  every_subcommand_has_help)
    for sub in demo validate schema run test trace; do
      "$safecass" "$sub" --help >/dev/null 2>&1; expect_code 0 $? "$sub --help"
    done
    "$safecass" >/dev/null 2>&1; expect_code 2 $? "no subcommand"
    "$safecass" frobnicate >/dev/null 2>&1; expect_code 2 $? "unknown subcommand"
    ;;
  validate_exit_codes)
    "$safecass" validate examples/robodoc/robodoc.json >/dev/null 2>&1; expect_code 0 $? "good system"
    bad=$(ls tests/data/bad_specs/*.json | head -1)
    "$safecass" validate "$bad" >/dev/null 2>&1; expect_code 1 $? "bad spec $bad"
    "$safecass" validate "$tmp/none.json" >/dev/null 2>&1; expect_code 2 $? "missing file"
    ;;
  trace_robodoc_writes_matrix_csv_and_report_with_no_error_gap)
    "$safecass" trace examples/robodoc/robodoc.json --scenarios examples/robodoc/story.json examples/robodoc/injection.json \
      examples/robodoc/warnings.json examples/robodoc/overload.json --csv "$tmp/trace.csv" --html "$tmp/trace.html" >"$tmp/out" 2>"$tmp/err"
    expect_code 0 $? "robodoc trace: $(cat "$tmp/err")"
    for h in H-3 H-5 H-6; do
      grep -q "^$h: " "$tmp/out" || fail "matrix without $h"
      grep -q "^$h," "$tmp/trace.csv" || fail "CSV without $h"
      grep -q "data-hazard=\"$h\"" "$tmp/trace.html" || fail "report without $h"
    done
    grep -q "report written to $tmp/trace.html" "$tmp/err" || fail "the report's path is not said: $(cat "$tmp/err")"
    "$safecass" trace examples/robodoc/robodoc.json --scenarios examples/robodoc/story.json --json >"$tmp/json" 2>/dev/null
    grep -q '"error_gaps":false' "$tmp/json" || fail "--json: $(head -c 300 "$tmp/json")"
    ;;
  trace_hazard_nothing_detects_fails_with_the_gap_named)
    "$safecass" trace tests/data/trace/undetected.json >"$tmp/out" 2>"$tmp/err"; expect_code 1 $? "undetected hazard"
    grep -q 'tests/data/trace/undetected.json:[0-9]*:[0-9]*: error: hazard H-9 has no detecting filter' "$tmp/out" \
      || fail "gap: $(cat "$tmp/out")"
    ;;
  trace_bad_input_and_strict_exit_codes)
    "$safecass" trace "$tmp/none.json" >/dev/null 2>"$tmp/err"; expect_code 2 $? "missing system"
    grep -q "none.json" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    "$safecass" trace tests/data/trace/arm.json --verify tests/data/trace/verify_malformed.jsonl >/dev/null 2>"$tmp/err"
    expect_code 2 $? "malformed verify result"
    grep -q "verify_malformed.jsonl:2:" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    "$safecass" trace tests/data/trace/arm.json --scenarios tests/data/trace/unchecked.scenario.json >/dev/null 2>&1
    expect_code 0 $? "warnings only"
    "$safecass" trace tests/data/trace/arm.json --scenarios tests/data/trace/unchecked.scenario.json --strict >/dev/null 2>&1
    expect_code 1 $? "warnings with --strict"
    "$safecass" trace tests/data/trace/arm.json --scenarios tests/data/trace/covered.scenario.json --html "$tmp/no/such/dir.html" \
      >/dev/null 2>"$tmp/err"; expect_code 2 $? "unwritable report"
    ;;
  analyze_exit_codes_tops_and_outputs)
    "$safecass" analyze examples/robodoc/robodoc.json --mef "$tmp/trees.xml" --format csv >"$tmp/fmea.csv" 2>/dev/null
    expect_code 0 $? "robodoc: no error-severity gap"
    head -1 "$tmp/fmea.csv" | grep -q "^id,name,kind,failure," || fail "csv header: $(head -1 "$tmp/fmea.csv")"
    grep -q "<opsa-mef>" "$tmp/trees.xml" || fail "no MEF written"
    "$safecass" analyze tests/data/verify/level_rule.json >"$tmp/out" 2>/dev/null
    expect_code 1 $? "an onset that misses its reaction"
    grep -q "GAP error reaction-missed" "$tmp/out" || fail "the gap is not named: $(grep GAP "$tmp/out")"
    # --top repeats, one value each, before or after SYSTEM.
    "$safecass" analyze --top SERVO=Error --top BMM.s_A=Warning examples/robodoc/robodoc.json --fault-trees \
      >"$tmp/out" 2>/dev/null; expect_code 0 $? "two --top before SYSTEM"
    grep -q "BMM.s_A at Warning or worse  (--top)" "$tmp/out" || fail "--top not a top: $(grep TOP "$tmp/out")"
    "$safecass" analyze examples/robodoc/robodoc.json --top SERVO=Normal >/dev/null 2>"$tmp/err"
    expect_code 2 $? "a top at Normal"
    grep -q "Warning or Error" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    "$safecass" analyze examples/robodoc/robodoc.json --scram "$tmp/no-scram" >/dev/null 2>"$tmp/err"
    expect_code 2 $? "SCRAM missing"
    grep -q "does not run" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    "$safecass" analyze tests/data/bad_specs/unknown_event.json >/dev/null 2>"$tmp/err"
    expect_code 2 $? "a bad system"
    grep -q "unknown_event.json:[0-9]*:[0-9]*: error" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    ;;
  *) fail "unknown case $case_name" ;;
esac
echo "ok: $case_name"
