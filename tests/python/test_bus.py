"""A live multi-process system from Python: the safecass_bus fixture starts IceStorm and the
coordinators and stops them by PID; connect() reaches a coordinator with the reader's certificate
and the keyring, and watch() iterates over its records (docs/python.md, "A live system")."""

import time

import pytest

import safecass
from conftest import ROBODOC


def test_a_live_coordinator_is_read_written_with_its_token_and_watched(safecass_bus):
    bus = safecass_bus(ROBODOC)
    bus.start("robot", allow_write=True)
    with bus.connect("robot") as reader:
        assert reader.name == "robot"
        assert reader.state("SYSTEM") in ("Normal", "Warning", "Error")
        with pytest.raises(safecass.Denied):
            reader.generate("EVT_FORCE_ERROR", "JR3.s_A")
        records = reader.watch(timeout=10)
        with bus.connect("robot", write=True) as writer:
            writer.generate("EVT_FORCE_ERROR", "JR3.s_A")
        seen = []
        deadline = time.monotonic() + 20
        for record in records:
            seen.append(record)
            if record.event == "EVT_FORCE_ERROR" and record.kind == "transition" or time.monotonic() > deadline:
                break
        assert any(r.event == "EVT_FORCE_ERROR" for r in seen)
        assert reader.state("JR3.s_A") == "Error"
        assert "JR3.s_A:EVT_FORCE_ERROR" in {c.root.name for c in reader.explain("SERVO").conditions}


def test_connecting_to_a_coordinator_that_is_not_there_is_a_bus_error(safecass_bus):
    bus = safecass_bus(ROBODOC)
    with pytest.raises(safecass.BusError):
        safecass.connect(bus.ice, "robot", keys=bus.keys, timeout=0.5)
