#!/usr/bin/env python3
"""scripts/bench-check on made-up runs: a regression on a known machine fails and names the
benchmark; a run on a machine the baseline does not know is not checked (exit 3); --record adds
the machine; a sub-nanosecond figure one clock cycle slower is not a regression.

usage: bench_check_test.py BENCH_CHECK WORK_DIR"""

import json
import os
import subprocess
import sys

check, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)


def run_report(path, mhz, figures):
    """A Google Benchmark report: five repetitions of each figure (ns), the first the fastest."""
    benchmarks = []
    for name, ns in figures.items():
        for k in range(5):
            benchmarks.append({"name": name, "run_name": name, "run_type": "iteration",
                               "real_time": ns * (1 + 0.01 * k), "time_unit": "ns"})
    context = {"num_cpus": 2, "mhz_per_cpu": mhz,
               "caches": [{"type": "Data", "level": 1, "size": 32768}, {"type": "Unified", "level": 2, "size": 1 << 20}]}
    with open(path, "w") as f:
        json.dump({"context": context, "benchmarks": benchmarks}, f)
    return path


def bench_check(*args):
    p = subprocess.run([check, *args], capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


failures = []


def expect(condition, what, output):
    if not condition:
        failures.append(f"{what}\n{output}")


base = os.path.join(work, "baseline.json")
with open(base, "w") as f:
    json.dump({"about": "test", "tolerance": 0.1,
               "machines": [{"machine": "an older machine", "benchmarks": {"BM_A": 100.0, "BM_Read": 0.3}}]}, f)
here = {"BM_A": 100.0, "BM_Read": 0.3}

rc, out = bench_check(run_report(os.path.join(work, "unknown.json"), 2000, here), base)
expect(rc == 3 and "NOT CHECKED" in out and "no figures for this machine" in out,
       "a run on a machine the baseline does not know must not be checked (exit 3)", out)

rc, out = bench_check("--record", base, run_report(os.path.join(work, "r1.json"), 2000, here),
                      run_report(os.path.join(work, "r2.json"), 2000, {"BM_A": 98.0, "BM_Read": 0.31}))
expect(rc == 0, "--record must record two runs of one machine", out)
with open(base) as f:
    recorded = json.load(f)["machines"]
expect(len(recorded) == 2 and recorded[1]["benchmarks"] == {"BM_A": 98.0, "BM_Read": 0.3},
       "--record keeps the older machine and records the fastest figure of each benchmark", json.dumps(recorded))

rc, out = bench_check(run_report(os.path.join(work, "same.json"), 2000, {"BM_A": 105.0, "BM_Read": 0.3}), base)
expect(rc == 0 and "within 10%" in out, "a run within the tolerance passes", out)

rc, out = bench_check(run_report(os.path.join(work, "slow.json"), 2000, {"BM_A": 118.0, "BM_Read": 0.3}), base)
expect(rc == 1 and "FAILED" in out and "BM_A" in out.split("FAILED")[1], "20 % slower fails and names it", out)

# One cycle at 2,000 MHz is 0.5 ns: 0.3 → 0.75 ns is within a cycle and the tolerance; 0.9 ns is not.
rc, out = bench_check(run_report(os.path.join(work, "cycle.json"), 2000, {"BM_A": 98.0, "BM_Read": 0.75}), base)
expect(rc == 0, "a sub-nanosecond figure a clock cycle slower is not a regression", out)
rc, out = bench_check(run_report(os.path.join(work, "two.json"), 2000, {"BM_A": 98.0, "BM_Read": 0.9}), base)
expect(rc == 1 and "BM_Read" in out.split("FAILED")[1], "a figure two cycles slower is", out)

rc, out = bench_check(run_report(os.path.join(work, "less.json"), 2000, {"BM_A": 98.0}), base)
expect(rc == 1 and "missing" in out, "a guarded benchmark missing from the run fails", out)

rc, out = bench_check(os.path.join(work, "absent.json"), base)
expect(rc == 2 and "make bench" in out, "an absent run says to run make bench", out)

for f in failures:
    print("FAILED:", f)
sys.exit(1 if failures else 0)
