"""Parsers for `.sv`, `.sm` and `.ss` (spec §3–§5): tokens to syntax tree.

Every syntax error is reported with its location and parsing resumes at the
next line, so one run reports every independent error. Nesting is bounded
(`MAX_NESTING`) so no input can exhaust the stack."""

from __future__ import annotations

import math

from .diagnostics import SM, SS, SV, Diagnostics, Source
from .lexer import ANNOT, EOF, ID, KW, LABEL, NL, NUM, OP, Tok, lex
from . import memo
from . import syntax as S

MAX_NESTING = 64  # parentheses, unary operators, nested guards and braces
MAX_DEPTH = 200  # depth of one expression tree
_REL = 4
_LEVELS = {"or": 1, "and": 2, "==": 3, "!=": 3, **{op: _REL for op in S.RELATIONAL}, "+": 5, "-": 5, "*": 6, "/": 6}
FUNCTIONS = ("roll_avg", "roll_median", "roll_min", "roll_max", "roll_range")


class ParseError(Exception):
    def __init__(self, tok: Tok, message: str):
        super().__init__(message)
        self.line, self.col, self.message = tok.line, tok.col, message


def show(t: Tok) -> str:
    if t.kind == NL:
        return "end of line"
    if t.kind == EOF:
        return "end of section"
    return f"`{t.text}`"


# ---- sections --------------------------------------------------------------

def split_sections(src: Source, lines: list[list[Tok]], diags: Diagnostics, lang: str):
    """Splits a file's lines at `[Name]` headers. Returns the non-empty lines
    before the first header and a list of (Header, lines)."""
    pre: list[list[Tok]] = []
    sections: list[tuple[S.Header, list[list[Tok]]]] = []
    for toks in lines:
        if not toks:
            continue
        first = toks[0]
        if first.kind == OP and first.text == "[":
            if (len(toks) == 3 and toks[1].kind in (ID, KW) and toks[2].kind == OP
                    and toks[2].text == "]"):
                sections.append((S.Header(first.line, first.col, toks[1].text), []))
            else:
                diags.error(src, lang, first.line, first.col,
                            "malformed section header: expected `[Name]` alone on its line")
                sections.append((S.Header(first.line, first.col, "<malformed>"), []))
            continue
        (sections[-1][1] if sections else pre).append(toks)
    return pre, sections


def stream(lines: list[list[Tok]]) -> list[Tok]:
    """The tokens of several lines, each line ended by a NL token, then EOF."""
    out: list[Tok] = []
    for toks in lines:
        out.extend(toks)
        last = toks[-1]
        out.append(Tok(NL, "", last.line, last.col + len(last.text)))
    if out:
        out.append(Tok(EOF, "", out[-1].line, out[-1].col))
    else:
        out.append(Tok(EOF, "", 0, 1))
    return out


# ---- expressions and statements ---------------------------------------------

class Parser:
    """Recursive descent over one token stream. The current token is
    self.toks[self.i]: the stream ends with EOF, which `next` never passes."""

    def __init__(self, toks: list[Tok], src: Source, diags: Diagnostics, lang: str):
        self.toks = toks
        self.i = 0
        self.src = src
        self.diags = diags
        self.lang = lang
        self.nesting = 0

    # -- helpers
    def peek(self, k: int = 0) -> Tok:
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else self.toks[-1]

    def next(self) -> Tok:
        t = self.toks[self.i]
        if t.kind != EOF:
            self.i += 1
        return t

    def at_op(self, text: str) -> bool:
        t = self.toks[self.i]
        return t.kind == OP and t.text == text

    def at_kw(self, text: str) -> bool:
        t = self.toks[self.i]
        return t.kind == KW and t.text == text

    def expect_op(self, text: str, what: str | None = None) -> Tok:
        t = self.peek()
        if t.kind == OP and t.text == text:
            return self.next()
        raise ParseError(t, f"expected `{text}`{what or ''}, found {show(t)}")

    def at_end(self) -> bool:
        return self.peek().kind in (NL, EOF)

    def end_of_statement(self, what: str) -> None:
        t = self.toks[self.i]
        if t.kind in (NL, EOF) or (t.kind == OP and t.text == "}"):
            return
        raise ParseError(t, f"unexpected {show(t)} after {what}")

    def skip_newlines(self) -> None:
        toks, i = self.toks, self.i
        while toks[i].kind == NL:
            i += 1
        self.i = i

    def enter(self, t: Tok) -> None:
        self.nesting += 1
        if self.nesting > MAX_NESTING:
            raise ParseError(t, f"nested too deeply (more than {MAX_NESTING} levels of guards, "
                                "parentheses and unary operators)")

    def resync(self) -> None:
        """Skips the rest of a bad line, and the body of any `{` opened on it."""
        depth = 0
        while True:
            t = self.peek()
            if t.kind == EOF:
                return
            if t.kind == LABEL and self.lang == SM and self.toks[self.i - 1].kind == NL:
                return  # a label opens the next block, even inside an unclosed `{`
            if t.kind == OP and t.text == "{":
                depth += 1
            elif t.kind == OP and t.text == "}":
                if depth == 0:
                    return
                depth -= 1
            elif t.kind == NL and depth == 0:
                self.i += 1
                return
            self.i += 1

    def report(self, e: ParseError) -> None:
        self.diags.error(self.src, self.lang, e.line, e.col, e.message)

    # -- expressions
    def expression(self) -> S.Expr:
        start = self.i
        e = self.or_expr()
        # every level of a tree has a token of its own: fewer tokens, no deeper tree
        if self.i - start > MAX_DEPTH and tree_depth(e) > MAX_DEPTH:
            raise ParseError(Tok(OP, "", e.line, e.col),
                             f"expression is nested too deeply (more than {MAX_DEPTH} levels of operators)")
        return e

    # The binary operators by precedence climbing: one call a level of the
    # tree rather than one a level of the grammar. Levels, loosest first:
    # or, and, == !=, the relational chain, + -, * /; all left-associative,
    # a run of relational operators one node (S.Chain). The current token is
    # read as self.toks[self.i]: the stream ends with EOF, which `next`
    # never passes. Only operators and keywords have these texts.
    def or_expr(self) -> S.Expr:
        return self.binary(1)

    def binary(self, min_level: int) -> S.Expr:
        left = self.unary()
        toks = self.toks
        levels = _LEVELS
        while True:
            t = toks[self.i]
            level = levels.get(t.text)
            if level is None or level < min_level:
                return left
            self.i += 1
            if level != _REL:
                left = S.Binary(left.line, left.col, t.text, left, self.binary(level + 1), t.col)
                continue
            operands, ops, cols = [left, self.binary(_REL + 1)], [t.text], [t.col]
            t = toks[self.i]
            while levels.get(t.text) == _REL:
                self.i += 1
                ops.append(t.text)
                cols.append(t.col)
                operands.append(self.binary(_REL + 1))
                t = toks[self.i]
            if len(ops) == 1:
                left = S.Binary(left.line, left.col, ops[0], left, operands[1], cols[0])
            else:
                left = S.Chain(left.line, left.col, tuple(operands), tuple(ops))

    def unary(self) -> S.Expr:
        t = self.toks[self.i]
        if (t.kind == OP and t.text in ("-", "!")) or (t.kind == KW and t.text == "not"):
            self.next()
            self.enter(t)
            operand = self.unary()
            self.nesting -= 1
            return S.Unary(t.line, t.col, t.text, operand)
        return self.primary()

    def primary(self) -> S.Expr:
        t = self.toks[self.i]
        if t.kind == ID:
            self.i += 1
            if self.toks[self.i].text == "(":  # only an operator has this text
                self.enter(self.toks[self.i])
                self.i += 1
                args = []
                if not self.at_op(")"):
                    args.append(self.expression())
                    while self.at_op(","):
                        self.next()
                        args.append(self.expression())
                self.expect_op(")", " to close the argument list")
                self.nesting -= 1
                return S.Call(t.line, t.col, t.text, tuple(args))
            return S.Name(t.line, t.col, t.text)
        if t.kind == NUM:
            self.i += 1
            if float(t.text) == math.inf:  # every literal must be a finite binary64 (401 digits is not)
                raise ParseError(t, "number is outside the representable range")
            return S.Num(t.line, t.col, t.text)
        if t.kind == KW and t.text in ("true", "false"):
            self.i += 1
            return S.Bool(t.line, t.col, t.text == "true")
        if t.kind == OP and t.text == "(":
            self.next()
            self.enter(t)
            e = self.or_expr()
            self.expect_op(")", " to close `(`")
            self.nesting -= 1
            return e
        if t.kind in (NL, EOF):
            raise ParseError(t, "expected an expression")
        raise ParseError(t, f"expected an expression, found {show(t)}")

    # -- state machine statements
    def sm_block(self, first: Tok | None = None) -> tuple[S.Stmt, ...]:
        """Statements up to the next label or the end of the section."""
        out: list[S.Stmt] = []
        while True:
            self.skip_newlines()
            t = self.toks[self.i]
            if t.kind in (EOF, LABEL):
                return tuple(out)
            if t.kind == OP and t.text == "}":
                self.report(ParseError(t, "unmatched `}`"))
                self.next()
                continue
            saved = self.nesting
            try:
                out.append(self.sm_statement())
                self.end_of_statement("the statement")
            except ParseError as e:
                self.nesting = saved
                self.report(e)
                self.resync()

    def sm_statement(self) -> S.Stmt:
        t = self.toks[self.i]
        if t.kind == OP and t.text == "->":
            self.next()
            target = self.peek()
            if target.kind != ID:
                raise ParseError(target, f"expected a state name after `->`, found {show(target)}")
            self.next()
            nxt = self.peek()
            if not (nxt.kind in (NL, EOF) or (nxt.kind == OP and nxt.text == "}")):
                raise ParseError(nxt, "nothing may follow a transition on its line")
            return S.Transition(t.line, t.col, target.text, target.col)
        # An ID is never the last token, and only an operator's text is `=`.
        if t.kind == ID and self.toks[self.i + 1].text == "=":
            self.i += 2
            if self.at_end():
                raise ParseError(self.peek(), "expected an expression")
            return S.Assign(t.line, t.col, t.text, self.expression())
        if t.kind == KW and t.text == "else":
            raise ParseError(t, "`else` without a matching `if`")
        if t.kind == ANNOT:
            raise ParseError(t, f"`{t.text}` is not allowed in a state machine block")
        if t.kind == KW and t.text == "if":
            self.next()
        self.enter(t)
        try:
            cond = self.expression()
            body, braced = self.sm_guarded_body()
            orelse, else_braced = self.sm_else()
        finally:
            self.nesting -= 1
        return S.If(t.line, t.col, cond, body, orelse, braced, else_braced)

    def sm_guarded_body(self) -> tuple[tuple[S.Stmt, ...], bool]:
        t = self.toks[self.i]
        if t.kind == OP and t.text == ":":
            self.next()
            if self.at_end():
                raise ParseError(self.peek(), "expected a statement after `:`")
            return (self.sm_statement(),), False
        if self.brace_ahead():
            return self.sm_braced(), True
        raise ParseError(t, f"expected `:` or `{{` after the condition, found {show(t)}")

    def brace_ahead(self) -> bool:
        """True at `{`, or at line ends followed by `{` (which is consumed up to)."""
        j = self.i
        while self.toks[j].kind == NL:
            j += 1
        t = self.toks[j]
        if t.kind == OP and t.text == "{":
            self.i = j
            return True
        return False

    def sm_braced(self) -> tuple[S.Stmt, ...]:
        open_ = self.next()  # "{"; its `if` already counts as a level of nesting
        out: list[S.Stmt] = []
        while True:
            self.skip_newlines()
            t = self.toks[self.i]
            if t.kind == OP and t.text == "}":
                self.next()
                return tuple(out)
            if t.kind in (EOF, LABEL):
                raise ParseError(open_, "unclosed `{`")
            saved = self.nesting
            try:
                out.append(self.sm_statement())
                self.end_of_statement("the statement")
            except ParseError as e:
                self.nesting = saved
                self.report(e)
                self.resync()

    def sm_else(self) -> tuple[tuple[S.Stmt, ...] | None, bool]:
        j = self.i
        while self.toks[j].kind == NL:
            j += 1
        t = self.toks[j]
        if not (t.kind == KW and t.text == "else"):
            return None, False
        self.i = j + 1
        nxt = self.peek()
        if nxt.kind == OP and nxt.text == ":":
            self.next()
            if self.at_end():
                # `else:` then `if` on the next line chains like `else` then `if`.
                j = self.i
                while self.toks[j].kind == NL:
                    j += 1
                if self.toks[j].kind == KW and self.toks[j].text == "if":
                    self.i = j
                    return (self.sm_statement(),), False
            if self.at_end() or self.at_op("}"):
                raise ParseError(t, "expected logic after else")
            return (self.sm_statement(),), False
        if nxt.kind == KW and nxt.text == "if":
            return (self.sm_statement(),), False
        if self.brace_ahead():
            open_ = self.i
            body = self.sm_braced()
            if all(k.kind == NL for k in self.toks[open_ + 1:self.i - 1]):  # `else { }`: no statement inside
                raise ParseError(t, "expected logic after else")
            return body, True
        if nxt.kind in (NL, EOF) or (nxt.kind == OP and nxt.text == "}"):
            # `else` then `if` on the next line chains too.
            j = self.i
            while self.toks[j].kind == NL:
                j += 1
            if self.toks[j].kind == KW and self.toks[j].text == "if":
                self.i = j
                return (self.sm_statement(),), False
            raise ParseError(t, "expected logic after else")
        raise ParseError(nxt, f"expected `:`, `{{` or `if` after `else`, found {show(nxt)}")

    # -- state script statements
    def ss_statements(self) -> tuple[S.Guarded, ...]:
        out: list[S.Guarded] = []
        while True:
            self.skip_newlines()
            t = self.peek()
            if t.kind == EOF:
                return tuple(out)
            self.nesting = 0
            try:
                out.append(self.ss_guarded())
                self.end_of_statement("the statement")
            except ParseError as e:
                self.report(e)
                self.resync()

    def ss_guarded(self) -> S.Guarded:
        t = self.peek()
        if t.kind == KW and t.text == "else":
            raise ParseError(t, "`else` is not allowed in a state script")
        if t.kind == ANNOT or (t.kind == ID and self.peek(1).kind == OP and self.peek(1).text == "="):
            raise ParseError(t, "every statement of a state script needs a guard (`cond: statement`)")
        if t.kind == OP and t.text == "->":
            raise ParseError(t, "transitions are not allowed in a state script")
        if t.kind == OP and t.text == "}":
            self.next()
            raise ParseError(t, "unmatched `}`")
        if t.kind == KW and t.text == "if":
            self.next()
        cond = self.expression()
        nxt = self.peek()
        if nxt.kind == OP and nxt.text == ":":
            self.next()
            if self.at_end():
                raise ParseError(self.peek(), "expected a statement after `:`")
            body = (self.ss_statement(),)
            self.check_else()
            return S.Guarded(t.line, t.col, cond, body, False)
        if self.brace_ahead():
            open_ = self.next()
            body = []
            while True:
                self.skip_newlines()
                b = self.peek()
                if b.kind == OP and b.text == "}":
                    self.next()
                    break
                if b.kind == EOF:
                    raise ParseError(open_, "unclosed `{`")
                try:
                    body.append(self.ss_statement())
                    self.end_of_statement("the statement")
                except ParseError as e:
                    self.report(e)
                    self.resync()
            self.check_else()
            stop = next((s for s in body if isinstance(s, S.Stop)), None)
            if stop is not None and body[-1] is not stop:
                after = body[body.index(stop) + 1]
                self.report(ParseError(Tok(OP, "", after.line, after.col),
                                       "nothing may follow `@stop` in its guard"))
            return S.Guarded(t.line, t.col, cond, tuple(body), True)
        raise ParseError(nxt, f"expected `:` or `{{` after the condition, found {show(nxt)}")

    def check_else(self) -> None:
        j = self.i
        while self.toks[j].kind == NL:
            j += 1
        t = self.toks[j]
        if t.kind == KW and t.text == "else":
            self.i = j
            raise ParseError(t, "`else` is not allowed in a state script")

    def ss_statement(self):
        t = self.peek()
        if t.kind == ANNOT and t.text == "@stop":
            self.next()
            nxt = self.peek()
            if not (nxt.kind in (NL, EOF) or (nxt.kind == OP and nxt.text == "}")):
                raise ParseError(nxt, "nothing may follow `@stop` in its guard")
            return S.Stop(t.line, t.col)
        if t.kind == ANNOT and t.text == "@assert":
            self.next()
            if self.at_end():
                raise ParseError(self.peek(), "expected an expression after `@assert`")
            return S.Assert(t.line, t.col, self.expression())
        if t.kind == ANNOT:
            raise ParseError(t, f"`{t.text}` is not allowed in a state script statement")
        if t.kind == ID and self.peek(1).kind == OP and self.peek(1).text == "=":
            self.next()
            self.next()
            if self.at_end():
                raise ParseError(self.peek(), "expected an expression")
            return S.Assign(t.line, t.col, t.text, self.expression())
        if t.kind == OP and t.text == "->":
            raise ParseError(t, "transitions are not allowed in a state script")
        raise ParseError(t, "guards do not nest in a state script: expected an input, "
                            "`@assert` or `@stop`")


def tree_depth(e: S.Expr) -> int:
    """Depth of an expression tree, without recursion."""
    best = 0
    todo = [(e, 1)]
    while todo:
        node, d = todo.pop()
        if d > best:
            best = d
        if isinstance(node, S.Binary):
            todo.append((node.left, d + 1))
            todo.append((node.right, d + 1))
        elif isinstance(node, S.Unary):
            todo.append((node.operand, d + 1))
        elif isinstance(node, (S.Chain,)):
            todo.extend((o, d + 1) for o in node.operands)
        elif isinstance(node, S.Call):
            todo.extend((a, d + 1) for a in node.args)
    return best


# ---- files -----------------------------------------------------------------

def _line_parser(toks: list[Tok], src, diags, lang) -> Parser:
    return Parser(stream([toks]), src, diags, lang)


def _whole_expression(toks: list[Tok], src, diags, lang, what: str) -> S.Expr | None:
    """The expression `toks` hold, with nothing after it (`unexpected X
    after WHAT`); None after reporting."""
    p = _line_parser(toks, src, diags, lang)
    try:
        e = p.expression()
        if not p.at_end():
            t = p.peek()
            raise ParseError(t, f"unexpected {show(t)} after {what}")
    except ParseError as err:
        p.report(err)
        return None
    return e


def parse_sv(src: Source, diags: Diagnostics) -> S.SvFile:
    return memo.run(("parse_sv", src.path, src.text), (), diags, lambda d: _parse_sv(src, d))


def _parse_sv(src: Source, diags: Diagnostics) -> S.SvFile:
    lang = SV
    lines = lex(src, diags, lang)
    pre, sections = split_sections(src, lines, diags, lang)
    for toks in pre:
        t = toks[0]
        if len(toks) >= 2 and t.kind == ID and toks[1].kind == ID:
            diags.error(src, lang, t.line, toks[1].col,
                        f"element `{toks[1].text}` declared before any region")
        else:
            diags.error(src, lang, t.line, t.col, f"unexpected {show(t)} before the first region")
    options: list[S.Option] = []
    regions: list[S.RegionDecl] = []
    for header, body in sections:
        if header.name == "options":
            options.extend(_options(body))
            continue
        elems = []
        for toks in body:
            d = _elem_decl(toks, src, diags, lang)
            if d is not None:
                elems.append(d)
        regions.append(S.RegionDecl(header, tuple(elems), len(body)))
    return S.SvFile(src.path, tuple(options), tuple(regions))


def _options(body: list[list[Tok]]) -> list[S.Option]:
    return [S.Option(t[0].line, t[0].col, t[0].text, tuple(t[1:])) for t in body]


def _elem_decl(toks: list[Tok], src, diags, lang) -> S.ElemDecl | None:
    """`TYPE name`; returns None after reporting a malformed line."""
    t = toks[0]
    if t.kind != ID:
        diags.error(src, lang, t.line, t.col, f"expected an element type, found {show(t)}")
        return None
    if len(toks) < 2 or toks[1].kind != ID:
        found = show(toks[1]) if len(toks) >= 2 else "end of line"
        col = toks[1].col if len(toks) >= 2 else t.col + len(t.text)
        diags.error(src, lang, t.line, col, f"expected an element name after `{t.text}`, found {found}")
        return None
    if len(toks) > 2:
        diags.error(src, lang, t.line, toks[2].col, f"unexpected {show(toks[2])} after the element name")
    return S.ElemDecl(t.line, t.col, t.text, toks[1].col, toks[1].text)


def parse_sm(src: Source, diags: Diagnostics) -> S.SmFile:
    return memo.run(("parse_sm", src.path, src.text), (), diags, lambda d: _parse_sm(src, d))


def _parse_sm(src: Source, diags: Diagnostics) -> S.SmFile:
    lang = SM
    lines = lex(src, diags, lang)
    pre, sections = split_sections(src, lines, diags, lang)
    for toks in pre:
        t = toks[0]
        diags.error(src, lang, t.line, t.col, f"unexpected {show(t)} before the first section")
    elements: list[S.SmElem] = []
    locals_: list[S.LocalDecl] = []
    states: list[S.StateDecl] = []
    params: list[S.ParamDecl] = []
    broken: list[str] = []  # names whose declaring line was malformed after the name
    sv_header = local_header = param_header = None
    for header, body in sections:
        name = header.name
        if name == "parameters":
            if param_header is not None:
                diags.error(src, lang, header.line, header.col + 1,
                            f"duplicate `[parameters]` section (previously on line {param_header.line})")
            elif states:
                diags.error(src, lang, header.line, header.col + 1, "`[parameters]` must come before the first state")
            param_header = param_header or header
            for toks in body:
                d = _param_decl(toks, src, diags, lang)
                if d is not None:
                    params.append(d)
                else:
                    broken.extend(_declared_name(toks))
            continue
        if name == "state_vector" or name == "local":
            prev = sv_header if name == "state_vector" else local_header
            if prev is not None:
                diags.error(src, lang, header.line, header.col + 1,
                            f"duplicate `[{name}]` section (previously on line {prev.line})")
            elif states:
                diags.error(src, lang, header.line, header.col + 1,
                            f"`[{name}]` must come before the first state")
            if name == "state_vector":
                sv_header = sv_header or header
                for toks in body:
                    e = _sm_elem(toks, src, diags, lang)
                    if e is not None:
                        elements.append(e)
            else:
                local_header = local_header or header
                for toks in body:
                    d = _local_decl(toks, src, diags, lang)
                    if d is not None:
                        locals_.append(d)
                    else:
                        broken.extend(_declared_name(toks))
            continue
        if name in ("all_states", "options"):
            diags.error(src, lang, header.line, header.col + 1,
                        f"`[{name}]` is reserved and not allowed in a state machine config")
            continue
        if name == "<malformed>":
            continue
        states.append(S.StateDecl(header, _state_blocks(body, src, diags, lang)))
    return S.SmFile(src.path, tuple(elements), tuple(locals_), tuple(states), sv_header, local_header,
                    tuple(params), param_header, tuple(broken))


def _declared_name(toks: list[Tok]) -> list[str]:
    """The name a malformed `TYPE name ...` line declares, if it got that
    far: its uses are not reported again as unknown names."""
    return [toks[1].text] if len(toks) > 1 and toks[0].kind == ID and toks[1].kind == ID else []


def _sm_elem(toks: list[Tok], src, diags, lang) -> S.SmElem | None:
    d = _elem_decl(toks[:2], src, diags, lang)
    if d is None:
        return None
    read_only = False
    alias = None
    alias_col = 0
    i = 2
    while i < len(toks):
        t = toks[i]
        if t.kind == ANNOT and t.text == "@read_only":
            if read_only:
                diags.error(src, lang, t.line, t.col, "redundant read-only annotation")
            read_only = True
            i += 1
        elif t.kind == ANNOT and t.text == "@alias":
            if i + 1 >= len(toks) or toks[i + 1].kind != ID:
                found = show(toks[i + 1]) if i + 1 < len(toks) else "end of line"
                col = toks[i + 1].col if i + 1 < len(toks) else t.col + len(t.text)
                diags.error(src, lang, t.line, col, f"expected a name after `@alias`, found {found}")
                return S.SmElem(d.line, d.type_col, d.type, d.name_col, d.name, read_only, alias, alias_col)
            if alias is not None:
                diags.error(src, lang, t.line, t.col, f"element `{d.name}` already has an alias (`{alias}`)")
            elif toks[i + 1].text == d.name:
                diags.error(src, lang, t.line, toks[i + 1].col, f"`@alias {d.name}` is the element's own name: an "
                            "alias is another name for it (remove the `@alias`, or give one)")
            else:
                alias, alias_col = toks[i + 1].text, toks[i + 1].col
            i += 2
        else:
            diags.error(src, lang, t.line, t.col,
                        f"unexpected {show(t)}: expected `@read_only` or `@alias NAME`")
            return S.SmElem(d.line, d.type_col, d.type, d.name_col, d.name, read_only, alias, alias_col)
    return S.SmElem(d.line, d.type_col, d.type, d.name_col, d.name, read_only, alias, alias_col)


def _assigned_decl(toks: list[Tok], src, diags, lang, what: str) -> S.ElemDecl | None:
    """`TYPE name =` at the head of a local's or a parameter's line; None
    after reporting a malformed one."""
    d = _elem_decl(toks[:2], src, diags, lang)
    if d is None:
        return None
    if len(toks) < 3 or not (toks[2].kind == OP and toks[2].text == "="):
        found = show(toks[2]) if len(toks) > 2 else "end of line"
        col = toks[2].col if len(toks) > 2 else toks[1].col + len(toks[1].text)
        diags.error(src, lang, d.line, col, f"expected `= {what}` after `{d.name}`, found {found}")
        return None
    return d


def _local_decl(toks: list[Tok], src, diags, lang) -> S.LocalDecl | None:
    d = _assigned_decl(toks, src, diags, lang, "initial value")
    if d is None:
        return None
    rest = toks[3:]
    read_only = False
    if rest and rest[-1].kind == ANNOT and rest[-1].text == "@read_only":
        read_only = True
        rest = rest[:-1]
        if rest and rest[-1].kind == ANNOT and rest[-1].text == "@read_only":
            diags.error(src, lang, rest[-1].line, rest[-1].col, "redundant read-only annotation")
            rest = rest[:-1]
    if not rest:
        t = toks[2]
        diags.error(src, lang, t.line, t.col + 1, "expected an expression")
        return None
    expr = _whole_expression(rest, src, diags, lang, "the initial value")
    if expr is None:
        return None
    return S.LocalDecl(d.line, d.type_col, d.type, d.name_col, d.name, expr, read_only)


PARAM_ANNOTS = ("@min", "@max", "@unit", "@when")


def _param_decl(toks: list[Tok], src, diags, lang) -> S.ParamDecl | None:
    """`TYPE name = default [@min E] [@max E] [@unit TEXT] [@when STATE...]`."""
    d = _assigned_decl(toks, src, diags, lang, "default value")
    if d is None:
        return None
    # split at the annotations: the default, then each annotation's tokens
    parts: list[tuple[Tok | None, list[Tok]]] = [(None, [])]
    for t in toks[3:]:
        if t.kind == ANNOT:
            parts.append((t, []))
        else:
            parts[-1][1].append(t)

    def expr_of(what: str, at: Tok, ts: list[Tok]) -> S.Expr | None:
        if not ts:
            diags.error(src, lang, at.line, at.col + len(at.text), f"expected {what}")
            return None
        return _whole_expression(ts, src, diags, lang, what)

    default = expr_of("a default value", toks[2], parts[0][1])
    if default is None:
        return None
    lo = hi = None
    unit = ""
    when: list[tuple[str, int]] = []
    when_col = 0
    seen: dict[str, int] = {}
    ok = True
    for at, ts in parts[1:]:
        if at.text not in PARAM_ANNOTS:
            diags.error(src, lang, at.line, at.col,
                        f"unexpected `{at.text}`: a parameter takes `@min`, `@max`, `@unit` and `@when`")
            ok = False
            continue
        if at.text in seen:
            diags.error(src, lang, at.line, at.col, f"`{at.text}` given twice for `{d.name}`")
            ok = False
            continue
        seen[at.text] = at.col
        if at.text == "@min":
            lo = expr_of("a minimum after `@min`", at, ts)
            ok = ok and lo is not None
        elif at.text == "@max":
            hi = expr_of("a maximum after `@max`", at, ts)
            ok = ok and hi is not None
        elif at.text == "@unit":
            if not ts:
                diags.error(src, lang, at.line, at.col + len(at.text), "expected a unit after `@unit`")
                ok = False
            unit = "".join(t.text for t in ts)
        else:
            when_col = at.col
            if not ts:
                diags.error(src, lang, at.line, at.col + len(at.text), "expected state names after `@when`")
                ok = False
            for t in ts:
                if t.kind != ID:
                    diags.error(src, lang, t.line, t.col, f"expected a state name after `@when`, found {show(t)}")
                    ok = False
                    break
                when.append((t.text, t.col))
    if not ok:
        return None
    return S.ParamDecl(d.line, d.type_col, d.type, d.name_col, d.name, default, lo, hi, unit, tuple(when), when_col,
                       tuple(seen.items()))


LABELS = ("entry", "step", "exit")


def _state_blocks(body: list[list[Tok]], src, diags, lang) -> tuple[S.Block, ...]:
    p = Parser(stream(body), src, diags, lang)
    blocks: list[S.Block] = []
    seen: dict[str, int] = {}
    reported_text = False
    while True:
        p.skip_newlines()
        t = p.peek()
        if t.kind == EOF:
            break
        if t.kind != LABEL:
            if not reported_text:
                diags.error(src, lang, t.line, t.col,
                            "text before the first label: expected `.entry`, `.step` or `.exit`")
                reported_text = True
            at = p.i
            p.resync()
            if p.i == at:  # resync stops before a `}`: step over it
                p.next()
            continue
        p.next()
        label = t.text[1:]
        if not p.at_end():
            nxt = p.peek()
            diags.error(src, lang, nxt.line, nxt.col, f"unexpected {show(nxt)} after `{t.text}`: "
                                                      "statements start on the next line")
            p.resync()
        if label not in LABELS:
            diags.error(src, lang, t.line, t.col, f"unknown label `{t.text}`: expected `.entry`, `.step` or `.exit`")
        elif label in seen:
            diags.error(src, lang, t.line, t.col,
                        f"duplicate label `{t.text}` (previously on line {seen[label]})")
        stmts = p.sm_block()
        reported_text = True  # text after a label belongs to the label's block
        if label in LABELS and label not in seen:
            seen[label] = t.line
            blocks.append(S.Block(t.line, t.col, label, stmts))
    return tuple(blocks)


def parse_ss(src: Source, diags: Diagnostics) -> S.SsFile:
    lang = SS
    lines = lex(src, diags, lang)
    pre, sections = split_sections(src, lines, diags, lang)
    for toks in pre:
        t = toks[0]
        diags.error(src, lang, t.line, t.col, f"unexpected {show(t)} before the first section")
    options: list[S.Option] = []
    out: list[S.ScriptSection] = []
    params: list[S.ScriptParam] = []
    for header, body in sections:
        if header.name == "options":
            options.extend(_options(body))
        elif header.name == "parameters":
            for toks in body:
                sp = _script_param(toks, src, diags, lang)
                if sp is not None:
                    params.append(sp)
        elif header.name == "<malformed>":
            continue
        else:
            p = Parser(stream(body), src, diags, lang)
            out.append(S.ScriptSection(header, p.ss_statements()))
    return S.SsFile(src.path, tuple(options), tuple(out), tuple(params))


def _script_param(toks: list[Tok], src, diags, lang) -> S.ScriptParam | None:
    """`NAME = value` in a script's `[parameters]` section."""
    t = toks[0]
    if t.kind != ID:
        diags.error(src, lang, t.line, t.col, f"expected a parameter name, found {show(t)}")
        return None
    if len(toks) < 3 or not (toks[1].kind == OP and toks[1].text == "="):
        found = show(toks[1]) if len(toks) > 1 else "end of line"
        col = toks[1].col if len(toks) > 1 else t.col + len(t.text)
        diags.error(src, lang, t.line, col, f"expected `= value` after `{t.text}`, found {found}")
        return None
    e = _whole_expression(toks[2:], src, diags, lang, "the value")
    if e is None:
        return None
    return S.ScriptParam(t.line, t.col, t.text, e, toks[2].col)
