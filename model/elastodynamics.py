"""Elastodynamic response of two finite blocks and the dispersion relation (docs/physics.md §2-§3)."""

from __future__ import annotations

import math

import numpy as np

from . import _kernels as K
from ._validate import check


def _flat(*arrays: np.ndarray) -> tuple[tuple[int, ...], list[np.ndarray]]:
    """Broadcast arrays and return the shape and contiguous 1-D copies."""
    b = np.broadcast_arrays(*arrays)
    shape = b[0].shape
    return shape, [np.array(x, dtype=x.dtype, order="C").ravel() for x in b]


def response_functions(z, kH, *, beta, eta=math.inf):
    """Elastic response functions (G_x, G_y) of two blocks of one material (Eq. Gs_general, S-G_gen).

    G_x = z^-2 [(1+a_s^2)^2/(a_s (T1_s+T2_s)) - 4 a_d/(T1_d+T2_d)],
    G_y = 2 (1+a_s^2) z^-2 [T2_d/(T1_d+T2_d) - T2_s/(T1_s+T2_s)],
    a_s = sqrt(1-z^2), a_d = sqrt(1-beta^2 z^2), T1_j = tanh(kH a_j), T2_j = tanh(eta kH a_j);
    eta = inf means a half-space below (T2 = +1, Eqs. Gx_LSA/Gy_LSA; docs/physics.md §11 notes the misprint).

    Evaluated in cancellation-free form (``model._kernels.response``, docs/physics.md §2): no z^-2
    cancellation at small |z|, no overflow for large complex arguments, G_y = 0 exactly for eta = 1. Poles
    lie on the real axis only; the open upper half-plane is analytic.

    Parameters
    ----------
    z : array_like complex, phase velocity c/c_s
    kH : array_like, > 0
    beta : array_like, c_s/c_d in (0, 1/sqrt(2)]
    eta : array_like, H2/H1 in (0, inf]

    Returns
    -------
    (G_x, G_y) : complex ndarrays of the broadcast shape.
    """
    gx, gy, _, _ = _response_all(z, kH, beta, eta)
    return gx, gy


def response_derivatives(z, kH, *, beta, eta=math.inf):
    """Analytic z-derivatives (dG_x/dz, dG_y/dz) of the response functions of Eq. Gs_general."""
    _, _, dgx, dgy = _response_all(z, kH, beta, eta)
    return dgx, dgy


def _response_all(z, kH, beta, eta):
    zz = check("z", z, complex_ok=True)
    q = check("kH", kH)
    b = check("beta", beta)
    e = check("eta", eta)
    shape, (zf, qf, bf, ef) = _flat(zz, q, b, e)
    out = [np.empty(zf.shape, np.complex128) for _ in range(4)]
    K.response_many(zf, qf, bf, ef, *out)
    return tuple(o.reshape(shape) for o in out)


def _dispersion_all(z, kH, gamma, f, beta, eta, Delta, xi):
    arrays = (
        check("z", z, complex_ok=True),
        check("kH", kH),
        check("gamma", gamma),
        check("f", f),
        check("beta", beta),
        check("eta", eta),
        check("Delta", Delta),
        check("xi", xi),
    )
    shape, flat = _flat(*arrays)
    fo = np.empty(flat[0].shape, np.complex128)
    dfo = np.empty_like(fo)
    sco = np.empty(flat[0].shape)
    K.dispersion_many(*flat, fo, dfo, sco)
    return fo.reshape(shape), dfo.reshape(shape), sco.reshape(shape)


def dispersion(z, kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0):
    """Dimensionless dispersion function F(z; kH) (Eq. implicit_spectrum with Eq. delta f RSF).

    F = gamma (G_x + i f G_y) + i z [1 + (Delta - 1)/(1 - i xi z kH)];  F = 0 defines the spectrum.

    Parameters broadcast against each other; gamma > 0, f real, Delta in (0, 1], xi >= 0.
    Returns a complex ndarray of the broadcast shape.
    """
    return _dispersion_all(z, kH, gamma, f, beta, eta, Delta, xi)[0]


def dispersion_derivative(z, kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0):
    """Analytic dF/dz of the dispersion function (Eq. implicit_spectrum with Eq. delta f RSF).

    dF/dz = gamma (G_x' + i f G_y') + i S + i z S',  S = 1 + (Delta-1)/(1 - i xi z kH).
    """
    return _dispersion_all(z, kH, gamma, f, beta, eta, Delta, xi)[1]


def dispersion_scale(z, kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0):
    """Sum of magnitudes of the terms of F: |F|/scale is the relative residual of a root."""
    return _dispersion_all(z, kH, gamma, f, beta, eta, Delta, xi)[2]


def root_error_estimate(z, kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0):
    """(residual, error) of approximate roots z of F(z; kH) = 0 (Eq. implicit_spectrum with Eq. delta f RSF).

    residual = |F(z)| / scale (scale: :func:`dispersion_scale`, the sum of the magnitudes of F's terms), and
    error = (|F(z)| + eps scale) / |F'(z)|: the first-order distance to the exact root, i.e. the Newton
    correction plus the shift that rounding errors of F cause. Broadcasts like :func:`dispersion`.
    """
    fv, dfv, sc = _dispersion_all(z, kH, gamma, f, beta, eta, Delta, xi)
    a = np.abs(fv)
    with np.errstate(divide="ignore", invalid="ignore"):
        return a / sc, (a + np.finfo(float).eps * sc) / np.abs(dfv)
