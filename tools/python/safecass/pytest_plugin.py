"""SAFECASS's pytest plugin (found through its ``pytest11`` entry point once safecass is importable).

Scenario files become test items: a ``.json`` file whose name matches the ini option
``safecass_scenarios`` (default ``*.scenario.json``), or any scenario file named on pytest's
command line. A failed expectation is reported with its file:line:col and the explain chain of
its address at the failing tick; JUnit XML comes from pytest's own ``--junitxml``.

Fixtures:

``safecass_system``
    A factory: ``safecass_system(path, scenario="", record="")`` builds a :class:`safecass.System`
    in this process; every system it made is closed at the end of the test.
``safecass_bus``
    A factory for a running multi-process system: ``bus = safecass_bus(system_file)`` makes the
    system's keys, starts IceStorm on a free port of 127.0.0.1, and ``bus.start(coordinator)``
    starts one coordinator process (``safecass run --coordinator NAME --ice ...``) and waits until
    it answers; ``bus.connect(coordinator)`` returns a :class:`safecass.RemoteSystem`. Every
    process is stopped by its PID at the end of the test.
"""

from __future__ import annotations

import fnmatch
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path
from typing import Any, Callable, Iterator

import pytest

import safecass


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addini("safecass_scenarios", "glob of the scenario files collected as tests", default="*.scenario.json")


def _is_scenario(path: Path) -> bool:
    try:
        with open(path, encoding="utf-8") as f:
            head = f.read(65536)
    except OSError:
        return False
    return '"steps"' in head


def pytest_collect_file(parent: pytest.Collector, file_path: Path) -> pytest.Collector | None:
    if file_path.suffix != ".json":
        return None
    pattern = parent.config.getini("safecass_scenarios")
    named = parent.session.isinitpath(file_path) and _is_scenario(file_path)
    if named or fnmatch.fnmatch(file_path.name, pattern):
        return ScenarioFile.from_parent(parent, path=file_path)
    return None


class ScenarioFile(pytest.File):
    def collect(self) -> Iterator[pytest.Item]:
        yield ScenarioItem.from_parent(self, name=self.path.name)


class ScenarioFailed(Exception):
    def __init__(self, result: safecass.ScenarioResult) -> None:
        super().__init__(result)
        self.result = result


class ScenarioItem(pytest.Item):
    """One scenario file, run with ``safecass.run_scenario``: it passes when every expectation holds."""

    def runtest(self) -> None:
        result = safecass.run_scenario(str(self.path))
        self.user_properties.append(("checks", result.checks))
        if not result.passed:
            raise ScenarioFailed(result)

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException], style: Any = None) -> str:
        error = excinfo.value
        if isinstance(error, ScenarioFailed):
            lines = []
            for failure in error.result.failures:
                lines.append(str(failure))
                lines.extend("    " + line for line in failure.explain.rstrip("\n").splitlines())
            known = {str(f) for f in error.result.failures}
            lines.extend(p for p in error.result.problems if p not in known)
            return "\n".join(lines)
        if isinstance(error, safecass.SpecError):
            return str(error)
        return super().repr_failure(excinfo)

    def reportinfo(self) -> tuple:
        return self.path, 0, f"scenario {self.path.name}"


@pytest.fixture
def safecass_system() -> Iterator[Callable[..., safecass.System]]:
    made: list[safecass.System] = []

    def make(path: str, scenario: str = "", record: str = "") -> safecass.System:
        system = safecass.System(str(path), scenario=str(scenario), record=str(record))
        made.append(system)
        return system

    yield make
    for system in made:
        system.close()


def _command() -> str:
    found = os.environ.get("SAFECASS") or shutil.which("safecass")
    if not found:
        raise pytest.UsageError("the safecass command is not found: install it, or set SAFECASS to its path")
    return found


def _start_icestorm() -> str:
    """scripts/start-icestorm: $SAFECASS_START_ICESTORM, else next to the command (a build tree's
    source, an installed libexec)."""
    given = os.environ.get("SAFECASS_START_ICESTORM")
    if given:
        return given
    command = Path(_command()).resolve()
    for candidate in (command.parent.parent / "libexec" / "safecass" / "start-icestorm",
                      Path(__file__).resolve().parent.parent.parent.parent / "scripts" / "start-icestorm"):
        if candidate.is_file():
            return str(candidate)
    raise pytest.UsageError("start-icestorm is not found: set SAFECASS_START_ICESTORM to its path")


class Bus:
    """IceStorm and the coordinators of one system, started for one test and stopped by PID."""

    def __init__(self, system: str, scratch: Path) -> None:
        self.system = str(Path(system).resolve())
        self.scratch = scratch
        self.keys = str(scratch / "keys")
        self.command = _command()
        self.processes: dict[str, subprocess.Popen] = {}
        self.tokens: dict[str, str] = {}
        self.icestorm_pid = 0
        scratch.mkdir(parents=True, exist_ok=True)
        subprocess.run([self.command, "keys", self.system, "--out", self.keys], check=True,
                       capture_output=True, timeout=60)
        env_file = scratch / "icestorm.env"
        subprocess.run([_start_icestorm(), "--keys", self.keys, "--port", "0", "--dir", str(scratch / "icestorm"),
                        "--env", str(env_file)], check=True, capture_output=True, timeout=60)
        values = dict(line.strip().split("=", 1) for line in env_file.read_text().splitlines() if "=" in line)
        self.icestorm_pid = int(values["ICESTORM_PID"].strip("'\""))
        self.ice = "127.0.0.1:" + values["ICESTORM_PORT"].strip("'\"")

    def start(self, coordinator: str, *extra: str, allow_write: bool = False, timeout: float = 30.0) -> None:
        """Starts one coordinator of the system and returns once a client can reach it."""
        command = [self.command, "run", self.system, "--coordinator", coordinator, "--ice", self.ice,
                   "--keys", self.keys, *extra]
        if allow_write:
            token = str(self.scratch / f"{coordinator}.token")
            command += ["--allow-write", "--token-file", token]
            self.tokens[coordinator] = token
        log = open(self.scratch / f"{coordinator}.log", "w")
        self.processes[coordinator] = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + timeout
        while True:
            try:
                self.connect(coordinator, timeout=1.0).close()
                return
            except safecass.Error:
                if self.processes[coordinator].poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"coordinator {coordinator} did not come up; its log: "
                                       f"{self.scratch / (coordinator + '.log')}")

    def connect(self, coordinator: str, write: bool = False, timeout: float = 2.0) -> safecass.RemoteSystem:
        token = self.tokens.get(coordinator, "") if write else ""
        return safecass.connect(self.ice, coordinator, keys=self.keys, token=token, timeout=timeout)

    def stop(self, coordinator: str) -> None:
        process = self.processes.pop(coordinator, None)
        if process is not None and process.poll() is None:
            process.send_signal(signal.SIGTERM)
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()

    def close(self) -> None:
        for name in list(self.processes):
            self.stop(name)
        if self.icestorm_pid:
            _stop(self.icestorm_pid)


def _stop(pid: int, grace: float = 10.0) -> None:
    """SIGTERM, then SIGKILL after `grace` seconds; returns once the process is gone."""
    try:
        os.kill(pid, signal.SIGTERM)
        deadline = time.monotonic() + grace
        while time.monotonic() < deadline:
            os.kill(pid, 0)
            time.sleep(0.05)
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


@pytest.fixture
def safecass_bus(tmp_path: Path) -> Iterator[Callable[[str], Bus]]:
    made: list[Bus] = []

    def make(system: str) -> Bus:
        bus = Bus(system, tmp_path / f"bus{len(made)}")
        made.append(bus)
        return bus

    yield make
    for bus in made:
        bus.close()
