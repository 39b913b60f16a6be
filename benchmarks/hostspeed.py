"""How fast the (shared, noisy) host runs Python right now, printed with every benchmark table so that
runs from different hours can be put side by side (a rough gauge: page building and the numba kernels
do not slow down in proportion to this loop)."""

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
            "(a rough gauge of contention: it varied between 0.46 and 1.25 s within one hour on the development "
            "machine).")
