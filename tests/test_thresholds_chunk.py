"""Chunked stability thresholds (issue 13): threshold_chunk / critical_gamma_chunk / critical_eta_chunk.

Against a slow per-point reference written here (a 17-value log scan with growth_analysis, then
scipy.optimize.brentq in ln x), at the check values of docs/physics.md §7, for independence of the chunk
composition (bitwise), and for the reason codes: on the physics where a case is robust, and on synthetic
max-growth functions (growth_chunk replaced) for the logic of each code, the forced bisection and jumps.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize

import model
from model import stability
from model.stability import THRESHOLD_STATUS, critical_eta_chunk, critical_gamma_chunk, threshold_chunk

S = np.log(stability.DEFAULT_KH)
PAPER = dict(f=0.9, beta=0.3)
ROWS = ("gamma", "f", "beta", "eta", "Delta", "xi")
SCAN = np.exp(np.linspace(math.log(1e-2), math.log(1e3), 17))  # the scan values of the default gamma range


def params6(**cols) -> np.ndarray:
    """(6, n) params in growth_chunk's layout from keyword columns (missing rows NaN, Delta 1, xi 0)."""
    n = max(np.size(v) for v in cols.values())
    default = dict(gamma=math.nan, eta=math.nan, Delta=1.0, xi=0.0)
    return np.stack([np.broadcast_to(np.asarray(cols.get(k, default.get(k)), dtype=float), (n,)) for k in ROWS])


class _Undefined(Exception):
    pass


def reference_threshold(name: str, base: dict, bounds: tuple[float, float]) -> tuple[float, int]:
    """Per-point reference: (threshold, reason) from growth_analysis, a 17-value scan and scipy's brentq."""

    def growth(x: float) -> float:
        return float(stability.growth_analysis(stability.DEFAULT_KH, **base, **{name: x}).growth)

    def in_ln(t: float) -> float:
        v = growth(math.exp(t))
        if not math.isfinite(v):
            raise _Undefined
        return v

    ts = np.linspace(math.log(bounds[0]), math.log(bounds[1]), 17)
    vals = [growth(math.exp(t)) for t in ts]
    for a, b, ta, tb in zip(vals[:-1], vals[1:], ts[:-1], ts[1:], strict=True):
        if math.isfinite(a) and math.isfinite(b) and (a < 0) != (b < 0):
            try:
                return math.exp(optimize.brentq(in_ln, ta, tb, xtol=1e-14, rtol=4 * np.finfo(float).eps)), 0
            except _Undefined:
                return math.nan, 3
    finite = np.array([v for v in vals if math.isfinite(v)])
    if finite.size and np.all(finite < 0):
        return math.nan, 1
    if finite.size and np.all(finite >= 0):
        return math.nan, 2
    return math.nan, 3


def random_points(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """Random parameter sets: half eta = inf, half finite eta; most Delta < 1 with xi > 0."""
    delta = np.where(rng.random(n) < 0.3, 1.0, rng.uniform(0.02, 1.0, n))
    return dict(
        f=rng.uniform(0.05, 2.0, n),
        beta=rng.uniform(0.02, 0.7, n),
        eta=np.where(np.arange(n) % 2 == 0, math.inf, 10 ** rng.uniform(0.0, 6.0, n)),
        Delta=delta,
        xi=np.where(delta < 1, 10 ** rng.uniform(-2.0, 3.0, n), 0.0),
    )


# --------------------------------------------------------------------------------------------
# physics
# --------------------------------------------------------------------------------------------


def test_check_values_critical_gamma_and_eta() -> None:
    """docs/physics.md §7: gamma_c = 2.4149 (eta = inf) and eta_c = 3.2982 (gamma = 3), f = 0.9, beta = 0.3."""
    gc, reason = critical_gamma_chunk(S, np.array([[0.9], [0.3], [math.inf], [1.0], [0.0]]))  # (5, n) layout
    assert reason.tolist() == [0] and abs(gc[0] - 2.4149) < 5e-5
    assert abs(float(model.max_growth(stability.DEFAULT_KH, gamma=gc[0], **PAPER)[0])) < 1e-14
    ec, reason = critical_eta_chunk(S, params6(gamma=3.0, f=0.9, beta=0.3))  # (6, n) layout, eta row ignored
    assert reason.tolist() == [0] and abs(ec[0] - 3.2982) < 5e-5
    assert abs(float(model.max_growth(stability.DEFAULT_KH, gamma=3.0, eta=ec[0], **PAPER)[0])) < 1e-14


@pytest.mark.parametrize(("name", "seed", "n"), [("gamma", 1, 14), ("eta", 2, 8)])
def test_against_per_point_reference(name: str, seed: int, n: int) -> None:
    """Random points (finite eta, Delta < 1 with xi > 0): same reason as the reference, threshold to 1e-12."""
    pts = random_points(np.random.default_rng(seed), n)
    if name == "eta":
        pts.pop("eta")
        pts["gamma"] = 10 ** np.random.default_rng(seed + 10).uniform(-1.0, 1.5, n)
    bounds = stability.THRESHOLD_RANGES[name]
    r = threshold_chunk(name, S, params6(**pts))
    found = 0
    for i in range(n):
        want, reason = reference_threshold(name, {k: float(v[i]) for k, v in pts.items()}, bounds)
        if r.reason[i] == 5:  # a jump: brentq (the reference) locates it like a root; here it is flagged
            assert reason == 0 and abs(r.location[i] - want) <= 1e-12 * want
            assert r.n_masked[0, i] != r.n_masked[1, i] and math.isnan(r.value[i])
            continue
        assert r.reason[i] == reason, (i, {k: v[i] for k, v in pts.items()}, r.reason[i], reason)
        if reason == 0:
            found += 1
            assert abs(r.value[i] - want) <= 1e-12 * want, (i, r.value[i], want)
            assert r.lo[i] <= r.value[i] <= r.hi[i] and r.location[i] == r.value[i]
        else:
            assert math.isnan(r.value[i])
    assert found >= n // 3  # thresholds found, so the comparison above is not vacuous


@pytest.mark.parametrize(("name", "kwargs", "bounds", "reason"), [
    ("gamma", dict(f=0.9, beta=0.3, eta=1.0), (1e-2, 1e3), 1),  # symmetric: stable throughout
    ("gamma", dict(f=0.9, beta=0.3, eta=math.inf), (10.0, 100.0), 2),  # above gamma_c = 2.4149
    ("gamma", dict(f=2.0, beta=1 / math.sqrt(2), eta=10**0.5), (1e-2, 1e3), 3),  # NaN inside the bracket
    ("eta", dict(gamma=0.5, f=0.9, beta=0.3), (1.0, 1e8), 1),
    ("eta", dict(gamma=3.0, f=0.9, beta=0.3), (10.0, 1e8), 2),  # above eta_c = 3.2982
])
def test_physical_cases_without_a_threshold(name: str, kwargs: dict, bounds: tuple, reason: int) -> None:
    """NaN and the reason code, as the reference says; the public function raises naming the reason."""
    assert reference_threshold(name, kwargs, bounds)[1] == reason
    r = threshold_chunk(name, S, params6(**kwargs), bounds)
    assert r.reason.tolist() == [reason] and math.isnan(r.value[0])
    fn = model.critical_gamma if name == "gamma" else model.critical_eta
    why = {1: "stable throughout", 2: "unstable throughout", 3: "undefined"}[reason]
    with pytest.raises(ValueError, match=f"no stability threshold for {name} .*{why}"):
        fn(**kwargs, **{f"{name}_range": bounds})
    if reason == 3:
        assert r.lo[0] < r.undefined_at[0] < r.hi[0]


def test_result_does_not_depend_on_the_chunk() -> None:
    """A point's threshold, reason and evaluation count are the same alone and anywhere in a chunk, bitwise."""
    pts = random_points(np.random.default_rng(3), 10)
    p = params6(**pts)
    p = np.concatenate([p, params6(f=[0.9, 0.9, math.nan], beta=0.3, eta=[math.inf, 1.0, math.inf])], axis=1)
    whole = threshold_chunk("gamma", S, p)
    assert set(whole.reason.tolist()) >= {0, 1, 3}  # the NaN parameter set: reason 3
    order = np.random.default_rng(4).permutation(p.shape[1])
    shuffled = threshold_chunk("gamma", S, p[:, order])
    for i in range(p.shape[1]):
        alone = threshold_chunk("gamma", S, p[:, i : i + 1])
        j = int(np.flatnonzero(order == i)[0])
        for r, k in ((alone, 0), (shuffled, j)):
            assert r.reason[k] == whole.reason[i] and r.evaluations[k] == whole.evaluations[i]
            assert np.array_equal(r.value[k], whole.value[i], equal_nan=True)


def test_public_functions_use_the_chunk_solver() -> None:
    """critical_gamma / critical_eta: scalars for scalars, broadcast arrays equal to the chunk values."""
    f = np.array([[0.6], [0.9], [1.5]])
    beta = np.array([0.2, 0.3])
    g = model.critical_gamma(f=f, beta=beta, workers=2)
    assert g.shape == (3, 2)
    gc, reason = critical_gamma_chunk(S, params6(f=np.broadcast_to(f, (3, 2)).ravel(),
                                                 beta=np.broadcast_to(beta, (3, 2)).ravel(), eta=math.inf))
    assert np.all(reason == 0) and np.array_equal(g.ravel(), gc)
    one = model.critical_gamma(f=0.9, beta=0.3)
    assert isinstance(one, float) and one == g[1, 1]
    e = model.critical_eta(gamma=np.array([3.0, 4.0]), f=0.9, beta=0.3)
    ec, _ = critical_eta_chunk(S, params6(gamma=[3.0, 4.0], f=0.9, beta=0.3))
    assert np.array_equal(e, ec) and e[1] < e[0]  # more elastodynamic coupling, unstable at smaller eta
    with pytest.raises(ValueError, match=r"stable throughout.*element \(1,\): f = 0.9, beta = 0.3, eta = 1"):
        model.critical_gamma(f=0.9, beta=0.3, eta=np.array([math.inf, 1.0]))


def test_layouts_and_ignored_row() -> None:
    """(5, n) and (6, n) params give the same result, whatever the ignored row holds."""
    p6 = params6(gamma=[1.0, -5.0], f=[0.9, 1.2], beta=[0.3, 0.5], eta=math.inf)
    a = critical_gamma_chunk(S, p6)
    b = critical_gamma_chunk(S, np.delete(p6, 0, axis=0))
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and np.all(a[1] == 0)


def test_rtol_loosens_the_bracket_only() -> None:
    """rtol: the threshold to that relative accuracy (here better: Brent's last steps are superlinear), with no
    more evaluations; validated like growth_analysis's rtol."""
    p = params6(f=[0.9, 1.3], beta=[0.3, 0.4], eta=math.inf, Delta=[1.0, 0.5], xi=[0.0, 1.0])
    full = threshold_chunk("gamma", S, p)
    loose = threshold_chunk("gamma", S, p, rtol=1e-6)
    assert np.all(full.reason == 0) and np.all(loose.reason == 0)
    assert np.all(np.abs(loose.value / full.value - 1) <= 1e-6)
    assert np.all(loose.evaluations <= full.evaluations)
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


def test_empty_chunk() -> None:
    r = threshold_chunk("gamma", S, np.empty((5, 0)))
    assert r.value.shape == (0,) and r.reason.shape == (0,) and r.n_masked.shape == (2, 0)


# --------------------------------------------------------------------------------------------
# the logic, on synthetic max-growth functions of x (growth_chunk replaced)
# --------------------------------------------------------------------------------------------


@pytest.fixture
def synthetic(monkeypatch: pytest.MonkeyPatch):
    """Install fun(x) -> (growth, n_masked) as the max growth of every parameter set, gamma being x."""

    def install(fun) -> None:
        def fake_growth_chunk(s_grid, params, rtol=None):
            out = np.zeros((5, params.shape[1]))
            out[0], out[4] = fun(params[0])
            return out

        monkeypatch.setattr(stability, "growth_chunk", fake_growth_chunk)

    return install


def _one(fun, synthetic, **kw):
    synthetic(fun)
    return threshold_chunk("gamma", S, params6(f=0.9, beta=0.3, eta=math.inf), **kw)


@pytest.mark.parametrize(("fun", "reason", "n_undefined"), [
    (lambda x: (-0.01 - 0 * x, 0 * x), 1, 0),
    (lambda x: (np.where(x < 0.05, np.nan, -0.01), 0 * x), 1, 3),  # stable wherever defined
    (lambda x: (0.0 * x, 0 * x), 2, 0),  # growth 0 counts as the unstable side, as in the reference
    (lambda x: (np.full_like(x, np.nan), 0 * x), 3, 17),
    (lambda x: (np.where(x < 1.5, -0.01, np.where(x < 3, np.nan, 0.01)), 0 * x), 3, 1),  # sign change across NaN
])
def test_reasons_without_a_bracket(synthetic, fun, reason: int, n_undefined: int) -> None:
    r = _one(fun, synthetic)
    assert r.reason.tolist() == [reason] and math.isnan(r.value[0]) and reason in THRESHOLD_STATUS
    assert r.evaluations.tolist() == [17] and r.n_undefined.tolist() == [n_undefined]
    assert math.isnan(r.lo[0]) and r.n_masked[:, 0].tolist() == [-1, -1]


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_smooth_crossing_either_direction(synthetic, sign: float) -> None:
    """A zero at 2.5 (stable below for sign = 1, unstable below for sign = -1): found to 1e-14 relative; the
    scan stops at the bracket [SCAN[7], SCAN[8]] (9 evaluations), then a few Brent steps."""
    r = _one(lambda x: (sign * 0.03 * np.log(x / 2.5), 0 * x), synthetic)
    assert r.reason.tolist() == [0] and abs(r.value[0] / 2.5 - 1) < 1e-14
    assert (r.lo[0], r.hi[0]) == (SCAN[7], SCAN[8])
    assert 9 < r.evaluations[0] <= 9 + 10


def test_zero_at_a_scan_value(synthetic) -> None:
    r = _one(lambda x: (np.log(x / SCAN[5]), 0 * x), synthetic)
    assert r.reason.tolist() == [0] and r.value[0] == SCAN[5] and r.evaluations[0] == 6


def test_first_crossing_is_taken(synthetic) -> None:
    """Two crossings (at 0.2 and at 40): the first one in the scan."""
    r = _one(lambda x: (-np.log(x / 0.2) * np.log(x / 40.0), 0 * x), synthetic)
    assert r.reason.tolist() == [0] and abs(r.value[0] / 0.2 - 1) < 1e-14


def test_undefined_inside_the_bracket(synthetic) -> None:
    """NaN strictly between the bracketing scan values: reason 3 at the first undefined value, no jump elsewhere."""
    r = _one(lambda x: (np.where((x > SCAN[7]) & (x < SCAN[8]), np.nan, np.log(x / 2.5)), 0 * x), synthetic)
    assert r.reason.tolist() == [3] and math.isnan(r.value[0]) and SCAN[7] < r.undefined_at[0] < SCAN[8]


def test_jump_is_located_and_flagged_by_the_masked_counts(synthetic) -> None:
    """A max growth jumping from -0.03 to +0.05 at x = 0.8 where the masked part of the grid changes (84 -> 0):
    located to 1e-14 relative, the masked counts at the ends of the final bracket differ, so it is reason 5
    (no threshold: NaN), its location kept."""
    r = _one(lambda x: (np.where(x < 0.8, -0.03, 0.05), np.where(x < 0.8, 84, 0)), synthetic)
    assert r.reason.tolist() == [5] and math.isnan(r.value[0]) and abs(r.location[0] / 0.8 - 1) < 2e-14
    assert r.n_masked[:, 0].tolist() == [84, 0]
    smooth = _one(lambda x: (0.03 * np.log(x / 2.5), 0 * x + 5), synthetic)
    assert smooth.n_masked[:, 0].tolist() == [5, 5]


@pytest.mark.parametrize("jump", [False, True])
def test_forced_bisection_is_bounded(synthetic, monkeypatch: pytest.MonkeyPatch, jump: bool) -> None:
    """With no Brent steps allowed (BRENT_ITER = 0) every step bisects: the threshold is still found, within
    ceil(log2(scan spacing / xtol)) + 2 steps after the scan; this bound is what excludes reason 4."""
    monkeypatch.setattr(stability, "BRENT_ITER", 0)
    fun = (lambda x: (np.where(x < 0.8, -0.03, 0.05), 0 * x)) if jump else (lambda x: (np.log(x / 0.8), 0 * x))
    r = _one(fun, synthetic)
    width = math.log(SCAN[1] / SCAN[0])
    assert r.reason.tolist() == [0] and abs(r.value[0] / 0.8 - 1) < 2e-14
    scan = 8  # the bracket [SCAN[6], SCAN[7]] holds 0.8
    assert scan < r.evaluations[0] <= scan + math.ceil(math.log2(width / stability.XTOL)) + 2
