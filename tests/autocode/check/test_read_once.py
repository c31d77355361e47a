"""A command reads a file once (autocode/memo.py): `fsw check PROJECT` meets
the machine and the state vector through the `.app` and as files of their
own, and parses and checks each once; a file with diagnostics is read
again wherever it is met, and says the same as with nothing kept."""

from __future__ import annotations

import shutil

import pytest

from conftest import EXAMPLES, run_fsw

from fswkit.autocode import check, memo, parser


@pytest.fixture
def counted(monkeypatch):
    calls = {"parse_sm": 0, "check_sm": 0}
    parse, checker = parser._parse_sm, check._check_sm

    def parse_sm(src, diags):
        calls["parse_sm"] += 1
        return parse(src, diags)

    def check_sm(f, src, sv, diags):
        calls["check_sm"] += 1
        return checker(f, src, sv, diags)

    monkeypatch.setattr(parser, "_parse_sm", parse_sm)
    monkeypatch.setattr(check, "_check_sm", check_sm)
    memo.clear()
    yield calls
    memo.clear()


def _project(tmp_path):
    project = tmp_path / "tank"
    shutil.copytree(EXAMPLES / "tank", project, ignore=shutil.ignore_patterns("build", "*.ss", "tank_typo.sm"))
    return project


def test_a_projects_machine_is_parsed_and_checked_once(counted, tmp_path):
    r = run_fsw("check", str(_project(tmp_path)))
    assert r.code == 0 and ", 0 errors," in r.err, r.err
    assert counted == {"parse_sm": 1, "check_sm": 1}


def test_an_edited_file_is_read_again(counted, tmp_path):
    project = _project(tmp_path)
    assert run_fsw("check", str(project)).code == 0
    sm = project / "tank.sm"
    sm.write_text(sm.read_text() + "\n")  # the same machine, another text
    assert run_fsw("check", str(project)).code == 0
    assert counted == {"parse_sm": 2, "check_sm": 2}


@pytest.mark.parametrize("bad", ["    valveOpen = nosuch\n", "    valveOpen = 1 $ 2\n", "    x = (1\n"])
def test_a_file_with_diagnostics_says_the_same_as_with_nothing_kept(bad, tmp_path, monkeypatch):
    project = _project(tmp_path)
    sm = project / "tank.sm"
    sm.write_text(sm.read_text() + "\n[Extra]\n.step\n" + bad)
    memo.clear()
    kept = run_fsw("check", str(project))
    # as before anything was kept: every reading straight into the command's diagnostics
    monkeypatch.setattr(memo, "run", lambda key, objs, diags, compute: compute(diags))
    fresh = run_fsw("check", str(project))
    assert kept.code == fresh.code != 0
    assert kept.err == fresh.err and kept.out == fresh.out
