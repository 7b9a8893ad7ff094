#!/usr/bin/env python3
"""`safecass viewer` out of file descriptors: accept() fails with EMFILE while connections wait in
the backlog. The viewer must back off (not spin a core, not flood its log) and serve again once
descriptors are free.

Usage: viewer_fd_limit_test.py SAFECASS_BINARY SOURCE_ROOT   (standard library only)
"""

import os
import re
import resource
import signal
import socket
import subprocess
import sys
import threading
import time

LIMIT = 48           # RLIMIT_NOFILE of the viewer: enough to start, soon exhausted by connections
CONNECTIONS = 120    # held open by this test: more than the viewer can accept
WINDOW = 3.0         # seconds of measurement while accept() keeps failing


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def cpu_seconds(pid):
    """User + system CPU time of a process, from /proc/PID/stat."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def main():
    safecass, root = sys.argv[1], sys.argv[2]

    def limit_fds():
        resource.setrlimit(resource.RLIMIT_NOFILE, (LIMIT, LIMIT))

    viewer = subprocess.Popen(
        [safecass, "viewer", "--system", "examples/robodoc/robodoc.json", "--port", "0"],
        cwd=root, stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=limit_fds)
    err_lines = []
    err_bytes = [0]

    def read_stderr():
        for line in iter(viewer.stderr.readline, b""):
            err_bytes[0] += len(line)
            err_lines.append((time.monotonic(), line.decode(errors="replace").rstrip("\n")))

    threading.Thread(target=read_stderr, daemon=True).start()
    sockets = []
    try:
        port = None
        deadline = time.monotonic() + 30
        while port is None and time.monotonic() < deadline:
            line = viewer.stdout.readline().decode()
            if line == "":
                fail("the viewer exited early: %s" % "\n".join(l for _, l in err_lines))
            m = re.search(r"open http://127\.0\.0\.1:(\d+)/", line)
            if m:
                port = int(m.group(1))
        if port is None:
            fail("no URL printed")
        threading.Thread(target=lambda: viewer.stdout.read(), daemon=True).start()

        # Hold many idle connections: the viewer keeps each (waiting for a request) until its
        # descriptors run out; the rest stay in the listen backlog and accept() fails with EMFILE.
        for _ in range(CONNECTIONS):
            s = socket.create_connection(("127.0.0.1", port), timeout=5)
            sockets.append(s)
        deadline = time.monotonic() + 10
        while not any("accept:" in l for _, l in err_lines) and time.monotonic() < deadline:
            time.sleep(0.05)
        accept_lines = [l for _, l in err_lines if "accept:" in l]
        if not accept_lines:
            fail("accept() never failed: is the limit too high? stderr: %s" % [l for _, l in err_lines])
        if "Too many open files" not in accept_lines[0] or "trying again in" not in accept_lines[0]:
            fail("the failure is not said with its reason and the wait: %r" % accept_lines[0])

        start_cpu = cpu_seconds(viewer.pid)
        start_bytes = err_bytes[0]
        start_lines = len(err_lines)
        time.sleep(WINDOW)
        cpu = cpu_seconds(viewer.pid) - start_cpu
        logged = err_bytes[0] - start_bytes
        lines = len(err_lines) - start_lines
        print("while out of descriptors for %.1f s: %.2f s of CPU, %d log lines (%d bytes)" % (WINDOW, cpu, lines, logged))
        if cpu > 0.5 * WINDOW:
            fail("the viewer spins while accept() fails: %.2f s of CPU in %.1f s" % (cpu, WINDOW))
        if lines > 1 or logged > 1000:
            fail("the log is flooded: %d lines, %d bytes in %.1f s" % (lines, logged, WINDOW))

        # Descriptors come back: the viewer serves again within its longest wait (1 s) and more.
        for s in sockets:
            s.close()
        sockets = []
        deadline = time.monotonic() + 10
        served = False
        while not served and time.monotonic() < deadline:
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=3) as s:
                    s.sendall(b"GET /api/view HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nConnection: close\r\n\r\n" % port)
                    reply = b""
                    while True:
                        chunk = s.recv(65536)
                        if not chunk:
                            break
                        reply += chunk
                    served = reply.startswith(b"HTTP/1.1 200")
            except OSError:
                pass
            if not served:
                time.sleep(0.2)
        if not served:
            fail("the viewer does not serve again after descriptors were freed")
        if viewer.poll() is not None:
            fail("the viewer stopped")
    finally:
        for s in sockets:
            s.close()
        if viewer.poll() is None:
            viewer.send_signal(signal.SIGTERM)
            try:
                viewer.wait(timeout=10)
            except subprocess.TimeoutExpired:
                viewer.kill()
                viewer.wait()
    print("ok: the viewer backs off while out of file descriptors and recovers")


if __name__ == "__main__":
    main()
