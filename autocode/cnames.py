"""How the names users write become C++ text (docs/codegen.md, "Names").

Every user-supplied name that reaches generated C++ goes through here:

- a machine's file stem becomes its namespace and its file names
  (`tank.sm` → `namespace tank`, `tank.gen.h`): kept as written when it is
  a plain lowercase identifier nothing else uses, else `sm_` + the stem
  with every character outside `[A-Za-z0-9_]` as `_`;
- element, state, local and region names (identifiers by the languages'
  lexer) become enumerators behind a prefix (`E_`, `S_`, `L_`, `R_`); the
  few that a system header defines as a macro get a `0` after the prefix,
  which no name can start with;
- file names and other text reach comments through `comment()` and string
  literals through `emit/common.c_string`, never raw.

Two machines whose names come out the same, or the same but for case (one
file on a case-insensitive file system), are refused where the machines
are listed (`machine_clashes`)."""

from __future__ import annotations

import re

# C++11 keywords and alternative tokens, and `typeof`, a keyword of the
# GNU dialect (-std=gnu++11) the firmware and the native builds use.
CXX_KEYWORDS = frozenset("""
alignas alignof and and_eq asm auto bitand bitor bool break case catch char char16_t char32_t
class compl const constexpr const_cast continue decltype default delete do double dynamic_cast
else enum explicit export extern false float for friend goto if inline int long mutable namespace
new noexcept not not_eq nullptr operator or or_eq private protected public register
reinterpret_cast return short signed sizeof static static_assert static_cast struct switch
template this thread_local throw true try typedef typeid typename union unsigned using virtual
void volatile wchar_t while xor xor_eq typeof
""".split())

# Names the generated code and the runtime use in or around namespace
# `fsw_gen` (the optional sections' too: [reload], [log], parameters, the
# resume after a reset, sensor tables), and names the C library or the
# compilers define as macros in lowercase (`stdin`, avr-libc's `sinf`, GNU
# mode's `linux`): a machine namespace of that name would hide or be
# replaced by them.
TAKEN = frozenset("""
fsw fsw_gen std sv app ex stats link begin poll run_cycle setup loop main run_script
script_main script_avr fswkit arduino
reload reload_image reload_ram vm_features app_features app_period_us fsw_console_rx fsw_console_rx_mask params param_staged
rec resume resume_watch_state time_base time_based
add_time_base plus_time_base millis64 pulses samples
log_fifo log_last log_nor_cs log_ring sensor_health
memcpy memset memcmp memmove strcmp strlen strtoul sscanf printf fprintf sprintf snprintf
fopen fclose fwrite fread fflush usleep clock_gettime timespec time errno assert offsetof
trace_row put64 print_value as_signed as_unsigned var_bytes write_trace fsw_trace_write
stdin stdout stderr linux unix i386
acosf asinf atan2f atanf cbrtf ceilf copysignf cosf coshf expf fabsf fdimf floorf fmaf fmaxf
fminf fmodf frexpf hypotf isfinitef isinff isnanf ldexpf log10f logf lrintf lroundf powf roundf
signbitf sinf sinhf squaref tanf tanhf truncf
con prn aux nul
""".split())

# Patterns of generated or library names: `*_t` types, the generated
# `task_*` and `link_*` names, windows `w0`/`sw0`, sensor parts `sensor0`,
# Windows device files.
TAKEN_PATTERN = re.compile(r".*_t|task_.*|link_.*|s?w[0-9]+|s[0-9]+_(entry|step|exit)|sensor[0-9]+|(com|lpt)[0-9]")

# Macros of the headers generated code sees (glibc's stdio.h and unistd.h,
# avr-libc) that a prefixed enumerator could spell.
MACROS = frozenset({"L_tmpnam", "L_ctermid", "L_cuserid", "L_XTND", "L_INCR", "L_SET", "R_OK",
                    "P_tmpdir"})

_PLAIN = re.compile(r"[a-z][a-z0-9_]*\Z")


def ident(name: str) -> str:
    """`name` with every character outside `[A-Za-z0-9_]` as `_`."""
    return re.sub(r"[^A-Za-z0-9_]", "_", name)


def machine_ident(stem: str) -> str:
    """The C++ namespace and file name stem of the machine in `<stem>.sm`."""
    if _PLAIN.match(stem) and "__" not in stem and stem not in CXX_KEYWORDS and stem not in TAKEN \
            and not TAKEN_PATTERN.fullmatch(stem):
        return stem
    return "sm_" + ident(stem)


def enumerator(prefix: str, name: str) -> str:
    """`prefix` + `name` (an identifier), unless a header defines that as a
    macro: then `prefix` + `0` + `name`, which no other name spells."""
    s = prefix + name
    return prefix + "0" + name if s in MACROS else s


def comment(text: str) -> str:
    """`text` safe inside a `//` comment: printable ASCII only (no line
    break, no `\\` that could splice the next line, no `?` that could begin
    a trigraph); anything else is written as `_`."""
    return "".join(ch if " " <= ch <= "~" and ch not in "\\?" else "_" for ch in text)


def machine_clashes(stems: list[str]) -> list[tuple[int, int]]:
    """Pairs (earlier, later) of indexes into `stems` whose machines would
    have the same namespace or file names, the same but for case
    included."""
    seen: dict[str, int] = {}
    out = []
    for i, stem in enumerate(stems):
        key = machine_ident(stem).lower()
        if key in seen:
            out.append((seen[key], i))
        else:
            seen[key] = i
    return out
