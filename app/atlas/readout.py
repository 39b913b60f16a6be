"""The Atlas tab's readouts of a whole atlas, in words: what it holds, how much of it is certified (the counts of
``asymslide info``: asymslide.atlas.summary), and the short texts of the verdict and crossing codes that the heat
map's hover, the readouts and the CSV share."""

from __future__ import annotations

import math
import re

import numpy as np

from asymslide import model
from asymslide.atlas import summary
from asymslide.atlas.refinement import refinement_text

from ..plotting import fmt
from .directory import Atlas, display_name

#: verdict class of an undetermined point
UNDETERMINED = model.Verdict.UNDETERMINED


#: the refused sign changes of the boundary in a few words (the full texts: model.CROSSING_STATUS)
REFUSED_CROSSING = {2: "a jump where the masked part of the kH range changes",
                    3: "a jump: the branch changes route (branch exchange)",
                    4: "a pole-dense neutral mode",
                    5: "the max growth is undefined in the bracket",
                    6: "not certified"}


def short_reason(code: int, texts: dict[int, str]) -> str:
    """The reason of a verdict or crossing code in a few words: its text up to the first colon or parenthesis after
    the class ("undetermined: pole-dense: ..." -> "pole-dense")."""
    text = texts.get(int(code), f"reason {int(code)}")
    head, _, rest = text.partition(": ")
    if head in ("stable", "unstable", "undetermined") and rest:
        text = rest
    return re.split(r": | \(", text, maxsplit=1)[0]


#: what a NaN growth means (the atlas engine stores model.growth_analysis: NaN where the branch could not be
#: followed at any kH, or where the maximum could not be refined)
NOT_COMPUTABLE = ("the Rayleigh branch could not be followed at any kH, or its maximum could not be refined "
                  "(n_masked_kH in the CSV tells which)")

#: what the CSV exports say about NaN growth rows
NAN_ROWS = ("max_growth NaN: not computable (n_masked_kH = the number of kH grid points: the branch was not followed "
            "at any kH; fewer: its maximum could not be refined)")


def adaptive_readout(d: Atlas) -> str:
    """The readout line of an adaptive atlas: the evaluated fraction overall and per level, margin and guard (or
    that its sweep has not finished)."""
    a = d.adaptive
    if not a.get("evaluated"):
        return ("**Adaptive atlas, not finished**: its values are written when the sweep ends; run the same "
                "`asymslide sweep --adaptive` command again to resume it")
    levels = "; ".join(f"level {lv['level']} (stride {lv['stride']}) {100 * lv['fraction_of_grid']:.2f} %"
                       for lv in a.get("per_level", []))
    return (f"**Adaptive** (asymslide sweep --adaptive): computed {a['evaluated']} of {a['points']} points, "
            f"evaluated fraction **{100 * a['evaluated_fraction']:.1f} %** ({levels}; {refinement_text(a)}); the "
            "other points are not computed: their verdict class comes from their cell (pale, dotted), their growth is "
            "not stored"
            + ("" if a.get("guard") else "; a single point of another class inside a cell is not seen (`--guard` "
               "looks closer)"))


def verdict_coverage(verdict: np.ndarray, reason: np.ndarray) -> str:
    """The readout line of an atlas's verdicts (the counts of ``asymslide info``: summary.verdict_coverage): how many
    points are certified stable or unstable, and why the others are undetermined."""
    c = summary.verdict_coverage(verdict, reason)
    why = ", ".join(f"{short_reason(code, model.VERDICT_STATUS)} {k}" for code, k in c.undetermined.items())
    share = f"{100 * c.certified / max(c.computed, 1):.1f} %"
    return (f"**Verdict of the Rayleigh branch** certified (stable or unstable) at {c.certified} of "
            f"{c.computed} points ({share})" + (f"; undetermined (hatched): {why}" if why else ""))


def crossing_coverage(reason: np.ndarray, which: str = "Thresholds in γ") -> str:
    """The readout line of an atlas's boundary in γ: certified thresholds and refused sign changes by reason."""
    r = np.asarray(reason)
    points = r.reshape(-1, r.shape[-1])
    certified = int(np.isin(r, model.CERTIFIED_CROSSINGS).sum())
    complete = int(np.all((points < 0) | np.isin(points, model.CERTIFIED_CROSSINGS), axis=1).sum())
    refused = ", ".join(f"{REFUSED_CROSSING.get(int(code), f'reason {int(code)}')} {int((r == code).sum())}"
                        for code in np.unique(r[(r >= 0) & ~np.isin(r, model.CERTIFIED_CROSSINGS)]))
    return (f"**{which}** {certified} certified crossing(s); every sign change certified at {complete} of "
            f"{points.shape[0]} points of the other axes" + (f"; refused (×, not thresholds): {refused}" if refused
                                                             else ""))


def atlas_readout(d: Atlas | None) -> str:
    """The readout of the whole atlas: its name and grid, the fixed parameters, its provenance, the not computable
    points, the verdicts' coverage (Rayleigh branch, sliding over every branch) and the thresholds in γ."""
    if d is None:
        return "**No atlas loaded yet.**"
    a = d.attrs
    shown = display_name(d.name)
    sizes = ", ".join(f"{d.label(n)}: {v.size}" for n, v in d.axes.items())
    lines = [f"**Atlas** {shown}" + (f" (file {d.name}.zarr)" if shown != d.name else "") + f" ({sizes} points)",
             "**Fixed** " + ", ".join(f"{d.label(k)} = {'∞' if math.isinf(v) else fmt(v)}"
                                       for k, v in d.fixed.items()),
             f"**Computed** by asymslide {a.get('asymslide_version')} (git {a.get('git_revision')}) on "
             f"{a.get('created')}; kH grid {a.get('kH_grid')}; rtol {a.get('rtol')}"]
    masked = int(np.sum(~np.isfinite(np.asarray(d.growth)))) if isinstance(d.growth, np.ndarray) else None
    if d.adaptive:
        lines.append(adaptive_readout(d))
        computed = np.asarray(d.computed) >= 0 if d.computed is not None else None
        masked = (int(np.sum(computed & ~np.isfinite(np.asarray(d.growth))))
                  if computed is not None and isinstance(d.growth, np.ndarray) else None)
    if masked is not None:
        lines.append(f"**Not computable** {masked} point(s) of the atlas (dark grey): {NOT_COMPUTABLE}"
                     if masked else "**Not computable** none")
    if isinstance(d.verdict, np.ndarray):
        lines.append(verdict_coverage(d.verdict, d.verdict_reason))
    if d.has_sliding:
        lo, hi = d.sliding_kH
        s = np.asarray(d.sliding.get("verdict_filled_all", d.sliding["verdict_all"]))
        how = (" (adaptive: refined on both verdicts, classes filled from their cells where not computed)"
               if "verdict_filled_all" in d.sliding else "")
        lines.append(f"**Sliding (every branch)** Im z ≥ {d.sliding_floor:g}, kH {lo:g} to {hi:g}{how}: unstable "
                     f"{int((s == 1).sum())}, stable {int((s == 0).sum())}, undetermined {int((s == 2).sum())}, "
                     f"not computed {int((s < 0).sum())} of {s.size} points")
    else:
        lines.append("**Rayleigh branch only**: this atlas has no sliding verdict over every branch")
    if d.crossings:
        which = "Thresholds in γ (Rayleigh branch)" if d.crossings_all else "Thresholds in γ"
        lines.append(crossing_coverage(d.crossings["gamma_c_crossing_reason"], which))
    if d.crossings_all:
        lines.append(crossing_coverage(d.crossings_all["gamma_c_crossing_reason"],
                                       "Thresholds of sliding in γ (every branch; dash-dotted, purple)"))
    elif d.gamma_c_reason is not None:
        r = np.asarray(d.gamma_c_reason)
        lines.append(f"**γ_c** found at {int((r == 0).sum())} of {r.size} points of the other axes")
    return "\n\n".join(lines)
