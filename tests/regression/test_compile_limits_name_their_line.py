"""`fsw compile` refused a machine whose conditions nest deeper than the
verifier tracks (FSW_VM_PENDING forward jumps pending at once) at 1:1 of
the machine; it names the statement where the jump too many is."""

from __future__ import annotations

from conftest import run_fsw

SV = "[Sensors]\nU64 time\nU32 state\nF64 x\nF64 y\n"
HEAD = ["[state_vector]", "U64 time @alias G", "U32 state @alias S", "F64 x @read_only", "F64 y", ""]


def test_conditions_nested_too_deep_are_located_at_their_statement(tmp_path):
    (tmp_path / "deep.sv").write_text(SV)
    lines = HEAD + ["[A]", ".step", "    y = 0"]
    depth = 17  # one more than FSW_VM_PENDING's 16
    for k in range(depth):
        lines.append("    " * (k + 1) + f"if x > {k} {{")
    lines.append("    " * (depth + 1) + "y = 1")
    for k in reversed(range(depth)):
        lines.append("    " * (k + 1) + "}")
    (tmp_path / "deep.sm").write_text("\n".join(lines) + "\n")
    r = run_fsw("compile", str(tmp_path / "deep.sm"), "-o", str(tmp_path / "deep.fsm"))
    assert r.code == 2, r.err
    assert "nested deeper than the verifier tracks" in r.err, r.err
    assert "deep.sm:1:1" not in r.err, r.err
    # the innermost `if`s or the statement they hold, not the state's header
    line = int(r.err.split("deep.sm:")[1].split(":")[0])
    first_if = len(HEAD) + 4
    assert first_if < line <= first_if + depth, r.err
    assert not (tmp_path / "deep.fsm").exists()


def test_code_past_the_image_s_limit_is_located_at_the_first_statement_past_it(tmp_path):
    (tmp_path / "big.sv").write_text(SV)
    n = 6000
    lines = HEAD + ["[A]", ".step"] + [f"    y = x * {k} + y * 3 - {k}" for k in range(n)]
    (tmp_path / "big.sm").write_text("\n".join(lines) + "\n")
    r = run_fsw("compile", str(tmp_path / "big.sm"), "-o", str(tmp_path / "big.fsm"))
    assert r.code == 2, r.err
    assert "bytes of code: an image holds at most 65535" in r.err, r.err
    line = int(r.err.split("big.sm:")[1].split(":")[0])
    first = len(HEAD) + 3
    assert first < line < first + n, r.err  # a statement of the state, neither 1 nor past the end
    k = line - first
    code = int(r.err.split("bytes of code")[0].split()[-1])
    assert k * code // n > 60000, (k, code)  # about where 65,535 bytes end, by the statements' even size
