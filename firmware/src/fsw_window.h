// Rolling windows (spec 4.4/4.6): roll_avg, roll_min, roll_max, roll_range,
// roll_median over the last N samples, in caller-provided static storage.
// The exact algorithms (bit for bit) are written down in docs/runtime.md.
#ifndef FSW_WINDOW_H
#define FSW_WINDOW_H

#include "fsw_types.h"

namespace fsw {

// A sample as a window stores it: NaN -> +0 (spec), and -0 -> +0 so that
// equal samples are identical bit patterns (no sign-of-zero ambiguity).
inline Real window_sample(Real x) { return (x != x || x == 0) ? Real(0) : x; }

// ---- state structs: all-zero is "no samples yet", so they live in .bss ----

// roll_avg: sum = base + fresh; see docs/runtime.md for the exact order.
struct RollAvg {
    Real base;
    Real fresh;
    WinIdx count;  // samples held, 0..n
    WinIdx head;   // ring position of the next sample
};

// roll_min / roll_max: a monotonic deque of (value, sequence number).
struct RollExt {
    WinIdx next;   // sequence number of the next sample (wraps)
    WinIdx front;  // deque front (the extreme) position
    WinIdx tail;   // position after the deque back
    WinIdx size;   // entries in the deque (0 only before the first sample)
};

// roll_median: a ring of raw samples plus the same samples kept sorted.
struct RollMedian {
    WinIdx count;
    WinIdx head;
};

// ---- non-template core (one copy in flash whatever the window sizes) -------
// `n` is the window size N (1..FSW_WINDOW_MAX_N); arrays hold n entries.

void roll_avg_push(RollAvg& w, Real* ring, WinIdx n, Real x);
inline Real roll_avg_value(const RollAvg& w) {
    return w.count == 0 ? Real(0) : (w.base + w.fresh) / static_cast<Real>(w.count);
}

void roll_max_push(RollExt& w, Real* vals, WinIdx* seqs, WinIdx n, Real x);
void roll_min_push(RollExt& w, Real* vals, WinIdx* seqs, WinIdx n, Real x);
inline Real roll_ext_value(const RollExt& w, const Real* vals) {
    return w.size == 0 ? Real(0) : vals[w.front];
}

void roll_median_push(RollMedian& w, Real* ring, Real* sorted, WinIdx n, Real x);
Real roll_median_value(const RollMedian& w, const Real* sorted);

// ---- typed wrappers: what generated code declares, one per call site -------
//     static fsw::RollMedianN<100> w_tank_sm_18;   // zero-initialised
//     w_tank_sm_18.push(x);  ...  r = w_tank_sm_18.value();

#define FSW_WINDOW_CHECK_N(N) \
    static_assert((N) >= 1 && (N) <= FSW_WINDOW_MAX_N, "window size N out of range")

template <uint32_t N>
struct RollAvgN {
    FSW_WINDOW_CHECK_N(N);
    RollAvg s;
    Real ring[N];
    void push(Real x) { roll_avg_push(s, ring, static_cast<WinIdx>(N), x); }
    Real value() const { return roll_avg_value(s); }
};

template <uint32_t N>
struct RollMaxN {
    FSW_WINDOW_CHECK_N(N);
    RollExt s;
    Real vals[N];
    WinIdx seqs[N];
    void push(Real x) { roll_max_push(s, vals, seqs, static_cast<WinIdx>(N), x); }
    Real value() const { return roll_ext_value(s, vals); }
};

template <uint32_t N>
struct RollMinN {
    FSW_WINDOW_CHECK_N(N);
    RollExt s;
    Real vals[N];
    WinIdx seqs[N];
    void push(Real x) { roll_min_push(s, vals, seqs, static_cast<WinIdx>(N), x); }
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

template <uint32_t N>
struct RollMedianN {
    FSW_WINDOW_CHECK_N(N);
    RollMedian s;
    Real ring[N];
    Real sorted[N];
    void push(Real x) { roll_median_push(s, ring, sorted, static_cast<WinIdx>(N), x); }
    Real value() const { return roll_median_value(s, sorted); }
};

}  // namespace fsw

#endif  // FSW_WINDOW_H
