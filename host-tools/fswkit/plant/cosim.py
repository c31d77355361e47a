"""The lock-step loop: the firmware on the simulated board (fswkit.sim.board)
and a plant scenario advance together at the scenario's rate. Each step is
one `batch` line: the sensors' volts, the digital parts' raw counts and the
switch levels that changed, a run to the step's last cycle, the pyro/valve
pins' edges and the UART's bytes — then the plant integrates the same
interval with the pins as they were, to the cycle. Up to SPECULATE steps go
to the board in one write, worked out ahead (see SPECULATE), with the same
flight as a step at a time. The UART's bytes go through the ground's decoder
(fswkit.link.Session), as `fsw monitor` decodes them, and into a link log
of the same format."""

from __future__ import annotations

import contextlib
import os
import threading
import time
from dataclasses import dataclass, field

from fswkit.link.layout import Layout
from fswkit.link.log import RX, LogWriter
from fswkit.link.session import Session
from fswkit.progress import progress
from fswkit.sim.board import RESET_CAUSES, EdgeOverflow, SimBoard, SimError
from fswkit.sim.sensors import PartFeed, board_parts, part_name

RECORD_HZ = 100  # truth rows per simulated second (the executor's rate)

# Plant steps one write to the board may carry. The plant works their inputs out ahead as if the
# firmware's outputs stayed as they are; the board runs them in turn and stops after a step in which a
# watched pin changed or the mission machine's state element did (`SimBoard.batches`), and the plant
# is worked out again from the write's start as far as the board went. While the board runs a full
# write, the next is worked out and sent behind it, all `batch?`: the board skips it if the one before
# stopped. Only while telemetry shows the state the firmware is in, never past a reset or a part
# failure that is due, and up to the step where the scenario says the run ends (`would_end`): so a
# flight is the same, step for step, as one sent a step at a time.
SPECULATE = 16


class CosimError(Exception):
    """The co-simulation could not go on (a message for the user)."""


@dataclass(frozen=True)
class PinEvent:
    """An output pin's edge, at its exact cycle, with the plant's truth at
    that instant (interpolated within the plant step)."""

    t: float
    pin: int
    role: str
    level: bool
    truth: dict


@dataclass(frozen=True)
class ResetEvent:
    """A reset of the MCU during a run: when (simulated s), its cause (one
    of fswkit.sim.board.RESET_CAUSES), the mission machine's state telemetry
    showed last before it (None: none yet), and what asked for it: "time"
    (the scenario's `reset_at`) or "state" (its `reset_state`)."""

    t: float
    cause: str
    state: str | None
    trigger: str


@dataclass
class Run:
    columns: tuple[str, ...]
    rows: list[tuple] = field(default_factory=list)  # truth, RECORD_HZ rows a second
    pin_events: list[PinEvent] = field(default_factory=list)
    samples: list[tuple[float, dict]] = field(default_factory=list)  # (s, {element: value}) per telemetry sample
    transitions: list[tuple[float, int, str]] = field(default_factory=list)  # (s, state id, name)
    session: Session | None = None
    steps: int = 0
    sim_s: float = 0.0
    wall_s: float = 0.0
    round_trips: int = 0
    ram: dict = field(default_factory=dict)  # what the board's RAM probes said, if it has them
    profile: object = None  # fswkit.sim.board.Profile of the functions `fly` was asked to profile
    resets: list[float] = field(default_factory=list)  # when the MCU was reset (the resets the scenario asked for)
    reset_events: list[ResetEvent] = field(default_factory=list)  # the same resets, with cause and state
    eeprom: bytes | None = None  # the board's EEPROM after the flight (the flight recorder's store)
    flash: bytes | None = None  # the SPI NOR flash's written part after the flight (`store spi_nor`)
    part_failures: list = field(default_factory=list)  # (simulated s, part "bmp280@0x76", "nack" | "stuck" | "noisy")
    # per digital part: [health frames, frames that said it had a fault, arrival (s) of the first such frame]
    part_health: dict = field(default_factory=dict)


_cpu_lock = threading.Lock()
_cpu_users: dict[int, int] = {}  # CPU -> flights pinned to it now


def _boards_pinned() -> dict[int, int]:
    """CPU -> the simulated boards of every process on this machine that run
    pinned to it (a flight's board runs on its flight's one CPU: `_one_cpu`)."""
    out: dict[int, int] = {}
    try:
        pids = [p for p in os.listdir("/proc") if p.isdigit()]
    except OSError:
        return out
    for pid in pids:
        try:
            with open(f"/proc/{pid}/comm") as f:
                if f.read().strip() != "simboard":
                    continue
            cpus = os.sched_getaffinity(int(pid))
        except (OSError, ValueError):  # gone meanwhile, or not ours to ask
            continue
        if len(cpus) == 1:
            cpu = next(iter(cpus))
            out[cpu] = out.get(cpu, 0) + 1
    return out


@contextlib.contextmanager
def _one_cpu():
    """Runs this thread, and the board it starts, on one CPU — the least used
    by other flights of this process, and of those the one the fewest boards
    of other processes are pinned to (processes that fly at once: pytest-xdist's
    workers, two `fsw sim`s), not the first CPU for every process. Lock-step
    is a ping-pong: one of the two processes works while the other waits, and
    a pipe round trip between two processes on one CPU costs about 10 µs,
    across CPUs 60 to 100 µs (about a quarter of a 1 kHz step's time).
    Yields another CPU this thread may move to once the board has started,
    when no other flight of any process has one pinned: the board then runs
    a write while this thread works out the next (SPECULATE), and a write's
    round trip between two CPUs is shared by its 16 steps; None otherwise."""
    if not hasattr(os, "sched_setaffinity"):
        yield None
        return
    try:
        before = os.sched_getaffinity(0)
    except OSError:
        yield None
        return
    if len(before) < 2:
        yield None
        return
    with _cpu_lock:
        pinned = _boards_pinned()
        cpu = min(sorted(before), key=lambda c: (_cpu_users.get(c, 0), pinned.get(c, 0)))
        _cpu_users[cpu] = _cpu_users.get(cpu, 0) + 1
        alone = not pinned and sum(_cpu_users.values()) == 1
        other = min(c for c in before if c != cpu) if alone else None
    try:
        try:
            os.sched_setaffinity(0, {cpu})
        except OSError:
            other = None
        yield other
    finally:
        with contextlib.suppress(OSError):
            os.sched_setaffinity(0, before)
        with _cpu_lock:
            _cpu_users[cpu] -= 1


def fly(scenario, elf: str, board, layout: Layout, log_path: str | None = None, *,
        wall_limit: float = 900.0, log_meta: dict | None = None, profile: list[int] | None = None) -> Run:
    """Runs the scenario to its end against the firmware; the Run. The
    board and this thread share one CPU for the run (`_one_cpu`). On a
    terminal, a bar shows the simulated time of the planned duration.
    `profile`: flash byte addresses of functions whose cycles the board
    counts from reset (SimBoard.profile; tools/bench_busy.py), in run.profile."""
    with _one_cpu() as other, progress("flight", total=float(scenario.max_s), unit="s") as bar:
        return _fly(scenario, elf, board, layout, log_path, wall_limit, log_meta, bar, profile, other)


def stop_words(stop: str, wall_limit: float) -> str:
    """Why the board stopped before the step's end, in words."""
    return {"wall-limit": f"the wall-clock limit ({wall_limit:g} s) was reached",
            "sim-limit": "the simulated-time limit was reached",
            "crashed": "the firmware crashed", "done": "the firmware stopped itself"}.get(stop, stop)


class Telemetry:
    """The firmware's UART bytes as a run's telemetry: recorded to the link
    log, decoded by a link Session into the run's samples and the state
    transitions of `state_element`, timed `offset` seconds before the
    board's clock (closed-loop flights: 0; tape replays: the tape's time).

    After a reset of the target (`restarted`) the offset is found again
    from the new boot's first frame (its hello, as a rule): the firmware's
    clock may have started again from 0 at the reset, or gone on from where
    it was (firmware that resumes its flight keeps `G` across a brown-out
    or a watchdog reset); whichever puts that frame between the reset and
    its arrival is taken, else the frame is timed at its arrival."""

    RESUME_SLACK_S = 1.0  # a clock that went on may have lost up to this much across the reset

    def __init__(self, run: Run, layout: Layout, state_element: str | None, log: LogWriter | None,
                 offset: float = 0.0):
        self.run, self.layout, self.log, self.offset = run, layout, log, offset
        self.session = run.session = Session(layout)
        self.state_element = state_element
        self.state_names = layout.states.get(state_element, {})
        self.regions = {s.index: s.region for s in layout.streams}
        self.per_s = 1000.0 if layout.time_unit == "ms" else 1e6
        self.last_state = None
        self.reset_t: float | None = None  # the target was reset then; its new clock not yet seen

    @property
    def state_name(self) -> str | None:
        """The state telemetry showed last (None: none yet)."""
        if self.last_state is None:
            return None
        return self.state_names.get(int(self.last_state), str(self.last_state))

    def restarted(self, t: float) -> None:
        """The target was reset at simulated second `t`: the next frame sets the time base."""
        self.reset_t = t

    def _rebase(self, fw_s: float, arrival: float) -> None:
        """The new boot's time base from its first frame, stamped `fw_s`
        (the firmware's seconds), read by simulated second `arrival`."""
        t_r, self.reset_t = self.reset_t, None
        restart, went_on = -t_r, self.offset
        if t_r <= fw_s - restart <= arrival:  # the clock started again from 0 at the reset
            self.offset = restart
        elif t_r - self.RESUME_SLACK_S <= fw_s - went_on <= arrival:  # it went on across the reset
            self.offset = went_on
        else:  # some other time base: the frame is taken as sent when it arrived
            self.offset = fw_s - arrival

    def feed(self, raw: bytes, t: float) -> None:
        """Takes the bytes the board sent up to simulated time `t` (s)."""
        if self.log:
            self.log.record(RX, round(t * 1e9), raw)
        run = self.run
        for ev in self.session.feed(raw, t):
            if self.reset_t is not None:
                self._rebase(ev.time / self.per_s, t)
            if ev.kind == "hello" and not ev.info["schema_ok"]:
                raise CosimError(f"the firmware's schema 0x{ev.info['schema']:08x} is not the configs' "
                                 f"0x{self.layout.schema:08x}: rebuild it")
            if ev.kind == "health":
                for part in ev.info.get("sensors", ()):
                    seen = run.part_health.setdefault(part["name"], [0, 0, None])
                    seen[0] += 1
                    if part["fault"]:
                        seen[1] += 1
                        if seen[2] is None:
                            seen[2] = t
            if ev.kind != "sample":
                continue
            names = self.regions[ev.stream].names
            for ts, vals in ev.samples:
                row = dict(zip(names, vals))
                tt = ts / self.per_s - self.offset
                run.samples.append((tt, row))
                st = row.get(self.state_element)
                if st is not None and st != self.last_state:
                    self.last_state = st
                    run.transitions.append((tt, int(st), self.state_names.get(int(st), str(st))))


def _fly(scenario, elf, board, layout, log_path, wall_limit, log_meta, bar, profile=None, other_cpu=None) -> Run:
    rate = scenario.rate
    f_cpu = int(board.f_cpu)
    if f_cpu % rate:
        raise CosimError(f"the plant rate {rate} Hz does not divide the {board.name}'s clock ({f_cpu} Hz)")
    cycles = f_cpu // rate
    record_every = max(1, rate // RECORD_HZ)
    vref = float(board.adc_vref)
    analog, digital = scenario.inputs(0.0)
    run = Run(columns=scenario.columns)
    log = LogWriter(log_path, layout, **(log_meta or {})) if log_path else None
    if log:
        log.commit()  # named from the start: a run killed outright still leaves its log
    telemetry = Telemetry(run, layout, scenario.state_element, log)
    sensors = tuple(getattr(getattr(scenario, "app", None), "sensors", ()) or ())
    try:
        nor = _nor(getattr(scenario, "app", None), board)
        where = dict(zip(sensors, (w for _k, w in board_parts(sensors, board))))
        b = SimBoard(elf, board, uart="control", sim_limit=scenario.max_s + 1.0, wall_limit=wall_limit,
                     eeprom=getattr(scenario, "eeprom", None),
                     analog=analog, spi_flash=nor[1] if nor else None,
                     ram_seed=_ram_seed(getattr(scenario, "seed", 1)),
                     parts=[(s.part, where[s]) for s in sensors] or None)
    except SimError as e:
        if log:
            log.close()
        raise CosimError(str(e)) from None
    wall0 = time.perf_counter()
    # With another CPU free (_one_cpu), this thread moves there while writes are chained, so that the
    # board runs one while the next is worked out; in a long stretch of steps sent one at a time, where a
    # round trip between two CPUs costs several times one on a CPU, it goes back to the board's.
    cpus = None
    if other_cpu is not None:
        with contextlib.suppress(OSError):
            cpus = (os.sched_getaffinity(0), {other_cpu})

    def place(on_other: bool) -> None:
        nonlocal cpus
        if cpus is not None and on_other != (cpus[1] == os.sched_getaffinity(0)):
            try:
                os.sched_setaffinity(0, cpus[1] if on_other else cpus[0])
            except OSError:
                cpus = None
    try:
        if profile:
            b.profile(profile)
        # the parts the plant feeds, with the calibration each holds (read once)
        feeds = {s: PartFeed(s, where[s], b.part_calibration(where[s]))
                 for s in getattr(scenario, "parts", ()) if s in where}
        # each part's feed by the part object itself (kept, so its id is never another's): a part is a
        # frozen dataclass whose hash walks all its fields, twice a step otherwise
        feed_of: dict[int, tuple] = {}
        last_raw: dict = {}  # harness id -> the raw counts set last
        fail_plan = list(getattr(scenario, "part_fail_plan", ()))
        last_mv = {name: _mv(v, vref) for name, v in analog.items()}
        last_din: dict[int, bool] = {}
        for pin in scenario.outputs:
            b.watch(pin)
        k = 0
        t1 = 0.0
        spec, fw_state = _guard(b, scenario, layout), None

        def changed_inputs(analog, digital):
            """(set_analog, set_digital, set_parts): what of the inputs (`analog`, `digital` and the
            scenario's parts' values) changed since last sent; last_mv, last_din and last_raw follow."""
            set_parts = {}  # the parts' raw counts that changed
            if feeds:
                for part, values in scenario.part_values.items():
                    known = feed_of.get(id(part))
                    if known is None or known[0] is not part:
                        known = feed_of[id(part)] = (part, feeds.get(part))
                    feed = known[1]
                    if feed is None:
                        continue
                    raw = feed.raw(**values)
                    old = last_raw.get(feed.where, {})
                    changed = {n: v for n, v in raw.items() if old.get(n) != v}
                    if changed:
                        last_raw[feed.where] = raw
                        set_parts[feed.where] = changed
            set_analog, set_digital = {}, {}  # the inputs that changed
            for name, v in analog.items():
                mv = _mv(v, vref)
                if mv != last_mv[name]:
                    last_mv[name] = mv
                    set_analog[name] = v
            for pin, level in digital.items():
                if last_din.get(pin) != level:
                    last_din[pin] = level
                    set_digital[pin] = level
            return set_analog, set_digital, set_parts

        def compose(k0: int, chained: bool):
            """The write that starts at step k0: its steps' `batch` arguments, the plant worked out
            ahead for them (all of them when there are several: a chained write may follow), the
            truth rows ahead, and what the plant was at its start. One step (nothing worked out
            ahead) unless speculating is safe (SPECULATE); a chained write is None then."""
            nonlocal analog, digital
            n = 1
            if (spec is not None and telemetry.reset_t is None and telemetry.last_state is not None
                    and int(telemetry.last_state) == fw_state):
                n = SPECULATE
                for due in (reset_at, state_due, fail_plan[0][0] if fail_plan else None):
                    if due is not None:
                        n = next((i for i in range(0 if chained else 1, n) if (k0 + i) / rate >= due), n)
            if chained and n <= 1:
                return None
            w = _Write(k0, n, first=(analog, digital))
            if n > 1:
                w.saved = (scenario.save(), dict(last_mv), dict(last_din), dict(last_raw))
            state = run.transitions[-1][2] if run.transitions else None
            for i in range(n):
                kk = k0 + i
                if kk:
                    analog, digital = scenario.inputs(kk / rate)
                w.steps.append(((kk + 1) * cycles,) + changed_inputs(analog, digital))
                if n > 1:  # ahead of the board: the plant with the pins as they are
                    scenario.advance(kk / rate, (kk + 1) / rate, ())
                    w.rows.append(scenario.record() if (kk + 1) % record_every == 0 else None)
                    w.ahead = i + 1
                    if scenario.would_end((kk + 1) / rate, state):  # the run ends with this step
                        w.n = n = i + 1
                        w.ends = True
                        break
            return w

        finished = False
        alone = 1  # writes of one step in a row (place: this thread on the board's CPU from 32 on)
        # resets the scenario asks for: at a simulated second (`reset_at`: a study's brown-out), and
        # `reset_after_s` after telemetry first shows the mission machine in `reset_state`
        reset_at, at_cause, reset_state, state_cause, after_s = _reset_plan(scenario, telemetry)
        state_due: float | None = None
        seen = 0  # transitions already looked at for reset_state
        pending: list = []  # writes sent whose responses are not read yet: (write, responses or None)
        while True:
            t0 = k / rate
            if not pending and (reset_at is not None or state_due is not None):
                for due, cause, trigger in ((reset_at, at_cause, "time"), (state_due, state_cause, "state")):
                    if due is None or t0 < due:
                        continue
                    if trigger == "time":
                        reset_at = None
                    else:
                        state_due = None
                    run.reset_events.append(ResetEvent(t0, cause, telemetry.state_name, trigger))
                    run.resets.append(t0)
                    b.reset(cause)
                    telemetry.restarted(t0)
                    last_mv = {name: -1 for name in last_mv}  # every input driven again
                    last_din = {}
            while not pending and fail_plan and t0 >= fail_plan[0][0]:  # a part fails (its mode set before the step runs)
                _at, part, mode = fail_plan.pop(0)
                if part in where:
                    if mode == "noisy":  # the plant's doing: the part itself works
                        scenario.noisy_parts.add(part)
                    else:
                        b.part_fail(where[part], mode)
                    run.part_failures.append((t0, part_name(part), mode))
            # a write, and while the board runs one, the next (chained): see SPECULATE
            if not pending:
                w = compose(k, False)
                if w.n == 1:
                    alone += 1
                    if alone == 32:
                        place(False)
                    pending.append((w, [b.batch(*w.steps[0])]))
                else:
                    b.batches_send(w.steps)
                    pending.append((w, None))
            last = pending[-1][0]
            if len(pending) == 1 and last.n == SPECULATE and not last.ends:
                w2 = compose(last.k0 + last.n, True)
                if w2 is not None:
                    if alone:
                        alone = 0
                        place(True)
                    b.batches_send(w2.steps, chained=True)
                    pending.append((w2, None))
            w, results = pending.pop(0)
            if results is None:
                try:
                    results = b.batches_read(w.n)
                except EdgeOverflow:
                    raise CosimError("the board recorded more pin edges than it keeps: a pin toggles too fast to "
                                     "watch") from None
            run.round_trips += 1
            ran = next((i for i, r in enumerate(results) if r is None), w.n)  # the steps the board ran
            stopped = ran < w.n  # the board stopped the run of steps: it runs no chained write
            for i in range(ran):
                step = results[i]
                t0 = k / rate
                if step.run.stop != "target":
                    raise CosimError(f"{stop_words(step.run.stop, wall_limit)} at {t0:.3f} s simulated")
                k += 1
                t1 = k / rate
                if spec is not None:
                    was, fw_state = fw_state, int.from_bytes(step.guard, "little")
                    if fw_state != was:
                        stopped = True  # a state change stops the run of steps
                edges = [(e.cycle / f_cpu, e.pin, e.level) for e in step.edges] if step.edges else ()
                if edges:
                    stopped = True  # and so does an edge
                if i >= w.ahead:  # a step sent alone: the plant was not worked out ahead for it
                    for ev in scenario.advance(t0, t1, edges):
                        run.pin_events.append(ev)
                    row = scenario.record() if k % record_every == 0 else None
                elif i == ran - 1 and stopped:  # the board stopped here (an edge, a state change; the plant
                    # has gone on ahead): the plant again from the write's start, as far as the board went, this
                    # step with its edges
                    plant, last_mv, last_din, last_raw = (w.saved[0], dict(w.saved[1]), dict(w.saved[2]),
                                                          dict(w.saved[3]))
                    scenario.restore(plant)
                    for j in range(ran):
                        kk = k - ran + j
                        analog, digital = scenario.inputs(kk / rate) if kk else w.first
                        changed_inputs(analog, digital)
                        for ev in scenario.advance(kk / rate, (kk + 1) / rate, edges if j == ran - 1 else ()):
                            run.pin_events.append(ev)
                    row = scenario.record() if k % record_every == 0 else None
                else:
                    row = w.rows[i]
                if step.uart:
                    telemetry.feed(step.uart, t1)
                    if reset_state is not None:
                        for tt, _sid, name in run.transitions[seen:]:
                            if name == reset_state:  # the first time only
                                state_due, reset_state = tt + after_s, None
                                break
                        seen = len(run.transitions)
                if row is not None:
                    run.rows.append(row)
                state = run.transitions[-1][2] if run.transitions else None
                bar.update(t1, state=state or "-")
                if scenario.done(t1, state):
                    if i != ran - 1 or (pending and not stopped):
                        raise CosimError(f"internal error: the run ended at {t1:.3f} s simulated, inside steps the "
                                         "board had already run ahead")
                    finished = True
                    break
            if stopped or finished:  # a chained write the board skipped, step by step
                for w2, _ in pending:
                    run.round_trips += 1
                    if any(r is not None for r in b.batches_read(w2.n)):
                        raise CosimError("internal error: the board ran steps after their run had stopped")
                pending = []
            if finished:
                break
        run.steps = k
        run.sim_s = t1
        run.wall_s = time.perf_counter() - wall0
        if profile:
            run.profile = b.profile_read()
        if getattr(board, "eeprom", 0):
            run.eeprom = b.eeprom_read(0, board.eeprom)
        if nor:  # the written part: whole 4 KiB sectors from 0 until a blank one
            run.flash = nor_image(b, nor[0])
        for probe in ("ram_usage", "stack_high_water"):  # the first the board has
            fn = getattr(b, probe, None)
            if callable(fn):
                try:
                    run.ram[probe] = fn()
                except (SimError, TypeError, ValueError) as e:
                    run.ram[probe] = f"unavailable ({e})"
                break
    except SimError as e:
        raise CosimError(str(e)) from None
    except ArithmeticError as e:  # the plant's state overflowed: parameters that pass the schema, flown too far
        raise CosimError(f"the {getattr(scenario, 'kind', 'plant')} plant's state is no longer a finite number at "
                         f"{t1:.3f} s simulated ({e}): check its parameters (docs/sim.md)") from None
    finally:
        b.close()
        if log:
            log.close()
    return run


@dataclass
class _Write:
    """Plant steps sent to the board in one write (fswkit.plant.cosim's loop)."""

    k0: int  # its first step
    n: int  # its steps
    first: tuple  # the inputs the loop held at its start (those of step 0 for the first write)
    steps: list = field(default_factory=list)  # each step's `batch` arguments
    ahead: int = 0  # the steps the plant was worked out for ahead of the board
    rows: list = field(default_factory=list)  # the truth rows ahead (None: no row at that step)
    saved: tuple | None = None  # the plant and the inputs last sent, at its start
    ends: bool = False  # the run ends with its last step (would_end): no write follows it


def _guard(b: SimBoard, scenario, layout: Layout):
    """Guards the state element's bytes on the board for speculative steps
    (SPECULATE) and returns its (address, size); None when the scenario
    cannot take them back (no save, restore and would_end) or the firmware
    has no state vector to watch."""
    if not all(hasattr(scenario, f) for f in ("save", "restore", "would_end")):
        return None
    el = next((e for e in layout.elements if e.name == scenario.state_element), None)
    if el is None or el.size > 8:
        return None
    try:
        addr, size = b.symbol("fsw_gen::sv")
    except SimError:
        return None
    if el.offset + el.size > size:
        return None
    b.guard(addr + el.offset, el.size)
    return addr + el.offset, el.size


def _ram_seed(seed) -> int:
    """The board's seed for the bytes a power-on reset leaves in RAM: the
    scenario's own, so that a run is its seed's, byte for byte."""
    if isinstance(seed, int) and 0 <= seed < 1 << 64:
        return seed
    import numpy as np

    return int(np.random.SeedSequence(seed).generate_state(1, np.uint64)[0])


def _reset_plan(scenario, telemetry: Telemetry):
    """(reset_at, its cause, reset_state, its cause, reset_after_s) from the
    scenario's attributes (plant.toml's [scenario] or set from Python; a
    study's brown-out sets reset_at); CosimError for a cause or a state
    that cannot be (scenario.load has checked the file's)."""
    reset_at = getattr(scenario, "reset_at", None)
    at_cause = getattr(scenario, "reset_at_cause", "brownout")
    reset_state = getattr(scenario, "reset_state", None)
    state_cause = getattr(scenario, "reset_cause", "brownout")
    after_s = float(getattr(scenario, "reset_after_s", 0.2))
    for cause in ((at_cause,) if reset_at is not None else ()) + ((state_cause,) if reset_state else ()):
        if cause not in RESET_CAUSES:
            raise CosimError(f"reset cause `{cause}`: one of {', '.join(RESET_CAUSES)}")
    if reset_state is not None:
        states = set(telemetry.state_names.values())
        if reset_state not in states:
            raise CosimError(f"reset_state `{reset_state}`: telemetry's `{scenario.state_element}` has no such state "
                             f"(its states: {', '.join(sorted(states)) or 'none'})")
        if not after_s >= 0:
            raise CosimError(f"reset_after_s must be 0 or more seconds, not {after_s}")
    return reset_at, at_cause, reset_state, state_cause, after_s


def nor_image(b, p) -> bytes:
    """The written part of the board's SPI NOR chip: whole 4 KiB sectors from
    address 0 up to the first blank one (records fill the chip from 0)."""
    out = b""
    while len(out) < p.flash_size:
        s = b.flash_read(len(out), 4096)
        if s == b"\xff" * 4096:
            break
        out += s
    return out


def _nor(app, board):
    """(plan, SimBoard's spi_flash "<port><bit>:<size>") when the application's
    flight recorder logs to an SPI NOR flash (docs/recorder.md, "On an SPI NOR flash chip"), else None."""
    if app is None or getattr(app, "log", None) is None or getattr(app.log, "store", "eeprom") != "spi_nor":
        return None
    from fswkit.autocode.recorder import plan
    from fswkit.sim.board import pin_map, sim_board

    p = plan(app)
    port, bit = pin_map(sim_board(board)).digital[p.cs_pin]
    return p, f"{port}{bit}:{p.flash_size}"


def _mv(volts: float, vref: float) -> int:
    """Millivolts at an analog pin, clamped to 0..vref as the converter saturates."""
    if volts != volts:
        raise FloatingPointError("a sensor's volts are not a number")
    return int(round(min(max(volts, 0.0), vref) * 1000))
