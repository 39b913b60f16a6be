"""What an atlas holds, in lines of text: its plan, its provenance, how far its sweep got and what its verdicts
cover (``asymslide info``; the Atlas tab shows the same coverage lines)."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import NamedTuple

import numpy as np

from asymslide import model

from .refinement import lattice_size, level_counts, refinement_text
from .schema import CROSSINGS
from .writers import done_chunks


def iter_summary(store: str | os.PathLike) -> Iterator[str]:
    """Lines describing an atlas: plan, provenance, completion and a summary of its values."""
    import xarray as xr

    path = Path(store)
    ds = xr.open_zarr(path, consolidated=False)
    plan = json.loads(ds.attrs.get("plan", "{}"))
    yield f"atlas {path}"
    yield (f"  written by asymslide {ds.attrs.get('asymslide_version')} (git {ds.attrs.get('git_revision')}, model "
           f"{str(ds.attrs.get('model_fingerprint', ''))[:12]}) on {ds.attrs.get('created')}")
    for name, values in plan.get("axes", {}).items():
        v = np.asarray(values)
        yield f"  axis {name} ({model.PARAMETERS[name].symbol}): {v.size} values from {v[0]:g} to {v[-1]:g}"
    yield "  fixed: " + ", ".join(f"{k} = {v}" for k, v in plan.get("fixed", {}).items())
    yield f"  kH grid: {ds.attrs.get('kH_grid')}; rtol: {ds.attrs.get('rtol')}"
    done = done_chunks(path)
    if done:
        yield "  chunks written: " + ", ".join(f"{kind} {int(done[kind].sum())} of {done[kind].size}"
                                              for kind in ("growth", "gamma_c", "count", "sliding", "gamma_c_all")
                                              if kind in done)
    if "adaptive" in ds.attrs and "computed" in ds:
        yield from _adaptive_store_lines(ds)
    g = ds["growth"].values if "growth" in ds else np.empty(0)
    finite = np.isfinite(g)
    if finite.any():
        yield (f"  growth (Rayleigh branch): {int(finite.sum())} of {g.size} points computed; unstable (growth > 0) at "
               f"{100 * float((g[finite] > 0).mean()):.1f} %; range {np.nanmin(g):.4g} .. {np.nanmax(g):.4g}")
    yield from _both_verdicts(ds)
    for name, which in (("gamma_c", "gamma_c"), ("gamma_c_all", "gamma_c_all (sliding, every branch)")):
        if name in ds:
            yield from _gamma_c_lines(ds[name].values, ds[f"{name}_reason"].values, which)
    if "gamma_c_complete" in ds:
        yield from _crossing_lines(ds)
    if "unstable_count" in ds:
        uc = ds["unstable_count"]
        yield (f"  unstable_count: window |Re z| <= {uc.attrs['re_max']:g}, {uc.attrs['im_min']:g} <= Im z <= "
               f"{uc.attrs['im_max']:g} on {ds.sizes['kH_count']} kH; max {int(uc.max())}, failed counts "
               f"{int((uc == -1).sum())}")


def _adaptive_store_lines(ds) -> Iterator[str]:
    """An adaptive atlas: its refinement, the points evaluated per level and the filled verdicts' classes."""
    yield from adaptive_lines(ds.attrs["adaptive"], ds["computed"].values)
    filled = ds["verdict_filled"].values
    if not (filled >= 0).all():
        yield "  verdict_filled: not yet (the sweep has not finished: run the same command to resume it)"
        return
    for name, which in (("verdict_filled", "every point"), ("verdict_filled_all", "sliding, every point")):
        if name in ds:
            v = ds[name].values
            yield (f"  {name} ({which}): " + ", ".join(f"{model.VERDICTS[k]} {100 * (v == k).mean():.1f} %"
                                                       for k in sorted(model.VERDICTS)))


def _gamma_c_lines(gc: np.ndarray, reason: np.ndarray, which: str = "gamma_c") -> Iterator[str]:
    """Where the threshold was found, its range, and the count of each reason it was not."""
    ok = reason == model.ThresholdReason.FOUND
    yield (f"  {which}: found at {int(ok.sum())} of {gc.size} points"
           + (f", range {np.nanmin(gc):.6g} .. {np.nanmax(gc):.6g}" if ok.any() else ""))
    for code, text in model.THRESHOLD_STATUS.items():
        n = int((reason == code).sum())
        if code and n:
            yield f"    reason {code} at {n} points: {text}"


def adaptive_lines(attribute: str, computed: np.ndarray) -> Iterator[str]:
    """The refinement of an adaptive atlas (its ``adaptive`` attribute) and the points evaluated per level (from
    ``computed``, so a sweep not finished yet is described as far as it got)."""
    a = json.loads(attribute)
    levels = int(a["levels"])
    counts = level_counts(computed, levels)
    size = computed.size
    yield (f"  adaptive: levels 0..{levels}, coarse grid {' x '.join(str(n) for n in a['coarse_shape'])} (stride "
           f"{a['coarse_stride']}), {refinement_text(a)}")
    for level, n in enumerate(counts):
        lattice = lattice_size(computed.shape, levels, level)
        yield (f"    level {level} (stride {2 ** (levels - level)}): {n} points evaluated = {100 * n / size:.2f} % of "
               f"the grid ({100 * n / lattice:.1f} % of the level's {lattice} points)")
    total = sum(counts)
    yield f"  evaluated fraction: {100 * total / size:.2f} % ({total} of {size} points)"


class Coverage(NamedTuple):
    """What a verdict covers over the computed points of an atlas: the counts ``asymslide info`` and the Atlas tab's
    readout both render (:func:`verdict_coverage`)."""

    computed: int
    stable: int
    unstable: int
    #: undetermined points per reason code (codes in increasing order; only those that occur)
    undetermined: dict[int, int]

    @property
    def certified(self) -> int:
        """The points with a certified verdict (stable or unstable)."""
        return self.stable + self.unstable


def verdict_coverage(verdict: np.ndarray, reason: np.ndarray) -> Coverage:
    """The coverage of a verdict field (``verdict`` / ``verdict_all`` and its reasons; -1: not computed)."""
    v, r = np.asarray(verdict), np.asarray(reason)
    undetermined = v == model.Verdict.UNDETERMINED
    return Coverage(int((v >= 0).sum()), int((v == model.Verdict.STABLE).sum()),
                    int((v == model.Verdict.UNSTABLE).sum()),
                    {int(code): int((undetermined & (r == code)).sum()) for code in np.unique(r[undetermined])})


def _verdict_lines(verdict: np.ndarray, reason: np.ndarray, which: str = "Rayleigh branch",
                   status: Mapping[int, str] | None = None) -> Iterator[str]:
    """Coverage of a verdict (`which`: "Rayleigh branch" or "sliding (every branch)"): the fraction of computed cells
    with a certified verdict, and why the rest are not (codes of `status`, default model.VERDICT_STATUS)."""
    status = model.VERDICT_STATUS if status is None else status
    c = verdict_coverage(verdict, reason)
    n = c.computed
    if not n:
        yield f"  {which} verdict: no cell computed yet"
        return
    yield (f"  {which} verdict coverage: {100 * c.certified / n:.1f} % of {n} computed cells certified (stable "
           f"{100 * c.stable / n:.1f} %, unstable {100 * c.unstable / n:.1f} %), undetermined "
           f"{100 * sum(c.undetermined.values()) / n:.1f} %")
    for code, k in c.undetermined.items():
        text = status.get(code, f"reason {code}")
        yield f"    undetermined, reason {code} at {k} cells: {text.removeprefix('undetermined: ')}"


def _both_verdicts(ds) -> Iterator[str]:
    """The Rayleigh branch's verdict and the sliding one (or that the atlas covers the Rayleigh branch only)."""
    if "verdict" in ds:
        yield from _verdict_lines(ds["verdict"].values, ds["verdict_reason"].values, "Rayleigh branch",
                                  model.VERDICT_STATUS)
    if "verdict_all" in ds:
        yield from _sliding_lines(ds)
    elif "verdict" in ds:
        yield ("  sliding (every branch): not computed: this atlas covers the Rayleigh branch only (other branches can "
               "be unstable where it is stable; asymslide sweep --sliding)")


def _sliding_lines(ds) -> Iterator[str]:
    """The sliding verdict (every branch): coverage, the growth, the families at the maximum, and where it differs
    from the Rayleigh branch's."""
    v = ds["verdict_all"].values
    floor = ds["verdict_all"].attrs.get("floor", ds["growth_all"].attrs.get("floor"))
    yield (f"  sliding (every branch, growth floor {floor:g}) on {ds.sizes.get('kH_sliding', 0)} kH from "
           f"{float(ds['kH_sliding'][0]):g} to {float(ds['kH_sliding'][-1]):g}:")
    yield from _verdict_lines(v, ds["verdict_reason_all"].values, "  sliding", model.SLIDING_STATUS)
    g = ds["growth_all"].values
    if np.isfinite(g).any():
        fam = ds["family_all"].values
        yield (f"    growth_all: range {np.nanmin(g):.4g} .. {np.nanmax(g):.4g}; fastest family at the maximum: "
               + ", ".join(f"{name.split(' (')[0]} {int((fam == k).sum())}" for k, name in model.FAMILIES.items()
                           if (fam == k).any()))
    bound = int((ds["lower_bound_all"].values == 1).sum())
    if bound:
        yield (f"    at {bound} cells (finite eta) growth_all is a lower bound of the continuous maximum "
               "(docs/physics.md §14.7)")
    if "verdict" in ds:
        r = ds["verdict"].values
        both = (r >= 0) & (v >= 0)
        if both.any():
            yield (f"    Rayleigh branch stable but sliding unstable at {int(((r == 0) & (v == 1) & both).sum())} of "
                   f"{int(((r == 0) & both).sum())} Rayleigh-stable cells")


def _crossing_lines(ds) -> Iterator[str]:
    """Coverage of the boundary in gamma: points whose every crossing is certified, and the crossings' reasons."""
    complete, count = ds["gamma_c_complete"].values, ds["gamma_c_n_crossings"].values
    done = complete >= 0
    n = int(done.sum())
    if not n:
        return
    reasons = ds["gamma_c_crossing_reason"].values
    hist = np.bincount(count[done].astype(int))
    over = int((count > CROSSINGS).sum())
    yield (f"  crossing coverage: every crossing in gamma certified at {100 * (complete == 1).sum() / n:.1f} % of {n} "
           f"computed points; crossings per point: "
           + ", ".join(f"{k}: {int(c)}" for k, c in enumerate(hist) if c)
           + (f" ({over} points have more than the {CROSSINGS} stored)" if over else ""))
    for code, text in model.CROSSING_STATUS.items():
        k = int((reasons == code).sum())
        if k:
            yield f"    crossings with reason {code}: {k} ({text})"
