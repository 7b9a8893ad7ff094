"""The Python module's figures (docs/benchmarks.md, "Python"), run by `make bench`:

    python3 benchmarks/bench_python.py PYTHON_DIR OUT.json

PYTHON_DIR is where the safecass package is laid out (build/release/python). Each figure is the
best (feeds, pushes) or the median (import) of several repetitions, on robodoc.
"""

import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROBODOC = str(Path(__file__).resolve().parent.parent / "examples" / "robodoc" / "robodoc.json")


def feed_rate(safecass, numpy, per_tick, n=1_000_000, repetitions=5):
    """Samples per second through System.feed: n samples of JR3.Fx, per_tick of them per 1 ms tick."""
    best = 0.0
    for _ in range(repetitions):
        system = safecass.System(ROBODOC)
        times = numpy.arange(n) / (1000.0 * per_tick)
        values = numpy.full(n, 1.0)
        start = time.perf_counter()
        system.feed("JR3.Fx", times, values)
        best = max(best, n / (time.perf_counter() - start))
        system.close()
    return best


def push_cost(safecass, n=200_000, repetitions=5):
    """Seconds per System.push call from Python (the C++ action path included)."""
    system = safecass.System(ROBODOC)
    push = system.push
    best = float("inf")
    for _ in range(repetitions):
        start = time.perf_counter()
        for _ in range(n):
            push("JR3.Fx", 1.0)
        best = min(best, (time.perf_counter() - start) / n)
    return best


def import_time(python_dir, repetitions=11):
    """Seconds `import safecass` adds to a fresh interpreter (median)."""
    env = dict(os.environ, PYTHONPATH=python_dir)

    def run(code):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, env=env)
        return time.perf_counter() - start

    bare = statistics.median(run("pass") for _ in range(repetitions))
    loaded = statistics.median(run("import safecass") for _ in range(repetitions))
    return loaded - bare


def main():
    python_dir, out = sys.argv[1], sys.argv[2]
    sys.path.insert(0, python_dir)
    import numpy
    import safecass

    figures = {
        "feed_samples_per_second_1_per_tick": feed_rate(safecass, numpy, 1),
        "feed_samples_per_second_10_per_tick": feed_rate(safecass, numpy, 10),
        "push_seconds_per_call": push_cost(safecass),
        "import_seconds": import_time(python_dir),
    }
    targets = {
        "feed_samples_per_second_1_per_tick": (">=", 5e6),
        "feed_samples_per_second_10_per_tick": (">=", 5e6),
        "push_seconds_per_call": ("<=", 1e-6),
        "import_seconds": ("<=", 0.1),
    }
    for name, value in figures.items():
        op, target = targets[name]
        met = value >= target if op == ">=" else value <= target
        print(f"python: {name:40s} {value:12.4g}  (target {op} {target:g}: {'met' if met else 'MISSED'})")
    Path(out).write_text(json.dumps({"figures": figures, "python": sys.version.split()[0]}, indent=2) + "\n")


if __name__ == "__main__":
    main()
