"""`import safecass`: loading, the one action path, the reads, the observer stream, scenarios,
verify and trace (docs/python.md)."""

import os
import threading

import numpy
import pytest

import safecass
from conftest import ROBODOC, ROOT


def test_a_bad_system_file_raises_spec_error_with_file_line_and_column():
    path = str(ROOT / "tests/data/bad_specs/bad_choice.json")
    with pytest.raises(safecass.SpecError) as caught:
        safecass.load(path)
    error = caught.value
    assert error.file == path and error.line == 11 and error.column == 71
    assert str(error).startswith(f"{path}:11:71: error: ")
    assert [d.to_dict()["line"] for d in error.diagnostics] == [d.line for d in safecass.validate(path)]


def test_load_gives_the_outline_and_validate_nothing_for_a_good_file():
    outline = safecass.load(ROBODOC)
    assert outline.name and "JR3" in outline.components
    assert outline.coordinators.to_dict() == {"robot": ["JR3", "BMM", "CONTROL", "SERVO"], "ui": ["PENDANT"]}
    assert [d.severity for d in safecass.validate(ROBODOC)] == ["warning"] * len(outline.warnings)


def test_a_missing_file_is_a_spec_error_naming_it():
    with pytest.raises(safecass.SpecError, match="no-such.json"):
        safecass.System("no-such.json")


def test_every_action_kind_goes_through_the_one_action_path_and_is_recorded(robodoc):
    robodoc.generate("EVT_FORCE_ERROR", "JR3.s_A")
    assert robodoc.state("JR3.s_A") == "Error"
    robodoc.reset("JR3.s_A", why="operator")
    assert robodoc.state("JR3.s_A") == "Normal"
    reset = [r for r in robodoc.history("JR3") if r.kind == "reset"]
    assert reset and reset[-1].text == "python: operator"
    robodoc.push("JR3.Fx", 1.0)
    robodoc.inject_deep("JR3.Fx", [1.0, 2.0])
    robodoc.inject("force_limit", [[1.0]])
    kinds = {r.kind for r in robodoc.history()}
    assert {"event", "transition", "reset", "injection"} <= kinds


def test_a_broadcast_reaches_the_application_machine_of_every_component(safecass_system):
    cell = safecass_system(str(ROOT / "tests/data/verify/broadcast.fixed.json"))
    cell.broadcast("EVT_ESTOP")
    assert [cell.state(c + ".s_A") for c in ("PANEL", "AXIS1", "AXIS2")] == ["Error"] * 3
    with pytest.raises(safecass.Error):
        cell.broadcast("NOT_AN_EVENT")


def test_a_refused_action_raises_and_changes_nothing(robodoc):
    robodoc.generate("EVT_FORCE_HIGH", "JR3.s_A")
    before = (robodoc.levels(), [r.to_dict() for r in robodoc.history()])
    with pytest.raises(safecass.NotFound, match="no event 'EVT_NOPE'"):
        robodoc.generate("EVT_NOPE", "JR3.s_A")
    with pytest.raises(safecass.InvalidArgument):
        robodoc.push("JR3.Fx", 1.0, 2.0)
    with pytest.raises(safecass.NotFound):
        robodoc.reset("NOWHERE")
    with pytest.raises(safecass.NotFound):
        robodoc.inject("no_filter", [[1.0]])
    assert (robodoc.levels(), [r.to_dict() for r in robodoc.history()]) == before


def test_states_explain_and_records_are_the_read_models_values(robodoc):
    robodoc.generate("EVT_FORCE_ERROR", "JR3.s_A")
    rows = robodoc.states()
    assert rows[0].address == "SYSTEM" and rows[0].state == "Error"
    assert robodoc.levels()["CONTROL.s_R.ForceData"] == "Error"
    why = robodoc.explain("SERVO")
    assert why.state == "Error"
    roots = {c.root.name for c in why.conditions}
    assert "JR3.s_A:EVT_FORCE_ERROR" in roots
    assert any(c.path[0] == "JR3.s_A" for c in why.conditions)
    record = robodoc.history("JR3.s_A")[0]
    d = record.to_dict()
    assert (d["kind"], d["machine"], d["event"], d["to"]) == (record.kind, record.machine, record.event,
                                                              record.to_level)
    assert robodoc.read("state summary")["system"] == "Error"
    assert any(f.filter == "force_limit" for f in robodoc.filters())


def test_a_callback_is_given_every_record_in_order_without_the_coordinators_lock(robodoc):
    seen = []

    def callback(record):
        # The coordinator's lock is not held: reading the system from here does not deadlock.
        seen.append((record.seq, robodoc.state("SYSTEM")))

    robodoc.subscribe(callback)
    robodoc.generate("EVT_FORCE_ERROR", "JR3.s_A")
    robodoc.advance(0.2)
    seqs = [s for s, _ in seen]
    assert seqs == sorted(seqs) and len(set(seqs)) == len(seqs) and seqs
    assert [r.seq for r in robodoc.history() if r.seq >= seqs[0]] == seqs


def test_an_exception_in_a_callback_is_raised_and_no_record_is_lost(robodoc):
    seen = []
    failed = []

    def callback(record):
        if not failed:
            failed.append(record.seq)
            raise RuntimeError("callback failed")
        seen.append(record.seq)

    robodoc.subscribe(callback)
    with pytest.raises(RuntimeError, match="callback failed"):
        robodoc.generate("EVT_FORCE_ERROR", "JR3.s_A")
    robodoc.advance(0.01)  # delivers what was left
    assert seen and seen[0] == failed[0] + 1
    assert failed + seen == [r.seq for r in robodoc.history() if r.seq >= failed[0]]


def test_feeding_an_array_gives_the_history_of_pushing_sample_by_sample(safecass_system):
    times = numpy.arange(0, 0.3, 0.001)
    force = numpy.where((times > 0.1) & (times < 0.2), 500.0, 1.0)
    fed = safecass_system(ROBODOC)
    fed.feed("JR3.Fx", times, force)
    pushed = safecass_system(ROBODOC)
    for t, v in zip(times, force):
        if t > 0:
            pushed.advance(t - 1e-9)
        pushed.push("JR3.Fx", v)
    pushed.advance(times[-1])
    assert fed.now == pytest.approx(times[-1])
    strip = lambda system: [{k: v for k, v in r.to_dict().items() if k != "seq"} for r in system.history()]
    assert strip(fed) == strip(pushed)
    assert any(r.to_level == "Error" for r in fed.history("JR3"))


def test_feed_refuses_times_that_go_back_or_a_wrong_shape_and_changes_nothing(robodoc):
    before = robodoc.levels(), len(robodoc.history())
    with pytest.raises(safecass.InvalidArgument, match=r"times\[2\]"):
        robodoc.feed("JR3.Fx", numpy.array([0.0, 0.002, 0.001]), numpy.ones(3))
    with pytest.raises(safecass.InvalidArgument, match="one row of 1"):
        robodoc.feed("JR3.Fx", numpy.array([0.0, 0.001]), numpy.ones((2, 2)))
    with pytest.raises(safecass.NotFound):
        robodoc.feed("JR3.nope", numpy.array([0.0]), numpy.ones(1))
    assert (robodoc.levels(), len(robodoc.history())) == before and robodoc.now == 0.0


def test_a_scenario_run_gives_each_failed_expectation_with_its_file_line_and_explain():
    path = str(ROOT / "tests/data/scenarios/failing.json")
    result = safecass.run_scenario(path)
    assert not result.passed and result.checks > 0
    failure = result.failures[0]
    assert failure.file == path and failure.line > 0 and failure.column > 0
    assert str(failure).startswith(f"{path}:{failure.line}:{failure.column}: expectation failed at t=")
    assert failure.address and failure.address in failure.explain
    assert [str(f) for f in result.failures] == result.problems


def test_a_passing_scenario_passes_and_a_bad_one_raises_with_its_position():
    assert safecass.run_scenario(str(ROOT / "examples/robodoc/story.json")).passed
    with pytest.raises(safecass.SpecError) as caught:
        safecass.run_scenario(str(ROOT / "tests/data/scenarios/malformed.json"))
    assert caught.value.line > 0


def test_verify_and_trace_give_their_results_as_objects():
    report = safecass.verify(str(ROOT / "tests/data/verify/broadcast.fixed.json"))
    assert report.exit_code == 0 and bool(report)
    assert all(p.verdict in ("holds", "violated", "undecided") for p in report.properties)
    violated = safecass.verify(str(ROOT / "tests/data/verify/broadcast.json"))
    assert violated.exit_code == 1 and any(p.verdict == "violated" for p in violated.properties)
    traced = safecass.trace(ROBODOC, [str(ROOT / "examples/robodoc/story.json")])
    assert traced.system and traced.hazards and "gaps" in traced
    assert isinstance(traced.to_dict()["hazards"], list)


def test_a_python_thread_runs_while_a_replay_runs(tmp_path):
    history = str(tmp_path / "run.jsonl")
    with safecass.System(ROBODOC, record=history) as run:  # 100 s of force at 1 kHz
        times = numpy.arange(0, 100, 0.001)
        run.feed("JR3.Fx", times, numpy.where(numpy.sin(times) > 0.9, 500.0, 1.0))
    replayed = safecass.replay(ROBODOC, str(tmp_path / "run.inputs"))
    counted = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counted.append(1)

    worker = threading.Thread(target=count)
    worker.start()
    try:
        before = len(counted)
        replayed.run()  # holding the GIL, it would leave the worker no bytecode to run until it returns
        during = len(counted) - before
    finally:
        stop.set()
        worker.join()
    assert during > 0
    assert replayed.now == pytest.approx(times[-1], abs=0.002)
    assert any(r.to_level == "Error" for r in replayed.history("JR3"))


def test_the_module_imports_its_version():
    assert safecass.__version__.count(".") == 2
    assert os.path.basename(safecass.__file__) == "__init__.py"
