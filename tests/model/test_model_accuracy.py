"""Accuracy of the model against the independent mpmath oracle (tests/oracle.py) and docs/physics.md §7.

Errors are relative unless stated. The measured maxima are printed (pytest -s) for the closing notes.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from asymslide import model
from tests import oracle

INF = math.inf
PAPER = dict(gamma=3.0, f=0.9, beta=0.3)


def rel(a: complex, b) -> float:
    b = complex(b)
    return abs(complex(a) - b) / abs(b)


# ---------------------------------------------------------------------------------------------- z_R
@pytest.mark.parametrize("beta", [1e-6, 0.05, 0.1, 0.2, 0.3, 1 / math.sqrt(3), 0.6, 0.7, 1 / math.sqrt(2)])
def test_rayleigh_speed_vs_oracle(beta):
    assert rel(model.rayleigh_speed(beta), oracle.rayleigh_speed(beta)) <= 1e-15


def test_rayleigh_speed_check_values():
    assert rel(model.rayleigh_speed(0.3), 0.9490317274618273) <= 1e-15
    assert rel(model.rayleigh_speed(math.sqrt(1 / 3)), 0.9194016867619661) <= 1e-15
    assert rel(model.rayleigh_speed(1 / math.sqrt(2)), 0.8740320488976421) <= 1e-15


# ------------------------------------------------------------------------------ response functions
RESPONSE_POINTS = [
    (0.9 + 0.01j, 1.0, 0.3, INF),
    (0.9 + 0.01j, 1.0, 0.3, 3.0),
    (0.5 + 0.2j, 0.05, 0.5, 10.0),
    (2.5 + 0.3j, 0.3, 0.3, 7.0),
    (-1.8 + 0.05j, 0.45, 0.3, 3.0),
    (1e-4 + 2e-5j, 1e-4, 0.3, 7.0),  # small |z|, small kH, finite eta: the z^-2 cancellation
    (3e-3 - 1e-3j, 0.01, 0.2, 1e8),
    (0.95 + 1e-3j, 1e4, 0.3, 1e-2),
    (0.999999 + 1e-6j, 0.5, 0.3, INF),  # next to the branch point z = 1
    (1.2 + 0.5j, 1e3, 0.6, 1.0 + 1e-9),
    (0.3 + 1.5j, 50.0, 0.1, 0.02),
]


@pytest.mark.parametrize("z,q,beta,eta", RESPONSE_POINTS)
def test_response_functions_vs_oracle(z, q, beta, eta):
    gx, gy = model.response_functions(z, q, beta=beta, eta=eta)
    ox, oy = oracle.response_functions(z, q, beta, eta)
    assert rel(gx, ox) <= 1e-13
    # G_y is accurate relative to the size of the response (|G_x| + |G_y|)
    assert abs(complex(gy) - complex(oy)) <= 1e-13 * (abs(complex(ox)) + abs(complex(oy)))


@pytest.mark.parametrize("z,q,beta,eta", RESPONSE_POINTS[:8])
def test_dispersion_and_derivative_vs_oracle(z, q, beta, eta):
    kw = dict(gamma=2.0, f=0.7, beta=beta, eta=eta, Delta=0.6, xi=0.8)
    fz = model.dispersion(z, q, **kw)
    dfz = model.dispersion_derivative(z, q, **kw)
    of = oracle.dispersion(z, q, 2.0, 0.7, beta, eta, 0.6, 0.8)
    odf = oracle.dispersion_dz(z, q, 2.0, 0.7, beta, eta, 0.6, 0.8)
    scale = float(model.dispersion_scale(z, q, **kw))
    assert abs(complex(fz) - complex(of)) <= 1e-14 * scale
    assert rel(dfz, odf) <= 1e-10


def test_gy_vanishes_exactly_for_symmetric_blocks():
    z = np.array([0.3 + 0.1j, 0.95 + 0.01j, 2.0 + 1.0j, 1e-5 + 1e-6j])
    _, gy = model.response_functions(z, np.array([[1e-4], [1.0], [1e4]]), beta=0.3, eta=1.0)
    assert np.all(gy == 0)


# ------------------------------------------------------------------------------- Rayleigh branch
SPECTRUM_CASES = [
    # (parameters, kH values)
    (dict(PAPER, eta=INF), [1e-4, 1e-2, 0.37, 0.767, 1.0, 30.0, 1e4]),
    (dict(PAPER, eta=1e8), [1e-3, 0.5, 1.0, 100.0]),
    (dict(PAPER, eta=7.0), [1e-4, 1e-3, 0.01, 0.37, 1.0, 10.0]),
    (dict(PAPER, eta=3.2982), [1e-4, 0.976, 3.0]),
    (dict(PAPER, eta=1.0), [1e-4, 0.1, 1.0, 10.0]),
    (dict(PAPER, eta=1.0 + 1e-9), [1e-3, 1.0]),
    (dict(PAPER, eta=0.05), [1e-4, 0.2, 50.0]),
    (dict(PAPER, eta=INF, Delta=0.5, xi=1.0), [0.01, 0.3, 1.0, 3.0]),
    (dict(PAPER, eta=INF, Delta=0.2, xi=1e4), [1e-3, 1.0, 100.0]),
    (dict(gamma=0.05, f=0.9, beta=0.3, eta=INF), [500.0, 1e3, 1e4]),  # root next to the branch point
    (dict(gamma=500.0, f=0.9, beta=0.3, eta=10.0), [1e-3, 0.5, 1.0, 20.0]),
    (dict(gamma=3.0, f=0.9, beta=0.02, eta=INF), [0.1, 1.0]),
    (dict(gamma=3.0, f=0.9, beta=0.7, eta=20.0), [1e-2, 1.0, 5.0]),
]

_SPECTRUM_ERRORS: list[float] = []


#: the fast lane (``make test-fast``) compares the first case, the paper's parameters at η = ∞; the others are slow
#: (1-4 s each: the oracle's 30 digits)
@pytest.mark.parametrize("params,qs", [pytest.param(*case, marks=() if i == 0 else pytest.mark.slow)
                                      for i, case in enumerate(SPECTRUM_CASES)])
def test_spectrum_vs_oracle(params, qs):
    qs = np.array(qs)
    res = model.rayleigh_branch(qs, **params)
    assert not res.mask.any(), res.reasons()
    ref = oracle.rayleigh_branch(list(qs), params["gamma"], params["f"], params["beta"], params["eta"],
                                 params.get("Delta", 1.0), params.get("xi", 0.0))
    errs = [rel(z, r) for z, r in zip(res.z, ref, strict=True)]
    _SPECTRUM_ERRORS.extend(errs)
    assert max(errs) <= 1e-11, list(zip(qs, errs, strict=True))
    # the reported error estimate is an honest bound (within a factor 10) of the true error
    assert np.all(np.array(errs) * np.abs(res.z) <= 10 * res.error + 1e-15 * np.abs(res.z))


RTOL_CASES = [SPECTRUM_CASES[i] for i in (0, 2, 4, 6, 7, 9, 10, 12)]


@pytest.mark.parametrize("rtol", [1e-6, 1e-10])
@pytest.mark.parametrize("params,qs", [pytest.param(*case, marks=() if i == 0 else pytest.mark.slow)
                                      for i, case in enumerate(RTOL_CASES)])  # the fast lane: the paper's case
def test_spectrum_rtol_vs_oracle(params, qs, rtol):
    """Looser accuracy settings: error vs the oracle below rtol, and below the returned error estimate."""
    qs = np.array(qs)
    res = model.rayleigh_branch(qs, **params, rtol=rtol)
    assert not res.mask.any(), res.reasons()
    ref = oracle.rayleigh_branch(list(qs), params["gamma"], params["f"], params["beta"], params["eta"],
                                 params.get("Delta", 1.0), params.get("xi", 0.0))
    errs = np.array([rel(z, r) for z, r in zip(res.z, ref, strict=True)])
    assert errs.max() <= rtol, list(zip(qs, errs, strict=True))
    assert np.all(errs * np.abs(res.z) <= res.error + 2e-16 * np.abs(res.z)), list(zip(errs, res.error, strict=True))


@pytest.mark.parametrize("params", [dict(PAPER, eta=INF), dict(PAPER, eta=7.0), dict(PAPER, eta=1.5),
                                    dict(PAPER, eta=INF, Delta=0.5, xi=1.0), dict(gamma=0.5, f=0.9, beta=0.3, eta=30.0),
                                    dict(gamma=50.0, f=1.5, beta=0.6, eta=INF)])
def test_spectrum_rtol_dense_grid(params):
    """512 kH: each setting within rtol of the full-accuracy roots (themselves ~1e-15 from the oracle, see
    test_spectrum_vs_oracle), the error estimate bounds the difference, and the interpolant is used."""
    q = np.logspace(-4, 4, 512)
    full = model.rayleigh_branch(q, **params)
    assert not full.mask.any()
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10, 1e-12):
        res = model.rayleigh_branch(q, **params, rtol=rtol)
        assert np.array_equal(res.mask, full.mask)
        d = np.abs(res.z - full.z)
        assert np.max(d / np.abs(full.z)) <= rtol
        assert np.all(d <= res.error + full.error + 2e-16 * np.abs(full.z))
        interpolated = np.isnan(res.residual)
        assert np.all(res.residual[~interpolated] < max(rtol, 1e-12))
        if rtol >= 1e-6:
            assert interpolated.mean() > 0.5  # the cheap path is actually taken
    # the one-point == dense-grid property holds at each setting
    for rtol in (1e-6, 1e-10):
        dense = model.spectrum(q, **params, rtol=rtol)
        assert model.spectrum(q[100:101], **params, rtol=rtol)[0] == dense[100]


@pytest.mark.parametrize("bad", [0.0, -1e-6, 1e-2, math.nan, math.inf, "1e-6", True, np.array([1e-6, 1e-8])])
def test_rtol_validation(bad):
    for fun in (model.spectrum, model.rayleigh_branch, model.max_growth):
        with pytest.raises(ValueError, match=r"rtol must be None \(full certified accuracy\) or a number in"):
            fun(np.array([0.5, 1.0]), **PAPER, rtol=bad)


@pytest.mark.parametrize("z,q,beta,eta", [(0.9 + 0.01j, 30.0, 0.3, 5.0), (0.95 - 0.02j, 20.0, 0.3, 7.0),
                                          (0.5 + 0.2j, 1e3, 0.5, 1.0 + 1e-9), (2.5 + 0.3j, 80.0, 0.3, 0.5)])
def test_response_where_the_lower_block_is_a_half_space_to_rounding(z, q, beta, eta):
    """eta kH Re(alpha) > 22: the kernels use the eta = inf form; still equal to the finite-eta oracle."""
    gx, gy = model.response_functions(z, q, beta=beta, eta=eta)
    ox, oy = oracle.response_functions(z, q, beta, eta)
    assert rel(gx, ox) <= 1e-13
    assert abs(complex(gy) - complex(oy)) <= 1e-13 * (abs(complex(ox)) + abs(complex(oy)))


SLOPE_CASES = [(0.767, dict(PAPER, eta=INF)), (1e-3, dict(PAPER, eta=INF)), (0.37, dict(PAPER, eta=7.0)),
               (1e-4, dict(PAPER, eta=7.0)), (10.0, dict(PAPER, eta=7.0)), (0.2, dict(PAPER, eta=0.05)),
               (1.0, dict(PAPER, eta=1.0 + 1e-9)), (0.3, dict(PAPER, eta=INF, Delta=0.5, xi=1.0))]


@pytest.mark.parametrize("q,params", [pytest.param(q, p, marks=pytest.mark.slow if p["eta"] == 1.0 + 1e-9 else ())
                                     for q, p in SLOPE_CASES])  # η = 1 + 1e-9: 2 s of the oracle's
def test_branch_slope_vs_oracle(q, params):
    """dz/dkH = -F_kH/F_z with the analytic F_kH of the kernels (used for the Hermite path interpolant)."""
    from asymslide.model._kernels import response as K

    p = dict(Delta=1.0, xi=0.0) | params
    z = complex(model.spectrum(np.array([q]), **p)[0])
    fq = K.dispersion_dq(z, q, p["gamma"], p["f"], p["beta"], p["eta"], p["Delta"], p["xi"])
    fz = complex(model.dispersion_derivative(z, q, **p))
    oz, odz = oracle.branch_tangent(q, p["gamma"], p["f"], p["beta"], p["eta"], p["Delta"], p["xi"])
    assert rel(-fq / fz, odz) <= 1e-10


def test_small_gamma_branch_runs_into_the_cut_and_is_masked():
    """gamma = 0.05, eta = inf: the branch hugs z = 1 and reaches the cut z > 1 between kH = 500 and 300;
    the oracle cannot follow it either. Below, the model returns NaN with a reason, never another root."""
    res = model.rayleigh_branch(np.array([100.0, 10.0, 1.0]), gamma=0.05, f=0.9, beta=0.3)
    assert res.mask.all() and np.all(res.status == 1)
    assert oracle.rayleigh_branch([100.0], 0.05, 0.9, 0.3, INF, strict=False) == [None]


def test_spectrum_check_value():
    z = model.spectrum(np.array([1.0]), **PAPER)
    assert rel(z[0], 0.88336356305352538 + 0.00815518661032729j) <= 1e-12


def test_spectrum_one_point_equals_dense_grid():
    grid = np.sort(np.append(np.logspace(-3, 3, 301), [0.37, 2.5e-4, 7e3]))
    for eta in (7.0, INF, 1.5):
        dense = model.spectrum(grid, **PAPER, eta=eta)
        for q in (0.37, 2.5e-4, 7e3):
            alone = model.spectrum(np.array([q]), **PAPER, eta=eta)[0]
            assert dense[np.searchsorted(grid, q)] == alone


@pytest.mark.slow
def test_spectrum_broadcast_shape_and_values():
    q = np.logspace(-1, 1, 5)
    gam = np.array([[2.0], [3.0]])
    eta = np.array([5.0, INF, 9.0])
    z = model.spectrum(q, gamma=gam, f=0.9, beta=0.3, eta=eta)
    assert z.shape == (2, 3, 5)
    assert np.array_equal(z[1, 2], model.spectrum(q, gamma=3.0, f=0.9, beta=0.3, eta=9.0))
    z2 = model.spectrum(q.reshape(5, 1), gamma=3.0, f=0.9, beta=0.3)
    assert z2.shape == (5, 1)


def test_paper_stability_facts():
    """Fig. 4a: eta = 1 stable for all kH, eta = inf unstable near kH ~ 0.77 with max Im z ~ 0.0106758."""
    q = np.logspace(-3, 3, 601)
    assert np.nanmax(model.spectrum(q, **PAPER, eta=1.0).imag) < 0
    fine = np.linspace(0.6, 1.0, 401)
    z = model.spectrum(fine, **PAPER, eta=INF)
    assert abs(np.nanmax(z.imag) - 0.0106758) < 1e-7
    assert abs(fine[np.nanargmax(z.imag)] - 0.767) < 0.005
    zd = model.spectrum(q, **PAPER, eta=INF, Delta=0.5, xi=1.0)
    assert abs(np.nanmax(zd.imag) - 0.028570) < 2e-5


@pytest.mark.parametrize("eta", [INF, 10.0])
def test_linear_expansion_vs_oracle(eta):
    q = np.array([0.1, 0.86, 3.0])
    z = model.linear_expansion(q, **PAPER, eta=eta)
    for zi, qi in zip(z, q, strict=True):
        assert rel(zi, oracle.linear_expansion(qi, 3.0, 0.9, 0.3, eta)) <= 1e-12


# ---------------------------------------------------------------------------------- thin-on-thick
def test_bessel_B_check_values():
    assert rel(model.bessel_integral_B(2.0), 0.79100634) <= 1e-8
    assert rel(model.bessel_integral_B(10.0), 0.99782980) <= 1e-8


@pytest.mark.parametrize("q", [1e-3, 0.03, 0.5, 1.0, 2.0, 4.0, 10.0, 24.0, 45.345, 100.0])
def test_bessel_B_and_tail_vs_oracle(q):
    assert rel(model.bessel_integral_B(q), oracle.B(q)) <= 1e-13
    assert rel(model.one_minus_bessel_integral_B(q), oracle.one_minus_B(q)) <= 1e-12
    assert rel(model.bessel_term_C(q), oracle.C(q)) <= 1e-13


@pytest.mark.slow
def test_bessel_tail_far_out_vs_struve_closed_form():
    """1 - B at q = 300 and 1000 (values 1e-67, 1e-219) against Int_0^x K0 = (pi x/2)(K0 L_-1 + K1 L_0)."""
    for q in (300.0, 1000.0):
        with mpmath.workdps(300):
            x = mpmath.mpf(q) / 2
            head = mpmath.pi * x / 2 * (mpmath.besselk(0, x) * mpmath.struvel(-1, x)
                                        + mpmath.besselk(1, x) * mpmath.struvel(0, x))
            ref = 2 / mpmath.pi * (mpmath.pi / 2 - head)
        assert rel(model.one_minus_bessel_integral_B(q), ref) <= 1e-12


@pytest.mark.parametrize("nu", [0.0, 0.33, 0.49])
@pytest.mark.parametrize("q", [1e-3, 0.1, 1.0, 5.0, 19.3, 45.0, 1e3])
def test_effective_moduli_vs_oracle(q, nu):
    m, n = model.effective_moduli(q, nu)
    om, on = oracle.effective_moduli(q, nu)
    assert rel(m, om) <= 1e-12
    # nu_eff -> nu; for nu = 0 it is exponentially small at large kW: absolute accuracy there
    assert abs(float(n) - float(on)) <= 1e-12 * max(abs(float(on)), 1e-3)


def test_effective_moduli_check_values():
    m, _ = model.effective_moduli(np.array([1.0, 3.0, 5.0]), 0.33)
    assert np.allclose(m, [1.52182858, 1.08044869, 1.01886667], rtol=1e-8, atol=0)


@pytest.mark.parametrize("nu,q_min,depth", [(0.2, 8.5897, 7.0327e-4), (0.33, 19.2946, 9.7473e-7),
                                            (0.4, 45.345, 5.847e-13), (0.3, 15.119, 1.13875e-5)])
def test_effective_modulus_minima(nu, q_min, depth):
    """The three minima of docs/physics.md §6 (and nu = 0.3): 1 - min mu_eff/mu to 1e-3 relative."""
    q = np.linspace(q_min * 0.98, q_min * 1.02, 2001)
    ex = model.effective_modulus_excess(q, nu)
    k = np.argmin(ex)
    assert abs(q[k] - q_min) / q_min < 1e-3
    assert rel(-ex[k], depth) <= 1e-3
    oq, od = oracle.mu_eff_minimum(nu)
    assert rel(-model.effective_modulus_excess(float(oq), nu), od) <= 1e-9
    # the plain ratio is also right to 1e-3 relative in 1 - mu_eff/mu
    assert rel(1 - model.effective_moduli(float(oq), nu)[0], od) <= 1e-3


def test_thin_on_thick_check_values():
    assert rel(model.thin_on_thick_response(0.919, 5.0, nu=0.33)[1], -0.0544266880084) <= 1e-10
    assert rel(model.thin_on_thick_response(0.9, 3.0, nu=0.33)[1], -0.101096689153) <= 1e-10
    assert rel(model.thin_on_thick_response(1e-8, 5.0, nu=0.33)[1], -0.04921931781306) <= 1e-10
    assert rel(model.thin_on_thick_response(1e-4, 5.0, nu=0.33)[1], -0.04921931774306) <= 1e-10


@pytest.mark.parametrize("kW", [1e-3, 1.0, 5.0, 30.0, 1e3])
@pytest.mark.parametrize("frac", [1e-8, 0.5, 0.99, 0.999999])
def test_thin_on_thick_vs_oracle(kW, frac):
    """From the quasi-static limit up to (just below) the lowest shear speed of the pair."""
    m, _ = model.effective_moduli(kW, 0.33)
    z = frac * min(1.0, math.sqrt(float(m)))
    gx, gy = model.thin_on_thick_response(z, kW, nu=0.33)
    ox, oy = oracle.thin_on_thick_response(z, kW, 0.33)
    assert rel(gx, ox) <= 1e-10
    assert rel(gy, oy) <= 1e-10


def test_thin_on_thick_smooth_through_the_thin_blocks_rayleigh_speed():
    """c = c_R of the thin block is a pole of its compliance M_upper, not of G: finite, smooth, oracle-exact."""
    zr = float(model.rayleigh_speed(math.sqrt((1 - 0.33) / 2)))
    zs = np.array([zr * (1 - 1e-9), np.nextafter(zr, 0), zr, np.nextafter(zr, 2), zr * (1 + 1e-9)])
    gy = model.thin_on_thick_response(zs, 5.0, nu=0.33)[1]
    assert np.all(np.isfinite(gy)) and np.ptp(gy.real) < 1e-9
    assert rel(gy[2], oracle.thin_on_thick_response(zr * (1 + 1e-12), 5.0, 0.33)[1]) <= 1e-10
    ds = model.normal_stress_change(np.array([1.0]), c=zr * 1345.0, c_s=1345.0, kW=5.0, nu=0.33, mu=1180 * 1345.0**2)
    assert np.isfinite(ds).all() and ds[0] > 0


def test_thin_on_thick_quasistatic_limit_vs_independent_formula():
    for kW in (0.01, 1.0, 5.0, 100.0):
        assert rel(model.thin_on_thick_response(1e-8, kW, nu=0.33)[1], oracle.thin_on_thick_quasistatic_gy(kW, 0.33)) \
            <= 1e-10


def test_normal_stress_change_vs_oracle():
    mu = 1180 * 1345.0**2
    v = np.array([0.1, 1.0, 2.0])
    ds = model.normal_stress_change(v, c=1237.0, c_s=1345.0, kW=5.0, nu=0.33, mu=mu)
    for d, vi in zip(ds, v, strict=True):
        assert rel(d, oracle.normal_stress_change(vi, 1237.0, 1345.0, 5.0, 0.33, mu)) <= 1e-10
    gy = oracle.thin_on_thick_response(mpmath.mpf(1237.0) / 1345.0, 5.0, 0.33)[1]
    assert gy.real < 0  # at this speed G_y < 0 ...
    assert np.all(ds > 0)  # ... so Delta sigma_yy = -(mu/c) G_y v > 0 for v > 0: a reduction of compression
    np.testing.assert_allclose(ds / v, ds[0] / v[0], rtol=1e-14)  # linear in the slip velocity


@pytest.mark.slow  # alone (a selection), it compares every case itself
def test_worst_spectrum_error_over_all_oracle_cases():
    """Every oracle point of SPECTRUM_CASES was compared, and the worst relative error of the Rayleigh branch over
    them is within 1e-11 (reported with -s). Uses the errors of test_spectrum_vs_oracle when the whole module ran,
    otherwise computes them."""
    n_points = sum(len(qs) for _, qs in SPECTRUM_CASES)
    errors = list(_SPECTRUM_ERRORS)
    if len(errors) != n_points:  # run on its own (or a selection): compare every case here
        errors = []
        for params, qs in SPECTRUM_CASES:
            res = model.rayleigh_branch(np.array(qs), **params)
            assert not res.mask.any(), res.reasons()
            ref = oracle.rayleigh_branch(list(qs), params["gamma"], params["f"], params["beta"], params["eta"],
                                         params.get("Delta", 1.0), params.get("xi", 0.0))
            errors += [rel(z, r) for z, r in zip(res.z, ref, strict=True)]
    assert len(errors) == n_points
    worst = max(errors)
    print(f"\nmax relative spectrum error vs oracle: {worst:.2e} over {n_points} points")
    assert worst <= 1e-11
