"""What a flight with pyro channels keeps across a brown-out or a watchdog
reset (docs/safety.md, "A reset in flight"): the spans of RAM the flight's
save copies into its banks, as app.py writes them into the resume's table
and limits.py counts them at `fsw check`. No import of the application's
model here: limits.py, which the application's check runs, imports it."""

from __future__ import annotations

from ..numeric import REALS
from .common import c_ident
from .machine import stored_locals, windows_watched

MAX_RESUME_SPANS = 255  # ResumeConfig::n_spans, a byte (the save's loop counts it in one register)
MAX_STRIDED = 255  # the bytes of a strided span (fsw::resume_strided: its count, a byte)


def resume_spans(app) -> list[tuple[str, str, str]]:
    """What a resume keeps (docs/safety.md, "A reset in flight"), as spans
    of RAM (address, size, what: C++ expressions): the state vector, each
    machine's bookkeeping, stored locals and windows, the pyro gates, the
    modes of the tasks without a mode element (theirs are in the state
    vector; consecutive ones in one strided span, `fsw::resume_strided`), an
    uploaded machine's and the recorder's. At most
    MAX_RESUME_SPANS (limits.check_limits says so at `fsw check`)."""
    real = REALS[app.board.real]
    spans = [("sv", "kSvSize", "the state vector")]
    for m in app.machines:
        ns = c_ident(m.name)
        spans.append((f"reinterpret_cast<uint8_t*>(&{ns}::machine)", "fsw::kMachineKept",
                      f"{m.name}: its state, entry time and last G"))
        if stored_locals(m, real):
            spans.append((f"{ns}::loc", f"{ns}::kLocSize", f"{m.name}: its locals"))
        if m.windows:  # a window not full uses the samples so far: emptied, a launch detector's 5 would be 1
            spans.append((f"reinterpret_cast<uint8_t*>(&{ns}::win)", f"sizeof {ns}::win",
                          f"{m.name}: its rolling windows"))
    spans.append(("reinterpret_cast<uint8_t*>(Pyro)", "sizeof Pyro", "the pyro gates: what has fired"))
    # the ground's modes (a task with a mode element: in the state vector), a
    # run of tasks without one in one strided span (a byte of each TaskStats)
    runs: list[list[int]] = []
    for i, t in enumerate(app.tasks):
        if t.mode is None:
            if runs and runs[-1][-1] == i - 1 and len(runs[-1]) < MAX_STRIDED:
                runs[-1].append(i)
            else:
                runs.append([i])
    for run in runs:
        names = [app.tasks[i].name for i in run]
        if len(run) == 1:
            spans.append((f"&stats[{run[0]}].mode", "1", f"task {names[0]}'s mode"))
        else:
            spans.append((f"&stats[{run[0]}].mode", f"fsw::resume_strided({len(run)}, sizeof(fsw::TaskStats))",
                          f"the modes of tasks {', '.join(names)}"))
    if app.reload is not None:  # an uploaded machine goes on where it was, not from its first state
        spans.append(("&reload.active", "1", "which machine runs: the generated one, or an uploaded slot"))
        spans.append(("reload_ram", "sizeof reload_ram", "an uploaded machine's windows and locals"))
    if app.log is not None:
        spans.append(("&rec.flight", "2", "the recorder's flight and mode"))
    return spans


def resume_watches(app) -> list[tuple[int, str, str]]:
    """The spans of resume_spans the save copies only while they change
    (fsw::ResumeWatch): (index, the C++ flag their writer sets, what). A
    machine's windows that some of its states do not sample
    (machine.windows_watched)."""
    spans = resume_spans(app)
    out = []
    for m in app.machines:
        if not windows_watched(m):
            continue
        ns = c_ident(m.name)
        i = next(k for k, (p, _, _) in enumerate(spans) if p == f"reinterpret_cast<uint8_t*>(&{ns}::win)")
        out.append((i, f"&{ns}::win_changed", f"{m.name}: its windows, pushed in some states only"))
    return out
