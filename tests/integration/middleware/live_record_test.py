"""The history of a live coordinator (`safecass run SYSTEM --coordinator NAME --ice ... --record FILE`):
the same recorder and the same loss reporting as in-process `safecass run --record` (docs/tools.md,
"The history file"; DESIGN §7 "nothing lost").

Usage: live_record_test.py CASE SAFECASS SOURCE_DIR ICESTORM_ENV KEYS_DIR SCRATCH

CASE is one of
  history_holds_the_printed_transitions_and_draws_as_a_timeline
  a_write_error_is_said_and_fails_the_run
  an_operators_write_over_the_bus_is_recorded_and_replays

The IceStorm is the ctest fixture's (middleware.icestorm_start writes ICESTORM_PORT into
ICESTORM_ENV); KEYS_DIR holds the robodoc system's bus keys (middleware.keys). Standard library
only.
"""

import json
import os
import re
import subprocess
import sys
import time

TRANSITION = re.compile(r"^\[robot\] (\S+) (Normal|Warning|Error) -> (Normal|Warning|Error)(?: (\S+))?(?: \(root (\S+)\))?$")


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


class Live:
    def __init__(self, binary, source, env_file, keys, scratch):
        self.binary = binary
        self.source = source
        self.scratch = scratch
        os.makedirs(scratch, exist_ok=True)
        values = dict(line.strip().split("=", 1) for line in open(env_file) if "=" in line)
        self.ice = "127.0.0.1:" + values["ICESTORM_PORT"]
        self.env = dict(os.environ, SAFECASS_KEYS=keys)

    def run_robot(self, record, *extra):
        """Runs the robot coordinator of robodoc for 2 s with the force-spike scenario."""
        command = [self.binary, "run", os.path.join(self.source, "examples/robodoc/robodoc.json"),
                   "--coordinator", "robot", "--ice", self.ice,
                   "--scenario", os.path.join(self.source, "tests/integration/middleware/robot_spike.json"),
                   "--duration", "2", "--record", record, *extra]
        done = subprocess.run(command, capture_output=True, text=True, timeout=60, env=self.env, cwd=self.source)
        return done.returncode, done.stdout, done.stderr


def printed_transitions(stdout):
    out = []
    for line in stdout.splitlines():
        m = TRANSITION.match(line)
        if m:
            address, before, after, event, root = m.groups()
            out.append((address, before, after, event or "", root or ""))
    return out


def recorded_transitions(records):
    out = []
    for r in records:
        if r["kind"] not in ("transition", "component-transition"):
            continue
        address = r.get("machine", r.get("component"))
        root = r.get("root")
        out.append((address, r["from"], r["to"], r.get("event", ""),
                    root["origin"] + ":" + root["event"] if root else ""))
    return out


def history_holds_the_printed_transitions_and_draws_as_a_timeline(live):
    history = os.path.join(live.scratch, "robot-history.jsonl")
    if os.path.exists(history):
        os.unlink(history)
    code, out, err = live.run_robot(history, "--json")
    if code != 0:
        fail(f"exit code {code}, expected 0\nstdout:\n{out}\nstderr:\n{err}")
    if not os.path.exists(history):
        fail("no history file: --record was ignored")
    with open(history) as f:
        text = f.read()
    if not text.endswith("\n"):
        fail("the history does not end with a newline")
    records = []
    for number, line in enumerate(text.splitlines(), 1):
        try:
            record = json.loads(line)
        except ValueError as e:
            fail(f"{history}:{number}: not JSON ({e}): {line}")
        if not isinstance(record, dict) or "kind" not in record:
            fail(f"{history}:{number}: not a record: {line}")
        if record["kind"] == "overflow":
            fail(f"{history}:{number}: records were dropped: {line}")
        records.append(record)

    printed = printed_transitions(out)
    recorded = recorded_transitions(records)
    if not any(t[0] == "JR3.s_A" and t[2] == "Error" for t in printed):
        fail("the force spike printed no JR3.s_A -> Error transition:\n" + out)
    if recorded != printed:
        fail("the history's transitions differ from those the process printed:\nprinted:\n" +
             "\n".join(map(str, printed)) + "\nrecorded:\n" + "\n".join(map(str, recorded)))
    seqs = [r["seq"] for r in records]
    if seqs != sorted(seqs) or len(set(seqs)) != len(seqs):
        fail("the records are not in stream order")

    # The recorder's status is the last line of the output, and it says nothing was lost.
    status = json.loads(out.splitlines()[-1])
    expected = {"kind": "recorder", "path": history, "written": len(records), "dropped": 0, "unwritten": 0,
                "write_error": False, "complete": True}
    if status != expected:
        fail(f"recorder status {status}, expected {expected}")
    if "history file" in err:
        fail("a loss was reported for a complete history: " + err)

    # The history is one that `safecass timeline` draws, with every transition.
    page = os.path.join(live.scratch, "robot-timeline.html")
    done = subprocess.run([live.binary, "timeline", history, "--html", page], capture_output=True, text=True,
                          timeout=60)
    if done.returncode != 0:
        fail(f"timeline: exit code {done.returncode}: {done.stderr}")
    with open(page) as f:
        html = f.read()
    if f'"transitions":{len(recorded)},' not in html:
        fail(f"the timeline page does not count the {len(recorded)} transitions of the history")
    # The inputs were recorded next to the history, by the recorder's own thread, and nothing was
    # lost; replayed through the same system in simulated time they raise the same force error.
    inputs = os.path.join(live.scratch, "robot-history.inputs")
    lines = out.splitlines()
    status = json.loads(lines[-2])
    if status.get("kind") != "input_recorder" or status.get("complete") is not True or status.get("samples", 0) < 100:
        fail(f"input recorder status {status}")
    done = subprocess.run([live.binary, "replay", os.path.join(live.source, "examples/robodoc/robodoc.json"),
                           "--input", inputs], capture_output=True, text=True, timeout=60)
    if done.returncode != 0:
        fail(f"replay of the live recording: exit code {done.returncode}: {done.stderr}")
    if "JR3.s_A  Warning -> Error" not in done.stdout and "JR3.s_A  Normal -> Error" not in done.stdout:
        fail("the replay of the live recording does not raise the force error:\n" + done.stdout)
    print(f"ok: {len(records)} records, {len(recorded)} transitions, the same as printed; timeline drawn; "
          f"{status['samples']} input samples recorded and replayed")


def a_write_error_is_said_and_fails_the_run(live):
    # A full disk: the coordinator keeps running to its end, then says what the history misses
    # and fails, as in-process `safecass run --record /dev/full` does.
    code, out, err = live.run_robot("/dev/full", "--json", "--record-inputs", "-")
    if code != 2:
        fail(f"--record /dev/full: exit code {code}, expected 2\nstdout:\n{out}\nstderr:\n{err}")
    if not re.search(r"^history file '/dev/full': write error after 0 records: No space left on device; "
                     r"\d+ records? (was|were) not written \(the system kept running; the history is incomplete\)$",
                     err, re.M):
        fail("--record /dev/full: no loss on stderr:\n" + err)
    if "expectations checked, 0 failed; the history file is incomplete (see above)" not in out:
        fail("--record /dev/full: the summary does not say the history is incomplete:\n" + out)
    status = json.loads(out.splitlines()[-1])
    if status.get("kind") != "recorder" or status.get("write_error") is not True or status.get("complete") is not False \
            or status.get("unwritten", 0) < 1:
        fail(f"--record /dev/full: recorder status {status}")
    if not printed_transitions(out):
        fail("--record /dev/full: the coordinator stopped monitoring (no transition printed)")

    # A file that cannot be created: refused at start, nothing run.
    missing = os.path.join(live.scratch, "no-such-dir", "h.jsonl")
    code, out, err = live.run_robot(missing)
    if code != 2 or f"cannot write history file '{missing}'" not in err or "[robot]" in out:
        fail(f"--record {missing}: exit code {code}\nstdout:\n{out}\nstderr:\n{err}")
    print("ok: a write error and an uncreatable file are said and fail the run")


def an_operators_write_over_the_bus_is_recorded_and_replays(live):
    # A write from `safecass console --ice --allow-write` is an input of the run: the live
    # coordinator records it as an action next to its samples, and the replay applies it.
    history = os.path.join(live.scratch, "operator-history.jsonl")
    token = os.path.join(live.scratch, "operator.token")
    for f in (history, token):
        if os.path.exists(f):
            os.unlink(f)
    quiet = os.path.join(live.source, "tests/integration/console_ice/robot_quiet.json")
    command = [live.binary, "run", os.path.join(live.source, "examples/robodoc/robodoc.json"),
               "--coordinator", "robot", "--ice", live.ice, "--scenario", quiet, "--duration", "6",
               "--record", history, "--allow-write", "--token-file", token, "--lost-after", "2000"]
    robot = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=live.env,
                             cwd=live.source)
    try:
        console = [live.binary, "console", "--ice", live.ice, "--coordinator", "robot", "--allow-write",
                   "--token-file", token, "-c"]
        deadline = time.monotonic() + 20
        while True:
            done = subprocess.run(console + ["event generate EVT_SERVO_OVERLOAD SERVO.s_A"] if os.path.exists(token)
                                  else ["false"], capture_output=True, text=True, timeout=30, env=live.env)
            if done.returncode == 0:
                break
            if time.monotonic() > deadline or robot.poll() is not None:
                fail(f"the console's write never reached the robot: {done.stderr}")
            time.sleep(0.2)
        refused = subprocess.run(console + ["event generate EVT_NO_SUCH_EVENT SERVO.s_A"], capture_output=True,
                                 text=True, timeout=30, env=live.env)
        if refused.returncode == 0:
            fail("an unknown event was accepted")
        done = subprocess.run(console + ["event generate /EVT_SERVO_OVERLOAD SERVO.s_A"], capture_output=True,
                              text=True, timeout=30, env=live.env)
        if done.returncode != 0:
            fail(f"the completion was refused: {done.stderr}")
        out, err = robot.communicate(timeout=60)
    finally:
        if robot.poll() is None:
            robot.kill()
            robot.wait()
    if robot.returncode != 0:
        fail(f"the robot exited with {robot.returncode}:\n{out}\n{err}")
    inputs = os.path.join(live.scratch, "operator-history.inputs")
    done = subprocess.run([live.binary, "replay", os.path.join(live.source, "examples/robodoc/robodoc.json"),
                           "--input", inputs], capture_output=True, text=True, timeout=60)
    if done.returncode != 0:
        fail(f"replay: exit code {done.returncode}: {done.stderr}")
    if "2 actions" not in done.stderr:
        fail("the replay did not apply exactly the two accepted writes: " + done.stderr)
    onset = re.search(r"^t=(\S+)  SERVO\.s_A  Normal -> Warning  EVT_SERVO_OVERLOAD", done.stdout, re.M)
    completion = re.search(r"^t=(\S+)  SERVO\.s_A  Warning -> Normal  /EVT_SERVO_OVERLOAD", done.stdout, re.M)
    if not onset or not completion or float(completion.group(1)) < float(onset.group(1)):
        fail("the replay does not raise and clear the operator's event:\n" + done.stdout)
    print(f"ok: the operator's two writes were recorded and replay at t={onset.group(1)} and t={completion.group(1)}")


def main():
    if len(sys.argv) != 7:
        print(__doc__)
        return 2
    case, binary, source, env_file, keys, scratch = sys.argv[1:]
    live = Live(os.path.abspath(binary), os.path.abspath(source), env_file, keys, os.path.abspath(scratch))
    {"history_holds_the_printed_transitions_and_draws_as_a_timeline":
         history_holds_the_printed_transitions_and_draws_as_a_timeline,
     "a_write_error_is_said_and_fails_the_run": a_write_error_is_said_and_fails_the_run,
     "an_operators_write_over_the_bus_is_recorded_and_replays":
         an_operators_write_over_the_bus_is_recorded_and_replays}[case](live)
    return 0


if __name__ == "__main__":
    sys.exit(main())
