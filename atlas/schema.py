"""The variables of an atlas, their attributes and the template dataset a store is created from.

Stability atlases: N-D sweeps of the Rayleigh branch's growth analysis, distributed with Dask, stored in Zarr.

The paper leaves the multi-dimensional stability phase diagram in (γ, f, β, η, Δ, ξ) to future work; an atlas is
that diagram on a grid. The engine only distributes: every number is computed by the model (docs/physics.md §9),

- ``growth``, ``kH_at_max``, ``kH_min``, ``kH_max``, ``n_masked``, ``verdict``, ``verdict_reason``:
  :func:`model.growth_chunk` at every grid point, bitwise what :func:`model.growth_analysis` gives at the same point
  (the continuous max growth over the kH range; the verdict 0 stable / 1 unstable / 2 undetermined and its reason
  code, :data:`model.VERDICT_STATUS`);
- ``gamma_c``, ``gamma_c_reason``: the threshold γ_c, the first certified crossing in γ (as
  :func:`model.critical_gamma`), over the grid of the other axes, so the 6-D boundary is stored as a 5-D function
  (NaN plus a reason code, :data:`model.THRESHOLD_STATUS`, where there is none in the γ range);
- the whole boundary in γ (:func:`model.crossings_chunk`, as :func:`model.critical_gammas`), over the same grid
  with a last dimension ``crossing`` of length :data:`CROSSINGS` (NaN-padded, in increasing γ): ``gamma_c_crossing``
  (the threshold where certified), ``gamma_c_location`` (where the sign change is, certified or not),
  ``gamma_c_kH`` and ``gamma_c_z`` (the neutral mode), ``gamma_c_direction`` (+1 destabilising, -1 stabilising as γ
  grows), ``gamma_c_crossing_reason`` (:data:`model.CROSSING_STATUS`); per point ``gamma_c_n_crossings`` (may
  exceed CROSSINGS) and ``gamma_c_complete`` (1 where every crossing is certified);
- optionally ``unstable_count``: :func:`model.unstable_count` (all branches) in a stated window at each kH of a
  stated grid;
- optionally the sliding verdict over every branch (:func:`model.sliding_chunk`, as :func:`model.sliding_analysis`,
  on its own kH grid ``kH_sliding`` with a stated growth floor; docs/physics.md §14): ``growth_all``,
  ``kH_at_max_all``, ``re_z_at_max_all`` (z at the maximum is re_z_at_max_all + i growth_all), ``family_all``
  (:data:`model.FAMILIES`), ``verdict_all`` and ``verdict_reason_all`` (:data:`model.SLIDING_STATUS`),
  ``max_at_end_all`` and ``lower_bound_all`` (1 at finite η: the maximum is a lower bound of the continuous one).
  A store without them covers the Rayleigh branch only (``asymslide info`` says so).

A store also records its plan (:meth:`asymslide.atlas.plan.Plan.identity`), the model's fingerprint
(:func:`model_fingerprint`) and the source's git revision.
"""

from __future__ import annotations

import datetime
import functools
import hashlib
import json
import subprocess
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from asymslide import model

from . import __version__  # the distribution's version, recorded in every store
from .plan import Plan, json_float, sliding_thresholds
from .refinement import AdaptiveSpec
from .refinement import summary as adaptive_summary

#: the growth variables, their Zarr fill values (where not computed) and attributes
GROWTH_VARS = {
    "growth": (np.float64, np.nan, "max over kH of Im(c/c_s) on the Rayleigh branch (refined between grid points)",
               "1"),
    "kH_at_max": (np.float64, np.nan, "kH where the growth is largest", "1"),
    "kH_min": (np.float64, np.nan, "lower end of the unstable band around the maximum (NaN: none or beyond the grid)",
               "1"),
    "kH_max": (np.float64, np.nan, "upper end of the unstable band around the maximum (NaN: none or beyond the grid)",
               "1"),
    "n_masked": (np.int16, -1, "kH grid points where the Rayleigh branch could not be followed (masked; -1: not "
                 "computed)", "1"),
    "verdict": (np.int8, -1, "0 stable, 1 unstable, 2 undetermined (-1: not computed); why: verdict_reason", "1"),
    "verdict_reason": (np.int8, -1, "the verdict's reason code (model.VERDICT_STATUS; -1: not computed)", "1"),
}
#: the sliding variables (every branch; model.sliding_chunk): dtype, fill, long name
SLIDING_VARS = {
    "growth_all": (np.float64, np.nan, "max over kH of Im(c/c_s) over every branch (sliding; NaN unless unstable with "
                   "a certified maximum; at finite eta a lower bound: lower_bound_all)"),
    "kH_at_max_all": (np.float64, np.nan, "kH where the growth over every branch is largest"),
    "re_z_at_max_all": (np.float64, np.nan, "Re z of the fastest root at the maximum (z = re_z_at_max_all + i "
                        "growth_all)"),
    "family_all": (np.int8, -1, "family of the fastest root at the maximum (model.FAMILIES; -1: none)"),
    "verdict_all": (np.int8, -1, "sliding (every branch above the floor): 0 stable, 1 unstable, 2 undetermined (-1: "
                    "not computed); why: verdict_reason_all"),
    "verdict_reason_all": (np.int8, -1, "the sliding verdict's reason code (model.SLIDING_STATUS; -1: not computed)"),
    "max_at_end_all": (np.int8, -1, "1 where the maximum lies at an end of the kH range (it may continue beyond)"),
    "lower_bound_all": (np.int8, -1, "1 at finite eta: growth_all is the maximum at the kH searched and along the "
                        "roots followed, a lower bound of the continuous one (docs/physics.md §14.7)"),
}
#: crossings in gamma stored per point (the ``crossing`` dimension; model.critical_gammas' max_crossings)
CROSSINGS = model.crossings.MAX_CROSSINGS
#: the variables of the whole boundary in gamma (with the ``crossing`` dimension): dtype, fill, long name
CROSSING_VARS = {
    "gamma_c_crossing": (np.float64, np.nan, "gamma at each certified crossing of the max growth (a neutral mode; NaN: "
                         "not certified or no such crossing)"),
    "gamma_c_location": (np.float64, np.nan, "gamma where each sign change of the max growth is (certified or not)"),
    "gamma_c_kH": (np.float64, np.nan, "kH of the neutral mode at each certified crossing"),
    "gamma_c_z": (np.float64, np.nan, "z = c/c_s (real) of the neutral mode at each certified crossing"),
    "gamma_c_direction": (np.int8, 0, "+1 destabilising (unstable above), -1 stabilising, 0 not certified or none"),
    "gamma_c_crossing_reason": (np.int8, -1, "reason code of each crossing (model.CROSSING_STATUS; -1: none)"),
}


def all_branches_name(name: str) -> str:
    """The name of a threshold variable of sliding (every branch; asymslide sweep --sliding-thresholds): the Rayleigh
    branch's name with ``gamma_c_all`` for ``gamma_c`` (model.crossings_chunk with branches="all", docs/physics.md
    §14.10)."""
    return name.replace("gamma_c", "gamma_c_all", 1)


#: per-point summaries of the boundary in gamma: dtype, fill, long name
CROSSING_SUMMARY_VARS = {
    "gamma_c_n_crossings": (np.int16, -1, "sign changes of the max growth found in the gamma range (-1: not computed; "
                            "may exceed the crossing dimension)"),
    "gamma_c_complete": (np.int8, -1, "1 where every crossing found is certified, 0 where not (-1: not computed)"),
}
#: the sliding threshold's crossing variables (with the ``crossing`` dimension)
CROSSING_ALL_VARS = {all_branches_name(name): v for name, v in CROSSING_VARS.items()}
#: Zarr fill values (what a chunk not written yet reads as) of the integer variables; floats: NaN
INT_FILL = {"n_masked": -1, "gamma_c_reason": -1, "unstable_count": -2, "verdict": -1, "verdict_reason": -1,
            "gamma_c_direction": 0, "gamma_c_crossing_reason": -1, "gamma_c_n_crossings": -1, "gamma_c_complete": -1,
            "computed": -1, "verdict_filled": -1, "verdict_filled_all": -1, "gamma_c_all_reason": -1,
            "gamma_c_all_direction": 0, "gamma_c_all_crossing_reason": -1, "gamma_c_all_n_crossings": -1,
            "gamma_c_all_complete": -1,
            **{name: v[1] for name, v in SLIDING_VARS.items() if np.dtype(v[0]).kind == "i"}}


@functools.cache
def model_fingerprint() -> str:
    """sha256 of the model's source and data files, its kernel package's included: any change of the model is another
    model version."""
    h = hashlib.sha256()
    root = Path(model.__file__).parent
    for path in sorted([*root.rglob("*.py"), *root.rglob("*.json")]):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()


@functools.cache
def git_revision() -> str:
    """The git commit of the source tree this package runs from ("+dirty" with uncommitted model changes), or
    "unknown" for an installed package."""
    root = Path(__file__).resolve().parent.parent
    try:
        rev = subprocess.run(["git", "-C", str(root), "rev-parse", "--short=12", "HEAD"], capture_output=True,
                             text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--", "model"],
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return rev + ("+dirty" if dirty else "")


def _attrs(plan: Plan, command: str | None) -> dict[str, Any]:
    return {
        "title": "asymslide stability atlas: Rayleigh-branch growth and the threshold gamma_c",
        "source": "Aldam et al., Frictional sliding without geometrical reflection symmetry, PRX 6, 041023 (2016); "
                  "docs/physics.md §9",
        "asymslide_version": __version__,
        "model_fingerprint": model_fingerprint(),
        "git_revision": git_revision(),
        "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "plan": json.dumps(plan.identity()),
        "fixed": json.dumps({k: json_float(v) for k, v in plan.fixed.items()}),
        "kH_grid": f"{len(plan.kH)} points from {plan.kH[0]:g} to {plan.kH[-1]:g} (variable kH)",
        "rtol": "None (full certified accuracy)" if plan.rtol is None else float(plan.rtol),
        "command": command or "",
        **({"adaptive": json.dumps(adaptive_summary(plan.shape, plan.adaptive))} if plan.adaptive else {}),
    }


def _long_name(name: str) -> str:
    p = model.PARAMETERS[name]
    return f"{p.symbol}: {p.description}"


def axis_scale(values: Any) -> str:
    """"log" if the axis's values are log-spaced (more than two, positive, a constant ratio), else "linear": the
    ``scale`` attribute of a store's axis, and how the Atlas tab reads a store written without it."""
    v = np.asarray(values, dtype=float)
    log = v.size > 2 and v[0] > 0 and bool(np.allclose(np.diff(np.log(v)), np.log(v[1] / v[0])))
    return "log" if log else "linear"


def template(plan: Plan, command: str | None = None):
    """The empty dataset of a plan (lazy arrays of fill values, chunked as the store), with every attribute."""
    import dask.array as da
    import xarray as xr

    coords: dict[str, Any] = {}
    for name, values in plan.axes.items():
        p = model.PARAMETERS[name]
        scale = axis_scale(values)
        coords[name] = (name, np.asarray(values), {"long_name": _long_name(name), "units": "1", "symbol": p.symbol,
                                                   "scale": scale})
    coords["kH"] = ("kH", np.asarray(plan.kH), {"long_name": "the kH grid the growth is bracketed on (then refined "
                                                "between its points)", "units": "1"})
    data: dict[str, Any] = {}
    flags: dict[str, int] = {}
    if plan.growth:
        data.update(_growth_vars(plan))
        if plan.adaptive is None:
            flags["growth"] = len(plan.growth_blocks())
    if plan.gamma_c:
        coords["crossing"] = ("crossing", np.arange(CROSSINGS), {"long_name": "index of a sign change of the max "
                                                                 "growth in gamma, in increasing gamma"})
        data.update(_gamma_c_vars(plan))
        flags["gamma_c"] = len(plan.gamma_c_blocks())
    if sliding_thresholds(plan):
        data.update(_gamma_c_all_vars(plan))
        flags["gamma_c_all"] = len(plan.gamma_c_blocks())
    if plan.count is not None:
        coords["kH_count"] = ("kH_count", np.asarray(plan.count.kH), {"long_name": "kH of the all-branch count",
                                                                      "units": "1"})
        data.update(_count_vars(plan))
        flags["count"] = len(plan.count_blocks())
    if plan.sliding is not None:
        coords["kH_sliding"] = ("kH_sliding", np.asarray(plan.sliding.kH),
                                {"long_name": "the kH grid of the sliding verdict (its ends are the range)",
                                 "units": "1"})
        data.update(_sliding_vars(plan))
        if plan.adaptive is None:  # an adaptive sweep's ``computed`` is its done flag, per point
            flags["sliding"] = len(plan.sliding_blocks())
    for kind, n in flags.items():
        data[f"done_{kind}"] = (f"{kind}_chunk", da.zeros(n, dtype=np.int8, chunks=1),
                                {"long_name": f"1 where the {kind} chunk is written (resumable sweeps)"})
    return xr.Dataset(data, coords=coords, attrs=_attrs(plan, command))


def _flag_attrs(meanings: Mapping[int, str]) -> dict[str, Any]:
    """CF flag_values / flag_meanings (the codes' texts, as JSON) of a variable of codes."""
    codes = sorted(meanings)
    return {"flag_values": codes, "flag_meanings": json.dumps({str(k): meanings[k] for k in codes})}


def _growth_vars(plan: Plan) -> dict[str, Any]:
    """The template's growth variables over the grid, with the adaptive sweep's own if the plan is adaptive (its
    ``computed`` is the done flag, per point)."""
    import dask.array as da

    dims = plan.names
    chunks = tuple(plan.chunks[n] for n in dims)
    meanings = {"verdict": model.VERDICTS, "verdict_reason": model.VERDICT_STATUS}
    data: dict[str, Any] = {}
    for name, (dtype, fill, long_name, units) in GROWTH_VARS.items():
        attrs = {"long_name": long_name, "units": units, **(_flag_attrs(meanings[name]) if name in meanings else {})}
        data[name] = (dims, da.full(plan.shape, fill, dtype=dtype, chunks=chunks), attrs)
    if plan.adaptive is not None:
        for name, (dtype, fill, long_name, attrs) in _adaptive_vars(plan.adaptive, plan.sliding is not None).items():
            data[name] = (dims, da.full(plan.shape, fill, dtype=dtype, chunks=chunks),
                          {"long_name": long_name, "units": "1", **attrs})
    return data


def _gamma_c_vars(plan: Plan) -> dict[str, Any]:
    """The template's threshold variables: gamma_c and its reason over the axes other than gamma, the crossings
    (with the dimension ``crossing``) and their summaries."""
    import dask.array as da

    gdims = plan.gamma_c_names
    gshape = tuple(len(plan.axes[n]) for n in gdims)
    gchunks = tuple(plan.chunks[f"gamma_c:{n}"] for n in gdims) or None
    data: dict[str, Any] = {
        "gamma_c": (gdims, da.full(gshape, np.nan, chunks=gchunks),
                    {"long_name": "the threshold gamma_c: the first certified crossing of the max growth on the "
                                  f"Rayleigh branch (searched in gamma {plan.gamma_range[0]:g} to "
                                  f"{plan.gamma_range[1]:g})", "units": "1"}),
        "gamma_c_reason": (gdims, da.full(gshape, INT_FILL["gamma_c_reason"], dtype=np.int8, chunks=gchunks),
                           {"long_name": "why gamma_c is NaN (0: found)", **_flag_attrs(model.THRESHOLD_STATUS)}),
    }
    xchunks = (*(gchunks or gshape), CROSSINGS)
    for name, (dtype, fill, long_name) in CROSSING_VARS.items():
        attrs = {"long_name": long_name, "units": "1"}
        if name == "gamma_c_crossing_reason":
            attrs.update(_flag_attrs(model.CROSSING_STATUS))
        data[name] = ((*gdims, "crossing"), da.full((*gshape, CROSSINGS), fill, dtype=dtype, chunks=xchunks), attrs)
    for name, (dtype, fill, long_name) in CROSSING_SUMMARY_VARS.items():
        data[name] = (gdims, da.full(gshape, fill, dtype=dtype, chunks=gchunks), {"long_name": long_name, "units": "1"})
    return data


def _gamma_c_all_vars(plan: Plan) -> dict[str, Any]:
    """The template's sliding threshold variables (every branch): the Rayleigh branch's, renamed, with their long
    names saying so and the floor and kH range of the search."""
    spec = plan.sliding
    assert spec is not None
    data = {}
    for name, (dims, arr, attrs) in _gamma_c_vars(plan).items():
        long_name = attrs["long_name"].replace("on the Rayleigh branch", "over every branch")
        text = f"sliding (every branch, growth floor {spec.floor:g}, kH {spec.kH[0]:g} to {spec.kH[-1]:g}): {long_name}"
        data[all_branches_name(name)] = (dims, arr, {**attrs, "long_name": text, "floor": spec.floor})
    return data


def _count_vars(plan: Plan) -> dict[str, Any]:
    """The template's all-branch count over the grid and ``kH_count``."""
    import dask.array as da

    cchunks = (*(plan.chunks[f"count:{n}"] for n in plan.names), len(plan.count.kH))
    re_max, im_min, im_max = plan.count.window
    return {"unstable_count": ((*plan.names, "kH_count"),
                               da.full((*plan.shape, len(plan.count.kH)), INT_FILL["unstable_count"], dtype=np.int16,
                                       chunks=cchunks),
                               {"long_name": "roots of F (any branch) with |Re z| <= re_max and im_min <= Im z <= "
                                             "im_max (argument principle; -1: the count failed; -2: not computed)",
                                "re_max": re_max, "im_min": im_min, "im_max": im_max, "units": "1"})}


def _sliding_vars(plan: Plan) -> dict[str, Any]:
    """The template's sliding variables over the grid (every branch; the floor in each one's attributes)."""
    import dask.array as da

    # an adaptive sweep writes them with the growth variables, chunked as those
    chunks = tuple(plan.chunks[n if plan.adaptive is not None else f"sliding:{n}"] for n in plan.names)
    meanings = {"verdict_all": model.VERDICTS, "verdict_reason_all": model.SLIDING_STATUS,
                "family_all": {-1: "none", **model.FAMILIES}}
    data: dict[str, Any] = {}
    for name, (dtype, fill, long_name) in SLIDING_VARS.items():
        attrs = {"long_name": long_name, "units": "1", "floor": plan.sliding.floor,  # type: ignore[union-attr]
                 **(_flag_attrs(meanings[name]) if name in meanings else {})}
        data[name] = (plan.names, da.full(plan.shape, fill, dtype=dtype, chunks=chunks), attrs)
    return data


def _adaptive_vars(spec: AdaptiveSpec, sliding: bool = False) -> dict[str, tuple[Any, int, str, dict[str, Any]]]:
    """The adaptive sweep's variables: dtype, fill, long name, further attributes (`sliding`: also the filled
    sliding verdict)."""
    levels = spec.levels or 0
    meanings = {"-1": "not computed (growth NaN there; its class is in verdict_filled)",
                **{str(k): f"computed at level {k} (stride {2 ** (levels - k)})" for k in range(levels + 1)}}
    classes = {"flag_values": sorted(model.VERDICTS),
               "flag_meanings": json.dumps({str(k): v for k, v in model.VERDICTS.items()})}
    filled_all = {"verdict_filled_all": (
        np.int8, -1, "sliding verdict class (every branch above the floor) at every point: the model's where computed, "
        "else the common class of the corners of the finest computed cell holding the point (-1: not yet filled)",
        classes)} if sliding else {}
    return {
        "computed": (np.int8, -1, "the refinement level at which the point was computed (-1: not computed)",
                     {"flag_values": list(range(-1, levels + 1)), "flag_meanings": json.dumps(meanings)}),
        "verdict_filled": (np.int8, -1, "verdict class at every point: the model's verdict where computed, else the "
                           "common class of the corners of the finest computed cell holding the point (-1: not yet "
                           "filled)", classes),
        **filled_all,
    }


def encoding(ds, fast: bool = False) -> dict[str, dict]:
    """Fill values; `fast`: Zstandard at level 1 instead of Zarr's default level (the same size on atlas data, ~3x
    faster to write: an adaptive sweep rewrites a chunk at every level that touches it)."""
    extra: dict[str, Any] = {}
    if fast:
        from zarr.codecs import ZstdCodec

        extra = {"compressors": [ZstdCodec(level=1)]}
    return {name: {"fill_value": np.nan if var.dtype.kind == "f" else INT_FILL.get(name, 0), **extra}
            for name, var in ds.data_vars.items()}
