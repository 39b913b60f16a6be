"""Chunked stability thresholds: crossings_chunk / threshold_chunk / critical_gamma_chunk.

Against an independent method written here (a 17-value log scan of the continuous max growth from
growth_analysis, then scipy.optimize.brentq in ln x on it), at the check values of docs/physics.md §7, for
independence of the chunk composition (bitwise), and for the reason codes: on the physics where a case is
robust, and on synthetic max-growth functions (the growth kernel and the neutral-mode solver replaced) for the
logic of each code: scan, Hermite insertion of close crossings, jumps, undefined stretches, certificates.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize

from asymslide import model
from asymslide.model import crossings, stability, thresholds
from asymslide.model._kernels import growth
from asymslide.model.crossings import CROSSING_STATUS, THRESHOLD_STATUS
from asymslide.model.thresholds import (
    critical_eta_chunk,
    critical_gamma_chunk,
    crossings_chunk,
    threshold_chunk,
)

S = np.log(thresholds.DEFAULT_KH)
PAPER = dict(f=0.9, beta=0.3)
ROWS = ("gamma", "f", "beta", "eta", "Delta", "xi")
SCAN = np.exp(np.linspace(math.log(1e-2), math.log(1e3), 17))  # the scan values of the default gamma range


def params6(**cols) -> np.ndarray:
    """(6, n) params in growth_chunk's layout from keyword columns (missing rows NaN, Delta 1, xi 0)."""
    n = max(np.size(v) for v in cols.values())
    default = dict(gamma=math.nan, eta=math.nan, Delta=1.0, xi=0.0)
    return np.stack([np.broadcast_to(np.asarray(cols.get(k, default.get(k)), dtype=float), (n,)) for k in ROWS])


def brent_threshold(name: str, base: dict, bounds: tuple[float, float]) -> float:
    """The first zero of the continuous max growth by a 17-value scan and scipy's brentq in ln x (NaN if none)."""

    def growth(t: float) -> float:
        return float(stability.growth_analysis(thresholds.DEFAULT_KH, **base, **{name: math.exp(t)}).growth)

    ts = np.linspace(math.log(bounds[0]), math.log(bounds[1]), 17)
    vals = [growth(t) for t in ts]
    for a, b, ta, tb in zip(vals[:-1], vals[1:], ts[:-1], ts[1:], strict=True):
        if math.isfinite(a) and math.isfinite(b) and (a < 0) != (b < 0):
            return math.exp(optimize.brentq(growth, ta, tb, xtol=1e-14, rtol=4 * np.finfo(float).eps))
    return math.nan


def random_points(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """Random parameter sets: half eta = inf, half finite eta; most Delta < 1 with xi > 0."""
    delta = np.where(rng.random(n) < 0.3, 1.0, rng.uniform(0.2, 1.0, n))
    return dict(
        f=rng.uniform(0.2, 1.5, n),
        beta=rng.uniform(0.05, 0.7, n),
        eta=np.where(np.arange(n) % 2 == 0, math.inf, 10 ** rng.uniform(0.3, 4.0, n)),
        Delta=delta,
        xi=np.where(delta < 1, 10 ** rng.uniform(-2.0, 2.0, n), 0.0),
    )


# --------------------------------------------------------------------------------------------
# physics
# --------------------------------------------------------------------------------------------


def test_check_values_critical_gamma_and_eta() -> None:
    """docs/physics.md §7: gamma_c = 2.4149 (eta = inf) and eta_c = 3.2982 (gamma = 3), f = 0.9, beta = 0.3."""
    gc, reason = critical_gamma_chunk(S, np.array([[0.9], [0.3], [math.inf], [1.0], [0.0]]))  # (5, n) layout
    assert reason.tolist() == [0] and abs(gc[0] - 2.4149) < 5e-5
    assert abs(float(model.max_growth(thresholds.DEFAULT_KH, gamma=gc[0], **PAPER)[0])) < 1e-14
    ec, reason = critical_eta_chunk(S, params6(gamma=3.0, f=0.9, beta=0.3))  # (6, n) layout, eta row ignored
    assert reason.tolist() == [0] and abs(ec[0] - 3.2982) < 5e-5
    assert abs(float(model.max_growth(thresholds.DEFAULT_KH, gamma=3.0, eta=ec[0], **PAPER)[0])) < 1e-14


@pytest.mark.parametrize(("name", "seed", "n"), [("gamma", 1, 12), ("eta", 2, 6)])
def test_neutral_mode_is_the_zero_of_the_continuous_max_growth(name: str, seed: int, n: int) -> None:
    """Random points (finite eta, Delta < 1 with xi > 0): every certified threshold is where brentq, run on the max
    growth itself, finds its zero (to 1e-11); points without a certified threshold have none of brentq's either,
    or one the certificate refuses with a reason (a jump: brentq locates it like a root)."""
    pts = random_points(np.random.default_rng(seed), n)
    if name == "eta":
        pts.pop("eta")
        pts["gamma"] = 10 ** np.random.default_rng(seed + 10).uniform(0.0, 1.5, n)
    bounds = thresholds.THRESHOLD_RANGES[name]
    r = threshold_chunk(name, S, params6(**pts))
    found = 0
    for i in range(n):
        want = brent_threshold(name, {k: float(v[i]) for k, v in pts.items()}, bounds)
        if r.reason[i] == 0:
            found += 1
            assert want == pytest.approx(r.value[i], rel=1e-11), (i, r.value[i], want)
            assert r.lo[i] < r.value[i] < r.hi[i] and r.location[i] == r.value[i] and r.direction[i] in (1, -1)
        else:
            assert math.isnan(r.value[i]) and r.reason[i] in THRESHOLD_STATUS
            if math.isfinite(want):  # brentq found a sign change the solver refused: it must say where and why
                assert r.reason[i] in (3, 4, 5, 6) and r.n_crossings[i] >= 1
    assert found >= n // 2  # thresholds found, so the comparison above is not vacuous


@pytest.mark.parametrize(("name", "kwargs", "bounds", "reason"), [
    ("gamma", dict(f=0.9, beta=0.3, eta=1.0), (1e-2, 1e3), 1),  # symmetric: stable throughout
    ("gamma", dict(f=0.9, beta=0.3, eta=math.inf), (10.0, 100.0), 2),  # above gamma_c = 2.4149
    ("eta", dict(gamma=0.5, f=0.9, beta=0.3), (1.0, 1e8), 1),
    ("eta", dict(gamma=3.0, f=0.9, beta=0.3), (10.0, 1e8), 2),  # above eta_c = 3.2982
])
def test_physical_cases_without_a_threshold(name: str, kwargs: dict, bounds: tuple, reason: int) -> None:
    """NaN and the reason code; the public function raises naming the reason."""
    r = threshold_chunk(name, S, params6(**kwargs), bounds)
    assert r.reason.tolist() == [reason] and math.isnan(r.value[0]) and r.n_crossings.tolist() == [0]
    fn = model.critical_gamma if name == "gamma" else model.critical_eta
    why = {1: "stable throughout", 2: "unstable throughout"}[reason]
    with pytest.raises(ValueError, match=f"no stability threshold for {name} .*{why}"):
        fn(**kwargs, **{f"{name}_range": bounds})


def test_result_does_not_depend_on_the_chunk() -> None:
    """A point's crossings, reasons and evaluation count are the same alone and anywhere in a chunk, bitwise."""
    pts = random_points(np.random.default_rng(3), 8)
    p = params6(**pts)
    p = np.concatenate([p, params6(f=[0.9, 0.9, math.nan], beta=0.3, eta=[math.inf, 1.0, math.inf])], axis=1)
    whole = crossings_chunk("gamma", S, p)
    assert set(whole.status.tolist()) >= {0, 1, 3}  # the NaN parameter set: undefined
    order = np.random.default_rng(4).permutation(p.shape[1])
    shuffled = crossings_chunk("gamma", S, p[:, order])
    for i in range(p.shape[1]):
        alone = crossings_chunk("gamma", S, p[:, i : i + 1])
        j = int(np.flatnonzero(order == i)[0])
        for r, k in ((alone, 0), (shuffled, j)):
            assert r.status[k] == whole.status[i] and r.evaluations[k] == whole.evaluations[i]
            for field in ("value", "location", "kH", "z", "reason", "direction"):
                assert np.array_equal(getattr(r, field)[k], getattr(whole, field)[i], equal_nan=True), field


def test_public_functions_use_the_chunk_solver() -> None:
    """critical_gamma / critical_eta: scalars for scalars, broadcast arrays equal to the chunk values;
    critical_gammas: the crossing axis last, its first certified crossing is critical_gamma."""
    f = np.array([[0.6], [0.9], [1.5]])
    beta = np.array([0.2, 0.3])
    g = model.critical_gamma(f=f, beta=beta, workers=2)
    assert g.shape == (3, 2)
    gc, reason = critical_gamma_chunk(S, params6(f=np.broadcast_to(f, (3, 2)).ravel(),
                                                 beta=np.broadcast_to(beta, (3, 2)).ravel(), eta=math.inf))
    assert np.all(reason == 0) and np.array_equal(g.ravel(), gc)
    one = model.critical_gamma(f=0.9, beta=0.3)
    assert isinstance(one, float) and one == g[1, 1]
    allc = model.critical_gammas(f=f, beta=beta, max_crossings=3)
    assert allc.value.shape == (3, 2, 3) and allc.count.shape == (3, 2) and allc.parameter == "gamma"
    assert np.array_equal(allc.first, g) and np.all(allc.complete) and np.all(allc.direction[..., 0] == 1)
    e = model.critical_eta(gamma=np.array([3.0, 4.0]), f=0.9, beta=0.3)
    ec, _ = critical_eta_chunk(S, params6(gamma=[3.0, 4.0], f=0.9, beta=0.3))
    assert np.array_equal(e, ec) and e[1] < e[0]  # more elastodynamic coupling, unstable at smaller eta
    assert np.array_equal(model.critical_etas(gamma=np.array([3.0, 4.0]), f=0.9, beta=0.3).first, e)
    with pytest.raises(ValueError, match=r"stable throughout.*element \(1,\): f = 0.9, beta = 0.3, eta = 1"):
        model.critical_gamma(f=0.9, beta=0.3, eta=np.array([math.inf, 1.0]))


def test_layouts_and_ignored_row() -> None:
    """(5, n) and (6, n) params give the same result, whatever the ignored row holds."""
    p6 = params6(gamma=[1.0, -5.0], f=[0.9, 1.2], beta=[0.3, 0.5], eta=math.inf)
    a = critical_gamma_chunk(S, p6)
    b = critical_gamma_chunk(S, np.delete(p6, 0, axis=0))
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and np.all(a[1] == 0)


def test_rtol_is_validated_and_changes_nothing() -> None:
    """rtol: validated like growth_analysis's; the threshold is solved at full accuracy anyway (the certificate at
    value (1 -/+ 1e-9) needs it, and the neutral mode converges quadratically), so the values are the same."""
    p = params6(f=[0.9, 1.3], beta=[0.3, 0.4], eta=math.inf, Delta=[1.0, 0.5], xi=[0.0, 1.0])
    full = threshold_chunk("gamma", S, p)
    loose = threshold_chunk("gamma", S, p, rtol=1e-6)
    assert np.all(full.reason == 0) and np.array_equal(full.value, loose.value)
    with pytest.raises(ValueError, match="rtol must be None"):
        threshold_chunk("gamma", S, p, rtol=1e-2)
    with pytest.raises(ValueError, match="rtol must be None"):
        model.critical_gamma(f=0.9, beta=0.3, rtol="1e-6")


def test_invalid_arguments() -> None:
    p = params6(f=0.9, beta=0.3, eta=math.inf)
    with pytest.raises(ValueError, match="name must be one of"):
        threshold_chunk("f", S, p)
    with pytest.raises(ValueError, match=r"params must have shape \(6, n\) or \(5, n\)"):
        threshold_chunk("gamma", S, p[:4])
    with pytest.raises(ValueError, match="gamma_range must be a pair"):
        critical_gamma_chunk(S, p, gamma_range=(0.0, 10.0))
    with pytest.raises(ValueError, match="eta_range must be a pair"):
        critical_eta_chunk(S, params6(gamma=3.0, f=0.9, beta=0.3), eta_range=(10.0, 1.0))
    with pytest.raises(ValueError, match="max_crossings must be an integer >= 1"):
        crossings_chunk("gamma", S, p, max_crossings=0)


def test_empty_chunk() -> None:
    r = threshold_chunk("gamma", S, np.empty((5, 0)))
    assert r.value.shape == (0,) and r.reason.shape == (0,) and r.n_crossings.shape == (0,)
    c = crossings_chunk("gamma", S, np.empty((5, 0)), max_crossings=2)
    assert c.value.shape == (0, 2) and c.count.shape == (0,)


# --------------------------------------------------------------------------------------------
# the logic, on synthetic max-growth functions of x (the growth kernel and the neutral-mode solver replaced)
# --------------------------------------------------------------------------------------------


@pytest.fixture
def synthetic(monkeypatch: pytest.MonkeyPatch):
    """Install G(x) -> growth and masked(x) -> masked grid points as the max growth of every parameter set, gamma
    being x; the neutral-mode solver becomes Newton on G (in t = ln x) from its start, so it converges exactly
    where G has a smooth zero (not at a jump)."""

    def install(g, masked=lambda x: 0) -> None:
        def slope(t: float) -> float:
            h = 1e-7
            return (g(math.exp(t + h)) - g(math.exp(t - h))) / (2 * h)

        def fake_growth_point(s_grid, gamma, f, beta, eta, delta, xi, rtol):
            v = g(gamma)
            verdict = growth.V_UNSTABLE if v > 0 else growth.V_STABLE
            return (v, 0.0, math.nan, math.nan, float(masked(gamma)), 0.5, 1e-16, float(verdict),
                    slope(math.log(gamma)), 0.0, 0.0, 0.0)

        def fake_neutral(x0, s0, t0, which, edge, *p):
            t = t0
            for it in range(60):
                d = slope(t)
                if not (math.isfinite(d) and d != 0.0):
                    break
                step = -g(math.exp(t)) / d
                t += step
                if abs(step) < 1e-15 * max(1.0, abs(t)):
                    return x0, s0, t, True, it, 0.0, slope(t), 0.0
            return x0, s0, t, False, 60, math.nan, math.nan, math.nan

        def fake_growth_many(s_grid, gamma, f, beta, eta, delta, xi, rtol, out):
            for i in range(gamma.shape[0]):
                out[:, i] = fake_growth_point(s_grid, gamma[i], f[i], beta[i], eta[i], delta[i], xi[i], rtol)

        monkeypatch.setattr(thresholds.K, "growth_point", fake_growth_point)
        monkeypatch.setattr(thresholds.K, "growth_many", fake_growth_many)
        monkeypatch.setattr(thresholds.K, "neutral_mode", fake_neutral)

    return install


def _one(fun, synthetic, masked=lambda x: 0, **kw):
    synthetic(fun, masked)
    return crossings_chunk("gamma", S, params6(f=0.9, beta=0.3, eta=math.inf), **kw)


@pytest.mark.parametrize(("fun", "status"), [
    (lambda x: -0.01 - 0 * x, 1),
    (lambda x: np.where(x < 0.05, np.nan, -0.01), 1),  # stable wherever defined
    (lambda x: 0.0 * x, 2),  # growth 0 counts as the unstable side
    (lambda x: np.full_like(x, np.nan), 3),
])
def test_reasons_without_a_crossing(synthetic, fun, status: int) -> None:
    r = _one(lambda x: float(fun(np.float64(x))), synthetic)
    assert r.status.tolist() == [status] and r.count.tolist() == [0] and status in THRESHOLD_STATUS
    assert r.evaluations.tolist() == [17] and np.all(r.reason == -1) and np.isnan(r.value).all()


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_smooth_crossing_either_direction(synthetic, sign: float) -> None:
    """A zero at 2.5 (stable below for sign = 1, unstable below for sign = -1): found to 1e-14 relative with its
    direction; 17 scan values and the two values of the certificate."""
    r = _one(lambda x: sign * 0.03 * math.log(x / 2.5), synthetic)
    assert r.status.tolist() == [0] and r.reason[0, 0] == 0 and abs(r.value[0, 0] / 2.5 - 1) < 1e-14
    assert r.direction[0, 0] == sign and r.complete[0] and r.evaluations[0] == 17 + 2
    assert r.lo[0, 0] == pytest.approx(2.5 * (1 - 1e-9), rel=1e-12) and r.hi[0, 0] == pytest.approx(2.5 * (1 + 1e-9))


def test_every_crossing_is_returned_in_order(synthetic) -> None:
    """Two crossings (at 0.2 and at 40): both, destabilising then stabilising; critical_gamma gives the first."""
    r = _one(lambda x: -math.log(x / 0.2) * math.log(x / 40.0), synthetic)
    assert r.count.tolist() == [2] and r.complete[0] and r.reason[0, :2].tolist() == [0, 0]
    assert np.allclose(r.value[0, :2], [0.2, 40.0], rtol=1e-13) and r.direction[0, :2].tolist() == [1, -1]
    assert r.reason[0, 2:].tolist() == [-1, -1] and np.isnan(r.value[0, 2:]).all() and r.first[0] == r.value[0, 0]


def test_close_pair_between_scan_values_is_found_by_the_hermite_test(synthetic) -> None:
    """An unstable window (0.98, 1.18) inside one scan interval [SCAN[6], SCAN[7]] = [0.75, 1.54]: both scan values
    are stable, but the Hermite model of G (values and slopes) dips above zero, so a value is inserted there and
    both crossings are found and certified."""
    c = math.sqrt(SCAN[6] * SCAN[7])
    r = _one(lambda x: 0.008 - math.log(x / c) ** 2, synthetic)
    lo, hi = c * math.exp(-math.sqrt(0.008)), c * math.exp(math.sqrt(0.008))
    assert SCAN[6] < lo < hi < SCAN[7]
    assert r.count.tolist() == [2] and r.complete[0] and np.allclose(r.value[0, :2], [lo, hi], rtol=1e-13)
    assert r.direction[0, :2].tolist() == [1, -1] and r.evaluations[0] > 17 + 4


def test_more_crossings_than_stored(synthetic) -> None:
    """sin(3 ln x) has a zero at every ln x = k pi/3 in the range (11 of them): the count says so, the first
    max_crossings are listed, in order."""
    zeros = [math.exp(k * math.pi / 3) for k in range(-10, 10) if 1e-2 < math.exp(k * math.pi / 3) < 1e3]
    r = _one(lambda x: math.sin(3 * math.log(x)), synthetic, max_crossings=4)
    assert r.count.tolist() == [len(zeros)] == [11] and r.value.shape == (1, 4) and r.complete[0]
    assert np.all(r.reason[0] == 0) and np.allclose(r.value[0], zeros[:4], rtol=1e-13)


def test_sign_change_across_undefined_values(synthetic) -> None:
    """Growth of both signs only across undefined scan values: a crossing that cannot be located (reason 5)."""
    r = _one(lambda x: -0.01 if x < 1.5 else (math.nan if x < 3 else 0.01), synthetic)
    assert r.count.tolist() == [1] and r.reason[0, 0] == crossings.X_UNDEFINED and r.status[0] == 3
    assert not r.complete[0] and math.isnan(r.value[0, 0]) and r.lo[0, 0] < 1.5 and r.hi[0, 0] > 3


def test_undefined_inside_the_bracket(synthetic) -> None:
    """NaN between the bracketing scan values, right where the zero is: undefined, no silent jump elsewhere."""
    r = _one(lambda x: math.nan if 2.4 < x < 2.6 else math.log(x / 2.5), synthetic)
    assert r.reason[0, 0] == crossings.X_UNDEFINED and r.status[0] == 3 and math.isnan(r.value[0, 0])


@pytest.mark.parametrize(("masked", "reason"), [(lambda x: 84 if x < 0.8 else 0, crossings.X_JUMP_MASKED),
                                                (lambda x: 0, crossings.X_JUMP)])
def test_jump_is_located_and_refused(synthetic, masked, reason: int) -> None:
    """A max growth jumping from -0.03 to +0.05 at x = 0.8: no neutral mode, the bracket is narrowed (by bisection
    once false position stalls) until G changes across it JUMP_FACTOR times more than its slopes (0 here, floored
    at MIN_JUMP_SLOPE) allow, refused as a jump (where the masked part of the kH range changes, or with the branch
    followed on both sides), its location kept."""
    r = _one(lambda x: -0.03 if x < 0.8 else 0.05, synthetic, masked)
    assert r.reason[0, 0] == reason and r.status[0] == 5 and math.isnan(r.value[0, 0]) and not r.complete[0]
    width = 0.08 / (thresholds.JUMP_FACTOR * thresholds.MIN_JUMP_SLOPE)
    assert r.lo[0, 0] < 0.8 <= r.hi[0, 0] and math.log(r.hi[0, 0] / r.lo[0, 0]) <= width
    assert abs(r.location[0, 0] / 0.8 - 1) < width
    assert r.evaluations[0] <= 17 + 20 and "jump" in CROSSING_STATUS[reason]


def test_certificate_refuses_a_smooth_zero_next_to_a_jump(synthetic) -> None:
    """A zero of a smooth function at 2.5 hidden by a jump at 2.5 + 1e-10: the neutral mode converges, but G at
    2.5 (1 + 1e-9) is not of the size its slope allows (the jump): not certified there; refused as a jump."""
    r = _one(lambda x: 0.03 * math.log(x / 2.5) + (0.02 if x > 2.5 * (1 + 1e-10) else 0.0), synthetic)
    assert r.reason[0, 0] in (crossings.X_JUMP, crossings.X_NOT_CERTIFIED) and math.isnan(r.value[0, 0])


def test_tangential_zero_is_not_certified(synthetic) -> None:
    """G touching zero with zero slope (a double zero): the sign test at +-1e-9 resolves nothing: no crossing is
    reported as certified (the scan sees no sign change at all, or the certificate refuses it)."""
    r = _one(lambda x: -0.01 * math.log(x / 2.5) ** 2, synthetic)
    assert not np.any(r.reason == 0)
