"""`fsw compile M.sm -o M.fsm --layout -` was refused (rightly: docs/cli.md,
`--layout -` is status 2) with `the image goes to standard output; the
layout needs a file` while the image went to M.fsm. The words now say what
is true in either case: with `-o -` the image has standard output, and
otherwise standard output carries no layout; either way nothing is
written."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES, run_fsw

TANK_SM = str(EXAMPLES / "tank" / "tank.sm")


@pytest.mark.parametrize("to_stdout", [True, False])
def test_layout_to_standard_output_is_refused_saying_where_the_image_goes(tmp_path, to_stdout):
    image = "-" if to_stdout else str(tmp_path / "tank.fsm")
    r = run_fsw("compile", TANK_SM, "-o", image, "--layout", "-")
    assert r.code == 2, r.err
    said = r.err.strip()
    assert said.startswith("fsw compile: --layout -: ") and "needs a file" in said
    assert ("the image goes to standard output" in said) == to_stdout, said
    assert r.out == "" and list(tmp_path.iterdir()) == []
