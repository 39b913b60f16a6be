"""Input validation shared by the public functions: clear ValueErrors naming parameter and range."""

from __future__ import annotations

import math

import numpy as np

BETA_MAX = 1.0 / math.sqrt(2.0)

# name -> (low, high, low_inclusive, high_inclusive, allow_inf, human readable range)
DOMAINS: dict[str, tuple[float, float, bool, bool, bool, str]] = {
    "beta": (0.0, BETA_MAX + 2e-16, False, True, False, "(0, 1/sqrt(2)]"),
    "nu": (0.0, 0.5, True, False, False, "[0, 0.5)"),
    "nu_any": (-1.0, 0.5, False, False, False, "(-1, 0.5)"),
    "beta_any": (0.0, 1.0, False, False, False, "(0, 1)"),
    "rho": (0.0, math.inf, False, False, False, "(0, inf)"),
    "kH": (0.0, math.inf, False, False, False, "(0, inf)"),
    "kW": (0.0, math.inf, False, False, False, "(0, inf)"),
    "eta": (0.0, math.inf, False, True, True, "(0, inf] (math.inf = half-space)"),
    "Delta": (0.0, 1.0, False, True, False, "(0, 1]"),
    "xi": (0.0, math.inf, True, False, False, "[0, inf)"),
    "gamma": (0.0, math.inf, False, False, False, "(0, inf)"),
    "f": (-math.inf, math.inf, False, False, False, "finite real"),
    "z": (-math.inf, math.inf, False, False, False, "finite complex"),
    "v": (-math.inf, math.inf, False, False, False, "finite real"),
    "mu": (0.0, math.inf, False, False, False, "(0, inf)"),
    "c": (0.0, math.inf, False, False, False, "(0, inf)"),
    "c_s": (0.0, math.inf, False, False, False, "(0, inf)"),
    # lab quantities (model/lab_units.py, docs/physics.md §12), SI units
    "c_d": (0.0, math.inf, False, False, False, "(0, inf) m/s"),
    "H1": (0.0, math.inf, False, False, False, "(0, inf) m"),
    "H2": (0.0, math.inf, False, True, True, "(0, inf] m (math.inf = half-space)"),
    "sigma0": (0.0, math.inf, False, False, False, "(0, inf) Pa"),
    "v_slip": (0.0, math.inf, False, False, False, "(0, inf) m/s"),
    "direct_effect": (0.0, math.inf, False, False, False, "(0, inf) s/m"),
    "steady_state_effect": (0.0, math.inf, False, False, False, "(0, inf) s/m"),
    "D": (0.0, math.inf, True, False, False, "[0, inf) m"),
    "abs_g_prime": (0.0, math.inf, False, False, False, "(0, inf)"),
    "rsf_a": (0.0, math.inf, False, False, False, "(0, inf)"),
    "rsf_b": (0.0, math.inf, True, False, False, "[0, inf)"),
    "wavelength": (0.0, math.inf, False, False, False, "(0, inf) m"),
    "growth_rate": (-math.inf, math.inf, False, False, False, "finite real, 1/s"),
    "e_folding_time": (0.0, math.inf, False, True, True, "(0, inf] s (inf = not growing)"),
    "phase_speed": (-math.inf, math.inf, False, False, False, "finite real, m/s"),
    # cohesive-zone model (model/rupture.py, docs/physics.md §13), SI units
    "x": (-math.inf, math.inf, False, False, False, "finite real"),
    "Gamma": (0.0, math.inf, False, False, False, "(0, inf)"),
    "X_c0": (0.0, math.inf, False, False, False, "(0, inf)"),
}


def check(name: str, value, *, complex_ok: bool = False, domain: str | None = None) -> np.ndarray:
    """Return `value` as a float (or complex) array after checking it lies in the domain of `name`.

    Raises ValueError naming the parameter and its valid range for NaN, out-of-range or
    non-numeric input (strings are never evaluated).
    """
    key = domain or name
    lo, hi, lo_inc, hi_inc, allow_inf, text = DOMAINS[key]
    if type(value) is float or type(value) is int:  # fast path for plain scalars
        v = float(value)
        if math.isfinite(v) and (lo < v < hi or (v == lo and lo_inc) or (v == hi and hi_inc)):
            return np.array(v, dtype=np.complex128 if complex_ok else np.float64)
        if v == math.inf and allow_inf:
            return np.array(v)
    if isinstance(value, np.ndarray) and value.dtype == np.float64 and not complex_ok and value.size:
        # fast path: range test of the extremes (NaN fails every comparison)
        vmin = value.min()
        vmax = value.max()
        if (lo <= vmin if lo_inc else lo < vmin) and (vmax <= hi if hi_inc else vmax < hi):
            return value
    return _checked_array(name, value, complex_ok, DOMAINS[key])


def _checked_array(name: str, value, complex_ok: bool, domain: tuple) -> np.ndarray:
    """:func:`check` past its fast paths: `value` as an array of the domain (lo, hi, lo_inc, hi_inc, allow_inf,
    text), or ValueError naming `name`, the range and the first bad value."""
    lo, hi, lo_inc, hi_inc, allow_inf, text = domain
    try:
        arr = np.asarray(value)
        if arr.dtype.kind not in "biufc":
            raise TypeError
        arr = arr.astype(np.complex128 if (complex_ok or arr.dtype.kind == "c") else np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numeric, in {text}; got {value!r}") from None
    if arr.dtype.kind == "c":
        if not complex_ok:
            raise ValueError(f"{name} must be real, in {text}; got complex values")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must be finite ({text}); got NaN or inf")
        return arr
    if np.any(np.isnan(arr)):
        raise ValueError(f"{name} must be in {text}; got NaN")
    finite = np.isfinite(arr)
    if not allow_inf and not np.all(finite):
        raise ValueError(f"{name} must be in {text}; got inf")
    bad = (arr < lo) | (arr > hi) | ((arr == lo) & (not lo_inc)) | ((arr == hi) & (not hi_inc) & finite)
    if allow_inf:
        bad &= ~(np.isposinf(arr) & (hi == math.inf))
    if np.any(bad):
        first = float(arr[bad].ravel()[0])
        raise ValueError(f"{name} must be in {text}; got {first!r}")
    return arr


RTOL_RANGE = (1e-15, 1e-3)


def check_rtol(rtol) -> float:
    """The accuracy setting `rtol` as the kernels' float: None -> 0.0 (full certified accuracy).

    Otherwise a real number in RTOL_RANGE: the requested relative accuracy of the roots. ValueError
    naming `rtol` and its range for anything else (arrays, NaN, strings, booleans, out of range).
    """
    if rtol is None:
        return 0.0
    lo, hi = RTOL_RANGE
    text = f"rtol must be None (full certified accuracy) or a number in [{lo:g}, {hi:g}]"
    if isinstance(rtol, bool) or not isinstance(rtol, int | float | np.floating | np.integer):
        raise ValueError(f"{text}; got {rtol!r}")
    v = float(rtol)
    if not (lo <= v <= hi):
        raise ValueError(f"{text}; got {rtol!r}")
    return v


def check_range(name: str, value, domain: str) -> tuple[float, float]:
    """A search interval `(lo, hi)` for the parameter `domain`, e.g. ``gamma_range`` for gamma.

    Must be two finite real numbers with lo < hi, both inside the parameter's domain (thresholds are
    searched in log space, so both must be positive). ValueError naming `name` otherwise.
    """
    text = DOMAINS[domain][5]
    msg = f"{name} must be a pair (lo, hi) of finite numbers with lo < hi, both in {domain}'s range {text}"
    if isinstance(value, str | bytes) or not hasattr(value, "__len__"):
        raise ValueError(f"{msg}; got {value!r}")
    try:
        pair = np.asarray(value)
        ok = pair.shape == (2,) and pair.dtype.kind in "iuf"
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"{msg}; got {value!r}")
    lo, hi = float(pair[0]), float(pair[1])
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"{msg}; got {value!r}")
    try:
        check(domain, np.array([lo, hi]))
    except ValueError:
        raise ValueError(f"{msg}; got {value!r}") from None
    return lo, hi


def check_kh_grid(kH) -> np.ndarray:
    """The kH grid, validated: a 1-D increasing array of at least 2 positive values."""
    q = check("kH", kH)
    if q.ndim != 1 or q.size < 2 or np.any(np.diff(q) <= 0):
        raise ValueError("kH must be a 1-D increasing grid with at least 2 points")
    return q


def check_floor(floor) -> float:
    """A growth floor, validated: a positive finite real number."""
    if isinstance(floor, (str, bytes, complex)) or np.ndim(floor) != 0:
        raise ValueError(f"floor must be a positive real number; got {floor!r}")
    try:
        v = float(floor)
    except (TypeError, ValueError):
        raise ValueError(f"floor must be a positive real number; got {floor!r}") from None
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"floor must be a positive real number; got {floor!r}")
    return v


#: the elastic states a Poisson ratio is converted under (model.elastic, model.lab_units, model.rupture)
PLANES = ("strain", "stress")


def check_plane(plane: str) -> str:
    """The plane (``"strain"`` or ``"stress"``), validated."""
    if plane not in PLANES:
        raise ValueError(f"plane must be one of {PLANES}; got {plane!r}")
    return plane
