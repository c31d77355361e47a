"""Progress on long work (builds, flights, tape replays, studies), drawn with
rich on standard error when it is a terminal, and nothing at all otherwise.

    from fswkit.progress import progress
    with progress("flight", total=30.0, unit="s") as p:   # total None: unknown
        p.update(done, failed=2)   # absolute position; fields shown after the bar

Nothing is shown (and nothing written anywhere) when standard error is not a
terminal, when FSW_NO_PROGRESS is set (to anything but "" or "0"), when
TERM=dumb or when CI is set: piped output stays byte-identical. Standard
output is never written to. `update` is throttled: it only stores its
arguments unless a tenth of a second has passed, so a loop may call it on
every step.

Nested bars share one display (the inner one below, removed when it ends).
A worker process (multiprocessing, or any child process started while a bar
is shown) does not draw: its bars are sent to the process that shows the
display, through a Unix datagram socket named in the environment
(FSW_PROGRESS_TO); a pool whose workers were started before the bar (a
forkserver) can call `attach(channel())` in each task. The display clears
itself when the outermost bar ends, by an exception (Ctrl-C, and SIGTERM or
SIGHUP under `outputs.stopped_by_signals`) as well; a SIGTERM or SIGHUP left
to its default action clears it and then ends the process by that signal,
as it would have.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import sys
import threading
import time

ENV_CHANNEL = "FSW_PROGRESS_TO"  # "<pid of the showing process>:<socket path>"
INTERVAL = 0.1  # seconds between two updates pushed to the display
REMOTE_INTERVAL = 0.25  # seconds between two datagrams from a worker


def enabled() -> bool:
    """Whether this process may draw progress: standard error a terminal,
    not a worker, and not turned off."""
    if os.environ.get("FSW_NO_PROGRESS", "") not in ("", "0"):
        return False
    if os.environ.get("TERM") == "dumb" or os.environ.get("CI"):
        return False
    try:
        if not sys.stderr.isatty():
            return False
    except (AttributeError, ValueError, OSError):
        return False
    import multiprocessing

    return multiprocessing.parent_process() is None


def active() -> bool:
    """Whether a bar opened now would be shown (here or by the process a
    worker reports to): work that costs something only to measure its
    total (a dry run of make) is done only then."""
    d = _display
    if d is not None and d.pid == os.getpid():
        return True
    if _remote_address() is not None:
        return os.environ.get("FSW_NO_PROGRESS", "") in ("", "0")
    return enabled()


class _Off:
    """A bar that is not shown."""

    def update(self, done, **fields) -> None:
        pass


_OFF = _Off()


class _Bar:
    """A bar of this process's display. An update between two pushes is
    kept (`value`) and pushed by the display's next refresh: the bar never
    stays behind the work."""

    def __init__(self, display, label, total, unit, depth):
        self._display, self._next = display, 0.0
        self.seq = self.pushed = 0
        self.value = None  # (seq, done, fields) of the last update
        self.task = display.add(label, total, unit, depth)
        display.bars.append(self)

    def update(self, done, **fields) -> None:
        self.seq += 1
        self.value = value = (self.seq, done, fields)
        now = time.monotonic()
        if now < self._next:
            return
        self._next = now + INTERVAL
        self._display.push(self, value)

    def close(self) -> None:
        self._display.remove(self)


class _Remote:
    """A bar of a worker process, sent to the process that shows the display."""

    _ids = 0

    def __init__(self, sock, address, label, total, unit, depth):
        _Remote._ids += 1
        self._sock, self._address, self._next = sock, address, 0.0
        self._head = {"p": os.getpid(), "i": _Remote._ids, "l": label, "t": total, "n": unit, "depth": depth}
        self._send("s", 0, {})

    def _send(self, kind, done, fields) -> None:
        message = dict(self._head, k=kind, d=done, f={k: str(v) for k, v in fields.items()})
        try:
            self._sock.sendto(json.dumps(message).encode(), socket.MSG_DONTWAIT, self._address)
        except (OSError, TypeError, ValueError):  # the display gone or busy: progress is not worth failing for
            pass

    def update(self, done, **fields) -> None:
        now = time.monotonic()
        if now < self._next:
            return
        self._next = now + REMOTE_INTERVAL
        self._send("u", done, fields)

    def close(self) -> None:
        self._send("e", 0, {})


# --- where a worker sends its bars -------------------------------------------

_attached: str | None = None  # a channel given to `attach`, over the environment's
_sender: socket.socket | None = None


def channel() -> str | None:
    """The channel a worker started before the display can `attach` to (None
    when nothing is shown)."""
    d = _display
    if d is not None and d.pid == os.getpid():
        return d.channel
    return None


def attach(channel_: str | None) -> None:
    """Sends this process's bars to the display of `channel_` (from `channel`)."""
    global _attached
    _attached = channel_


def _remote_address() -> str | None:
    value = _attached or os.environ.get(ENV_CHANNEL)
    if not value:
        return None
    pid, _, path = value.partition(":")
    if not path or pid == str(os.getpid()):
        return None
    return path


def _remote(label, total, unit):
    global _sender
    address = _remote_address()
    if address is None:
        return None
    if os.environ.get("FSW_NO_PROGRESS", "") not in ("", "0"):
        return None
    try:
        if _sender is None:
            _sender = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    except OSError:
        return None
    return _Remote(_sender, address, label, total, unit, _remote_depth)


_remote_depth = 0


# --- the display ---------------------------------------------------------------

_display = None  # the _Display of the process that shows bars (None: nothing shown)


def _number(value, unit: str) -> str:
    if value is None:
        return "?"
    if isinstance(value, int) or float(value).is_integer() and unit != "s":
        return f"{int(value):,}"
    return f"{value:,.1f}"


def _columns():
    from rich.progress import BarColumn, ProgressColumn, TextColumn, TimeElapsedColumn, TimeRemainingColumn
    from rich.text import Text

    class Count(ProgressColumn):
        def render(self, task):
            unit = task.fields.get("unit", "")
            total = task.fields.get("total_shown")
            text = _number(task.completed, unit) + ("/" + _number(total, unit) if total is not None else "")
            return Text(text + (" " + unit if unit else ""), style="progress.download")

    class Rate(ProgressColumn):
        def render(self, task):
            speed = task.speed
            if speed is None:
                return Text("")
            unit = task.fields.get("unit", "")
            if unit == "s":  # simulated (or tape) seconds per second of the wall clock
                return Text(f"{speed:.1f}× real time", style="progress.data.speed")
            shown = f"{speed:,.0f}" if speed >= 100 else f"{speed:.3g}"
            return Text(f"{shown} {unit or 'it'}/s", style="progress.data.speed")

    class Left(ProgressColumn):
        """ETA when the total is known, time elapsed otherwise."""

        def __init__(self):
            super().__init__()
            self._eta, self._elapsed = TimeRemainingColumn(), TimeElapsedColumn()

        def render(self, task):
            if task.total is None:
                return self._elapsed.render(task)
            eta = self._eta.render(task)
            return Text("ETA ") + eta

    return (
        TextColumn("{task.description}"),
        BarColumn(),
        Count(),
        Rate(),
        Left(),
        TextColumn("{task.fields[extra]}"),
    )


class _Display:
    def __init__(self):
        import tempfile

        from rich.console import Console
        from rich.progress import Progress

        self.pid = os.getpid()
        self.lock = threading.RLock()
        self.bars: list[_Bar] = []
        same_terminal = False
        try:  # standard output on the same terminal: its lines printed above the bars
            same_terminal = sys.stdout.isatty() and os.path.samestat(
                os.fstat(sys.stdout.fileno()), os.fstat(sys.stderr.fileno()))
        except (AttributeError, ValueError, OSError):
            pass
        self._streams = (sys.stdout, sys.stderr)
        display = self

        class Flushing(Progress):
            def get_renderables(self):
                display.flush()
                yield from super().get_renderables()

        self.progress = Flushing(*_columns(), console=Console(file=sys.stderr), transient=True,
                                 redirect_stdout=same_terminal, redirect_stderr=True)
        self.remote_tasks: dict[tuple[int, int], int] = {}
        self.channel = None
        self._dir = None
        self._sock = None
        self._saved_env = os.environ.get(ENV_CHANNEL)
        self._stop = threading.Event()
        try:
            self._dir = tempfile.mkdtemp(prefix="fsw-progress-")
            path = os.path.join(self._dir, "s")
            self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
            self._sock.bind(path)
            self._sock.settimeout(0.2)
            self.channel = f"{self.pid}:{path}"
            os.environ[ENV_CHANNEL] = self.channel
        except OSError:  # no socket: workers' bars are not shown, ours are
            self._close_socket()
        self.progress.start()
        self._thread = None
        if self._sock is not None:
            self._thread = threading.Thread(target=self._receive, name="fsw-progress", daemon=True)
            self._thread.start()
        self._signals = _clearing_signals(self)

    # bars of this process
    def add(self, label, total, unit, depth, extra=""):
        with self.lock:
            return self.progress.add_task("  " * depth + label, total=total, unit=unit,
                                          total_shown=total, extra=extra)

    def update(self, task, done, fields):
        extra = "  ".join(f"{k}={v}" for k, v in fields.items())
        with self.lock:
            self.progress.update(task, completed=done, extra=extra)

    def push(self, bar, value):
        with self.lock:
            if value[0] > bar.pushed:
                bar.pushed = value[0]
                self.update(bar.task, value[1], value[2])

    def flush(self):
        """Pushes the updates the bars kept (from rich's refresh: never waits
        for the lock, which a thread adding a bar holds while it refreshes)."""
        if not self.lock.acquire(blocking=False):
            return
        try:
            for bar in self.bars:
                value = bar.value
                if value is not None and value[0] > bar.pushed:
                    self.push(bar, value)
        finally:
            self.lock.release()

    def remove(self, bar):
        with self.lock:
            self.bars.remove(bar)
            self.progress.remove_task(bar.task)

    # bars of workers
    def _receive(self):
        last_check = time.monotonic()
        while not self._stop.is_set():
            try:
                data = self._sock.recv(65536)
            except socket.timeout:
                data = None
            except OSError:
                return
            if data is not None:
                try:
                    self._remote(json.loads(data))
                except (ValueError, KeyError, TypeError, AttributeError):
                    pass
            now = time.monotonic()
            if now - last_check > 1.0:
                last_check = now
                self._forget_dead()

    def _remote(self, m):
        key = (int(m["p"]), int(m["i"]))
        kind = m["k"]
        with self.lock:
            task = self.remote_tasks.get(key)
            if kind == "e":
                if task is not None:
                    del self.remote_tasks[key]
                    self.progress.remove_task(task)
                return
            if task is None:
                total = m.get("t")
                total = float(total) if isinstance(total, (int, float)) else None
                task = self.add(str(m.get("l", "")), total, str(m.get("n", "")), 1 + int(m.get("depth", 0)))
                self.remote_tasks[key] = task
            if kind == "u":
                self.update(task, float(m.get("d", 0)), dict(m.get("f") or {}))

    def _forget_dead(self):
        with self.lock:
            for key, task in list(self.remote_tasks.items()):
                try:
                    os.kill(key[0], 0)
                except ProcessLookupError:
                    del self.remote_tasks[key]
                    self.progress.remove_task(task)
                except OSError:
                    pass

    def _close_socket(self):
        if self._sock is not None:
            self._sock.close()
            self._sock = None
        if self._dir is not None:
            try:
                for name in os.listdir(self._dir):
                    os.unlink(os.path.join(self._dir, name))
                os.rmdir(self._dir)
            except OSError:
                pass
            self._dir = None

    def close(self):
        """Clears the bars and puts everything back as it was."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(1.0)
        try:
            self.progress.stop()
        finally:
            if os.environ.get(ENV_CHANNEL) == self.channel and self.channel is not None:
                if self._saved_env is None:
                    del os.environ[ENV_CHANNEL]
                else:
                    os.environ[ENV_CHANNEL] = self._saved_env
            self._close_socket()
            _restore_signals(self._signals)


def _clearing_signals(display):
    """SIGTERM and SIGHUP at their default action (death) clear the display
    first; their status stays that of the signal."""
    if threading.current_thread() is not threading.main_thread():
        return {}

    def clear_then_die(signum, _frame):
        global _display
        try:
            if _display is display:
                _display = None
                display.close()
        finally:
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)

    saved = {}
    for sig in (signal.SIGTERM, signal.SIGHUP):
        try:
            if signal.getsignal(sig) == signal.SIG_DFL:
                saved[sig] = signal.signal(sig, clear_then_die)
        except (ValueError, OSError):
            pass
    return saved


def _restore_signals(saved):
    for sig, handler in saved.items():
        try:
            if threading.current_thread() is threading.main_thread():
                signal.signal(sig, handler)
        except (ValueError, OSError):
            pass


def _after_fork_in_child():
    """A child forked while bars are shown is a worker: it gets back the
    streams the display replaced, and never draws."""
    global _display, _depth, _lock, _threads
    _lock = threading.Lock()  # another thread may have held it at the fork
    _threads = threading.local()
    d = _display
    if d is not None:
        _display, _depth = None, 0
        sys.stdout, sys.stderr = d._streams


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)

_depth = 0  # bars of this process now shown
_lock = threading.Lock()  # _display and _depth, for bars of several threads (a pool of replays)
_threads = threading.local()  # .depth: the bars of this thread now shown


@contextlib.contextmanager
def progress(label: str, total: float | int | None = None, unit: str = ""):
    """A progress bar for the block (see the module's documentation)."""
    global _display, _depth, _remote_depth
    with _lock:
        d = _display
        if d is None or d.pid != os.getpid():
            d = None
            remote = _remote(label, total, unit)
            if remote is None and enabled():
                try:
                    d = _display = _Display()
                except Exception:  # noqa: BLE001  (a terminal rich cannot draw on: no bar, never a failure)
                    _display = None
        if d is not None:
            mine = getattr(_threads, "depth", 0)  # a pool thread's first bar goes under the outer one
            bar = _Bar(d, label, total, unit, mine or (1 if _depth else 0))
            _threads.depth = mine + 1
            _depth += 1
    if d is None:
        if remote is None:
            yield _OFF
            return
        _remote_depth += 1
        try:
            yield remote
        finally:
            _remote_depth -= 1
            remote.close()
        return
    try:
        yield bar
    finally:
        _threads.depth -= 1
        with _lock:
            _depth -= 1
            last = _depth == 0 and _display is d
            if last:
                _display = None
            elif _display is d:
                bar.close()
        if last:
            d.close()
