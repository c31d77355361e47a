"""Link logs: an append-only binary file of the raw bytes that crossed the
link, with host timestamps, headed by the layout the recording decoded with.
Every chunk is written (unbuffered) as soon as it is read, so a Ctrl-C or a
yanked cable loses nothing already received; the file is fsync'ed on close.

    magic     8 bytes  b"FSWLOG1\\n"
    header    u32 length + that many bytes of JSON: {"format": 1, "layout": {...}, ...}
    records   dir u8 (0 from the target, 1 to the target), host time u64 (ns since
              the Unix epoch), length u32 (never 0), the bytes
"""

from __future__ import annotations

import json
import os
import struct
import tempfile

from fswkit.autocode.diagnostics import read_input
from fswkit.outputs import RECORDING_MAGIC, is_direct

from .layout import Layout, LayoutError, from_dict

MAGIC = RECORDING_MAGIC
MAX_LOG = 1 << 30  # bytes of a log the tools read: 1 GiB, a day of a link at 115200 baud
_REC = struct.Struct("<BQI")
RX, TX = 0, 1


class LogError(Exception):
    pass


class LogWriter:
    """A new log. An existing file at `path` is never truncated unless
    `force`; the log is written into a temporary file beside `path` and
    takes its name at `commit()` (the monitor commits once the target is
    known to be the right one) or at `close()`, so a refused or failed
    start leaves whatever was at `path` as it was. A write that fails (a
    full disk) is a LogError saying so."""

    def __init__(self, path: str, layout: Layout, *, force: bool = False, **meta):
        self.path = path
        self._fd = None
        self._tmp = None
        if os.path.isdir(path):
            raise LogError(f"cannot write {path}: it is a folder")
        if os.path.lexists(path) and not force:
            raise LogError(f"{path} exists: a log is never overwritten unless asked (--force replaces it); "
                           "choose another name")
        try:
            if is_direct(path):  # a device or a pipe: written in place
                self._fd = os.open(path, os.O_WRONLY | os.O_APPEND)
            else:
                target = os.path.realpath(path) if os.path.islink(path) else path
                fd, self._tmp = tempfile.mkstemp(prefix=f".{os.path.basename(target)}.", suffix=".part",
                                                 dir=os.path.dirname(os.path.abspath(target)))
                self._target = target
                os.fchmod(fd, 0o644)
                self._fd = fd
        except OSError as e:
            raise LogError(f"cannot write {path}: {e.strerror or e}") from None
        head = json.dumps({"format": 1, "layout": layout.raw, **meta}, sort_keys=True).encode()
        try:
            self._write(MAGIC + struct.pack("<I", len(head)) + head)
        except LogError:  # a full disk from the start: no temporary file left beside the path
            self.close(keep=False)
            raise

    def _write(self, data: bytes) -> None:
        view = memoryview(data)
        try:
            while view:
                n = os.write(self._fd, view)
                view = view[n:]
        except OSError as e:
            raise LogError(f"cannot write the log {self.path}: {e.strerror or e}") from None

    def record(self, direction: int, host_time_ns: int, data: bytes) -> None:
        if data and self._fd is not None:
            self._write(_REC.pack(direction, host_time_ns, len(data)) + data)

    def commit(self) -> None:
        """Gives the log its name (replacing what was there, when forced)."""
        if self._tmp is not None:
            try:
                os.replace(self._tmp, self._target)
            except OSError as e:
                raise LogError(f"cannot write {self.path}: {e.strerror or e}") from None
            self._tmp = None

    def close(self, keep: bool = True) -> None:
        """Ends the log: committed when `keep`, else (never committed) removed."""
        if self._fd is not None:
            try:
                os.fsync(self._fd)
            except OSError:
                pass
            os.close(self._fd)
            self._fd = None
        if self._tmp is not None:
            if keep:
                self.commit()
            else:
                try:
                    os.unlink(self._tmp)
                except OSError:
                    pass
                self._tmp = None


class LogReader:
    """A log's layout and records. A record cut short (the recorder died
    mid-write) or one no recorder writes (a damaged file) ends the log:
    `truncated` says so, and `incomplete` in words, once read."""

    def __init__(self, path: str):
        try:
            data = read_input(path, MAX_LOG)
        except OSError as e:
            raise LogError(f"cannot read {path}: {e.strerror or e}") from None
        if not data.startswith(MAGIC) or len(data) < len(MAGIC) + 4:
            raise LogError(f"{path}: not an fswkit link log (no FSWLOG1 header)")
        (n,) = struct.unpack_from("<I", data, len(MAGIC))
        start = len(MAGIC) + 4
        try:
            self.header = json.loads(data[start:start + n].decode())
        except ValueError as e:  # JSONDecodeError and UnicodeDecodeError alike
            raise LogError(f"{path}: not a valid log: its header is not JSON ({e})") from None
        except RecursionError:
            raise LogError(f"{path}: not a valid log: its header is JSON nested too deeply to read") from None
        if not isinstance(self.header, dict) or "layout" not in self.header:
            raise LogError(f"{path}: not a valid log: its header has no `layout` object")
        if self.header.get("format") != 1:
            raise LogError(f"{path}: not a valid log: field `format`: expected 1, found "
                           f"{json.dumps(self.header.get('format'))[:40]}")
        try:
            self.layout = from_dict(self.header["layout"])
        except LayoutError as e:
            raise LogError(f"{path}: not a valid log: {e}") from None
        self._data = data
        self._at = start + n
        self.path = path
        self.truncated = False
        self.incomplete: str | None = None

    def _ends(self, at: int, why: str) -> None:
        self.truncated = True
        self.incomplete = why.format(at=at, left=len(self._data) - at)

    def records(self):
        """(direction, host time in seconds, bytes) in recording order."""
        data, at = self._data, self._at
        size = _REC.size
        while at < len(data):
            # a record's head cut short is a record that runs past the end
            d, t, n = _REC.unpack_from(data, at) if at + size <= len(data) else (RX, 0, len(data))
            if d not in (RX, TX) or n == 0:  # a recorder writes no empty record: a tail of NULs is damage
                self._ends(at, "the record at byte {at:,} is not one a recorder writes: the file is damaged; "
                               "its last {left:,} bytes are not decoded")
                return
            if at + size + n > len(data):
                self._ends(at, "the record at byte {at:,} is cut short ({left:,} bytes not decoded): the "
                               "recording stopped mid-write, or the file is damaged")
                return
            yield d, t / 1e9, data[at + size:at + size + n]
            at += size + n
