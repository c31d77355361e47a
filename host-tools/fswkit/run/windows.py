"""Rolling windows for the reference interpreter (spec §4.6): the last N
samples of an expression. Every arithmetic result is rounded to `R`
exactly as the firmware runtime does it (docs/runtime.md).

avg/min/max/range cost O(1) amortised per update, median O(log N) search
plus one list insertion and removal."""

from __future__ import annotations

from bisect import bisect_left, insort
from collections import deque

from fswkit.autocode.numeric import INF, Real

NAN = float("nan")


class Window:
    __slots__ = ("n", "buf", "real")

    def __init__(self, n: int, real: Real):
        self.n = n
        self.buf: deque[float] = deque()
        self.real = real


class AvgWindow(Window):
    """Mean of the samples, exactly as the firmware computes it: the sum of
    the finite samples is `base + fresh`; each new one is added to `fresh`
    and the leaving one subtracted from `base`; at the end of every full lap
    of the ring `fresh` holds the in-order sum of exactly the window's finite
    samples and replaces `base`, so rounding drift cannot accumulate. The
    infinite samples are counted instead (`pinf`, `ninf`): while the window
    holds any, the mean is that infinity (NaN with both), and once they have
    left it is the finite samples' mean again."""

    __slots__ = ("ring", "base", "fresh", "count", "head", "pinf", "ninf")

    def __init__(self, n, real):
        super().__init__(n, real)
        self.ring = [0.0] * n
        self.base = self.fresh = 0.0
        self.count = self.head = self.pinf = self.ninf = 0

    def push(self, x: float) -> float:
        r = self.real.rnd
        if x != x or x == 0:
            x = 0.0
        n, head = self.n, self.head
        if self.count == n:
            old = self.ring[head]
            if old == INF:
                self.pinf -= 1
            elif old == -INF:
                self.ninf -= 1
            else:
                self.base = r(self.base - old)
        else:
            self.count += 1
        self.ring[head] = x
        if x == INF:
            self.pinf += 1
        elif x == -INF:
            self.ninf += 1
        else:
            self.fresh = r(self.fresh + x)
        head += 1
        if head == n:
            head = 0
            self.base, self.fresh = self.fresh, 0.0
        self.head = head
        if self.pinf or self.ninf:
            return NAN if self.pinf and self.ninf else INF if self.pinf else -INF
        return r(r(self.base + self.fresh) / self.count)


class _Extremum(Window):
    """Monotonic deque of (update number, value): the front is the least.
    MaxWindow keeps its samples negated, so that both kinds run the one
    update with its one comparison inline (a comparison callback a sample
    cost a third of a state script's step)."""

    __slots__ = ("mono", "count")

    def __init__(self, n, real):
        super().__init__(n, real)
        self.mono: deque[tuple[int, float]] = deque()
        self.count = 0

    def _least(self, x: float) -> float:
        """Adds `x` (a number, not NaN); the least of the window."""
        mono = self.mono
        while mono and mono[-1][1] >= x:
            mono.pop()
        count = self.count
        mono.append((count, x))
        self.count = count + 1
        if mono[0][0] <= count - self.n:
            mono.popleft()
        return mono[0][1]


class MinWindow(_Extremum):
    __slots__ = ()

    def push(self, x: float) -> float:
        return self._least(0.0 if x != x or x == 0 else x)


class MaxWindow(_Extremum):
    __slots__ = ()

    def push(self, x: float) -> float:
        # (+ 0.0: a zero comes back as 0.0, not the -0.0 its negation gives)
        return -self._least(0.0 if x != x or x == 0 else -x) + 0.0


class RangeWindow(Window):
    """max − min over the window, rounded to R."""

    __slots__ = ("lo", "hi")

    def __init__(self, n, real):
        super().__init__(n, real)
        self.lo = MinWindow(n, real)
        self.hi = MaxWindow(n, real)

    def push(self, x: float) -> float:
        return self.real.rnd(self.hi.push(x) - self.lo.push(x))


class MedianWindow(Window):
    """Middle sample of the sorted window; of an even count, a + (b − a)/2
    of the two middle samples, each operation rounded to R."""

    __slots__ = ("sorted",)

    def __init__(self, n, real):
        super().__init__(n, real)
        self.sorted: list[float] = []

    def push(self, x: float) -> float:
        if x != x or x == 0:
            x = 0.0
        buf, s = self.buf, self.sorted
        buf.append(x)
        if len(buf) > self.n:
            old = buf.popleft()
            del s[bisect_left(s, old)]
        insort(s, x)
        k = len(s)
        if k & 1:
            return s[k // 2]
        a, b = s[k // 2 - 1], s[k // 2]
        r = self.real.rnd
        return r(a + r(r(b - a) / 2.0))


KINDS = {"avg": AvgWindow, "min": MinWindow, "max": MaxWindow,
         "range": RangeWindow, "median": MedianWindow}


def make_window(func: str, n: int, real: Real) -> Window:
    return KINDS[func](n, real)
