"""The Stability map refined at its neutral curve against the unrefined maps it replaces (issue 33, "Exact
boundaries"): for each plane at the app's default inputs, the time of the map job (chunks, refinement, certified
crossings; empty caches, best of 2) and the points evaluated, for the old 40 x 40 medium and 64 x 64 fine maps and
the new medium (24 x 24 refined twice: 96 x 96 cells at the curve) and fine (40 x 40: 160 x 160).

    .venv/bin/python benchmarks/map_refine.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from asymslide.app.params import SpectrumParams  # noqa: E402
from asymslide.app.stability_map import compute, grids  # noqa: E402


class _Job:
    """What compute_map needs of a job: nothing is cancelled or shown."""

    def check(self) -> None:
        pass

    def advance(self, *_args, **_kwargs) -> None:
        pass


def timed(key: tuple) -> tuple[float, int]:
    """Best of two cold runs of the map job of `key`: seconds, points evaluated."""
    best, points = float("inf"), 0
    for _ in range(2):
        compute.CHUNKS.clear()
        compute.compute_crossings.clear()
        t0 = time.perf_counter()
        res = compute.compute_map(key, _Job())
        best = min(best, time.perf_counter() - t0)
        points = res.x.size * res.y.size + (0 if res.refined is None else res.refined.points["x"].size)
    return best, points


def main() -> None:
    args = SpectrumParams().model_args()
    timed(grids.key_for("β-γ", "coarse", args))  # warm the kernels
    print("| plane | old medium 40 × 40 | new medium 24 × 24 → 96 × 96 | old fine 64 × 64 "
          "| new fine 40 × 40 → 160 × 160 |")
    print("|---|---|---|---|---|")
    for plane in grids.PLANES:
        medium, fine = grids.key_for(plane, "medium", args), grids.key_for(plane, "fine", args)
        cells = [timed((plane, 40, medium[2], 0)), timed(medium), timed((plane, 64, fine[2], 0)), timed(fine)]
        print(f"| {plane} | " + " | ".join(f"{t:.2f} s, {p} points" for t, p in cells) + " |")


if __name__ == "__main__":
    main()
