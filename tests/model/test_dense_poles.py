"""Counts and roots beside dense real-axis poles (finite eta): right or refused, never a smaller number.

At finite eta the lower block's real-axis poles are spaced ~ pi / ((1 + eta) kH); a root just above the bottom edge
beside a pole below it changes log F only within ~ its distance of the pole, where the acceptance tests on coarser
samples cannot see it. The bottom edge is therefore graded around every pole in range (docs/physics.md §10), however
many there are; a line needing more than 2^23 samples is refused (RuntimeError), never counted without them. Before,
families with more than 20000 poles in range were left ungraded and their roots silently lost.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from mpmath import mp

from asymslide import model
from tests import oracle

#: the issue's first case: the count fell from 1120 to 1118 as re_max grew from 1569.79 to 1569.80
CASE_1 = dict(gamma=3.2801, f=0.6919, beta=0.35, eta=3.0, Delta=0.3654, xi=2.7141)
CASE_1_WINDOW = dict(im_min=1e-4, im_max=3.0)
#: the two roots lost there (the issue's 30-digit residuals ~1e-28), far inside the window
CASE_1_LOST = (complex(-1.3206454, 0.0013194), complex(-1.4290182, 0.00023289))
#: the issue's second case: its root_window at floor 1e-4 (|Re z| <= 64057, ~221,000 poles in range)
CASE_2 = dict(gamma=5.6087, f=1.2033, beta=0.3576, eta=3.0, Delta=0.8781, xi=1.3451)


def _oracle_roots(kH: float, p: dict, x0: float, x1: float, y0: float, y1: float) -> list[complex]:
    return [complex(z) for z in oracle.roots_in_rectangle(kH, p["gamma"], p["f"], p["beta"], p["eta"], p["Delta"],
                                                          p["xi"], x0=x0, x1=x1, y0=y0, y1=y1, dps=20)]


def _same_roots(ours: np.ndarray, ref: list[complex], rtol: float = 1e-10) -> bool:
    if ours.size != len(ref):
        return False
    return all(np.min(np.abs(ours - r)) <= rtol * abs(r) for r in ref)


@pytest.mark.slow
def test_the_count_does_not_fall_as_the_window_grows_past_20000_poles() -> None:
    """Case 1 (kH = 10, eta = 3): the windows |Re z| <= 1569.79, 1569.80 and the root_window's 2191.7 (at
    floor 1e-4) hold the same roots; the roots found in the big window at Re z in (-1.5, -1.2) are the oracle's there
    (mpmath, its own F and contour: the two roots the count used to lose among them)."""
    counts = [model.unstable_count(10.0, **CASE_1, **CASE_1_WINDOW, re_max=r) for r in (1569.79, 1569.80, 2191.7)]
    assert counts[0] == counts[1] == counts[2], counts
    roots = model.unstable_modes(10.0, **CASE_1, **CASE_1_WINDOW, re_max=1569.80)
    assert roots.size == counts[1]
    strip = roots[(roots.real > -1.5) & (roots.real < -1.2)]
    ref = _oracle_roots(10.0, CASE_1, -1.5, -1.2, 1e-4, 3.0)
    assert _same_roots(strip, ref), (strip, ref)
    for z in CASE_1_LOST:
        assert np.min(np.abs(strip - z)) <= 1e-6 * abs(z)


@pytest.mark.slow
def test_the_whole_root_window_beside_two_hundred_thousand_poles() -> None:
    """Case 2 (kH = 1, eta = 3, floor 1e-4): over its root_window the count is the independent
    reference's 2903 (it was 491), nested windows count no more in the smaller one, and the roots at |Re z| < 4 are
    the oracle's."""
    re_max, im_max = (float(v) for v in model.root_window(1.0, **CASE_2, floor=1e-4))
    w = dict(im_min=1e-4, im_max=im_max)
    inner = [model.unstable_count(1.0, **CASE_2, **w, re_max=r) for r in (1e3, 1e4, 3e4)]
    roots = model.unstable_modes(1.0, **CASE_2, **w, re_max=re_max)
    assert inner == sorted(inner) and inner[-1] <= roots.size == 2903
    ref = _oracle_roots(1.0, CASE_2, -4.0, 4.0, 1e-4, im_max)
    assert _same_roots(roots[np.abs(roots.real) < 4.0], ref)


def _count(kH: float, p: dict, re_max: float, im_min: float, im_max: float) -> int | None:
    """The count, or None where it is refused (RuntimeError naming why: too many samples, or no edge placement)."""
    try:
        return model.unstable_count(kH, **p, re_max=re_max, im_min=im_min, im_max=im_max)
    except RuntimeError as exc:
        assert "samples" in str(exc) or "edge" in str(exc), exc
        return None


@pytest.mark.slow
def test_counts_are_monotone_in_nested_windows() -> None:
    """A window inside another never counts more roots (seeded sets: eta log-uniform in [1.5, 1e4], kH in [0.1, 10],
    floors im_min log-uniform down to 1e-5, re_max up to the width where the windows hold ~2e5 poles). A refused count
    (RuntimeError) is allowed, a smaller one is not; most counts are not refused."""
    rng = np.random.default_rng(52)
    compared = 0
    for _ in range(30):
        p = dict(gamma=float(10 ** rng.uniform(-1, 1.3)), f=float(rng.uniform(0.2, 1.5)),
                 beta=float(rng.uniform(0.1, 0.65)), eta=float(10 ** rng.uniform(math.log10(1.5), 4)),
                 Delta=float(rng.uniform(0.2, 1.0)), xi=float(rng.choice([0.0, 10 ** rng.uniform(-1, 1)])))
        kH = float(10 ** rng.uniform(-1, 1))
        spacing = math.pi / ((1.0 + p["eta"]) * kH)  # of the pole parameter: ~ the spacing in Re z far out
        r_big = min(float(10 ** rng.uniform(0.5, 3)), 5e4 * spacing)
        r_small = r_big / float(rng.uniform(1.0001, 3.0))
        floor = float(10 ** rng.uniform(-5, -2))
        im_max = 3.0
        big = _count(kH, p, r_big, floor, im_max)
        small = _count(kH, p, r_small, floor * float(rng.uniform(1.0, 10.0)), im_max)
        if big is not None and small is not None:
            compared += 1
            assert small <= big, (p, kH, r_small, r_big, floor, small, big)
    assert compared >= 24


@pytest.mark.slow
@pytest.mark.parametrize("re_max", [200.0, 5000.0])
def test_a_line_needing_more_than_its_cap_of_samples_is_refused(re_max: float) -> None:
    """eta = 1e4, kH = 1, im_min = 1e-5: |Re z| <= 200 holds ~1.7 million poles, whose graded seeds (7 each) exceed a
    line's 2^23 samples (refused by the sampler before any evaluation); |Re z| <= 5000 holds ~40 million, more than
    the cap by themselves (refused before the seeds are built). Refused with a reason, never counted without the
    grading."""
    with pytest.raises(RuntimeError, match="samples"):
        model.unstable_count(1.0, gamma=3.0, f=0.9, beta=0.3, eta=1e4, re_max=re_max, im_min=1e-5, im_max=2.0)


def test_the_oracle_refuses_rather_than_count_without_its_graded_nodes() -> None:
    """The oracle's own contour grades its edges around at most MAX_SINGULAR poles; beyond, it refuses."""
    with mp.workdps(15), pytest.raises(RuntimeError, match="real-axis poles"):
        oracle.count_roots(10.0, 3.0, 0.9, 0.3, 3.0, x0=-400.0, x1=400.0, y0=1e-4, y1=1.0)
