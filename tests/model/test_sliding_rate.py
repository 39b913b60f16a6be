"""The temporal growth rate sigma = kH Im z (c_s/H) over a kH range at finite eta (docs/physics.md §14.15):
model.sliding_analysis(rate=True).

Issue 48 measured on main: ``rate`` NaN at every finite eta tried (eta = 2, 10; gamma = 1, 3), and at eta = 1e8 a
maximum 13x below eta = inf's, whose root fastest_mode finds at eta = 1e8 between the grid points. Here the rate's
maximum is certified inside the range, large eta equals eta = inf where the lower block's waves cannot reach its far
face, and the maximum is checked with the independent oracle (tests/oracle.py, its own contour count): one root at
the reported (kH, z), none higher in sigma there or beside it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from mpmath import mp

from asymslide import model
from asymslide.model import sliding
from tests import oracle

INF = math.inf
PAPER = dict(f=0.9, beta=0.3)


@pytest.mark.slow
@pytest.mark.parametrize("eta, gamma", [(2.0, 1.0), (2.0, 3.0), (10.0, 1.0), (10.0, 3.0)])
def test_the_temporal_rate_at_finite_eta_is_certified_inside_the_range(eta: float, gamma: float) -> None:
    """The four sets of the issue: rate is a certified maximum inside the range, not below the rate of the fastest
    root at any grid point (fastest_mode there), and its root is that of the maximum (its Im z times its kH)."""
    p = dict(PAPER, gamma=gamma, eta=eta)
    r = model.sliding_analysis(**p, rate=True)
    assert int(r.verdict_reason) == sliding.S_UNSTABLE
    sigma, kh, z = float(r.rate), float(r.kH_at_max_rate), complex(r.z_at_max_rate)
    assert math.isfinite(sigma) and not bool(r.rate_at_end)
    assert r.kH_range[0] < kh < r.kH_range[1]
    assert sigma == pytest.approx(kh * z.imag, rel=1e-12)
    grid = model.SLIDING_KH
    fm = model.fastest_mode(grid, **p, count=False)
    ok = fm.status == 0
    assert ok.sum() >= 10
    assert np.all(grid[ok] * fm.growth[ok] <= sigma * (1 + 1e-9))


@pytest.mark.slow
def test_ranked_in_time_the_fastest_mode_is_not_the_one_of_largest_im_z() -> None:
    """eta = 10, gamma = 3 (the issue's first measurement): the largest Im z sits at the range's end kH = 0.01, where
    it grows in time at kH Im z ~ 0.002 c_s/H; the fastest in time grows at 0.0723 c_s/H at kH ~ 0.42, interior."""
    r = model.sliding_analysis(**PAPER, gamma=3.0, eta=10.0, rate=True)
    assert bool(r.max_at_end) and float(r.kH_at_max) == pytest.approx(0.01)
    in_time_of_im_max = float(r.kH_at_max) * float(r.growth)
    assert in_time_of_im_max < 0.003
    assert float(r.rate) > 20 * in_time_of_im_max and 0.3 < float(r.kH_at_max_rate) < 0.6
    assert float(r.rate) == pytest.approx(0.0723332, rel=1e-5)


@pytest.mark.slow
@pytest.mark.parametrize("gamma", [2.5125, 3.0])
def test_large_eta_gives_eta_infs_maxima(gamma: float) -> None:
    """At eta = 1e3, 1e4, 1e8 the maxima of Im z and of kH Im z equal eta = inf's to 1e-9 (the issue measured 0.0021 at
    eta = 1e8 for eta = inf's 0.0276 at gamma = 2.5125): above the real axis the lower block's waves decay like
    exp(-eta kH Re alpha) before its far face, so the roots are eta = inf's; the eta = inf analysis guides the search
    (ETA_GUIDE)."""
    ref = model.sliding_analysis(**PAPER, gamma=gamma, eta=INF, rate=True)
    for eta in (1e3, 1e4, 1e8):
        r = model.sliding_analysis(**PAPER, gamma=gamma, eta=eta, rate=True)
        assert int(r.verdict_reason) == sliding.S_UNSTABLE, eta
        for name in ("growth", "rate"):
            assert float(getattr(r, name)) == pytest.approx(float(getattr(ref, name)), rel=1e-9), (eta, name)
        assert complex(r.z_at_max_rate) == pytest.approx(complex(ref.z_at_max_rate), rel=1e-9)


#: the sets whose rate maximum the oracle checks (finite eta, one guided by eta = inf)
ORACLE_SETS = [dict(PAPER, gamma=3.0, eta=10.0), dict(PAPER, gamma=3.0, eta=2.0),
               dict(PAPER, gamma=2.5125, eta=1e3)]


def _count(kh: float, p: dict, lo: float, hi: float) -> int:
    """The oracle's count of roots with lo <= Im z <= hi in the model's window at Im z >= lo (docs/physics.md §14's
    theorem, tested against the oracle's F on rays in test_sliding.py)."""
    re, _ = model.root_window(kh, **p, floor=lo)
    return oracle.count_roots(kh, p["gamma"], p["f"], p["beta"], p["eta"], x0=-float(re), x1=float(re), y0=lo,
                              y1=hi)


@pytest.mark.slow
@pytest.mark.parametrize("p", ORACLE_SETS, ids=lambda p: f"gamma={p['gamma']},eta={p['eta']:g}")
def test_the_rate_maximum_against_the_oracle(p: dict) -> None:
    """At the reported kH the oracle's F vanishes at z, and its count finds exactly one root with sigma within 1e-3
    below the maximum and none above it (1 + 1e-4); at kH x e^(+-0.05) none reaches the maximum."""
    r = model.sliding_analysis(**p, rate=True)
    sigma, kh, z = float(r.rate), float(r.kH_at_max_rate), complex(r.z_at_max_rate)
    args = (p["gamma"], p["f"], p["beta"], p["eta"])
    with mp.workdps(30):
        res = abs(oracle.dispersion(z, kh, *args)) / abs(oracle.dispersion_dz(z, kh, *args))
    assert res < 1e-9 * abs(z)
    _, top = model.root_window(kh, **p, floor=sigma / kh * (1 - 1e-3))
    hi = 1.01 * float(top) + 1e-3
    assert _count(kh, p, sigma / kh * (1 - 1e-3), hi) == 1
    assert _count(kh, p, sigma / kh * (1 + 1e-4), hi) == 0
    for side in (math.exp(-0.05), math.exp(0.05)):
        k = kh * side
        assert _count(k, p, sigma / k, 1.01 * float(model.root_window(k, **p, floor=sigma / k)[1]) + 1e-3) == 0
