// Rolling window updates: O(1) average, O(1) amortised min/max (monotonic
// deques), and a sorted array kept by binary search + one memmove (median).
#include "fsw_window.h"

namespace fsw {

template <typename I>
static inline I step_fwd(I i, I n) { return static_cast<I>(i + 1u == n ? 0u : i + 1u); }
template <typename I>
static inline I step_back(I i, I n) { return static_cast<I>(i == 0 ? n - 1u : i - 1u); }

#if FSW_REAL_IS_FLOAT
// On binary32 R the tests below are made on the bits, with the same
// results as the float comparisons and no float library call (on an 8-bit
// MCU each is a routine): the extreme deques' ordering (of samples, never
// NaN or -0: the key orders them as the floats) and roll_avg_mean's test
// of 1/n (window_sample, fsw_window.h, likewise).
static inline uint32_t real_bits(Real x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}
static inline uint32_t order_key(Real x) {
    const uint32_t b = real_bits(x);
    return (b & 0x80000000UL) != 0 ? ~b : b | 0x80000000UL;
}
static inline bool nonzero(Real x) { return (real_bits(x) & 0x7FFFFFFFUL) != 0; }
// +1 for +inf, -1 for -inf, 0 for any other sample (never NaN).
static inline int8_t infinity_sign(Real x) {
    const uint32_t b = real_bits(x);
    return (b & 0x7FFFFFFFUL) != 0x7F800000UL ? 0 : (b & 0x80000000UL) != 0 ? -1 : 1;
}
#else
static inline Real order_key(Real x) { return x; }
static inline bool nonzero(Real x) { return x != 0; }
static inline int8_t infinity_sign(Real x) {
    const Real inf = static_cast<Real>(__builtin_inf());
    return x == inf ? 1 : x == -inf ? -1 : 0;
}
#endif

template <typename I>
void roll_avg_add(Real x, RollAvgS<I>& w, Real* ring, typename same_t<I>::type n) {
    // The sample goes into its slot first and is read back from there: the
    // same operations in the same order, with fewer values to keep across
    // the float routines' calls (on AVR no call of the register-saving
    // routine around them).
    // An infinite sample is counted, never summed: subtracting it from a sum
    // that holds it would leave NaN (inf - inf) in `base` until the next lap.
    Real* const slot = ring + w.head;
    const Real oldest = *slot;
    *slot = window_sample(x);
    if (w.count == n) {  // the oldest sample leaves
        const int8_t inf = infinity_sign(oldest);
        if (inf == 0) w.base = w.base - oldest;
        else if (inf > 0) --w.pinf;
        else --w.ninf;
    } else {
        ++w.count;
    }
    const int8_t inf = infinity_sign(*slot);
    if (inf == 0) w.fresh = w.fresh + *slot;
    else if (inf > 0) ++w.pinf;
    else ++w.ninf;
    w.head = step_fwd(w.head, n);
    if (w.head == 0) {
        // A full lap: `fresh` is the in-order sum of exactly the samples in
        // the window, so it replaces `base` and any rounding drift is gone.
        w.base = w.fresh;
        w.fresh = 0;
    }
}

template <typename I>
static void ext_push(RollExtS<I>& w, Real* vals, I* seqs, I n, Real x, bool is_max) {
    x = window_sample(x);
    const I seq = w.next;
    // The front leaves once it is n samples old (at most one per push; ages
    // are below 2^bits of I, as n is, so the wrapping difference is exact).
    if (w.size != 0 && static_cast<I>(seq - seqs[w.front]) >= n) {
        w.front = step_fwd(w.front, n);
        --w.size;
    }
    // Drop entries the new sample dominates (ties: the newer one stays).
    const auto kx = order_key(x);
    while (w.size != 0) {
        const I back = step_back(w.tail, n);
        const auto kb = order_key(vals[back]);
        if (is_max ? (kb > kx) : (kb < kx)) break;
        w.tail = back;
        --w.size;
    }
    vals[w.tail] = x;
    seqs[w.tail] = seq;
    w.tail = step_fwd(w.tail, n);
    ++w.size;
    w.next = static_cast<I>(seq + 1u);
}

template <typename I>
void roll_max_push(RollExtS<I>& w, Real* vals, I* seqs, typename same_t<I>::type n, Real x) {
    ext_push<I>(w, vals, seqs, n, x, true);
}

template <typename I>
void roll_min_push(RollExtS<I>& w, Real* vals, I* seqs, typename same_t<I>::type n, Real x) {
    ext_push<I>(w, vals, seqs, n, x, false);
}

template <typename I>
void roll_ring_push(RollRingS<I>& w, Real* ring, typename same_t<I>::type n, Real x) {
    ring[w.head] = window_sample(x);
    w.head = step_fwd(w.head, n);
    if (w.count < n) ++w.count;
}

template <typename I>
Real roll_ring_extreme(const RollRingS<I>& w, const Real* ring, bool is_max) {
    if (w.count == 0) return Real(0);
    I best = 0;
    auto kb = order_key(ring[0]);
    for (I i = 1; i < w.count; ++i) {
        const auto k = order_key(ring[i]);
        if (is_max ? (k > kb) : (k < kb)) {
            kb = k;
            best = i;
        }
    }
    return ring[best];
}

// First index in [lo, hi) whose value is >= x (x > value: keep going right).
template <typename I>
static I lower_bound(const Real* s, I lo, I hi, Real x) {
    while (lo < hi) {
        const I mid = static_cast<I>(lo + (hi - lo) / 2u);
        if (s[mid] < x) lo = static_cast<I>(mid + 1u); else hi = mid;
    }
    return lo;
}

// First index in [lo, hi) whose value is > x.
template <typename I>
static I upper_bound(const Real* s, I lo, I hi, Real x) {
    while (lo < hi) {
        const I mid = static_cast<I>(lo + (hi - lo) / 2u);
        if (s[mid] <= x) lo = static_cast<I>(mid + 1u); else hi = mid;
    }
    return lo;
}

template <typename I>
void roll_median_push(RollMedianS<I>& w, Real* ring, Real* sorted, typename same_t<I>::type n, Real x) {
    x = window_sample(x);
    if (w.count < n) {  // filling: insert only
        ring[w.head] = x;
        w.head = step_fwd(w.head, n);
        const I j = upper_bound<I>(sorted, 0, w.count, x);
        memmove(sorted + j + 1, sorted + j, (w.count - j) * sizeof(Real));
        sorted[j] = x;
        ++w.count;
        return;
    }
    const Real old = ring[w.head];
    ring[w.head] = x;
    w.head = step_fwd(w.head, n);
    // Samples are normalised, so equal values are identical: any copy of
    // `old` may be the one removed.
    const I i = lower_bound<I>(sorted, 0, n, old);
    if (x >= old) {
        // Shift the run (old, x) left by one and put x at its end.
        const I j = lower_bound<I>(sorted, static_cast<I>(i + 1u), n, x);
        memmove(sorted + i, sorted + i + 1, (j - i - 1u) * sizeof(Real));
        sorted[j - 1u] = x;
    } else {
        // Shift the run (x, old) right by one and put x at its start.
        const I j = upper_bound<I>(sorted, 0, i, x);
        memmove(sorted + j + 1, sorted + j, (i - j) * sizeof(Real));
        sorted[j] = x;
    }
}

template <typename I>
Real roll_median_value(const RollMedianS<I>& w, const Real* sorted) {
    if (w.count == 0) return 0;
    const I mid = static_cast<I>(w.count / 2u);
    if ((w.count & 1u) != 0) return sorted[mid];
    const Real a = sorted[mid - 1u];
    const Real b = sorted[mid];
    return a + (b - a) / 2;
}

#if defined(__AVR__)
template <typename I>
Real roll_avg_mean(const RollAvgS<I>& w, typename same_t<I>::type n, Real inv) {
    if (w.count == n && nonzero(inv) && (w.pinf | w.ninf) == 0) return scale_pow2(w.base + w.fresh, inv);
    return roll_avg_value(w);
}
template Real roll_avg_mean<uint8_t>(const RollAvgS<uint8_t>&, uint8_t, Real);
template Real roll_avg_mean<WinIdx>(const RollAvgS<WinIdx>&, WinIdx, Real);
#endif

// The two index types in use: bytes for windows of up to 255 samples, WinIdx.
#define FSW_WINDOW_INSTANCES(I)                                                      \
    template void roll_avg_add<I>(Real, RollAvgS<I>&, Real*, I);                    \
    template void roll_max_push<I>(RollExtS<I>&, Real*, I*, I, Real);                \
    template void roll_min_push<I>(RollExtS<I>&, Real*, I*, I, Real);                \
    template void roll_ring_push<I>(RollRingS<I>&, Real*, I, Real);                  \
    template Real roll_ring_extreme<I>(const RollRingS<I>&, const Real*, bool);      \
    template void roll_median_push<I>(RollMedianS<I>&, Real*, Real*, I, Real);       \
    template Real roll_median_value<I>(const RollMedianS<I>&, const Real*);
FSW_WINDOW_INSTANCES(uint8_t)
FSW_WINDOW_INSTANCES(WinIdx)
#undef FSW_WINDOW_INSTANCES

}  // namespace fsw
