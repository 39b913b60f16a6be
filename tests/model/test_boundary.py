"""A stability boundary users can trust: the continuous max growth, its verdict, every threshold crossing as a
certified neutral mode, and the pole-dense regime (docs/physics.md §9).

Reference values come from the independent mpmath oracle (tests/oracle.py: neutral modes at 30 digits by Newton
on the three real equations, the branch's maximum by findroot on Im dz/dq) or from the model's own full-accuracy
spectrum where only a property is tested (a maximum no finer sampling beats, continuity).
"""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from asymslide import model
from asymslide.model._kernels import growth as K
from asymslide.model.crossings import CROSSING_STATUS, X_CERTIFIED, X_EDGE
from tests import oracle

KH = np.logspace(-3, 3, 97)  # the atlases' default kH grid
PAPER = dict(f=0.9, beta=0.3)


# --------------------------------------------------------------------------------------------
# 1. the continuous max growth
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_narrow_peak_between_grid_points_with_the_opposite_sign_of_the_grid_maximum() -> None:
    """gamma = 2.45, just above gamma_c = 2.41488: the unstable band is [0.61, 0.86], between two points of a grid
    of two points per decade, all of whose values are negative (the grid's largest, -0.0022 at kH = 1). The growth
    is the peak's: positive, equal to the oracle's maximum of the branch, with its band."""
    grid = np.logspace(-3, 3, 13)
    on_grid = model.spectrum(grid, gamma=2.45, **PAPER).imag
    assert np.all(on_grid < 0) and np.max(on_grid) < -2e-3
    r = model.growth_analysis(grid, gamma=2.45, **PAPER)
    q_star, g_star = oracle.rayleigh_branch_max_growth(0.73, 2.45, 0.9, 0.3, math.inf)
    assert float(r.growth) == pytest.approx(float(g_star), rel=1e-10) and float(r.growth) > 7e-4
    assert float(r.kH_at_max) == pytest.approx(float(q_star), rel=1e-6)
    assert r.verdict == 1 and r.verdict_reason == K.V_UNSTABLE and 0.6 < r.kH_min < r.kH_at_max < r.kH_max < 0.9
    band = model.spectrum(np.array([float(r.kH_min), float(r.kH_max)]), gamma=2.45, **PAPER)
    assert np.all(np.abs(band.imag) < 1e-14)


def test_growth_depends_on_the_grid_ends_only() -> None:
    """The same range sampled by 13, 97 or 1001 points (or any interior points): the same growth, bitwise."""
    p = dict(gamma=3.0, f=0.9, beta=0.3, eta=10.0, Delta=0.6, xi=2.0)
    inner = np.sort(np.exp(np.random.default_rng(0).uniform(math.log(1e-3), math.log(1e3), 40)))
    grids = [np.logspace(-3, 3, 13), KH, np.logspace(-3, 3, 1001), np.concatenate([[1e-3], inner, [1e3]])]
    values = [model.growth_analysis(g, **p) for g in grids]
    assert all(v.growth == values[0].growth and v.kH_at_max == values[0].kH_at_max for v in values)


def test_maximum_switching_peaks_is_continuous_to_1e_12() -> None:
    """eta = 10: the maximum over [1e-3, 1e3] sits at the grid's end kH = 1e-3 for gamma below 2.3211613 and at the
    Rayleigh peak near kH = 0.73 above. At gamma_s (located here by bisection on where the maximum is, to rounding)
    the growth is continuous: 1e-12 relative perturbations of gamma change it by less than its slope allows."""
    def analysis(g: float) -> model.GrowthResult:
        return model.growth_analysis(KH, gamma=g, f=0.9, beta=0.3, eta=10.0)

    a, b = 2.17, 2.62
    assert analysis(a).kH_at_max == pytest.approx(1e-3) and 0.7 < analysis(b).kH_at_max < 0.8
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (m, b) if analysis(m).kH_at_max < 2e-3 else (a, m)
    lo, hi = analysis(a * (1 - 1e-12)), analysis(b * (1 + 1e-12))
    assert lo.kH_at_max == pytest.approx(1e-3) and 0.7 < hi.kH_at_max < 0.8  # the maximum switched peaks ...
    assert abs(float(hi.growth) - float(lo.growth)) < 1e-13  # ... the growth did not jump (slope ~0.05)
    assert lo.verdict_reason == hi.verdict_reason == K.V_STABLE and float(lo.growth) < 0


PARAMS = ("gamma", "f", "beta", "eta", "Delta", "xi")


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(gamma=st.floats(0.3, 30.0), f=st.floats(0.2, 1.5), beta=st.floats(0.05, 0.7),
       eta=st.one_of(st.just(math.inf), st.floats(1.2, 1e4)), Delta=st.floats(0.2, 1.0), xi=st.floats(0.0, 10.0),
       which=st.sampled_from(PARAMS), rel=st.sampled_from([1e-12, 1e-9, 1e-6]))
def test_growth_is_continuous_in_every_parameter(gamma, f, beta, eta, Delta, xi, which, rel) -> None:
    """Where the branch is followed on the whole range (no masked point, no pole-dense part), a relative change
    rel of any parameter changes the growth by at most rel x (its slope bound) + rounding: no jumps, including
    where the maximum switches from one peak to another."""
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    assume(not (which == "eta" and math.isinf(eta)))
    out0 = model.growth_chunk(np.log(KH), np.array([[p[k]] for k in PARAMS]))[:, 0]
    assume(out0[4] == 0 and out0[10] == 0 and np.isfinite(out0[0]))
    q = dict(p, **{which: p[which] * (1 + rel)})
    q["beta"], q["Delta"] = min(q["beta"], 1 / math.sqrt(2)), min(q["Delta"], 1.0)  # inside their domains
    out1 = model.growth_chunk(np.log(KH), np.array([[q[k]] for k in PARAMS]))[:, 0]
    assume(out1[4] == 0 and out1[10] == 0)
    slope = {"gamma": abs(out0[8]), "eta": abs(out0[9])}.get(which, 1.0)
    assert abs(out1[0] - out0[0]) <= 2 * (slope + 1e-3) * rel + 1e-14, (out0[0], out1[0])


def test_verdicts_and_their_reasons() -> None:
    """stable / unstable / undetermined with the reason: a symmetric pair is stable; the paper's point unstable; at
    eta = inf and small gamma the branch leaves the physical sheet through the cut (Im z -> 0-) below kH ~ 5: stable
    where it exists; a branch masked on the whole range certifies nothing; finite eta, small gamma: pole-dense."""
    cases = [(dict(gamma=3.0, eta=1.0), 0, K.V_STABLE), (dict(gamma=3.0), 1, K.V_UNSTABLE),
             (dict(gamma=0.2), 0, K.V_STABLE), (dict(gamma=0.12, eta=10.0), 2, K.V_POLE_DENSE),
             (dict(gamma=0.01, f=2.0, beta=1 / math.sqrt(2), eta=10**0.5), 2, K.V_POLE_DENSE)]
    for kw, verdict, reason in cases:
        r = model.growth_analysis(KH, **{**PAPER, **kw})
        assert (int(r.verdict), int(r.verdict_reason)) == (verdict, reason), kw
        assert model.VERDICTS[int(r.verdict)] in model.VERDICT_STATUS[int(r.verdict_reason)]
    cut = model.growth_analysis(KH, gamma=0.2, **PAPER)
    assert cut.n_masked > 0 and -1e-8 < float(cut.growth) < 0  # the branch ends at the cut (Im z -> 0-)
    assert np.array_equal(model.verdict_class(np.arange(-1, 6)), [2, 0, 1, 2, 2, 2, 2])


# --------------------------------------------------------------------------------------------
# 2. every crossing a neutral mode, against the oracle
# --------------------------------------------------------------------------------------------


def _random_sets(n: int, seed: int) -> list[dict]:
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        delta = 1.0 if i % 4 == 0 else float(rng.uniform(0.2, 1.0))
        out.append(dict(f=float(rng.uniform(0.3, 1.5)), beta=float(rng.uniform(0.05, 0.65)),
                        eta=math.inf if i % 2 == 0 else float(10 ** rng.uniform(0.3, 3.0)), Delta=delta,
                        xi=0.0 if delta == 1.0 else float(10 ** rng.uniform(-1.5, 1.5))))
    return out


def _check_against_oracle(which: str, c: model.Crossings, i: int, k: int, p: dict) -> float:
    """The oracle's neutral mode from the model's: relative error of the threshold; kH, z, maximum and direction."""
    return _check_one(which, float(c.value[i, k]), float(c.kH[i, k]), float(c.z[i, k]), int(c.reason[i, k]),
                      int(c.direction[i, k]), p)


def _check_one(which: str, value: float, q: float, x: float, reason: int, direction: int, p: dict) -> float:
    args = {**dict(gamma=1.0, eta=math.inf, Delta=1.0, xi=0.0), **p, which: value}
    edge = reason == X_EDGE
    ox, oq, ov = oracle.neutral_mode(which, x, q, value, args["gamma"], args["f"], args["beta"], args["eta"],
                                     args["Delta"], args["xi"], edge=edge)
    err = abs(value / float(ov) - 1)
    assert err <= 1e-10, (p, value, float(ov))
    assert abs(x - float(ox)) <= 1e-10 * max(abs(x), 1e-3) and abs(q / float(oq) - 1) <= 1e-7
    d2, dt = oracle.neutral_curvature(which, ox, oq, ov, args["gamma"], args["f"], args["beta"], args["eta"],
                                      args["Delta"], args["xi"])
    assert (edge or float(d2) < 0) and np.sign(float(dt)) == direction  # a maximum; its direction
    return err


@pytest.mark.parametrize(("which", "seed"), [("gamma", 11), ("eta", 12)])
@pytest.mark.slow
def test_every_returned_threshold_is_the_oracles_neutral_mode(which: str, seed: int) -> None:
    """24 random parameter sets (half finite eta, most Delta < 1 with xi > 0), every crossing in the default range:
    each certified one matches the oracle's neutral mode to 1e-10 (threshold, kH, z), is a maximum of Im z in kH,
    and has the direction of the oracle's slope; every other one is NaN with a reason code."""
    sets = _random_sets(24, seed)
    if which == "eta":
        rng = np.random.default_rng(seed + 1)
        for p in sets:
            p.pop("eta")
            p["gamma"] = float(10 ** rng.uniform(0.3, 1.5))
    names = [k for k in sets[0] if k != which]
    cols = {k: np.array([p[k] for p in sets]) for k in names}
    c = model.critical_gammas(**cols) if which == "gamma" else model.critical_etas(**cols)
    errors, finite_eta, state = [], 0, 0
    for i, p in enumerate(sets):
        for k in range(c.value.shape[1]):
            reason = int(c.reason[i, k])
            if reason in (X_CERTIFIED, X_EDGE):
                errors.append(_check_against_oracle(which, c, i, k, p))
                finite_eta += which == "eta" or math.isfinite(p["eta"])
                state += p["Delta"] < 1 and p["xi"] > 0
            elif reason >= 0:
                assert math.isnan(c.value[i, k]) and reason in CROSSING_STATUS and np.isfinite(c.location[i, k])
    assert len(errors) >= 20 and finite_eta >= 8 and state >= 8, (len(errors), finite_eta, state)
    assert max(errors) <= 1e-10


def test_check_values_are_the_oracles() -> None:
    """docs/physics.md §7: gamma_c = 2.4149 (eta = inf), eta_c = 3.2982 (gamma = 3) as neutral modes of the oracle."""
    g = model.critical_gammas(**PAPER)
    e = model.critical_etas(gamma=3.0, **PAPER)
    for which, c, p in (("gamma", g, dict(PAPER)), ("eta", e, dict(PAPER, gamma=3.0))):
        assert c.count == 1 and c.complete and c.reason[0] == X_CERTIFIED
        err = _check_one(which, float(c.value[0]), float(c.kH[0]), float(c.z[0]), X_CERTIFIED, int(c.direction[0]), p)
        assert err <= 1e-12
    assert abs(float(g.value[0]) - 2.4149) < 5e-5 and abs(float(e.value[0]) - 3.2982) < 5e-5


@pytest.mark.slow
def test_threshold_lies_on_the_oracles_rayleigh_branch() -> None:
    """The second certificate, independently: the oracle's own continuation of the Rayleigh branch from kH = 1e4
    reaches the neutral mode (eta = 10, Delta = 0.6, xi = 2): at gamma_c (1 -/+ 1e-6) its root at the neutral mode's
    kH has Im z of opposite signs and Re z equal to the mode's."""
    p = dict(f=0.9, beta=0.3, eta=10.0, Delta=0.6, xi=2.0)
    c = model.critical_gammas(**p)
    assert c.count == 1 and c.reason[0] == X_CERTIFIED
    g, q, x = float(c.value[0]), float(c.kH[0]), float(c.z[0])
    below, above = (oracle.rayleigh_branch([q], g * (1 + d), 0.9, 0.3, 10.0, 0.6, 2.0)[0] for d in (-1e-6, 1e-6))
    assert float(below.imag) < 0 < float(above.imag) and c.direction[0] == 1
    assert abs(float(below.real) - x) < 1e-6 and abs(float(above.real) - x) < 1e-6


# --------------------------------------------------------------------------------------------
# 3. the pole-dense regime (finite eta, small gamma)
# --------------------------------------------------------------------------------------------


def test_pole_dense_small_gamma_is_undetermined_and_never_a_threshold() -> None:
    """eta = 10, f = 0.9, beta = 0.3, Delta = 1, gamma = 0.12: the branch runs above the shear speed through the
    lower block's undamped poles (at kH = 9.19: z = 1.410 - 1.6e-7 i, eta kH Re alpha_s ~ 1e-5). The independent check
    is the all-branch count there: 0, >= 10 and >= 25 roots in |Re z| <= 6 above Im z = 1e-3, 1e-5 and 1e-7, i.e. many
    roots just above the poles whose number depends on the resolution: the verdict is undetermined (pole-dense).
    Over gamma in [0.1, 30] the only crossing reported is the certified one at 2.4232 (the oracle's neutral mode);
    the sign change of the old grid maximum near gamma = 0.45 (a peak at Re z = 4.8 among the poles) is none."""
    p = dict(gamma=0.12, f=0.9, beta=0.3, eta=10.0)
    r = model.growth_analysis(KH, **p)
    assert int(r.verdict) == 2 and int(r.verdict_reason) == K.V_POLE_DENSE
    z = model.spectrum(np.array([9.1896]), **p)[0]
    assert abs(z.real) > 1 and abs(z.imag) < 1e-6 and 10 * 9.1896 * cmath.sqrt(1 - z * z).real < 1e-3
    counts = [model.unstable_count(9.1896, **p, re_max=6.0, im_min=m, im_max=1.0) for m in (1e-3, 1e-5, 1e-7)]
    assert counts[0] == 0 and counts[1] >= 10 and counts[2] >= 25, counts
    c = model.critical_gammas(f=0.9, beta=0.3, eta=10.0, gamma_range=(0.1, 30.0))
    assert c.count == 1 and c.reason[0] == X_CERTIFIED and c.direction[0] == 1 and c.complete
    assert float(c.value[0]) == pytest.approx(2.4231820150825816, rel=1e-12)  # oracle.neutral_mode, 30 digits
    small = model.growth_analysis(KH, gamma=np.array([0.1, 0.2, 0.3, 0.4]), f=0.9, beta=0.3, eta=10.0)
    assert np.all(small.verdict_reason == K.V_POLE_DENSE)
    assert model.critical_gamma(f=0.9, beta=0.3, eta=10.0, gamma_range=(0.1, 30.0)) == c.value[0]


def test_a_neutral_mode_among_the_poles_is_refused() -> None:
    """A real z > 1 at finite eta is pole-dense by definition (eta kH Re alpha_s = 0): such a neutral mode is
    reported with its own reason (never certified), as _try_neutral does."""
    assert K.is_pole_dense(complex(1.3, 0.0), 0.0, 10.0) and not K.is_pole_dense(complex(1.3, 0.0), 0.0, math.inf)
    assert not K.is_pole_dense(complex(0.9, 1e-9), 0.0, 10.0)
    # large attenuation (the lower block a half-space to its waves): not pole-dense
    assert not K.is_pole_dense(complex(1.0048, -0.0066), math.log(1000.0), 10.0)
    assert "pole-dense" in CROSSING_STATUS[4]
