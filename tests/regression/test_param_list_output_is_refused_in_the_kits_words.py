"""`fsw param list -o FILE` over an existing FILE said `FILE exists: a
parameter file is never overwritten without --force`, in words of its
own, where every other command with `--force` says the kit's (docs/cli.md,
"Output files": `FILE exists: it is replaced only when asked (--force)`).
It now says those, before the port is opened, and leaves the file as it
was."""

from __future__ import annotations

from conftest import EXAMPLES, run_fsw


def test_an_existing_parameter_file_is_refused_as_every_output_is(tmp_path):
    out = tmp_path / "params.toml"
    out.write_text("MAIN_ALT = 220\n")
    r = run_fsw("param", str(EXAMPLES / "rocket"), "list", "-o", str(out), "--port", "/dev/no-such-port")
    assert r.code == 1, r.err
    assert r.err.strip() == f"fsw param: {out} exists: it is replaced only when asked (--force)"
    assert out.read_text() == "MAIN_ALT = 220\n"
