"""Thresholds and growth maps on the Rayleigh branch against docs/physics.md §7 and the mpmath oracle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from asymslide import model
from asymslide.model import stability
from tests import oracle

PAPER = dict(f=0.9, beta=0.3)
Q = np.logspace(-3, 3, 241)


def test_max_growth_check_value_and_refinement():
    r = stability.growth_analysis(Q, gamma=3.0, **PAPER)
    assert abs(float(r.growth) - 0.0106758) < 5e-8
    assert abs(float(r.kH_at_max) - 0.767) < 2e-3
    # refined maximum: no grid point of a much finer grid beats it
    fine = np.linspace(0.7, 0.85, 3001)
    assert np.nanmax(model.spectrum(fine, gamma=3.0, **PAPER).imag) <= float(r.growth) + 1e-13
    # the band ends are zeros of Im z
    z = model.spectrum(np.array([float(r.kH_min), float(r.kH_max)]), gamma=3.0, **PAPER)
    assert np.all(np.abs(z.imag) < 1e-13)


def test_max_growth_against_oracle():
    q_star, g_star = oracle.rayleigh_branch_max_growth(0.767, 3, 0.9, 0.3, math.inf)
    g, k = model.max_growth(Q, gamma=3.0, **PAPER)
    assert abs(float(g) - float(g_star)) <= 1e-9 * abs(float(g_star))
    assert abs(float(k) - float(q_star)) <= 1e-4 * float(q_star)


def test_max_growth_broadcasts_to_a_map():
    g = np.array([1.0, 3.0, 10.0])
    e = np.array([1.0, 3.0, 10.0, math.inf])
    growth, kmax = model.max_growth(Q, gamma=g[:, None], eta=e[None, :], **PAPER)
    assert growth.shape == (3, 4) and kmax.shape == (3, 4)
    assert np.all(growth[:, 0] < 0)  # eta = 1: symmetric, stable
    assert growth[1, 3] == pytest.approx(0.0106758, abs=5e-8)
    one = model.max_growth(Q, gamma=10.0, eta=3.0, **PAPER)[0]
    assert growth[2, 1] == one


def test_delta_xi_growth_check_value():
    g, _ = model.max_growth(Q, gamma=3.0, **PAPER, Delta=0.5, xi=1.0)
    assert abs(float(g) - 0.028570) < 5e-7


def test_critical_gamma_and_eta_check_values():
    gc = model.critical_gamma(**PAPER)
    assert abs(gc - 2.4149) < 5e-5
    assert abs(float(model.max_growth(model.thresholds.DEFAULT_KH, gamma=gc, **PAPER)[0])) < 1e-14
    ec = model.critical_eta(gamma=3.0, **PAPER)
    assert abs(ec - 3.2982) < 5e-5
    g, k = model.max_growth(model.thresholds.DEFAULT_KH, gamma=3.0, eta=ec, **PAPER)
    assert abs(float(g)) < 1e-14
    assert abs(float(k) - 0.976) < 0.01


def test_thresholds_raise_without_crossing():
    with pytest.raises(ValueError, match="no stability threshold for gamma"):
        model.critical_gamma(f=0.9, beta=0.3, eta=1.0)
    with pytest.raises(ValueError, match="no stability threshold for eta"):
        model.critical_eta(gamma=0.5, f=0.9, beta=0.3)


def test_criterion_chi_check_values_and_oracle():
    qmin, gmin = stability.min_gy_at_rayleigh_speed(0.3)
    assert abs(qmin - 0.86438) < 1e-5 and abs(gmin + 0.475111) < 1e-6
    assert abs(float(model.criterion_chi(0.3)) - 1.99750) < 1e-5
    oq, og = oracle.criterion_min_gy(0.3)
    assert abs(gmin - float(og)) <= 1e-12 * abs(float(og))
    chi = model.criterion_chi(np.array([0.1, 0.3, 0.5]))
    assert chi.shape == (3,) and np.all(chi > 0)


def test_critical_chi_is_gamma_c_times_f():
    assert model.critical_chi(0.3, f=0.9) == pytest.approx(2.4149 * 0.9, rel=2e-5)


def test_global_verdict():
    sym = model.stability_verdict(gamma=3.0, f=0.9, beta=0.3, eta=1.0)
    assert sym.stable and sym.rayleigh_growth < 0 and not sym.counts.any()
    assert model.stable(gamma=3.0, f=0.9, beta=0.3, eta=1.0)
    # eta = inf: the Rayleigh branch itself is unstable
    assert not model.stable(gamma=3.0, f=0.9, beta=0.3)
    # eta = 3 < eta_c: the Rayleigh branch is stable, but another branch is unstable near kH = 0.45
    v = model.stability_verdict(gamma=3.0, f=0.9, beta=0.3, eta=3.0, kH=np.array([0.3, 0.45, 0.6]))
    assert v.rayleigh_growth < 0 and v.counts[1] >= 1 and not v.stable


@pytest.mark.parametrize("rtol", [1e-6, 1e-10])
def test_max_growth_rtol_against_oracle(rtol):
    q_star, g_star = oracle.rayleigh_branch_max_growth(0.767, 3, 0.9, 0.3, math.inf)
    g, k = model.max_growth(Q, gamma=3.0, **PAPER, rtol=rtol)
    assert abs(float(g) - float(g_star)) <= rtol * abs(model.spectrum(np.array([float(k)]), gamma=3.0, **PAPER)[0])
    assert abs(math.log(float(k) / float(q_star))) <= 1e-4
    r = stability.growth_analysis(Q, gamma=3.0, **PAPER, rtol=rtol)
    z = model.spectrum(np.array([float(r.kH_min), float(r.kH_max)]), gamma=3.0, **PAPER)
    assert np.all(np.abs(z.imag) < 10 * rtol)


def test_growth_map_agrees_with_full_spectrum_and_stays_on_the_grid():
    """A small eta-gamma map: each growth is the max of the full-accuracy spectrum on a fine grid (to the
    refinement) over the part of the branch that is not pole-dense (docs/physics.md §9: for finite eta, |Re z| > 1
    with eta kH Re alpha_s < 1), the location lies inside the kH grid (monotone cases: at its end), band ends are
    zeros."""
    gam = np.array([0.5, 1.5, 3.0, 12.0])
    eta = np.array([1.0, 3.0, 30.0, 6700.0, math.inf])
    r = stability.growth_analysis(Q, gamma=gam[:, None], eta=eta[None, :], **PAPER)
    fine = np.logspace(-3, 3, 6001)
    for i, g in enumerate(gam):
        for j, e in enumerate(eta):
            z = model.spectrum(fine, gamma=g, eta=e, **PAPER)
            with np.errstate(invalid="ignore"):
                pole_dense = (np.abs(z.real) > 1) & (e * fine * np.sqrt(1 - z * z).real < 1)
            regular = np.where(pole_dense, np.nan, z.imag)
            assert Q[0] <= r.kH_at_max[i, j] <= Q[-1]
            assert np.nanmax(regular) <= r.growth[i, j] + 1e-13
            local = r.kH_at_max[i, j] * np.exp(np.linspace(-1e-3, 1e-3, 201))
            local = local[(local >= Q[0]) & (local <= Q[-1])]
            zl = model.spectrum(local, gamma=g, eta=e, **PAPER).imag
            assert r.growth[i, j] - 1e-12 <= np.nanmax(zl) <= r.growth[i, j] + 1e-13
            at = model.spectrum(np.array([r.kH_at_max[i, j]]), gamma=g, eta=e, **PAPER)[0]
            assert at.imag == pytest.approx(r.growth[i, j], abs=1e-15)
            # a pole-dense part leaves the verdict undetermined (4) unless the regular part grows (1)
            assert r.verdict_reason[i, j] in ((1, 4) if pole_dense.any() else (0, 1, 2, 5))
            for band_end in (r.kH_min[i, j], r.kH_max[i, j]):
                if np.isfinite(band_end):
                    assert abs(model.spectrum(np.array([band_end]), gamma=g, eta=e, **PAPER)[0].imag) < 1e-13


def test_verdict_is_not_stable_where_the_rayleigh_branch_cannot_be_followed():
    """A masked branch (NaN growth on the whole grid) certifies nothing, even with no root in the window."""
    v = model.stability_verdict(gamma=0.01, f=2.0, beta=1 / math.sqrt(2), eta=10**0.5)
    assert math.isnan(v.rayleigh_growth)
    assert not v.stable and not model.stable(gamma=0.01, f=2.0, beta=1 / math.sqrt(2), eta=10**0.5)
