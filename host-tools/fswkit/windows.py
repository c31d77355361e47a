"""Rolling windows for the reference interpreter (spec §4.6): the last N
samples of an expression. Every arithmetic result is rounded to `R`
exactly as the firmware runtime does it (docs/runtime.md).

avg/min/max/range cost O(1) amortised per update, median O(log N) search
plus one list insertion and removal."""

from __future__ import annotations

from bisect import bisect_left, insort
from collections import deque

from fswkit.autocode.numeric import Real


class Window:
    __slots__ = ("n", "buf", "real")

    def __init__(self, n: int, real: Real):
        self.n = n
        self.buf: deque[float] = deque()
        self.real = real


class AvgWindow(Window):
    """Mean of the samples: a running sum in R (add the new sample, then
    subtract the one that leaves), recomputed from the samples in order,
    oldest first, every N updates so rounding error cannot accumulate."""

    __slots__ = ("sum", "since")

    def __init__(self, n, real):
        super().__init__(n, real)
        self.sum = 0.0
        self.since = 0

    def push(self, x: float) -> float:
        r = self.real.rnd
        if x != x:
            x = 0.0
        buf = self.buf
        buf.append(x)
        if len(buf) > self.n:
            old = buf.popleft()
            self.sum = r(r(self.sum + x) - old)
        else:
            self.sum = r(self.sum + x)
        self.since += 1
        if self.since >= self.n:
            self.since = 0
            s = 0.0
            for y in buf:
                s = r(s + y)
            self.sum = s
        return r(self.sum / len(buf))


class _Extremum(Window):
    """Monotonic deque of (update number, value): the front is the extremum."""

    __slots__ = ("mono", "count")

    def __init__(self, n, real):
        super().__init__(n, real)
        self.mono: deque[tuple[int, float]] = deque()
        self.count = 0

    def _push(self, x: float, keep_front_if) -> float:
        if x != x:
            x = 0.0
        mono = self.mono
        while mono and keep_front_if(mono[-1][1], x):
            mono.pop()
        mono.append((self.count, x))
        self.count += 1
        if mono[0][0] <= self.count - 1 - self.n:
            mono.popleft()
        return mono[0][1]


class MinWindow(_Extremum):
    __slots__ = ()

    def push(self, x: float) -> float:
        return self._push(x, lambda last, new: last >= new)


class MaxWindow(_Extremum):
    __slots__ = ()

    def push(self, x: float) -> float:
        return self._push(x, lambda last, new: last <= new)


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
        if x != x:
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
