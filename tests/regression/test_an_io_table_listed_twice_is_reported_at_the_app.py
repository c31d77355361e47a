"""An I/O table named twice in [configs] (`io tank.aio` and `io
./tank.aio`, a copy-paste) was read twice, and every row of the second
reading was refused at the table itself, pointing at the same row:
`tank.aio:4:8: pin A0 is already used (tank.aio:4)`; a `.sns` said
`address 0x76 is already the bmp280's (x.sns:1)` at x.sns:1. The table
was right and the .app wrong. Now the second `io` line is the error
(`tank.app:LINE:COL: tank.aio is already listed on line N`), the table is
read once, and its rows are not reported."""

from __future__ import annotations

from conftest import EXAMPLES, run_fsw

TANK = EXAMPLES / "tank"


def project(tmp_path, extra: str):
    for name in ("tank.sv", "tank.sm", "tank.app", "tank.aio", "tank.dio"):
        (tmp_path / name).write_bytes((TANK / name).read_bytes())
    (tmp_path / "tank.sv").write_text((tmp_path / "tank.sv").read_text() + "[Baro]\nF32 baro\n")
    (tmp_path / "baro.sns").write_text("bmp280 i2c:0x76 pressure=baro\n")
    app = (tmp_path / "tank.app").read_text()
    assert "io           tank.dio\n" in app
    app = app.replace("io           tank.dio\n", "io           tank.dio\nio           baro.sns\n" + extra)
    (tmp_path / "tank.app").write_text(app)
    lines = app.splitlines()
    return len(lines) - lines[::-1].index(extra.splitlines()[0]) if extra else None  # the last such line


def test_a_channel_table_listed_twice_is_one_error_at_the_app(tmp_path):
    line = project(tmp_path, "io           ./tank.aio\n")
    r = run_fsw("check", "tank.app", cwd=tmp_path)
    assert r.code == 1, r.err
    assert f"application config error @ tank.app:{line}:14:" in r.err, r.err
    assert "already listed on line 11" in r.err, r.err
    assert "tank.aio:4" not in r.err and r.err.count("error @") == 1, r.err


def test_a_sensor_table_listed_twice_is_one_error_at_the_app(tmp_path):
    line = project(tmp_path, "io           baro.sns\n")
    r = run_fsw("check", "tank.app", cwd=tmp_path)
    assert r.code == 1, r.err
    assert f"application config error @ tank.app:{line}:14:" in r.err, r.err
    assert "already listed on line 13" in r.err and r.err.count("error @") == 1, r.err


def test_each_table_once_is_accepted(tmp_path):
    project(tmp_path, "")
    r = run_fsw("check", "tank.app", cwd=tmp_path)
    assert r.code == 0, r.err
