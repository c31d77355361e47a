"""`[log] element altitude delta=1e-45` passed `fsw check` and built: the
firmware multiplies a sample by 1/STEP in binary32, and 1/1e-45 is no
binary32 number (the generated table said `1e+45f`, infinity), so every
sample of the element was recorded as the saturated count. A step below
about 2.94e-39 is now refused at the number, and the message for a step
above the limit says the limit (it said "a positive number" of `1e38`)."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES

LINE = "element altitude delta=0.5"


def project(tmp_path, encoding: str):
    shutil.copytree(EXAMPLES / "hpr", tmp_path / "hpr")
    app = tmp_path / "hpr" / "hpr.app"
    text = app.read_text()
    assert LINE in text
    app.write_text(text.replace(LINE, f"element altitude {encoding}"))
    return app


@pytest.mark.parametrize("encoding", ["delta=1e-45", "quant=1e-45", "delta=2.9e-39", "quant=1e-40"])
def test_a_step_whose_inverse_is_no_binary32_number_is_refused(fsw, tmp_path, encoding):
    r = fsw("check", str(project(tmp_path, encoding)))
    assert r.code == 1, r.out
    assert "hpr.app:49:24:" in r.err
    assert "too small a count" in r.err and "1/STEP in binary32" in r.err
    assert "Traceback" not in r.err


@pytest.mark.parametrize("encoding", ["delta=2.94e-39", "quant=1e-30", "delta=1000000"])
def test_steps_within_the_range_are_accepted(fsw, tmp_path, encoding):
    r = fsw("check", str(project(tmp_path, encoding)))
    assert r.code == 0, r.err


def test_a_step_above_the_limit_says_the_limit(fsw, tmp_path):
    r = fsw("check", str(project(tmp_path, "delta=1e38")))
    assert r.code == 1, r.out
    assert "a positive number up to 1,000,000, found `1e38`" in r.err
