"""The temporal growth rate sigma = kH Im z (c_s/H) over a kH range at finite eta (docs/physics.md §14.15):
model.sliding_analysis(rate=True).

Measured before this was built: ``rate`` NaN at every finite eta tried (eta = 2, 10; gamma = 1, 3), and at eta = 1e8 a
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


# ------------------------------------------------------------------------------------------------
# sigma over every kH (docs/physics.md §14.16)
# ------------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_sigma_over_every_kh_does_not_depend_on_the_range() -> None:
    """gamma = 3, eta = inf: over [1, 100] the rate peaks at kH ~ 56 (0.04808), but sigma, the supremum over every
    kH, is the maximum at kH = 0.4932 that the default range [0.01, 100] holds, found below the range."""
    full = model.sliding_analysis(**PAPER, gamma=3.0, rate=True)
    short = model.sliding_analysis(**PAPER, gamma=3.0, kH=np.logspace(0, 2, 9), rate=True)
    assert float(short.rate) < 0.0481 < float(full.rate)
    for r in (full, short):
        assert float(r.sigma) == pytest.approx(0.0485628317, rel=1e-9)
        assert float(r.kH_at_sigma) == pytest.approx(0.49317917, rel=1e-6)
        assert complex(r.z_at_sigma) == pytest.approx(complex(full.z_at_max_rate), rel=1e-9)
        assert float(r.sigma_kH_low) < 0.01
    plain = model.sliding_analysis(**PAPER, gamma=3.0)
    assert math.isnan(float(plain.sigma)) and math.isnan(float(plain.kH_at_sigma))
    # at finite eta too: over [1, 100] the rate's maximum is 0.0710; the search below the range finds kH = 0.419's
    short10 = model.sliding_analysis(**PAPER, gamma=3.0, eta=10.0, kH=np.logspace(0, 2, 9), rate=True)
    assert float(short10.rate) < 0.0711 and float(short10.sigma) == pytest.approx(0.0723331963, rel=1e-9)
    assert float(short10.kH_at_sigma) == pytest.approx(0.41912706, rel=1e-6)


@pytest.mark.slow
def test_sigma_is_approached_as_kh_goes_to_infinity_or_is_nan_where_nothing_grows() -> None:
    """gamma = 15: the range's maximum (0.273074 at kH = 56) is below the limit 0.273087, so sigma is the limit,
    approached as kH -> infinity (kH_at_sigma = inf, z_at_sigma its Re z); gamma = 3: attained at kH = 0.49;
    gamma = 1: stable on the range and nothing grows as kH -> infinity: NaN, not a rate."""
    r = model.sliding_analysis(**PAPER, gamma=np.array([15.0, 3.0, 1.0]), rate=True)
    assert r.rate[0] < r.rate_limit[0] == r.sigma[0] and math.isinf(r.kH_at_sigma[0])
    assert r.z_at_sigma[0] == complex(r.rate_limit_re_z[0], 0.0)
    assert r.sigma[1] == r.rate[1] > r.rate_limit[1] and r.kH_at_sigma[1] == r.kH_at_max_rate[1]
    assert int(r.verdict[2]) == 0 and r.rate_limit[2] == 0.0 and math.isnan(r.sigma[2])


@pytest.mark.slow
def test_below_the_range_the_oracle_finds_no_faster_root() -> None:
    """eta = 10, gamma = 3: below the range's start the model searched quarter decades down to sigma_kH_low, where
    the bound of §14.3 at Im z = sigma/kH holds (the window above sigma/kH is empty there and at every smaller kH);
    the oracle's counts above sigma/kH at those quarter decades are 0."""
    p = dict(PAPER, gamma=3.0, eta=10.0)
    r = model.sliding_analysis(**p, rate=True)
    sigma, low = float(r.sigma), float(r.sigma_kH_low)
    assert 1e-4 < low < 0.01 and float(r.kH_at_sigma) > 0.01
    for kh in (low, low / 10, low / 1e3):
        _, top = model.root_window(kh, **p, floor=sigma / kh)
        assert float(top) <= sigma / kh * (1 + 1e-4)  # no room above sigma / kH
    for kh in np.exp(np.arange(math.log(low), math.log(0.01), math.log(10) / 4)):
        _, top = model.root_window(kh, **p, floor=sigma / kh)
        assert _count(kh, p, sigma / kh, 1.01 * float(top) + 1e-3) == 0, kh
