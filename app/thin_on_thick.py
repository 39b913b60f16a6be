"""Scene "Thin-on-thick" (paper Sect. III, Fig. 3): effective moduli, effective bimaterial G_y and the
normal-stress change of a thin block (width W) sliding on a thick one of the same material.

The app computes no physics: the cached ``compute_*`` functions only call the public API of :mod:`model`,
one function per dependency group, so that e.g. changing ρ or σ₀ recomputes only the (cheap) Δσ_yy line
and changing kW recomputes neither the μ_eff(kW) curve nor anything that depends only on ν.

While the kW slider is held, the plots follow it without a HoloViews redraw: the new markers and curves are written
into the Bokeh sources on the page (:mod:`app.live`, a few ms instead of ~0.15 s for the four plots), with the ranges
fitted by the plots' hooks as a redraw fits them.
"""

from __future__ import annotations

import html
import io
import math

import holoviews as hv
import numpy as np
import panel as pn
import param
from bokeh.models import GlyphRenderer

from asymslide import model

from . import live
from .declarations import physical_parameters
from .exports import csv_download, csv_table
from .layout import controls_column, material_readout, scene_layout, shared_material_widgets
from .params import CUSTOM, LabParams, RuptureParams, ThinOnThickParams
from .plotting import PALETTE, fit_y_hook, fmt

#: kW grid of the effective-moduli plots (Fig. 3a and inset)
KW = np.logspace(-2, 3, 400)
#: slip-velocity grid of Fig. 3c [m/s]
V = np.linspace(0.0, 2.0, 201)
#: number of points of the c/c_s grid of Fig. 3b
N_Z = 400
Z_MIN = 1e-3
#: fraction of the limiting speed (model.limiting_speed) at which the c/c_s grid stops
Z_MAX_FRACTION = 0.999

MU_LABEL = "μ_eff/μ"
NU_LABEL = "ν_eff"
Z_LABEL = "c/c_s"
GY_LABEL = "G_y"
V_LABEL = "v [m/s]"
DS_LABEL = "Δσ_yy/σ₀"
#: legend names of the reference lines of Fig. 3b (every line a user sees is named)
ZERO_LABEL = "G_y = 0"
C_R_LABEL = "c_R (thin block)"
#: relative difference below which ν counts as the material's: a shared URL holds ν to 6 digits (app/urlstate.py)
NU_RTOL = 1e-5



def _quiet() -> np.errstate:
    """The model may return NaN (with a RuntimeWarning) where it cannot evaluate, e.g. exactly at c = c_R;
    the page shows such points as gaps and says so in the readout instead of failing."""
    return np.errstate(divide="ignore", invalid="ignore")



# --------------------------------------------------------------------------------------------
# cached model calls, one per dependency group
# --------------------------------------------------------------------------------------------


@pn.cache(max_items=64)
def compute_moduli_curve(nu: float) -> dict:
    """mu_eff/mu and nu_eff on :data:`KW` (depends on nu only)."""
    mu_ratio, nu_eff = model.effective_moduli(KW, nu)
    return {"kW": KW, "mu_ratio": mu_ratio, "nu_eff": nu_eff}


@pn.cache(max_items=256)
def compute_point(kW: float, nu: float) -> dict:
    """Scalars at the current (kW, nu): effective moduli, mu_eff/mu - 1, z_R of the thin block, G_y(z_R)."""
    mu_ratio, nu_eff = model.effective_moduli(kW, nu)
    excess = model.effective_modulus_excess(kW, nu)
    # the thin block is under plane stress (docs/physics.md §6)
    z_R = float(model.rayleigh_speed(model.wave_speed_ratio(nu, plane="stress")))
    with _quiet():
        _, gy = model.thin_on_thick_response(z_R, kW, nu=nu)
    return {"kW": kW, "nu": nu, "mu_ratio": float(mu_ratio), "nu_eff": float(nu_eff), "excess": float(excess),
            "z_R": z_R, "gy_R": float(np.real(gy)), "z_max": Z_MAX_FRACTION * float(model.limiting_speed(kW, nu))}


@pn.cache(max_items=64)
def compute_gy_curve(kW: float, nu: float) -> dict:
    """Re G_y on c/c_s from :data:`Z_MIN` to 0.999 min(1, sqrt(mu_eff/mu)) (Fig. 3b)."""
    z = np.linspace(Z_MIN, compute_point(kW, nu)["z_max"], N_Z)
    with _quiet():
        _, gy = model.thin_on_thick_response(z, kW, nu=nu)
    return {"z": z, "gy": np.real(gy)}


@pn.cache(max_items=256)
def compute_stress_line(kW: float, nu: float, c_s: float, rho: float, sigma0: float) -> dict:
    """Δσ_yy/σ₀ on :data:`V` at c = c_R of the thin block (Fig. 3c); sigma0 in Pa, mu = rho c_s^2. The shared lab
    values may be anything a user typed: the model's message (``{"error": ...}``) where it refuses them."""
    if not (math.isfinite(sigma0) and sigma0 > 0):
        return {"error": f"sigma0 must be in (0, inf) Pa; got {sigma0:g}"}
    try:
        c = compute_point(kW, nu)["z_R"] * c_s
        mu = float(model.shear_modulus(rho, c_s))
        with _quiet():
            ds = model.normal_stress_change(V, c=c, c_s=c_s, kW=kW, nu=nu, mu=mu) / sigma0
            slope = float(model.normal_stress_change(1.0, c=c, c_s=c_s, kW=kW, nu=nu, mu=mu)) / sigma0
    except ValueError as exc:
        return {"error": str(exc)}
    return {"v": V, "ds": ds, "slope": slope, "c": c, "mu": mu}


def fit_x_hook(plot, _element) -> None:
    """HoloViews plot hook: the x range spans the x of every glyph shown, unpadded (as HoloViews' own range of these
    curves): where a held slider's curves are written (app.live), the range follows them as a redraw would, and (a)
    and its inset, whose x ranges Panel links, show one range (HoloViews padded (a)'s on the first drawing only)."""
    values = [np.asarray(r.data_source.data[r.glyph.x], dtype=float).ravel() for r in plot.state.renderers
              if isinstance(r, GlyphRenderer) and r.visible and isinstance(getattr(r.glyph, "x", None), str)
              and r.glyph.x in r.data_source.data]
    finite = np.concatenate(values) if values else np.empty(0)
    finite = finite[np.isfinite(finite)]
    if finite.size and finite.max() > finite.min():
        plot.state.x_range.update(start=float(finite.min()), end=float(finite.max()))


def gy_title(kW: float) -> str:
    """The title of (b) at `kW`."""
    return f"(b) G_y at kW = {fmt(kW, 4)}"


def material_readout_with_nu(lab: LabParams, nu: float) -> str:
    """:func:`~app.layout.material_readout` and the ν a scene uses. ν has its own widget, so it can differ from the
    named preset's after the material was chosen: it is then marked as not the material's (a readout
    once named fused silica beside ν = 0.44)."""
    line = material_readout(lab)
    if lab.material == CUSTOM:
        return line + f", ν = {fmt(nu)}"
    preset = RuptureParams.material_nu(lab.material)
    if math.isclose(nu, preset, rel_tol=NU_RTOL):
        return line + f", ν = {fmt(nu)} ({lab.material}'s)"
    return line + f"; **ν** = {fmt(nu)}, set here: not {lab.material}'s ν = {fmt(preset)}"


class ThinOnThickScene(pn.viewable.Viewer):
    """Widgets, plots (Fig. 3a-c) and readout for one :class:`ThinOnThickParams`."""

    params = param.ClassSelector(class_=ThinOnThickParams)
    #: the page's shared material constants (c_s, ρ, σ₀; the Lab-units panel's)
    material = param.ClassSelector(class_=LabParams)
    #: normalised model arguments per dependency group; a plot depends only on the keys it uses
    nu_key = param.Number(default=None, allow_None=True)
    point_key = param.Tuple(default=None, length=2, allow_None=True)  # (kW, nu)
    stress_key = param.Tuple(default=None, length=5, allow_None=True)  # (kW, nu, c_s, rho, sigma0 [Pa])
    #: selected kW values drawn as a family (Fig. 3b curves, Fig. 3a markers; set by the Fig. 3 preset)
    compare_kW = param.List(default=[], item_type=float)
    #: count HoloViews' redraws at a new point_key (plots (a), (b)) and stress_key (plot (c)): the plots depend on
    #: them, not on the keys; while the kW slider is held, the plots on the page follow it without one (app.live)
    drawn = param.Integer(default=0, precedence=-1)
    stress_drawn = param.Integer(default=0, precedence=-1)

    def __init__(self, **kwargs):
        kwargs.setdefault("params", ThinOnThickParams())
        kwargs.setdefault("material", LabParams())
        super().__init__(**kwargs)
        #: the plot panes by name (moduli, nu_eff, gy, stress) once built: a held slider writes into them
        self.panes: dict[str, pn.pane.HoloViews] = {}
        self._shown: tuple = (None, None)  # the (point_key, stress_key) the plots on the page show (drawn or written)
        self.follow = live.Follow(self._follow, self._redraw)
        self._update_keys()
        self.params.param.watch(self._update_keys, list(physical_parameters(ThinOnThickParams)))
        self.material.param.watch(self._update_keys, ["c_s", "rho", "sigma0_MPa"])
        self.material.param.watch(self._material_chosen, "material")
        self.moduli_dmap = hv.DynamicMap(self.moduli_plot)
        self.nu_eff_dmap = hv.DynamicMap(self.nu_eff_plot)
        self.gy_dmap = hv.DynamicMap(self.gy_plot)
        self.stress_dmap = hv.DynamicMap(self.stress_plot)

    def _material_chosen(self, event: param.parameterized.Event) -> None:
        """A material preset chosen (in any scene): ν becomes its ν, as ρ and c_s become its values (as in the
        Rupture-fronts scene), so that the readout never names one material with another's ν."""
        if event.new != CUSTOM:
            self.params.nu = RuptureParams.material_nu(event.new)

    def _update_keys(self, *events) -> None:
        """The model arguments from the parameters (a held slider's moves: read on the next turn, app.live.Follow)."""
        if events and self.follow.defer(self._update_keys):
            return
        p, m = self.params, self.material
        kw, nu = p.kW, float(p.nu)
        stress = (kw, nu, float(m.c_s), float(m.rho), float(m.sigma0_MPa) * 1e6)
        with param.parameterized.batch_call_watchers(self):
            if nu != self.nu_key:
                self.nu_key = nu
            if (kw, nu) != self.point_key:
                self.point_key = (kw, nu)
            if stress != self.stress_key:
                self.stress_key = stress
            if (self.point_key, stress) != self._shown:  # in the same batch: a plot redraws once
                self.follow.changed()

    def _redraw(self) -> None:
        """HoloViews redraws the plots whose key the page does not show yet."""
        point, stress = self._shown
        self._shown = (self.point_key, self.stress_key)
        if self.point_key != point:
            self.drawn += 1
        if self.stress_key != stress:
            self.stress_drawn += 1

    def _follow(self) -> bool:
        """Write the plots of the current kW into the page (:mod:`app.live`) when only kW differs from what it shows;
        True if the page then shows the current keys. False where that cannot be done (ν or the material changed,
        plots not rendered): HoloViews redraws then."""
        point, stress = self.point_key, self.stress_key
        shown_point, shown_stress = self._shown
        if (point, stress) == self._shown:
            return True
        if (shown_point is None or shown_stress is None or point[1:] != shown_point[1:]
                or stress[1:] != shown_stress[1:] or len(self.panes) < 4 or not KW[0] <= point[0] <= KW[-1]):
            return False  # the current-kW markers lie within the μ_eff, ν_eff curves: (a)'s x ranges stay theirs
        if not all(live.push(self.panes[name], layers, title=gy_title(point[0]) if name == "gy" else None)
                   for name, layers in self.live_layers(point, stress).items()):
            return False
        self._shown = (point, stress)
        return True

    @staticmethod
    def live_layers(point_key: tuple, stress_key: tuple) -> dict[str, dict[str, tuple[np.ndarray, np.ndarray]]]:
        """What a kW change changes in each plot (by pane name, then layer label): the current-kW markers of (a), the
        G_y curve and the zero line over its c/c_s in (b), the Δσ_yy line of (c) (empty where the model refuses the
        shared lab values), as the plots draw them."""
        pt, gy = compute_point(*point_key), compute_gy_curve(*point_key)
        d = compute_stress_line(*stress_key)
        v, ds = (d["v"], d["ds"]) if "error" not in d else (np.array([]), np.array([]))
        kw = np.array([pt["kW"]])
        return {"moduli": {"current kW": (kw, np.array([pt["mu_ratio"]]))},
                "nu_eff": {"current kW": (kw, np.array([pt["nu_eff"]]))},
                "gy": {ZERO_LABEL: (np.array([gy["z"][0], gy["z"][-1]]), np.array([0.0, 0.0])),
                       "current kW": (gy["z"], gy["gy"])},
                "stress": {DS_LABEL: (np.asarray(v, float), np.asarray(ds, float))}}

    def point(self) -> dict:
        return compute_point(*self.point_key)

    def family_points(self) -> list[dict]:
        return [compute_point(kw, self.nu_key) for kw in self.compare_kW]

    @param.depends("nu_key", "drawn", "compare_kW")
    def moduli_plot(self) -> hv.Overlay:
        d, pt = compute_moduli_curve(self.nu_key), self.point()
        one = hv.HLine(1.0).opts(color="black", line_width=1, line_dash="dotted")
        curve = hv.Curve((d["kW"], d["mu_ratio"]), "kW", MU_LABEL, label=MU_LABEL).opts(color="#1f4e79", line_width=2)
        marker = hv.Scatter(([pt["kW"]], [pt["mu_ratio"]]), "kW", MU_LABEL, label="current kW").opts(
            color="#b2182b", size=9)
        fam = [hv.Scatter(([q["kW"]], [q["mu_ratio"]]), "kW", MU_LABEL, label=f"kW = {q['kW']:g}").opts(
            color=PALETTE[i % len(PALETTE)], size=8, marker="square") for i, q in enumerate(self.family_points())]
        return hv.Overlay([one, curve, *fam, marker]).opts(
            hv.opts.Overlay(logx=True, responsive=True, height=320, title="(a) Effective shear modulus",
                            show_legend=False, framewise=True, xlabel="kW", ylabel=MU_LABEL,
                            hooks=[fit_x_hook, fit_y_hook]))

    @param.depends("nu_key", "drawn", "compare_kW")
    def nu_eff_plot(self) -> hv.Overlay:
        d, pt = compute_moduli_curve(self.nu_key), self.point()
        curve = hv.Curve((d["kW"], d["nu_eff"]), "kW", NU_LABEL, label=NU_LABEL).opts(color="#1f4e79", line_width=2)
        marker = hv.Scatter(([pt["kW"]], [pt["nu_eff"]]), "kW", NU_LABEL, label="current kW").opts(
            color="#b2182b", size=7)
        fam = [hv.Scatter(([q["kW"]], [q["nu_eff"]]), "kW", NU_LABEL, label=f"kW = {q['kW']:g}").opts(
            color=PALETTE[i % len(PALETTE)], size=6, marker="square") for i, q in enumerate(self.family_points())]
        return hv.Overlay([curve, *fam, marker]).opts(
            hv.opts.Overlay(logx=True, width=300, height=220, title="(a, inset) ν_eff",
                            show_legend=False, framewise=True, xlabel="kW", ylabel=NU_LABEL,
                            hooks=[fit_x_hook, fit_y_hook]))

    @param.depends("drawn", "compare_kW")
    def gy_plot(self) -> hv.Overlay:
        d, pt = compute_gy_curve(*self.point_key), self.point()
        # the reference lines are glyphs, not Bokeh Spans (hv.HLine/VLine), which a legend cannot list; the zero line
        # is a Curve over the plotted c/c_s so that fit_y_hook keeps 0 in the y range (G_y < 0 at the defaults)
        zero = hv.Curve(([d["z"][0], d["z"][-1]], [0.0, 0.0]), Z_LABEL, GY_LABEL, label=ZERO_LABEL).opts(
            color="black", line_width=1)
        c_r = hv.VLines([pt["z_R"]], label=C_R_LABEL).opts(color="#999999", line_dash="dashed", line_width=1)
        fam = []
        for i, kw in enumerate(self.compare_kW):
            e = compute_gy_curve(kw, self.point_key[1])
            fam.append(hv.Curve((e["z"], e["gy"]), Z_LABEL, GY_LABEL, label=f"kW = {kw:g}").opts(
                color=PALETTE[i % len(PALETTE)], line_width=1.2))
        curve = hv.Curve((d["z"], d["gy"]), Z_LABEL, GY_LABEL, label="current kW").opts(
            color="#1f4e79", line_width=2)
        return hv.Overlay([zero, c_r, *fam, curve]).opts(
            hv.opts.Overlay(responsive=True, height=300, title=gy_title(pt["kW"]),
                            show_legend=True, legend_position="bottom_left", framewise=True,
                            xlabel=Z_LABEL, ylabel=GY_LABEL, hooks=[fit_x_hook, fit_y_hook]))

    @param.depends("stress_drawn")
    def stress_plot(self) -> hv.Overlay:
        d = compute_stress_line(*self.stress_key)
        zero = hv.HLine(0.0).opts(color="black", line_width=1)
        v, ds = (d["v"], d["ds"]) if "error" not in d else ([], [])
        curve = hv.Curve((v, ds), V_LABEL, DS_LABEL, label=DS_LABEL).opts(color="#b2182b", line_width=2)
        return (zero * curve).opts(
            hv.opts.Overlay(responsive=True, height=300, title="(c) Normal-stress change at c = c_R",
                            show_legend=False, framewise=True, xlabel=V_LABEL, ylabel=DS_LABEL,
                            hooks=[fit_y_hook]))

    @param.depends("stress_key")
    def messages(self) -> pn.viewable.Viewable:
        """The model's message where it refuses the shared lab values (plot (c) is then empty), or nothing."""
        d = compute_stress_line(*self.stress_key)
        if "error" not in d:
            return pn.pane.Markdown("", margin=0)
        return pn.pane.Alert(f"**The shared lab values are not valid** (c_s, ρ or σ₀; plot (c) is empty): "
                             f"{html.escape(d['error'], quote=False)}", alert_type="danger",
                             sizing_mode="stretch_width")

    @param.depends("stress_key", "material.material")
    def readout(self) -> str:
        pt = self.point()
        d = compute_stress_line(*self.stress_key)
        if "error" in d:
            d = {"c": math.nan, "slope": math.nan, "mu": math.nan, "ds": np.array([math.nan])}
        lines = [material_readout_with_nu(self.material, float(self.params.nu)),
            f"**kW** = {fmt(pt['kW'], 4)}",
            f"**μ_eff/μ** = {fmt(pt['mu_ratio'], 10)}",
            f"**μ_eff/μ − 1** = {pt['excess']:.6e}" if np.isfinite(pt["excess"]) else "**μ_eff/μ − 1** = —",
            f"**ν_eff** = {fmt(pt['nu_eff'], 6)}",
            f"**c_R/c_s** (thin block, plane stress) = {fmt(pt['z_R'], 6)}, c_R = {fmt(d['c'], 5)} m/s",
            f"**G_y(c_R)** = {fmt(pt['gy_R'], 6)}",
            f"**dΔσ_yy/σ₀/dv** = {fmt(d['slope'], 5)} s/m (μ = ρc_s² = {fmt(d['mu'] / 1e9, 4)} GPa)",
        ]
        if not (np.all(np.isfinite(d["ds"])) and np.isfinite(pt["gy_R"])):
            lines.append("**Warning** the model returned non-finite values at c = c_R")
        return "\n\n".join(lines)

    def csv_moduli(self) -> io.StringIO:
        d = compute_moduli_curve(self.nu_key)
        return csv_table(f"asymslide thin-on-thick Fig. 3a; nu = {self.nu_key!r}",
                         {"kW": d["kW"], "mu_eff_over_mu": d["mu_ratio"], "nu_eff": d["nu_eff"]})

    def csv_gy(self) -> io.StringIO:
        kw, nu = self.point_key
        cols = {}
        for k in (kw, *self.compare_kW):
            d = compute_gy_curve(k, nu)
            cols[f"c_over_c_s(kW={k!r})"], cols[f"G_y(kW={k!r})"] = d["z"], d["gy"]
        return csv_table(f"asymslide thin-on-thick Fig. 3b; nu = {nu!r}", cols)

    def csv_stress(self) -> io.StringIO:
        d = compute_stress_line(*self.stress_key)
        kw, nu, c_s, rho, sigma0 = self.stress_key
        if "error" in d:
            d = {"v": np.empty(0), "ds": np.empty(0)}
        return csv_table(f"asymslide thin-on-thick Fig. 3c at c = c_R; kW = {kw!r}, nu = {nu!r}, c_s = {c_s!r} m/s, "
                         f"rho = {rho!r} kg/m^3, sigma0 = {sigma0!r} Pa",
                         {"v_m_per_s": d["v"], "dsigma_yy_over_sigma0": d["ds"]})

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """The scene's widgets (ThinOnThickParams.make_widgets); the plots follow its held sliders (app.live)."""
        widgets = self.params.make_widgets()
        self.follow.track(widgets)
        return widgets

    def plot_pane(self, name: str, **options: object) -> pn.pane.HoloViews:
        """The pane of plot `name` (moduli, nu_eff, gy, stress: (a), its inset, (b), (c)); the first of each name is
        the one a held slider writes into."""
        dmap = {"moduli": self.moduli_dmap, "nu_eff": self.nu_eff_dmap, "gy": self.gy_dmap,
                "stress": self.stress_dmap}[name]
        pane = pn.pane.HoloViews(dmap, **options)
        self.panes.setdefault(name, pane)
        return pane

    def __panel__(self) -> pn.viewable.Viewable:
        controls = controls_column(self.make_widgets(), self.readout, extra=shared_material_widgets(
            self.material, "the Lab-units panel and Rupture fronts"))
        wide = {"sizing_mode": "stretch_width"}
        plots = pn.Column(
            pn.panel(self.messages),
            pn.FlexBox(self.plot_pane("moduli", styles={"flex": "1 1 400px", "min-width": "0"}, **wide),
                       self.plot_pane("nu_eff"), flex_wrap="wrap", sizing_mode="stretch_width"),
            self.plot_pane("gy", **wide),
            self.plot_pane("stress", **wide),
            pn.FlexBox(csv_download(self.csv_moduli, "thin_on_thick_moduli.csv", "CSV (a)"),
                       csv_download(self.csv_gy, "thin_on_thick_gy.csv", "CSV (b)"),
                       csv_download(self.csv_stress, "thin_on_thick_stress.csv", "CSV (c)"), flex_wrap="wrap"),
            sizing_mode="stretch_width",
        )
        return scene_layout(controls, plots, "Thin-on-thick")
