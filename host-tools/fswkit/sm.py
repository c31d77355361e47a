"""libfswsm from Python (docs/bytecode.md, "The host library, libfswsm"):
the runtime's bytecode VM, built as a shared library with a C ABI
(firmware/host/fswsm.h), driven through ctypes.

    from fswkit.sm import Machine
    m = Machine.from_sm("examples/tank/tank.sm")        # compiled in process, f64
    m["tankPressure"] = 780.0
    m.step(g=10)
    print(m.state, m["valveOpen"])

    m = Machine.from_image("tank.fsm", "tank.layout")   # `fsw compile -o tank.fsm --layout tank.layout`

The library is compiled with the host's g++ on first use (one per
evaluation type: libfswsm64.so, libfswsm32.so) and cached like `fsw test
--native`'s builds: under ~/.cache/fswkit/native (or $FSW_CACHE_DIR), keyed
by the hash of its sources, the runtime's headers, the flags and the
compiler, built in a private temporary folder and moved into place whole,
so that concurrent builds never see each other's half-written files.
`python -m fswkit.sm build` builds both and prints where they are.

Every refusal of the library is a Python exception (FswsmError and one
subclass per code); the library checks every argument, so bad input never
crashes the process."""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import struct
import subprocess
import sys
import threading

from fswkit.autocode.kit import RUNTIME

HOST = os.path.join(os.path.dirname(RUNTIME), "host")  # firmware/host: fswsm.h, fswsm.cpp
HEADER = os.path.join(HOST, "fswsm.h")
# The runtime's sources the VM calls (fsw_vm.cpp and its helpers), compiled
# into the library as they are: no copy of the VM.
RUNTIME_SOURCES = ("fsw_vm.cpp", "fsw_element.cpp", "fsw_convert.cpp", "fsw_f64.cpp", "fsw_window.cpp",
                   "fsw_machine.cpp")
# fswkit.run.native's flags (its warnings too: the runtime is held to them),
# for a shared library whose only exports are fswsm.h's functions.
LIB_CXXFLAGS = ["-std=gnu++11", "-O2", "-ffp-contract=off", "-fno-exceptions", "-fno-rtti", "-Wall", "-Wextra",
                "-Werror", "-Wno-unused-function", "-fPIC", "-shared", "-fvisibility=hidden", "-Wl,--as-needed",
                "-Wl,--no-undefined"]
REAL_BITS = {"f32": 32, "f64": 64}

# Return codes (fswsm.h).
OK, STEP_TIME, STEP_CONFIG = 0, 1, 3
(E_ARG, E_NOMEM, E_VERIFY, E_REAL, E_SCHEMA, E_LAYOUT, E_FILE, E_NO_LAYOUT, E_NO_IMAGE, E_NO_SV, E_SMALL,
 E_INDEX, E_NAME, E_VALUE, E_SIZE, E_STATE) = range(-1, -17, -1)
TYPE_NAMES = ("I8", "I16", "I32", "I64", "U8", "U16", "U32", "U64", "F32", "F64", "bool")
_FORMATS = ("<b", "<h", "<i", "<q", "<B", "<H", "<I", "<Q", "<f", "<d", "<B")


# ---- exceptions -----------------------------------------------------------------------

class FswsmError(Exception):
    """A refusal of libfswsm: `code` (FSWSM_*), `name` ("FSWSM_E_REAL"), the
    library's message, and for image refusals the verifier's `reason`
    (fsw_vm.h VmReason) and `reason_text`."""

    def __init__(self, code: int, name: str, message: str, reason: int = 0, reason_text: str = ""):
        super().__init__(f"{message} [{name}]")
        self.code, self.name, self.message = code, name, message
        self.reason, self.reason_text = reason, reason_text


class StepTimeError(FswsmError):
    """The step was refused: G did not increase (the runtime's kErrTime)."""


class StepRefused(FswsmError):
    """The runtime refused a step (kErrConfig)."""


class BadArgument(FswsmError, ValueError):
    pass


class OutOfMemory(FswsmError, MemoryError):
    pass


class ImageRefused(FswsmError):
    """vm_verify refused the image: `reason` says which rule."""


class WrongReal(ImageRefused):
    """The image was compiled for the other evaluation type than the library's."""


class WrongSchema(ImageRefused):
    """The image is bound to another state vector."""


class LayoutError(FswsmError, ValueError):
    pass


class FileUnreadable(FswsmError, OSError):
    pass


class NotReady(FswsmError):
    """No layout, image or state vector yet."""


class BufferTooSmall(FswsmError, ValueError):
    pass


class ElementIndexError(FswsmError, IndexError):
    pass


class NameNotFound(FswsmError, KeyError):
    def __str__(self) -> str:  # KeyError would quote the message
        return Exception.__str__(self)


class ValueNotHeld(FswsmError, ValueError):
    """A value the element's type cannot hold."""


class SizeError(FswsmError, ValueError):
    pass


class StateError(FswsmError, ValueError):
    pass


_ERRORS = {STEP_TIME: StepTimeError, STEP_CONFIG: StepRefused, E_ARG: BadArgument, E_NOMEM: OutOfMemory,
           E_VERIFY: ImageRefused, E_REAL: WrongReal, E_SCHEMA: WrongSchema, E_LAYOUT: LayoutError,
           E_FILE: FileUnreadable, E_NO_LAYOUT: NotReady, E_NO_IMAGE: NotReady, E_NO_SV: NotReady,
           E_SMALL: BufferTooSmall, E_INDEX: ElementIndexError, E_NAME: NameNotFound, E_VALUE: ValueNotHeld,
           E_SIZE: SizeError, E_STATE: StateError}


class BuildError(Exception):
    """The host compiler is missing, or the library did not compile."""


class ConfigError(Exception):
    """Machine.from_sm: the machine's configs did not compile (the located
    diagnostics in the message)."""


# ---- building the library ----------------------------------------------------------------

def sources() -> list[str]:
    return [os.path.join(HOST, "fswsm.cpp")] + [os.path.join(RUNTIME, n) for n in RUNTIME_SOURCES]


def _key(cxx: str, bits: int) -> str:
    from fswkit.run import native

    h = hashlib.sha256(b"libfswsm\0" + native.compiler_identity(cxx).encode() + b"\0")
    headers = sorted(os.path.join(RUNTIME, n) for n in os.listdir(RUNTIME) if n.endswith(".h")) + [HEADER]
    for path in sources() + headers:
        with open(path, "rb") as f:
            h.update(os.path.basename(path).encode() + b"\0" + f.read())
    h.update(" ".join([cxx] + LIB_CXXFLAGS + native.compiler_flags(cxx) + native.FLAGS[bits]).encode())
    return h.hexdigest()[:20]


_build_lock = threading.Lock()
LINK_ONLY = ("-shared",)  # with the -Wl, options: LIB_CXXFLAGS's for the link alone


def _build_step(cmd: list[str], cwd: str, bits: int) -> None:
    """One compiler run of the library's build, in `cwd`: a failure is
    BuildError, said as the disk's when the disk is full."""
    from fswkit.run import native

    r = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd)
    if r.returncode != 0:
        from fswkit.outputs import host_write_faults

        full = host_write_faults((r.stdout + r.stderr).splitlines())
        if full:  # the disk, not the kit
            raise BuildError(f"cannot write libfswsm{bits} into the kit's cache {native.cache_dir()}: "
                             f"{'; '.join(full)} (FSW_CACHE_DIR names another folder)")
        errors = [ln.strip()[:300] for ln in r.stderr.splitlines() if "error" in ln]
        raise BuildError(f"libfswsm{bits} did not compile (a defect of fswkit, or an unusual compiler): "
                         + " ".join(cmd) + "".join("\n  " + e for e in errors[:6]))


def library_path(real: str = "f64") -> str:
    """The path of libfswsm32.so or libfswsm64.so for `real` ("f32", "f64"),
    compiled now if the cache has no build of these sources."""
    from fswkit.run import native

    if real not in REAL_BITS:
        raise ValueError(f"real must be one of {sorted(REAL_BITS)}, not {real!r}")
    bits = REAL_BITS[real]
    cxx = native.CXX
    if shutil.which(cxx) is None:
        raise BuildError(f"no host C++ compiler `{cxx}` to build libfswsm (install g++, or set CXX)")
    out = os.path.join(native.cache_dir(), _key(cxx, bits))
    lib = os.path.join(out, f"libfswsm{bits}.so")
    if os.path.exists(lib):
        return lib
    with _build_lock:
        if os.path.exists(lib):
            return lib
        native.sweep(native.cache_dir())
        tmp = native.private_tmp(out)
        with native.removed_when_done(tmp):
            os.makedirs(tmp, exist_ok=True)
            flags = [cxx] + LIB_CXXFLAGS + native.compiler_flags(cxx) + native.FLAGS[bits]
            native.objects_then_link(lambda cmd: _build_step(cmd, tmp, bits),
                                     [f for f in flags if f not in LINK_ONLY and not f.startswith("-Wl,")]
                                     + ["-I", RUNTIME, "-I", HOST], flags, sources(), os.path.basename(lib), tmp)
            try:
                os.replace(tmp, out)
            except OSError:  # another process built the same library first
                if not os.path.exists(lib):
                    raise
    return lib


_libs: dict[str, ctypes.CDLL] = {}


def library(real: str = "f64") -> ctypes.CDLL:
    """The loaded library for `real`, its functions' signatures declared."""
    path = library_path(real)
    if path in _libs:
        return _libs[path]
    lib = ctypes.CDLL(path)
    c = ctypes
    h, u8p, u16p, u32p = c.c_void_p, c.POINTER(c.c_uint8), c.POINTER(c.c_uint16), c.POINTER(c.c_uint32)
    sigs = {
        "fswsm_real_bytes": (c.c_int, []), "fswsm_abi": (c.c_int, []),
        "fswsm_error_name": (c.c_char_p, [c.c_int]), "fswsm_error_text": (c.c_char_p, [c.c_int]),
        "fswsm_reason_text": (c.c_char_p, [c.c_int]), "fswsm_type_name": (c.c_char_p, [c.c_int]),
        "fswsm_type_size": (c.c_int, [c.c_int]),
        "fswsm_create": (h, []), "fswsm_destroy": (None, [h]),
        "fswsm_last_error": (c.c_char_p, [h]), "fswsm_reason": (c.c_int, [h]),
        "fswsm_set_layout": (c.c_int, [h, u16p, u8p, c.c_uint32, c.c_uint32, c.c_uint32]),
        "fswsm_layout_file": (c.c_int, [h, c.c_char_p]), "fswsm_layout_text": (c.c_int, [h, c.c_char_p]),
        "fswsm_sv_size": (c.c_int, [h, u32p]), "fswsm_element_count": (c.c_int, [h, u32p]),
        "fswsm_schema": (c.c_int, [h, u32p]),
        "fswsm_element_info": (c.c_int, [h, c.c_uint32, u8p, u32p, u32p]),
        "fswsm_element_name": (c.c_char_p, [h, c.c_uint32]),
        "fswsm_element_index": (c.c_int, [h, c.c_char_p, u32p]),
        "fswsm_load_image": (c.c_int, [h, c.c_char_p, c.c_uint32]),
        "fswsm_load_image_file": (c.c_int, [h, c.c_char_p]),
        "fswsm_state_count": (c.c_int, [h, u32p]), "fswsm_state_name": (c.c_char_p, [h, c.c_uint32]),
        "fswsm_state_id": (c.c_int, [h, c.c_char_p, u32p]),
        "fswsm_bind": (c.c_int, [h, c.c_void_p, c.c_uint32]), "fswsm_reset": (c.c_int, [h, c.c_uint32]),
        "fswsm_step": (c.c_int, [h]), "fswsm_state": (c.c_int, [h, u32p]),
        "fswsm_time_in_state": (c.c_int, [h, c.POINTER(c.c_uint64)]),
        "fswsm_get": (c.c_int, [h, c.c_uint32, c.POINTER(c.c_double)]),
        "fswsm_set": (c.c_int, [h, c.c_uint32, c.c_double]),
        "fswsm_get_raw": (c.c_int, [h, c.c_uint32, c.c_void_p, c.c_uint32]),
        "fswsm_set_raw": (c.c_int, [h, c.c_uint32, c.c_void_p, c.c_uint32]),
    }
    for name, (res, args) in sigs.items():
        f = getattr(lib, name)
        f.restype, f.argtypes = res, args
    if lib.fswsm_real_bytes() != REAL_BITS[real] // 8:
        raise BuildError(f"{path} is not a binary{REAL_BITS[real]} build")
    _libs[path] = lib
    return lib


# ---- the layout file (`fsw compile --layout`) -------------------------------------------------

def _c_name(name, exc, code: int, code_name: str, what: str) -> bytes:
    """A name for the C API: C reads a string up to its first NUL, so a name
    holding one would find the element or state named by what precedes it."""
    text = str(name)
    if "\0" in text:
        raise exc(code, code_name, f"no {what} named {text!r}: a name holds no NUL")
    return text.encode()


def layout_text(m, real_bits: int, image: str | None = None) -> str:
    """The layout file of machine `m` (fswkit.autocode.model.Machine) and
    its image compiled for binary`real_bits`: what libfswsm needs besides
    the image (docs/cli.md, `fsw compile --layout`)."""
    from fswkit.autocode import vmverify as V

    layout = V.layout_of(m.sv)
    alias = {v.name: v.alias for v in m.vars if v.kind == "element" and v.alias}
    what = f"{os.path.basename(image)} ({os.path.basename(m.path)})" if image else os.path.basename(m.path)
    out = [f"# The state vector that {what} is bound to, for libfswsm",
           "# (docs/bytecode.md): written by `fsw compile --layout`.",
           "fswsm-layout 1", f"real {real_bits}", f"schema 0x{layout.schema:08x}", f"size {m.sv.size}",
           f"elements {len(m.sv.elements)}", "# index name type offset size [alias]"]
    for k, e in enumerate(m.sv.elements):
        out.append(f"element {k} {e.name} {e.type.name} {e.offset} {e.type.size}"
                   + (f" {alias[e.name]}" if e.name in alias else ""))
    out.append(f"states {len(m.states)}")
    out += [f"state {k} {st.name}" for k, st in enumerate(m.states, 1)]
    return "\n".join(out) + "\n"


def _load_machine(path: str, sv: str | None):
    from fswkit.autocode.diagnostics import Diagnostics
    from fswkit.autocode.project import load_machine

    d = Diagnostics()
    m = load_machine(str(path), d, None if sv is None else str(sv))
    if m is None:
        raise ConfigError(d.render().rstrip() or f"{path}: the machine did not compile")
    return m


# ---- a machine ----------------------------------------------------------------------------------

class Machine:
    """A state machine stepped by libfswsm over a state vector this object
    holds (`sv`, a bytearray) or one the caller binds (`bind`)."""

    def __init__(self, real: str = "f64"):
        self._lib = library(real)
        self.real = real
        self._h = self._lib.fswsm_create()
        if not self._h:
            raise MemoryError("libfswsm: out of memory")
        self.sv: bytearray | None = None
        self._sv_c = None
        self._index: dict[str, int] = {}
        self._types: list[int] = []
        self._names: list[str] = []

    # -- constructors --

    @classmethod
    def from_sm(cls, path, sv=None, real: str = "f64") -> "Machine":
        """Compiles MACHINE.sm (and its .sv, found beside it unless given)
        through the kit's compiler in this process, and loads it."""
        if real not in REAL_BITS:
            raise ValueError(f"real must be one of {sorted(REAL_BITS)}, not {real!r}")
        return cls.from_model(_load_machine(path, sv), real)

    @classmethod
    def from_model(cls, m, real: str = "f64") -> "Machine":
        """A checked machine (fswkit.autocode.model.Machine, as
        fswkit.autocode.project.load_machine gives it), compiled and loaded."""
        from fswkit.autocode.emit.bytecode import BytecodeError, compile_machine
        from fswkit.autocode.numeric import REALS

        if real not in REAL_BITS:
            raise ValueError(f"real must be one of {sorted(REAL_BITS)}, not {real!r}")
        try:
            image = compile_machine(m, REALS[real])
        except BytecodeError as e:
            raise ConfigError(f"{m.path}:{e.line}:{e.col}: cannot compile to bytecode: {e}") from None
        self = cls(real)
        self.model = m
        self.load_layout_text(layout_text(m, REAL_BITS[real]))
        self.load_image(image)
        self.bind(bytearray(self.sv_size))
        return self

    @classmethod
    def from_image(cls, path, layout_file, real: str | None = None) -> "Machine":
        """Loads FILE.fsm with the layout file `fsw compile --layout` wrote.
        `real` picks the library; by default the image's own (its byte 5),
        so only an explicit `real` can meet WrongReal."""
        if real is None:
            from fswkit.autocode.diagnostics import read_head

            try:  # read_head refuses a FIFO without waiting on it: the library refuses it too
                head = read_head(path, 6)
            except OSError:  # the library says so, as FileUnreadable
                head = b""
            real = "f32" if len(head) == 6 and head[5] == 4 else "f64"
        self = cls(real)
        self.load_layout_file(layout_file)
        self._check(self._lib.fswsm_load_image_file(self._h, os.fsencode(path)))
        self.bind(bytearray(self.sv_size))
        return self

    # -- the steps of the C API, for whoever wants them one by one --

    def _check(self, code: int) -> int:
        if code == OK:
            return code
        lib = self._lib
        reason = lib.fswsm_reason(self._h) if code in (E_VERIFY, E_REAL, E_SCHEMA) else 0  # an image's refusal
        message = (lib.fswsm_last_error(self._h) or b"").decode(errors="replace") \
            or lib.fswsm_error_text(code).decode()
        exc = _ERRORS.get(code, FswsmError)
        reason_text = lib.fswsm_reason_text(reason).decode() if reason else ""
        raise exc(code, lib.fswsm_error_name(code).decode(), message, reason, reason_text)

    def _layout_loaded(self) -> None:
        lib, c = self._lib, ctypes
        n = c.c_uint32()
        self._check(lib.fswsm_element_count(self._h, c.byref(n)))
        self._types, self._names, self._offsets = [], [], []
        t, off = c.c_uint8(), c.c_uint32()
        for k in range(n.value):
            self._check(lib.fswsm_element_info(self._h, k, c.byref(t), c.byref(off), None))
            self._types.append(t.value)
            self._offsets.append(off.value)
            self._names.append(lib.fswsm_element_name(self._h, k).decode())
        self._index = {nm: k for k, nm in enumerate(self._names) if nm}
        self.sv, self._sv_c = None, None

    def load_layout_file(self, path) -> None:
        self._check(self._lib.fswsm_layout_file(self._h, os.fsencode(path)))
        self._layout_loaded()

    def load_layout_text(self, text: str) -> None:
        self._check(self._lib.fswsm_layout_text(self._h, text.encode()))
        self._layout_loaded()

    def set_layout(self, elems, schema: int, sv_size: int) -> None:
        """`elems`: (offset, type code) per element in layout order, as
        fswkit.autocode.vmverify.layout_of gives them."""
        n = len(elems)
        # the C types would wrap a number too large for them without a word
        for k, (off, t) in enumerate(elems):
            if not (isinstance(off, int) and 0 <= off <= 0xFFFF and isinstance(t, int) and 0 <= t <= 0xFF):
                raise LayoutError(E_LAYOUT, "FSWSM_E_LAYOUT", f"element {k}: offset {off!r} and type code {t!r}: an "
                                  "offset is 0..65535 and a type code 0..255")
        for what, v in (("schema", schema), ("sv_size", sv_size)):
            if not (isinstance(v, int) and 0 <= v <= 0xFFFFFFFF):
                raise LayoutError(E_LAYOUT, "FSWSM_E_LAYOUT", f"{what} {v!r}: a number of 32 bits (0..4294967295)")
        offs = (ctypes.c_uint16 * max(n, 1))(*[o for o, _ in elems])
        types = (ctypes.c_uint8 * max(n, 1))(*[t for _, t in elems])
        self._check(self._lib.fswsm_set_layout(self._h, offs, types, n, schema, sv_size))
        self._layout_loaded()

    def load_image(self, image: bytes) -> None:
        self._check(self._lib.fswsm_load_image(self._h, bytes(image), len(image)))

    def bind(self, buffer) -> None:
        """Steps over `buffer` (a bytearray or another writable buffer) from
        now on; it must hold the state vector (sv_size bytes)."""
        mv = memoryview(buffer)
        if mv.readonly:
            raise TypeError("the state vector must be a writable buffer (a bytearray)")
        n = mv.nbytes
        arr = (ctypes.c_uint8 * max(n, 1)).from_buffer(buffer) if n else (ctypes.c_uint8 * 1)()
        self._check(self._lib.fswsm_bind(self._h, arr, n))
        self.sv, self._sv_c = buffer, arr

    # -- what it is --

    @property
    def sv_size(self) -> int:
        n = ctypes.c_uint32()
        self._check(self._lib.fswsm_sv_size(self._h, ctypes.byref(n)))
        return n.value

    @property
    def names(self) -> list[str]:
        """Element names in layout order ("" where the layout gave none)."""
        return list(self._names)

    def index(self, name) -> int:
        if isinstance(name, int):
            if not 0 <= name <= 0xFFFFFFFF:
                raise ElementIndexError(E_INDEX, "FSWSM_E_INDEX", f"element index {name} out of range: the layout "
                                        f"has {len(self._types)} elements")
            return name
        k = self._index.get(name)
        if k is None:
            c_name = _c_name(name, NameNotFound, E_NAME, "FSWSM_E_NAME", "element")
            n = ctypes.c_uint32()
            self._check(self._lib.fswsm_element_index(self._h, c_name, ctypes.byref(n)))
            k = self._index[name] = n.value
        return k

    def type(self, name) -> str:
        k = self.index(name)
        if not 0 <= k < len(self._types):
            raise ElementIndexError(E_INDEX, "FSWSM_E_INDEX", f"element index {k} out of range: the layout has "
                                    f"{len(self._types)} elements")
        return TYPE_NAMES[self._types[k]]

    @property
    def states(self) -> list[str]:
        n = ctypes.c_uint32()
        self._check(self._lib.fswsm_state_count(self._h, ctypes.byref(n)))
        return [(self._lib.fswsm_state_name(self._h, k) or b"").decode() for k in range(1, n.value + 1)]

    @property
    def state_id(self) -> int:
        n = ctypes.c_uint32()
        self._check(self._lib.fswsm_state(self._h, ctypes.byref(n)))
        return n.value

    @property
    def state(self) -> str:
        """The current state's name (its id as text where the layout named none)."""
        k = self.state_id
        return (self._lib.fswsm_state_name(self._h, k) or b"").decode() or str(k)

    @property
    def T(self) -> int:
        t = ctypes.c_uint64()
        self._check(self._lib.fswsm_time_in_state(self._h, ctypes.byref(t)))
        return t.value

    @property
    def reason(self) -> int:
        return self._lib.fswsm_reason(self._h)

    # -- running --

    def reset(self, state=1) -> None:
        """Back to before the first step, in `state` (a name or an id, 1..)."""
        if isinstance(state, str):
            c_name = _c_name(state, StateError, E_STATE, "FSWSM_E_STATE", "state")
            n = ctypes.c_uint32()
            self._check(self._lib.fswsm_state_id(self._h, c_name, ctypes.byref(n)))
            state = n.value
        if not (isinstance(state, int) and 0 <= state <= 0xFFFFFFFF):  # the C type would wrap it
            raise StateError(E_STATE, "FSWSM_E_STATE", f"state {state!r}: a state id is a name or a number 1..255")
        self._check(self._lib.fswsm_reset(self._h, state))

    def step(self, g: int | None = None) -> None:
        """One step; with `g`, G is written first. StepTimeError when G did
        not increase (nothing changed)."""
        if g is not None:
            self["G"] = int(g)
        self._check(self._lib.fswsm_step(self._h))

    # -- elements --

    def get_raw(self, name) -> bytes:
        k = self.index(name)
        size = TYPE_SIZES[self._types[k]] if 0 <= k < len(self._types) else 1
        buf = ctypes.create_string_buffer(size)
        self._check(self._lib.fswsm_get_raw(self._h, k, buf, size))
        return buf.raw

    def set_raw(self, name, data: bytes) -> None:
        k = self.index(name)
        data = bytes(data)
        self._check(self._lib.fswsm_set_raw(self._h, k, data, len(data)))

    def get_double(self, name) -> float:
        d = ctypes.c_double()
        self._check(self._lib.fswsm_get(self._h, self.index(name), ctypes.byref(d)))
        return d.value

    def set_double(self, name, value: float) -> None:
        self._check(self._lib.fswsm_set(self._h, self.index(name), float(value)))

    def __getitem__(self, name):
        """The element's value: int for integer types, bool, or float (exact)."""
        k = self.index(name)
        raw = self.get_raw(k)  # the library refuses an index out of range
        t = self._types[k]
        v = struct.unpack(_FORMATS[t], raw)[0]
        return bool(v) if t == 10 else v

    def __setitem__(self, name, value) -> None:
        """Writes an element: an int or bool exactly (refused outside the
        type's range), a float through fswsm_set (rounded for F32; refused
        for an integer element unless whole and in range)."""
        k = self.index(name)
        t = self._types[k] if 0 <= k < len(self._types) else None
        if t is not None and isinstance(value, (bool, int)) and not isinstance(value, float):
            value = int(value)
            if t == 10:
                if value not in (0, 1):
                    raise ValueNotHeld(E_VALUE, "FSWSM_E_VALUE", f"element {k} {self._names[k]} (bool) cannot hold "
                                       f"{value}: a bool takes 0 or 1")
                return self.set_raw(k, bytes([value]))
            if t <= 7:
                try:
                    return self.set_raw(k, struct.pack(_FORMATS[t], value))
                except struct.error:
                    raise ValueNotHeld(E_VALUE, "FSWSM_E_VALUE", f"element {k} {self._names[k]} "
                                       f"({TYPE_NAMES[t]}) cannot hold {value}") from None
        self.set_double(k, value)

    def values(self) -> dict[str, object]:
        """Every named element's value."""
        return {nm: self[k] for k, nm in enumerate(self._names) if nm}

    # -- the end --

    def close(self) -> None:
        if getattr(self, "_h", None):
            self._lib.fswsm_destroy(self._h)
            self._h = None

    def __del__(self):
        self.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


TYPE_SIZES = (1, 2, 4, 8, 1, 2, 4, 8, 4, 8, 1)


def main(argv: list[str] | None = None) -> int:
    """`python -m fswkit.sm build [f32|f64]...`: builds the libraries and
    prints their paths and the header's, for a C or LabVIEW user."""
    args = sys.argv[1:] if argv is None else argv
    if not args or args[0] != "build" or any(a not in REAL_BITS for a in args[1:]):
        sys.stderr.write("usage: python -m fswkit.sm build [f32|f64]...\n")
        return 2
    try:
        for real in args[1:] or ["f64", "f32"]:
            print(library_path(real))
        print(HEADER)
    except BuildError as e:
        sys.stderr.write(f"libfswsm: {e}\n")
        return 1
    except BrokenPipeError:  # `... | head -1`
        sys.stdout = None
    return 0


if __name__ == "__main__":
    sys.exit(main())
