"""The parameter store's stage queue (FSW_PARAM_QUEUE) was 24 bytes, but no
PARAM_STAGE can carry more than 18 bytes of arguments: the link takes a
command of at most FSW_LINK_RX_CAP (24) bytes encoded, one COBS code byte,
the three bytes of its opcode and sequence number and two of CRC. Six bytes
of every application with parameters were never used, and with them the
parameters' RAM beyond their values (tools/bench_params.py, target <= 96 B)
was 100 B once an application without parameters read its commands where
the UART's ring holds them. Now the queue is the longest STAGE a frame
carries, 18 bytes, and the firmware refuses to build with one that could
not take it (a STAGE that never fits an empty queue would be BUSY for
ever)."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from conftest import ROOT
from fswkit.link import wire
from fswkit.param.client import RX_CAP, _encoded

CONFIG = (ROOT / "firmware/src/fsw_config.h").read_text()


def _define(name: str) -> int:
    m = re.search(rf"#  define {name} (\d+)", CONFIG)
    assert m, name
    return int(m.group(1))


def _longest_stage() -> int:
    return max(n for n in range(256) if _encoded(bytes(n)) <= RX_CAP)


def test_the_queue_is_the_longest_stage_a_frame_carries():
    assert _define("FSW_LINK_RX_CAP") == RX_CAP == 24
    # an encoded frame: a COBS code byte, opcode and sequence number, the arguments, the CRC
    assert wire.encoded_size(3 + 18) == 24 and _longest_stage() == 18
    assert _define("FSW_PARAM_QUEUE") == _longest_stage()


@pytest.mark.skipif(shutil.which("g++") is None, reason="no host C++ compiler")
def test_a_queue_that_cannot_take_the_longest_stage_does_not_build(tmp_path):
    src = tmp_path / "q.cpp"
    src.write_text('#include "fsw_param.h"\nint main() { return 0; }\n')
    # to an object, named relative to the test's folder: a compiler cache (ccache) keeps it
    args = ["g++", "-std=c++11", "-c", "-I", str(ROOT / "firmware/src"), "q.cpp", "-o", "q.o"]
    assert subprocess.run(args, capture_output=True, text=True, cwd=tmp_path).returncode == 0
    r = subprocess.run(args + ["-DFSW_PARAM_QUEUE=17"], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode != 0 and "FSW_PARAM_QUEUE" in r.stderr, r.stderr
