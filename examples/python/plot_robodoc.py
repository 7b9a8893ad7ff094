"""Plots a recording of robodoc: the force fed to JR3 and the levels of JR3, CONTROL and SERVO.

    PYTHONPATH=build/python python3 examples/python/plot_robodoc.py robodoc.png

It runs robodoc's story (examples/robodoc/story.json) with its history and inputs recorded, reads
both back as numpy arrays and draws them with matplotlib (headless: the Agg backend).
"""

import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import safecass  # noqa: E402

HERE = Path(__file__).resolve().parent.parent / "robodoc"


def main(out: str) -> None:
    with tempfile.TemporaryDirectory() as scratch:
        history = str(Path(scratch) / "story.jsonl")
        result = safecass.run_scenario(str(HERE / "story.json"), record=history)
        inputs = safecass.read_recording(history[: -len(".jsonl")] + ".inputs")
        records = safecass.read_history(history)
    figure, (force, levels) = plt.subplots(2, 1, sharex=True, figsize=(9, 5))
    for signal in ("JR3.Fx", "JR3.Fy"):
        t, v = inputs.signal(signal)
        force.plot(t, v, label=signal)
    force.set_ylabel("force (N)")
    force.legend(loc="upper right")
    for offset, address in enumerate(("JR3", "CONTROL", "SERVO")):
        t, level = records.levels(address)
        levels.step([0.0, *t], [0, *level], where="post", label=address)
    levels.set_yticks([0, 1, 2], ["Normal", "Warning", "Error"])
    levels.set_xlabel("time (s)")
    levels.legend(loc="upper right")
    figure.suptitle(f"robodoc's story: {'passed' if result.passed else 'failed'}, {result.checks} checks")
    figure.savefig(out, dpi=100)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "robodoc.png")
