"""The temporal growth rate sigma = kH Im z as kH -> infinity (model.growth_rate_limit; docs/physics.md §14.14).

The limit comes from the reduced equation over the torus of the blocks' phases; the references here do not use the
reduction: the contour solver's certified roots of the full F at large kH (model.fastest_mode), and, at finite eta,
roots of the oracle's F (mpmath, tests/oracle.py) polished at a kH where the blocks' phases are those of the limit.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from scipy.optimize import brentq

from asymslide import model
from tests import oracle

PAPER = dict(gamma=3.0, f=0.9, beta=0.3)
#: a set where the supremum is large (found by a seeded draw; Delta < 1 and xi > 0: S -> 1 as kH -> infinity)
STRONG = dict(gamma=16.836, f=0.967, beta=0.414, Delta=0.84, xi=1.0)


def _sigma(kH: float, p: dict) -> float:
    fm = model.fastest_mode(kH, **p, count=False)
    assert int(fm.status) in (0, 1)
    return kH * float(fm.growth) if int(fm.status) == 0 else 0.0


@pytest.mark.slow
def test_the_supremum_is_approached_from_below_as_kh_grows() -> None:
    """At eta = inf, gamma = 3, the certified fastest root's sigma rises towards a bound as kH grows
    (0.04813, 0.04819 at kH = 1e3, 3e3, z -> 3.40 beside 1/beta): the limit is 0.048336, supersonic, at
    x = 3.3979, above both and within 0.5 % of the larger."""
    lim = model.growth_rate_limit(**PAPER)
    sigma = float(lim.sigma)
    assert int(lim.status) == 0 and int(lim.family) == 3 and 1 / 0.3 < float(lim.x) < 3.5
    s1, s3 = _sigma(1e3, PAPER), _sigma(3e3, PAPER)
    assert s1 < s3 < sigma < s3 * 1.005
    assert abs(sigma - 0.048336) < 1e-6


@pytest.mark.slow
def test_a_strong_set_agrees_with_the_certified_roots() -> None:
    """sigma at kH = 1e3 and 3e3 lies below the limit and approaches it (relative gap 1e-4 at 3e3)."""
    sigma = float(model.growth_rate_limit(**STRONG).sigma)
    s1, s3 = _sigma(1e3, STRONG), _sigma(3e3, STRONG)
    assert max(s1, s3) < sigma * (1 + 1e-6)
    assert sigma - s3 < 1e-3 * sigma


@pytest.mark.slow
@pytest.mark.parametrize("gamma", [0.3, 1.0])
def test_no_growth_at_large_kh_where_the_limit_is_zero(gamma: float) -> None:
    """Where the reduced equation has no growing root (gamma = 0.3, 1 with f = 0.9, beta = 0.3), the contour finds no
    root with sigma >= 1e-3 at kH = 1e3 (floor 1e-6 on Im z)."""
    p = dict(PAPER, gamma=gamma)
    lim = model.growth_rate_limit(**p)
    assert int(lim.status) == 1 and float(lim.sigma) == 0.0 and int(lim.family) == -1
    assert _sigma(1e3, p) == 0.0


def test_input_is_checked() -> None:
    with pytest.raises(ValueError, match="gamma"):
        model.growth_rate_limit(gamma=-1.0, f=0.9, beta=0.3)
    with pytest.raises(ValueError, match="beta"):
        model.growth_rate_limit(gamma=1.0, f=0.9, beta=0.9)
    with pytest.raises(ValueError, match="eta"):
        model.growth_rate_limit(gamma=1.0, f=0.9, beta=0.3, eta=-2.0)


def _matched_kh(x: float, phases: np.ndarray, beta: float, near: float) -> tuple[float, float]:
    """(x', kH) near (x, near) where kH alpha_j(x') has the upper block's phases of the limit exactly (both waves:
    -sgn(x) kH |alpha_j(x')| = phi_j mod pi), with x' within O(1/kH) of x; at eta = 2 the lower block's phases are
    then 2 phi_j, the limit's too."""
    sg, ax = math.copysign(1.0, x), abs(x)

    def m_s(v: float) -> float:
        return math.sqrt(v * v - 1.0)

    def m_d(v: float) -> float:
        return math.sqrt(beta * beta * v * v - 1.0)

    a_s, a_d = ((-sg * p) % math.pi for p in phases[:2])
    n_d = round((near * m_d(ax) - a_d) / math.pi)
    best = None
    for n_s in range(round((near * m_s(ax) - a_s) / math.pi) - 2, round((near * m_s(ax) - a_s) / math.pi) + 3):
        ratio = (a_s + n_s * math.pi) / (a_d + n_d * math.pi)
        xv = brentq(lambda v, r=ratio: m_s(v) / m_d(v) - r, (1.0 + 1e-12) / beta, 1e3)
        if best is None or abs(xv - ax) < abs(best[0] - ax):
            best = (xv, (a_d + n_d * math.pi) / m_d(xv))
    return sg * best[0], best[1]


@pytest.mark.slow
def test_at_finite_eta_the_oracles_roots_approach_the_limit() -> None:
    """eta = 2, gamma = 3 (tied phases: psi_j = 2 phi_j): the limit 0.14968 is supersonic (x = 4.2914); at kH ~ 100
    and 300 where the blocks' phases are the limit's, the oracle's F has a root with sigma 2.6e-4 and 8.7e-5 below
    it (an O(1/kH) approach); the contour's certified fastest root at kH = 30 (0.14708) lies below it too."""
    p = dict(PAPER, eta=2.0)
    lim = model.growth_rate_limit(**p)
    sigma, x = float(lim.sigma), float(lim.x)
    assert int(lim.status) == 0 and int(lim.family) == 3 and int(lim.tied) == 1
    assert abs(sigma - 0.14968) < 1e-5 and 4.28 < abs(x) < 4.30
    assert np.allclose(lim.phases[2:], (2.0 * lim.phases[:2]) % math.pi, atol=1e-9)
    gaps = []
    for near in (100.0, 300.0):
        xv, kh = _matched_kh(x, lim.phases, 0.3, near)
        z = mpmath.findroot(lambda w, q=kh: oracle.dispersion(w, q, eta=2.0, Delta=1, xi=0, **PAPER),
                            mpmath.mpc(xv, sigma / kh))
        assert abs(float(z.real) - xv) < 1e-4
        gaps.append(sigma - kh * float(z.imag))
    assert 0.0 < gaps[1] < gaps[0] < 1e-3 * sigma and gaps[1] < 0.5 * gaps[0]
    fm = model.fastest_mode(30.0, **p, floor=0.02 / 30.0, count=False)
    assert int(fm.status) == 0 and 0.98 * sigma < 30.0 * float(fm.growth) < sigma


@pytest.mark.slow
def test_large_eta_agrees_with_eta_inf() -> None:
    """The lower block's phases enter through tanh(eta s |x| beta_j^2/|alpha_j| + i psi_j), which tends to 1 as
    eta grows: at eta = 1e3 and 1e8 the limit is eta = inf's, 0.048336, to 1e-9; at eta = 10 it is higher (0.0626,
    the lower block's reflections still felt at sigma ~ 0.05)."""
    ref = float(model.growth_rate_limit(**PAPER).sigma)
    got = model.growth_rate_limit(**PAPER, eta=np.array([1e3, 1e8, 10.0]))
    assert np.all(got.status == 0)
    assert np.allclose(got.sigma[:2], ref, rtol=1e-9, atol=0.0)
    assert got.sigma[2] > 1.2 * ref


def test_identical_blocks_keep_no_growth_as_kh_grows() -> None:
    """eta = 1 (the paper: stable at every kH, G_y = 0): the phases are tied with psi_j = phi_j, so T1_j = T2_j and
    G_y = 0 in the reduced equation too; no root grows (status 1, sigma 0). A thickness ratio 1 + 1e-6 frees the
    lower block's phases: their torus is reached only at kH of order 1e6, and there sigma reaches 0.22."""
    lim = model.growth_rate_limit(**PAPER, eta=1.0)
    assert int(lim.status) == 1 and float(lim.sigma) == 0.0 and int(lim.tied) == 1
    near = model.growth_rate_limit(**PAPER, eta=1.0 + 1e-6)
    assert int(near.tied) == 0 and float(near.sigma) > 0.2


@pytest.mark.slow
def test_free_phases_reach_at_least_the_tied_ones() -> None:
    """At eta = 2 + 1e-3 the lower block's phases are free (eta is not p/q with q <= 8): their torus holds the tied
    one of eta = 2 (to O(1e-3) in the moduli), so the supremum is not lower: 0.1695 against 0.1497."""
    tied = model.growth_rate_limit(**PAPER, eta=2.0)
    free = model.growth_rate_limit(**PAPER, eta=2.001)
    assert int(free.tied) == 0 and int(free.status) == 0
    assert float(free.sigma) > float(tied.sigma)


@pytest.mark.slow
def test_it_broadcasts() -> None:
    lim = model.growth_rate_limit(gamma=np.array([1.0, 3.0]), f=0.9, beta=0.3)
    assert lim.sigma.shape == (2,) and lim.phases.shape == (2, 4)
    assert lim.status.tolist() == [1, 0]


@pytest.mark.slow
def test_sliding_analysis_states_the_limit_beside_the_range() -> None:
    """With rate=True at eta = inf, sliding_analysis gives the limit beside the maximum over its kH range: at gamma = 3
    the range's maximum (kH = 0.49) is above it (attained); at gamma = 15 the rate over [1e-2, 1e2] peaks at kH ~ 56
    below the limit, which it then approaches beyond the range (at gamma = 10 a root at kH = 0.52 is above its limit,
    by 6e-5); at gamma = 1 sliding is stable and nothing grows as
    kH -> infinity. Without rate the limit is NaN; at eta = 10 it is the finite-eta limit."""
    r = model.sliding_analysis(gamma=np.array([1.0, 3.0, 15.0]), f=0.9, beta=0.3, rate=True)
    assert r.rate_limit[0] == 0.0 and not r.rate_beyond_range[0] and int(r.verdict[0]) == 0
    assert r.rate[1] > r.rate_limit[1] > 0.0 and not r.rate_beyond_range[1] and 0.4 < r.kH_at_max_rate[1] < 0.6
    assert r.rate_limit[2] > r.rate[2] and r.rate_beyond_range[2] and r.kH_at_max_rate[2] < 100.0
    assert abs(r.rate_limit_re_z[2] - float(model.growth_rate_limit(gamma=15.0, f=0.9, beta=0.3).x)) < 1e-6
    plain = model.sliding_analysis(gamma=3.0, f=0.9, beta=0.3)
    finite = model.sliding_analysis(gamma=3.0, f=0.9, beta=0.3, eta=10.0, rate=True)
    assert math.isnan(float(plain.rate_limit)) and not bool(plain.rate_beyond_range)
    assert float(finite.rate_limit) == float(model.growth_rate_limit(gamma=3.0, f=0.9, beta=0.3, eta=10.0).sigma)
