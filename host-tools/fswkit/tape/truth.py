"""A tape's truth worked out from the tape itself (`fsw tape truth`), by the
rules the shared flights' `.truth.toml` files follow (docs/tapes.md,
"Truth files"): liftoff at the tape's 0 s, the boost from the accelerometer,
the pad pressure, the apogee of the ISA pressure altitude smoothed over a
centered 0.5 s, the landing. A replay (`fsw sim --tape`) compares the
firmware's events with these; the recording altimeter's own events
(`recorder_*`) are the log's, not the tape's, and are not worked out here.

Each value is written with its rule as a comment, as the shared files are."""

from __future__ import annotations

import math

import numpy as np

from fswkit.tape.tape import Tape, _Errors, isa_altitude

SMOOTH_S = 0.5  # the altitude's centered moving average, by time
BOOST_G = 2.0  # the boost: a sample above this ...
BOOST_HOLD_S = 0.1  # ... that stays above it this long
BAND_M = 5.0  # the apogee's band: the span within this of the apogee
LANDED_BELOW_M = 100.0  # the landing: below this above the pad ...
LANDED_WITHIN_M = 2.0  # ... from where the altitude stays within this ...
LANDED_FOR_S = 1.0  # ... this long


# The ISA troposphere the tapes' altitudes are worked out in (docs/tapes.md; fsw tape import refuses an
# altitude beyond it), m above sea level.
ISA_LOW_M, ISA_TOP_M = -1_000.0, 11_000.0


def check_altitudes(tape: Tape) -> None:
    """TapeError at each row whose pressure is beyond the ISA troposphere
    (a recorder's glitch row, a cell in another unit): its altitude, and so
    the apogee, the band and the landing worked out from it, would be no
    flight's."""
    have = tape.available("pressure_pa")
    asl = isa_altitude(tape.pressure[have])
    rows = np.flatnonzero(have)[(asl < ISA_LOW_M) | (asl >= ISA_TOP_M)]
    if rows.size == 0:
        return
    err = _Errors(tape.path)
    pad = tape.pad_pressure()
    above = tape.altitude_agl(pad)
    for i in rows.tolist():
        where = f"row {i + 1}: " if not tape.first_line else ""
        err.at(tape.first_line + i if tape.first_line else None, None,
               f"{where}pressure_pa {tape.pressure[i]:g} is {above[i]:.0f} m above the pad, "
               f"{float(isa_altitude(tape.pressure[i])):.0f} m ASL: beyond the ISA troposphere the truth's "
               f"altitudes are worked in ({ISA_LOW_M / 1000:g} to {ISA_TOP_M / 1000:g} km ASL), so no apogee "
               "or landing could be worked out from it (a glitch row? leave its cell empty)")
    err.raise_if_any()


def smoothed_altitude(tape: Tape, pad_pa: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, altitude m above the pad): the tape's ISA altitude, a
    centered SMOOTH_S moving average by time (irregular sampling is fine),
    at the rows that have a pressure."""
    have = tape.available("pressure_pa")
    t = tape.time[have]
    h = tape.altitude_agl(pad_pa)[have]
    if t.size == 0:
        return t, h
    c = np.concatenate(([0.0], np.cumsum(h)))
    lo = np.searchsorted(t, t - SMOOTH_S / 2, side="left")
    hi = np.searchsorted(t, t + SMOOTH_S / 2, side="right")
    return t, (c[hi] - c[lo]) / (hi - lo)


def compute(tape: Tape) -> list[tuple[str, float | None, str]]:
    """The truth's values in the shared files' order: (key, value, rule); a
    value that the tape cannot give is None, its rule saying why."""
    out: list[tuple[str, float | None, str]] = [("liftoff_s", 0.0, "the tape's time base (its 0 s is liftoff)")]
    t_all = tape.time
    have_a = tape.available("accel_g")
    ta, a = t_all[have_a], tape.accel[have_a]
    boost = None
    if a.size:
        for i in np.flatnonzero(a > BOOST_G).tolist():
            j = int(np.searchsorted(ta, ta[i] + BOOST_HOLD_S, side="right"))
            if ta[j - 1] - ta[i] >= BOOST_HOLD_S - 1e-9 and (a[i:j] > BOOST_G).all():
                boost = i
                break
    if boost is None:
        why = "no accel_g" if not a.size else f"no accel_g sample above {BOOST_G:g} g for {BOOST_HOLD_S:g} s"
        out.append(("accel_over_2g_s", None, why))
        out.append(("burnout_s", None, why + ": give it (s after liftoff, the motor's burn) for `fsw sim --tape`"))
    else:
        out.append(("accel_over_2g_s", float(ta[boost]),
                    f"first sample > {BOOST_G:g} g that stays > {BOOST_G:g} g for {BOOST_HOLD_S:g} s"))
        after = np.flatnonzero(a[boost:] < 0.0)
        if after.size:
            k = boost + int(after[0])
            out.append(("burnout_s", float(ta[k]), "first sample after accel_over_2g_s with accel_g < 0 g"))
            out.append(("max_boost_accel_g", float(np.max(a[boost:k])),
                        "largest accel_g between accel_over_2g_s and burnout_s"))
        else:
            out.append(("burnout_s", None, "accel_g never below 0 g after the boost: give it (s after liftoff) "
                                           "for `fsw sim --tape`"))
    if a.size:
        m = int(np.argmax(a))
        out.append(("max_accel_g", float(a[m]), "largest accel_g sample in the whole tape"))
        out.append(("max_accel_s", float(ta[m]), ""))
    pad = tape.pad_pressure()
    if math.isnan(pad):
        out.append(("pad_pressure_pa", None, "no pressure_pa: no altitude, no apogee (`fsw sim --tape` needs it)"))
        out.append(("log_end_s", float(t_all[-1]), ""))
        return out
    before = int((tape.available("pressure_pa") & (t_all < 0)).sum())
    out.append(("pad_pressure_pa", pad, f"mean of the {before} pre-liftoff pressure sample{'s' if before != 1 else ''}" if before else
                "the first pressure sample (none before liftoff)"))
    t, h = smoothed_altitude(tape, pad)
    raw = tape.altitude_agl(pad)[tape.available("pressure_pa")]
    up = t >= 0
    if not up.any():
        out.append(("apogee_s", None, "no pressure sample after liftoff"))
        out.append(("log_end_s", float(t_all[-1]), ""))
        return out
    first = int(np.flatnonzero(up)[0])
    k = first + int(np.argmax(h[first:]))
    top = float(h[k])
    lo = k
    while lo > first and h[lo - 1] >= top - BAND_M:
        lo -= 1
    hi = k
    while hi + 1 < h.size and h[hi + 1] >= top - BAND_M:
        hi += 1
    if hi == h.size - 1:  # never came down from it: a climb the tape cut, or no flight
        out.append(("apogee_s", None, f"the tape ends at {t_all[-1]:.2f} s within {BAND_M:g} m of its highest "
                                      f"smoothed altitude ({top:.1f} m AGL at {t[k]:.2f} s): no descent from it, "
                                      "no apogee (a tape cut in the climb, or no flight)"))
        out.append(("log_end_s", float(t_all[-1]), ""))
        return out
    out.append(("apogee_s", float(t[k]), f"max of ISA pressure altitude AGL (pad = pad_pressure_pa) after a "
                                        f"centered {SMOOTH_S:g} s moving average"))
    out.append(("apogee_m_agl", top, ""))
    out.append(("apogee_band5m_from_s", float(t[lo]), f"contiguous span around apogee_s where the smoothed altitude "
                                                    f"is within {BAND_M:g} m of apogee_m_agl: how flat the top is"))
    out.append(("apogee_band5m_to_s", float(t[hi]), ""))
    out.append(("raw_max_alt_m_agl", float(np.max(raw[first:])), "unsmoothed maximum over the same samples"))
    landing = None
    for i in range(k + 1, h.size):
        if h[i] >= LANDED_BELOW_M:
            continue
        j = int(np.searchsorted(t, t[i] + LANDED_FOR_S, side="right"))
        if t[j - 1] - t[i] >= LANDED_FOR_S - 1e-9 and (np.abs(h[i:j] - h[i]) <= LANDED_WITHIN_M).all():
            landing = i
            break
    if landing is None:
        out.append(("landing_s", None, f"the tape ends at {t_all[-1]:.2f} s, {h[-1]:.1f} m AGL (smoothed), without "
                                       "coming to rest on the ground"))
    else:
        out.append(("landing_s", float(t[landing]), f"first sample after apogee, below {LANDED_BELOW_M:g} m AGL, "
                                                    f"from which the smoothed altitude stays within "
                                                    f"{LANDED_WITHIN_M:g} m for {LANDED_FOR_S:g} s"))
        out.append(("landing_alt_m_agl", float(h[landing]), ""))
    out.append(("log_end_s", float(t_all[-1]), ""))
    return out


def format_truth(name: str, tape: Tape, values: list[tuple[str, float | None, str]], source: str) -> str:
    """The `.truth.toml` text of `values` (compute's): each value with its
    rule as a comment, a value the tape cannot give as a comment alone."""
    lines = [f"# truth for {source} - worked out by `fsw tape truth` from the tape itself (docs/tapes.md)",
             "# times in s from liftoff (tape time base); altitudes m AGL via ISA: "
             "H(p) = 44330.77*(1-(p/101325)^0.190263) m",
             f"name = {_toml_str(name)}"]
    recorder = tape.flight[len("recorder "):].strip() if tape.flight.startswith("recorder ") else ""  # an import's
    if recorder:
        lines.append(f"recorder = {_toml_str(recorder)}")
    for key, v, rule in values:
        if v is None:
            lines.append(f"# no {key}: {rule}")
            continue
        digits = 1 if key.endswith(("_pa", "_m_agl")) else 3
        text = f"{key} = {round(v, digits)!r}"
        lines.append(text + (f"  # {rule}" if rule else ""))
    return "\n".join(lines) + "\n"


def _toml_str(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'
