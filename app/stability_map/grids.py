"""The Stability map's grids: the kH grid, the points per axis of each resolution, the planes and their axes, the
chunks of rows a map is computed in, and the key of a map (what it depends on)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from ..params import SpectrumParams

#: kH grid on which the maximum over kH is bracketed (then refined between grid points by the model)
KH = np.logspace(-3, 3, 96)

#: points per axis of the map. The η-γ plane is the slowest (finite η costs ~20x more per point): on 2 cores
#: ~0.6 / 0.9 / 2.0 s coarse / medium / fine (2-4x that when the cores are busy); the others take <= 0.2 s at η = ∞
RESOLUTIONS = {"coarse": 24, "medium": 24, "fine": 40}
#: the levels of refinement at the neutral curve per resolution (app.map_refine: each level halves the cells the
#: Rayleigh branch's verdict changes across; finest grid: 24, 96, 160 cells per axis)
LEVELS = {"coarse": 0, "medium": 2, "fine": 2}

#: a chunk has up to 256 parameter points per CPU (the model runs blocks of 256 on parallel threads), and a map
#: has at least MIN_CHUNKS chunks (progress steps, and how soon a stale computation stops)
CHUNK_POINTS = 256 * (os.cpu_count() or 1)
MIN_CHUNKS = 4

#: the order of SpectrumParams.model_args()
ARG_NAMES = SpectrumParams.MODEL_ARGS


@dataclass(frozen=True)
class Axis:
    """One axis of a plane: the model keyword, the paper's symbol, the plotted range, log or linear."""

    name: str
    lo: float
    hi: float
    log: bool
    step: float = 0.0  # a click on a linear axis is rounded to this (the slider's step)

    @classmethod
    def of(cls, name: str) -> Axis:
        """The axis of the model argument `name`, from its declaration (SpectrumParams, ``axis`` and ``step``)."""
        decl = SpectrumParams.declaration(name)
        lo, hi, log = decl.axis
        return cls(name, lo, hi, log, step=0.0 if log else decl.step)

    @property
    def label(self) -> str:
        return SpectrumParams.symbol(self.name)

    def values(self, n: int) -> np.ndarray:
        """The n grid values (cell centres), log- or linearly spaced from lo to hi."""
        if self.log:
            return np.logspace(math.log10(self.lo), math.log10(self.hi), n)
        return np.linspace(self.lo, self.hi, n)

    def edges(self, n: int) -> np.ndarray:
        """The n + 1 cell edges around :meth:`values` (midpoints in the axis' own scale)."""
        t = np.log10(self.values(n)) if self.log else self.values(n)
        h = t[1] - t[0]
        e = np.concatenate([[t[0] - h / 2], (t[:-1] + t[1:]) / 2, [t[-1] + h / 2]])
        return 10.0**e if self.log else e


#: the planes (x, y) by model argument; the name of a plane reads "x-y" in the paper's symbols
PLANE_ARGS = (("eta", "gamma"), ("Delta", "xi"), ("f", "gamma"), ("beta", "gamma"))
PLANES: dict[str, tuple[Axis, Axis]] = {
    f"{Axis.of(x).label}-{Axis.of(y).label}": (Axis.of(x), Axis.of(y)) for x, y in PLANE_ARGS}


#: the planes' URL words ("eta-gamma" for "η-γ")
PLANE_WORDS = {f"{Axis.of(x).label}-{Axis.of(y).label}": f"{x}-{y}" for x, y in PLANE_ARGS}


def plane_axes(plane: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) grid values of a plane at n points per axis."""
    ax, ay = PLANES[plane]
    return ax.values(n), ay.values(n)


def chunk_rows(n: int) -> list[tuple[int, int]]:
    """Row ranges [start, stop) of the chunks of an n x n map: <= CHUNK_POINTS points each, at least MIN_CHUNKS."""
    rows = max(1, min(CHUNK_POINTS // n, math.ceil(n / MIN_CHUNKS)))
    return [(a, min(a + rows, n)) for a in range(0, n, rows)]


def key_for(plane: str, resolution: str, args: tuple[float, ...]) -> tuple:
    """What a map depends on: plane, points per axis, and the model arguments off the plane (normalised)."""
    names = {a.name for a in PLANES[plane]}
    fixed = tuple((k, float(v)) for k, v in zip(ARG_NAMES, args, strict=True) if k not in names)
    return (plane, RESOLUTIONS[resolution], fixed, LEVELS[resolution])


def grid_words(n: int, levels: int) -> str:
    """The map's grid in words: "24 × 24 points", refined: "…, refined to 96 × 96 at the neutral curve"."""
    m = n * 2**levels
    return f"{n} × {n} points" + (f", refined to {m} × {m} at the neutral curve" if levels else "")
