"""Fig. 4c beside the Stability map: the exact threshold χ_c(β) = γ_c f of the Rayleigh branch, the approximate
criterion, and the threshold of sliding over every branch (computed as a job, in cached chunks of β); its plot
elements, readout and CSV."""

from __future__ import annotations

import io
from functools import partial
from typing import Any

import holoviews as hv
import numpy as np
import panel as pn

from asymslide import model

from .. import jobs
from ..exports import csv_table
from ..params import SpectrumParams
from ..plotting import fmt

#: β grids of Fig. 4c: the criterion (line) and, at every other of its points, the exact threshold (symbols)
BETA_CRITERION = np.linspace(0.025, 0.70, 28)
BETA_EXACT = BETA_CRITERION[1::2].copy()
#: Fig. 4c y range; a current χ off this range is drawn at its edge
CHI_RANGE = (0.0, 5.0)
#: β per cached chunk of Fig. 4c's sliding threshold (about 0.5 s a β at η = ∞)
FIG4C_SLIDING_CHUNK = 2
#: Fig. 4c's marker colour of the sliding threshold (every branch)
SLIDING_THRESHOLD_COLOR = "#d6604d"


@pn.cache(max_items=1)
def compute_criterion() -> np.ndarray:
    """χ_c of the approximate criterion (Eq. criterion) on :data:`BETA_CRITERION` (independent of f)."""
    return np.asarray(model.criterion_chi(BETA_CRITERION), float)


@pn.cache(max_items=32)
def compute_fig4c(f: float) -> dict:
    """Fig. 4c at friction coefficient f: exact χ_c(β) (NaN where there is no threshold) and the criterion."""
    exact = np.full(BETA_EXACT.shape, np.nan)
    reason = ""
    try:
        exact = np.asarray(model.critical_chi(BETA_EXACT, f=f), float)
    except ValueError:  # no threshold at some beta: per point, NaN there
        for i, b in enumerate(BETA_EXACT):
            try:
                exact[i] = float(model.critical_chi(float(b), f=f))
            except ValueError as exc:
                reason = str(exc)
    return {"beta": BETA_EXACT, "exact": exact, "beta_criterion": BETA_CRITERION, "criterion": compute_criterion(),
            "reason": reason}


@pn.cache(max_items=64)
def compute_fig4c_sliding_chunk(f: float, betas: tuple[float, ...]) -> dict:
    """Fig. 4c's threshold of sliding over every branch at `betas` (η = ∞, Δ = 1; the model's kH range and growth
    floor: :func:`model.critical_gammas` with ``branches="all"``, docs/physics.md §14.10): χ_c = γ_c f at the first
    certified crossing in γ (NaN where there is none), its crossing reason (model.CROSSING_STATUS; 1: at an end of
    the kH range), kH and z, and the status (model.THRESHOLD_STATUS) of each β."""
    r = model.critical_gammas(f=f, beta=np.asarray(betas, dtype=float), branches="all")
    first = r.first  # the model's first certified crossing; its kH and z are the ones at the same crossing
    found = np.isfinite(first)
    rows = np.arange(len(betas))
    k = np.argmax(r.value == first[:, None], axis=1)
    pick = {name: np.where(found, np.asarray(getattr(r, name))[rows, k], np.nan) for name in ("kH", "z")}
    return {"chi": first * f, "kH": pick["kH"], "z": np.real(pick["z"]),
            "reason": np.where(found, r.reason[rows, k], -1), "status": np.asarray(r.status, int)}


def compute_fig4c_sliding(f: float, job: jobs.Job) -> dict:
    """Fig. 4c's sliding threshold at every β of :data:`BETA_EXACT` (a job: cached chunks of
    :data:`FIG4C_SLIDING_CHUNK` β, progress per β)."""
    parts = []
    for i in range(0, BETA_EXACT.size, FIG4C_SLIDING_CHUNK):
        job.check()
        betas = tuple(float(b) for b in BETA_EXACT[i:i + FIG4C_SLIDING_CHUNK])
        parts.append(compute_fig4c_sliding_chunk(f, betas))
        job.advance("β", len(betas))
    out = {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}
    return {"f": f, "beta": BETA_EXACT, **out}


def fig4c_sliding_text(d: dict) -> str:
    """The sliding threshold of Fig. 4c in words: where it is certified, where it lies on an end of the kH range
    (over a wider range it may lie elsewhere), and why it is missing at the other β."""
    chi, beta = d["chi"], d["beta"]
    found = np.isfinite(chi)
    text = (f"**Sliding threshold (every branch, f = {fmt(d['f'])})** certified at {int(found.sum())} of "
            f"{beta.size} β (triangles)")
    if found.any():
        text += f": χ_c from {fmt(float(np.nanmin(chi)))} to {fmt(float(np.nanmax(chi)))}"
        at_end = found & (d["reason"] == model.CrossingReason.EDGE)
        if at_end.any():
            text += (f"; at {int(at_end.sum())} β its neutral mode is at kH = {fmt(float(np.nanmax(d['kH'][at_end])))}"
                     f", the end of the kH range searched (z = {fmt(float(d['z'][at_end][0]), 6)}: a root just beyond "
                     "the shear wave speed; over a wider kH range the threshold may lie lower)")
        text += (". The map's sliding verdict, with its growth floor, turns unstable a little higher, where the "
                 "growth exceeds the floor (docs/physics.md §14.10)")
    missing = [f"β = {fmt(float(b))}: {model.THRESHOLD_STATUS.get(int(st), f'status {int(st)}')}"
               for b, st, ok in zip(beta, d["status"], found, strict=True) if not ok]
    if missing:
        text += ". No certified threshold at " + "; ".join(missing)
    return text + "."


#: Fig. 4c's axes
BETA_DIM = hv.Dimension("beta", label="β = c_s/c_d")
CHI_DIM = hv.Dimension("chi", label="χ_c = γ_c f")


def fig4c_applies(p: SpectrumParams) -> bool:
    """Fig. 4c is for η = ∞ and Δ = 1: only then is the current χ = γ f comparable with χ_c."""
    return bool(p.eta_infinite and p.Delta == 1)


def fig4c_curves(f: float) -> hv.Overlay:
    """The criterion (line) and the exact threshold at friction coefficient f (circles)."""
    d = compute_fig4c(float(f))
    criterion = hv.Curve((d["beta_criterion"], d["criterion"]), BETA_DIM, CHI_DIM,
                         label="criterion (Eq. criterion)").opts(color="#b2182b", line_width=2)
    exact = hv.Scatter((d["beta"], d["exact"]), BETA_DIM, CHI_DIM, label=f"exact threshold (f = {f:g})").opts(
        marker="circle", size=8, fill_color="white", line_color="#1f4e79", line_width=1.5)
    return criterion * exact


def fig4c_sliding_points(d: dict | None, f: float) -> hv.Scatter:
    """The sliding threshold's certified points `d` (:func:`compute_fig4c_sliding`) if computed at the current f
    (none for another f: redrawn when f changes, not only when the points do)."""
    current = d is not None and d["f"] == float(f)
    points = (d["beta"], d["chi"]) if current else ([], [])
    return hv.Scatter(points, BETA_DIM, CHI_DIM, label="sliding threshold (every branch)").opts(
        marker="triangle", size=9, color=SLIDING_THRESHOLD_COLOR, line_color="black")


def fig4c_marker(p: SpectrumParams) -> hv.Overlay:
    """The current β (dotted line) and, where Fig. 4c applies, the current χ = γ f (star, clamped to the range)."""
    point = [(p.beta, min(max(p.gamma * p.f, CHI_RANGE[0]), CHI_RANGE[1]))] if fig4c_applies(p) else []
    return (hv.VLine(p.beta).opts(color="#666666", line_dash="dotted", line_width=1.5)
            * hv.Points(point, kdims=[BETA_DIM, CHI_DIM], label="current χ = γ f").opts(
                marker="star", size=16, color="#ffd92f", line_color="black"))


def fig4c_readout(p: SpectrumParams, sliding: dict | None, status: str) -> str:
    """Fig. 4c's readout: the current χ against the thresholds, and the sliding threshold (or its job's `status`)."""
    if fig4c_applies(p):
        text = (f"**Current** χ = γ f = {fmt(p.gamma * p.f)} at β = {fmt(p.beta)} (star; dotted line: β). "
                "The Rayleigh branch is unstable above its exact threshold (circles), sliding (every branch) "
                "above the sliding threshold (triangles).")
        if not CHI_RANGE[0] <= p.gamma * p.f <= CHI_RANGE[1]:
            text += f" The star is drawn at the edge of the plotted range {CHI_RANGE}."
    else:
        text = (f"**Current** β = {fmt(p.beta)} (dotted line). Fig. 4c is for η = ∞ and Δ = 1; at the current "
                "η and Δ the threshold differs, so χ = γ f is not drawn.")
    if status:
        text += f"\n\n{status}"
    elif sliding is not None and sliding["f"] == float(p.f):
        text += "\n\n" + fig4c_sliding_text(sliding)
    return text


def fig4c_csv(f: float, sl: dict | None) -> io.StringIO:
    """What Fig. 4c shows: β, the criterion's χ_c, and the exact threshold χ_c at f (computed at every other β: NaN
    at the others, and where there is no threshold), and the sliding threshold `sl` if computed at f."""
    d = compute_fig4c(f)
    exact = np.full(d["beta_criterion"].shape, np.nan)
    exact[1::2] = d["exact"]
    columns = {"beta": d["beta_criterion"], "chi_c_criterion": d["criterion"], "chi_c_exact": exact}
    note = "chi_c_sliding (every branch) not computed yet"
    if sl is not None and sl["f"] == f:
        chi = np.full(exact.shape, np.nan)
        chi[1::2] = sl["chi"]
        columns["chi_c_sliding"] = chi
        note = ("chi_c_sliding: the sliding threshold over every branch (model.critical_gammas branches='all', "
                "first certified crossing; NaN: none certified)")
    return csv_table(f"asymslide Fig. 4c (eta = inf, Delta = 1); f = {f!r}; chi_c_exact at every other beta; "
                     f"{note}", columns)


def fig4c_view(scene: Any) -> hv.Overlay:
    """Fig. 4c of a :class:`~asymslide.app.stability_map.scene.StabilityMapScene`: the curves at its f, the sliding
    threshold's points, the current β and χ; redrawn as its parameters change."""
    p = scene.params
    return (hv.DynamicMap(partial(_curves_drawn, scene), streams=[hv.streams.Params(p, ["f"])])
            * hv.DynamicMap(partial(_sliding_points_shown, scene),
                            streams=[hv.streams.Params(scene, ["fig4c_sliding"]), hv.streams.Params(p, ["f"])])
            * hv.DynamicMap(partial(_marker_shown, scene), streams=[hv.streams.Params(
                p, ["beta", "gamma", "f", "eta_infinite", "Delta"])])).opts(
        hv.opts.Overlay(title="Fig. 4c: instability threshold χ_c vs β (η = ∞, Δ = 1)", responsive=True,
                        height=340, legend_position="top_left", xlim=(0.0, 0.7071), ylim=CHI_RANGE))


def _curves_drawn(scene: Any, f: float, **_stream_values) -> hv.Overlay:
    """Fig. 4c's curves at f; once drawn, the scene keeps its sliding threshold current."""
    scene._fig4c_drawn = True
    scene.ensure_fig4c_sliding()
    return fig4c_curves(f)


def _sliding_points_shown(scene: Any, fig4c_sliding: dict | None = None, f: float | None = None,
                          **_stream_values) -> hv.Scatter:
    """The scene's sliding threshold's certified points, at the f they were computed for."""
    return fig4c_sliding_points(fig4c_sliding, scene.params.f if f is None else f)


def _marker_shown(scene: Any, **_stream_values) -> hv.Overlay:
    """The scene's current β and χ = γ f."""
    return fig4c_marker(scene.params)
