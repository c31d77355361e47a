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
