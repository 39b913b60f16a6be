"""Tests of the oracle's root counting and location in a rectangle (tests/oracle.py, section 8) against the check
values of docs/physics.md §3, §7 and §10 and against internal consistency (additivity of counts, the mirror
symmetry, roots on an edge, the exterior margin). Independent of ``model``.
"""

from __future__ import annotations

import functools
import math
import random

import oracle as o
import pytest
from mpmath import mp

INF = math.inf
F0, BETA0, GAMMA0 = 0.9, 0.3, 3  # f, beta, gamma of docs/physics.md §3 (worked examples) and §7
ETA3_ROOT = "-1.86154054015624 + 0.04806456251133j"  # eta = 3, q = 0.45 (§3, §7)
INF_ROOT = "3.53354704617255 + 0.07585981635187j"  # eta = inf, q = 0.45 (§3, §7)
RAYLEIGH_Q1 = "0.88336356305352538 + 0.00815518661032729j"  # eta = inf, q = 1 (§7)


@pytest.fixture(autouse=True)
def _test_arithmetic_at_50_digits():
    """Arithmetic inside the tests runs at 50 digits (the oracle sets its own precision internally)."""
    with mp.workdps(50):
        yield


def close(a, b, tol: float) -> bool:
    """|a - b| <= tol (absolute), at 50 digits."""
    with mp.workdps(50):
        return abs(mp.mpmathify(a) - mp.mpmathify(b)) <= tol


def rounds_to(z, re: str, im: str) -> bool:
    """z agrees with the quoted digits: |Re z - re| and |Im z - im| within half a unit of their last digits."""

    def half_ulp(s: str) -> float:
        return 0.5 * 10.0 ** -len(s.split(".")[1])

    return close(mp.re(z), re, half_ulp(re)) and close(mp.im(z), im, half_ulp(im))


def relative_residual(z, q, gamma, f, beta, eta, Delta=1, xi=0):
    """|F(z)| / |z| with the oracle's 30-digit public F (independent of the counting's working precision)."""
    return abs(o.dispersion(z, q, gamma, f, beta, eta, Delta, xi)) / abs(z)


@functools.lru_cache(maxsize=4)
def roots_eta10(f: float) -> tuple:
    """The roots of eta = 10, q = 0.77 (docs/physics.md §3) in [-5, 5] x [1e-4, 2] for friction coefficient f."""
    return tuple(o.roots_in_rectangle(0.77, GAMMA0, f, BETA0, 10, x0=-5, x1=5, y0=1e-4, y1=2))


# =============================================================================================
# Check values (docs/physics.md §3, §7)
# =============================================================================================


@pytest.mark.slow
def test_eta10_ten_roots_with_rayleigh_and_faster_root() -> None:
    """eta = 10, q = 0.77: ten roots with Im z >= 1e-4, |Re z| <= 5, among them the Rayleigh branch
    0.8847 + 0.01045i and the faster-growing 2.3954 + 0.03804i (the fastest)."""
    n = o.count_roots(0.77, GAMMA0, F0, BETA0, 10, x0=-5, x1=5, y0=1e-4, y1=2)
    roots = roots_eta10(F0)
    assert n == 10
    assert len(roots) == 10
    assert all(-5 <= mp.re(z) <= 5 and 1e-4 <= mp.im(z) <= 2 for z in roots)
    assert all(mp.im(a) >= mp.im(b) for a, b in zip(roots[:-1], roots[1:], strict=False))  # sorted, fastest first
    assert sum(rounds_to(z, "0.8847", "0.01045") for z in roots) == 1
    assert rounds_to(roots[0], "2.3954", "0.03804")
    assert all(relative_residual(z, 0.77, GAMMA0, F0, BETA0, 10) < 1e-20 for z in roots)


def test_backward_root_eta3() -> None:
    """eta = 3, q = 0.45: the backward-travelling root -1.86154054015624 + 0.04806456251133i (to 1e-12), the fastest
    in [-5, 5] x [1e-3, 2]."""
    roots = o.roots_in_rectangle(0.45, GAMMA0, F0, BETA0, 3, x0=-1.9, x1=-1.8, y0=0.04, y1=0.06)
    assert len(roots) == 1 and close(roots[0], ETA3_ROOT, 1e-12)
    z, n = o.fastest_root(0.45, GAMMA0, F0, BETA0, 3, re_max=5, im_min=1e-3, im_max=2)
    assert n >= 1 and close(z, ETA3_ROOT, 1e-12)
    assert relative_residual(z, 0.45, GAMMA0, F0, BETA0, 3) < 1e-20


def test_root_faster_than_cd_eta_inf() -> None:
    """eta = inf, q = 0.45: the root 3.53354704617255 + 0.07585981635187i (faster than c_d; to 1e-12), the fastest
    in [-5, 5] x [1e-3, 2]."""
    roots = o.roots_in_rectangle(0.45, GAMMA0, F0, BETA0, INF, x0=3.5, x1=3.6, y0=0.07, y1=0.08)
    assert len(roots) == 1 and close(roots[0], INF_ROOT, 1e-12)
    z, n = o.fastest_root(0.45, GAMMA0, F0, BETA0, INF, re_max=5, im_min=1e-3, im_max=2)
    assert n >= 1 and close(z, INF_ROOT, 1e-12)
    assert relative_residual(z, 0.45, GAMMA0, F0, BETA0, INF) < 1e-20


def test_rayleigh_branch_root_eta_inf_q1() -> None:
    """eta = inf, q = 1: the Rayleigh-branch root 0.88336356305352538 + 0.00815518661032729i is found, in a small
    rectangle and in the default window [-5, 5] x [1e-4, 2]; it agrees with the oracle's branch continuation."""
    small = o.roots_in_rectangle(1, GAMMA0, F0, BETA0, INF, x0=0.8, x1=0.95, y0=1e-3, y1=0.05)
    assert len(small) == 1 and close(small[0], RAYLEIGH_Q1, 1e-16)
    wide = o.roots_in_rectangle(1, GAMMA0, F0, BETA0, INF, x0=-5, x1=5, y0=1e-4, y1=2)
    assert sum(close(z, RAYLEIGH_Q1, 1e-16) for z in wide) == 1
    assert close(o.rayleigh_branch([1], GAMMA0, F0, BETA0, INF)[0], small[0], 1e-20)


def test_fastest_root_none_in_empty_window() -> None:
    """No root above the fastest one: (None, 0)."""
    assert o.fastest_root(0.45, GAMMA0, F0, BETA0, INF, re_max=5, im_min=0.08, im_max=2) == (None, 0)
    assert o.count_roots(0.45, GAMMA0, F0, BETA0, INF, x0=-5, x1=5, y0=0.08, y1=2) == 0


# =============================================================================================
# Internal consistency
# =============================================================================================


@pytest.mark.slow
def test_mirror_symmetry() -> None:
    """F(-conj z; -f) = conj F(z; f) (docs/physics.md §3): in a symmetric window the counts for f and -f agree and
    z -> -conj(z) maps the roots onto each other."""
    plus, minus = roots_eta10(F0), roots_eta10(-F0)
    assert len(plus) == len(minus) == 10
    mirrored = sorted((-mp.conj(z) for z in plus), key=lambda z: (-mp.im(z), mp.re(z)))
    for a, b in zip(mirrored, minus, strict=True):
        assert close(a, b, 1e-20)
    assert (o.count_roots(0.45, GAMMA0, -F0, BETA0, 3, x0=-5, x1=5, y0=1e-3, y1=2)
            == o.count_roots(0.45, GAMMA0, F0, BETA0, 3, x0=-5, x1=5, y0=1e-3, y1=2))


ADDITIVITY_CASES = [
    # (q, gamma, f, beta, eta, Delta, xi): finite and infinite eta, Delta < 1 with xi > 0
    (0.77, 3, 0.9, 0.3, 10, 1, 0),
    (2.0, 1.5, 0.5, 0.4, 5, 0.5, 2),
    (1.3, 8, 0.7, 0.35, INF, 0.6, 1),
]


@pytest.mark.parametrize("case", ADDITIVITY_CASES)
@pytest.mark.slow
def test_count_is_additive(case) -> None:
    """The count of a rectangle is the sum of the counts of its two halves, cut vertically and horizontally at
    random positions (each count samples its own contour from scratch)."""
    rng = random.Random(str(case))
    q, gamma, f, beta, eta, Delta, xi = case
    args = (q, gamma, f, beta, eta, Delta, xi)
    x0, x1, y0, y1 = -4.0, 4.0, 1e-3, 1.5
    whole = o.count_roots(*args, x0=x0, x1=x1, y0=y0, y1=y1)
    assert whole >= 1
    xc = rng.uniform(-2.0, 2.0)
    assert whole == (o.count_roots(*args, x0=x0, x1=xc, y0=y0, y1=y1)
                     + o.count_roots(*args, x0=xc, x1=x1, y0=y0, y1=y1))
    yc = math.exp(rng.uniform(math.log(2e-3), math.log(0.5)))
    assert whole == (o.count_roots(*args, x0=x0, x1=x1, y0=y0, y1=yc)
                     + o.count_roots(*args, x0=x0, x1=x1, y0=yc, y1=y1))


@pytest.mark.slow
def test_count_equals_roots_found_delta_xi() -> None:
    """Delta < 1, xi > 0, finite eta: the roots found are as many as counted, each in the window with a tiny
    residual of the 30-digit F."""
    args = (2.0, 1.5, 0.5, 0.4, 5, 0.5, 2)
    n = o.count_roots(*args, x0=-3, x1=3, y0=1e-3, y1=1)
    roots = o.roots_in_rectangle(*args, x0=-3, x1=3, y0=1e-3, y1=1)
    assert n == len(roots) >= 1
    assert all(-3 <= mp.re(z) <= 3 and 1e-3 <= mp.im(z) <= 1 for z in roots)
    assert all(relative_residual(z, *args) < 1e-20 for z in roots)


@pytest.mark.parametrize("edge", ["bottom", "top", "left", "right"])
def test_root_on_edge_raises(edge: str) -> None:
    """A root on the boundary (the eta = 3 root of §7, known to 14 digits) raises instead of returning a count."""
    z = mp.mpc(ETA3_ROOT)
    x, y = float(mp.re(z)), float(mp.im(z))
    window = {
        "bottom": {"x0": -2.0, "x1": -1.7, "y0": y, "y1": 0.1},
        "top": {"x0": -2.0, "x1": -1.7, "y0": 0.01, "y1": y},
        "left": {"x0": x, "x1": -1.7, "y0": 0.01, "y1": 0.1},
        "right": {"x0": -2.0, "x1": x, "y0": 0.01, "y1": 0.1},
    }[edge]
    with pytest.raises(RuntimeError, match="root"):
        o.count_roots(0.45, GAMMA0, F0, BETA0, 3, **window)
    with pytest.raises(RuntimeError):
        o.roots_in_rectangle(0.45, GAMMA0, F0, BETA0, 3, **window)


def test_bad_window_rejected() -> None:
    for window in ({"x0": 1, "x1": -1, "y0": 0.1, "y1": 1}, {"x0": -1, "x1": 1, "y0": 0, "y1": 1},
                   {"x0": -1, "x1": 1, "y0": 1, "y1": 0.5}):
        with pytest.raises(ValueError):
            o.count_roots(1, GAMMA0, F0, BETA0, INF, **window)


# =============================================================================================
# Exterior of the window: Re(F/(i z)) > 0
# =============================================================================================


def test_exterior_points_lie_outside_and_reach_im_min() -> None:
    pts = o.exterior_points(12, 1e-6, 12, n=400, factor=8)
    assert 300 <= len(pts) <= 500
    assert all(abs(mp.re(z)) >= 12 * (1 - 1e-12) or mp.im(z) >= 12 * (1 - 1e-12) for z in pts)
    assert all(mp.im(z) >= 1e-6 * (1 - 1e-12) for z in pts)
    assert sum(mp.im(z) == mp.mpf(1e-6) for z in pts) >= 40  # the tightest height, on both sides
    assert max(abs(mp.re(z)) for z in pts) >= 8 * 12 * (1 - 1e-12)
    assert max(mp.im(z) for z in pts) >= 8 * 12 * (1 - 1e-12)


@pytest.mark.parametrize(
    ("args", "window"),
    [
        ((1, GAMMA0, F0, BETA0, INF), {"re_max": 12, "im_min": 1e-6, "im_max": 12}),
        ((3, 23.65, 0.8219, 0.3014, INF, 0.6091, 1), {"re_max": 45, "im_min": 1e-6, "im_max": 45}),
    ],
)
def test_exterior_margin_positive(args, window) -> None:
    """Re(F/(i z)) > 0 on rays beyond windows of about the size the theorem computes (docs/physics.md §10)."""
    assert o.exterior_min_margin(*args, **window) > 0
