"""What the bindings raise, and the plain result objects made from the tools' JSON answers.

The C++ module raises these classes; they live here so that they are ordinary Python classes
(picklable, subclassable, documented) that a test can catch by their standard bases too:
``except LookupError`` catches :class:`NotFound`.
"""

from __future__ import annotations

import copy
import json
from typing import Any, Iterator


class Error(Exception):
    """Every error of SAFECASS. ``code`` names the kind: "not-found", "invalid-argument", "denied", ..."""

    code = "error"

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


class NotFound(Error, LookupError):
    """A name or an address that the system does not have. Nothing was changed."""

    code = "not-found"


class InvalidArgument(Error, ValueError):
    """A value outside its range or of the wrong shape. Nothing was changed."""

    code = "invalid-argument"


class InvalidState(Error):
    """Not allowed in the system's current state (an injection into a disabled filter, ...)."""

    code = "invalid-state"


class Denied(Error, PermissionError):
    """A write refused: no write access, or a wrong token."""

    code = "denied"


class BusError(Error, OSError):
    """A file that cannot be read or written, or a live system that does not answer in time."""

    code = "io"


class SpecError(Error):
    """A specification, scenario or recording that cannot be used, with every problem found.

    ``diagnostics`` holds each problem (file, line, column, severity, message, pointer); the
    message is their lines as ``safecass validate`` prints them, ``file:line:col: error: ...``.
    ``file``, ``line`` and ``column`` are those of the first one.
    """

    code = "parse"

    def __init__(self, message: str, diagnostics: list | None = None) -> None:
        super().__init__(message)
        self.diagnostics = list(diagnostics or [])
        first = self.diagnostics[0] if self.diagnostics else None
        self.file = first.file if first is not None else ""
        self.line = first.line if first is not None else 0
        self.column = first.column if first is not None else 0


class Result:
    """A read-only result made of named fields: a tool's JSON answer as an object.

    Fields are attributes (``report.holds``); nested objects are Results and lists are lists.
    ``to_dict()`` gives the answer as plain dicts and lists, the same keys as the command's
    ``--json`` output.
    """

    __slots__ = ("_fields",)

    def __init__(self, fields: dict) -> None:
        object.__setattr__(self, "_fields", fields)

    @classmethod
    def from_json(cls, text: str) -> "Result":
        return cls(json.loads(text))

    def __getattr__(self, name: str) -> Any:
        fields = object.__getattribute__(self, "_fields")
        if name in fields:
            return _wrap(fields[name])
        raise AttributeError(f"{type(self).__name__} has no field {name!r} (fields: {', '.join(fields)})")

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is read-only")

    def __getitem__(self, name: str) -> Any:
        return _wrap(self._fields[name])

    def __contains__(self, name: str) -> bool:
        return name in self._fields

    def __iter__(self) -> Iterator[str]:
        return iter(self._fields)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Result) and self._fields == other._fields

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}={v!r}" for k, v in self._fields.items() if not isinstance(v, (list, dict)))
        return f"{type(self).__name__}({shown})"

    def to_dict(self) -> dict:
        return copy.deepcopy(self._fields)


def _wrap(value: Any) -> Any:
    if isinstance(value, dict):
        return Result(value)
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value
