"""The Spectrum's sliding computation in pieces that a worker process can run (app.spectrum.compute_sliding).

Pure functions of plain values (a dict of model keywords, a tuple of kH) returning dicts of numbers and arrays:
they pickle, and importing this module imports only NumPy and :mod:`model` (not Panel), so a spawned worker
starts in about a second. No physics here: each is one call of the public model API per point.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from asymslide import model


def sliding_maximum(p: Mapping[str, float]) -> dict:
    """Sliding over every branch at the model keywords `p`: the maximum over kH with the Rayleigh branch's beside it
    (:func:`model.sliding_analysis`)."""
    r = model.sliding_analysis(**p)
    return {"floor": float(r.floor), "max": float(r.growth), "kH_at_max": float(r.kH_at_max),
            "z_at_max": complex(r.z_at_max), "family_at_max": int(r.family), "verdict": int(r.verdict),
            "reason": int(r.verdict_reason), "at_end": bool(r.max_at_end), "lower_bound": bool(r.lower_bound),
            "range": tuple(float(x) for x in r.kH_range), "rayleigh_max": float(r.rayleigh.growth),
            "rayleigh_verdict": int(r.rayleigh.verdict)}


def fastest_roots(p: Mapping[str, float], kH: Sequence[float]) -> dict[str, np.ndarray]:
    """The fastest root of every branch at each of `kH` (:func:`model.fastest_mode`): growth, z, family and status
    (NaN / -1 where the status is not 0, certified)."""
    n = len(kH)
    out = {"growth": np.full(n, np.nan), "z": np.full(n, complex(np.nan, np.nan)),
           "family": np.full(n, -1, np.int8), "status": np.full(n, -1, np.int8)}
    for i, k in enumerate(kH):
        m = model.fastest_mode(float(k), **p, count=False)
        out["status"][i] = int(m.status)
        if int(m.status) == 0:
            out["growth"][i], out["z"][i], out["family"][i] = float(m.growth), complex(m.z), int(m.family)
    return out


def sliding_gamma_crossings(x_name: str, x: Sequence[float], fixed: Sequence[tuple[str, float]], floor: float,
                            gamma_range: tuple[float, float], max_crossings: int) -> dict[str, np.ndarray]:
    """Every crossing in γ (within `gamma_range`) of the max growth over every branch at the x values `x` of the
    parameter `x_name`, the others `fixed`, the growth floor `floor`, at most `max_crossings` per x
    (:func:`model.critical_gammas` with branches="all": app.sliding_boundary)."""
    args = {**dict(fixed), x_name: np.asarray(x, float)}
    c = model.critical_gammas(**args, gamma_range=gamma_range, branches="all", floor=floor,
                              max_crossings=max_crossings, workers=1)
    return {"value": np.asarray(c.value, float), "location": np.asarray(c.location, float),
            "direction": np.asarray(c.direction, np.int8), "reason": np.asarray(c.reason, np.int8),
            "kH": np.asarray(c.kH, float), "z": np.real(np.asarray(c.z)).astype(float),
            "count": np.asarray(c.count, int)}
