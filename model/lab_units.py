"""Conversions between laboratory quantities (SI units) and the dimensionless groups of the paper
(docs/physics.md §12 for the definitions and assumptions, §1 for the notation), and material presets.

Notation of the paper (Sect. IV B, Eq. rsf_phi and the equation defining Delta and xi):

- direct effect       ``direct_effect``       = partial_v f(v, phi)         [s/m]  (the paper's \\partial_v f)
- steady-state slope  ``steady_state_effect`` = d f(v, phi_0(v)) / d v      [s/m]  (the paper's d_v f)
- gamma = mu / (sigma0 c_s partial_v f)     (Sect. IV A with f'(v); Sect. IV B: "partial_v f replaces f'(v)")
- Delta = d_v f / partial_v f, xi = D c_s / (H v |g'(1)|), with the state law phi' = g(v phi / D)
- eta = H2 / H1, H1 = H = the height of the upper block (the H of kH), H2 = the lower block (inf: half-space)

All functions take keyword-only arguments that broadcast (NumPy in, NumPy out) and raise ValueError naming the
parameter and its valid range for bad input. :func:`dimensionless_parameters` turns a whole lab setting into the
keyword arguments of :func:`spectrum`; :func:`rate_state_parameters` goes the other way.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from types import MappingProxyType

import numpy as np
from scipy.optimize import minimize_scalar

from ._validate import BETA_MAX, check, check_plane
from .elastic import poisson_ratio, shear_modulus, wave_speed_ratio
from .spectrum import spectrum

MATERIALS_FILE = Path(__file__).resolve().parent / "materials.json"

# c_d / c_s bounds for a Poisson ratio in (-1, 0.5) (plane strain, i.e. bulk speeds) and for nu >= 0
_CD_OVER_CS_MIN_ANY = 2.0 / math.sqrt(3.0)
_CD_OVER_CS_MIN_MODEL = math.sqrt(2.0)


def _numeric_allow_nan(name: str, value) -> np.ndarray:
    """`value` as a complex array; NaN passes through (masked spectrum points), everything else must be finite."""
    try:
        arr = np.asarray(value)
        if arr.dtype.kind not in "biufc":
            raise TypeError
        arr = arr.astype(np.complex128)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numeric (complex c/c_s; NaN allowed); got {value!r}") from None
    nan = np.isnan(arr.real) | np.isnan(arr.imag)
    if np.any(~nan & ~np.isfinite(arr)):
        raise ValueError(f"{name} must be finite or NaN; got inf")
    if np.any(nan):  # complex(nan) has imaginary part 0: a masked point must not read as "not growing"
        arr = np.where(nan, complex(np.nan, np.nan), arr)
    return arr


# --- elastic wave speeds (docs/physics.md §1; reuses model/elastic.py) ---------------------------------------


def _first_bad(bad: np.ndarray, *arrays: np.ndarray) -> list[float]:
    """The values of `arrays` (broadcast to bad's shape) at the first element where `bad` holds (for messages)."""
    i = np.unravel_index(np.argmax(bad), bad.shape)
    return [float(np.broadcast_to(a, bad.shape)[i]) for a in arrays]


def poisson_ratio_from_speeds(*, c_s, c_d, plane: str = "strain") -> np.ndarray:
    """Poisson ratio nu from the shear and dilatational wave speeds c_s, c_d [m/s] (docs/physics.md §12).

    plane = "strain": c_d is the bulk (3-D, plane-strain) P-wave speed, nu = (1 - 2 beta^2) / (2 (1 - beta^2));
    plane = "stress": c_d is the thin-plate speed sqrt(E / (rho (1 - nu^2))), nu = 1 - 2 beta^2 (beta = c_s/c_d).
    nu in (-1, 0.5) needs c_d > (2/sqrt(3)) c_s (strain) or c_s < c_d < 2 c_s (stress).
    """
    cs = check("c_s", c_s)
    cd = check("c_d", c_d)
    if check_plane(plane) == "strain":
        bad, text = cd <= _CD_OVER_CS_MIN_ANY * cs, "c_d > (2/sqrt(3)) c_s"
    else:
        bad, text = (cd <= cs) | (cd >= 2.0 * cs), "c_s < c_d < 2 c_s"
    if np.any(bad):
        got_cs, got_cd = _first_bad(bad, cs, cd)
        raise ValueError(
            f"c_d must satisfy {text} for plane {plane} (Poisson ratio nu in (-1, 0.5)); got c_d = {got_cd!r}, "
            f"c_s = {got_cs!r}"
        )
    return poisson_ratio(cs / cd, plane=plane)


def dilatational_wave_speed(*, c_s, nu, plane: str = "strain") -> np.ndarray:
    """Dilatational wave speed c_d = c_s / beta(nu) [m/s] (the inverse of :func:`poisson_ratio_from_speeds`).

    plane = "strain" gives the bulk P-wave speed c_s sqrt(2 (1 - nu) / (1 - 2 nu)); plane = "stress" the
    thin-plate speed c_s sqrt(2 / (1 - nu)) (Supplement Sect. S-V A computes PMMA's 2333 m/s this way).
    """
    cs = check("c_s", c_s)
    return cs / wave_speed_ratio(nu, plane=plane)


def shear_wave_speed(*, mu, rho) -> np.ndarray:
    """Shear wave speed c_s = sqrt(mu / rho) [m/s] (inverse of :func:`shear_modulus`)."""
    return np.sqrt(check("mu", mu) / check("rho", rho))


def wave_speed_ratio_from_speeds(*, c_s, c_d, plane: str = "strain") -> np.ndarray:
    """beta = c_s / c_d of the 2-D model, from the bulk (plane-strain) speeds c_s and c_d [m/s].

    plane = "strain": beta = c_s / c_d. plane = "stress": the thin-plate ratio sqrt((1 - nu) / 2) with nu from
    the bulk speeds (docs/physics.md §12). The spectrum functions need beta <= 1/sqrt(2), i.e. nu >= 0, i.e.
    c_d >= sqrt(2) c_s: ValueError naming c_d otherwise.
    """
    cs = check("c_s", c_s)
    cd = check("c_d", c_d)
    # a few ulps of slack so that c_d = sqrt(2) c_s, rounded, is still nu = 0 (beta clipped to 1/sqrt(2) below)
    bad = cd < _CD_OVER_CS_MIN_MODEL * cs * (1.0 - 1e-15)
    if np.any(bad):
        got_cs, got_cd = _first_bad(bad, cs, cd)
        raise ValueError(
            "c_d must be >= sqrt(2) c_s (Poisson ratio nu >= 0, beta = c_s/c_d <= 1/sqrt(2), the model's range); "
            f"got c_d = {got_cd!r}, c_s = {got_cs!r}"
        )
    if check_plane(plane) == "strain":
        return np.minimum(cs / cd, BETA_MAX)
    return wave_speed_ratio(poisson_ratio_from_speeds(c_s=cs, c_d=cd, plane="strain"), plane="stress")


# --- gamma, eta, Delta, xi (Sect. IV; docs/physics.md §1, §12) -----------------------------------------------


def gamma_from_lab(*, mu, sigma0, c_s, direct_effect) -> np.ndarray:
    """gamma = mu / (sigma0 c_s partial_v f) (Sect. IV A, Fig. 4 caption; Sect. IV B: partial_v f replaces f'(v)).

    mu [Pa] shear modulus, sigma0 [Pa] normal stress, c_s [m/s], direct_effect = partial_v f [s/m], the
    instantaneous response of the friction coefficient to a velocity jump.
    """
    m, s0, cs, de = check("mu", mu), check("sigma0", sigma0), check("c_s", c_s), check("direct_effect", direct_effect)
    return m / (s0 * cs * de)


def direct_effect_from_gamma(*, gamma, mu, sigma0, c_s) -> np.ndarray:
    """partial_v f = mu / (sigma0 c_s gamma) [s/m], the inverse of :func:`gamma_from_lab`."""
    g, m, s0, cs = check("gamma", gamma), check("mu", mu), check("sigma0", sigma0), check("c_s", c_s)
    return m / (s0 * cs * g)


def eta_from_heights(*, H1, H2) -> np.ndarray:
    """eta = H2 / H1 (Sect. IV: H2 = eta H1); H1 [m] upper block (the H of kH), H2 [m] lower block, inf = half-space."""
    return check("H2", H2) / check("H1", H1)


def lower_height_from_eta(*, eta, H1) -> np.ndarray:
    """H2 = eta H1 [m] (inf for eta = inf), the inverse of :func:`eta_from_heights`."""
    return check("eta", eta) * check("H1", H1)


def Delta_from_lab(*, steady_state_effect, direct_effect) -> np.ndarray:
    """Delta = d_v f / partial_v f (Sect. IV B, the equation defining Delta and xi); both slopes in s/m.

    The stability model covers 0 < Delta <= 1 (steady-state velocity strengthening no stronger than the direct
    effect): ValueError naming steady_state_effect otherwise.
    """
    sse = check("steady_state_effect", steady_state_effect)
    de = check("direct_effect", direct_effect)
    d = sse / de
    bad = d > 1.0
    if np.any(bad):
        raise ValueError(
            "steady_state_effect must be in (0, direct_effect] (Delta = d_v f / partial_v f in (0, 1]); "
            f"got steady_state_effect/direct_effect = {float(d[bad].ravel()[0])!r}"
        )
    return d


def steady_state_effect_from_Delta(*, Delta, direct_effect) -> np.ndarray:
    """d_v f = Delta partial_v f [s/m], the inverse of :func:`Delta_from_lab`."""
    return check("Delta", Delta) * check("direct_effect", direct_effect)


def xi_from_lab(*, D, c_s, H1, v, abs_g_prime=1.0) -> np.ndarray:
    """xi = D c_s / (H v |g'(1)|) (Sect. IV B, with Eq. rsf_phi: phi' = g(v phi / D)).

    D [m] memory length, c_s [m/s], H1 = H [m] upper block height, v [m/s] steady sliding velocity,
    abs_g_prime = |g'(1)| (1 for the aging and the slip law, see :func:`xi_from_rate_state`).
    """
    d, cs, h = check("D", D), check("c_s", c_s), check("H1", H1)
    vv, gp = check("v", v, domain="v_slip"), check("abs_g_prime", abs_g_prime)
    return d * cs / (h * vv * gp)


def memory_length_from_xi(*, xi, c_s, H1, v, abs_g_prime=1.0) -> np.ndarray:
    """D = xi H v |g'(1)| / c_s [m], the inverse of :func:`xi_from_lab`."""
    x, cs, h = check("xi", xi), check("c_s", c_s), check("H1", H1)
    vv, gp = check("v", v, domain="v_slip"), check("abs_g_prime", abs_g_prime)
    return x * h * vv * gp / cs


# --- Dieterich-Ruina rate-and-state friction (an ASSUMPTION; docs/physics.md §12) ----------------------------
#
# f(v, theta) = f0 + a ln(v/v*) + b ln(v* theta / D_c), with the aging law theta' = 1 - v theta / D_c
# (g(x) = 1 - x) or the slip law theta' = -(v theta / D_c) ln(v theta / D_c) (g(x) = -x ln x). theta plays the
# paper's phi (a time), both laws have g(1) = 0, g'(1) = -1, so D = D_c and the two give the same linear
# stability. Then partial_v f = a/v and, at steady state theta = D_c/v, d_v f = (a - b)/v: Delta = 1 - b/a.


def _check_rsf(a, b) -> tuple[np.ndarray, np.ndarray]:
    aa = check("a", a, domain="rsf_a")
    bb = check("b", b, domain="rsf_b")
    bad = bb >= aa
    if np.any(bad):
        got_a, got_b = _first_bad(bad, aa, bb)
        raise ValueError(
            "rate-and-state parameters must satisfy 0 <= b < a (steady-state velocity strengthening, "
            f"Delta = 1 - b/a in (0, 1]); got a = {got_a!r}, b = {got_b!r}"
        )
    return aa, bb


def direct_effect_from_rate_state(*, a, v) -> np.ndarray:
    """partial_v f = a / v [s/m] for Dieterich-Ruina friction (assumption, docs/physics.md §12)."""
    return check("a", a, domain="rsf_a") / check("v", v, domain="v_slip")


def steady_state_effect_from_rate_state(*, a, b, v) -> np.ndarray:
    """d_v f = (a - b) / v [s/m] for Dieterich-Ruina friction; needs 0 <= b < a (docs/physics.md §12)."""
    aa, bb = _check_rsf(a, b)
    return (aa - bb) / check("v", v, domain="v_slip")


def Delta_from_rate_state(*, a, b) -> np.ndarray:
    """Delta = d_v f / partial_v f = (a - b) / a = 1 - b/a for Dieterich-Ruina friction.

    The paper's analysis needs 0 < Delta <= 1, i.e. 0 <= b < a: ValueError naming a and b otherwise.
    """
    aa, bb = _check_rsf(a, b)
    return (aa - bb) / aa


def b_from_Delta(*, Delta, a) -> np.ndarray:
    """b = a (1 - Delta), the inverse of :func:`Delta_from_rate_state`."""
    return check("a", a, domain="rsf_a") * (1.0 - check("Delta", Delta))


def xi_from_rate_state(*, D_c, c_s, H1, v) -> np.ndarray:
    """xi = D_c c_s / (H v): :func:`xi_from_lab` with D = D_c and |g'(1)| = 1 (aging or slip law, §12)."""
    return xi_from_lab(D=check("D_c", D_c, domain="D"), c_s=c_s, H1=H1, v=v, abs_g_prime=1.0)


# --- spectrum results in lab units (docs/physics.md §12) -----------------------------------------------------


def wavelength(*, kH, H1) -> np.ndarray:
    """lambda = 2 pi H / (kH) [m] of the mode with dimensionless wavenumber kH (H = H1, the upper block)."""
    return 2.0 * np.pi * check("H1", H1) / check("kH", kH)


def kH_from_wavelength(*, wavelength, H1) -> np.ndarray:
    """kH = 2 pi H / lambda, the inverse of :func:`wavelength`."""
    return 2.0 * np.pi * check("H1", H1) / check("wavelength", wavelength)


def growth_rate(*, kH, z, H1, c_s) -> np.ndarray:
    """Growth rate k Im(c) = kH Im(c/c_s) c_s / H [1/s] of a mode exp(i k (x - c t)) (Eq. implicit_spectrum).

    z = c/c_s as returned by :func:`spectrum` (NaN where masked: NaN out); negative = decaying mode.
    """
    zz = _numeric_allow_nan("z", z)
    return check("kH", kH) * zz.imag * check("c_s", c_s) / check("H1", H1)


def im_z_from_growth_rate(*, growth_rate, kH, H1, c_s) -> np.ndarray:
    """Im(c/c_s) = rate H / (kH c_s), the inverse of :func:`growth_rate`."""
    r = check("growth_rate", growth_rate)
    return r * check("H1", H1) / (check("kH", kH) * check("c_s", c_s))


def e_folding_time(*, kH, z, H1, c_s) -> np.ndarray:
    """Time [s] over which a growing mode's amplitude grows by a factor e: 1 / :func:`growth_rate`.

    inf where the mode does not grow (Im z <= 0: it never e-folds up); NaN where z is NaN (masked point).
    """
    rate = growth_rate(kH=kH, z=z, H1=H1, c_s=c_s)
    out = np.full(rate.shape, np.inf)
    grows = rate > 0.0
    np.divide(1.0, rate, out=out, where=grows)
    out[np.isnan(rate)] = np.nan
    return out


def im_z_from_e_folding_time(*, e_folding_time, kH, H1, c_s) -> np.ndarray:
    """Im(c/c_s) = H / (kH c_s t_e) (0 for t_e = inf), the inverse of :func:`e_folding_time` for growing modes."""
    t = check("e_folding_time", e_folding_time)
    return check("H1", H1) / (check("kH", kH) * check("c_s", c_s) * t)


def phase_speed(*, z, c_s) -> np.ndarray:
    """Phase speed Re(c) = Re(c/c_s) c_s [m/s] (NaN where z is NaN)."""
    return _numeric_allow_nan("z", z).real * check("c_s", c_s)


def re_z_from_phase_speed(*, phase_speed, c_s) -> np.ndarray:
    """Re(c/c_s) = phase speed / c_s, the inverse of :func:`phase_speed`."""
    return check("phase_speed", phase_speed) / check("c_s", c_s)


def spectrum_in_lab_units(*, kH, z, H1, c_s) -> dict[str, np.ndarray]:
    """A spectrum z(kH) in lab units: wavelength [m], growth_rate [1/s], e_folding_time [s], phase_speed [m/s]."""
    return {
        "wavelength": np.broadcast_to(wavelength(kH=kH, H1=H1), np.broadcast_shapes(np.shape(kH), np.shape(z))),
        "growth_rate": growth_rate(kH=kH, z=z, H1=H1, c_s=c_s),
        "e_folding_time": e_folding_time(kH=kH, z=z, H1=H1, c_s=c_s),
        "phase_speed": phase_speed(z=z, c_s=c_s),
    }


def fastest_growing_mode(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0) -> tuple[float, complex]:
    """(kH*, z*): the Rayleigh-branch mode whose amplitude grows fastest in time (docs/physics.md §12.5).

    The growth rate of a mode is k Im c = (kH Im z) c_s / H (:func:`growth_rate`), so for every H and c_s it
    peaks where kH Im z does: this is that maximum, which lies at a larger kH than the maximum of Im z alone
    (:func:`growth_analysis`). kH is an increasing grid of at least 3 points (> 0); the largest
    kH Im z on it is refined between its two neighbours (bounded Brent in ln kH, single-kH
    :func:`spectrum` calls, to ~1e-10 in ln kH). Where the maximum is at an end of the grid, or a
    neighbour is masked, the grid point is returned unrefined (the true maximum may lie beyond the grid). A
    stable setting gives the least-damped point (kH* Im z* <= 0); (nan, nan) if the branch is masked on the
    whole grid. The physical parameters are scalars, with the domains of :func:`spectrum`.
    """
    q = check("kH", kH)
    if q.ndim != 1 or q.size < 3 or np.any(np.diff(q) <= 0.0):
        raise ValueError(f"kH must be an increasing 1-D grid of at least 3 points; got shape {q.shape}")
    p = {"gamma": gamma, "f": f, "beta": beta, "eta": eta, "Delta": Delta, "xi": xi}
    for name, value in p.items():
        if np.ndim(value) != 0:
            raise ValueError(f"{name} must be a scalar for fastest_growing_mode; got shape {np.shape(value)}")
    z = spectrum(q, **p)
    rate = q * z.imag
    if not np.isfinite(rate).any():
        return math.nan, complex(math.nan, math.nan)
    i = int(np.nanargmax(rate))
    best_k, best_z = float(q[i]), complex(z[i])
    if 0 < i < q.size - 1 and np.isfinite(rate[i - 1]) and np.isfinite(rate[i + 1]):

        def minus_rate(t: float) -> float:
            k = math.exp(t)
            r = k * float(spectrum(np.array([k]), **p)[0].imag)
            return -r if math.isfinite(r) else math.inf

        res = minimize_scalar(minus_rate, bounds=(math.log(q[i - 1]), math.log(q[i + 1])), method="bounded",
                              options={"xatol": 1e-10})
        if math.isfinite(res.fun) and -res.fun >= rate[i]:
            best_k = math.exp(res.x)
            best_z = complex(spectrum(np.array([best_k]), **p)[0])
    return best_k, best_z


# --- a whole lab setting <-> the model's keyword arguments ---------------------------------------------------


def dimensionless_parameters(
    *, rho, c_s, c_d, sigma0, f, H1, H2, v, a, b, D_c, plane: str = "strain"
) -> dict[str, np.ndarray]:
    """The model parameters gamma, f, beta, eta, Delta, xi of a lab setting, ready for ``model.spectrum(kH, **p)``.

    rho [kg/m^3], c_s and c_d [m/s] (bulk speeds, e.g. ``material(name).elastic_constants()``), sigma0 [Pa]
    normal stress, f the steady friction coefficient at v, H1 / H2 [m] upper / lower block heights (H2 = inf for
    a half-space), v [m/s] steady sliding velocity, a, b, D_c [m] Dieterich-Ruina parameters (the aging or slip
    law; an assumption, docs/physics.md §12). plane = "strain" (the paper's Sect. IV) or "stress" (thin plates:
    beta from nu). mu = rho c_s^2. Arguments broadcast; each value is a float ndarray (0-d for scalar input).
    """
    mu = shear_modulus(rho, c_s)
    de = direct_effect_from_rate_state(a=a, v=v)
    out = {
        "gamma": gamma_from_lab(mu=mu, sigma0=sigma0, c_s=c_s, direct_effect=de),
        "f": check("f", f),
        "beta": wave_speed_ratio_from_speeds(c_s=c_s, c_d=c_d, plane=plane),
        "eta": eta_from_heights(H1=H1, H2=H2),
        "Delta": Delta_from_rate_state(a=a, b=b),
        "xi": xi_from_rate_state(D_c=D_c, c_s=c_s, H1=H1, v=v),
    }
    return {k: np.asarray(v, dtype=np.float64) for k, v in out.items()}


def rate_state_parameters(*, gamma, Delta, xi, eta, rho, c_s, sigma0, H1, v) -> dict[str, np.ndarray]:
    """The lab values a, b, D_c [m] and H2 [m] that give gamma, Delta, xi, eta for a material, sigma0, H1 and v.

    The inverse of :func:`dimensionless_parameters` for the friction and geometry (beta is fixed by the
    material, f passes through): a = v mu / (sigma0 c_s gamma), b = a (1 - Delta), D_c = xi H1 v / c_s,
    H2 = eta H1, with mu = rho c_s^2 and Dieterich-Ruina friction (docs/physics.md §12). Values: float ndarrays.
    """
    mu = shear_modulus(rho, c_s)
    vv = check("v", v, domain="v_slip")
    a = vv * direct_effect_from_gamma(gamma=gamma, mu=mu, sigma0=sigma0, c_s=c_s)
    out = {
        "a": a,
        "b": b_from_Delta(Delta=Delta, a=a),
        "D_c": memory_length_from_xi(xi=xi, c_s=c_s, H1=H1, v=vv),
        "H2": lower_height_from_eta(eta=eta, H1=H1),
    }
    return {k: np.asarray(v, dtype=np.float64) for k, v in out.items()}


# --- material presets (data: model/materials.json) -----------------------------------------------------------


@dataclass(frozen=True)
class Material:
    """An isotropic lab material: density and bulk wave speeds, each with its source (model/materials.json).

    c_d is the bulk (3-D, plane-strain) dilatational speed. Derived: mu = rho c_s^2, nu, beta, plane-stress c_d.
    ``reported`` holds further values quoted by the sources (e.g. PMMA's plane-stress c_d), for comparison.
    """

    name: str
    description: str
    rho: float
    c_s: float
    c_d: float
    rho_source: str
    c_s_source: str
    c_d_source: str
    assumptions: tuple[str, ...] = ()
    reported: MappingProxyType = field(default_factory=lambda: MappingProxyType({}), hash=False, compare=False)

    @property
    def mu(self) -> float:
        """Shear modulus rho c_s^2 [Pa]."""
        return float(shear_modulus(self.rho, self.c_s))

    @property
    def nu(self) -> float:
        """Poisson ratio from the bulk speeds (plane-strain relation)."""
        return float(poisson_ratio_from_speeds(c_s=self.c_s, c_d=self.c_d, plane="strain"))

    @property
    def c_d_plane_stress(self) -> float:
        """Thin-plate dilatational speed c_s sqrt(2 / (1 - nu)) [m/s]."""
        return float(dilatational_wave_speed(c_s=self.c_s, nu=self.nu, plane="stress"))

    def beta(self, plane: str = "strain") -> float:
        """beta = c_s / c_d of the 2-D model for plane strain or plane stress."""
        return float(wave_speed_ratio_from_speeds(c_s=self.c_s, c_d=self.c_d, plane=plane))

    def elastic_constants(self) -> dict[str, float]:
        """rho, c_s, c_d as keyword arguments for :func:`dimensionless_parameters`."""
        return {"rho": self.rho, "c_s": self.c_s, "c_d": self.c_d}


def _entry_value(entry: dict, key: str, name: str) -> tuple[float, str, bool]:
    item = entry[key]
    value, source = float(item["value"]), str(item["source"]).strip()
    if not source:
        raise ValueError(f"{MATERIALS_FILE.name}: {name}.{key} has no source")
    return value, source, bool(item.get("assumption", False))


def _material_from_entry(entry: dict) -> Material:
    name = str(entry["name"])
    rho, rho_src, rho_ass = _entry_value(entry, "rho", name)
    c_s, c_s_src, c_s_ass = _entry_value(entry, "c_s", name)
    c_d, c_d_src, c_d_ass = _entry_value(entry, "c_d", name)
    check("rho", rho)
    poisson_ratio_from_speeds(c_s=c_s, c_d=c_d)  # a file entry must be a physical isotropic solid
    reported = {k: float(v["value"]) for k, v in entry.get("reported", {}).items()}
    assumptions = tuple(k for k, flag in (("rho", rho_ass), ("c_s", c_s_ass), ("c_d", c_d_ass)) if flag)
    return Material(
        name=name,
        description=str(entry.get("description", "")),
        rho=rho,
        c_s=c_s,
        c_d=c_d,
        rho_source=rho_src,
        c_s_source=c_s_src,
        c_d_source=c_d_src,
        assumptions=assumptions,
        reported=MappingProxyType(reported),
    )


@lru_cache(maxsize=1)
def _materials() -> dict[str, Material]:
    data = json.loads(MATERIALS_FILE.read_text(encoding="utf-8"))
    out: dict[str, Material] = {}
    for entry in data["materials"]:
        m = _material_from_entry(entry)
        out[m.name] = m
    return out


def material_names() -> tuple[str, ...]:
    """Names of the material presets, in file order."""
    return tuple(_materials())


def material(name: str) -> Material:
    """The material preset called `name` (case-insensitive); ValueError listing the known names otherwise."""
    table = _materials()
    if isinstance(name, str):
        if name in table:
            return table[name]
        for key, m in table.items():
            if key.casefold() == name.strip().casefold():
                return m
    raise ValueError(f"material must be one of {list(table)}; got {name!r}")
