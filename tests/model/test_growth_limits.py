"""The temporal growth rate sigma = kH Im z as kH -> infinity (model.growth_rate_limit; docs/physics.md §14.14).

The limit comes from the reduced equation over the torus of the upper block's phases; the references here are the
contour solver's certified roots of the full F at large kH (model.fastest_mode), which do not use the reduction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from asymslide import model

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


def test_finite_eta_is_refused_and_input_is_checked() -> None:
    lim = model.growth_rate_limit(**PAPER, eta=10.0)
    assert int(lim.status) == 2 and math.isnan(float(lim.sigma))
    with pytest.raises(ValueError, match="gamma"):
        model.growth_rate_limit(gamma=-1.0, f=0.9, beta=0.3)
    with pytest.raises(ValueError, match="beta"):
        model.growth_rate_limit(gamma=1.0, f=0.9, beta=0.9)


@pytest.mark.slow
def test_it_broadcasts() -> None:
    lim = model.growth_rate_limit(gamma=np.array([1.0, 3.0]), f=0.9, beta=0.3)
    assert lim.sigma.shape == (2,) and lim.phases.shape == (2, 2)
    assert lim.status.tolist() == [1, 0]


@pytest.mark.slow
def test_sliding_analysis_states_the_limit_beside_the_range() -> None:
    """With rate=True at eta = inf, sliding_analysis gives the limit beside the maximum over its kH range: at gamma = 3
    the range's maximum (kH = 0.49) is above it (attained); at gamma = 10 the rate over [1e-2, 1e2] peaks at kH ~ 56
    below the limit, which it then approaches beyond the range; at gamma = 1 sliding is stable and nothing grows as
    kH -> infinity. Without rate, and at finite eta, the limit is NaN."""
    r = model.sliding_analysis(gamma=np.array([1.0, 3.0, 10.0]), f=0.9, beta=0.3, rate=True)
    assert r.rate_limit[0] == 0.0 and not r.rate_beyond_range[0] and int(r.verdict[0]) == 0
    assert r.rate[1] > r.rate_limit[1] > 0.0 and not r.rate_beyond_range[1] and 0.4 < r.kH_at_max_rate[1] < 0.6
    assert r.rate_limit[2] > r.rate[2] and r.rate_beyond_range[2] and r.kH_at_max_rate[2] < 100.0
    assert abs(r.rate_limit_re_z[2] - float(model.growth_rate_limit(gamma=10.0, f=0.9, beta=0.3).x)) < 1e-6
    plain = model.sliding_analysis(gamma=3.0, f=0.9, beta=0.3)
    finite = model.sliding_analysis(gamma=3.0, f=0.9, beta=0.3, eta=10.0, rate=True)
    assert math.isnan(float(plain.rate_limit)) and math.isnan(float(finite.rate_limit))
    assert not bool(plain.rate_beyond_range) and not bool(finite.rate_beyond_range)
