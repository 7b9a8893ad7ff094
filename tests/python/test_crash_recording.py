"""Recordings survive a crash: `safecass run --record` killed with SIGKILL at random moments leaves
an inputs recording and a history that read back up to their last whole record, and the readers
say how much was cut (docs/record-format.md)."""

import os
import random
import signal
import subprocess
import time

import safecass
from conftest import ROBODOC

RUNS = 20

# Fifty simulated minutes of a force that rises and falls: the recorders write the whole time.
SCENARIO = """{ "system": "%s", "period": 0.001, "duration": 3000,
  "steps": [ { "at": 0, "sample": { "JR3.Fy": 0, "JR3.Fz": 0 } },
             { "at": 0, "ramp": { "signal": "JR3.Fx", "from": 0, "to": 400, "until": 1500 } },
             { "at": 1500, "ramp": { "signal": "JR3.Fx", "from": 400, "to": 0, "until": 3000 } } ] }
"""


def test_a_recording_killed_at_any_moment_reads_back_to_its_last_whole_record(tmp_path):
    scenario = tmp_path / "long.json"
    scenario.write_text(SCENARIO % ROBODOC)
    command = os.environ.get("SAFECASS", "safecass")
    rng = random.Random(20261129)
    cut_inputs = cut_histories = killed = 0
    for run in range(RUNS):
        history = tmp_path / f"run{run}.jsonl"
        process = subprocess.Popen([command, "run", ROBODOC, "--scenario", str(scenario), "--record", str(history)],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        # A moment in the run: after both files exist, at a random time after that.
        deadline = time.monotonic() + 30
        while not (history.exists() and history.with_suffix(".inputs").exists()) and time.monotonic() < deadline:
            time.sleep(0.005)
        time.sleep(rng.uniform(0.0, 0.4))
        process.send_signal(signal.SIGKILL)
        process.wait()
        inputs = safecass.read_recording(str(history.with_suffix(".inputs")))
        read = safecass.read_history(str(history))
        killed += process.returncode == -signal.SIGKILL
        assert inputs.end is None or process.returncode == 0  # a clean end only when it finished first
        assert (inputs.cut_bytes > 0) == inputs.truncated
        assert (read.cut_bytes > 0) == (read.torn is not None)
        assert list(read.records["seq"]) == sorted(read.records["seq"])
        cut_inputs += inputs.truncated
        cut_histories += read.torn is not None
        # The same file cut at a random byte, as a crash of the machine may leave it: it reads back
        # as a prefix of what was there, and says how many bytes it left out.
        data = history.with_suffix(".inputs").read_bytes()
        at = rng.randrange(data.index(b"\n") + 1, len(data) + 1)
        cut = tmp_path / f"cut{run}.inputs"
        cut.write_bytes(data[:at])
        part = safecass.read_recording(str(cut))
        assert len(part.inputs) <= len(inputs.inputs)
        assert (part.inputs == inputs.inputs[:len(part.inputs)]).all()
        assert part.truncated == (part.cut_bytes > 0) and part.cut_bytes < at
    assert killed >= RUNS // 2, f"only {killed} of {RUNS} runs were killed while recording"
    print(f"{killed} of {RUNS} runs killed while recording: {cut_inputs} inputs recordings and {cut_histories} "
          "histories ended inside a record")
