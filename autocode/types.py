"""Element types (spec §2): each stored in its full declared width,
little-endian, on every board."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ElemType:
    name: str
    size: int  # bytes in the state vector
    kind: str  # "int", "float" or "bool"
    signed: bool = False
    lo: int = 0
    hi: int = 0

    @property
    def is_int(self) -> bool:
        return self.kind == "int"

    @property
    def is_float(self) -> bool:
        return self.kind == "float"

    @property
    def is_bool(self) -> bool:
        return self.kind == "bool"

    @property
    def fmt(self) -> str:
        """The `struct` format character of one stored value (pack it with
        a leading `<`: little-endian, no padding)."""
        if self.kind == "float":
            return "f" if self.size == 4 else "d"
        c = {1: "b", 2: "h", 4: "i", 8: "q"}[self.size]
        return c if self.signed else c.upper()

    def __str__(self) -> str:
        return self.name


def _int(name: str, bits: int, signed: bool) -> ElemType:
    lo = -(1 << (bits - 1)) if signed else 0
    hi = (1 << (bits - 1)) - 1 if signed else (1 << bits) - 1
    return ElemType(name, bits // 8, "int", signed, lo, hi)


TYPES: dict[str, ElemType] = {
    t.name: t
    for t in (
        _int("I8", 8, True), _int("I16", 16, True), _int("I32", 32, True), _int("I64", 64, True),
        _int("U8", 8, False), _int("U16", 16, False), _int("U32", 32, False), _int("U64", 64, False),
        ElemType("F32", 4, "float"), ElemType("F64", 8, "float"), ElemType("bool", 1, "bool", lo=0, hi=1),
    )
}
U64 = TYPES["U64"]
U32 = TYPES["U32"]
U8 = TYPES["U8"]
