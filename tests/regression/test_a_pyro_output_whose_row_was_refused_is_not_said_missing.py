"""A pyro channel's `.dio` row refused for its own reason (its pin already
used by another row) was reported twice: at the row, and again at the
`[pyro]` row as "`main` is not a digital output", which is false -- the
table declares it one, on a pin it cannot have. The [pyro] row now says
nothing more of an output whose table row was refused: one error, where
the fault is."""

from __future__ import annotations

from conftest import run_fsw
from support.configs import edit, example_copy


def test_one_error_at_the_refused_row(tmp_path):
    proj = example_copy("rocket", tmp_path)
    edit(proj / "rocket.dio", "o      5    drogue", "o      6    drogue")  # main's pin
    r = run_fsw("check", str(proj))
    out = r.out + r.err
    assert r.code == 1 and out.count(" error @ ") == 1, out
    assert "is already used" in out and "is not a digital output" not in out, out


def test_an_output_the_tables_do_not_have_is_still_said(tmp_path):
    proj = example_copy("rocket", tmp_path)
    dio = proj / "rocket.dio"
    dio.write_text("\n".join(l for l in dio.read_text().splitlines() if "    main " not in l) + "\n")
    r = run_fsw("check", str(proj))
    assert r.code == 1 and "`main` is not a digital output" in r.out + r.err, r.out + r.err
