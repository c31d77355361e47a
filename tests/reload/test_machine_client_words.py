"""What the ground's machine client says when the target's answers are
not the ones it hoped for (fswkit/reload/client.py), with the target's
answers stubbed:

- an activation still pending after `--wait` seconds was blamed on the
  running machine's state, also when the target was still checking the
  image (its check runs a slice a machine step: `--wait 0` got that message
  with the machine in an allowed state all along);
- a MACHINE_INFO answer with a slot number past 2 (a target of another
  version, a corrupted answer) made `revert` index the slots with it: an
  IndexError traceback, or the wrong slot."""

from __future__ import annotations

import pytest

from fswkit.reload.client import NONE, Info, MachineClient, MachineError, Slot


class Clock:
    """A transport whose time moves only when it is waited on; nothing goes
    over it (the client's commands are stubbed)."""

    session = None

    def __init__(self):
        self.t = 0.0

    def now(self) -> float:
        return self.t

    def events(self, wait: float):
        self.t += wait
        return []

    def send(self, data: bytes) -> None:
        pass


def _client(monkeypatch, info: Info) -> MachineClient:
    c = MachineClient(Clock(), 64)
    monkeypatch.setattr(c, "info", lambda: info)
    monkeypatch.setattr(c, "_one", lambda op, args=b"": {"status": 0, "status_name": "OK", "reason": "", "data": b""})
    return c


def _info(active=0, pending=NONE, refused=0, slot_status=(1, 0)) -> Info:
    return Info(active, pending, refused, 0, False, 384, 64, 0, 0, 0, 0, 0,
                (Slot(1, slot_status[0], 1, 187, 1, 0xbd0e), Slot(2, slot_status[1], 0, 0, 0, 0)))


def test_a_pending_activation_names_both_things_it_waits_for(monkeypatch):
    c = _client(monkeypatch, _info(pending=1))
    with pytest.raises(MachineError) as e:
        c.activate(1, 0.0)
    said = str(e.value)
    assert said.startswith("not switched after 0 s: the target checks the image first")
    assert "then switches when the running machine is in a state in which another may take over" in said
    assert "the activation stays pending" in said


@pytest.mark.parametrize("field, value", [("active", 7), ("pending", 3), ("refused", 9)])
def test_an_info_answer_naming_no_slot_is_refused_in_words(monkeypatch, field, value):
    from fswkit.autocode.protocol import RELOAD_INFO, RELOAD_SLOT

    fields = dict(active=0, pending=NONE, refused=0)
    fields[field] = value
    data = RELOAD_INFO.pack(fields["active"], fields["pending"], fields["refused"], 0, 0, 384, 64, 0, 0, 0, 0, 0) \
        + RELOAD_SLOT.pack(2, 1, 187, 1, 0xbd0e) * 2
    c = MachineClient(Clock(), 64)
    monkeypatch.setattr(c, "_one", lambda op, args=b"": {"status": 0, "status_name": "OK", "reason": "", "data": data})
    with pytest.raises(MachineError) as e:
        c.revert(1.0)
    assert f"the target's MACHINE_INFO answer names {field} {value}" in str(e.value)
