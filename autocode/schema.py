"""The schema hash: a fingerprint of the state vector layout (and, for an
application, of what flows over the link), shared by the generated code,
the firmware's hello frame and the host decoder."""

from __future__ import annotations

import hashlib

from . import model as M


def layout_text(sv: M.StateVector) -> str:
    """A canonical description of the layout: what the hash covers."""
    lines = [f"lock {int(sv.lock)}"]
    for r in sv.regions:
        lines.append(f"region {r.name} {r.offset} {r.size}")
        lines += [f"  {e.type.name} {e.name} {e.offset}" for e in r.elements]
    return "\n".join(lines) + "\n"


def schema_hash(sv: M.StateVector, extra: str = "") -> int:
    """A 32-bit fingerprint of the layout (and `extra`)."""
    digest = hashlib.sha256((layout_text(sv) + extra).encode()).digest()
    return int.from_bytes(digest[:4], "little")
