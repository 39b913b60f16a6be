"""Scene "Rupture fronts" (supplement S-V C; docs/physics.md §13): the slip velocity behind a steady mode-II rupture
front with an exponential cohesive zone, its peak v_m against the front speed c/c_R, and the normal-stress change
Δσ_yy/σ₀ that Eq. dsigma predicts at v_m for a thin block of width W (kW = 3, 4, 5 as Fig. 3c).

The app computes no physics: the cached ``compute_*`` functions only call the public API of :mod:`model`, one
function per dependency group, so that moving c/c_R recomputes the profile and the point values but none of the
curves over c/c_R, changing σ₀ recomputes only the Δσ_yy/σ₀ curves, and changing one kW only its curve. Bad input
(c ≥ c_R, a Poisson ratio outside (−1, 0.5), a non-positive Γ, …) empties the views it affects and shows the
model's message; the session keeps working.

While the c/c_R slider is held, the plots follow it without a HoloViews redraw: the new profile and markers are
written into the Bokeh sources on the page (:mod:`app.live`, a few ms instead of ~0.3 s for the four plots), with the
y range of (a) fitted by its hook as a redraw fits it; where that cannot show what a redraw would (bad input, a
marker that would widen a plot's range), HoloViews redraws.
"""

from __future__ import annotations

import html
import io

import holoviews as hv
import numpy as np
import panel as pn
import param

from asymslide import model

from . import live
from .docs import reference_card
from .exports import csv_download, csv_table
from .layout import controls_column, material_readout, scene_layout, shared_material_widgets
from .params import CUSTOM, LabParams, RuptureParams
from .plotting import PALETTE, fit_y_hook, fmt
from .thin_on_thick import material_readout_with_nu

#: the plates of the experiment are thin: plane stress (model.PAPER_DEFAULTS.plane; Eq. dsigma's thin block is too)
PLANE = model.PAPER_DEFAULTS.plane

#: c/c_R grid of the curves (b)-(d), up to the slider's end (RuptureParams.c_over_cR), so that the current speed's
#: markers lie on the curves; v_m diverges at c_R
C_RATIO = np.linspace(0.01, 0.999, 200)
#: positions of the slip-velocity profile in units of X_c0: behind the tip to -4 X_c0, points crowded towards the
#: tip (where X_c(c) = X_c0/f_II shrinks as c -> c_R), and a little ahead of it, where v = 0
PROFILE_GRID = np.concatenate([-4.0 * np.linspace(1.0, 0.0, 600) ** 2, np.linspace(0.0, 0.5, 41)[1:]])

X_LABEL = "x [mm] (from the tip; x < 0 behind it)"
V_LABEL = "v [m/s]"
C_LABEL = "c/c_R"
VM_LABEL = "v_m [m/s]"
DS_LABEL = "Δσ_yy/σ₀ at v_m"
#: the y-axis label of (c): Δσ_yy/σ₀ is a ratio; its axis is logarithmic (the curves span 10⁻² to 10⁰ at the
#: paper's inputs, rising steeply towards c_R: a linear axis flattened them to 0)
DS_LOG_LABEL = "Δσ_yy/σ₀ at v_m (dimensionless, log scale)"

ASSUMPTIONS = """\
**Assumptions** (docs/physics.md §13.1; model.rupture):
1. *Thin-on-thin*: a steady 2-D mode-II shear crack moving at constant c between two identical blocks of infinite
   height; the geometric asymmetry enters only afterwards, through Eq. dsigma (thin block of width W on a thick one).
2. *Plane stress* (the thin PMMA plates): ν₂D = ν/(1 + ν), c_R the plane-stress Rayleigh speed.
3. *Exponential cohesive law with its tail to −∞*: τ − τ_r = τ_p e^{x/X_c} for all x < 0 behind the tip
   (weakening is never complete).
4. *Small-scale yielding*: X_c ≪ crack length; the far field is the K_II field.
5. *Constant Γ and c-independent τ_p*, hence X_c(c) = X_c0/f_II(c) (the contraction the supplement reports).
6. *Sub-Rayleigh*: 0 < c < c_R.
7. *Density*: ρ enters only through μ = ρ c_s²; PMMA's ρ = 1180 kg/m³ is an assumption (the paper gives none).
"""


def _sources() -> str:
    rows = "\n".join(f"- **{k}**: {v}" for k, v in model.RuptureParameters.SOURCES.items())
    return "**The paper's inputs (the defaults) and their sources** (model.PAPER_DEFAULTS):\n\n" + rows


# --------------------------------------------------------------------------------------------
# cached model calls, one per dependency group
# --------------------------------------------------------------------------------------------


@pn.cache(max_items=64)
def compute_speeds(rho: float, c_s: float, nu: float) -> dict:
    """c_R (plane stress) and μ = ρ c_s² of the material, or the model's message."""
    try:
        c_R = float(model.rayleigh_wave_speed(c_s=c_s, nu=nu, plane=PLANE))
        mu = float(model.shear_modulus(rho, c_s))
    except ValueError as exc:
        return {"error": str(exc)}
    return {"c_R": c_R, "mu": mu}


@pn.cache(max_items=256)
def compute_front(c_ratio: float, Gamma: float, X_c0: float, rho: float, c_s: float, nu: float) -> dict:
    """The front at c = c_ratio c_R: c, f_II, X_c, τ_p, K_II, v_m and its position x_m, E′ (SI units)."""
    sp = compute_speeds(rho, c_s, nu)
    if "error" in sp:
        return sp
    c, mu = c_ratio * sp["c_R"], sp["mu"]
    kw = dict(Gamma=Gamma, X_c0=X_c0, mu=mu, c_s=c_s, nu=nu, plane=PLANE)
    try:
        tau_p = float(model.peak_cohesive_stress(Gamma=Gamma, X_c0=X_c0, mu=mu, nu=nu, plane=PLANE))
    except ValueError as exc:
        return {"error": str(exc)}
    try:
        f_ii = float(model.mode_ii_universal_function(c, c_s=c_s, nu=nu, plane=PLANE))
        x_c = float(model.cohesive_zone_size(c, X_c0=X_c0, c_s=c_s, nu=nu, plane=PLANE))
        k_ii = float(model.stress_intensity_factor(c, **kw))
        v_m = float(model.peak_slip_velocity(c, **kw))
        x_m = float(model.peak_slip_location(c, X_c0=X_c0, c_s=c_s, nu=nu, plane=PLANE))
        e_prime = float(model.plane_modulus(mu=mu, nu=nu, plane=PLANE))
    except ValueError as exc:  # the rupture speed: say which c/c_R the model refused
        return {"error": f"c/c_R = {c_ratio:g}: {exc}"}
    return {"c": c, "c_R": sp["c_R"], "mu": mu, "f_II": f_ii, "X_c": x_c, "tau_p": tau_p, "K_II": k_ii, "v_m": v_m,
            "x_m": x_m, "E_prime": e_prime}


@pn.cache(max_items=64)
def compute_profile(c_ratio: float, Gamma: float, X_c0: float, rho: float, c_s: float, nu: float) -> dict:
    """The slip velocity v(x) [m/s] on x = :data:`PROFILE_GRID` X_c0 [m]."""
    front = compute_front(c_ratio, Gamma, X_c0, rho, c_s, nu)
    if "error" in front:
        return front
    x = PROFILE_GRID * X_c0
    v = model.slip_velocity_profile(x, c=front["c"], Gamma=Gamma, X_c0=X_c0, mu=front["mu"], c_s=c_s, nu=nu,
                                    plane=PLANE)
    return {"x": x, "v": np.asarray(v, float)}


@pn.cache(max_items=64)
def compute_vm_curve(Gamma: float, X_c0: float, rho: float, c_s: float, nu: float) -> dict:
    """v_m [m/s] on c = :data:`C_RATIO` c_R."""
    sp = compute_speeds(rho, c_s, nu)
    if "error" in sp:
        return sp
    c = C_RATIO * sp["c_R"]
    try:
        v_m = model.peak_slip_velocity(c, Gamma=Gamma, X_c0=X_c0, mu=sp["mu"], c_s=c_s, nu=nu, plane=PLANE)
    except ValueError as exc:
        return {"error": str(exc)}
    return {"c_ratio": C_RATIO, "c": c, "v_m": np.asarray(v_m, float)}


@pn.cache(max_items=128)
def compute_stress_curve(kW: float, sigma0: float, Gamma: float, X_c0: float, rho: float, c_s: float,
                         nu: float) -> dict:
    """Δσ_yy/σ₀ at v_m (Eq. dsigma) on c = :data:`C_RATIO` c_R for one kW."""
    sp = compute_speeds(rho, c_s, nu)
    if "error" in sp:
        return sp
    try:
        ds = model.relative_normal_stress_change_at_peak_slip(C_RATIO * sp["c_R"], kW=kW, sigma0=sigma0, Gamma=Gamma,
                                                               X_c0=X_c0, mu=sp["mu"], c_s=c_s, nu=nu)
    except ValueError as exc:  # Eq. dsigma's thin-on-thick part has a narrower domain (nu >= 0)
        return {"error": f"Eq. dsigma (thin-on-thick): {exc}"}
    return {"c_ratio": C_RATIO, "ds": np.asarray(ds, float)}


@pn.cache(max_items=256)
def compute_stress_point(c_ratio: float, kW: float, sigma0: float, Gamma: float, X_c0: float, rho: float,
                         c_s: float, nu: float) -> dict:
    """Δσ_yy/σ₀ at v_m at the current c for one kW."""
    front = compute_front(c_ratio, Gamma, X_c0, rho, c_s, nu)
    if "error" in front:
        return front
    try:
        ds = model.relative_normal_stress_change_at_peak_slip(front["c"], kW=kW, sigma0=sigma0, Gamma=Gamma,
                                                               X_c0=X_c0, mu=front["mu"], c_s=c_s, nu=nu)
    except ValueError as exc:
        return {"error": str(exc)}
    return {"ds": float(ds)}


# --------------------------------------------------------------------------------------------
# the scene
# --------------------------------------------------------------------------------------------


def _identity(values: np.ndarray) -> np.ndarray:
    return values


def _positive(values: np.ndarray) -> np.ndarray:
    """`values` with those <= 0 as NaN: gaps on a log axis (Bokeh would otherwise draw them at the axis' end)."""
    values = np.asarray(values, float)
    return np.where(values > 0, values, np.nan)


def _overlay(layers: list[hv.Element], **options: object) -> hv.Overlay:
    return hv.Overlay(layers).opts(hv.opts.Overlay(responsive=True, framewise=True, **options))


def profile_title(c_ratio: float) -> str:
    """The title of (a) at c = `c_ratio` c_R."""
    return f"(a) Slip velocity behind the tip at c = {fmt(c_ratio)} c_R"


def marker_key(i: int) -> live.LayerKey:
    """The layer of the current-c marker of the `i`-th kW in (c) and (d): the first has the legend entry, the others
    no label (app.live addresses them by their order)."""
    return "current c" if i == 0 else ("", i - 1)


def _inside(value: float, values: np.ndarray) -> bool:
    """Whether a marker at `value` lies within the finite `values` of the curves beside it (a NaN is not drawn): then
    it does not change the range HoloViews computes for the plot."""
    if np.isnan(value):
        return True
    finite = values[np.isfinite(values)]
    return bool(np.isfinite(value) and finite.size and finite.min() <= value <= finite.max())


class RuptureScene(pn.viewable.Viewer):
    """Widgets, plots (a)-(d), readout and messages for one :class:`RuptureParams`."""

    params = param.ClassSelector(class_=RuptureParams)
    #: the page's shared material constants (the material, ρ, c_s, σ₀; the Lab-units panel's)
    material = param.ClassSelector(class_=LabParams)
    #: the model arguments per dependency group, SI units; a view depends only on the keys it uses
    front_key = param.Tuple(default=None, length=6, allow_None=True, precedence=-1)  # (c/c_R, Γ, X_c0, ρ, c_s, ν)
    curve_key = param.Tuple(default=None, length=5, allow_None=True, precedence=-1)  # (Γ, X_c0, ρ, c_s, ν)
    stress_key = param.Tuple(default=None, length=4, allow_None=True, precedence=-1)  # (σ₀, kW₁, kW₂, kW₃)
    #: counts HoloViews' redraws at a new front_key (the plots depend on it, not on front_key): while the c/c_R slider
    #: is held, the plots on the page follow it without one (app.live)
    drawn = param.Integer(default=0, precedence=-1)

    def __init__(self, **kwargs) -> None:
        kwargs.setdefault("params", RuptureParams())
        kwargs.setdefault("material", LabParams())
        super().__init__(**kwargs)
        #: the plot panes by name (profile, vm, stress, stress_vm) once built: a held slider writes into them
        self.panes: dict[str, pn.pane.HoloViews] = {}
        self._shown: tuple | None = None  # the front_key the plots on the page show (drawn or written)
        self.follow = live.Follow(self._follow, self._redraw)
        self._update_keys()
        self.params.param.watch(self._update_keys, [n for n in self.params.param if n != "name"])
        self.material.param.watch(self._update_keys, ["rho", "c_s", "sigma0_MPa"])
        self.material.param.watch(self._material_chosen, "material")
        self.profile_dmap = hv.DynamicMap(self.profile_plot)
        self.vm_dmap = hv.DynamicMap(self.vm_plot)
        self.stress_dmap = hv.DynamicMap(self.stress_plot)
        self.stress_vm_dmap = hv.DynamicMap(self.stress_vm_plot)

    def _material_chosen(self, event: param.parameterized.Event) -> None:
        """A material preset chosen (in any scene): ν becomes its ν, as ρ and c_s become its values."""
        if event.new != CUSTOM:
            self.params.nu = RuptureParams.material_nu(event.new)

    def _update_keys(self, *events) -> None:
        """The model arguments from the parameters (a held slider's moves: read on the next turn, app.live.Follow)."""
        if events and self.follow.defer(self._update_keys):
            return
        p, m = self.params, self.material
        curve = (float(p.Gamma), p.X_c0_mm * 1e-3, float(m.rho), float(m.c_s), float(p.nu))
        front = (float(p.c_over_cR), *curve)
        stress = (m.sigma0_MPa * 1e6, float(p.kW1), float(p.kW2), float(p.kW3))
        with param.parameterized.batch_call_watchers(self):
            for name, value in (("front_key", front), ("curve_key", curve), ("stress_key", stress)):
                if value != getattr(self, name):
                    setattr(self, name, value)
            if front != self._shown:  # in the same batch: a plot that also depends on another key redraws once
                self.follow.changed()

    # ----------------------------------------------------------------------------------------
    # following a held slider (app.live)
    # ----------------------------------------------------------------------------------------

    def _redraw(self) -> None:
        """HoloViews redraws the plots at front_key, unless the page shows it already."""
        if self.front_key != self._shown:
            self._shown = self.front_key
            self.drawn += 1

    def _follow(self) -> bool:
        """Write the plots of front_key into the page (:mod:`app.live`) when only c/c_R differs from what it shows;
        True if the page then shows front_key. False where a redraw would draw something else than new data in the
        same layers (bad input, other inputs, a marker outside the curves beside it, which widens a framewise range,
        plots not rendered): HoloViews redraws then."""
        front, shown = self.front_key, self._shown
        if front == shown:
            return True
        if (shown is None or front[1:] != shown[1:] or len(self.panes) < 4
                or not (self._pushable(shown) and self._pushable(front))):
            return False
        if not all(live.push(self.panes[name], layers, title=profile_title(front[0]) if name == "profile" else None)
                   for name, layers in self.live_layers(front).items()):
            return False
        self._shown = front
        return True

    def _fronts(self, front_key: tuple) -> tuple[dict, dict, dict, list[dict], list[dict]]:
        """front, profile, v_m curve, Δσ curves and Δσ points at `front_key` (the cached model calls)."""
        c, curve = front_key[0], front_key[1:]
        sigma0 = self.stress_key[0]
        curves = [compute_stress_curve(kw, sigma0, *curve) for kw in self.kWs()]
        points = [compute_stress_point(c, kw, sigma0, *curve) for kw in self.kWs()]
        return compute_front(*front_key), compute_profile(*front_key), compute_vm_curve(*curve), curves, points

    def _pushable(self, front_key: tuple) -> bool:
        """Whether the plots at `front_key` have every layer (no bad input) and each marker (and the cohesive zone)
        lies within the curves beside it: the framewise x ranges, and the y ranges of (b)-(d), are then those of the
        curves, which a held c/c_R does not change ((a)'s y range is fitted by its hook)."""
        front, profile, vm, curves, points = self._fronts(front_key)
        if any("error" in d for d in (front, profile, vm, *curves, *points)):
            return False
        x = profile["x"] * 1e3
        checks = [_inside(-front["X_c"] * 1e3, x), _inside(front["x_m"] * 1e3, x),
                  _inside(front_key[0], vm["c_ratio"]), _inside(front["v_m"], vm["v_m"])]
        c_values = np.concatenate([_positive(d["ds"]) for d in curves])
        vm_values = np.concatenate([d["ds"] for d in curves])
        for pt in points:
            checks += [_inside(float(_positive(np.array([pt["ds"]]))[0]), c_values), _inside(pt["ds"], vm_values)]
        return all(checks)

    def live_layers(self, front_key: tuple) -> dict[str, dict[live.LayerKey, live.Layer]]:
        """What a c/c_R change changes in each plot (by pane name, then layer): the profile, its peak and cohesive
        zone in (a); the current-c markers in (b)-(d), on (c)'s log axis as :meth:`_stress_layers` draws them."""
        front, profile, _vm, _curves, points = self._fronts(front_key)
        c, v_m = front_key[0], front["v_m"]
        return {
            "profile": {"cohesive zone size X_c": (np.array([-front["X_c"] * 1e3]), np.array([0.0])),
                        "v(x)": (profile["x"] * 1e3, profile["v"]),
                        "peak v_m": (np.array([front["x_m"] * 1e3]), np.array([v_m]))},
            "vm": {"current c": (np.array([c]), np.array([v_m]))},
            "stress": {marker_key(i): (np.array([c]), _positive(np.array([pt["ds"]]))) for i, pt in enumerate(points)},
            "stress_vm": {marker_key(i): (np.array([v_m]), np.array([pt["ds"]])) for i, pt in enumerate(points)},
        }

    # ----------------------------------------------------------------------------------------
    # data
    # ----------------------------------------------------------------------------------------

    def front(self) -> dict:
        return compute_front(*self.front_key)

    def profile(self) -> dict:
        return compute_profile(*self.front_key)

    def vm_curve(self) -> dict:
        return compute_vm_curve(*self.curve_key)

    def kWs(self) -> tuple[float, ...]:
        return self.stress_key[1:]

    def stress_curves(self) -> list[tuple[float, dict]]:
        sigma0 = self.stress_key[0]
        return [(kw, compute_stress_curve(kw, sigma0, *self.curve_key)) for kw in self.kWs()]

    def stress_points(self) -> list[tuple[float, dict]]:
        sigma0 = self.stress_key[0]
        return [(kw, compute_stress_point(self.front_key[0], kw, sigma0, *self.curve_key)) for kw in self.kWs()]

    # ----------------------------------------------------------------------------------------
    # plots
    # ----------------------------------------------------------------------------------------

    @param.depends("drawn")
    def profile_plot(self) -> hv.Overlay:
        """(a) v(x) behind the tip at the current c, with the peak v_m and the cohesive zone size X_c."""
        d, front = self.profile(), self.front()
        layers: list[hv.Element] = []
        if "error" in d:
            layers.append(hv.Curve(([], []), X_LABEL, V_LABEL, label="v(x)"))
        else:
            layers += [
                hv.VSpans([(-front["X_c"] * 1e3, 0.0)], label="cohesive zone size X_c").opts(color="#f4a582",
                                                                                            alpha=0.35),
                hv.Curve((d["x"] * 1e3, d["v"]), X_LABEL, V_LABEL, label="v(x)").opts(color="#1f4e79", line_width=2),
                hv.Scatter(([front["x_m"] * 1e3], [front["v_m"]]), X_LABEL, V_LABEL, label="peak v_m").opts(
                    color="#b2182b", size=9),
            ]
        # the y range fitted by a hook: the same at a redraw and where a held slider's profile is written (app.live)
        return _overlay(layers, height=320, title=profile_title(self.front_key[0]), legend_position="top_left",
                        xlabel=X_LABEL, ylabel=V_LABEL, hooks=[fit_y_hook])

    @param.depends("curve_key", "drawn")
    def vm_plot(self) -> hv.Overlay:
        """(b) v_m vs c/c_R, with the current c."""
        d, front = self.vm_curve(), self.front()
        layers: list[hv.Element] = [hv.Curve(([], []), C_LABEL, VM_LABEL, label="v_m")]
        if "error" not in d:
            layers = [hv.Curve((d["c_ratio"], d["v_m"]), C_LABEL, VM_LABEL, label="v_m").opts(color="#1f4e79",
                                                                                             line_width=2)]
        if "error" not in front:
            layers.append(hv.Scatter(([self.front_key[0]], [front["v_m"]]), C_LABEL, VM_LABEL, label="current c").opts(
                color="#b2182b", size=9))
        # log y: v_m diverges at c_R, which the curve approaches to 0.999 c_R (where the slider ends)
        return _overlay(layers, height=300, title="(b) Peak slip velocity v_m vs c/c_R", legend_position="top_left",
                        xlabel=C_LABEL, ylabel=VM_LABEL, logy=True)

    def _stress_layers(self, against_vm: bool) -> list[hv.Element]:
        """The Δσ_yy/σ₀ curves and current-c markers of (c) (against c/c_R, log y: values <= 0 become gaps, which
        :meth:`log_note` names) or of (d) (against v_m, linear y: every value)."""
        xlabel = VM_LABEL if against_vm else C_LABEL
        shown = _identity if against_vm else _positive
        vm = self.vm_curve()
        front = self.front()
        points = dict(self.stress_points())
        layers: list[hv.Element] = []
        for i, (kw, d) in enumerate(self.stress_curves()):
            color = PALETTE[i % len(PALETTE)]
            label = f"kW = {fmt(kw)}"
            if "error" in d or (against_vm and "error" in vm):
                layers.append(hv.Curve(([], []), xlabel, DS_LABEL, label=label))
                continue
            x = vm["v_m"] if against_vm else d["c_ratio"]
            layers.append(hv.Curve((x, shown(d["ds"])), xlabel, DS_LABEL, label=label).opts(color=color,
                                                                                            line_width=2))
            pt = points[kw]
            if "error" not in pt and "error" not in front:
                x0 = front["v_m"] if against_vm else self.front_key[0]
                marker_label = "current c" if i == 0 else ""  # one legend entry for the three markers
                marker = hv.Scatter(([x0], shown(np.array([pt["ds"]]))), xlabel, DS_LABEL, label=marker_label)
                layers.append(marker.opts(color=color, size=8, line_color="black"))
        return layers

    @param.depends("curve_key", "stress_key", "drawn")
    def stress_plot(self) -> hv.Overlay:
        """(c) Δσ_yy/σ₀ at v_m vs c/c_R for the three kW, on a log y axis: the curves rise from ~10⁻² to ~10⁰ near
        c_R, where v_m diverges (a linear axis showed them as flat lines at 0). (d) keeps a linear axis."""
        return _overlay(self._stress_layers(against_vm=False), height=300, legend_position="top_left",
                        title="(c) Δσ_yy/σ₀ at v_m (Eq. dsigma) vs c/c_R",
                        xlabel=C_LABEL, ylabel=DS_LOG_LABEL, logy=True,
                        # not linked to (d), which has the same y dimension: Panel would give both (d)'s linear
                        # range, which starts below 0 and so hid (c)'s log axis
                        shared_axes=False)

    @param.depends("curve_key", "stress_key", "drawn")
    def stress_vm_plot(self) -> hv.Overlay:
        """(d) the same against v_m (as Figs. 2c and 3c of the paper)."""
        return _overlay(self._stress_layers(against_vm=True), height=300, legend_position="top_left",
                        title="(d) Normal-stress change at v_m vs the peak slip velocity v_m (cf. Figs. 2c, 3c)",
                        xlabel=VM_LABEL, ylabel=DS_LABEL)

    # ----------------------------------------------------------------------------------------
    # messages, readout, export
    # ----------------------------------------------------------------------------------------

    def errors(self) -> dict[str, list[str]]:
        """The model's message for each bad input -> the views it empties."""
        out: dict[str, list[str]] = {}

        def add(d: dict, where: str) -> None:
            if "error" in d:
                out.setdefault(d["error"], []).append(where)

        add(self.front(), "(a), the current point and the readout")
        add(self.vm_curve(), "(b) and (d)")
        for kw, d in self.stress_curves():
            add(d, f"(c) and (d) at kW = {fmt(kw)}")
        return out

    @param.depends("front_key", "curve_key", "stress_key")
    def messages(self) -> pn.viewable.Viewable:
        """A visible message for bad input (the model's words), or nothing."""
        errors = self.errors()
        if not errors:
            return pn.pane.Markdown("", margin=0)
        text = "\n".join(f"- {html.escape(msg, quote=False)} — empty: {', '.join(where)}"
                         for msg, where in errors.items())
        return pn.pane.Alert(f"**Some values are outside the model's range:**\n\n{text}", alert_type="danger",
                             sizing_mode="stretch_width")

    def nonpositive_kWs(self) -> list[float]:
        """The kW whose Δσ_yy/σ₀ curve has values <= 0 somewhere (possible at ν = 0 and large kW), which the log
        axis of (c) cannot show."""
        return [kw for kw, d in self.stress_curves() if "error" not in d and np.any(d["ds"] <= 0)]

    @param.depends("curve_key", "stress_key")
    def log_note(self) -> pn.viewable.Viewable:
        """Says which values the log axis of (c) leaves out (they are in (d)), or nothing."""
        kws = self.nonpositive_kWs()
        if not kws:
            return pn.pane.Markdown("", margin=0)
        return pn.pane.Alert(f"(c) has a log axis: its values Δσ_yy/σ₀ ≤ 0 (kW = {', '.join(fmt(k) for k in kws)}) "
                             "are gaps there; (d) shows them on a linear axis.", alert_type="info",
                             sizing_mode="stretch_width")

    @param.depends("front_key", "stress_key", "material.material")
    def readout(self) -> str:
        f = self.front()
        if "error" in f:
            return material_readout(self.material) + "\n\n**Front** — (see the message above)"
        lines = [
            material_readout_with_nu(self.material, float(self.params.nu)),
            f"**c** = {fmt(f['c'], 5)} m/s = {fmt(self.front_key[0])} c_R, **c_R** = {fmt(f['c_R'], 5)} m/s "
            "(plane stress)",
            f"**f_II(c)** = {fmt(f['f_II'])}",
            f"**X_c** = X_c0/f_II = {fmt(f['X_c'] * 1e3)} mm",
            f"**τ_p** = {fmt(f['tau_p'] / 1e6)} MPa (E′ = {fmt(f['E_prime'] / 1e9)} GPa, μ = ρc_s² = "
            f"{fmt(f['mu'] / 1e9)} GPa)",
            f"**K_II** = {fmt(f['K_II'] / 1e3)} kPa·m^½",
            f"**v_m** = {fmt(f['v_m'])} m/s at x_m = {fmt(f['x_m'] * 1e3)} mm",
        ]
        for kw, pt in self.stress_points():
            value = fmt(pt["ds"]) if "error" not in pt else "—"
            lines.append(f"**Δσ_yy/σ₀ at v_m**, kW = {fmt(kw)}: {value}")
        return "\n\n".join(lines)

    def csv_profile(self) -> io.StringIO:
        d = self.profile()
        header = "asymslide rupture front (a): slip velocity; " + self._header(front=True)
        if "error" in d:
            return csv_table(header + " (not valid)", {"x_mm": [], "v_m_per_s": []})
        return csv_table(header, {"x_mm": d["x"] * 1e3, "v_m_per_s": d["v"]})

    def csv_curves(self) -> io.StringIO:
        """(b)-(d): c/c_R, v_m and Δσ_yy/σ₀ at v_m for each kW (NaN where the model refused the input)."""
        vm = self.vm_curve()
        nan = np.full(C_RATIO.shape, np.nan)
        cols = {"c_over_c_R": C_RATIO, "v_m_m_per_s": nan if "error" in vm else vm["v_m"]}
        for kw, d in self.stress_curves():
            cols[f"dsigma_yy_over_sigma0(kW={kw!r})"] = nan if "error" in d else d["ds"]
        return csv_table("asymslide rupture fronts (b)-(d); " + self._header(front=False)
                         + f", sigma0 = {self.stress_key[0]!r} Pa", cols)

    def _header(self, front: bool) -> str:
        c, gamma, x_c0, rho, c_s, nu = self.front_key
        text = (f"Gamma = {gamma!r} J/m^2, X_c0 = {x_c0!r} m, rho = {rho!r} kg/m^3, c_s = {c_s!r} m/s, nu = {nu!r}, "
                f"plane {PLANE}")
        return (f"c/c_R = {c!r}, " + text) if front else text

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """The scene's widgets (RuptureParams.make_widgets); the plots follow its held sliders (app.live)."""
        widgets = self.params.make_widgets()
        self.follow.track(widgets)
        return widgets

    def plot_pane(self, name: str, **options: object) -> pn.pane.HoloViews:
        """The pane of plot `name` (profile, vm, stress, stress_vm: (a)-(d)); the first of each name is the one a
        held slider writes into."""
        dmap = {"profile": self.profile_dmap, "vm": self.vm_dmap, "stress": self.stress_dmap,
                "stress_vm": self.stress_vm_dmap}[name]
        pane = pn.pane.HoloViews(dmap, sizing_mode="stretch_width", **options)
        self.panes.setdefault(name, pane)
        return pane

    def __panel__(self) -> pn.viewable.Viewable:
        controls = controls_column(self.make_widgets(), self.readout, extra=shared_material_widgets(
            self.material, "the Lab-units panel and Thin-on-thick"))
        flex = {"flex": "1 1 360px", "min-width": "0"}
        plots = pn.Column(
            pn.panel(self.messages),
            self.plot_pane("profile"),
            pn.FlexBox(self.plot_pane("vm", styles=flex), self.plot_pane("stress", styles=flex),
                       flex_wrap="wrap", sizing_mode="stretch_width"),
            pn.panel(self.log_note),
            self.plot_pane("stress_vm"),
            pn.FlexBox(csv_download(self.csv_profile, "rupture_profile.csv", "CSV (a)"),
                       csv_download(self.csv_curves, "rupture_curves.csv", "CSV (b)-(d)"), flex_wrap="wrap"),
            pn.pane.Markdown(ASSUMPTIONS, sizing_mode="stretch_width"),
            reference_card("13.1"),
            pn.Card(pn.pane.Markdown(_sources(), sizing_mode="stretch_width"), title="Defaults and sources",
                    collapsed=True, sizing_mode="stretch_width"),
            sizing_mode="stretch_width",
        )
        return scene_layout(controls, plots, "Rupture fronts")
