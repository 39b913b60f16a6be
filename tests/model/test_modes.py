"""Tests of model.modes: every unstable mode in a window (docs/physics.md §2-§3).

Reference roots are the "other branch" values of docs/physics.md §3 (f = 0.9, beta = 0.3, Delta = 1, gamma = 3).
"""

from __future__ import annotations

import math
import warnings
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mpmath import mp

from asymslide import model
from asymslide.model import modes
from asymslide.model._roots import contour
from asymslide.model.modes import unstable_count, unstable_modes
from tests import oracle

PAPER = dict(gamma=3.0, f=0.9, beta=0.3)


def _has(roots: np.ndarray, z: complex, rtol: float) -> bool:
    return roots.size > 0 and float(np.min(np.abs(roots - z))) <= rtol * abs(z)


def _residual(roots: np.ndarray, kH: float, **p) -> np.ndarray:
    F = model.dispersion(roots, kH, **p)
    return np.abs(F) / model.dispersion_scale(roots, kH, **p)


@pytest.mark.parametrize(
    "eta, kH, z_ref",
    [
        (3.0, 0.45, -1.86154054015624 + 0.04806456251133j),  # backward travelling, eta < eta_c
        (math.inf, 0.45, 3.53354704617255 + 0.07585981635187j),  # faster than c_d
    ],
)
def test_other_branch_reference_roots(eta, kH, z_ref):
    roots = unstable_modes(kH, eta=eta, **PAPER)
    assert _has(roots, z_ref, 1e-10), roots
    assert unstable_count(kH, eta=eta, **PAPER) == roots.size
    assert np.all(_residual(roots, kH, eta=eta, **PAPER) < 1e-12)


def test_eta10_ten_roots_rayleigh_not_dominant():
    roots = unstable_modes(0.77, eta=10.0, **PAPER)
    assert roots.size == 10
    assert unstable_count(0.77, eta=10.0, **PAPER) == 10
    assert _has(roots, 0.8847 + 0.01045j, 1e-4)  # Rayleigh branch
    assert _has(roots, 2.3954 + 0.03804j, 1e-4)
    assert abs(roots[0] - (2.3954 + 0.03804j)) < 1e-4  # sorted by decreasing Im z: the dominant mode first
    assert np.all(np.diff(roots.imag) <= 0)
    assert np.all(roots.imag >= 1e-4) and np.all(np.abs(roots.real) <= 5.0)
    assert np.min(np.abs(roots[:, None] - roots[None, :]) + np.eye(roots.size)) > 1e-6  # distinct


def test_roots_match_mpmath_oracle():
    """The roots agree with mpmath findroot on the independent oracle's F (30 digits) to 1e-12."""
    p = oracle.Params.make(3.0, 0.9, 0.3, 3.0)
    for z in unstable_modes(0.45, eta=3.0, **PAPER):
        with mp.workdps(30):
            ref = complex(mp.findroot(lambda w: oracle.dispersion_core(w, mp.mpf(0.45), p), mp.mpc(z)))
        assert abs(z - ref) <= 1e-12 * abs(ref)


@pytest.mark.parametrize("kH", [0.05, 0.3, 0.5, 1.0, 3.0, 30.0])
def test_symmetric_blocks_have_no_unstable_mode(kH):
    assert unstable_count(kH, eta=1.0, **PAPER) == 0
    assert unstable_modes(kH, eta=1.0, **PAPER).size == 0


@pytest.mark.parametrize("eta, kH", [(10.0, 0.77), (3.0, 0.45), (math.inf, 0.45)])
def test_mirror_symmetry(eta, kH):
    """z -> -conj(z) maps the roots for f to the roots for -f (the window is symmetric in Re z)."""
    plus = unstable_modes(kH, gamma=3.0, f=0.9, beta=0.3, eta=eta)
    minus = unstable_modes(kH, gamma=3.0, f=-0.9, beta=0.3, eta=eta)
    assert plus.size == minus.size
    mirrored = np.sort_complex(-np.conj(minus))
    assert np.allclose(np.sort_complex(plus), mirrored, rtol=0, atol=1e-10)


def test_rayleigh_branch_is_among_the_modes():
    z_r = model.spectrum(np.array([0.77]), eta=math.inf, **PAPER)[0]
    assert z_r.imag >= 1e-4
    roots = unstable_modes(0.77, eta=math.inf, **PAPER)
    assert _has(roots, z_r, 1e-10), (z_r, roots)


@pytest.mark.parametrize("eta, kH, im_min", [(3.0, 0.45, 1e-2), (math.inf, 0.45, 1e-2), (10.0, 0.77, 3e-2)])
def test_count_agrees_with_cxroots(eta, kH, im_min):
    cxroots = pytest.importorskip("cxroots")
    p = dict(eta=eta, **PAPER)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        n_cx = cxroots.Rectangle([-5.0, 5.0], [im_min, 2.0]).count_roots(
            lambda z: model.dispersion(z, kH, **p), lambda z: model.dispersion_derivative(z, kH, **p)
        )
    assert unstable_count(kH, im_min=im_min, **p) == n_cx
    assert unstable_modes(kH, im_min=im_min, **p).size == n_cx


def test_strict_sampling_finds_the_same_roots():
    """A 10x finer contour sampling (tolerances / 4-10, initial spacing / 10) changes nothing.

    The finer settings are patched into the root engine's constants (model._roots.contour), which a problem
    reads when it is set up."""
    args = (0.77, 3.0, 0.9, 0.3, 10.0, 1.0, 0.0, 5.0, 1e-4, 2.0)
    normal, n_normal = modes._modes(modes._problem(*args))
    finer = dict(PHASE_MAX=contour.PHASE_MAX / 4, TRAP_TOL=contour.TRAP_TOL / 10, LIN_TOL=contour.LIN_TOL / 10,
                 H0=contour.H0 / 10)
    with mock.patch.multiple(contour, **finer):
        prob = modes._problem(*args)
    assert prob.tols == (finer["PHASE_MAX"], finer["TRAP_TOL"], finer["LIN_TOL"]) and prob.h0 == finer["H0"]
    strict, n_strict = modes._modes(prob)
    assert n_strict > 2 * n_normal  # the finer sampling did take more samples
    assert normal.size == strict.size >= 1
    assert np.allclose(np.sort_complex(normal), np.sort_complex(strict), rtol=0, atol=1e-12)


def test_window_semantics_roots_on_the_boundary_count():
    p = dict(eta=3.0, **PAPER)
    z0 = unstable_modes(0.45, **p)[0]
    for window in (dict(im_min=z0.imag), dict(im_max=z0.imag), dict(re_max=-z0.real)):
        assert unstable_count(0.45, **p, **window) == 1, window
        assert _has(unstable_modes(0.45, **p, **window), z0, 1e-14), window
    # clearly outside: not counted
    assert unstable_count(0.45, **p, im_min=z0.imag * (1 + 1e-6)) == 0
    assert unstable_count(0.45, **p, im_max=z0.imag * (1 - 1e-6)) == 0
    assert unstable_count(0.45, **p, re_max=-z0.real * (1 - 1e-6)) == 0
    # im_min = 0: just above the real axis (Im z >= 1e-10)
    assert unstable_count(0.45, **p, im_min=0.0) >= 1


def test_count_depends_on_im_min_for_large_eta():
    """Large finite eta: more roots just above the dense real-axis poles as im_min decreases."""
    p = dict(eta=100.0, **PAPER)
    counts = [unstable_count(0.77, im_min=m, **p) for m in (1e-2, 1e-3, 1e-4)]
    assert counts[0] < counts[1] < counts[2]  # 1, 36, 85 at the time of writing
    assert len(unstable_modes(0.77, im_min=1e-3, **p)) == counts[1]


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(kH=np.array([0.5, 1.0])), "kH"),
        (dict(kH=-1.0), "kH"),
        (dict(gamma=0.0), "gamma"),
        (dict(beta=0.9), "beta"),
        (dict(eta=float("nan")), "eta"),
        (dict(Delta=1.5), "Delta"),
        (dict(re_max=0.0), "re_max"),
        (dict(im_min=-1e-3), "im_min"),
        (dict(im_max=1e-4), "im_max"),
        (dict(im_max=float("inf")), "im_max"),
    ],
)
def test_invalid_input(kwargs, name):
    args = dict(kH=0.5, gamma=3.0, f=0.9, beta=0.3, eta=3.0)
    args.update(kwargs)
    kH = args.pop("kH")
    for fn in (unstable_modes, unstable_count):
        with pytest.raises(ValueError, match=name):
            fn(kH, **args)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    kH=st.floats(-1.5, 1.0).map(lambda x: 10.0**x),
    gamma=st.floats(-1.0, 1.5).map(lambda x: 10.0**x),
    f=st.floats(-1.5, 1.5),
    beta=st.floats(0.05, 0.7),
    eta=st.one_of(st.just(math.inf), st.floats(-1.0, 2.0).map(lambda x: 10.0**x)),
    Delta=st.one_of(st.just(1.0), st.floats(0.2, 1.0)),
    xi=st.floats(0.0, 10.0),
    im_min=st.sampled_from([1e-4, 1e-3, 1e-2]),
)
def test_property_roots_are_roots_in_the_window(kH, gamma, f, beta, eta, Delta, xi, im_min):
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    roots = unstable_modes(kH, im_min=im_min, **p)
    assert unstable_count(kH, im_min=im_min, **p) == roots.size
    if roots.size:
        assert np.all(_residual(roots, kH, **p) < 1e-12)
        tol = 1e-9
        assert np.all(roots.imag >= im_min * (1 - tol)) and np.all(roots.imag <= 2.0 + tol)
        assert np.all(np.abs(roots.real) <= 5.0 + tol)
        assert np.all(np.diff(roots.imag) <= 0)
