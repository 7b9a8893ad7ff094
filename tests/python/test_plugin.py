"""The pytest plugin: scenario files collected as test items, a failure shown with its file:line
and the explain chain, JUnit XML from pytest's own --junitxml (docs/python.md, "pytest")."""

import xml.etree.ElementTree as ET

from conftest import ROBODOC

pytest_plugins = ["pytester"]

PASSING = """{ "system": "%s", "period": 0.001, "duration": 0.1,
  "steps": [ { "at": 0.01, "generate": { "event": "EVT_FORCE_ERROR", "target": "JR3.s_A" } },
             { "at": 0.02, "expect": { "JR3": "Error", "SERVO": "Error" } } ] }
"""
FAILING = """{ "system": "%s", "period": 0.001, "duration": 0.1,
  "steps": [ { "at": 0.01, "generate": { "event": "EVT_FORCE_ERROR", "target": "JR3.s_A" } },
             { "at": 0.02,
               "expect": { "SERVO": "Normal" } } ] }
"""


def test_scenario_files_are_collected_and_a_failure_shows_its_line_and_explain_chain(pytester):
    pytester.makefile(".scenario.json", good=PASSING % ROBODOC, bad=FAILING % ROBODOC)
    pytester.makefile(".json", other='{"not": "a scenario"}')
    result = pytester.runpytest("--junitxml=out.xml")
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines([
        "*bad.scenario.json:4:*: expectation failed at t=0.020000: SERVO is Error, expected Normal*",
        "*SERVO.s_R.Command: Error EVT_SERVICE_FAILURE*<- JR3.s_A:EVT_FORCE_ERROR*",
    ])
    cases = ET.parse(pytester.path / "out.xml").getroot().iter("testcase")
    outcome = {c.get("name"): [child.tag for child in c] for c in cases}
    assert outcome["good.scenario.json"] == [] or "failure" not in outcome["good.scenario.json"]
    assert "failure" in outcome["bad.scenario.json"]


def test_a_scenario_named_on_the_command_line_is_collected_whatever_its_name(pytester):
    path = pytester.makefile(".json", story=PASSING % ROBODOC)
    result = pytester.runpytest(str(path))
    result.assert_outcomes(passed=1)


def test_a_malformed_scenario_fails_with_its_file_line_and_column(pytester):
    pytester.makefile(".scenario.json", broken=(PASSING % ROBODOC).replace('"expect"', '"expectt"'))
    result = pytester.runpytest()
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*broken.scenario.json:3:*: error: unknown step action*expectt*"])


def test_the_system_fixture_builds_a_system_and_closes_it(pytester):
    pytester.makepyfile(f"""
        def test_it(safecass_system):
            robot = safecass_system({ROBODOC!r})
            robot.generate("EVT_FORCE_ERROR", "JR3.s_A")
            assert robot.state("SERVO") == "Error"
    """)
    pytester.runpytest().assert_outcomes(passed=1)
