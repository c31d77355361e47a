"""`fsw plot -o` writes exactly the file it names, in the format its
extension names, or refuses before decoding anything: no extension, or one
that is not an image format (`out.txt`), is a clear error, never a
traceback after the work or a report of a file it did not write."""

from __future__ import annotations

import pytest
from conftest import run_fsw
from support.linkstream import write_log


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    return write_log(tmp_path_factory.mktemp("plot") / "flight.log", 300)


@pytest.mark.parametrize("name", ["out.txt", "noext", "out.", "out.png.bak"])
def test_unknown_or_missing_extension_is_refused_before_work(log, tmp_path, name):
    out = tmp_path / name
    r = run_fsw("plot", str(log), "-e", "tankPressure", "-o", str(out))
    assert r.code == 1, r.err
    assert "Traceback" not in r.err and "internal error" not in r.err, r.err
    assert "image format" in r.err and ".png" in r.err, r.err
    assert list(tmp_path.iterdir()) == []  # nothing written, not even `noext.png`


@pytest.mark.parametrize("name", ["p.png", "p.svg", "p.PDF"])
def test_the_named_file_is_written(log, tmp_path, name):
    out = tmp_path / name
    r = run_fsw("plot", str(log), "-e", "tankPressure", "-o", str(out))
    assert r.code == 0, r.err
    assert [p.name for p in tmp_path.iterdir()] == [name]
    assert f"fsw plot: {out}:" in r.err
    head = out.read_bytes()[:8]
    assert head.startswith({"png": b"\x89PNG", "svg": b"<?xml", "pdf": b"%PDF"}[name.rsplit(".", 1)[1].lower()])
