"""A board's VM has only what its application's layout can ask for
(docs/bytecode.md, "A board's VM"): the window functions of the machine
that [reload] names, the value types of it and its state vector, the
vector's lock option. The build writes them as fsw::vm_features, LTO drops
the rest of the VM, and both verifiers refuse an image that needs more:
`fsw machine upload` with a located error, the board with kVmNoFeature."""

from __future__ import annotations

from conftest import EXAMPLES

STAND = EXAMPLES / "stand"

# the stand's vent controller with a median filter on the pressure, an F32
# gain and an I16 trim: none of them in the stand's machine or state vector
WIDER = (STAND / "tank_700.sm").read_text().replace(
    "U64 counter             = 0\n",
    "U64 counter             = 0\nF32 gain                = 1.5\nI16 trim                = 0\n").replace(
    "if tankPressure > 700 {", "if roll_median(tankPressure, 5) > 700 {")


def _stand():
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.target.build import load

    return load(str(STAND), Diagnostics())


def test_the_stand_s_vm_has_its_types_and_no_window():
    from fswkit.autocode import vmverify as V

    app = _stand()
    f = V.features_of(app.sv, app.machines[app.reload.machine])
    # tank.sv's F64 pressure and tank.sm's U16 locals (U32, U64 and bool always); no window, no signed type, no lock
    assert V.feature_names(f) == ["U16", "F64"] and f == 0x2040


def test_the_generated_code_defines_the_features():
    from fswkit.autocode.emit.app import emit_app

    text = "\n".join(emit_app(_stand()).values())
    assert "extern const uint16_t vm_features = 0x2040;" in text, text


def test_an_upload_that_needs_more_is_a_located_error(fsw, tmp_path):
    sm = tmp_path / "tank_median.sm"
    sm.write_text(WIDER)
    r = fsw("machine", str(STAND), "upload", str(sm), "--port", str(tmp_path / "none"))  # refused before it opens
    assert r.code == 2, r.err
    assert "Traceback" not in r.err
    lines = WIDER.splitlines()
    gain = next(i for i, x in enumerate(lines, 1) if x.startswith("F32 gain"))
    med = next(i for i, x in enumerate(lines, 1) if "roll_median" in x)
    assert f"tank_median.sm:{gain}:1:" in r.err and "local `gain` is F32" in r.err, r.err
    trim = gain + 1
    assert f"tank_median.sm:{trim}:1:" in r.err and "local `trim` is I16" in r.err, r.err
    assert f"tank_median.sm:{med}:" in r.err and "roll_median: the firmware's VM was built without it" in r.err, r.err
    assert "add it to `TankVentControl`" not in r.err  # the machine's name, not a state's
    assert "or add it to `tank`" in r.err, r.err


def test_the_host_verifier_refuses_the_image_as_the_board_would(tmp_path):
    from fswkit.autocode import vmverify as V
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.emit.bytecode import compile_machine
    from fswkit.autocode.numeric import F32MODE
    from fswkit.autocode.project import load_machine

    app = _stand()
    feats = V.features_of(app.sv, app.machines[app.reload.machine])
    lay = V.layout_of(app.sv)
    sm = tmp_path / "tank_median.sm"
    sm.write_text(WIDER)
    for text, want in ((WIDER, V.NO_FEATURE), (WIDER.replace("roll_median(tankPressure, 5)", "tankPressure"),
                                                V.NO_FEATURE), ((STAND / "tank_700.sm").read_text(), V.OK)):
        sm.write_text(text)
        im = compile_machine(load_machine(str(sm), Diagnostics(), app.sv.path), F32MODE)
        assert V.verify(im, lay, 4, features=feats) == want
        assert V.verify(im, lay, 4) == V.OK  # libfswsm's VM has every feature
    assert V.NO_FEATURE == 18 and "built without" in V.REASONS[V.NO_FEATURE]


def _stand_with(tmp_path, vm_row: str):
    """examples/stand copied with `vm_row` added to its [reload]."""
    import shutil

    out = tmp_path / "stand"
    for name in ("stand", "tank"):  # the stand reads the tank's configs beside it
        shutil.copytree(EXAMPLES / name, tmp_path / name, ignore=shutil.ignore_patterns("build"))
    app = (out / "stand.app").read_text()
    assert "\nactivate TankVentControl Idle" in app
    (out / "stand.app").write_text(app.replace("\nactivate TankVentControl Idle",
                                               f"\n{vm_row}\nactivate TankVentControl Idle"))
    return out


def test_reload_vm_builds_the_board_with_more(fsw, tmp_path):
    """`vm roll_median F32 I16` in [reload]: the board's VM has them too, so
    the wider machine uploads (it fails only at the port); `vm all`: every
    feature, the VM libfswsm has."""
    from fswkit.autocode import vmverify as V
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.emit.app import emit_app
    from fswkit.target.build import load

    stand = _stand_with(tmp_path, "vm       roll_median F32 I16   # what an upload may use beyond the machine's")
    app_text = (stand / "stand.app").read_text()
    (stand / "stand.app").write_text(app_text.replace("\nram      64 ", "\nram      96 "))  # the median's samples
    app = load(str(stand), Diagnostics())
    f = V.board_features(app)
    assert V.feature_names(f) == ["roll_median", "I16", "U16", "F32", "F64"], V.feature_names(f)
    assert f"extern const uint16_t vm_features = 0x{f:04x};" in "\n".join(emit_app(app).values())
    sm = tmp_path / "tank_median.sm"
    sm.write_text(WIDER)
    r = fsw("machine", str(stand), "upload", str(sm), "--port", str(tmp_path / "none"))
    assert r.code != 0 and "built without" not in r.err and "no such port" in r.err, r.err

    every = load(str(_stand_with(tmp_path / "all", "vm all")), Diagnostics())
    assert V.board_features(every) == V.ALL_FEATURES


def test_reload_vm_refuses_what_it_does_not_know(fsw, tmp_path):
    for row, col, said in (("vm roll_mean", 4, "unknown VM feature `roll_mean`"),
                           ("vm all F32", 8, "`all` is every feature: name nothing beside it"),
                           ("vm F32 F32", 8, "`F32` named twice"),
                           ("vm", 1, "`vm` takes the VM's features beyond the machine's")):
        stand = _stand_with(tmp_path / str(col) / row.replace(" ", "_"), row)
        r = fsw("check", str(stand))
        lines = (stand / "stand.app").read_text().splitlines()
        n = lines.index(row) + 1
        assert r.code != 0 and "Traceback" not in r.err, r.err
        assert f"stand.app:{n}:{col}:" in r.err and said in r.err, (row, r.err)
