"""Scene "All branches": every unstable root of F(z; kH) = 0 in the complex z-plane, not only the Rayleigh branch.

The paper (Sect. IV) follows the Rayleigh branch; other branches of the same dispersion relation exist and can be
unstable where the Rayleigh branch is stable (docs/physics.md §3). This scene shows, at a chosen kH, every root
with Im z > 0 in a window (:func:`model.unstable_modes`, counted with the argument principle), the Rayleigh-branch
root (:func:`model.rayleigh_branch`), and the certified number of unstable roots (:func:`model.unstable_count`)
against kH.

The app computes no physics: the cached ``compute_*`` functions only call the public API of :mod:`model`, one
function per dependency group, so that changing kH recomputes only the roots at kH (not the count-vs-kH curve),
a window change does not recompute the Rayleigh branch, and ξ at Δ = 1 (which does not enter F) recomputes nothing.
The plots are HoloViews DynamicMaps over parameter-dependent methods (updated in place); the readout is evaluated
lazily, so building the page computes nothing until the tab is shown.
"""

from __future__ import annotations

import io
import math

import holoviews as hv
import numpy as np
import panel as pn
import param

from asymslide import model

from .common import FAMILY_NAMES
from .declarations import Physical, from_log10, physical_parameters
from .docs import reference_card
from .exports import csv_download
from .layout import EQUATION_STYLES, heading, scene_layout
from .params import SpectrumParams
from .plotting import fmt
from .widgets import make_widgets

# --------------------------------------------------------------------------------------------
# grids, window limits, labels
# --------------------------------------------------------------------------------------------

#: fine kH grid of the Rayleigh branch (where it is unstable: the shaded bands of the count plot)
KH_FINE = np.logspace(-2, 2, 385)
#: kH grid of the count-vs-kH curve: every 8th point of :data:`KH_FINE` (49 points, 12 per decade)
KH_COUNT = KH_FINE[::8].copy()

#: default kH: at the paper's defaults (gamma = 3, f = 0.9, beta = 0.3, eta = inf) there is an unstable root
#: faster than c_d besides the Rayleigh root (docs/physics.md §3)
KH_DEFAULT = 0.45

#: default window (the model's defaults): |Re z| <= re_max, im_min <= Im z <= im_max
WINDOW_DEFAULT = (5.0, 1e-4, 2.0)
#: allowed window: 0 < re_max <= RE_MAX_LIMIT, IM_MIN_FLOOR <= im_min < im_max <= IM_MAX_LIMIT. Below Im z ~ 1e-5
#: the dense real-axis poles of finite eta make the count take seconds per kH or fail (model.modes docstring)
RE_MAX_LIMIT = 20.0
IM_MIN_FLOOR = 1e-5
IM_MAX_LIMIT = 10.0

#: at most this many roots are listed in the readout (all of them are in the plot and the CSV)
TABLE_ROWS = 12


EQUATION = (r"$F(z;\,kH) = \gamma\,\big(G_x + i f\,G_y\big) + i z\left[1 + \frac{\Delta - 1}{1 - i\,\xi\,z\,kH}\right]"
            r" = 0, \qquad z = c/c_s$")

HELP = f"""
**All branches.** Every root of the dispersion relation F(z; kH) = 0 with Im z > 0 (an unstable mode) in the
window |Re z| ≤ max |Re z|, min Im z ≤ Im z ≤ max Im z, not only the Rayleigh branch of the *Spectrum* tab.
The number of roots is certified by the argument principle (F has no poles in the upper half-plane), then each
root is located and polished; hover over a root for z and its error estimate. The diamond is the Rayleigh-branch
root at the same kH, drawn even when it is stable (Im z < 0) or outside the window. Grey lines: Re z = ±1 (c = ±c_s)
and ±1/β (c = ±c_d), where F has branch points. The lower plot counts the unstable roots on a log kH grid; the
shaded bands are where the Rayleigh branch itself is unstable, the dashed curve counts the other branches.
The star is the fastest root of every branch at this kH in the complete window (`model.fastest_mode`: no root
with Im z above the growth floor lies outside it), drawn even when it lies outside the window you set; the orange
curve counts every root above that floor in the complete window (refused at finite η, where that window reaches
millions in |Re z| next to the layers' poles).

Reference cases (docs/physics.md §3; f = 0.9, β = 0.3, Δ = 1, γ = 3):
η = ∞, kH = 0.45: besides the Rayleigh root, a root z ≈ 3.5335 + 0.0759i faster than c_d.
η = 3, kH = 0.45: the Rayleigh branch is stable, but a backward-travelling root z ≈ −1.8615 + 0.0481i is not
(that branch is unstable for about 0.29 < kH < 0.76).
η = 10, kH = 0.77: ten roots; the fastest-growing one, 2.3954 + 0.0380i (between c_s and c_d), is not the Rayleigh
root 0.8847 + 0.0105i. For large finite η many roots sit just above the real axis (Im z ~ 1e-4, next to the dense
real-axis poles): how many are counted depends on min Im z (allowed down to {IM_MIN_FLOOR:g}).
"""

RE_DIM = hv.Dimension("re", label="Re[c/c_s]")
IM_DIM = hv.Dimension("im", label="Im[c/c_s]")
ERROR_DIM = hv.Dimension("error", label="error estimate |Δz|")
RESIDUAL_DIM = hv.Dimension("residual", label="|F|/scale")
RB_ERROR_DIM = hv.Dimension("rb_error", label="error estimate |Δz|")
RB_RESIDUAL_DIM = hv.Dimension("rb_residual", label="|F|/scale")
COUNT_DIM = hv.Dimension("count", label="unstable roots in window")
KH_DIM = hv.Dimension("kH")

ROOT_COLOR = "#1f4e79"
RAYLEIGH_COLOR = "#b2182b"
FASTEST_COLOR = "#e08214"


def _fmt_z(z: complex, digits: int = 10) -> str:
    if not (np.isfinite(z.real) and np.isfinite(z.imag)):
        return "—"
    sign = "−" if z.imag < 0 else "+"
    return f"{z.real:.{digits}g} {sign} {abs(z.imag):.{digits}g}i"


def _num(x: float) -> str:
    """A CSV number: the shortest repr that round-trips, empty for NaN (a masked or failed value)."""
    return repr(float(x)) if np.isfinite(x) else ""


def window_problem(re_max: float | None, im_min: float | None, im_max: float | None) -> str:
    """Why the window cannot be used ("" if it can); the user's values are only compared, never evaluated."""
    vals = {"max |Re z|": re_max, "min Im z": im_min, "max Im z": im_max}
    for name, v in vals.items():
        if v is None or not isinstance(v, (int, float)) or not math.isfinite(v):
            return f"{name}: enter a finite number"
    if not 0 < re_max <= RE_MAX_LIMIT:
        return f"max |Re z| must be in (0, {RE_MAX_LIMIT:g}]; got {re_max:g}"
    if not IM_MIN_FLOOR <= im_min:
        return (f"min Im z must be ≥ {IM_MIN_FLOOR:g} (closer to the real axis the poles of F make the count "
                f"slow or impossible); got {im_min:g}")
    if not im_max <= IM_MAX_LIMIT:
        return f"max Im z must be ≤ {IM_MAX_LIMIT:g}; got {im_max:g}"
    if not im_min < im_max:
        return f"min Im z ({im_min:g}) must be below max Im z ({im_max:g})"
    return ""


def _in_window(z: np.ndarray, window: tuple[float, float, float]) -> np.ndarray:
    """True where z lies in the closed window (False for NaN)."""
    re_max, im_min, im_max = window
    with np.errstate(invalid="ignore"):
        return (np.abs(z.real) <= re_max) & (z.imag >= im_min) & (z.imag <= im_max)


def _runs(kh: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """(first kH, last kH) of every run of consecutive True values of mask."""
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return [(float(kh[a]), float(kh[b])) for a, b in zip(starts, stops, strict=True)]


# --------------------------------------------------------------------------------------------
# cached model calls, one per dependency group
# --------------------------------------------------------------------------------------------


@pn.cache(max_items=256)
def compute_roots(kH: float, gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float,
                  re_max: float, im_min: float, im_max: float) -> dict:
    """Every unstable root at kH in the window, with its residual |F|/scale and error estimate
    (:func:`model.root_error_estimate`). A model failure (RuntimeError, ValueError) gives no roots and its message.
    """
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    message = ""
    try:
        z = np.asarray(model.unstable_modes(kH, **p, re_max=re_max, im_min=im_min, im_max=im_max), np.complex128)
    except (RuntimeError, ValueError) as exc:
        z, message = np.empty(0, np.complex128), str(exc)
    residual, error = model.root_error_estimate(z, kH, **p)
    return {"kH": kH, "z": z, "residual": residual, "error": error, "message": message}


@pn.cache(max_items=256)
def compute_rayleigh_point(kH: float, gamma: float, f: float, beta: float, eta: float, Delta: float,
                           xi: float) -> dict:
    """The Rayleigh-branch root at kH with the model's status, residual and error estimate."""
    r = model.rayleigh_branch(kH, gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    return {"z": complex(r.z), "status": int(r.status), "residual": float(r.residual), "error": float(r.error)}


@pn.cache(max_items=64)
def compute_rayleigh_curve(gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float) -> dict:
    """The Rayleigh branch on :data:`KH_FINE` and the kH bands where it is unstable (Im z > 0)."""
    r = model.rayleigh_branch(KH_FINE, gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    with np.errstate(invalid="ignore"):
        unstable = r.z.imag > 0
    return {"kH": KH_FINE, "z": r.z, "status": r.status, "bands": _runs(KH_FINE, unstable),
            "masked": int(np.count_nonzero(r.status != 0))}


@pn.cache(max_items=256)
def compute_fastest(kH: float, gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float) -> dict:
    """The fastest root of every branch at kH in the complete window (model.fastest_mode, its default floor): z,
    family, status, and the window at the floor."""
    m = model.fastest_mode(kH, gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi, count=False)
    return {"z": complex(m.z), "family": int(m.family), "status": int(m.status), "re_max": float(m.re_max),
            "im_max": float(m.im_max), "floor": float(m.floor)}


@pn.cache(max_items=32)
def compute_floor_count(gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float) -> dict:
    """On :data:`KH_COUNT`: the number of roots of every branch with Im z >= the floor in the complete window (-1
    where refused: finite eta, the window at the floor too wide) and the fastest root's Im z (model.fastest_mode)."""
    m = model.fastest_mode(KH_COUNT, gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi, count=True)
    count = np.where(m.count >= 0, m.count, np.nan).astype(float)
    return {"kH": KH_COUNT, "count": count, "growth": np.where(m.status == 0, m.growth, np.nan),
            "refused": int(np.count_nonzero(m.count < 0)), "floor": float(m.floor)}


@pn.cache(max_items=32)
def compute_count_curve(gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float,
                        re_max: float, im_min: float, im_max: float) -> dict:
    """Certified number of unstable roots in the window on :data:`KH_COUNT` (NaN where the model failed), and
    the same count without the Rayleigh-branch root (where that root is known)."""
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    window = (re_max, im_min, im_max)
    count = np.full(KH_COUNT.shape, np.nan)
    failures: dict[str, int] = {}
    for i, kh in enumerate(KH_COUNT):
        try:
            count[i] = model.unstable_count(float(kh), **p, re_max=re_max, im_min=im_min, im_max=im_max)
        except (RuntimeError, ValueError) as exc:
            failures[str(exc)] = failures.get(str(exc), 0) + 1
    z_r = compute_rayleigh_curve(*p.values())["z"][::8]
    with np.errstate(invalid="ignore"):
        other = np.where(np.isfinite(z_r), count - _in_window(z_r, window), np.nan)
    return {"kH": KH_COUNT, "count": count, "other": other, "z_rayleigh": z_r,
            "rayleigh_in_window": _in_window(z_r, window), "failures": failures}


# --------------------------------------------------------------------------------------------
# the scene
# --------------------------------------------------------------------------------------------


class AllBranchesScene(pn.viewable.Viewer):
    """Widgets, the z-plane plot, the count-vs-kH plot, the readout and the CSV downloads."""

    params = param.ClassSelector(class_=SpectrumParams)

    # user-facing parameters of this scene (the physical ones are shared, in `params`)
    log10_kH = Physical(math.log10(KH_DEFAULT), bounds=(-2.0, 2.0), step=0.01, label="kH", log10=True, url="kH",
                        doc="kH: wavenumber k times the upper block's height H (slider: log10 kH)")
    re_max = Physical(WINDOW_DEFAULT[0], allow_None=True, step=0.5, label="window: max |Re z|", widget="input",
                      url="re_max", doc="half-width of the window in Re z (validated, see window_problem)")
    im_min = Physical(WINDOW_DEFAULT[1], allow_None=True, step=1e-4, label="window: min Im z", widget="input",
                      url="im_min", doc="lower edge of the window in Im z (validated)")
    im_max = Physical(WINDOW_DEFAULT[2], allow_None=True, step=0.1, label="window: max Im z", widget="input",
                      url="im_max", doc="upper edge of the window in Im z (validated)")

    #: the URL holds kH and the window only where they differ from the defaults
    URL_CHANGED_ONLY = True

    # normalised keys, one per dependency group; a view depends only on the keys it uses
    args_key = param.Tuple(default=None, length=6, allow_None=True, precedence=-1)
    kH_key = param.Number(default=None, allow_None=True, precedence=-1)
    window_key = param.Tuple(default=None, length=3, allow_None=True, precedence=-1)
    #: why the typed window is not used ("" if it is)
    window_message = param.String(default="", precedence=-1)
    #: False while the tab is hidden. Panel's dynamic Tabs keep a tab's plots alive once it has been shown, so
    #: without this a change of the shared parameters on another tab would recompute this (costly) tab; while
    #: inactive the keys are frozen and the change is applied once when the tab is shown again (set by the page)
    active = param.Boolean(default=True, precedence=-1)

    def __init__(self, **kwargs):
        if "params" not in kwargs:
            kwargs["params"] = SpectrumParams()
        super().__init__(**kwargs)
        self.window_alert = pn.pane.Alert("", alert_type="danger", visible=False, sizing_mode="stretch_width")
        self._update_keys()
        self.params.param.watch(self._update_keys, [*physical_parameters(SpectrumParams), "eta_infinite", "dragging"])
        self.param.watch(self._update_keys, [*physical_parameters(AllBranchesScene), "active"])
        self.zplane_dmap = hv.DynamicMap(self.zplane_plot)
        self.count_dmap = hv.DynamicMap(self.count_plot)
        self.roots_download = csv_download(self.roots_csv, "asymslide_all_branches_roots.csv", "Download roots (CSV)")
        self.count_download = csv_download(self.count_csv, "asymslide_all_branches_count.csv",
                                           "Download count vs kH (CSV)")

    def _update_keys(self, *_events) -> None:
        """Recompute the normalised keys from the parameters; a view updates only if a key it uses changed."""
        if not self.active or self.params.dragging:  # a held shared slider: the (costly) roots wait for its release
            return
        args = self.params.model_args()
        kh = from_log10(self.log10_kH)
        message = window_problem(self.re_max, self.im_min, self.im_max)
        if message:
            window = self.window_key if self.window_key is not None else WINDOW_DEFAULT
            message += f" — still showing the window {self._window_text(window)}"
        else:
            window = (float(self.re_max), float(self.im_min), float(self.im_max))
        with param.parameterized.batch_call_watchers(self):
            if args != self.args_key:
                self.args_key = args
            if kh != self.kH_key:
                self.kH_key = kh
            if window != self.window_key:
                self.window_key = window
            if message != self.window_message:
                self.window_message = message
        self.window_alert.object = message
        self.window_alert.visible = bool(message)

    @staticmethod
    def _window_text(window: tuple[float, float, float]) -> str:
        re_max, im_min, im_max = window
        return f"|Re z| ≤ {re_max:g}, {im_min:g} ≤ Im z ≤ {im_max:g}"

    # -- data ----------------------------------------------------------------------------------

    def roots(self) -> dict:
        """Unstable roots at the current kH and window (cached)."""
        return compute_roots(self.kH_key, *self.args_key, *self.window_key)

    def rayleigh_point(self) -> dict:
        """Rayleigh-branch root at the current kH (cached)."""
        return compute_rayleigh_point(self.kH_key, *self.args_key)

    def count_curve(self) -> dict:
        """Unstable-root count on :data:`KH_COUNT` for the current window (cached)."""
        return compute_count_curve(*self.args_key, *self.window_key)

    def rayleigh_curve(self) -> dict:
        """Rayleigh branch on :data:`KH_FINE` (cached)."""
        return compute_rayleigh_curve(*self.args_key)

    def fastest(self) -> dict:
        """The fastest root of every branch at the current kH, in the complete window (cached)."""
        return compute_fastest(self.kH_key, *self.args_key)

    def floor_count(self) -> dict:
        """Roots above the floor in the complete window on :data:`KH_COUNT` (cached)."""
        return compute_floor_count(*self.args_key)

    @staticmethod
    def _rayleigh_index(roots: np.ndarray, z_r: complex) -> int | None:
        """Index of the Rayleigh-branch root among the unstable roots (both are converged roots of the same F,
        so they agree to ~1e-12 relative when they are the same root), or None."""
        if roots.size == 0 or not np.isfinite(z_r):
            return None
        d = np.abs(roots - z_r)
        i = int(np.argmin(d))
        return i if d[i] <= 1e-8 * max(1.0, abs(z_r)) else None

    # -- plots ---------------------------------------------------------------------------------

    @param.depends("args_key", "kH_key", "window_key")
    def zplane_plot(self) -> hv.Overlay:
        """Roots, Rayleigh-branch root, window, wave-speed guides and zero line in the z-plane."""
        d, r, fm = self.roots(), self.rayleigh_point(), self.fastest()
        re_max, im_min, im_max = self.window_key
        beta = self.args_key[2]
        z, z_r = d["z"], r["z"]
        fast = [fm["z"]] if fm["status"] == 0 else []
        fastest = hv.Scatter({"re": np.real(fast), "im": np.imag(fast)}, RE_DIM, [IM_DIM],
                             label="fastest root, every branch").opts(
            color=FASTEST_COLOR, marker="star", size=20, fill_alpha=0.35, line_color="black", tools=["hover"],
            hover_tooltips=[("fastest root (every branch)", "@re{%.10g} + @im{%.10g}i")],
            hover_formatters={"@re": "printf", "@im": "printf"})
        roots = hv.Scatter({"re": z.real, "im": z.imag, "error": d["error"], "residual": d["residual"]},
                           RE_DIM, [IM_DIM, ERROR_DIM, RESIDUAL_DIM], label="unstable roots").opts(
            color=ROOT_COLOR, size=8, tools=["hover"],
            hover_tooltips=[("z", "@re{%.10g} + @im{%.10g}i"), ("error estimate", "@error{%.1e}"),
                            ("|F|/scale", "@residual{%.1e}")],
            hover_formatters={"@re": "printf", "@im": "printf", "@error": "printf", "@residual": "printf"})
        shown = [z_r] if np.isfinite(z_r) else []
        rayleigh = hv.Scatter({"re": np.real(shown), "im": np.imag(shown), "rb_error": [r["error"]] * len(shown),
                               "rb_residual": [r["residual"]] * len(shown)},
                              RE_DIM, [IM_DIM, RB_ERROR_DIM, RB_RESIDUAL_DIM], label="Rayleigh-branch root").opts(
            color=RAYLEIGH_COLOR, marker="diamond", size=18, fill_alpha=0.0, line_width=2, tools=["hover"],
            hover_tooltips=[("Rayleigh branch z", "@re{%.10g} + (@im{%.10g})i"), ("error estimate", "@rb_error{%.1e}"),
                            ("|F|/scale", "@rb_residual{%.1e}")],
            hover_formatters={"@re": "printf", "@im": "printf", "@rb_error": "printf", "@rb_residual": "printf"})
        window = hv.Bounds((-re_max, im_min, re_max, im_max), label="window").opts(
            color="#666666", line_dash="dashed", line_width=1)
        zero = hv.HLine(0.0).opts(color="black", line_width=1)
        c_s = hv.VLines([-1.0, 1.0], label="Re z = ±1 (c_s)").opts(color="#999999", line_dash="dashed", line_width=1)
        c_d = hv.VLines([-1.0 / beta, 1.0 / beta], label="Re z = ±1/β (c_d)").opts(
            color="#999999", line_dash="dotted", line_width=1.5)
        # view: the window's width, and in Im z the roots and the Rayleigh root (the window may be much taller)
        ims = np.concatenate((z.imag, np.imag(shown), np.imag(fast), [0.0, im_min]))
        lo, hi = float(ims.min()), float(ims.max())
        pad = 0.1 * (hi - lo) if hi > lo else 0.05
        xs = np.concatenate(([-re_max, re_max], np.real(shown), np.real(fast)))
        xpad = 0.04 * float(xs.max() - xs.min())
        title = f"z-plane at kH = {fmt(self.kH_key)}: {z.size} unstable root(s) in the window"
        return (window * zero * c_s * c_d * roots * rayleigh * fastest).opts(
            hv.opts.Overlay(responsive=True, height=380, title=title, legend_position="right", framewise=True,
                            xlabel=RE_DIM.label, ylabel=IM_DIM.label,
                            xlim=(float(xs.min()) - xpad, float(xs.max()) + xpad), ylim=(lo - pad, hi + pad)))

    @param.depends("args_key", "kH_key", "window_key")
    def count_plot(self) -> hv.Overlay:
        """Certified count vs kH (steps), count of the other branches, Rayleigh-unstable bands, current kH."""
        c, rc, d, fc = self.count_curve(), self.rayleigh_curve(), self.roots(), self.floor_count()
        bands = hv.VSpans(rc["bands"], label="Rayleigh branch unstable").opts(color="#f4a582", alpha=0.35)
        above = hv.Curve((fc["kH"], fc["count"]), KH_DIM, COUNT_DIM,
                         label=f"every root with Im z ≥ {fc['floor']:g} (complete window)").opts(
            interpolation="steps-mid", color=FASTEST_COLOR, line_width=2)
        total = hv.Curve((c["kH"], c["count"]), KH_DIM, COUNT_DIM, label="all roots in window").opts(
            interpolation="steps-mid", color=ROOT_COLOR, line_width=2)
        other = hv.Curve((c["kH"], c["other"]), KH_DIM, COUNT_DIM, label="other branches (all − Rayleigh)").opts(
            interpolation="steps-mid", color="#4d9221", line_width=1.5, line_dash="dashed")
        n_here = np.nan if d["message"] else float(d["z"].size)
        current = hv.VLine(self.kH_key).opts(color=RAYLEIGH_COLOR, line_width=1, line_dash="dotted")
        marker = hv.Scatter(([self.kH_key], [n_here]), KH_DIM, COUNT_DIM, label="current kH").opts(
            color=RAYLEIGH_COLOR, size=9, tools=["hover"])
        failed = sum(c["failures"].values())
        title = "Unstable roots vs kH" + (f" ({failed} grid point(s) failed: gaps)" if failed else "")
        if rc["masked"]:
            title += f" (Rayleigh branch masked at {rc['masked']} of {KH_FINE.size} kH)"
        if fc["refused"]:
            title += f"; above the floor: refused at {fc['refused']} of {KH_COUNT.size} kH (window too wide)"
        return (bands * total * other * above * current * marker).opts(
            hv.opts.Overlay(logx=True, responsive=True, height=300, title=title, legend_position="top_left",
                            framewise=True, xlabel="kH", ylabel=COUNT_DIM.label))

    # -- readout -------------------------------------------------------------------------------

    @param.depends("args_key", "kH_key", "window_key")
    def readout(self) -> str:
        """Markdown: kH and window, certified count, table of roots, where the Rayleigh-branch root is."""
        d, r = self.roots(), self.rayleigh_point()
        z = d["z"]
        lines = [f"**kH** = {fmt(self.kH_key, 6)}; window {self._window_text(self.window_key)}"]
        if d["message"]:
            lines.append(f"**Model error** no roots shown: {d['message']}")
        else:
            lines.append(f"**Unstable roots** {z.size} (certified by the argument principle)")
        idx = self._rayleigh_index(z, r["z"])
        if z.size:
            rows = ["| # | z = c/c_s | error | \\|F\\|/scale |", "|---|---|---|---|"]
            for i in range(min(z.size, TABLE_ROWS)):
                mark = " (Rayleigh)" if i == idx else ""
                rows.append(f"| {i + 1}{mark} | {_fmt_z(z[i], 8)} | {d['error'][i]:.1e} | {d['residual'][i]:.1e} |")
            if z.size > TABLE_ROWS:
                rows.append(f"| … | {z.size - TABLE_ROWS} more in the plot and the CSV | | |")
            lines.append("\n".join(rows))
        z_r = r["z"]
        if not np.isfinite(z_r):
            lines.append(f"**Rayleigh-branch root** masked: {model.STATUS.get(r['status'], 'unknown reason')}")
        else:
            where = f"z = {_fmt_z(z_r)} (error {r['error']:.1e})"
            if idx is not None:
                lines.append(f"**Rayleigh-branch root** {where}: root #{idx + 1} above")
            elif z_r.imag <= 0:
                lines.append(f"**Rayleigh-branch root** {where}: stable (Im z ≤ 0), drawn below the window")
            else:
                lines.append(f"**Rayleigh-branch root** {where}: unstable but outside the window")
        lines.append(self._fastest_line(z))
        return "\n\n".join(lines)

    def _fastest_line(self, roots: np.ndarray) -> str:
        """Where the fastest root of every branch at this kH is (complete window, model.fastest_mode): one of the
        roots listed, or outside the window set (reported with its z), or none above the floor, or refused."""
        fm = self.fastest()
        head = f"**Fastest root, every branch** (complete window |Re z| ≤ {fm['re_max']:.4g}, Im z ≥ {fm['floor']:g})"
        if fm["status"] != 0:
            return f"{head}: {model.MODE_STATUS[fm['status']]}"
        z = fm["z"]
        text = f"{head}: z = {_fmt_z(z, 8)}, {FAMILY_NAMES.get(fm['family'], 'family unknown')}"
        idx = self._rayleigh_index(roots, z)  # the same root within 1e-8 relative
        if idx is not None:
            return f"{text}: root #{idx + 1} above"
        if _in_window(np.array([z]), self.window_key)[0]:
            return f"{text}: in the window"
        return f"{text}: **the fastest mode lies outside the window** (drawn as a star; widen the window to list it)"

    # -- CSV -----------------------------------------------------------------------------------

    def _header(self) -> list[str]:
        gamma, f, beta, eta, Delta, xi = self.args_key
        re_max, im_min, im_max = self.window_key
        return [f"# asymslide, all branches: gamma={gamma!r} f={f!r} beta={beta!r} eta={eta!r} Delta={Delta!r} "
                f"xi={xi!r}", f"# window: re_max={re_max!r} im_min={im_min!r} im_max={im_max!r}"]

    def roots_csv(self) -> io.StringIO:
        """What the z-plane plot shows: every unstable root, then the Rayleigh-branch root (kind rayleigh_branch)."""
        d, r = self.roots(), self.rayleigh_point()
        z = d["z"]
        idx = self._rayleigh_index(z, r["z"])
        lines = [*self._header(), f"# kH={self.kH_key!r} count={z.size}"]
        if d["message"]:
            lines.append(f"# model error: {d['message']}")
        lines.append("kind,kH,re_z,im_z,error_estimate,residual,on_rayleigh_branch")
        for i in range(z.size):
            lines.append(",".join(["unstable_root", _num(self.kH_key), _num(z[i].real), _num(z[i].imag),
                                   _num(d["error"][i]), _num(d["residual"][i]), str(int(i == idx))]))
        z_r = r["z"]
        lines.append(",".join(["rayleigh_branch", _num(self.kH_key), _num(z_r.real), _num(z_r.imag), _num(r["error"]),
                               _num(r["residual"]), "1"]))
        fm = self.fastest()  # the fastest root of every branch in the complete window (model.fastest_mode)
        lines.append(",".join(["fastest_root_every_branch", _num(self.kH_key), _num(fm["z"].real), _num(fm["z"].imag),
                               "", "", str(int(self._rayleigh_index(np.array([z_r]), fm["z"]) is not None))]))
        return io.StringIO("\n".join(lines) + "\n")

    def count_csv(self) -> io.StringIO:
        """What the count plot shows: the count and the other-branch count on the kH grid, the Rayleigh root there,
        the bands where the Rayleigh branch is unstable and the current kH (comment lines)."""
        c, rc, d = self.count_curve(), self.rayleigh_curve(), self.roots()
        bands = "; ".join(f"{a!r}..{b!r}" for a, b in rc["bands"]) or "none"
        lines = [*self._header(), f"# Rayleigh branch unstable (Im z > 0) for kH in: {bands}",
                 f"# current kH={self.kH_key!r} count={d['z'].size if not d['message'] else 'failed'}"]
        lines.extend(f"# {n} grid point(s) failed: {msg}" for msg, n in c["failures"].items())
        fc = self.floor_count()
        lines.append(f"# count_above_floor: every root with Im z >= {fc['floor']!r} in the complete window "
                     "(model.fastest_mode; empty where refused); fastest_im_z: the fastest root's Im z")
        lines.append("kH,count,other_branches,rayleigh_re_z,rayleigh_im_z,rayleigh_in_window,count_above_floor,"
                     "fastest_im_z")

        for i, kh in enumerate(c["kH"]):
            count = "" if not np.isfinite(c["count"][i]) else str(int(c["count"][i]))
            other = "" if not np.isfinite(c["other"][i]) else str(int(c["other"][i]))
            z_r = c["z_rayleigh"][i]
            above = "" if not np.isfinite(fc["count"][i]) else str(int(fc["count"][i]))
            lines.append(",".join([_num(kh), count, other, _num(z_r.real), _num(z_r.imag),
                                   str(int(c["rayleigh_in_window"][i])), above, _num(fc["growth"][i])]))
        return io.StringIO("\n".join(lines) + "\n")

    # -- layout --------------------------------------------------------------------------------

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this scene (from the declarations): the kH slider updates on release, the window
        inputs on change."""
        return make_widgets(self)

    def __panel__(self) -> pn.viewable.Viewable:
        """The tab: shared and own widgets, window message and readout (left); plots, downloads, help (right)."""
        own = self.make_widgets()
        controls = pn.Column(
            heading("Parameters"), *self.params.make_widgets().values(),
            heading("Wavenumber and window"), *own.values(), self.window_alert,
            pn.panel(self.readout, lazy=True, sizing_mode="stretch_width"),
            width=360,
        )
        plots = pn.Column(
            pn.pane.LaTeX(EQUATION, renderer="katex", styles=EQUATION_STYLES),
            # linked_axes=False: the kH axis of the Spectrum tab (same page, same dimension name) must not
            # impose its range here
            pn.pane.HoloViews(self.zplane_dmap, sizing_mode="stretch_width", linked_axes=False),
            self.roots_download,
            pn.pane.HoloViews(self.count_dmap, sizing_mode="stretch_width", linked_axes=False),
            self.count_download,
            pn.pane.Markdown(HELP, sizing_mode="stretch_width"),
            reference_card("3"),
            sizing_mode="stretch_width",
        )
        return scene_layout(controls, plots, "All branches")
