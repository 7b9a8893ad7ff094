"""Recordings as arrays: an inputs recording and a history file read into numpy structured arrays
(docs/python.md, "Recordings as arrays")."""

import importlib.util

import numpy
import pytest

import safecass
from conftest import ROBODOC


@pytest.fixture
def recorded(tmp_path):
    history = tmp_path / "run.jsonl"
    times = numpy.arange(0, 0.5, 0.001)
    force = numpy.where((times > 0.1) & (times < 0.3), 500.0, 2.0)
    with safecass.System(ROBODOC, record=str(history)) as run:
        run.feed("JR3.Fx", times, force)
        run.generate("EVT_FORCE_HIGH", "JR3.s_A")
        kept = [r.to_dict() for r in run.history()]
    return history, tmp_path / "run.inputs", times, force, kept


def test_an_inputs_recording_reads_back_as_the_samples_that_were_fed(recorded):
    _, inputs, times, force, _ = recorded
    recording = safecass.read_recording(str(inputs))
    assert recording.inputs.dtype.names == ("time", "signal", "index", "value")
    t, v = recording.signal("JR3.Fx")
    numpy.testing.assert_allclose(t, times)
    numpy.testing.assert_array_equal(v, force)
    assert recording.actions[0]["action"] == "generate" and recording.actions[0]["event"] == "EVT_FORCE_HIGH"
    assert not recording.truncated and recording.end is not None and recording.losses == []


def test_a_history_file_reads_back_as_the_records_the_system_kept(recorded):
    history, _, _, _, kept = recorded
    read = safecass.read_history(str(history))
    assert read.records.dtype.names == ("time", "seq", "kind", "address", "event", "level", "root")
    assert list(read.records["seq"]) == [r["seq"] for r in kept]
    assert list(read.records["kind"]) == [r["kind"] for r in kept]
    errors = read.records[read.records["level"] == "Error"]
    assert len(errors) and all(root.endswith(":EVT_FORCE_ERROR") or root for root in errors["root"])
    times, levels = read.levels("JR3")
    assert levels[0] == 2 and list(times) == sorted(times)
    assert read.dropped == 0 and read.torn is None


def test_a_torn_last_line_is_said_and_a_malformed_line_raises_with_its_number(recorded, tmp_path):
    history = recorded[0]
    text = history.read_text()
    torn = tmp_path / "torn.jsonl"
    torn.write_text(text + '{"seq": 99, "t": 0.6, "ki')
    assert safecass.read_history(str(torn)).torn == text.count("\n") + 1
    bad = tmp_path / "bad.jsonl"
    bad.write_text(text.replace('"to":"Error"', '"to":"Bad"', 1))
    with pytest.raises(safecass.SpecError) as caught:
        safecass.read_history(str(bad))
    assert caught.value.line > 0 and "Bad" in str(caught.value)


def test_a_recording_that_is_not_one_raises_naming_the_file(tmp_path):
    junk = tmp_path / "junk.inputs"
    junk.write_bytes(b"not a recording\n")
    with pytest.raises(safecass.SpecError, match="junk.inputs"):
        safecass.read_recording(str(junk))


@pytest.mark.skipif(importlib.util.find_spec("pandas") is None, reason="pandas is not installed")
def test_to_pandas_gives_a_data_frame_of_the_same_rows(recorded):
    history, inputs, _, _, _ = recorded
    frame = safecass.read_recording(str(inputs)).to_pandas()
    assert list(frame.columns) == ["time", "signal", "index", "value"] and len(frame) == 500
    assert len(safecass.read_history(str(history)).to_pandas()) == len(safecass.read_history(str(history)))
