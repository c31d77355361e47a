"""The link's numbers are written twice, once per side of the wire: in
autocode (autocode/protocol.py, autocode/types.py, autocode/app.py), from
which the generator sizes the firmware's buffers and the ground tools
decode, and in the runtime's headers. This test reads the headers and holds
the two equal: protocol number, header length, frame types, opcodes,
acknowledgement codes, payload sizes, the encoded-size bound, task modes,
element type codes and sizes."""

from __future__ import annotations

import re

from conftest import ROOT

from fswkit.autocode import protocol as P
from fswkit.autocode.app import TASK_MODES
from fswkit.autocode.emit.app import ELEM_CODE
from fswkit.autocode.types import TYPES
from fswkit.link import wire

SRC = ROOT / "firmware" / "src"


def header(name: str) -> str:
    text = (SRC / name).read_text()
    return re.sub(r"//[^\n]*", "", text)  # comments say numbers too


def constant(text: str, name: str) -> int:
    m = re.search(rf"static const uint8_t {name} = (\w+);", text)
    assert m, f"{name} not found"
    return int(m.group(1), 0)


def enum(text: str, name: str) -> dict[str, int]:
    m = re.search(rf"enum {name} : uint8_t \{{(.*?)\}};", text, re.S)
    assert m, f"enum {name} not found"
    out = {}
    for item in m.group(1).split(","):
        if item.strip():
            k, v = (s.strip() for s in item.split("="))
            out[k] = int(v, 0)
    return out


def snake(camel: str) -> str:
    return re.sub(r"(?<!^)(?=[A-Z])", "_", camel).upper()


def test_protocol_number_and_header():
    h = header("fsw_link.h")
    assert constant(h, "kLinkProtocol") == P.PROTOCOL == wire.PROTOCOL
    assert constant(h, "kLinkHeader") == P.HEADER == wire.HEADER


def test_frame_types():
    frames = enum(header("fsw_link.h"), "LinkFrame")
    assert frames == {"kFrameHello": P.HELLO, "kFrameHealth": P.HEALTH, "kFrameAck": P.ACK,
                      "kFrameSnapshot": P.SNAPSHOT, "kFrameSample": P.SAMPLE}


def test_opcodes():
    ops = enum(header("fsw_link.h"), "LinkOp")
    assert {snake(k[len("kOp"):]).lower(): v for k, v in ops.items()} == {n: op for op, n in P.OP_NAMES.items()}


def test_acknowledgement_codes():
    status = enum(header("fsw_link.h"), "LinkStatus")
    assert {v: snake(k[len("kAck"):]) for k, v in status.items()} == {v: name for v, (name, _) in P.STATUS.items()}


def test_payload_sizes_and_the_encoded_bound():
    """link_config_ok checks the transmit buffer against a hello, a health
    frame for n tasks and a snapshot chunk: the sizes the generator plans
    the buffer with (schema.link_plan)."""
    h = header("fsw_link.h")
    hello = re.search(r"link_encoded_max\(kLinkHeader \+ (\d+)u\)", h)
    health = re.search(r"link_encoded_max\(kLinkHeader \+ (\d+)u \+ (\d+)u \* n_tasks \+ n_pyro\)", h)
    snapshot = re.search(r"link_encoded_max\(kLinkHeader \+ (\d+)u \+ snapshot_chunk\)", h)
    assert hello and health and snapshot
    assert int(hello.group(1)) == P.HELLO_PAYLOAD.size
    assert (int(health.group(1)), int(health.group(2))) == (P.HEALTH_PAYLOAD.size, P.HEALTH_TASK.size)
    assert P.HEALTH_PYRO == 1  # n_pyro bytes: a status byte a channel
    assert int(snapshot.group(1)) == P.SNAPSHOT_OFFSET
    bound = re.search(r"link_encoded_max\(uint32_t body\) \{ return (.*?); \}", h)
    assert bound
    assert bound.group(1) == "body + 2u + (body + 2u) / 254u + 2u"
    for body in (0, 1, 251, 252, 253, 254, 505, 506, 2000):
        assert P.encoded_max(body + P.CRC) == body + 2 + (body + 2) // 254 + 2
        assert wire.encoded_size(body) == P.encoded_max(body + P.CRC) - 1  # the ground's, without the delimiter


def test_task_modes():
    modes = enum(header("fsw_executor.h"), "TaskMode")
    assert {k[len("kMode"):].lower(): v for k, v in modes.items()} == TASK_MODES


def test_element_types():
    """The same types, and each type's size as fsw_types.h computes it from
    its code (`elem_size`)."""
    codes = enum(header("fsw_types.h"), "ElemType")
    assert {k[1:] if k != "kBool" else "bool" for k in codes} == set(TYPES)
    assert {c.removeprefix("fsw::") for c in ELEM_CODE.values()} == set(codes)  # what the generator writes
    for k, code in codes.items():
        t = TYPES[k[1:] if k != "kBool" else "bool"]
        size = 1 if t.is_bool else 1 << (code - 6 if code >= codes["kF32"] else code & 3)
        assert size == t.size, k


def test_pyro_status_bits_and_the_resumed_bit():
    """The health frame's pyro status bits (fsw_io.h) and the reset cause's
    resumed bit (fsw_resume.h) are the ground's."""
    consts = dict((k, int(v, 16)) for k, v in re.findall(r"static const uint8_t (k\w+) = (0x[0-9A-Fa-f]+);",
                                                         header("fsw_io.h") + header("fsw_resume.h")))
    assert (consts["kPyroArmed"], consts["kPyroContinuity"], consts["kPyroNoSense"], consts["kPyroFired"],
            consts["kPyroFiring"]) == (P.PYRO_ARMED, P.PYRO_CONTINUITY, P.PYRO_NO_SENSE, P.PYRO_FIRED,
                                       P.PYRO_FIRING)
    assert consts["kResetResumed"] == P.RESET_RESUMED
