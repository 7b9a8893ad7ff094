"""A live system for the `safecass console --ice` tests: IceStorm (scripts/start-icestorm on a free
port) and the robot coordinator of examples/robodoc as a `safecass run --coordinator` process with
write access. Both are stopped by PID in stop(), which the tests call in a `finally`.

Standard library only.
"""

import os
import signal
import subprocess
import time

TOKEN_WAIT = 15.0  # seconds for the coordinator to write its token file


class LiveSystem:
    def __init__(self, binary, source_dir, scratch):
        self.binary = os.path.abspath(binary)
        self.source = os.path.abspath(source_dir)
        self.scratch = os.path.abspath(scratch)
        os.makedirs(self.scratch, exist_ok=True)
        self.icestorm_pid = 0
        self.coordinator = None
        self.port = 0
        self.token_file = os.path.join(self.scratch, "robot.token")
        self.log = os.path.join(self.scratch, "robot.log")

    @property
    def ice(self):
        return f"127.0.0.1:{self.port}"

    def start(self):
        env_file = os.path.join(self.scratch, "icestorm.env")
        if os.path.exists(env_file):
            os.unlink(env_file)
        # The bus is authenticated and IceStorm admits only the system's certificates: the system's
        # keys, inherited by IceStorm and every process started here.
        keys = os.path.join(self.scratch, "keys")
        subprocess.run([self.binary, "keys", os.path.join(self.source, "examples/robodoc/robodoc.json"), "--out", keys,
                        "--replace"], check=True, stdout=subprocess.DEVNULL, timeout=20)
        os.environ["SAFECASS_KEYS"] = keys
        subprocess.run([os.path.join(self.source, "scripts", "start-icestorm"), "--port", "0", "--replace", "--dir",
                        os.path.join(self.scratch, "icestorm"), "--env", env_file],
                       check=True, stdout=subprocess.DEVNULL, timeout=45)  # the script waits 30 s itself
        values = dict(line.strip().split("=", 1) for line in open(env_file) if "=" in line)
        self.icestorm_pid = int(values["ICESTORM_PID"])
        self.port = int(values["ICESTORM_PORT"])
        if os.path.exists(self.token_file):
            os.unlink(self.token_file)
        with open(self.log, "w") as log:
            self.coordinator = subprocess.Popen(
                [self.binary, "run", os.path.join(self.source, "examples/robodoc/robodoc.json"), "--coordinator", "robot",
                 "--scenario", os.path.join(self.source, "tests/integration/console_ice/robot_quiet.json"),
                 "--ice", self.ice, "--allow-write", "--token-file", self.token_file, "--duration", "55",
                 # Not a test of loss detection: a loaded CI machine must not turn a late
                 # heartbeat into EVT_COORDINATOR_LOST (tests/integration/middleware covers it).
                 "--lost-after", "2000"],
                stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        deadline = time.monotonic() + TOKEN_WAIT
        while not (os.path.exists(self.token_file) and os.path.getsize(self.token_file) > 0):
            if self.coordinator.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("the robot coordinator did not start; its log:\n" + self.logs())
            time.sleep(0.05)

    def logs(self):
        try:
            with open(self.log) as f:
                return f.read()[-3000:]
        except OSError:
            return "(no log)"

    def console(self, *args, timeout=20):
        """Runs `safecass console --ice ... --coordinator robot ARGS`; returns (code, stdout, stderr).

        Waits up to 5 s for each answer (the default 2 s is too short for a loaded machine or a
        sanitizer build, where a reply can take longer and the console then prints nothing)."""
        command = [self.binary, "console", "--ice", self.ice, "--coordinator", "robot", "--timeout", "5000", *args]
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, cwd=self.source)
        return done.returncode, done.stdout, done.stderr

    def stop(self):
        if self.coordinator is not None and self.coordinator.poll() is None:
            self.coordinator.send_signal(signal.SIGTERM)
            try:
                self.coordinator.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.coordinator.kill()
                self.coordinator.wait()
        self.coordinator = None
        if self.icestorm_pid:
            try:
                os.kill(self.icestorm_pid, signal.SIGTERM)
                for _ in range(100):
                    os.kill(self.icestorm_pid, 0)
                    time.sleep(0.05)
                os.kill(self.icestorm_pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            self.icestorm_pid = 0
