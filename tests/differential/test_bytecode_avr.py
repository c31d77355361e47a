"""The bytecode VM on the board: a sample of the generated machines + scripts
(the first FSW_VM_AVR_CASES of test_bytecode.py's run, default 40) whose
machine steps through fsw::vm_step (vm_harness.vm_shim, the image in RAM as
a loader would hold it), built for an ATmega2560 with the script's runner of
test_simavr.py (avr_sim.py) and run under simavr, binary32 with avr-libc's
and libgcc's own float code, against the interpreter in binary32 mode: same
per-step trace, same ending, steps and asserts.

As in test_simavr.py, only a case whose interpreter run divides into the
subnormal range (where avr-libc's division may be one unit off) is allowed
to differ. Deterministic: FSW_DIFF_SEED sets the seed (default 1)."""

from __future__ import annotations

import os
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

import avr_sim as A
import gen_programs as gp
import harness as H
from vm_harness import vm_shim
from fswkit.autocode.emit.script import script_writes_locals
from fswkit.autocode.numeric import F32MODE

AVR_CASES = int(os.environ.get("FSW_VM_AVR_CASES", "40"))
SEED = int(os.environ.get("FSW_DIFF_SEED", "1"))
PER_ELF = 5  # RAM: each case's image (in RAM, as a loader holds it), state vector, locals and windows are static

missing = A.available()
pytestmark = pytest.mark.skipif(missing is not None, reason=f"AVR toolchain or simavr missing: {missing}")


def _shim(script, ns: str) -> str:
    return vm_shim(script.machine, F32MODE, script_writes_locals(script), ns, avr=True)


def test_vm_cases_on_simavr(tmp_path, monkeypatch):
    t0 = time.monotonic()
    cases = gp.cases(SEED, AVR_CASES)
    loaded = [(c, *H.load(c)) for c in cases]
    with ThreadPoolExecutor(H.JOBS) as pool:
        outcomes, sizes = A.run_sample(str(tmp_path), loaded, pool, PER_ELF, machine_cpp=_shim)
    built = time.monotonic() - t0
    r = A.compare(loaded, outcomes, str(tmp_path), monkeypatch)
    assert not r.bad, "\n\n".join(f"=== case {c.index} (VM, binary32, simavr): {d}\n{c.repro()}"
                                  for c, d in r.bad[:3])
    assert r.steps > 5 * len(loaded)  # the comparison means something
    print(f"\nVM on simavr: {len(loaded)} cases, {r.steps} steps ({'; '.join(sizes)}); {r.dividing} divide into "
          f"the subnormal range, {len(r.documented)} of them differ; {time.monotonic() - t0:.1f}s "
          f"({built:.1f}s building and simulating)")


def test_an_image_the_board_refuses_is_a_clear_error(tmp_path):
    """The board runs its own vm_verify before the first step: an image whose
    magic is wrong stops the run with the reason, not with a wrong trace."""
    c = gp.case(SEED, 0)
    s, _ = H.load(c)
    good = _shim(s, "fsw_c0")

    def bad(script, ns: str) -> str:
        shim = _shim(script, ns)
        assert shim == good
        return shim.replace("const uint8_t kImage[] = {\n    70,", "const uint8_t kImage[] = {\n    71,", 1)

    assert "const uint8_t kImage[] = {\n    70," in good  # 'F' of "FSMB"
    with ThreadPoolExecutor(H.JOBS) as pool:
        elf = A.build_elf(str(tmp_path), [(0, s)], pool, machine_cpp=bad)
    with pytest.raises(A.native.NativeError, match=r"case 0: vm_verify refused the image on the board: reason 1$"):
        A.run_elf(elf, [(0, s)])
