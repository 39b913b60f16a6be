"""What the two threshold solvers (model.thresholds, ``model._sliding_thresholds``) share: one crossing found in a scan
(:class:`Crossing`) and the empty result they fill (:func:`empty_crossings`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .crossings import T_UNDEFINED, X_CERTIFIED, X_EDGE, Crossings


@dataclass
class Crossing:
    """One sign change of G: the threshold (if certified) and what is known about it."""

    reason: int
    lo: float  # the bracket in t
    hi: float
    t: float = math.nan  # the threshold (certified) or where the sign change was located
    s: float = math.nan
    x: float = math.nan
    direction: int = 0

    @property
    def certified(self) -> bool:
        return self.reason in (X_CERTIFIED, X_EDGE)


def empty_crossings(n: int, k: int, name: str) -> Crossings:
    """A :class:`Crossings` for n parameter sets and k crossings each, NaN-padded, status undefined."""
    nan = np.full((n, k), np.nan)
    return Crossings(nan, nan.copy(), nan.copy(), nan.copy(), nan.copy(), nan.copy(), np.zeros((n, k), np.int8),
                     np.full((n, k), -1, np.int8), np.zeros(n, np.int64), np.zeros(n, bool), np.zeros(n, bool),
                     np.full(n, T_UNDEFINED, np.int8), np.full(n, np.nan), np.full(n, np.nan), np.zeros(n, np.int64),
                     np.zeros(n, np.int64), name)
