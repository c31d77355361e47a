// Rolling window updates: O(1) average, O(1) amortised min/max (monotonic
// deques), and a sorted array kept by binary search + one memmove (median).
#include "fsw_window.h"

namespace fsw {

static inline WinIdx step_fwd(WinIdx i, WinIdx n) { return static_cast<WinIdx>(i + 1u == n ? 0u : i + 1u); }
static inline WinIdx step_back(WinIdx i, WinIdx n) { return static_cast<WinIdx>(i == 0 ? n - 1u : i - 1u); }

void roll_avg_push(RollAvg& w, Real* ring, WinIdx n, Real x) {
    x = window_sample(x);
    if (w.count == n) {
        w.base = w.base - ring[w.head];  // the oldest sample leaves
    } else {
        ++w.count;
    }
    ring[w.head] = x;
    w.fresh = w.fresh + x;
    w.head = step_fwd(w.head, n);
    if (w.head == 0) {
        // A full lap: `fresh` is the in-order sum of exactly the samples in
        // the window, so it replaces `base` and any rounding drift is gone.
        w.base = w.fresh;
        w.fresh = 0;
    }
}

static void ext_push(RollExt& w, Real* vals, WinIdx* seqs, WinIdx n, Real x, bool is_max) {
    x = window_sample(x);
    const WinIdx seq = w.next;
    // The front leaves once it is n samples old (at most one per push).
    if (w.size != 0 && static_cast<WinIdx>(seq - seqs[w.front]) >= n) {
        w.front = step_fwd(w.front, n);
        --w.size;
    }
    // Drop entries the new sample dominates (ties: the newer one stays).
    while (w.size != 0) {
        const WinIdx back = step_back(w.tail, n);
        const Real b = vals[back];
        if (is_max ? (b > x) : (b < x)) break;
        w.tail = back;
        --w.size;
    }
    vals[w.tail] = x;
    seqs[w.tail] = seq;
    w.tail = step_fwd(w.tail, n);
    ++w.size;
    w.next = static_cast<WinIdx>(seq + 1u);
}

void roll_max_push(RollExt& w, Real* vals, WinIdx* seqs, WinIdx n, Real x) {
    ext_push(w, vals, seqs, n, x, true);
}

void roll_min_push(RollExt& w, Real* vals, WinIdx* seqs, WinIdx n, Real x) {
    ext_push(w, vals, seqs, n, x, false);
}

// First index in [lo, hi) whose value is >= x (x > value: keep going right).
static WinIdx lower_bound(const Real* s, WinIdx lo, WinIdx hi, Real x) {
    while (lo < hi) {
        const WinIdx mid = static_cast<WinIdx>(lo + (hi - lo) / 2u);
        if (s[mid] < x) lo = static_cast<WinIdx>(mid + 1u); else hi = mid;
    }
    return lo;
}

// First index in [lo, hi) whose value is > x.
static WinIdx upper_bound(const Real* s, WinIdx lo, WinIdx hi, Real x) {
    while (lo < hi) {
        const WinIdx mid = static_cast<WinIdx>(lo + (hi - lo) / 2u);
        if (s[mid] <= x) lo = static_cast<WinIdx>(mid + 1u); else hi = mid;
    }
    return lo;
}

void roll_median_push(RollMedian& w, Real* ring, Real* sorted, WinIdx n, Real x) {
    x = window_sample(x);
    if (w.count < n) {  // filling: insert only
        ring[w.head] = x;
        w.head = step_fwd(w.head, n);
        const WinIdx j = upper_bound(sorted, 0, w.count, x);
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
    const WinIdx i = lower_bound(sorted, 0, n, old);
    if (x >= old) {
        // Shift the run (old, x) left by one and put x at its end.
        const WinIdx j = lower_bound(sorted, static_cast<WinIdx>(i + 1u), n, x);
        memmove(sorted + i, sorted + i + 1, (j - i - 1u) * sizeof(Real));
        sorted[j - 1u] = x;
    } else {
        // Shift the run (x, old) right by one and put x at its start.
        const WinIdx j = upper_bound(sorted, 0, i, x);
        memmove(sorted + j + 1, sorted + j, (i - j) * sizeof(Real));
        sorted[j] = x;
    }
}

Real roll_median_value(const RollMedian& w, const Real* sorted) {
    if (w.count == 0) return 0;
    const WinIdx mid = static_cast<WinIdx>(w.count / 2u);
    if ((w.count & 1u) != 0) return sorted[mid];
    const Real a = sorted[mid - 1u];
    const Real b = sorted[mid];
    return a + (b - a) / 2;
}

}  // namespace fsw
