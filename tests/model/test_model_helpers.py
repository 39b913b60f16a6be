"""Model functions that used to be computed in the app, against the mpmath oracle and their definitions:
plane-stress beta(nu), mu = rho c_s^2, the limiting speed of the thin-on-thick pair, the criterion level
-z_R/(gamma f) and the residual/error estimate of a root."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from asymslide import model
from tests import oracle


@pytest.mark.parametrize("nu", [0.0, 0.2, 0.33, 0.45])
def test_wave_speed_ratio_plane_stress_and_strain(nu: float) -> None:
    # plane stress: the 2-D Poisson ratio nu/(1+nu) in the plane-strain formula
    nu2 = nu / (1 + nu)
    assert model.wave_speed_ratio(nu, plane="stress") == pytest.approx(math.sqrt((1 - 2 * nu2) / (2 - 2 * nu2)),
                                                                        rel=1e-15)
    assert model.wave_speed_ratio(nu) == pytest.approx(math.sqrt((1 - 2 * nu) / (2 - 2 * nu)), rel=1e-15)
    for plane in ("strain", "stress"):
        assert model.poisson_ratio(model.wave_speed_ratio(nu, plane=plane), plane=plane) == pytest.approx(
            nu, abs=1e-15)


def test_elastic_constants_reject_bad_input() -> None:
    with pytest.raises(ValueError, match="nu"):
        model.wave_speed_ratio(0.5)
    with pytest.raises(ValueError, match="plane"):
        model.wave_speed_ratio(0.3, plane="membrane")
    with pytest.raises(ValueError, match="rho"):
        model.shear_modulus(-1.0, 1345.0)
    assert model.shear_modulus(1180.0, 1345.0) == pytest.approx(1180.0 * 1345.0**2, rel=1e-15)


@pytest.mark.parametrize(("kW", "nu"), [(0.5, 0.33), (5.0, 0.33), (19.3, 0.33), (45.0, 0.4), (1e3, 0.2)])
def test_limiting_speed_is_the_slower_shear_speed(kW: float, nu: float) -> None:
    mpmath.mp.dps = 30
    mu_ratio, _ = oracle.effective_moduli(kW, nu)
    want = min(mpmath.mpf(1), mpmath.sqrt(mu_ratio))
    assert float(model.limiting_speed(kW, nu)) == pytest.approx(float(want), rel=1e-14)


def test_normal_stress_change_refuses_speeds_at_the_limit() -> None:
    c_max = float(model.limiting_speed(50.0, 0.33)) * 1345.0  # mu_eff < mu at kW = 50: the lower block is slower
    assert c_max < 1345.0
    with pytest.raises(ValueError, match="shear wave speed"):
        model.normal_stress_change(1.0, c=c_max, c_s=1345.0, kW=50.0, nu=0.33, mu=2e9)


def test_criterion_level() -> None:
    mpmath.mp.dps = 30
    level = model.criterion_gy_level(gamma=np.array([3.0, 0.5]), f=0.9, beta=0.3)
    z_r = oracle.rayleigh_speed(0.3)
    assert level == pytest.approx([float(-z_r / mpmath.mpf(2.7)), float(-z_r / mpmath.mpf(0.45))], rel=1e-15)
    assert model.criterion_gy_level(gamma=3.0, f=0.0, beta=0.3) == -math.inf


def test_root_error_estimate_bounds_the_distance_to_the_exact_root() -> None:
    mpmath.mp.dps = 30
    p = dict(gamma=3.0, f=0.9, beta=0.3, eta=10.0)
    roots = model.unstable_modes(0.77, **p)
    residual, error = model.root_error_estimate(roots, 0.77, **p)
    assert residual.shape == error.shape == roots.shape and np.all(residual < 1e-12)
    for z, e in zip(roots, error, strict=True):
        exact = mpmath.findroot(lambda w: oracle.dispersion(w, 0.77, **p), mpmath.mpc(z))
        distance = abs(complex(exact) - z)
        assert distance <= 10 * e  # a first-order estimate: the true error is below it (up to rounding)
    # a perturbed root: the estimate follows the perturbation
    _, err = model.root_error_estimate(roots[0] + 1e-6, 0.77, **p)
    assert err == pytest.approx(1e-6, rel=0.01)
