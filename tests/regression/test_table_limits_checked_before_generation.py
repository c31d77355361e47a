"""Limits of the generated tables were not checked before generation: a
state vector over 65,535 B, a task or stream slower than the executor's
(telemetry's) rate / 65,535, a telemetry task faster than 65,535 Hz, more
than 255 tasks or writable elements or 128 streams, a frame longer than the
link's 16-bit buffer size, a state vector or window larger than an AVR
board's RAM: each passed `fsw check` and then failed in the compiler (or
wrapped around in a uint16_t). A state script with no `@assert` made
`kAssertText[] = {, 0}` under `--native`. Every value written into a typed
table is now checked against its C type's range by the checker, with a
located error; each limit is tested as a pair, the largest value accepted
(and its C++ compiled) and the next one refused."""

from __future__ import annotations

import os


from support import cxx
from fswkit.autocode.app import load_app
from fswkit.autocode.board import load_board
from fswkit.autocode.diagnostics import Diagnostics
from fswkit.autocode.emit.app import emit_app
from fswkit.autocode.emit.script import script_files
from fswkit.autocode.numeric import REALS
from fswkit.autocode.project import load_machine, load_script, load_sv
from fswkit.autocode.protocol import encoded_max

SM = "[state_vector]\nU64 time @alias G\nU32 state @alias S\n\n[Run]\n"


def _errors(diags: Diagnostics) -> str:
    return "\n".join(d.render() for d in diags.errors)


def _write(folder, name: str, text: str) -> str:
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def _app(folder, *, sv: str = "", tasks: str = "", telemetry: str = "", uplink: str = "", rate: int = 100,
         board: str = "native", sm: str = SM, unit: str = "ms") -> str:
    _write(folder, "a.sv", "[Main]\nU64 time\nU32 state\n" + sv)
    _write(folder, "m.sm", sm)
    return _write(folder, "a.app", f"[application]\nboard {board}\nrate {rate}\n[configs]\nstate_vector a.sv\n"
                                   f"machine m.sm\n[time]\nunit {unit}\n[tasks]\nrun machine m\n{tasks}"
                                   f"[telemetry]\n{telemetry}[uplink]\n{uplink}")


def _load(path: str):
    diags = Diagnostics()
    return load_app(path, diags), _errors(diags)


def _pair(tmp_path, make, where: str, message: str, board: str = "native"):
    """`make(ok)` for ok True (must load) and False (must be refused at
    `where`, a `file:line:col`, with `message`); the accepted application's
    C++ must compile."""
    ok_dir, bad_dir = tmp_path / "ok", tmp_path / "bad"
    ok_dir.mkdir()
    bad_dir.mkdir()
    app, errors = _load(make(ok_dir, True))
    assert app is not None, errors
    proc = cxx.compile_each(load_board(board), cxx.write(emit_app(app), str(tmp_path / "gen")))
    assert proc.returncode == 0, proc.stderr[-3000:]
    app, errors = _load(make(bad_dir, False))
    assert app is None
    assert f"{where}:" in errors and message in errors, errors
    assert errors.count("error @") == 1, errors


def test_state_vector_of_65535_bytes_accepted_65536_refused(tmp_path):
    def sv(n_bytes):
        # G and S (12 B), then F64s and U8s up to n_bytes
        f64, u8 = divmod(n_bytes - 12, 8)
        return "[Main]\nU64 time\nU32 state\n" + "".join(f"F64 f{i}\n" for i in range(f64)) + \
            "".join(f"U8 b{i}\n" for i in range(u8))
    diags = Diagnostics()
    assert load_sv(_write(tmp_path, "ok.sv", sv(65535)), diags).size == 65535 and not diags.errors
    diags = Diagnostics()
    load_sv(_write(tmp_path, "bad.sv", sv(65536)), diags)
    errors = _errors(diags)
    last = 3 + (65536 - 12) // 8 + 4  # the fourth U8 ends at byte 65,536
    assert f"bad.sv:{last}:4:" in errors and "past 65,535 B with `b3`" in errors, errors
    assert errors.count("error @") == 1


def test_locals_of_65535_bytes_accepted_65536_refused(tmp_path):
    _write(tmp_path, "m.sv", "[Main]\nU64 time\nU32 state\n")

    def sm(n_bytes):
        f64, u8 = divmod(n_bytes, 8)
        return SM.replace("[Run]", "[local]\n" + "".join(f"F64 f{i} = 1\n" for i in range(f64))
                          + "".join(f"U8 b{i} = 1\n" for i in range(u8)) + "\n[Run]")
    diags = Diagnostics()
    assert load_machine(_write(tmp_path, "ok.sm", sm(65535)), diags, str(tmp_path / "m.sv")) is not None, \
        _errors(diags)
    diags = Diagnostics()
    load_machine(_write(tmp_path, "bad.sm", sm(65536)), diags, str(tmp_path / "m.sv"))
    errors = _errors(diags)
    assert f"bad.sm:{5 + 8192}:5:" in errors and "past 65,535 B with `f8191`" in errors, errors
    assert errors.count("error @") == 1


def test_task_divider_of_64000_accepted_65536_refused(tmp_path):
    # Rates divide 1,000,000, so a divider is 2^a 5^b: 64,000 is the largest
    # under 65,536, the first that does not fit a uint16_t.
    _pair(tmp_path, lambda d, ok: _app(d, rate=1000, unit="us", tasks=f"slow outputs rate={1000 / (64000 if ok else 65536)}\n"),
          "a.app:11:1", "runs every 65,536 executor cycles: at most every 65,535")


def test_stream_interval_of_64000_accepted_65536_refused(tmp_path):
    _pair(tmp_path, lambda d, ok: _app(d, rate=100, tasks="down telemetry rate=100\n",
                                       telemetry=f"Main rate={100 / (64000 if ok else 65536)}\n"),
          "a.app:13:1", "samples every 65536 telemetry runs: at most every 65,535")


def test_telemetry_at_62500_hz_accepted_100000_refused(tmp_path):
    # The executor rates around 65,535 Hz that divide 1,000,000.
    _pair(tmp_path, lambda d, ok: _app(d, rate=62500 if ok else 100000, unit="us",
                                       tasks=f"down telemetry rate={62500 if ok else 100000}\n"),
          "a.app:11:1", "runs at 100000 Hz: at most 65,535 Hz")


def test_255_tasks_accepted_256_refused(tmp_path):
    _pair(tmp_path, lambda d, ok: _app(d, tasks="".join(f"t{i} outputs\n" for i in range(254 if ok else 255))),
          "a.app:265:1", "an application runs at most 255 tasks")


def test_128_streams_accepted_129_refused(tmp_path):
    def make(d, ok):
        n = 128 if ok else 129
        regions = "".join(f"[R{i}]\nU8 e{i}\n" for i in range(n - 1))
        return _app(d, sv=regions, tasks="down telemetry rate=100\n",
                    telemetry="Main rate=1\n" + "".join(f"R{i} rate=1\n" for i in range(n - 1)))
    _pair(tmp_path, make, "a.app:141:1", "the link carries at most 128 streams")


def test_255_writable_elements_accepted_256_refused(tmp_path):
    def make(d, ok):
        n = 255 if ok else 256
        return _app(d, sv="".join(f"U8 e{i}\n" for i in range(n)), tasks="up uplink\n",
                    uplink="".join(f"e{i}\n" for i in range(n)))
    _pair(tmp_path, make, "a.app:269:1", "the uplink writes at most 255")


def test_frames_of_65535_wire_bytes_accepted_65536_refused(tmp_path):
    # The largest region whose frame (header, samples, CRC) fits a 16-bit
    # buffer once COBS-encoded, and one byte more.
    size = max(n for n in range(60000, 65536) if encoded_max(6 + n + 2) <= 65535)
    assert encoded_max(6 + size + 1 + 2) > 65535

    def make(d, ok):
        f64, u8 = divmod(size + (0 if ok else 1), 8)
        big = "[Big]\n" + "".join(f"F64 f{i}\n" for i in range(f64)) + "".join(f"U8 b{i}\n" for i in range(u8))
        return _app(d, sv=big, tasks="down telemetry rate=1\n", telemetry="Big rate=0.125\n")
    _pair(tmp_path, make, "a.app:13:1", "at most 65,535 B (the link's buffer is sized in 16 bits)")


def test_state_vector_as_large_as_the_uno_ram_accepted_one_more_refused(tmp_path):
    def make(d, ok):
        return _app(d, board="uno", sv="".join(f"U8 b{i}\n" for i in range(2048 - 12 + (0 if ok else 1))))
    _pair(tmp_path, make, "a.app:5:14", "the state vector is 2,049 B: more than the uno's RAM (2,048 B)",
          board="uno")


def test_window_as_large_as_the_uno_ram_accepted_one_more_refused(tmp_path):
    def make(d, ok):
        sm = SM.replace("U32 state @alias S\n", "U32 state @alias S\nF32 x\n") + \
            f".step\n    x = roll_avg(x, {512 if ok else 513})\n"
        return _app(d, board="uno", sv="F32 x\n", sm=sm)
    _pair(tmp_path, make, "a.app:6:9", "holds 2,052 B: more than the uno's RAM (2,048 B)", board="uno")


def test_script_without_asserts_compiles_natively(tmp_path):
    _write(tmp_path, "m.sv", "[Main]\nU64 time\nU32 state\n")
    _write(tmp_path, "m.sm", SM)
    path = _write(tmp_path, "m.ss", "[options]\ndelta_t 1\n\n[all_states]\nG == 3: @stop\n")
    diags = Diagnostics()
    script = load_script(path, diags)
    assert script is not None, _errors(diags)
    files = script_files(script, REALS["f64"], lambda p, line: "")
    proc = cxx.compile_each(load_board("native"), cxx.write(files, str(tmp_path / "gen")))
    assert proc.returncode == 0, proc.stderr[-3000:]


def test_rates_far_below_the_limits_are_named_as_written(tmp_path):
    # A rate of 1e-400 Hz is taken exactly: it is refused as too slow, with
    # the rate as written and the interval in a few digits, not "0.0 Hz"
    # and a number of 400 digits.
    _app(tmp_path, rate=100, tasks="slow outputs rate=1e-400\ndown telemetry rate=100\n",
         telemetry="Main rate=1e-400\n")
    app, errors = _load(str(tmp_path / "a.app"))
    assert app is None
    assert "a.app:11:1:" in errors and "task `slow` runs every 1e+402 executor cycles: at most every 65,535" \
        in errors, errors
    assert "a.app:14:1:" in errors and "stream `Main` at 1e-400 Hz samples every 1e+402 telemetry runs" \
        in errors, errors
    assert errors.count("error @") == 2 and max(len(line) for line in errors.splitlines()) < 250, errors


def test_a_fractional_rate_is_named_as_a_decimal(tmp_path):
    # Rates are exact fractions inside; a message names them as the config
    # spells them (`0.5`), never as `1/2`.
    _app(tmp_path, rate=100000, tasks="down telemetry rate=0.5\n", telemetry="Main rate=50\n")
    path = tmp_path / "a.app"
    path.write_text(path.read_text().replace("run machine m", "run machine m rate=1562.5"))
    app, errors = _load(str(path))
    assert app is None
    assert "task `run` runs at 1562.5 Hz but `G` counts in ms" in errors, errors
    assert "stream rate 50 Hz must divide the telemetry task's rate 0.5 Hz" in errors, errors
    assert "/2" not in errors, errors
