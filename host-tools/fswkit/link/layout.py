"""What the ground needs to decode a target's frames: the state vector
layout, the streams with their batching, tasks, writable elements, state
names and analog calibrations. Built from the checked application by the
one front end (autocode), and saved as JSON at the head of every log so a
log decodes without the configs."""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from fractions import Fraction

from fswkit.autocode.types import TYPES  # element types by name: size, range, struct format


class LayoutError(Exception):
    pass


@dataclass(frozen=True)
class Element:
    index: int
    name: str
    type: str
    offset: int
    region: str

    @property
    def size(self) -> int:
        return TYPES[self.type].size


@dataclass(frozen=True)
class Region:
    name: str
    offset: int
    size: int
    elements: tuple[Element, ...]
    struct: struct.Struct  # the region's elements, packed little-endian
    bools: tuple[int, ...]  # positions of bool elements (stored as bytes, any non-zero is true)
    names: tuple[str, ...]

    def decode(self, data: bytes, at: int = 0) -> tuple:
        vals = self.struct.unpack_from(data, at)
        if not self.bools:
            return vals
        return self._fix(vals)

    def decode_all(self, data: bytes) -> list[tuple]:
        """Every sample of a batch (len(data) a multiple of the size)."""
        vals = list(self.struct.iter_unpack(data))
        if self.bools:
            vals = [self._fix(v) for v in vals]
        return vals

    def _fix(self, vals: tuple) -> tuple:
        v = list(vals)
        for i in self.bools:
            v[i] = v[i] != 0
        return tuple(v)


@dataclass(frozen=True)
class Stream:
    index: int
    region: Region
    rate: float  # samples per second
    batch: int
    period: float  # time units between two samples


@dataclass(frozen=True)
class Layout:
    schema: int
    name: str
    sv_size: int
    time_unit: str  # ms | us
    rate: int
    elements: tuple[Element, ...]
    regions: tuple[Region, ...]
    streams: tuple[Stream, ...]
    tasks: tuple[tuple[str, str], ...]  # (name, kind)
    writable: tuple[str, ...]
    states: dict  # S element name -> {state id: state name}
    analog: dict  # element name -> {pin, scale, offset, vref, bits}
    health_payload: int
    raw: dict  # the JSON form
    pyro: tuple[str, ...] = ()  # the [pyro] channels' elements: a status byte each in health frames
    sensors: tuple[str, ...] = ()  # the sensor parts (`bmp280@0x76`): a health code each, after the pyro bytes

    def element(self, name: str) -> Element | None:
        return next((e for e in self.elements if e.name == name), None)

    def task_index(self, name: str) -> int | None:
        return next((i for i, (n, _) in enumerate(self.tasks) if n == name), None)

    @property
    def has_uplink(self) -> bool:
        return any(k == "uplink" for _, k in self.tasks)

    def show(self, name: str, value) -> str:
        """A value as the monitor shows it: state names for S, units detail."""
        if value is None:
            return "—"
        if name in self.states:
            st = self.states[name].get(int(value))
            return f"{value} ({st})" if st else str(value)
        if isinstance(value, bool):
            return "true" if value else "false"
        if isinstance(value, float):
            return f"{value:.6g}"
        return str(value)


def _region(name, offset, size, elems) -> Region:
    fmt = "<" + "".join(TYPES[e.type].fmt for e in elems)
    if struct.calcsize(fmt) != size:
        raise LayoutError(f"region `{name}`: elements add up to {struct.calcsize(fmt)} bytes, not {size}")
    return Region(name, offset, size, tuple(elems), struct.Struct(fmt),
                  tuple(i for i, e in enumerate(elems) if e.type == "bool"), tuple(e.name for e in elems))


def _field(where: str, v, want: str) -> str:
    return f"field `{where}`: expected {want}, found {type(v).__name__} {json_text(v)}"


def json_text(v) -> str:
    import json

    text = json.dumps(v)
    return text if len(text) <= 40 else text[:37] + "..."


def _is_int(v, lo: int = 0, hi: int = 2**64) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and lo <= v <= hi


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _fraction(v) -> bool:
    try:
        return isinstance(v, (str, int)) and not isinstance(v, bool) and Fraction(v) > 0
    except (ValueError, ZeroDivisionError):
        return False


def check_dict(d) -> None:
    """LayoutError naming the first field of a layout's JSON form (a log
    header: anyone may have written it) whose type or value a decoder cannot
    use."""
    def need(ok: bool, where: str, v, want: str) -> None:
        if not ok:
            raise LayoutError(_field(where, v, want))

    need(isinstance(d, dict), "layout", d, "an object")
    spec = {"schema": (lambda v: _is_int(v, 0, 2**32 - 1), "a 32-bit unsigned number"),
            "name": (lambda v: isinstance(v, str), "a string"),
            "sv_size": (lambda v: _is_int(v, 0, 1 << 20), "a size in bytes"),
            "time_unit": (lambda v: v in ("ms", "us"), '"ms" or "us"'),
            "rate": (lambda v: _is_int(v, 1, 1 << 20), "a rate in Hz"),
            "health_payload": (lambda v: _is_int(v, 0, 1 << 16), "a size in bytes"),
            "elements": (lambda v: isinstance(v, list), "a list"),
            "regions": (lambda v: isinstance(v, list), "a list"),
            "streams": (lambda v: isinstance(v, list), "a list"),
            "tasks": (lambda v: isinstance(v, list), "a list"),
            "writable": (lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v), "a list of names"),
            "states": (lambda v: isinstance(v, dict), "an object"),
            "analog": (lambda v: isinstance(v, dict), "an object")}
    for key in ("pyro", "sensors"):  # absent: no pyro channels (older logs) / no sensor parts
        if key in d:
            need(isinstance(d[key], list) and all(isinstance(x, str) for x in d[key]), f"layout.{key}", d[key],
                 "a list of names")
    for key, (ok, want) in spec.items():
        if key not in d:
            raise LayoutError(f"field `layout.{key}` is missing")
        need(ok(d[key]), f"layout.{key}", d[key], want)
    items = {"elements": {"name": (lambda v: isinstance(v, str), "a string"),
                          "type": (lambda v: isinstance(v, str) and v in TYPES, "one of " + " ".join(TYPES)),
                          "offset": (lambda v: _is_int(v, 0, 1 << 20), "an offset in bytes"),
                          "region": (lambda v: isinstance(v, str), "a region name")},
             "regions": {"name": (lambda v: isinstance(v, str), "a string"),
                         "offset": (lambda v: _is_int(v, 0, 1 << 20), "an offset in bytes"),
                         "size": (lambda v: _is_int(v, 0, 1 << 20), "a size in bytes")},
             "streams": {"region": (lambda v: isinstance(v, str), "a region name"),
                         "rate": (_fraction, "a positive rate such as \"50\" or \"25/2\""),
                         "batch": (lambda v: _is_int(v, 1, 1 << 16), "a whole number of samples >= 1"),
                         "period": (_fraction, "a positive period such as \"20\"")},
             "tasks": {"name": (lambda v: isinstance(v, str), "a string"),
                       "kind": (lambda v: isinstance(v, str), "a string")}}
    for key, fields in items.items():
        for i, item in enumerate(d[key]):
            where = f"layout.{key}[{i}]"
            need(isinstance(item, dict), where, item, "an object")
            for name, (ok, want) in fields.items():
                if name not in item:
                    raise LayoutError(f"field `{where}.{name}` is missing")
                need(ok(item[name]), f"{where}.{name}", item[name], want)
    for el, names in d["states"].items():
        need(isinstance(names, dict) and all(isinstance(n, str) for n in names.values()), f"layout.states.{el}",
             names, "an object of state names")
        for k in names:
            need(k.lstrip("-").isdigit(), f"layout.states.{el}", k, "state ids")
    for el, cal in d["analog"].items():
        need(isinstance(cal, dict), f"layout.analog.{el}", cal, "an object")
        for name in ("scale", "offset"):
            need(_is_num(cal.get(name)), f"layout.analog.{el}.{name}", cal.get(name), "a number")
        need(isinstance(cal.get("pin"), (str, int)) and not isinstance(cal.get("pin"), bool),
             f"layout.analog.{el}.pin", cal.get("pin"), "a pin")


def from_dict(d: dict) -> Layout:
    """A layout from its JSON form (a log header); LayoutError naming the
    field that is wrong."""
    check_dict(d)
    try:
        elements = tuple(Element(i, e["name"], e["type"], e["offset"], e["region"])
                         for i, e in enumerate(d["elements"]))
        regions = tuple(_region(r["name"], r["offset"], r["size"],
                                [e for e in elements if e.region == r["name"]]) for r in d["regions"])
        by_name = {r.name: r for r in regions}
        streams = tuple(Stream(i, by_name[s["region"]], float(Fraction(s["rate"])), s["batch"],
                               float(Fraction(s["period"]))) for i, s in enumerate(d["streams"]))
        return Layout(int(d["schema"]), d["name"], d["sv_size"], d["time_unit"], d["rate"], elements, regions,
                      streams, tuple((t["name"], t["kind"]) for t in d["tasks"]), tuple(d["writable"]),
                      {k: {int(i): n for i, n in v.items()} for k, v in d["states"].items()},
                      d["analog"], d["health_payload"], d, tuple(d.get("pyro", ())),
                      tuple(d.get("sensors", ())))
    except (KeyError, TypeError, ValueError, ZeroDivisionError) as e:
        raise LayoutError(f"not a link layout: {type(e).__name__}: {e}") from None


def from_app(app) -> Layout:
    """The layout of a checked application (fswkit.autocode.app.Application)."""
    from fswkit.autocode.schema import app_schema_hash, link_plan

    plan = link_plan(app)
    per_second = 1000 if app.time_unit == "ms" else 1000000
    tele_div = app.tasks[plan.telemetry_task].divider if plan.telemetry_task is not None else 1
    streams = []
    for s in plan.streams:
        period = Fraction(s.every * tele_div * per_second, app.rate)
        streams.append({"region": s.region.name, "rate": str(s.rate), "batch": s.batch, "period": str(period)})
    states = {}
    for m in app.machines:
        states[m.vars[m.s].name] = {str(st.id): st.name for st in m.states}
    analog = {}
    for c in app.channels:
        if c.analog:
            analog[c.element.name] = {"pin": c.pin, "dir": c.direction, "scale": c.scale, "offset": c.offset,
                                      "vref": app.board.adc_vref, "bits": app.board.adc_bits}
    d = {
        "schema": app_schema_hash(app),
        "name": app.name,
        "sv_size": app.sv.size,
        "time_unit": app.time_unit,
        "rate": app.rate,
        "elements": [{"name": e.name, "type": e.type.name, "offset": e.offset, "region": e.region}
                     for e in app.sv.elements],
        "regions": [{"name": r.name, "offset": r.offset, "size": r.size} for r in app.sv.regions],
        "streams": streams,
        "tasks": [{"name": t.name, "kind": t.kind} for t in app.tasks],
        "writable": [e.name for e in plan.writable],
        "states": states,
        "analog": analog,
        "health_payload": plan.health_payload,
        "pyro": [p.element.name for p in app.pyro],
    }
    if app.sensors:  # only then: the layouts of applications without sensor parts are as they were
        from fswkit.autocode.sensors import sensor_name
        d["sensors"] = [sensor_name(p) for p in app.sensors]
    return from_dict(d)


def encode_value(el: Element, text: str) -> bytes:
    """The element's bytes for a value typed by a user; LayoutError with a
    clear reason when the text is not a value of the element's type."""
    t = el.type
    if t == "bool":
        v = text.strip().lower()
        if v in ("true", "1"):
            return b"\x01"
        if v in ("false", "0"):
            return b"\x00"
        raise LayoutError(f"`{el.name}` is bool: give true, false, 1 or 0, not `{text}`")
    if t in ("F32", "F64"):
        try:
            x = float(text)
        except ValueError:
            raise LayoutError(f"`{el.name}` is {t}: `{text}` is not a number") from None
        # a finite number is in range when it rounds to a finite value of the
        # type (binary32: below 2^128 - 2^103, which 3.4028235e38 is); only
        # `inf` itself stands for infinity
        limit = "±3.4028235e38" if t == "F32" else "±1.7976931348623157e308"
        literal_inf = text.strip().lstrip("+-").lower() in ("inf", "infinity")
        if math.isinf(x) and not literal_inf:
            raise LayoutError(f"`{el.name}` is {t}: {text} is out of its range ({limit}, or inf)")
        try:
            return struct.pack("<" + TYPES[t].fmt, x)
        except OverflowError:
            raise LayoutError(f"`{el.name}` is {t}: {text} is out of its range ({limit}, or inf)") from None
    try:
        v = int(text, 0)
    except ValueError:
        raise LayoutError(f"`{el.name}` is {t}: `{text}` is not a whole number") from None
    lo, hi = TYPES[t].lo, TYPES[t].hi
    if not lo <= v <= hi:
        raise LayoutError(f"`{el.name}` is {t}: {v} is outside {lo}..{hi}")
    return struct.pack("<" + TYPES[t].fmt, v)
