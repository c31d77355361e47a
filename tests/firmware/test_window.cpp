// Scenario: rolling windows against a brute-force reference: window 1, even
// and odd medians, NaN samples, fewer samples than N, duplicates, +-inf,
// and roll_avg's documented operation order (docs/runtime.md).
#include "test_support.h"

using namespace fsw;

void setUp(void) {}
void tearDown(void) {}

#if defined(__AVR__)
static const uint16_t kMaxN = 16;
#else
static const uint16_t kMaxN = 128;
#endif

// Brute-force reference: the last n samples, oldest first.
struct Ref {
    Real s[kMaxN];
    uint16_t n, count;
    void reset(uint16_t size) { n = size; count = 0; }
    void push(Real x) {
        x = (x != x || x == 0) ? Real(0) : x;
        if (count == n) {
            memmove(s, s + 1, (n - 1u) * sizeof(Real));
            s[n - 1u] = x;
        } else {
            s[count++] = x;
        }
    }
    Real max() const {
        if (count == 0) return 0;
        Real m = s[0];
        for (uint16_t i = 1; i < count; ++i) if (s[i] >= m) m = s[i];
        return m;
    }
    Real min() const {
        if (count == 0) return 0;
        Real m = s[0];
        for (uint16_t i = 1; i < count; ++i) if (s[i] <= m) m = s[i];
        return m;
    }
    Real median() const {
        if (count == 0) return 0;
        Real t[kMaxN];
        memcpy(t, s, count * sizeof(Real));
        for (uint16_t i = 1; i < count; ++i)  // insertion sort
            for (uint16_t j = i; j > 0 && t[j - 1u] > t[j]; --j) { const Real k = t[j]; t[j] = t[j - 1u]; t[j - 1u] = k; }
        if (count & 1u) return t[count / 2u];
        const Real a = t[count / 2u - 1u], b = t[count / 2u];
        return a + (b - a) / 2;
    }
    Real mean() const {
        if (count == 0) return 0;
        Real sum = 0;
        for (uint16_t i = 0; i < count; ++i) sum += s[i];
        return sum / static_cast<Real>(count);
    }
};

// Every kind of window over storage for kMaxN samples, run at size n.
struct All {
    RollAvg avg; Real avg_ring[kMaxN];
    RollExt mx; Real mx_v[kMaxN]; WinIdx mx_s[kMaxN];
    RollExt mn; Real mn_v[kMaxN]; WinIdx mn_s[kMaxN];
    RollMedian med; Real med_ring[kMaxN]; Real med_sorted[kMaxN];
    uint16_t n;
    void reset(uint16_t size) {
        memset(this, 0, sizeof *this);
        n = size;
    }
    void push(Real x) {
        roll_avg_push(avg, avg_ring, n, x);
        roll_max_push(mx, mx_v, mx_s, n, x);
        roll_min_push(mn, mn_v, mn_s, n, x);
        roll_median_push(med, med_ring, med_sorted, n, x);
    }
};

static All w;
static Ref ref;

static uint32_t rng_state = 12345u;
static uint32_t rng() {
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

static Real nan_real() { volatile Real z = 0; return z / z; }
static const Real kInf = static_cast<Real>(__builtin_inf());

static bool close_enough(Real expected, Real got) {
    if (expected != expected || got != got) return expected != expected && got != got;
    if (expected == got) return true;  // infinities too
    if (expected - expected != 0 || got - got != 0) return false;  // an infinity and another value
    Real d = expected - got;
    if (d < 0) d = -d;
    Real m = expected < 0 ? -expected : expected;
    return d <= (m + 1) * Real(1e-5);
}

static void check_against_ref(void) {
    ASSERT_REAL_SAME(ref.max(), roll_ext_value(w.mx, w.mx_v));
    ASSERT_REAL_SAME(ref.min(), roll_ext_value(w.mn, w.mn_v));
    ASSERT_REAL_SAME(ref.median(), roll_median_value(w.med, w.med_sorted));
    TEST_ASSERT_TRUE_MESSAGE(close_enough(ref.mean(), roll_avg_value(w.avg)), "roll_avg far from the mean");
}

static void run_sequence(uint16_t n, uint16_t len, uint8_t kind) {
    w.reset(n);
    ref.reset(n);
    check_against_ref();  // no samples: all zero
    for (uint16_t i = 0; i < len; ++i) {
        Real x;
        switch (kind) {
            case 0: x = static_cast<Real>(static_cast<int32_t>(rng() % 7u) - 3); break;   // many ties
            case 1: x = static_cast<Real>(static_cast<int32_t>(rng() % 20001u) - 10000) / 7; break;
            case 2: x = static_cast<Real>(i); break;                                       // rising
            case 3: x = static_cast<Real>(len - i); break;                                 // falling
            default: {                                                                     // specials
                const uint32_t r = rng() % 8u;
                x = r == 0 ? nan_real() : r == 1 ? kInf : r == 2 ? -kInf : r == 3 ? -Real(0)
                  : static_cast<Real>(static_cast<int32_t>(rng() % 11u) - 5);
            }
        }
        w.push(x);
        ref.push(x);
        ASSERT_REAL_SAME(ref.max(), roll_ext_value(w.mx, w.mx_v));
        ASSERT_REAL_SAME(ref.min(), roll_ext_value(w.mn, w.mn_v));
        ASSERT_REAL_SAME(ref.median(), roll_median_value(w.med, w.med_sorted));
        // With +-inf among the samples too: the mean of the window's samples
        // (inf, -inf or NaN while it holds infinities), not NaN left behind
        // by an infinite sample that has left it.
        TEST_ASSERT_TRUE_MESSAGE(close_enough(ref.mean(), roll_avg_value(w.avg)), "roll_avg far from the mean");
    }
}

static void test_no_samples_gives_zero(void) {
    w.reset(5);
    ASSERT_REAL_SAME(Real(0), roll_avg_value(w.avg));
    ASSERT_REAL_SAME(Real(0), roll_ext_value(w.mx, w.mx_v));
    ASSERT_REAL_SAME(Real(0), roll_ext_value(w.mn, w.mn_v));
    ASSERT_REAL_SAME(Real(0), roll_median_value(w.med, w.med_sorted));
}

static void test_window_of_one_is_the_last_sample(void) {
    w.reset(1);
    const Real xs[] = {5, -3, Real(2.5), 7, 7, -1};
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; ++i) {
        w.push(xs[i]);
        ASSERT_REAL_SAME(xs[i], roll_avg_value(w.avg));
        ASSERT_REAL_SAME(xs[i], roll_ext_value(w.mx, w.mx_v));
        ASSERT_REAL_SAME(xs[i], roll_ext_value(w.mn, w.mn_v));
        ASSERT_REAL_SAME(xs[i], roll_median_value(w.med, w.med_sorted));
    }
}

static void test_fewer_samples_than_n_use_the_samples_so_far(void) {
    w.reset(10);
    w.push(4);
    ASSERT_REAL_SAME(Real(4), roll_avg_value(w.avg));
    ASSERT_REAL_SAME(Real(4), roll_median_value(w.med, w.med_sorted));
    w.push(1);
    ASSERT_REAL_SAME(Real(2.5), roll_avg_value(w.avg));
    ASSERT_REAL_SAME(Real(2.5), roll_median_value(w.med, w.med_sorted));  // even: 1 + (4-1)/2
    ASSERT_REAL_SAME(Real(4), roll_ext_value(w.mx, w.mx_v));
    ASSERT_REAL_SAME(Real(1), roll_ext_value(w.mn, w.mn_v));
    w.push(10);
    ASSERT_REAL_SAME(Real(4), roll_median_value(w.med, w.med_sorted));    // odd: middle
    ASSERT_REAL_SAME(Real(5), roll_avg_value(w.avg));
}

static void test_even_median_is_a_plus_half_the_difference(void) {
    w.reset(4);
    w.push(1);
    w.push(2);
    w.push(Real(2.5));
    w.push(100);
    ASSERT_REAL_SAME(Real(2.25), roll_median_value(w.med, w.med_sorted));
    w.push(-kInf);  // window -inf? no: 2, 2.5, 100, -inf -> middle 2, 2.5
    ASSERT_REAL_SAME(Real(2.25), roll_median_value(w.med, w.med_sorted));
    w.push(kInf);   // 2.5, 100, -inf, inf -> middle 2.5, 100
    ASSERT_REAL_SAME(Real(51.25), roll_median_value(w.med, w.med_sorted));
    w.push(-kInf);  // 100, -inf, inf, -inf -> middle -inf, 100: -inf + inf/2 = -inf + inf = NaN
    TEST_ASSERT_TRUE(roll_median_value(w.med, w.med_sorted) != roll_median_value(w.med, w.med_sorted));
}

static void test_nan_samples_are_stored_as_zero(void) {
    w.reset(3);
    w.push(nan_real());
    ASSERT_REAL_SAME(Real(0), roll_avg_value(w.avg));
    ASSERT_REAL_SAME(Real(0), roll_ext_value(w.mx, w.mx_v));
    w.push(-5);
    w.push(nan_real());
    ASSERT_REAL_SAME(Real(0), roll_ext_value(w.mx, w.mx_v));
    ASSERT_REAL_SAME(Real(-5), roll_ext_value(w.mn, w.mn_v));
    ASSERT_REAL_SAME(Real(0), roll_median_value(w.med, w.med_sorted));
    w.push(-Real(0));  // -0 is stored as +0: results carry no sign of zero
    TEST_ASSERT_EQUAL_HEX8(0, reinterpret_cast<const uint8_t*>(&w.med_sorted[2])[sizeof(Real) - 1]);
}

static void test_random_sequences_match_brute_force(void) {
    const uint16_t sizes[] = {1, 2, 3, 4, 7, 16, kMaxN};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; ++s) {
        for (uint8_t kind = 0; kind < 5; ++kind) {
            run_sequence(sizes[s], static_cast<uint16_t>(3u * sizes[s] + 17u), kind);
        }
    }
}

// roll_avg follows the documented order of operations exactly (the Python
// reference mirrors it); here it is re-derived from the sample list.
static void test_avg_follows_the_documented_operation_order(void) {
    const uint16_t n = 7;
    Real samples[40];
    w.reset(n);
    for (uint16_t k = 0; k < 40; ++k) {
        samples[k] = static_cast<Real>(static_cast<int32_t>(rng() % 100000u)) / 997;
        w.push(samples[k]);
        // base = the in-order sum of the last complete lap, minus the samples
        // that left since, one by one; fresh = the in-order sum of this lap.
        const uint16_t pushed = static_cast<uint16_t>(k + 1u);
        const uint16_t lap_start = static_cast<uint16_t>(pushed - pushed % n);  // first sample of this lap
        Real base = 0, fresh = 0;
        if (lap_start >= n) {
            for (uint16_t i = static_cast<uint16_t>(lap_start - n); i < lap_start; ++i) base = base + samples[i];
            for (uint16_t i = static_cast<uint16_t>(lap_start - n); i < pushed - n; ++i) base = base - samples[i];
        }
        for (uint16_t i = lap_start; i < pushed; ++i) fresh = fresh + samples[i];
        const uint16_t count = pushed < n ? pushed : n;
        ASSERT_REAL_SAME((base + fresh) / static_cast<Real>(count), roll_avg_value(w.avg));
    }
}

// An infinite sample is counted, not summed: while the window holds one the
// mean is that infinity (NaN with both signs), and once the infinities have
// left it is the finite samples' mean at once, not NaN (inf - inf) until the
// next lap. The typed wrapper of a power-of-two N (times 1/N) likewise.
static void test_avg_forgets_an_infinite_sample_that_left(void) {
    w.reset(3);
    static RollAvgN<2> two;
    w.push(kInf); two.push(kInf);
    ASSERT_REAL_SAME(kInf, roll_avg_value(w.avg));
    ASSERT_REAL_SAME(kInf, two.value());
    w.push(1); two.push(1);
    w.push(1); two.push(1);
    ASSERT_REAL_SAME(kInf, roll_avg_value(w.avg));    // inf, 1, 1
    ASSERT_REAL_SAME(Real(1), two.value());           // 1, 1
    w.push(1); two.push(-kInf);
    ASSERT_REAL_SAME(Real(1), roll_avg_value(w.avg));  // 1, 1, 1
    ASSERT_REAL_SAME(-kInf, two.value());             // 1, -inf
    w.push(-kInf); two.push(kInf);
    ASSERT_REAL_SAME(-kInf, roll_avg_value(w.avg));   // 1, 1, -inf
    TEST_ASSERT_TRUE(two.value() != two.value());     // -inf, inf: NaN
    w.push(kInf); two.push(Real(0.5));
    TEST_ASSERT_TRUE(roll_avg_value(w.avg) != roll_avg_value(w.avg));  // 1, -inf, inf
    ASSERT_REAL_SAME(kInf, two.value());              // inf, 0.5
    w.push(4); two.push(Real(1.5));
    w.push(5);
    ASSERT_REAL_SAME(Real(1), two.value());           // 0.5, 1.5: times 1/2
    ASSERT_REAL_SAME(kInf, roll_avg_value(w.avg));    // inf, 4, 5
    w.push(6);
    ASSERT_REAL_SAME(Real(5), roll_avg_value(w.avg));  // 4, 5, 6
}

static void test_avg_does_not_drift(void) {
    w.reset(10);
    for (uint16_t k = 0; k < 1000; ++k) w.push(Real(0.1));
    // After a whole lap the sum is recomputed in order: exactly 10 x 0.1 / 10.
    Real sum = 0;
    for (int i = 0; i < 10; ++i) sum = sum + Real(0.1);
    ASSERT_REAL_SAME(sum / 10, roll_avg_value(w.avg));
}

static void test_typed_wrappers_and_range(void) {
    static RollRangeN<3> r;
    static RollMedianN<3> m;
    static RollAvgN<3> a;
    const Real xs[] = {3, 9, 1, 4};
    for (size_t i = 0; i < 4; ++i) { r.push(xs[i]); m.push(xs[i]); a.push(xs[i]); }
    ASSERT_REAL_SAME(Real(8), r.value());       // 9 - 1 over {9, 1, 4}
    ASSERT_REAL_SAME(Real(4), m.value());
    ASSERT_REAL_SAME(Real(14) / 3, a.value());
}

// Windows of up to 255 samples index with bytes (half the RAM on an 8-bit
// MCU): the same values, bit for bit, as the WinIdx core on the same
// samples, well past the byte sequence numbers' wrap at 256 pushes.
template <uint32_t N>
static void byte_window_matches_winidx(void) {
    static_assert(sizeof(typename RollMaxN<N>::I) == 1, "a window of N <= 255 indexes with bytes");
    static RollAvgN<N> a;
    static RollMaxN<N> mx;
    static RollMinN<N> mn;
    static RollMedianN<N> med;
    static RollAvg wa; static Real wa_ring[N];
    static RollExt wx; static Real wx_v[N]; static WinIdx wx_s[N];
    static RollExt wn; static Real wn_v[N]; static WinIdx wn_s[N];
    static RollMedian wm; static Real wm_ring[N]; static Real wm_sorted[N];
    for (uint16_t k = 0; k < 3u * N + 300u; ++k) {
        const uint32_t r = rng();
        // Runs of equal values and steady climbs and falls exercise the deques.
        const Real x = (r & 7u) == 0 ? Real(0) : static_cast<Real>(static_cast<int32_t>(r % 2001u) - 1000) / 8;
        a.push(x); mx.push(x); mn.push(x); med.push(x);
        roll_avg_push(wa, wa_ring, static_cast<WinIdx>(N), x);
        roll_max_push(wx, wx_v, wx_s, static_cast<WinIdx>(N), x);
        roll_min_push(wn, wn_v, wn_s, static_cast<WinIdx>(N), x);
        roll_median_push(wm, wm_ring, wm_sorted, static_cast<WinIdx>(N), x);
        ASSERT_REAL_SAME(roll_avg_value(wa), a.value());
        ASSERT_REAL_SAME(roll_ext_value(wx, wx_v), mx.value());
        ASSERT_REAL_SAME(roll_ext_value(wn, wn_v), mn.value());
        ASSERT_REAL_SAME(roll_median_value(wm, wm_sorted), med.value());
    }
}

static void test_byte_indexed_windows_match_the_winidx_core(void) {
    static_assert(sizeof(RollMaxN<256>::I) == sizeof(WinIdx), "a window of 256 samples indexes with WinIdx");
    byte_window_matches_winidx<1>();
    byte_window_matches_winidx<5>();
#if !defined(__AVR__)  // on the MCU's 2 KB of RAM the two copies of 255 samples do not fit
    byte_window_matches_winidx<255>();
#endif
}

// One ring for a machine's roll_min, roll_max and roll_range of one
// argument (RollMinMaxN): the values of the three windows of their own, bit
// for bit, on samples with runs, zeros of both signs, infinities and NaNs
// (stored as +0), from the first push on.
template <uint32_t N>
static void ring_matches_the_deques(void) {
    static RollMinMaxN<N> ring;
    static RollMinN<N> mn;
    static RollMaxN<N> mx;
    static RollRangeN<N> rg;
    memset(&ring, 0, sizeof ring);
    memset(&mn, 0, sizeof mn);
    memset(&mx, 0, sizeof mx);
    memset(&rg, 0, sizeof rg);
    ASSERT_REAL_SAME(Real(0), ring.least());
    ASSERT_REAL_SAME(Real(0), ring.greatest());
    ASSERT_REAL_SAME(Real(0), ring.range());
    const Real inf = static_cast<Real>(__builtin_inf());
    for (uint16_t k = 0; k < 3u * N + 300u; ++k) {
        const uint32_t r = rng();
        Real x = static_cast<Real>(static_cast<int32_t>(r % 2001u) - 1000) / 8;
        switch ((r >> 12) & 15u) {
        case 0: x = Real(0); break;
        case 1: x = -Real(0); break;
        case 2: x = inf; break;
        case 3: x = -inf; break;
        case 4: x = static_cast<Real>(__builtin_nan("")); break;
        default: break;
        }
        ring.push(x);
        mn.push(x);
        mx.push(x);
        rg.push(x);
        ASSERT_REAL_SAME(mn.value(), ring.least());
        ASSERT_REAL_SAME(mx.value(), ring.greatest());
        ASSERT_REAL_SAME(rg.value(), ring.range());
    }
}

// Not on the MCU, whose 2 KB of RAM the other tests' windows fill: the
// native binary32 build runs the same code on the same order keys.
#if !defined(__AVR__)
static void test_one_ring_gives_the_extremes_of_their_own_windows(void) {
    static_assert(sizeof(RollMinMaxN<5>) < sizeof(RollMinN<5>) + sizeof(RollMaxN<5>), "one ring is smaller");
    ring_matches_the_deques<1>();
    ring_matches_the_deques<2>();
    ring_matches_the_deques<5>();
    ring_matches_the_deques<16>();
}
#endif

#if !defined(__AVR__)
// The language's largest window: 100000 samples.
static void test_largest_window(void) {
    static RollMaxN<100000> mx;
    static RollMedianN<100000> med;
    for (uint32_t i = 0; i < 100000u; ++i) {
        mx.push(static_cast<Real>(i));
        med.push(static_cast<Real>(i));
    }
    ASSERT_REAL_SAME(Real(99999), mx.value());
    ASSERT_REAL_SAME(Real(49999.5), med.value());
    for (uint32_t i = 0; i < 1000u; ++i) {
        mx.push(-1);
        med.push(static_cast<Real>(100000u + i));
    }
    ASSERT_REAL_SAME(Real(99999), mx.value());
    ASSERT_REAL_SAME(Real(50999.5), med.value());
}
#endif

static void run(void) {
    UNITY_BEGIN();
    RUN_TEST(test_no_samples_gives_zero);
    RUN_TEST(test_window_of_one_is_the_last_sample);
    RUN_TEST(test_fewer_samples_than_n_use_the_samples_so_far);
    RUN_TEST(test_even_median_is_a_plus_half_the_difference);
    RUN_TEST(test_nan_samples_are_stored_as_zero);
    RUN_TEST(test_random_sequences_match_brute_force);
    RUN_TEST(test_avg_follows_the_documented_operation_order);
    RUN_TEST(test_avg_forgets_an_infinite_sample_that_left);
    RUN_TEST(test_avg_does_not_drift);
    RUN_TEST(test_typed_wrappers_and_range);
    RUN_TEST(test_byte_indexed_windows_match_the_winidx_core);
#if !defined(__AVR__)
    RUN_TEST(test_one_ring_gives_the_extremes_of_their_own_windows);
#endif
#if !defined(__AVR__)
    RUN_TEST(test_largest_window);
#endif
    (void)UNITY_END();
}

FSW_TEST_MAIN(run)
