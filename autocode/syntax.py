"""The syntax tree the parsers produce: names are still strings, nothing
is resolved. The checker turns it into the typed model (model.py)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Union


# ---- expressions -----------------------------------------------------------

@dataclass(frozen=True)
class Num:
    line: int
    col: int
    text: str


@dataclass(frozen=True)
class Bool:
    line: int
    col: int
    value: bool


@dataclass(frozen=True)
class Name:
    line: int
    col: int
    name: str


@dataclass(frozen=True)
class Unary:
    line: int
    col: int
    op: str  # "-", "not", "!"
    operand: "Expr"


@dataclass(frozen=True)
class Binary:
    line: int
    col: int  # the first token of the left operand
    op: str  # * / + - < <= > >= == != and or
    left: "Expr"
    right: "Expr"
    op_col: int = 0


@dataclass(frozen=True)
class Chain:
    """A run of two or more relational operators: `a < b <= c`."""
    line: int
    col: int
    operands: tuple["Expr", ...]
    ops: tuple[str, ...]


@dataclass(frozen=True)
class Call:
    line: int
    col: int
    func: str
    args: tuple["Expr", ...]


Expr = Union[Num, Bool, Name, Unary, Binary, Chain, Call]

RELATIONAL = ("<", "<=", ">", ">=")


# ---- state machine statements ---------------------------------------------

@dataclass(frozen=True)
class Assign:
    line: int
    col: int
    target: str
    expr: Expr


@dataclass(frozen=True)
class Transition:
    line: int
    col: int
    target: str
    target_col: int


@dataclass(frozen=True)
class If:
    line: int
    col: int
    cond: Expr
    body: tuple["Stmt", ...]
    orelse: tuple["Stmt", ...] | None = None  # None: no else
    braced: bool = False
    else_braced: bool = False


Stmt = Union[Assign, Transition, If]


# ---- state script statements ----------------------------------------------

@dataclass(frozen=True)
class Assert:
    line: int
    col: int
    expr: Expr


@dataclass(frozen=True)
class Stop:
    line: int
    col: int


@dataclass(frozen=True)
class Guarded:
    line: int
    col: int
    cond: Expr
    body: tuple[Union[Assign, Assert, Stop], ...]
    braced: bool = False


# ---- files -----------------------------------------------------------------

@dataclass(frozen=True)
class Header:
    line: int
    col: int
    name: str


@dataclass(frozen=True)
class ElemDecl:
    line: int
    type_col: int
    type: str
    name_col: int
    name: str


@dataclass(frozen=True)
class RegionDecl:
    header: Header
    elements: tuple[ElemDecl, ...]
    lines: int = 0  # non-blank lines in the section, well-formed or not


@dataclass(frozen=True)
class Option:
    line: int
    col: int
    name: str
    args: tuple  # tokens after the name


@dataclass(frozen=True)
class SvFile:
    path: str
    options: tuple[Option, ...]
    regions: tuple[RegionDecl, ...]


@dataclass(frozen=True)
class SmElem:
    line: int
    type_col: int
    type: str
    name_col: int
    name: str
    read_only: bool
    alias: str | None
    alias_col: int = 0


@dataclass(frozen=True)
class LocalDecl:
    line: int
    type_col: int
    type: str
    name_col: int
    name: str
    expr: Expr
    read_only: bool


@dataclass(frozen=True)
class ParamDecl:
    """A `[parameters]` line: `TYPE name = default`, then `@min`, `@max`,
    `@unit`, `@when` in any order (docs/parameters.md)."""
    line: int
    type_col: int
    type: str
    name_col: int
    name: str
    expr: Expr
    min: Expr | None
    max: Expr | None
    unit: str
    when: tuple[tuple[str, int], ...]  # (state name, column)
    when_col: int  # column of `@when` (0: none)
    annot_cols: tuple[tuple[str, int], ...] = ()  # (annotation, column) as written


@dataclass(frozen=True)
class Block:
    line: int
    col: int
    label: str  # "entry", "step", "exit"
    stmts: tuple[Stmt, ...]


@dataclass(frozen=True)
class StateDecl:
    header: Header
    blocks: tuple[Block, ...]


@dataclass(frozen=True)
class SmFile:
    path: str
    elements: tuple[SmElem, ...]
    locals: tuple[LocalDecl, ...]
    states: tuple[StateDecl, ...]
    sv_header: Header | None = None
    local_header: Header | None = None
    params: tuple[ParamDecl, ...] = ()
    param_header: Header | None = None
    broken: tuple[str, ...] = ()  # locals and parameters whose line was malformed after the name


@dataclass(frozen=True)
class ScriptSection:
    header: Header  # name "all_states" for an [all_states] section
    stmts: tuple[Guarded, ...]


@dataclass(frozen=True)
class ScriptParam:
    """A script's `[parameters]` line: `NAME = value`."""
    line: int
    col: int
    name: str
    expr: Expr
    expr_col: int


@dataclass(frozen=True)
class SsFile:
    path: str
    options: tuple[Option, ...]
    sections: tuple[ScriptSection, ...]
    params: tuple[ScriptParam, ...] = ()
