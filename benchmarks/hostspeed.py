"""How fast the (shared, noisy) host runs Python right now, printed with every benchmark table so that
runs from different days can be compared: a 2x slower loop means roughly 2x longer timings everywhere."""

from __future__ import annotations

import math
import time


def host_loop_seconds(n: int = 10_000_000) -> float:
    """Best of three runs of a pure-Python ``n``-step loop, in seconds."""
    best = math.inf
    for _ in range(3):
        t0, acc = time.perf_counter(), 0
        for i in range(n):
            acc += i
        best = min(best, time.perf_counter() - t0)
    return best


def host_line(before: float, after: float) -> str:
    """One Markdown sentence with the loop time measured before and after a benchmark."""
    return (f"Host speed: a 10^7-step Python loop took {before:.2f} s before and {after:.2f} s after "
            "(0.5-1.3 s seen on the development machine on one day; timings tend to scale with it).")
