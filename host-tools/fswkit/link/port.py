"""Opening the serial port (pyserial): a device (/dev/ttyACM0, a pty) or a
pyserial URL (socket://host:port, loop://).

A device is opened for one program at a time: pyserial's `exclusive` lock
(flock) keeps out every other fswkit command, and TIOCEXCL keeps out other
programs (avrdude, a terminal) that open the device while we hold it.
Whoever holds it leaves a holder record (`runtime_dir()/ports/`, its pid,
its command and, for a ground station, its local socket), so a second
opener is told who has it ("busy: held by fsw ground, pid 4242") and a
client can find the station that serves the port."""

from __future__ import annotations

import errno
import fcntl
import json
import os
import stat
import tempfile
import termios


class PortError(Exception):
    pass


class PortBusy(PortError):
    """The port is held by another program (`holder`: its record, or None)."""

    def __init__(self, message: str, holder: dict | None):
        super().__init__(message)
        self.holder = holder


def is_url(name: str) -> bool:
    return "://" in name


class RuntimeDirError(OSError):
    """The runtime folder is not this user's own (`runtime_dir`); said as
    `FOLDER: why` wherever an OSError is."""

    def __str__(self) -> str:
        return f"{self.filename}: {self.strerror}"


def runtime_dir() -> str:
    """Where holder records and stations' sockets live: $XDG_RUNTIME_DIR/fswkit,
    else a folder of this user's in the temporary directory (FSW_RUNTIME_DIR
    overrides both). Used only when it is a folder of this user's, not a
    link, that no one else can write (RuntimeDirError otherwise): in a shared
    /tmp another user could make it first and plant a record that sends
    the tools' commands to their own socket."""
    base = os.environ.get("FSW_RUNTIME_DIR")
    if not base:
        xdg = os.environ.get("XDG_RUNTIME_DIR")
        base = os.path.join(xdg, "fswkit") if xdg else os.path.join(tempfile.gettempdir(), f"fswkit-{os.getuid()}")
    os.makedirs(base, mode=0o700, exist_ok=True)
    st = os.lstat(base)
    if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.getuid() or st.st_mode & 0o022:
        raise RuntimeDirError(errno.EPERM, "not a folder of this user's that only this user can write (another user "
                      "could plant a port's holder record there): remove it, or set FSW_RUNTIME_DIR to one", base)
    return base


def port_key(name: str) -> str:
    """A port's name for its holder record: its real path (two names of one
    device are one port), as a file name."""
    real = name if is_url(name) else os.path.realpath(name)
    return real.strip("/").replace("/", "_").replace(":", "_") or "port"


def _record_path(name: str) -> str:
    d = os.path.join(runtime_dir(), "ports")
    os.makedirs(d, mode=0o700, exist_ok=True)
    return os.path.join(d, port_key(name) + ".json")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def holder(name: str) -> dict | None:
    """The record of the live program holding port `name`, or None (a record
    left by a program that died is removed)."""
    path = _record_path(name)
    try:
        with open(path, encoding="utf-8") as f:
            rec = json.load(f)
    except (OSError, ValueError):
        return None
    if not isinstance(rec, dict) or not isinstance(rec.get("pid"), int) or not _alive(rec["pid"]):
        try:
            os.unlink(path)
        except OSError:
            pass
        return None
    return rec


def busy_message(name: str, rec: dict | None) -> str:
    if rec is None:
        return f"{name} is busy: another program holds it open (close it, or find it with `fuser {name}`)"
    what = f"held by {rec.get('command', 'a program')}, pid {rec['pid']}"
    if rec.get("socket"):
        what += " (a ground station: `fsw monitor`, `fsw cmd`, `fsw param`, `fsw dump` go through it)"
    else:
        what += " (`fsw ground` shares a port between the tools)"
    return f"{name} is busy: {what}"


def _write_record(name: str, rec: dict) -> str:
    path = _record_path(name)
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), prefix=".rec.")
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        json.dump(rec, f)
    os.replace(tmp, path)
    return path


def _release(record: str) -> None:
    """Removes a holder record, when it is this process's."""
    try:
        with open(record, encoding="utf-8") as f:
            mine = json.load(f).get("pid") == os.getpid()
    except (OSError, ValueError):
        return
    if mine:
        try:
            os.unlink(record)
        except OSError:
            pass


def _held_serial():
    """pyserial's port class, with a `close()` that also gives up TIOCEXCL
    and the holder record (`record`: its path)."""
    import serial

    class Held(serial.Serial):
        record: str | None = None

        def close(self) -> None:
            try:
                if self.is_open:
                    fcntl.ioctl(self.fileno(), termios.TIOCNXCL)
            except (OSError, ValueError):
                pass
            try:
                super().close()
            except Exception:  # noqa: BLE001 - closing a port that went away
                pass
            if self.record is not None:
                record, self.record = self.record, None
                _release(record)

    return Held


PTY_SLAVE_MAJORS = range(136, 144)  # Linux's Unix98 pseudo-terminal slaves (/dev/pts/N)


def port_identity(name: str) -> tuple | None:
    """What a port that went away must still be to be opened again (None:
    whatever device comes back at the name, as a USB adapter plugged in
    again does). A pseudo-terminal does not come back: once its other end
    closed, the next one the system makes takes the same number, another
    program's (a terminal window's, say). Named by its own /dev/pts path,
    it is ("pty", device) and is never opened again; named by a link (a
    simulator's or socat's `link=`), it is the link itself, and a link made
    again is the port back."""
    if is_url(name):
        return None
    try:
        st = os.stat(name)
        link = os.lstat(name)
    except OSError:
        return None
    if not stat.S_ISCHR(st.st_mode) or os.major(st.st_rdev) not in PTY_SLAVE_MAJORS:
        return None
    if stat.S_ISLNK(link.st_mode):
        return ("link", link.st_dev, link.st_ino, link.st_ctime_ns)
    return ("pty", st.st_rdev)


def port_returned(name: str, identity: tuple | None) -> str | None:
    """None when the port `name` may be opened again (the port whose
    identity was `identity`, `port_identity`'s, may be back), else why not."""
    if identity is None:
        return None
    if identity[0] == "pty":
        return ("it was a pseudo-terminal, and one does not come back: the next one takes the same number "
                "(another program's); start the station again on the new port")
    try:
        link = os.lstat(name)
    except OSError:
        return "its link is not there"
    if (link.st_dev, link.st_ino, link.st_ctime_ns) == identity[1:]:
        return "its link still names the pseudo-terminal that closed"
    return None


def not_a_port(name: str) -> str | None:
    """Why a device path cannot be a serial port, in words (None: it may
    be one — a device, a pty — or is a pyserial URL). A FIFO opens without
    waiting and a socket not at all, so each is said to be what it is
    before pyserial tries (it would call a FIFO a device, a socket `No such
    device or address`)."""
    if is_url(name):
        return None
    try:
        mode = os.stat(name).st_mode
    except FileNotFoundError:
        return "no such port (`fsw ports` lists the serial ports connected)"
    except OSError:
        return None  # pyserial says why
    if stat.S_ISDIR(mode):
        return "it is a folder, not a serial port"
    if stat.S_ISREG(mode):
        return "it is a regular file, not a serial port"
    if stat.S_ISFIFO(mode):
        return "it is a FIFO (a named pipe), not a serial port"
    if stat.S_ISSOCK(mode):
        return "it is a socket, not a serial port"
    return None


def no_terminal(port: str, err: int | None, text: str) -> str | None:
    """What to say of a device that opened but is not a terminal (`/dev/null`,
    a disk: the system refuses a serial port's settings on it), or None when
    that is not the trouble."""
    if err == errno.ENOTTY or os.strerror(errno.ENOTTY) in text:
        return (f"cannot open {port}: it is a device that is not a terminal, not a serial port "
                "(`fsw ports` lists the serial ports connected)")
    return None


def denied(port: str, err: int | None, text: str) -> str | None:
    """What to say of a port the system would not open for this user (the
    usual first trouble on Linux: the serial devices belong to `dialout`),
    or None when that is not the trouble."""
    if err == errno.EACCES or "permission denied" in text.lower():
        return (f"no permission to open {port}: add yourself to the `dialout` group "
                "(sudo usermod -aG dialout $USER, then log in again)")
    return None


def open_port(name: str, baud: int, *, command: str | None = None, socket: str | None = None):
    """The port `name` at `baud`. With `command` (the fswkit command opening
    it), a device is held exclusively and a holder record written, both
    given up by the port's `close()`. PortBusy when another program has it."""
    try:
        import serial
    except ImportError:
        raise PortError("pyserial is not installed: run `make setup` (or pip install pyserial)") from None
    why = not_a_port(name)
    if why is not None:
        raise PortError(f"cannot open {name}: {why}")
    exclusive = command is not None and not is_url(name)
    if exclusive:
        rec = holder(name)
        if rec is not None and rec["pid"] != os.getpid():
            raise PortBusy(busy_message(name, rec), rec)
    try:
        if exclusive:
            port = _held_serial()(name, baudrate=baud, timeout=0.05, write_timeout=2, exclusive=True)
        else:
            port = serial.serial_for_url(name, baudrate=baud, timeout=0.05, write_timeout=2)
    except (serial.SerialException, ValueError, OSError) as e:
        text = str(e)
        if exclusive and ("exclusively lock" in text or "Resource temporarily unavailable" in text
                          or "Device or resource busy" in text or getattr(e, "errno", None) == 16):
            rec = holder(name)
            raise PortBusy(busy_message(name, rec), rec) from None
        err = getattr(e, "errno", None)
        raise PortError(denied(name, err, text) or no_terminal(name, err, text) or f"cannot open {name}: {e}") \
            from None
    if not exclusive:
        return port
    try:
        fcntl.ioctl(port.fileno(), termios.TIOCEXCL)
    except OSError:
        pass  # not a terminal (a FIFO in a test): the flock alone keeps fswkit's commands out
    rec = {"pid": os.getpid(), "command": command, "port": name, "baud": baud}
    if socket:
        rec["socket"] = socket
    port.record = _write_record(name, rec)
    return port


def port_errors():
    """The exceptions a port raises when it goes away (a yanked cable):
    termios.error too, which pyserial's flush() lets out of tcdrain()."""
    import serial

    return (serial.SerialException, OSError, termios.error)


def drain(port) -> None:
    """`port.flush()`, the bytes written handed to the line; a device that
    went away meanwhile is an OSError (tcdrain()'s termios.error is none,
    and the callers of a write wait on OSError)."""
    try:
        port.flush()
    except termios.error as e:
        errno = e.args[0] if len(e.args) >= 2 and isinstance(e.args[0], int) else 5  # EIO
        text = e.args[-1] if e.args else "Input/output error"
        raise OSError(errno, f"the port went away: {text}") from None
