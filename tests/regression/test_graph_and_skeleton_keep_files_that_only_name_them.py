"""`fsw graph -o FILE` and `fsw skeleton -o FILE` replace, without
`--force`, only their own earlier output, and took for it any file whose
first 8 KiB held the words "`fsw graph" (or "`fsw skeleton"): the user's
notes or a project's README that said how to run the command were
overwritten by a graph. Now only the command's own head line among the
first lines (DOT's `// state machine M: `fsw graph` output ...`, Mermaid's
`%% ...`, the skeleton's `# State-script skeleton for M, made by `fsw
skeleton``) makes a file the command's; a file that only names it is
refused unless `--force`."""

from __future__ import annotations

import shutil

from conftest import EXAMPLES, run_fsw

TANK = EXAMPLES / "tank"
NOTES = ("# Design notes\n\nRegenerate the diagram with `fsw graph tank.sm -o diagram.dot`, and a script with\n"
         "`fsw skeleton tank.sm -o tank.ss`; then review both by hand.\n")


def _project(tmp_path):
    project = tmp_path / "tank"
    shutil.copytree(TANK, project, ignore=shutil.ignore_patterns("build"))
    return project


def test_notes_that_name_the_commands_are_kept(tmp_path):
    project = _project(tmp_path)
    notes = tmp_path / "notes.md"
    for argv, command in ((["graph", str(project / "tank.sm")], "graph"),
                          (["graph", str(project / "tank.sm"), "--format", "mermaid"], "graph"),
                          (["skeleton", str(project / "tank.sm")], "skeleton")):
        notes.write_text(NOTES)
        r = run_fsw(*argv, "-o", str(notes))
        assert r.code == 1, r.out + r.err
        assert (f"{notes} exists and is not an earlier output of `fsw {command}` (a file you wrote?): it is "
                "replaced only when asked (--force)") in r.err, r.err
        assert notes.read_text() == NOTES


def test_their_own_earlier_output_is_still_replaced(tmp_path):
    project = _project(tmp_path)
    out = tmp_path / "out.txt"
    for argv in (["graph", str(project / "tank.sm")], ["graph", str(project / "tank.sm"), "--format", "mermaid"],
                 ["graph", str(project / "tank.sm")], ["skeleton", str(project / "tank.sm")]):
        if argv[0] == "skeleton":
            out.unlink()
        for _ in range(2):
            r = run_fsw(*argv, "-o", str(out))
            assert r.code == 0, r.err
    notes = tmp_path / "notes.md"
    notes.write_text(NOTES)
    assert run_fsw("graph", str(project / "tank.sm"), "-o", str(notes), "--force").code == 0
    assert notes.read_text().startswith("// state machine tank.sm: `fsw graph` output")
