#!/usr/bin/env python3
"""Interactive `safecass console --ice` in a pseudo-terminal against a live robot coordinator:
the banner, TAB completion of command words and of names fetched from the coordinator, a write
with the token, up-arrow history, a refused command, quit. Reuses the pty driver of the
in-process console's test (tests/unit/tools/console_pty_test.py).

Usage: console_ice_pty_test.py SAFECASS_BINARY SOURCE_DIR SCRATCH_DIR
"""

import os
import signal
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "unit", "tools"))
from console_pty_test import Console, Failure  # noqa: E402
from live_system import LiveSystem  # noqa: E402


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    binary, source, scratch = sys.argv[1:]
    signal.alarm(110)  # a last resort: the default action ends this script
    system = LiveSystem(binary, source, scratch)
    console = None
    stopped = False  # the coordinator stopped with SIGSTOP (continued before it is stopped for good)
    try:
        system.start()
        console = Console(os.path.abspath(binary), source,
                          ("--ice", system.ice, "--coordinator", "robot", "--allow-write", "--token-file",
                           system.token_file, "--timeout", "5000"))
        # Connecting is several steps, each with its own bound (the heartbeat found within
        # --timeout, a proof of life, the first reads, Ice's 2 s calls): on a loaded machine they
        # add up to more than the 15 s any later line gets.
        console.expect(r"coordinator robot on IceStorm 127\.0\.0\.1:\d+ \(4 components\), live, writes allowed",
                       "banner", timeout=60)
        console.expect(r"safecass> ", "first prompt")

        # TAB completes a command word, then a component name fetched from the coordinator.
        console.send("state li\t")
        console.expect(r"state list", "TAB completion of 'state li'")
        console.send("CONT\t")
        console.expect(r"CONTROL", "TAB completion of a component name")
        console.send("\r")
        console.expect(r"\nCONTROL +Normal", "state list CONTROL")
        console.expect(r"safecass> ", "prompt after state list")

        # An event name and a machine address, both completed from the coordinator's names.
        console.send("event generate EVT_FORCE_ER\t")
        console.expect(r"EVT_FORCE_ERROR", "TAB completion of an event name")
        console.send("JR3.s_\t\t")
        console.expect(r"JR3\.s_A", "TAB listing of JR3's machines")
        console.send("A\r")
        console.expect(r"generated EVT_FORCE_ERROR on JR3.s_A", "event generate with the token")
        console.expect(r"safecass> ", "prompt after event generate")

        console.send("state list JR3\r")
        console.expect(r"\n  JR3\.s_A +Error +EVT_FORCE_ERROR", "JR3.s_A in Error")
        console.expect(r"safecass> ", "prompt after state list JR3")

        # Up arrow twice: the generate line again (a refresh of the same condition).
        console.send("\x1b[A")
        console.send("\x1b[A")
        console.expect(r"event generate EVT_FORCE_ERROR JR3\.s_A", "history (up arrow)")
        console.send("\r")
        console.expect(r"generated EVT_FORCE_ERROR on JR3.s_A", "the recalled command ran")
        console.expect(r"safecass> ", "prompt after the recalled command")

        # Errors from the coordinator are usage lines; the console goes on.
        console.send("explain NOPE\r")
        console.expect(r"explain: .*NOPE.* \(usage: explain ADDRESS\)", "an unknown address")
        console.expect(r"safecass> ", "prompt after a bad address")

        # Quitting does not wait on a coordinator that has stopped answering (here stopped with
        # SIGSTOP): closing the connection to it waits at most a second, not the endpoint's 60 s.
        os.kill(system.coordinator.pid, signal.SIGSTOP)
        stopped = True
        asked = time.monotonic()
        console.send("quit\r")
        status = console.wait_exit()
        took = time.monotonic() - asked
        if not os.WIFEXITED(status) or os.WEXITSTATUS(status) != 0:
            raise Failure(f"quit: exit status {status}, expected a normal exit with code 0")
        if took > 5.0:
            raise Failure(f"quit took {took:.1f} s beside a stopped coordinator (at most 5 s expected)")
    except (Failure, RuntimeError, OSError) as failure:
        print(f"FAILED: {failure}\n--- coordinator log ---\n{system.logs()}", file=sys.stderr)
        return 1
    finally:
        if console is not None:
            console.kill()
        if stopped:
            os.kill(system.coordinator.pid, signal.SIGCONT)
        system.stop()
    print("console --ice pty test passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
