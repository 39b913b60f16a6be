"""The Rayleigh branch of the stability spectrum and its linear expansion (docs/physics.md §3-§4)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _kernels as K
from ._validate import check, check_rtol
from .elastodynamics import response_derivatives, response_functions
from .rayleigh import rayleigh_speed

#: Reasons for masked (NaN) points, the codes of ``status`` of a :class:`SpectrumResult`.
STATUS = {
    K.OK: "ok",
    K.LOST: "branch lost: the Rayleigh branch could not be followed down to this kH "
    "(collision with another branch or ill-conditioned root)",
    K.NOCONV: "Newton did not converge to the continued root at this kH",
    K.START: "no Rayleigh-branch root found at kH = 1e4",
    K.INPUT: "invalid parameters",
}


@dataclass(frozen=True)
class SpectrumResult:
    """Rayleigh-branch roots with diagnostics.

    Attributes
    ----------
    z : complex ndarray, c/c_s; NaN where masked.
    status : int8 ndarray, 0 where valid, else a key of :data:`STATUS` giving the reason.
    residual : float ndarray, |F(z)| / (sum of magnitudes of the terms of F) at the returned root (NaN
        where a looser `rtol` returned the path interpolant without evaluating F).
    error : float ndarray, estimated absolute error of z (rounding-level condition estimate plus the
        size of the last Newton correction squared, or the interpolant's truncation estimate).
    """

    z: np.ndarray
    status: np.ndarray
    residual: np.ndarray
    error: np.ndarray

    @property
    def mask(self) -> np.ndarray:
        """True where the point is masked (NaN)."""
        return self.status != K.OK

    def reasons(self) -> dict[str, int]:
        """Count of masked points per reason."""
        out: dict[str, int] = {}
        for code, text in STATUS.items():
            n = int(np.count_nonzero(self.status == code))
            if code != K.OK and n:
                out[text] = n
        return out


def _check_spectrum_args(kH, gamma, f, beta, eta, Delta, xi):
    q = check("kH", kH)
    params = [
        check("gamma", gamma),
        check("f", f),
        check("beta", beta),
        check("eta", eta),
        check("Delta", Delta),
        check("xi", xi),
    ]
    return q, params


def rayleigh_branch(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0,
                    rtol: float | None = None) -> SpectrumResult:
    """Rayleigh-branch roots z = c/c_s of F(z; kH) = 0 with diagnostics (Eq. implicit_spectrum).

    The branch is defined as in docs/physics.md §3: at kH = 1e4 the root continued from z_R
    (homotopy in 1/gamma from gamma = inf, where it is the Rayleigh root of the large-kH response),
    then continued in ln kH downward (and upward for kH > 1e4) by an adaptive predictor-corrector path
    whose nodes depend only on the physical parameters. Every requested kH is reached by Newton's
    method from the Hermite interpolant of the surrounding path nodes (values and analytic slopes
    dz/d ln kH = -kH F_kH / F_z), so one kH alone gives the same digits as a dense grid. Where the path
    cannot be continued safely (step size underflow: a collision with another branch), or Newton fails,
    the point is NaN and `status` says why: never a root of another branch.

    rtol : None (default) for full accuracy, every root certified to ~1e-15 relative; or the requested
        relative accuracy in [1e-15, 1e-3]. Looser settings are faster: points whose interpolant is
        estimated accurate to 0.1 rtol are returned without evaluating F (their `residual` is NaN, their
        `error` the truncation estimate); the others take Newton steps until the certified error is
        below 0.1 rtol. From rtol = 1e-7 on, the path nodes are sparser. The branch (its nodes, and so
        which root is followed) is certified in the same way at every setting.

    Shapes: parameters broadcast against each other; result shape = broadcast shape + kH.shape.
    """
    tol = check_rtol(rtol)
    q, params = _check_spectrum_args(kH, gamma, f, beta, eta, Delta, xi)
    s = np.ascontiguousarray(np.log(q).ravel())
    if all(p.ndim == 0 for p in params):  # common case: one parameter set, passed as scalars
        out = (np.empty(s.size, np.complex128), np.empty(s.size, np.int8), np.empty(s.size), np.empty(s.size))
        K.branch_one(s, *(float(p) for p in params), tol, *out)
        return SpectrumResult(*(o.reshape(q.shape) for o in out))
    pshape = np.broadcast_shapes(*(p.shape for p in params))
    flat = [np.array(np.broadcast_to(p, pshape), order="C").ravel() for p in params]
    n = flat[0].size
    z = np.empty((n, s.size), np.complex128)
    status = np.empty((n, s.size), np.int8)
    resid = np.empty((n, s.size))
    err = np.empty((n, s.size))
    K.branch_many(s, *flat, tol, z, status, resid, err)
    shape = pshape + q.shape
    return SpectrumResult(z.reshape(shape), status.reshape(shape), resid.reshape(shape), err.reshape(shape))


def spectrum(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, rtol: float | None = None) -> np.ndarray:
    """Complex c/c_s on the Rayleigh branch of Eq. implicit_spectrum (with Eq. delta f RSF, Eq. Gs_general).

    Im z > 0 means the mode with wavenumber k grows. Accurate to ~1e-15 relative where defined (or to
    the requested `rtol`, see :func:`rayleigh_branch`); NaN where the branch cannot be followed
    unambiguously (use :func:`rayleigh_branch` for the reason, the residual and the error estimate of
    each point).

    Parameters
    ----------
    kH : array_like, > 0 (the last axes of the result)
    gamma, f, beta, eta, Delta, xi : array_like, broadcast against each other
        gamma > 0, f real, beta in (0, 1/sqrt(2)], eta in (0, inf], Delta in (0, 1], xi >= 0.
    rtol : None (full certified accuracy, the default) or the requested relative accuracy in [1e-15, 1e-3]

    Returns
    -------
    complex ndarray of shape broadcast(gamma, f, beta, eta, Delta, xi).shape + kH.shape
    """
    return rayleigh_branch(kH, gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi, rtol=rtol).z


def linear_expansion(kH, *, gamma, f, beta, eta=math.inf):
    """z_R + delta z, the linear expansion of the spectrum about the Rayleigh speed (Eq. S-dz, Delta = 1).

    delta z = -[z_R - i gamma (G_x + i f G_y)] / [1 - i gamma (G_x' + i f G_y')], all at z = z_R.
    Broadcasting as in :func:`spectrum`: result shape = broadcast(gamma, f, beta, eta).shape + kH.shape.
    """
    q = check("kH", kH)
    g, ff, b, e = check("gamma", gamma), check("f", f), check("beta", beta), check("eta", eta)
    pshape = np.broadcast_shapes(g.shape, ff.shape, b.shape, e.shape)
    ex = (Ellipsis,) + (None,) * q.ndim
    g, ff, b, e = (np.broadcast_to(x, pshape)[ex] for x in (g, ff, b, e))
    zr = rayleigh_speed(b).astype(np.complex128)
    gx, gy = response_functions(zr, q, beta=b, eta=e)
    dgx, dgy = response_derivatives(zr, q, beta=b, eta=e)
    dz = -(zr - 1j * g * (gx + 1j * ff * gy)) / (1.0 - 1j * g * (dgx + 1j * ff * dgy))
    return zr + dz
