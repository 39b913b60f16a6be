"""Property tests (hypothesis) of numerical stability over wide parameter ranges (docs/physics.md §7 stress cases)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from asymslide import model

INF = math.inf
SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])

gammas = st.floats(1e-2, 1e3).map(float)
fs = st.floats(0.0, 2.0)
betas = st.one_of(st.floats(1e-3, 1 / math.sqrt(2)), st.sampled_from([1e-3, 0.3, 1 / math.sqrt(2)]))
etas = st.one_of(st.sampled_from([INF, 1.0, 1.0 + 1e-9, 1e8, 1e-2]), st.floats(-2, 8).map(lambda x: 10.0**x))
deltas = st.one_of(st.just(1.0), st.floats(1e-3, 1.0))
xis = st.one_of(st.just(0.0), st.sampled_from([1e4]), st.floats(-3, 4).map(lambda x: 10.0**x))


@SETTINGS
@given(gamma=gammas, f=fs, beta=betas, eta=etas, Delta=deltas, xi=xis)
def test_spectrum_finite_or_masked_with_small_residual(gamma, f, beta, eta, Delta, xi):
    q = np.logspace(-4, 4, 97)
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    with warnings.catch_warnings(), np.errstate(over="raise", invalid="raise", divide="raise"):
        warnings.simplefilter("error")
        res = model.rayleigh_branch(q, **p)
    ok = ~res.mask
    assert np.all(np.isfinite(res.z[ok]))
    assert np.all(np.isnan(res.z[~ok]))
    assert np.all(res.status[~ok] > 0)
    if ok.any():
        z = res.z[ok]
        F = model.dispersion(z, q[ok], **p)
        scale = model.dispersion_scale(z, q[ok], **p)
        assert np.max(np.abs(F) / scale) < 1e-12
        assert np.all(res.residual[ok] < 1e-12)


def _branch_slope(z: np.ndarray, q: np.ndarray, p: dict) -> np.ndarray:
    """dz/d(ln kH) = -kH F_kH / F_z, F_kH by a central difference (test-side only)."""
    h = 1e-6
    fp = model.dispersion(z, q * (1 + h), **p)
    fm = model.dispersion(z, q * (1 - h), **p)
    fq = (fp - fm) / (2 * h)  # = kH dF/dkH
    return -fq / model.dispersion_derivative(z, q, **p)


JUMP_DS = 0.01  # ln-spacing of the neighbours compared
JUMP_DEPTH = 8  # bisections of an interval where the trapezoid rule misses (down to JUMP_DS/256 ~ 4e-5)


def _continuous(s_a: float, s_b: float, p: dict, depth: int) -> bool:
    """z(s_b) - z(s_a) agrees with the trapezoid rule on the slope, on [s_a, s_b] or on each half (recursively).

    A jump to another root leaves a difference that no subdivision explains. Next to a square-root branch point
    (where the branch is lost: z ~ z_c + a sqrt(s - s_c)) the slope diverges and the trapezoid rule fails on
    every level; there the finest interval passes if |z_b - z_a| <= 2 h min(|z_a'|, |z_b'|), which such an end
    point satisfies and a jump by more than that does not.
    """
    q = np.exp(np.array([s_a, s_b]))
    z = model.spectrum(q, **p)
    if np.isnan(z).any():
        return False  # the branch was lost inside an interval whose ends lie on it
    slope = _branch_slope(z, q, p)
    h = s_b - s_a
    predicted = 0.5 * (slope[0] + slope[1]) * h
    actual = z[1] - z[0]
    if abs(actual - predicted) <= 0.05 * abs(predicted) + 1e-9 * abs(z[0]):
        return True
    if depth == 0:
        return bool(abs(actual) <= 2 * h * np.min(np.abs(slope)) * (1 + 1e-6))
    mid = 0.5 * (s_a + s_b)
    return _continuous(s_a, mid, p, depth - 1) and _continuous(mid, s_b, p, depth - 1)


@SETTINGS
@given(gamma=st.floats(0.5, 1e3), f=fs, beta=betas, eta=etas, Delta=deltas, xi=xis,
       s0=st.floats(math.log(1e-4), math.log(1e4) - 0.05))
@example(gamma=0.5, f=0.0, beta=0.25, eta=1.0, Delta=1.0, xi=0.0, s0=-2.0234375)  # 0.002 above a branch point
def test_no_branch_jumps_between_neighbours(gamma, f, beta, eta, Delta, xi, s0):
    """Neighbouring kH (ln-spacing 0.01) agree with the local derivative: z2 - z1 ~ (z1' + z2')/2 ds, on the
    interval or on its bisections (see _continuous)."""
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    z = model.spectrum(np.exp(np.array([s0, s0 + JUMP_DS])), **p)
    if np.isnan(z).any():
        return
    assert _continuous(s0, s0 + JUMP_DS, p, JUMP_DEPTH), z


@SETTINGS
@given(
    zr=st.floats(-6, 6), zi=st.one_of(st.floats(1e-12, 6), st.floats(-6, -1e-12)), logmag=st.floats(-8, 1),
    q=st.floats(-4, 4).map(lambda x: 10.0**x), beta=betas, eta=etas,
)
def test_response_functions_overflow_free(zr, zi, logmag, q, beta, eta):
    z = complex(zr, zi) / abs(complex(zr, zi)) * 10.0**logmag
    with warnings.catch_warnings(), np.errstate(over="raise", invalid="raise", divide="raise"):
        warnings.simplefilter("error")
        gx, gy = model.response_functions(z, q, beta=beta, eta=eta)
        dgx, dgy = model.response_derivatives(z, q, beta=beta, eta=eta)
    assert np.isfinite(gx) and np.isfinite(gy) and np.isfinite(dgx) and np.isfinite(dgy)


@SETTINGS
@given(frac=st.floats(1e-8, 0.999999), kW=st.floats(-3, 3).map(lambda x: 10.0**x), nu=st.floats(0.0, 0.499))
def test_thin_on_thick_finite(frac, kW, nu):
    m, n = model.effective_moduli(kW, nu)
    assert 0 < n < 0.5 and m > 0
    z = frac * min(1.0, math.sqrt(float(m)))
    with warnings.catch_warnings(), np.errstate(over="raise", invalid="raise", divide="raise"):
        warnings.simplefilter("error")
        gx, gy = model.thin_on_thick_response(z, kW, nu=nu)
    assert np.isfinite(gx) and np.isfinite(gy)


# ----------------------------------------------------------------------------------- bad input
BAD = [
    ("beta", 0.0), ("beta", 0.75), ("beta", -0.1), ("beta", math.nan),
    ("eta", 0.0), ("eta", -5.0), ("eta", math.nan),
    ("Delta", 0.0), ("Delta", 1.5), ("xi", -1.0), ("xi", math.inf),
    ("gamma", 0.0), ("gamma", math.nan), ("f", math.nan),
]


@pytest.mark.parametrize("name,value", BAD)
def test_spectrum_rejects_bad_parameters(name, value):
    p = dict(gamma=3.0, f=0.9, beta=0.3, eta=INF, Delta=1.0, xi=0.0)
    p[name] = value
    with pytest.raises(ValueError, match=name):
        model.spectrum(np.array([1.0]), **p)


@pytest.mark.parametrize("kH", [0.0, -1.0, math.nan, "1.0", [1.0, -2.0]])
def test_spectrum_rejects_bad_kH(kH):
    with pytest.raises(ValueError, match="kH"):
        model.spectrum(kH, gamma=3.0, f=0.9, beta=0.3)


@pytest.mark.parametrize("nu", [-0.1, 0.5, 0.7, math.nan])
def test_thin_on_thick_rejects_bad_nu(nu):
    with pytest.raises(ValueError, match="nu"):
        model.effective_moduli(1.0, nu)
    with pytest.raises(ValueError, match="nu"):
        model.thin_on_thick_response(0.5, 1.0, nu=nu)


def test_other_functions_reject_bad_input():
    with pytest.raises(ValueError, match="beta"):
        model.rayleigh_speed(0.8)
    with pytest.raises(ValueError, match="kW"):
        model.effective_moduli(0.0, 0.3)
    with pytest.raises(ValueError, match="z"):
        model.response_functions(math.nan, 1.0, beta=0.3)
    with pytest.raises(ValueError, match="c must be below"):
        model.normal_stress_change(1.0, c=1400.0, c_s=1345.0, kW=5.0, nu=0.33, mu=2e9)
    with pytest.raises(ValueError, match="eta"):
        model.linear_expansion(1.0, gamma=3.0, f=0.9, beta=0.3, eta=-1.0)


def test_stress_extremes_are_finite_or_masked():
    """docs/physics.md §7 stress list: kH = 1e-4 and 1e4, eta = 1, 1+1e-9, 1e8, inf; beta -> 0, 1/sqrt2;
    gamma tiny and huge; Delta -> 0; xi = 0 and 1e4."""
    q = np.array([1e-4, 1e-2, 1.0, 1e2, 1e4])
    for p in [
        dict(gamma=3.0, f=0.9, beta=0.3, eta=np.array([1.0, 1.0 + 1e-9, 1e8, INF])[:, None]),
        dict(gamma=np.array([1e-2, 1e3])[:, None], f=0.9, beta=np.array([1e-3, 1 / math.sqrt(2)]), eta=INF),
        dict(gamma=3.0, f=0.9, beta=0.3, eta=INF, Delta=1e-3, xi=np.array([0.0, 1e4])[:, None]),
    ]:
        with warnings.catch_warnings(), np.errstate(over="raise", invalid="raise", divide="raise"):
            warnings.simplefilter("error")
            res = model.rayleigh_branch(q, **p)
        assert np.all(np.isfinite(res.z[~res.mask])) and np.all(np.isnan(res.z[res.mask]))
    # gamma huge: the root is z_R to O(1/gamma) at large kH
    z = model.spectrum(np.array([1e4]), gamma=1e3, f=0.9, beta=0.3)
    assert abs(z[0] - model.rayleigh_speed(0.3)) < 1e-2


def test_the_thick_block_functions_broadcast_over_two_dimensional_input():
    """B(q), the effective moduli and the normal-stress change at the peak slip take arrays of any shape (a 2-D kW
    once raised: the quadrature's scale kept the input's shape while its results were flat)."""
    kW = np.array([[0.5, 3.0], [5.0, 40.0]])
    flat = [float(model.bessel_integral_B(k)) for k in kW.ravel()]
    np.testing.assert_allclose(model.bessel_integral_B(kW), np.reshape(flat, kW.shape), rtol=2e-15)  # BLAS order
    mu_eff, nu_eff = model.effective_moduli(kW, 0.33)
    assert mu_eff.shape == nu_eff.shape == kW.shape
    p = model.PAPER_DEFAULTS
    c = np.array([0.9, 0.95, 0.99]) * 1236.0
    kws = dict(sigma0=p.sigma0, **{k: v for k, v in p.model_kwargs().items() if k != "plane"})
    grid = model.relative_normal_stress_change_at_peak_slip(c[:, None], kW=np.array([[3.0, 4.0, 5.0]]), **kws)
    column = [model.relative_normal_stress_change_at_peak_slip(c, kW=k, **kws) for k in (3.0, 4.0, 5.0)]
    assert grid.shape == (3, 3)
    np.testing.assert_allclose(grid, np.stack(column, axis=1), rtol=2e-15)
