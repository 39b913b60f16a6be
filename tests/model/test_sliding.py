"""The whole spectrum (docs/physics.md §14): model.root_window, model.fastest_mode, model.sliding_analysis.

The window is a theorem (a lower bound of Re[F/(iz)] at large |z|); it is checked here with the oracle's F on rays
beyond it. The fastest root and the count above the floor are compared with the independent oracle (mpmath, its
own contour sampling: tests/oracle.py §8) on random parameter sets, finite eta and xi > 0 included, in the complete
window. Then the mechanisms that hide roots: a fastest root outside the old default window, a fastest mode that
changes family as kH moves, and the floor at finite eta.
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mpmath import mp

from asymslide import model
from asymslide.model import sliding
from asymslide.model._roots import track
from asymslide.model._roots.search import Search
from asymslide.model._roots.track import Analysis
from tests import oracle

INF = math.inf
PAPER = dict(gamma=3.0, f=0.9, beta=0.3)
# the example of a fastest root outside the old default window, at eta = inf
FAST_OFF_WINDOW = dict(gamma=23.65, f=0.8219, beta=0.3014, Delta=0.6091, xi=1.0)


def _oracle_args(p: dict) -> dict:
    return dict(gamma=p["gamma"], f=p["f"], beta=p["beta"], eta=p.get("eta", INF), Delta=p.get("Delta", 1.0),
                xi=p.get("xi", 0.0))


# ------------------------------------------------------------------------------------------------
# where the roots can be
# ------------------------------------------------------------------------------------------------

WINDOW_CASES = [
    (1.0, dict(PAPER), 1e-6),
    (3.0, dict(FAST_OFF_WINDOW), 1e-6),
    (0.05, dict(gamma=0.7, f=-1.1, beta=0.62, Delta=0.3, xi=0.0), 1e-6),
    (0.77, dict(PAPER, eta=10.0), 1e-2),
    (2.0, dict(gamma=12.0, f=0.4, beta=0.15, eta=2.5, Delta=0.5, xi=3.0), 3e-2),
    (0.3, dict(gamma=5.0, f=0.9, beta=0.3, eta=1.0), 1e-3),
]


@pytest.mark.parametrize("kH, p, floor", WINDOW_CASES)
def test_no_root_beyond_the_window_oracle_rays(kH, p, floor):
    """Re[F/(iz)] > 0 (so F != 0) at the oracle's points on rays beyond the window, down to Im z = floor."""
    re_max, im_max = model.root_window(kH, **p, floor=floor)
    margin = oracle.exterior_min_margin(kH, **_oracle_args(p), re_max=float(re_max), im_min=floor,
                                        im_max=float(im_max), n=240, dps=20)
    assert margin > 0.0


@settings(max_examples=60, deadline=None)
@given(
    kH=st.floats(1e-2, 1e2), gamma=st.floats(0.05, 200.0), f=st.floats(-2.0, 2.0), beta=st.floats(0.05, 0.7071),
    eta=st.one_of(st.just(INF), st.floats(0.2, 1e3)), Delta=st.floats(0.05, 1.0), xi=st.floats(0.0, 50.0),
    floor=st.floats(1e-6, 0.1), t=st.floats(0.0, 1.0), r=st.floats(1.0, 30.0), seed=st.integers(0, 2**31),
)
def test_lower_bound_of_re_f_over_iz_holds(kH, gamma, f, beta, eta, Delta, xi, floor, t, r, seed):
    """The model's F: Re[F/(iz)] > 0 at points with Im z >= floor and |z| >= rho(floor) (the exclusion radius)."""
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    re_max, _ = model.root_window(kH, **p, floor=floor)
    if not math.isfinite(float(re_max)):
        return
    rng = np.random.default_rng(seed)
    rad = float(re_max) * r * rng.uniform(1.0, 1.5, 64)
    ang = rng.uniform(0.0, math.pi, 64)
    z = rad * np.exp(1j * ang)
    z = z.real + 1j * np.maximum(z.imag, floor * (1.0 + t))
    z = z[np.abs(z) >= float(re_max)]
    w = model.dispersion(z, kH, **p) / (1j * z)
    assert np.all(w.real > 0.0)


def test_window_is_finite_at_eta_inf_for_floor_zero_limit_and_grows_like_one_over_floor_at_finite_eta():
    """eta = inf: the window hardly depends on the floor (about 2 gamma |f| / S + ...); finite eta: it grows like
    1/floor (the roots just above the layers' poles reach out as Im z |Re z| ~ const, §14)."""
    r_inf = [float(model.root_window(1.0, **PAPER, floor=fl)[0]) for fl in (1e-3, 1e-6, 1e-9)]
    assert max(r_inf) / min(r_inf) < 1.01 and max(r_inf) < 10.0
    r10 = [float(model.root_window(0.77, **PAPER, eta=10.0, floor=fl)[0]) for fl in (1e-3, 1e-4, 1e-5)]
    assert 8.0 < r10[1] / r10[0] < 12.0 and 8.0 < r10[2] / r10[1] < 12.0


def test_half_space_limit_has_no_growing_root():
    """Well-posedness (§14): at kH -> inf, F tends to the identical-half-space F_inf (G_y = 0), which has no root with
    Im z > 0, so the temporal rate kH Im z stays bounded. Counted where F = F_inf to rounding (kH Im z >= 1e3)."""
    rng = np.random.default_rng(31)
    for _ in range(24):
        p = dict(gamma=float(10 ** rng.uniform(-2, 4)), f=float(rng.uniform(-3, 3)),
                 beta=float(rng.uniform(0.05, 0.7071)), eta=INF, Delta=float(10 ** rng.uniform(-4, 0)),
                 xi=float(rng.choice([0.0, 10 ** rng.uniform(-3, 4)])))
        search = Search(*(p[k] for k in ("gamma", "f", "beta", "eta", "Delta", "xi")), 1e-9)
        q = 1e12
        assert search.count(q, search.rho(1e-9, q), 1e-9, search.top(q)) == 0, p


# ------------------------------------------------------------------------------------------------
# the fastest root and the count above the floor against the oracle
# ------------------------------------------------------------------------------------------------


def _floor_of_width(kH: float, p: dict, width: float) -> float:
    """The lowest floor (to 1e-3 relative) whose window has re_max <= width (re_max falls as the floor rises)."""
    lo, hi = 1e-6, 1.0
    if float(model.root_window(kH, **p, floor=lo)[0]) <= width:
        return lo
    while hi / lo > 1.001:
        mid = math.sqrt(lo * hi)
        lo, hi = (lo, mid) if float(model.root_window(kH, **p, floor=mid)[0]) <= width else (mid, hi)
    return hi


def _random_cases(seed: int) -> list[tuple[float, dict, float]]:
    """Parameter sets whose complete window at their floor is at most 25 wide (the oracle's cost), mostly where
    sliding is unstable, Delta < 1 with xi > 0 in about half: 14 at eta = inf with floor 1e-6, and 12 at finite
    eta (8 with roots above the floor), each with the lowest floor whose window is 20 wide (finite eta: the
    window grows like 1/floor)."""
    rnd = random.Random(seed)
    inf_cases: list[tuple[float, dict, float]] = []
    fin_cases: list[tuple[float, dict, float]] = []
    with_roots = 0
    while len(inf_cases) < 14 or len(fin_cases) < 12:
        finite = len(inf_cases) >= 14
        p = dict(gamma=10 ** rnd.uniform(0.3 if finite else 0.0, 1.2), f=rnd.choice((-1, 1)) * rnd.uniform(0.4, 1.2),
                 beta=rnd.uniform(0.2, 0.65), eta=10 ** rnd.uniform(0.3, 1.6) if finite else INF)
        if rnd.random() < 0.5:
            p.update(Delta=rnd.uniform(0.2, 0.9), xi=10 ** rnd.uniform(-1, 1))
        if not finite:
            kH = 10 ** rnd.uniform(-0.7, 0.7)
            if float(model.root_window(kH, **p, floor=1e-6)[0]) <= 25.0:
                inf_cases.append((kH, p, 1e-6))
            continue
        kH = 10 ** rnd.uniform(-0.5, 0.5)
        floor = _floor_of_width(kH, p, 20.0)
        if not 1e-3 < floor < 0.05:
            continue
        n = int(model.fastest_mode(kH, **p, floor=floor).count)
        if n > 0 or len(fin_cases) - with_roots < 4:
            fin_cases.append((kH, p, floor))
            with_roots += n > 0
    return inf_cases + fin_cases


ORACLE_CASES = _random_cases(2031)


def test_the_oracle_cases_cover_finite_eta_xi_and_unstable_sets():
    """The random cases below are not trivial: most hold roots above the floor, finite eta and xi > 0 among them."""
    counts = [int(model.fastest_mode(kH, **p, floor=fl).count) for kH, p, fl in ORACLE_CASES]
    finite = [math.isfinite(p["eta"]) for _, p, _ in ORACLE_CASES]
    assert sum(c > 0 for c in counts) >= 14 and sum(c > 1 for c in counts) >= 6
    assert sum(c > 0 and fi for c, fi in zip(counts, finite, strict=True)) >= 8
    assert sum(p.get("xi", 0.0) > 0 and c > 0 for (_, p, _), c in zip(ORACLE_CASES, counts, strict=True)) >= 5


@pytest.mark.slow
@pytest.mark.parametrize("kH, p, floor", ORACLE_CASES)
def test_fastest_mode_and_count_against_the_oracle(kH, p, floor):
    """The fastest root within 1e-10 relative, and the exact count of roots with Im z >= floor, in the complete
    window (the model's root_window; the oracle counts and locates in it with its own sampling)."""
    fm = model.fastest_mode(kH, **p, floor=floor)
    re_max, im_max = float(fm.re_max), float(fm.im_max)
    z_o, n_o = oracle.fastest_root(kH, **_oracle_args(p), re_max=re_max, im_min=floor, im_max=im_max, dps=20)
    assert int(fm.count) == n_o
    if n_o == 0:
        assert int(fm.status) == sliding.M_BELOW and math.isnan(float(fm.growth))
    else:
        assert int(fm.status) == sliding.M_OK
        assert abs(complex(fm.z) - complex(z_o)) <= 1e-10 * abs(complex(z_o))


# ------------------------------------------------------------------------------------------------
# mechanisms
# ------------------------------------------------------------------------------------------------


def test_fastest_root_just_outside_the_old_default_window():
    """At kH = 0.3 the fastest root 5.0859 + 0.6080i (13x the Rayleigh branch's max growth) lies beyond
    |Re z| <= 5, the All-branches tab's old default window; fastest_mode finds it, the oracle agrees."""
    fm = model.fastest_mode(0.3, **FAST_OFF_WINDOW)
    z = complex(fm.z)
    assert abs(z - (5.0859 + 0.6080j)) < 1e-4 and int(fm.family) == 3
    assert not np.any(np.abs(model.unstable_modes(0.3, **FAST_OFF_WINDOW) - z) < 1e-8)  # not in the old window
    roots = oracle.roots_in_rectangle(0.3, **_oracle_args(FAST_OFF_WINDOW), x0=5.0, x1=5.2, y0=0.55, y1=0.65)
    assert len(roots) == 1 and abs(complex(roots[0]) - z) <= 1e-12 * abs(z)
    growth = float(model.growth_analysis(np.logspace(-2, 2, 17), **FAST_OFF_WINDOW).growth)
    assert z.imag > 13.0 * growth


def test_fastest_mode_changes_family_as_kH_moves():
    """The paper's defaults: at kH = 1 the fastest root is the Rayleigh branch (docs/physics.md §7), at kH = 0.45
    a root faster than the dilatational wave (§3, §7)."""
    fm = model.fastest_mode([0.45, 1.0], **PAPER)
    assert abs(complex(fm.z[0]) - (3.53354704617255 + 0.07585981635187j)) < 1e-13
    assert abs(complex(fm.z[1]) - (0.88336356305352538 + 0.00815518661032729j)) < 1e-14
    assert fm.family.tolist() == [3, 0]
    assert model.FAMILIES[3].startswith("supersonic") and model.FAMILIES[0] == "Rayleigh branch"


@pytest.mark.slow
def test_the_floor_at_finite_eta():
    """eta = 10, kH = 0.77: the fastest root 5.8889 + 0.0399i lies beyond |Re z| <= 5 (the old default window) and
    does not depend on the floor; the count above the floor grows as the floor drops (17 above 1e-2, the oracle's
    count; 28 above 7e-3), and at 1e-6 the window (|Re z| < 1.4e6) is refused for counting, the fastest root still
    certified."""
    counts = []
    for floor in (1e-2, 7e-3, 1e-6):
        fm = model.fastest_mode(0.77, **PAPER, eta=10.0, floor=floor)
        assert int(fm.status) == sliding.M_OK
        assert abs(complex(fm.z) - (5.88885572455388 + 0.039925285843501j)) < 1e-12
        counts.append(int(fm.count))
    assert counts == [17, 28, -1]
    re_max, im_max = model.root_window(0.77, **PAPER, eta=10.0, floor=1e-2)
    assert oracle.count_roots(0.77, **_oracle_args(dict(PAPER, eta=10.0)), x0=-float(re_max), x1=float(re_max),
                              y0=1e-2, y1=float(im_max)) == 17


# ------------------------------------------------------------------------------------------------
# over a kH range
# ------------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_sliding_is_unstable_where_the_rayleigh_branch_is_stable():
    """gamma = 2 (below the Rayleigh branch's gamma_c = 2.41): the Rayleigh branch is stable, sliding is not: a
    backward root just beyond the shear speed grows at kH ~ 20 (checked a root of the oracle's F and the fastest
    in the complete window there)."""
    r = model.sliding_analysis(gamma=2.0, f=0.9, beta=0.3)
    assert int(r.rayleigh.verdict) == 0 and int(r.verdict) == 1 and int(r.verdict_reason) == sliding.S_UNSTABLE
    z, kH = complex(r.z_at_max), float(r.kH_at_max)
    assert -1.01 < z.real < -1.0 and 1e-5 < z.imag < 1e-4 and 10 < kH < 40 and int(r.family) == 2
    with mp.workdps(30):
        res = abs(oracle.dispersion(z, kH, 2.0, 0.9, 0.3, INF)) / abs(oracle.dispersion_dz(z, kH, 2.0, 0.9, 0.3, INF))
    assert res < 1e-12 * abs(z)  # a root to ~1e-12 (|F/F'| is the distance to it)


def test_paper_defaults_fastest_mode_is_supersonic_and_about_nine_times_the_rayleigh_branch():
    r = model.sliding_analysis(**PAPER)
    assert int(r.verdict) == 1 and int(r.family) == 3
    assert abs(float(r.growth) - 0.0990362481632939) < 1e-12
    assert abs(float(r.rayleigh.growth) - 0.0106758) < 1e-7
    assert 9.0 < float(r.growth) / float(r.rayleigh.growth) < 9.5


def test_sliding_stable_set():
    """gamma = 1 (f = 0.9, beta = 0.3): no root of any branch above the floor anywhere in the range."""
    r = model.sliding_analysis(gamma=1.0, f=0.9, beta=0.3)
    assert int(r.verdict) == 0 and int(r.verdict_reason) == sliding.S_STABLE and math.isnan(float(r.growth))
    for kH in (0.05, 0.8, 20.0):
        assert int(model.fastest_mode(kH, gamma=1.0, f=0.9, beta=0.3).count) == 0


def test_sliding_maximum_is_never_below_the_rayleigh_branch():
    rng = np.random.default_rng(7)
    for _ in range(6):
        p = dict(gamma=float(10 ** rng.uniform(0.2, 1.3)), f=float(rng.uniform(0.3, 1.2)),
                 beta=float(rng.uniform(0.1, 0.65)), Delta=float(rng.uniform(0.3, 1.0)), xi=1.0)
        r = model.sliding_analysis(**p)
        if int(r.rayleigh.verdict) == 1 and int(r.verdict_reason) == sliding.S_UNSTABLE:
            assert float(r.growth) >= float(r.rayleigh.growth) * (1 - 1e-12), p
            if int(r.family) == 0:
                assert abs(float(r.growth) - float(r.rayleigh.growth)) <= 1e-12 * float(r.growth), p


@pytest.mark.parametrize("eta", [INF, 10.0])
def test_grid_points_searched_once_agree_with_fastest_mode_at_each_kH(eta):
    """sliding_analysis searches a grid point once for the sample and the track (every root above a fraction of the
    maximum so far, located: Analysis.every_root). At each grid point its fastest root is fastest_mode's (the
    banded, best-first search of one kH, checked against the oracle above), and a point found empty above a level
    has no root there."""
    rng = np.random.default_rng(2031 if math.isinf(eta) else 2032)
    searched_once = 0
    for _ in range(3):
        p = dict(gamma=float(10 ** rng.uniform(0.0, 1.3)), f=float(rng.uniform(0.3, 1.2)),
                 beta=float(rng.uniform(0.1, 0.65)), Delta=float(rng.uniform(0.3, 1.0)), xi=1.0, eta=eta)
        ray = model.growth_analysis(**p, kH=model.SLIDING_KH)
        an = Analysis(Search(*(p[k] for k in ("gamma", "f", "beta", "eta", "Delta", "xi")),
                                               model.DEFAULT_FLOOR), np.log(model.SLIDING_KH))
        g = float(ray.growth)
        an.sample((math.log(float(ray.kH_at_max)), complex(float(ray.re_z_at_max), g))
                  if math.isfinite(g) and g >= model.DEFAULT_FLOOR else None)
        for s, (level, found) in an.known.items():
            searched_once += 1
            fm = model.fastest_mode(math.exp(s), **p)
            t = an.tops[s]
            roots = [r for r in found if r[0].imag >= model.DEFAULT_FLOOR]  # (eta = inf: searched to floor/10)
            if roots:
                assert t.status == sliding.M_OK and abs(t.z - complex(fm.z)) <= 1e-10 * abs(t.z), (p, s)
                assert all(r[0].imag <= t.z.imag for r in roots)
            else:
                assert t.status == sliding.M_BELOW and not float(fm.growth) >= max(level, model.DEFAULT_FLOOR), (p, s)
    assert searched_once >= 10


def test_sliding_analysis_broadcasts_and_chunk_rows():
    g = np.array([[1.0], [3.0]])
    r = model.sliding_analysis(gamma=g, f=0.9, beta=0.3, eta=np.array([INF, INF]))
    assert r.verdict.shape == (2, 2) and r.verdict.tolist() == [[0, 0], [1, 1]]
    rows = model.sliding_chunk(np.log(model.SLIDING_KH), np.array([[3.0], [0.9], [0.3], [INF], [1.0], [0.0]]))
    assert rows.shape == (len(model.SLIDING_ROWS), 1)
    assert rows[model.SLIDING_ROWS.index("growth_all"), 0] == float(r.growth[1, 0])


@pytest.mark.parametrize("bad", [0.0, -1e-6, math.nan, math.inf, "1e-6", [1e-6, 1e-5], 1j])
def test_bad_floor_is_refused(bad):
    for fn in (lambda: model.fastest_mode(1.0, **PAPER, floor=bad), lambda: model.root_window(1.0, **PAPER, floor=bad),
               lambda: model.sliding_analysis(**PAPER, floor=bad)):
        with pytest.raises(ValueError, match="floor"):
            fn()


def test_bad_parameters_are_refused():
    with pytest.raises(ValueError, match="gamma"):
        model.fastest_mode(1.0, gamma=-1.0, f=0.9, beta=0.3)
    with pytest.raises(ValueError, match="kH"):
        model.fastest_mode(-1.0, **PAPER)
    with pytest.raises(ValueError, match="kH"):
        model.sliding_analysis(**PAPER, kH=[1.0, 0.5])


# ------------------------------------------------------------------------------------------------
# thresholds of sliding (every branch)
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("f", [0.9, -0.9])
def test_sliding_threshold_in_gamma_is_the_oracles_neutral_mode(f):
    """f = +-0.9, beta = 0.3, eta = inf: sliding turns unstable at gamma = 1.1866, well below the Rayleigh branch's
    2.4149 (+0.9; none for -0.9), through the backward (forward for -0.9) root just beyond the shear speed whose
    maximum reaches the end of the kH range [1e-2, 1e2] there (reason 1). The neutral mode, on the upper lip of the
    cut, equals the oracle's (50 digits) to 1e-12; the mirror f -> -f maps x -> -x."""
    c = model.critical_gammas(f=f, beta=0.3, branches="all")
    assert int(c.count) == 1 and int(c.reason[0]) == 1 and int(c.direction[0]) == 1
    value, kH, x = float(c.value[0]), float(c.kH[0]), float(c.z[0])
    assert abs(value - 1.18660385697411) < 1e-11 and kH == pytest.approx(100.0, rel=1e-14)
    assert 1.0 < abs(x) < 1.001 and np.sign(x) == -np.sign(f)
    xo, qo, vo = oracle.neutral_mode("gamma", x, kH, value, 0, f, 0.3, INF, edge=True, upper_lip=True)
    assert abs(float(vo) - value) <= 1e-12 * value and abs(float(xo) - x) <= 1e-12
    # either side of the threshold: the sliding verdict (with a floor far below the growth there) changes
    for g, verdict in ((value * (1 - 1e-3), 0), (value * (1 + 1e-3), 1)):
        assert int(model.sliding_analysis(gamma=g, f=f, beta=0.3, floor=1e-10).verdict) == verdict


def test_sliding_thresholds_api():
    ray = model.critical_gamma(f=0.9, beta=0.3)
    allb = model.critical_gamma(f=0.9, beta=0.3, branches="all")
    assert allb < ray and abs(ray - 2.414880573904695) < 1e-12
    with pytest.raises(ValueError, match="branches"):
        model.critical_gammas(f=0.9, beta=0.3, branches="every")
    with pytest.raises(ValueError, match="no sliding threshold"):
        model.critical_gamma(f=0.9, beta=0.3, eta=10.0, branches="all", gamma_range=(1.0, 10.0))


# -- roots across the cuts beside the branch points (eta = inf; model._roots.cuts) -------------------------------


@pytest.mark.parametrize("chart", [1, 2, 3, 4])
def test_chart_across_a_cut_is_f_on_the_physical_sheet_against_the_oracle(chart):
    """In a chart (the local variable w = alpha_d beside +-1/beta, alpha_s beside +-1), F at a point with Re w > 0
    and Im z > 0 is F of the physical sheet at z(w): the oracle's (mpmath, principal square roots), to 1e-12; and
    dF/dv is the derivative of the chart's F (a central difference, to 1e-6)."""
    from asymslide.model._kernels.response import CHART_ORIGIN, chart_point, dispersion_eval

    rng = random.Random(chart)
    p = dict(gamma=2.7, f=0.8, beta=0.41, eta=INF, Delta=0.7, xi=0.9)
    par = (p["gamma"], p["f"], p["beta"], -float(chart), p["Delta"], p["xi"])
    checked = 0
    for _ in range(12):
        w = complex(rng.uniform(0.01, 0.5), rng.uniform(-0.5, 0.5))
        v = w + CHART_ORIGIN
        z = chart_point(v, p["beta"], chart)[0]
        if not z.imag > 0:
            continue
        kH = 10 ** rng.uniform(-1.5, 1.5)
        fv, dfv, _ = dispersion_eval(v, kH, *par)
        with mp.workdps(30):
            fo = complex(oracle.dispersion(z, kH, p["gamma"], p["f"], p["beta"], INF, p["Delta"], p["xi"]))
        assert abs(fv - fo) <= 1e-12 * max(abs(fo), 1.0), (chart, w, kH)
        h = 1e-6
        num = (dispersion_eval(v + h, kH, *par)[0] - dispersion_eval(v - h, kH, *par)[0]) / (2 * h)
        assert abs(num - dfv) <= 1e-6 * max(abs(dfv), 1.0), (chart, w, kH)
        checked += 1
    assert checked >= 4


BORN_AT_THE_CUT = dict(gamma=3.5880114280439144, f=0.628106392219389, beta=0.45668014955490915,
                       Delta=0.8914233559279807, xi=1.0)  # sample 14 of bench_sliding.py at eta = inf


def test_a_root_born_at_the_cut_between_grid_points_is_found(monkeypatch):
    """A root of the other sheet comes out of the cut just beyond 1/beta at kH ~ 0.76, grows to Im z = 0.0167 at kH
    = 0.81 (ten times the fastest root at any grid point) and leaves through the real axis at kH ~ 0.88: it is on
    the physical sheet between two grid points only. Followed in the chart beside 1/beta from the grid point kH = 1
    (where it lies below the real axis), it is found: the default grid gives the maximum of a 129-point grid."""
    r = model.sliding_analysis(**BORN_AT_THE_CUT)
    dense = model.sliding_analysis(**BORN_AT_THE_CUT, kH=np.logspace(-2, 2, 129))
    assert int(r.verdict_reason) == sliding.S_UNSTABLE and int(dense.verdict_reason) == sliding.S_UNSTABLE
    assert abs(float(r.growth) - 0.016718942940617272) <= 1e-9 * 0.0167
    assert abs(float(r.growth) - float(dense.growth)) <= 1e-9 * float(r.growth)
    z = complex(r.z_at_max)
    assert 1.0 < z.real < 1.0 / BORN_AT_THE_CUT["beta"] and 0.7 < float(r.kH_at_max) < 0.9
    with mp.workdps(30):
        res = abs(oracle.dispersion(z, float(r.kH_at_max), BORN_AT_THE_CUT["gamma"], BORN_AT_THE_CUT["f"],
                                    BORN_AT_THE_CUT["beta"], INF, BORN_AT_THE_CUT["Delta"], BORN_AT_THE_CUT["xi"]))
        res /= abs(oracle.dispersion_dz(z, float(r.kH_at_max), BORN_AT_THE_CUT["gamma"], BORN_AT_THE_CUT["f"],
                                        BORN_AT_THE_CUT["beta"], INF, BORN_AT_THE_CUT["Delta"],
                                        BORN_AT_THE_CUT["xi"]))
    assert res < 1e-12 * abs(z)  # a root of the oracle's F on the physical sheet
    monkeypatch.setattr(track, "CUT_CHARTS", False)
    without = model.sliding_analysis(**BORN_AT_THE_CUT)
    assert float(without.growth) < 0.2 * float(r.growth)  # what the search found before the charts


RISES_ABOVE_THE_FLOOR = dict(gamma=1.6267023614672673, f=0.7395206334034172, beta=0.6558710838935,
                             Delta=0.6928799066512659, xi=1.0)  # sample 38 of bench_sliding.py at eta = inf


def test_a_root_rising_above_the_floor_between_grid_points_is_found(monkeypatch):
    """A backward root just beyond the shear speed is 8.5e-7 (below the floor 1e-6) at the grid points kH = 31.6 and
    56.2 and reaches 1.4e-6 between them: followed from the grid points (where it lies in [floor/10, floor)), it is
    found, and the verdict is unstable, as on a 129-point grid. Without following it the verdict was stable."""
    r = model.sliding_analysis(**RISES_ABOVE_THE_FLOOR)
    assert int(r.verdict) == 1 and int(r.rayleigh.verdict) == 0
    assert 1e-6 < float(r.growth) < 2e-6 and 31.6 < float(r.kH_at_max) < 56.2
    assert -1.01 < complex(r.z_at_max).real < -1.0
    for kH in (model.SLIDING_KH[14], model.SLIDING_KH[15]):  # below the floor at the grid points on either side
        assert int(model.fastest_mode(kH, **RISES_ABOVE_THE_FLOOR).count) == 0
    monkeypatch.setattr(track, "FLOOR_WATCH", 1.0)
    assert int(model.sliding_analysis(**RISES_ABOVE_THE_FLOOR).verdict) == 0


HUMP_BETWEEN_GRID = dict(gamma=0.22691293642141988, f=0.9141748518780519, beta=0.42186930346996965,
                         Delta=0.7571758773509893, xi=1.0, eta=10.0)  # sample 12 of bench_sliding.py at eta = 10


def test_at_finite_eta_the_maximum_is_a_lower_bound_and_says_so():
    """At finite eta a root can come up through the real axis beside a pole of the layers and fall back within 0.03
    decades of kH, between two grid points where it lies below the axis: the default grid does not see it. The result
    says so (lower_bound, docs/physics.md §14.7): its growth is a certified root's, and lower than that root's peak,
    which is the fastest root at its kH (the oracle's F vanishes there); a grid through that kH finds it. At eta =
    inf the flag is False."""
    r = model.sliding_analysis(**HUMP_BETWEEN_GRID)
    assert bool(r.lower_bound) and int(r.verdict_reason) == sliding.S_UNSTABLE
    kh_peak = 0.2526548620079365
    fm = model.fastest_mode(kh_peak, **HUMP_BETWEEN_GRID, count=False)
    z = complex(fm.z)
    assert abs(z - (3.5607739153409788 + 0.00809879384063006j)) <= 1e-9 * abs(z)
    assert float(r.growth) < 0.6 * z.imag  # the default grid's maximum, 0.00467: a lower bound
    p = {k: HUMP_BETWEEN_GRID[k] for k in ("gamma", "f", "beta", "eta", "Delta", "xi")}
    with mp.workdps(30):
        res = abs(oracle.dispersion(z, kh_peak, *p.values())) / abs(oracle.dispersion_dz(z, kh_peak, *p.values()))
    assert res < 1e-10 * abs(z)
    through = model.sliding_analysis(**HUMP_BETWEEN_GRID, kH=np.sort(np.append(model.SLIDING_KH, kh_peak)))
    assert float(through.growth) >= z.imag * (1 - 1e-9)
    assert not bool(model.sliding_analysis(**{**HUMP_BETWEEN_GRID, "eta": INF}).lower_bound)
