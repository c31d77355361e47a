/* libfswsm: the runtime's bytecode VM (docs/bytecode.md) as a host library
 * with a C ABI, for ground equipment: test stands (LabVIEW's Call Library
 * Function node, any language with a C FFI), Python scripts (fswkit.sm).
 *
 * The library wraps the runtime's own fsw_vm.cpp and helpers: a machine
 * steps here with the bits it steps with on a board of the same evaluation
 * type R. Each build has one R: libfswsm64 (binary64) and libfswsm32
 * (binary32, binary64 elements converted in software, as on an AVR); an
 * image of the other R is refused (FSWSM_E_REAL). Build (docs/bytecode.md,
 * "The host library, libfswsm"): `python -m fswkit.sm build` prints both
 * libraries' paths, or by hand
 *
 *   g++ -std=gnu++11 -O2 -ffp-contract=off -fno-exceptions -fno-rtti -fPIC -shared \
 *       -fvisibility=hidden -Wl,--no-undefined -DFSW_REAL_IS_FLOAT=0 -DFSW_F64_SOFT=0 \
 *       -I firmware/src -I firmware/host \
 *       firmware/host/fswsm.cpp firmware/src/fsw_vm.cpp firmware/src/fsw_element.cpp \
 *       firmware/src/fsw_convert.cpp firmware/src/fsw_f64.cpp firmware/src/fsw_window.cpp \
 *       firmware/src/fsw_machine.cpp -o libfswsm64.so
 *   (binary32: -DFSW_REAL_IS_FLOAT=1 -DFSW_F64_SOFT=1 ... -o libfswsm32.so)
 *
 * A machine is an opaque handle. Its life: fswsm_create; a layout (the
 * state vector the image is bound to: fswsm_layout_file, the file `fsw
 * compile --layout` writes, or fswsm_set_layout); an image (fswsm_load_image,
 * verified by the runtime's vm_verify before anything runs); a state vector
 * in the caller's memory (fswsm_bind); then fswsm_step, element reads and
 * writes, fswsm_reset; fswsm_destroy. The library keeps no global state: any
 * number of handles live at once. A handle is used by one thread at a time.
 *
 * Every function that can refuse returns an int: FSWSM_OK (0), or a
 * negative FSWSM_E_* code when it refused (and changed nothing);
 * fswsm_step returns the runtime's Result (0 ok, 1 G did not increase) or a
 * negative code. fswsm_error_name and fswsm_error_text give any code's name
 * and words; fswsm_last_error the handle's last refusal in full ("the image
 * is binary32 ..."); after
 * FSWSM_E_VERIFY, FSWSM_E_REAL or FSWSM_E_SCHEMA, fswsm_reason the
 * verifier's VmReason (docs/bytecode.md, "The verifier") and
 * fswsm_reason_text its words. No function crashes on bad input it can see:
 * a null pointer, bytes that are not an image, a layout that does not fit,
 * a buffer smaller than the state vector, an index out of range are all
 * refused. (A pointer to memory smaller than the length passed with it is
 * not something a C library can see.) */
#ifndef FSWSM_H
#define FSWSM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32)
#define FSWSM_API __declspec(dllexport)
#else
#define FSWSM_API __attribute__((visibility("default")))
#endif

/* The version of this interface: 1. */
#define FSWSM_ABI 1

/* Return codes. Non-negative codes of fswsm_step are the runtime's Result. */
enum {
    FSWSM_OK = 0,
    FSWSM_STEP_TIME = 1,      /* fswsm_step: G did not increase; nothing changed (kErrTime) */
    FSWSM_STEP_CONFIG = 3,    /* fswsm_step: the runtime refused the image (kErrConfig; not for a verified image) */
    FSWSM_E_ARG = -1,         /* a null handle or pointer, or an argument out of its range */
    FSWSM_E_NOMEM = -2,       /* out of memory */
    FSWSM_E_VERIFY = -3,      /* vm_verify refused the image: fswsm_reason says which rule */
    FSWSM_E_REAL = -4,        /* the image's R (header byte 5) is not this library's */
    FSWSM_E_SCHEMA = -5,      /* the image is bound to another state vector (schema hash or element count) */
    FSWSM_E_LAYOUT = -6,      /* a layout that cannot be (unknown type, element outside the state vector, bad file line) */
    FSWSM_E_FILE = -7,        /* a file that cannot be read */
    FSWSM_E_NO_LAYOUT = -8,   /* no layout given yet */
    FSWSM_E_NO_IMAGE = -9,    /* no image loaded yet */
    FSWSM_E_NO_SV = -10,      /* no state vector bound yet */
    FSWSM_E_SMALL = -11,      /* the caller's buffer is smaller than the layout's state vector */
    FSWSM_E_INDEX = -12,      /* an element index out of the layout */
    FSWSM_E_NAME = -13,       /* no element or state of that name */
    FSWSM_E_VALUE = -14,      /* a value the element's type cannot hold */
    FSWSM_E_SIZE = -15,       /* a length that is not the element's size, or an image longer than 65535 bytes */
    FSWSM_E_STATE = -16       /* a state id out of 1..states */
};

/* Element types, as the runtime numbers them (fsw_types.h ElemType). */
enum {
    FSWSM_I8 = 0, FSWSM_I16 = 1, FSWSM_I32 = 2, FSWSM_I64 = 3,
    FSWSM_U8 = 4, FSWSM_U16 = 5, FSWSM_U32 = 6, FSWSM_U64 = 7,
    FSWSM_F32 = 8, FSWSM_F64 = 9, FSWSM_BOOL = 10
};

typedef struct fswsm fswsm; /* one machine: opaque */

/* ---- the library ---------------------------------------------------------- */

/* Bytes of this build's evaluation type R: 4 (libfswsm32) or 8 (libfswsm64). */
FSWSM_API int fswsm_real_bytes(void);
/* FSWSM_ABI of this build. */
FSWSM_API int fswsm_abi(void);
/* "FSWSM_E_REAL" etc. for any code above ("FSWSM_OK", "FSWSM_STEP_TIME");
 * "unknown" for another. */
FSWSM_API const char* fswsm_error_name(int code);
/* What a code means, in words. */
FSWSM_API const char* fswsm_error_text(int code);
/* Words of a verifier reason (fsw_vm.h VmReason, 0..16): "bad magic ...". */
FSWSM_API const char* fswsm_reason_text(int reason);
/* Name of an element type ("F64"), "" for an unknown one; its size in bytes, 0 for unknown. */
FSWSM_API const char* fswsm_type_name(int type);
FSWSM_API int fswsm_type_size(int type);

/* ---- a machine -------------------------------------------------------------- */

/* A new, empty machine; NULL only when out of memory. */
FSWSM_API fswsm* fswsm_create(void);
/* Frees it (the bound state vector stays the caller's); NULL is ignored. */
FSWSM_API void fswsm_destroy(fswsm* h);
/* The message of the handle's last refusal, in full ("" before any); valid
 * until the handle's next call. A call that succeeds may clear it. */
FSWSM_API const char* fswsm_last_error(const fswsm* h);
/* The verifier's reason (VmReason) of the last image load: 0 once accepted. */
FSWSM_API int fswsm_reason(const fswsm* h);

/* ---- the layout: the state vector the image is bound to ---------------------- */

/* `count` elements in layout order: element k at byte offsets[k], of type
 * types[k] (FSWSM_*); the state vector's schema hash and its size in bytes.
 * Every element must lie inside sv_size. Discards a loaded image and the bound
 * state vector, and any names a layout file gave. */
FSWSM_API int fswsm_set_layout(fswsm* h, const uint16_t* offsets, const uint8_t* types, uint32_t count,
                               uint32_t schema, uint32_t sv_size);
/* The layout file `fsw compile --layout FILE` writes (docs/cli.md): the
 * layout, and the names of the elements and states. Same effects as
 * fswsm_set_layout. A bad line is refused with FSWSM_E_LAYOUT, its line
 * number in fswsm_last_error. */
FSWSM_API int fswsm_layout_file(fswsm* h, const char* path);
/* The same from text in memory (NUL-terminated). */
FSWSM_API int fswsm_layout_text(fswsm* h, const char* text);

/* Bytes of the layout's state vector, its elements, its schema hash. */
FSWSM_API int fswsm_sv_size(const fswsm* h, uint32_t* size);
FSWSM_API int fswsm_element_count(const fswsm* h, uint32_t* count);
FSWSM_API int fswsm_schema(const fswsm* h, uint32_t* schema);
/* Element `index`'s type (FSWSM_*), byte offset and size; any pointer may be NULL. */
FSWSM_API int fswsm_element_info(const fswsm* h, uint32_t index, uint8_t* type, uint32_t* offset, uint32_t* size);
/* Element `index`'s name ("" when the layout gave none); NULL for an index out of range. */
FSWSM_API const char* fswsm_element_name(const fswsm* h, uint32_t index);
/* The index of the element named `name` (its state-vector name, or the
 * machine's alias of it, such as G or S). */
FSWSM_API int fswsm_element_index(const fswsm* h, const char* name, uint32_t* index);

/* ---- the image ---------------------------------------------------------------- */

/* Copies the image, refuses one of another R (FSWSM_E_REAL) or of another
 * state vector (FSWSM_E_SCHEMA), runs vm_verify against the layout (any other
 * rule: FSWSM_E_VERIFY), and on success resets the machine to its first
 * state (fswsm_reset(h, 1)). On a refusal the previous image, if any, stays. */
FSWSM_API int fswsm_load_image(fswsm* h, const uint8_t* image, uint32_t len);
/* The same from a file (`fsw compile -o FILE.fsm`). */
FSWSM_API int fswsm_load_image_file(fswsm* h, const char* path);
/* The loaded image's number of states. */
FSWSM_API int fswsm_state_count(const fswsm* h, uint32_t* states);
/* Name of state `id` (1..states), "" when the layout gave none; NULL out of range. */
FSWSM_API const char* fswsm_state_name(const fswsm* h, uint32_t id);
/* The id of the state named `name`. */
FSWSM_API int fswsm_state_id(const fswsm* h, const char* name, uint32_t* id);

/* ---- running -------------------------------------------------------------------- */

/* Binds the state vector: `len` bytes at `sv`, the caller's (the library
 * never frees it); len must be at least fswsm_sv_size. NULL unbinds. */
FSWSM_API int fswsm_bind(fswsm* h, uint8_t* sv, uint32_t len);
/* Back to the state before the first step in state `id` (1..states): T 0,
 * locals at their initial values, windows empty (vm_reset). The state
 * vector is not touched. */
FSWSM_API int fswsm_reset(fswsm* h, uint32_t id);
/* One step (vm_step, spec 4.6) with G as the state vector holds it: FSWSM_OK,
 * FSWSM_STEP_TIME when G did not increase (nothing changed), or a negative code. */
FSWSM_API int fswsm_step(fswsm* h);
/* The current state id (1..states): the state the next step runs in. */
FSWSM_API int fswsm_state(const fswsm* h, uint32_t* id);
/* T of the last step (the time in the current state), in G's units. */
FSWSM_API int fswsm_time_in_state(const fswsm* h, uint64_t* t);

/* ---- elements of the bound state vector ------------------------------------------ */

/* Element `index` as a double: exact, but for 64-bit integers beyond 2^53
 * (rounded to nearest) — use fswsm_get_raw for those; a float's NaN stays NaN. */
FSWSM_API int fswsm_get(const fswsm* h, uint32_t index, double* value);
/* Writes `value` into element `index`: a float element takes it rounded to
 * its type (F32: to nearest; NaN and infinities kept); an integer element
 * takes an integral value inside its range, a bool 0 or 1 — anything else is
 * refused with FSWSM_E_VALUE and nothing written. */
FSWSM_API int fswsm_set(fswsm* h, uint32_t index, double value);
/* The element's bytes as the state vector holds them (little-endian); `len`
 * must be the element's size. */
FSWSM_API int fswsm_get_raw(const fswsm* h, uint32_t index, void* out, uint32_t len);
FSWSM_API int fswsm_set_raw(fswsm* h, uint32_t index, const void* in, uint32_t len);

#ifdef __cplusplus
}
#endif

#endif /* FSWSM_H */
