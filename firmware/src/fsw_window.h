// Rolling windows (spec 4.4/4.6): roll_avg, roll_min, roll_max, roll_range,
// roll_median over the last N samples, in caller-provided static storage.
// The exact algorithms (bit for bit) are written down in docs/runtime.md.
#ifndef FSW_WINDOW_H
#define FSW_WINDOW_H

#include "fsw_convert.h"
#include "fsw_types.h"

namespace fsw {

// std::conditional, without the standard library.
template <bool B, typename T, typename F>
struct conditional_t {
    typedef T type;
};
template <typename T, typename F>
struct conditional_t<false, T, F> {
    typedef F type;
};

// A sample as a window stores it: NaN -> +0 (spec), and -0 -> +0 so that
// equal samples are identical bit patterns (no sign-of-zero ambiguity). On
// binary32 R the test is made on the bits (no float routine on an 8-bit MCU).
#if FSW_REAL_IS_FLOAT
inline Real window_sample(Real x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    // +-0 or NaN: +0. The choice is made on the bits and they are the
    // result: a choice between two floats compiled to byte moves in
    // reversed order and back on AVR (24 B of flash a window's push).
    if (static_cast<uint32_t>((b & 0x7FFFFFFFUL) - 1u) >= 0x7F800000UL) b = 0;  // magnitude 0, or above infinity's
    memcpy(&x, &b, sizeof x);
    return x;
}
#else
inline Real window_sample(Real x) { return (x != x || x == 0) ? Real(0) : x; }
#endif

// x * inv, for inv a power of two no greater than 1 (a full window's 1/n):
// the same bits as the multiplication. On binary32 R, where x and the
// product are normal numbers, the product is x with its exponent lowered
// (exact: no rounding), done on the bits; a zero, subnormal, infinite or
// NaN x, or a product below the normal range, is multiplied. On an 8-bit
// MCU that is a few instructions instead of the float routine's 130 or
// so cycles (the rocket's nav reads its 16-sample average every step).
#if FSW_REAL_IS_FLOAT && defined(__AVR__)
// In a few lines of assembly around the multiplication's call, its
// operands where the routine takes them (the compiler's version, on the
// bytes below, took 28 B more of flash in roll_avg_mean, and one on the
// 32-bit pattern shifts by 23 a bit at a time).
inline Real scale_pow2(Real x, Real inv) {
    register Real r asm("r22") = x;  // avr-gcc's float argument and result registers
    register Real v asm("r18") = inv;
    __asm__(
        "mov  r26, r24\n\t"  // x's biased exponent: byte 3's low seven bits and byte 2's top one
        "lsl  r26\n\t"
        "mov  r26, r25\n\t"
        "rol  r26\n\t"
        "mov  r27, r20\n\t"  // inv's, then k = 127 - it (inv = 2^-k)
        "lsl  r27\n\t"
        "mov  r27, r21\n\t"
        "rol  r27\n\t"
        "subi r27, 127\n\t"
        "neg  r27\n\t"
        "cpi  r26, 0xFF\n\t"  // infinite or NaN: multiplied
        "breq 1f\n\t"
        "cp   r27, r26\n\t"  // a product below the normal range, or x 0 or subnormal: multiplied
        "brsh 1f\n\t"
        "sub  r26, r27\n\t"  // the product's exponent, into its two places
        "lsl  r24\n\t"
        "lsr  r26\n\t"
        "ror  r24\n\t"
        "bst  r25, 7\n\t"  // the sign kept
        "mov  r25, r26\n\t"
        "bld  r25, 7\n\t"
        "rjmp 2f\n\t"
        "1:\n\t"
        "%~call __mulsf3\n\t"
        "2:\n\t"
        : "+r"(r), "+r"(v)
        :
        : "r26", "r27", "r30", "r31", "r0");
    return r;
}
#elif FSW_REAL_IS_FLOAT
inline Real scale_pow2(Real x, Real inv) {
    uint8_t b[4], i[4];  // little-endian: byte 3 the sign and the exponent's high seven bits, byte 2's top bit its low one
    memcpy(b, &x, sizeof b);
    memcpy(i, &inv, sizeof i);
    const uint8_t e = static_cast<uint8_t>((b[3] << 1) | (b[2] >> 7));  // x's biased exponent
    const uint8_t k = static_cast<uint8_t>(127u - static_cast<uint8_t>((i[3] << 1) | (i[2] >> 7)));  // inv = 2^-k
    if (e != 0xFFu && e > k) {
        const uint8_t f = static_cast<uint8_t>(e - k);
        b[3] = static_cast<uint8_t>((b[3] & 0x80u) | (f >> 1));
        b[2] = static_cast<uint8_t>((b[2] & 0x7Fu) | (f << 7));
        memcpy(&x, b, sizeof x);
        return x;
    }
    return x * inv;
}
#else
inline Real scale_pow2(Real x, Real inv) { return x * inv; }
#endif

// ---- state structs: all-zero is "no samples yet", so they live in .bss ----
// Templates on the index type I: uint8_t for windows of up to 255 samples
// (the typed wrappers below pick it: on an 8-bit MCU a byte index is half
// the RAM and fewer instructions), WinIdx above. The plain names (RollAvg,
// ...) are the WinIdx ones.

// roll_avg: sum of the finite samples = base + fresh, the infinite ones
// counted; see docs/runtime.md for the exact order.
template <typename I>
struct RollAvgS {
    Real base;
    Real fresh;
    I count;  // samples held, 0..n
    I head;   // ring position of the next sample
    I pinf;   // +inf samples held
    I ninf;   // -inf samples held
};

// roll_min / roll_max: a monotonic deque of (value, sequence number).
template <typename I>
struct RollExtS {
    I next;   // sequence number of the next sample (wraps)
    I front;  // deque front (the extreme) position
    I tail;   // position after the deque back
    I size;   // entries in the deque (0 only before the first sample)
};

// roll_median: a ring of raw samples plus the same samples kept sorted.
template <typename I>
struct RollMedianS {
    I count;
    I head;
};

// roll_min, roll_max and roll_range of one argument over one N, kept
// together: a ring of the last N samples, each extreme found by a scan where
// it is read (roll_ring_extreme).
template <typename I>
struct RollRingS {
    I count;  // samples held, 0..n: ring positions 0..count-1
    I head;   // ring position of the next sample
};

typedef RollAvgS<WinIdx> RollAvg;
typedef RollExtS<WinIdx> RollExt;
typedef RollMedianS<WinIdx> RollMedian;

// The index type of a window of N samples.
template <uint32_t N>
struct WinIdxFor {
    typedef typename conditional_t<(N <= 0xFFu), uint8_t, WinIdx>::type type;
};

// ---- non-template core (one copy in flash per index type in use) ----------
// `n` is the window size N (1..FSW_WINDOW_MAX_N, 1..255 for uint8_t);
// arrays hold n entries. Instantiated in fsw_window.cpp for uint8_t and WinIdx.
template <typename T>
struct same_t {
    typedef T type;
};

template <typename I>
void roll_avg_add(Real x, RollAvgS<I>& w, Real* ring, typename same_t<I>::type n);
template <typename I>
inline void roll_avg_push(RollAvgS<I>& w, Real* ring, typename same_t<I>::type n, Real x) {
    roll_avg_add<I>(x, w, ring, n);
}
// The mean while the window holds an infinite sample: that infinity, or NaN
// with both (inf + -inf). Only called when pinf or ninf is not 0.
template <typename I>
inline Real roll_avg_infinite(const RollAvgS<I>& w) {
    const Real inf = static_cast<Real>(__builtin_inf());
    return w.ninf == 0 ? inf : w.pinf == 0 ? -inf : static_cast<Real>(__builtin_nan(""));
}
template <typename I>
inline Real roll_avg_value(const RollAvgS<I>& w) {
    if ((w.pinf | w.ninf) != 0) return roll_avg_infinite(w);
    const Real n = sizeof(I) <= 2 ? real_from_U16(w.count) : real_from_U32(w.count);
    return w.count == 0 ? Real(0) : (w.base + w.fresh) / n;
}

// The value of a window of n samples: roll_avg_value, but times `inv` (1/n,
// exact) instead of divided by n once the window is full when inv is not 0
// (n a power of two: the same quotient, no division on the MCU). Out of line
// on AVR, where the float calls inline cost flash at every use.
#if defined(__AVR__)
template <typename I>
FSW_NOINLINE Real roll_avg_mean(const RollAvgS<I>& w, typename same_t<I>::type n, Real inv);
#else
template <typename I>
inline Real roll_avg_mean(const RollAvgS<I>& w, typename same_t<I>::type n, Real inv) {
    if (inv != 0 && w.count == n && (w.pinf | w.ninf) == 0) return scale_pow2(w.base + w.fresh, inv);
    return roll_avg_value(w);
}
#endif

template <typename I>
void roll_max_push(RollExtS<I>& w, Real* vals, I* seqs, typename same_t<I>::type n, Real x);
template <typename I>
void roll_min_push(RollExtS<I>& w, Real* vals, I* seqs, typename same_t<I>::type n, Real x);
template <typename I>
inline Real roll_ext_value(const RollExtS<I>& w, const Real* vals) {
    return w.size == 0 ? Real(0) : vals[w.front];
}

template <typename I>
void roll_median_push(RollMedianS<I>& w, Real* ring, Real* sorted, typename same_t<I>::type n, Real x);
template <typename I>
Real roll_median_value(const RollMedianS<I>& w, const Real* sorted);

template <typename I>
void roll_ring_push(RollRingS<I>& w, Real* ring, typename same_t<I>::type n, Real x);
// The least (is_max false) or the greatest of the samples held; 0 before the first.
template <typename I>
Real roll_ring_extreme(const RollRingS<I>& w, const Real* ring, bool is_max);

// ---- typed wrappers: what generated code declares, one per call site -------
//     static fsw::RollMedianN<100> w_tank_sm_18;   // zero-initialised
//     w_tank_sm_18.push(x);  ...  r = w_tank_sm_18.value();

#define FSW_WINDOW_CHECK_N(N) \
    static_assert((N) >= 1 && (N) <= FSW_WINDOW_MAX_N, "window size N out of range")

template <uint32_t N>
struct RollAvgN {
    FSW_WINDOW_CHECK_N(N);
    typedef typename WinIdxFor<N>::type I;
    RollAvgS<I> s;
    Real ring[N];
    void push(Real x) { roll_avg_push<I>(s, ring, static_cast<I>(N), x); }
    // A full window of a power-of-two N multiplies by 1/N, a constant R
    // holds exactly: the same bits as the division, with no division routine.
    Real value() const { return roll_avg_mean<I>(s, static_cast<I>(N), (N & (N - 1)) == 0 ? Real(1) / Real(N) : 0); }
};

template <uint32_t N>
struct RollMaxN {
    FSW_WINDOW_CHECK_N(N);
    typedef typename WinIdxFor<N>::type I;
    RollExtS<I> s;
    Real vals[N];
    I seqs[N];
    void push(Real x) { roll_max_push<I>(s, vals, seqs, static_cast<I>(N), x); }
    Real value() const { return roll_ext_value(s, vals); }
};

template <uint32_t N>
struct RollMinN {
    FSW_WINDOW_CHECK_N(N);
    typedef typename WinIdxFor<N>::type I;
    RollExtS<I> s;
    Real vals[N];
    I seqs[N];
    void push(Real x) { roll_min_push<I>(s, vals, seqs, static_cast<I>(N), x); }
    Real value() const { return roll_ext_value(s, vals); }
};

// roll_range = roll_max - roll_min over the same samples.
template <uint32_t N>
struct RollRangeN {
    RollMaxN<N> hi;
    RollMinN<N> lo;
    void push(Real x) {
        hi.push(x);
        lo.push(x);
    }
    Real value() const { return hi.value() - lo.value(); }
};

// roll_min, roll_max and roll_range of one argument over the same N (a
// machine's windows of one argument, sampled together: the generator
// declares one of these for them): one ring of the last N samples, the
// extremes found by a scan of it where read. The same values bit for bit as
// a RollMinN's, a RollMaxN's and a RollRangeN's of those samples (stored as
// window_sample makes them: no NaN and no -0, so the order is total and
// equal samples are the same bits), in 4N + 2 bytes (N <= 255, binary32 R)
// where a RollMinN and a RollMaxN take 10N + 8; a read costs a pass over
// the N samples, so the generator keeps it for small N.
template <uint32_t N>
struct RollMinMaxN {
    FSW_WINDOW_CHECK_N(N);
    typedef typename WinIdxFor<N>::type I;
    RollRingS<I> s;
    Real ring[N];
    void push(Real x) { roll_ring_push<I>(s, ring, static_cast<I>(N), x); }
    // (Not min() and max(): Arduino.h defines those names as macros.)
    Real least() const { return roll_ring_extreme<I>(s, ring, false); }
    Real greatest() const { return roll_ring_extreme<I>(s, ring, true); }
    Real range() const { return greatest() - least(); }
};

template <uint32_t N>
struct RollMedianN {
    FSW_WINDOW_CHECK_N(N);
    typedef typename WinIdxFor<N>::type I;
    RollMedianS<I> s;
    Real ring[N];
    Real sorted[N];
    void push(Real x) { roll_median_push<I>(s, ring, sorted, static_cast<I>(N), x); }
    Real value() const { return roll_median_value(s, sorted); }
};

}  // namespace fsw

#endif  // FSW_WINDOW_H
