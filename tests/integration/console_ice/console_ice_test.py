#!/usr/bin/env python3
"""`safecass console --ice` and `safecass timeline --ice` against a live coordinator: IceStorm and
the robot coordinator of examples/robodoc run as real processes; the console reads them, is refused
a write without the token, generates an event with it and sees the state change, watches a change
happen, and the timeline draws the live history. Unreachable IceStorm or coordinator: exit 2, fast.

Usage: console_ice_test.py SAFECASS_BINARY SOURCE_DIR SCRATCH_DIR
Everything started is stopped by PID, whatever happens.
"""

import json
import re
import os
import socket
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from live_system import LiveSystem  # noqa: E402


class Failure(Exception):
    pass


def check(condition, what, *details):
    if not condition:
        raise Failure(what + ("\n" + "\n".join(str(d) for d in details) if details else ""))


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def wait_for_console(system):
    """The first request: retried until the coordinator's heartbeat is on IceStorm (10 s at most)."""
    deadline = time.monotonic() + 10
    while True:
        code, out, err = system.console("-c", "state list; explain CONTROL")
        if code == 0 or time.monotonic() > deadline:
            return code, out, err
        time.sleep(0.2)


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    binary, source, scratch = sys.argv[1:]
    system = LiveSystem(binary, source, scratch)
    try:
        system.start()
        token = ["--token-file", system.token_file]

        # Reads: the same shapes as in-process.
        code, out, err = wait_for_console(system)
        check(code == 0, f"state list; explain CONTROL: exit {code}", out, err, system.logs())
        for line in ["SYSTEM", "CONTROL", "  JR3.s_A", "  CONTROL.s_R.ForceData", "JR3.s_S.ForceData",
                     "CONTROL is Normal: no active condition"]:
            check(line in out, f"state list/explain: no {line!r}", out)
        check("PENDANT" not in out.split("CONTROL is Normal")[0], "state list shows only this coordinator's components", out)

        code, out, err = system.console("-c", "filter list; filter info force_limit; event list; connection list; "
                                              "service list; help explain")
        check(code == 0, f"read commands: exit {code}", out, err)
        for part in ["force_limit", "parameters:", "EVT_FORCE_ERROR", "JR3.s_S.ForceData", "= s_P.ForceData * s_F * s_A",
                     "usage: explain ADDRESS"]:
            check(part in out, f"read commands: no {part!r}", out)
        check(any(l.split() == ["CONTROL.ForceData", "->", "JR3.ForceData", "s_R", "Normal", "s_S", "Normal", "propagates",
                                "Error"] for l in out.splitlines()), "connection list row", out)

        # Writes: refused without --allow-write, without the token and with a wrong one; nothing changes.
        code, out, err = system.console("-c", "event generate EVT_FORCE_ERROR JR3.s_A", *token)
        check(code == 2 and "this console is read-only" in err, "a write without --allow-write is refused", code, out, err)
        code, out, err = system.console("--allow-write", "-c", "event generate EVT_FORCE_ERROR JR3.s_A")
        check(code == 2 and err.startswith("event generate: ") and "token" in err and "usage: event generate" in err,
              "a write without the token is refused by the coordinator, with a usage line", code, out, err)
        wrong = os.path.join(scratch, "wrong.token")
        with open(wrong, "w") as f:
            f.write("0" * 64 + "\n")
        os.chmod(wrong, 0o600)
        code, out, err = system.console("--allow-write", "--token-file", wrong, "-c", "reset JR3 nothing")
        check(code == 2 and "token" in err, "a wrong token is refused", code, out, err)
        code, out, err = system.console("--json", "-c", "state list JR3")
        check(code == 0, "state list JR3 --json", out, err)
        rows = {r["address"]: r for r in map(json.loads, out.splitlines())}
        check(rows["JR3.s_A"]["state"] == "Normal" and rows["JR3.s_A"]["kind"] == "application",
              "refused writes changed nothing", out)

        # With the token: the event is processed, the state changes and propagates.
        code, out, err = system.console("--allow-write", *token, "-c",
                                        "event generate EVT_FORCE_ERROR JR3.s_A; state list JR3; explain CONTROL")
        check(code == 0, f"event generate with the token: exit {code}", out, err, system.logs())
        check("generated EVT_FORCE_ERROR on JR3.s_A" in out, "generate confirmation", out)
        check(any(l.split()[:3] == ["JR3.s_A", "Error", "EVT_FORCE_ERROR"] for l in out.splitlines()), "JR3.s_A in Error", out)
        check("<- JR3.s_A:EVT_FORCE_ERROR" in out and "path JR3.s_A -> JR3.s_S.ForceData" in out,
              "explain CONTROL names the root cause and its path", out)
        code, out, err = system.console("-c", "state history JR3.s_A 5; event history 3; bogus; state list NOPE")
        check(code == 2, "a bad command in -c makes the exit code 2", code, out, err)
        check("JR3.s_A  Normal -> Error  EVT_FORCE_ERROR" in out, "state history shows the transition", out, err)
        check("raised EVT_FORCE_ERROR" in out, "event history shows the event", out)
        check("unknown command 'bogus' (usage: help [COMMAND])" in err and "state list: " in err and "NOPE" in err,
              "bad commands get usage lines", err)
        code, out, err = system.console("--json", "-c", "explain CONTROL; state history JR3.s_A 1")
        lines = [json.loads(l) for l in out.splitlines()]
        check(code == 0 and lines and lines[0]["root_origin"] == "JR3.s_A" and lines[-1]["kind"] == "transition",
              "--json explain and history", out, err)
        code, out, err = system.console("-c", "time")
        check(code == 2 and "in-process only" in err, "time is in-process only", code, out, err)

        # watch follows the records the coordinator pushes: a completion generated meanwhile shows,
        # and so does a fault that lasts about a millisecond (a warning raised and cleared by two
        # requests back to back in another process), which no poll of the states would see. The
        # watch's window opens once its console has found the robot and proven it alive, which a
        # loaded machine delays by seconds: the changes are made again and again until the watch
        # ends (the error raised again after each round), so that some fall inside the window.
        watcher = subprocess.Popen([system.binary, "console", "--ice", system.ice, "--coordinator", "robot",
                                    "-c", "watch 4"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            rounds, failed = 0, []
            while watcher.poll() is None and rounds < 200:
                code, out, err = system.console("--allow-write", *token, "-c",
                                                "event generate /EVT_FORCE_ERROR JR3.s_A; "
                                                "event generate EVT_FORCE_HIGH JR3.s_A; event generate /EVT_FORCE_HIGH JR3.s_A; "
                                                "event generate EVT_FORCE_ERROR JR3.s_A")
                rounds += 1
                if code != 0:
                    failed.append((code, out, err))
            check(rounds > 0 and not failed, "the completion, the glitch (a warning raised and cleared at once) and "
                  "the error again, each round", rounds, failed[:1])
            watched, werr = watcher.communicate(timeout=30)
        finally:
            if watcher.poll() is None:
                watcher.kill()
                watcher.wait()
        code, out, err = system.console("--allow-write", *token, "-c", "event generate /EVT_FORCE_ERROR JR3.s_A")
        check(code == 0, "the completion event, as before the watch", out, err)
        check(watcher.returncode == 0, "watch exit code", watched, werr)
        check("JR3.s_A  Error -> Normal" in watched and "watched robot for 4 s:" in watched,
              "watch prints the change", watched)
        # Live times are wall-clock time, ISO 8601 in the local zone with milliseconds.
        check(re.search(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}[+-]\d\d:\d\d  JR3\.s_A  Error -> Normal", watched, re.M),
              "watch lines start with the wall-clock time", watched)
        check("JR3.s_A  Normal -> Warning  EVT_FORCE_HIGH" in watched and "JR3.s_A  Warning -> Normal  /EVT_FORCE_HIGH" in watched,
              "watch shows the glitch: both its transitions", watched)
        code, out, err = system.console("--json", "-c", "state history JR3.s_A 10")
        glitch = [r for r in (json.loads(l) for l in out.splitlines())
                  if r["kind"] == "transition" and r.get("event", "").endswith("EVT_FORCE_HIGH")]
        lasted = glitch[-1]["t"] - glitch[-2]["t"] if len(glitch) >= 2 else None
        check(lasted is not None and lasted < 0.02,
              f"the glitch lasted less than the 20 ms the states were once polled at ({lasted} s)", out, err)

        # A live timeline page of the coordinator's history.
        page = os.path.join(scratch, "live-timeline.html")
        if os.path.exists(page):
            os.unlink(page)
        done = subprocess.run([system.binary, "timeline", "--ice", system.ice, "--coordinator", "robot", "--html", page],
                              capture_output=True, text=True, timeout=20)
        check(done.returncode == 0 and os.path.exists(page), "timeline --ice wrote a page", done.stdout, done.stderr)
        html = open(page, encoding="utf-8").read()
        for part in ["coordinator robot (live, IceStorm", "JR3.s_A", "EVT_FORCE_ERROR", "CONTROL.s_R.ForceData"]:
            check(part in html, f"the live timeline has {part!r}", html[:2000])

        # Injections and a reset through the coordinator (values under the force limit: no fault);
        # a sample file is checked by the console first, so its errors name the line.
        good = os.path.join(scratch, "force.txt")
        bad = os.path.join(scratch, "bad.txt")
        with open(good, "w") as f:
            f.write("# force norm, N\n3\n4\n")
        with open(bad, "w") as f:
            f.write("3\n4 x\n")
        code, out, err = system.console("--allow-write", *token, "-c", "filter inject force_limit 3; filter dinject "
                                        f"JR3.ForceNorm 4 5; filter dinload JR3.ForceNorm {good}; reset JR3 checked")
        check(code == 0, f"injections and reset: exit {code}", out, err)
        for part in ["queued 1 sample into filter force_limit", "wrote 2 samples into signal JR3.ForceNorm",
                     "reset JR3 at ", "(checked)"]:
            check(part in out, f"injections and reset: no {part!r}", out)
        check(out.count("wrote 2 samples") == 2, "dinject and dinload both wrote", out)
        code, out, err = system.console("--allow-write", *token, "-c", f"filter dinload JR3.ForceNorm {bad}; "
                                        "filter inject NOPE 1; filter dinject JR3.NoSuch 1; filter inject force_limit x")
        check(code == 2 and out == "", "bad injections are refused", code, out, err)
        errors = err.splitlines()
        check(len(errors) == 4 and f"{bad}:2: 'x' is not a number" in errors[0] and "NOPE" in errors[1]
              and "JR3.NoSuch" in errors[2] and "'x' is not a number" in errors[3], "each bad injection says why", err)
        # Injected values are finite on this path too, and a sample file must be a regular file (read
        # here, by the console): refused before anything is sent, never a hang.
        infinite = os.path.join(scratch, "infinite.txt")
        with open(infinite, "w") as f:
            f.write("3\n-inf\n")
        fifo = os.path.join(scratch, "samples.fifo")
        if os.path.lexists(fifo):
            os.unlink(fifo)
        os.mkfifo(fifo)
        code, out, err = system.console("--allow-write", *token, "-c", "filter inject force_limit inf; filter dinject "
                                        f"JR3.ForceNorm nan; filter dinload JR3.ForceNorm {infinite}; "
                                        f"filter dinload JR3.ForceNorm /dev/zero; filter dinload JR3.ForceNorm {fifo}")
        check(code == 2 and out == "", "non-finite values and unreadable files are refused", code, out, err)
        errors = err.splitlines()
        check(len(errors) == 5 and "'inf' is not a finite number: injected values must be finite" in errors[0]
              and "'nan' is not a finite number" in errors[1] and f"{infinite}:2: '-inf' is not a finite number" in errors[2]
              and "cannot read file '/dev/zero': not a regular file (a character device)" in errors[3]
              and f"cannot read file '{fifo}': not a regular file (a FIFO)" in errors[4], "each refusal says why", err)

        # Unreachable: exit 2 with a message, never a hang.
        for args, what in [(["--coordinator", "nobody"], "no such coordinator"),
                           (["--ice", f"127.0.0.1:{free_port()}"], "no IceStorm")]:
            command = [system.binary, "console", "--ice", system.ice, "--coordinator", "robot", "--timeout", "700",
                       "-c", "state list"]
            flag = args[0]
            command[command.index(flag) + 1] = args[1]
            started = time.monotonic()
            done = subprocess.run(command, capture_output=True, text=True, timeout=15)
            took = time.monotonic() - started
            check(done.returncode == 2 and done.stderr.startswith("console: ") and took < 8,
                  f"{what}: exit 2 with a message in {took:.1f} s", done.stdout, done.stderr)
        done = subprocess.run([system.binary, "timeline", "--ice", f"127.0.0.1:{free_port()}", "--coordinator", "robot",
                               "--html", page + ".unused"], capture_output=True, text=True, timeout=15)
        check(done.returncode == 2 and "safecass timeline:" in done.stderr and not os.path.exists(page + ".unused"),
              "timeline --ice without IceStorm: exit 2", done.stderr)
        code, out, err = system.console("--token-file", os.path.join(scratch, "no-such.token"), "-c", "state list")
        check(code == 2 and "--token-file" in err, "an unreadable token file is an error", err)
    except (Failure, RuntimeError, subprocess.SubprocessError, OSError, ValueError, KeyError) as failure:
        print(f"FAILED: {failure}", file=sys.stderr)
        return 1
    finally:
        system.stop()
    print("console --ice test passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
