"""SAFECASS from Python: load, run, inject, read and verify the safety layer of a robot.

    import safecass
    robot = safecass.System("examples/robodoc/robodoc.json")
    robot.push("JR3.force", 80.0); robot.advance(0.01); print(robot.state("JR3"))

Every call goes through the C++ libraries the ``safecass`` command uses (docs/python.md): the
same checks, the same records, the same answers as the console and ``safecass run``.
"""

from __future__ import annotations

from typing import Any, Iterator

from ._safecass import (  # noqa: F401  (the public API)
    Coverage,
    Diagnostic,
    Explain,
    Explanation,
    Failure,
    Property,
    Record,
    RemoteSystem,
    Root,
    ScenarioResult,
    StateRow,
    System,
    VerifyReport,
    __version__,
    connect,
    load,
    replay,
    run_scenario,
    trace,
    validate,
    verify,
)
from ._safecass import _read_history, _read_inputs
from ._values import BusError, Denied, Error, InvalidArgument, InvalidState, NotFound, Result, SpecError

__all__ = [
    "BusError", "Coverage", "Denied", "Diagnostic", "Error", "Explain", "Explanation", "Failure", "History",
    "InvalidArgument", "InvalidState", "NotFound", "Property", "Record", "Recording", "RemoteSystem", "Result",
    "Root", "ScenarioResult", "SpecError", "StateRow", "System", "VerifyReport", "connect", "load",
    "read_history", "read_recording", "replay", "run_scenario", "trace", "validate", "verify", "watch",
]


def _pandas(array: Any) -> Any:
    try:
        import pandas
    except ImportError as e:  # pandas is optional
        raise ImportError("to_pandas() needs pandas (Debian: python3-pandas)") from e
    return pandas.DataFrame(array)


class Recording:
    """An inputs recording (``safecass run --record``'s ``.inputs``, docs/record-format.md).

    ``inputs`` is a numpy structured array, one row per value: ``time`` (seconds), ``signal``
    ("Component.signal"), ``index`` (the value's place in a vector sample, 0 for a scalar) and
    ``value``. ``actions`` lists the operator's actions as dicts, ``losses`` the samples the
    recorder could not keep, ``end`` the last tick of a cleanly closed recording (None when it was
    cut), ``truncated`` whether the file ended inside a record (a killed recorder) and
    ``cut_bytes`` how many bytes after its last whole record were left out.
    """

    def __init__(self, path: str) -> None:
        self.path = str(path)
        parts = _read_inputs(self.path)
        self.header: dict = parts["header"]
        self.inputs = parts["inputs"]
        self.actions: list = parts["actions"]
        self.losses: list = parts["losses"]
        self.end = parts["end"]
        self.truncated: bool = parts["truncated"]
        self.cut_bytes: int = parts["cut_bytes"]

    def signal(self, name: str, index: int = 0) -> tuple:
        """The (times, values) numpy arrays of one signal's element, ready to plot or to feed."""
        rows = self.inputs[(self.inputs["signal"] == name) & (self.inputs["index"] == index)]
        return rows["time"].copy(), rows["value"].copy()

    def to_pandas(self) -> Any:
        """The inputs as a pandas DataFrame (needs pandas)."""
        return _pandas(self.inputs)

    def __len__(self) -> int:
        return len(self.inputs)

    def __repr__(self) -> str:
        return f"<Recording {self.path}: {len(self.inputs)} values, {len(self.actions)} actions>"


class History:
    """A history file (``safecass run --record FILE``: JSON lines, docs/record-format.md).

    ``records`` is a numpy structured array, one row per record: ``time`` (seconds), ``seq``,
    ``kind`` ("event", "transition", ...), ``address`` (the machine, else the component),
    ``event``, ``level`` (a transition's new level, an event's level) and ``root``
    ("JR3.s_A:EVT_FORCE_ERROR", or ""). ``dropped`` counts records the recorder dropped; ``torn``
    is the line number of a torn last line (a killed recorder), or None, and ``cut_bytes`` its
    length.
    """

    def __init__(self, path: str) -> None:
        self.path = str(path)
        parts = _read_history(self.path)
        self.records = parts["records"]
        self.dropped: int = parts["dropped"]
        self.torn = parts["torn"]
        self.cut_bytes: int = parts["cut_bytes"]

    def levels(self, address: str) -> tuple:
        """The (times, levels) of one address's transitions, levels as 0 Normal, 1 Warning, 2 Error."""
        import numpy

        rows = self.records[(self.records["address"] == address) &
                            numpy.isin(self.records["kind"], ("transition", "component-transition"))]
        codes = numpy.select([rows["level"] == "Warning", rows["level"] == "Error"], [1, 2], 0)
        return rows["time"].copy(), codes.astype(numpy.int8)

    def to_pandas(self) -> Any:
        """The records as a pandas DataFrame (needs pandas)."""
        return _pandas(self.records)

    def __len__(self) -> int:
        return len(self.records)

    def __repr__(self) -> str:
        return f"<History {self.path}: {len(self.records)} records>"


def read_recording(path: str) -> Recording:
    """Reads an inputs recording into numpy arrays (SpecError when it is malformed)."""
    return Recording(path)


def read_history(path: str) -> History:
    """Reads a history file into a numpy array (SpecError naming the line when one is malformed)."""
    return History(path)


def watch(system: RemoteSystem, timeout: float | None = None) -> Iterator[Record]:
    """The coordinator's records from this call on, in order and each once, for as long as the
    caller iterates; with a timeout, the iteration ends after that many seconds without a record.
    """
    system._follow()  # now, not at the first next(): nothing between this call and the loop is missed
    return _records(system, timeout)


def _records(system: RemoteSystem, timeout: float | None) -> Iterator[Record]:
    while True:
        record = system._next_record(timeout if timeout is not None else 1.0)
        if record is not None:
            yield record
        elif timeout is not None:
            return


RemoteSystem.watch = watch  # type: ignore[attr-defined]
