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
    grep -q "none.json:1:1: error: cannot open file" "$tmp/err" || fail "message: $(cat "$tmp/err")"
    ;;
  run_records_history_as_json_lines)
    "$safecass" run --scenario examples/force_sensor/scenario.json --record "$tmp/h.jsonl" >/dev/null; expect_code 0 $? "run"
    [ -s "$tmp/h.jsonl" ] || fail "empty history"
    grep -q '"kind":"injection"' "$tmp/h.jsonl" || fail "no injection in history"
    grep -q '"outcome":"raised","component":"FORCE_SENSOR","machine":"FORCE_SENSOR.s_A","event":"EVT_FORCE_ERROR"' "$tmp/h.jsonl" || fail "no onset"
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
    for sub in demo validate schema run test; do
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
  *) fail "unknown case $case_name" ;;
esac
echo "ok: $case_name"
