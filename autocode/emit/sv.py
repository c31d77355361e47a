"""The state vector as C++: `sv.gen.h` (element and region offsets, the
schema hash) and `sv.gen.cpp` (the bytes)."""

from __future__ import annotations

from .. import model as M
from ..schema import schema_hash
from .common import banner, version_check


def emit_sv(sv: M.StateVector, ns: str = "fsw_gen") -> dict[str, str]:
    """`sv.gen.h`/`sv.gen.cpp` in namespace `ns` (another `ns` lets several
    generated projects share one program, as the differential tests do)."""
    guard = f"{ns.upper()}_SV_H"
    h = [banner([sv.path], sv), f"#ifndef {guard}", f"#define {guard}", "",
         '#include "fswkit.h"', "", f"namespace {ns} {{", "",
         f"// The state vector: {len(sv.regions)} regions, {sv.size} bytes, packed, little-endian.",
         f"static const uint16_t kSvSize = {max(sv.size, 1)};",
         f"static const uint32_t kSchemaHash = 0x{schema_hash(sv):08x}UL;",
         f"static const bool kSvLock = {'true' if sv.lock else 'false'};",
         "extern uint8_t sv[kSvSize];", "",
         "// Element offsets (bytes from the start of the state vector)."]
    h.append("enum : uint16_t {")
    for e in sv.elements:
        h.append(f"    E_{e.name} = {e.offset},  // {e.type.name}, region {e.region}")
    h.append("};")
    h.append("")
    h.append("// Regions: offset and size in bytes.")
    h.append("enum : uint16_t {")
    for r in sv.regions:
        h.append(f"    R_{r.name}_off = {r.offset}, R_{r.name}_size = {r.size},")
    h.append("};")
    h += ["", f"}}  // namespace {ns}", "", f"#endif  // {guard}", ""]
    c = [banner([sv.path], sv), '#include "sv.gen.h"', "", version_check("sv.gen.cpp"),
         f"static_assert({ns}::kSvSize == {max(sv.size, 1)}, \"state vector size\");", "",
         f"namespace {ns} {{", "", "uint8_t sv[kSvSize];  // every element starts at zero", "",
         f"}}  // namespace {ns}", ""]
    return {"sv.gen.h": "\n".join(h), "sv.gen.cpp": "\n".join(c)}
