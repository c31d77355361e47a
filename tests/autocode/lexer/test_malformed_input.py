"""No input, however malformed, makes a loader or `fsw check` / `fsw test`
raise: only located diagnostics (the fuzzer's invariants, fswkit.testing.fuzz,
in small); the lexer's incremental columns are visual columns.
FSW_PROPERTY_SCALE scales the example counts (fswkit.testing.properties)."""

from __future__ import annotations

import tempfile

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fswkit.testing import fuzz
from fswkit.testing.properties import cases


# ---- malformed input: diagnostics only -------------------------------------------------------

CORPUS = fuzz.corpus(generated=0)


def _run(files, changed=frozenset((0, 1, 2))):
    with tempfile.TemporaryDirectory() as d:
        fuzz.run_case(tuple(files), d, cli=True, changed=changed)


@cases(120)
@given(st.integers(0, len(CORPUS) - 1), st.randoms(use_true_random=False), st.sets(st.integers(0, 2), min_size=1))
def test_mutated_inputs_give_only_diagnostics(k, r, which):
    files = list(CORPUS[k].files)
    others = [f for p in CORPUS[:8] for f in p.files]
    for i in which:
        files[i] = fuzz.mutate(files[i], r, others)
    _run(files)


@cases(100)
@given(st.binary(max_size=600), st.integers(0, 2), st.integers(0, len(CORPUS) - 1))
def test_random_bytes_give_only_diagnostics(data, i, k):
    files = list(CORPUS[k].files)
    files[i] = data
    _run(files)


@pytest.mark.parametrize("special", range(len(fuzz.SPECIALS)))
def test_pathological_inputs_give_only_diagnostics(special):
    """Deep nesting, long lines, huge numbers: in every file."""
    import random

    tank = next(p for p in CORPUS if p.name.endswith("tank.ss"))
    for i in range(3):
        for at in (0, len(tank.files[i]) // 2, len(tank.files[i])):
            files = list(tank.files)
            files[i] = files[i][:at] + fuzz.SPECIALS[special](random.Random(special)) + files[i][at:]
            _run(files)


@cases(300)
@given(st.text(st.sampled_from("ab \t\r\n\x0b\u00e9"), max_size=60), st.lists(st.integers(0, 60), max_size=12))
def test_incremental_columns_are_visual_columns(text, indices):
    """The lexer's linear-time columns equal `visual_col` (tabs expanded as
    `str.expandtabs` does, CR included), at increasing or any indices."""
    from fswkit.autocode.diagnostics import Columns, visual_col

    cols = Columns(text)
    for i in sorted(indices) + indices:
        i = min(i, len(text))
        assert cols(i) == visual_col(text, i), (text, i)
