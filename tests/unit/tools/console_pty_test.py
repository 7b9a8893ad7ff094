#!/usr/bin/env python3
"""Interactive `safecass console` in a pseudo-terminal: TAB completion, a write, up-arrow history
and quit. Every wait has a timeout and the console is killed on any failure, so it never hangs.

Usage: console_pty_test.py SAFECASS_BINARY SOURCE_DIR
"""

import os
import pty
import re
import select
import signal
import sys
import time

TIMEOUT = 15.0  # seconds for any one expected output
ANSI = re.compile(rb"\x1b\[[0-9;?]*[ -/]*[@-~]|\x1b[()][0-9A-Za-z]|\x1b[=>78]|\x1bO[A-Za-z]|\r|\x07")


class Failure(Exception):
    pass


class Console:
    """`safecass console ARGS` on a pseudo-terminal (default ARGS: the in-process ROBODOC system)."""

    def __init__(self, binary, source_dir, args=("--system", "examples/robodoc/robodoc.json", "--allow-write")):
        self.pid, self.fd = pty.fork()
        if self.pid == 0:  # child: the console on the pty
            try:
                os.chdir(source_dir)
                env = dict(os.environ, TERM="xterm", COLUMNS="200", LINES="50")
                os.execve(binary, [binary, "console", *args], env)
            finally:
                os._exit(127)
        self.raw = b""
        self.seen = 0  # offset in the cleaned text up to which output has been matched

    def text(self):
        return ANSI.sub(b"", self.raw).decode("utf-8", "replace")

    def read_some(self, deadline):
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            return False
        ready, _, _ = select.select([self.fd], [], [], remaining)
        if not ready:
            return False
        try:
            chunk = os.read(self.fd, 4096)
        except OSError:  # EIO: the child closed the terminal
            return None
        if not chunk:
            return None
        self.raw += chunk
        return True

    def expect(self, pattern, what, timeout=TIMEOUT):
        """Waits until `pattern` (a regex) appears in the output after what was matched before, for
        at most `timeout` seconds."""
        deadline = time.monotonic() + timeout
        regex = re.compile(pattern)
        while True:
            match = regex.search(self.text(), self.seen)
            if match:
                self.seen = match.end()
                return match
            got = self.read_some(deadline)
            if got is None or got is False:
                tail = self.text()[self.seen:][-800:]
                reason = "the console ended" if got is None else "timeout"
                raise Failure(f"{what}: {reason} waiting for {pattern!r}; output since the last match:\n{tail}")

    def send(self, data):
        os.write(self.fd, data.encode())

    def wait_exit(self):
        deadline = time.monotonic() + TIMEOUT
        while time.monotonic() < deadline:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid == self.pid:
                self.pid = 0
                return status
            if self.read_some(min(deadline, time.monotonic() + 0.1)) is None:
                time.sleep(0.05)
        raise Failure("quit: the console did not exit")

    def kill(self):
        if self.pid:
            try:
                os.kill(self.pid, signal.SIGKILL)
                os.waitpid(self.pid, 0)
            except OSError:
                pass
            self.pid = 0


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    binary, source_dir = os.path.abspath(sys.argv[1]), sys.argv[2]
    signal.alarm(120)  # a last resort: the default action ends this script
    console = Console(binary, source_dir)
    try:
        console.expect(r"safecass> ", "first prompt")

        # TAB completes the command word.
        console.send("state li\t")
        console.expect(r"state list", "TAB completion of 'state li'")
        console.send("\r")
        console.expect(r"\nSYSTEM +Normal", "state list")
        console.expect(r"safecass> ", "prompt after state list")

        # TAB completes a name too: the event.
        console.send("event generate EVT_CONTROL_FORCE_FR\t")
        console.expect(r"EVT_CONTROL_FORCE_FREEZE", "TAB completion of an event name")
        console.send("CONTROL.s_A\r")
        console.expect(r"generated EVT_CONTROL_FORCE_FREEZE on CONTROL.s_A", "event generate")
        console.expect(r"safecass> ", "prompt after event generate")

        console.send("state list\r")
        console.expect(r"\nCONTROL +Error +EVT_CONTROL_FORCE_FREEZE", "CONTROL in Error")
        console.expect(r"safecass> ", "prompt after the second state list")

        # Up arrow twice: back to the event generate line, run again (a refresh: no transition).
        console.send("\x1b[A")
        console.send("\x1b[A")
        console.expect(r"event generate EVT_CONTROL_FORCE_FREEZE CONTROL\.s_A", "history (up arrow)")
        console.send("\r")
        console.expect(r"generated EVT_CONTROL_FORCE_FREEZE on CONTROL.s_A", "the recalled command ran")
        console.expect(r"safecass> ", "prompt after the recalled command")

        # A bad command changes nothing and the console goes on.
        console.send("frobnicate\r")
        console.expect(r"unknown command 'frobnicate' \(usage: help \[COMMAND\]\)", "usage line")
        console.expect(r"safecass> ", "prompt after a bad command")

        console.send("quit\r")
        status = console.wait_exit()
        if not os.WIFEXITED(status) or os.WEXITSTATUS(status) != 0:
            raise Failure(f"quit: exit status {status}, expected a normal exit with code 0")
    except Failure as failure:
        print(f"FAILED: {failure}", file=sys.stderr)
        return 1
    finally:
        console.kill()
    print("console pty test passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
