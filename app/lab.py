"""The "Lab units" panel of the Spectrum and Stability-map scenes (docs/physics.md §12): a laboratory setting
(:class:`~app.params.LabParams`) mapped onto the sliders γ, f, β, η, Δ, ξ, and the spectrum read back in lab units.

One :class:`LabScene` per session is shared by both scenes (each shows its own widgets, bound to the same
parameters). While its link is on, every change of a lab value sets the shared :class:`~app.params.SpectrumParams`
in one update, with the values the model returns (:func:`model.dimensionless_parameters`) clamped to the sliders'
ranges; bad input leaves the sliders as they are and the panel shows the model's message (in mm, MPa or µm for
the fields typed in those units). Moving a slider by hand afterwards is allowed: the panel then says the sliders no
longer match the lab values and offers to re-apply them.

The readouts describe the lab setting (its own γ, β, … unclamped; the same cached spectrum as the Spectrum scene's
while the sliders match): the fastest-growing mode, i.e. the largest growth rate k Im c
(:func:`model.fastest_growing_mode`), as wavelength, growth rate, e-folding time and phase speed
(:func:`model.spectrum_in_lab_units`), and the unstable band as a wavelength range (:func:`model.wavelength`).

The app computes no physics: every number comes from a ``pn.cache``'d call into the public :mod:`model` API; the
app only converts mm, µm and MPa to SI units and back.
"""

from __future__ import annotations

import html
import io
import math
from dataclasses import dataclass, field

import holoviews as hv
import numpy as np
import panel as pn
import param
from bokeh.models import CustomJSTickFormatter, LinearAxis

from asymslide import model

from . import spectrum as sp
from .common import FAMILY_NAMES
from .declarations import declared_parameters
from .docs import reference_card
from .exports import csv_download, csv_table
from .params import LabParams, SpectrumParams, follow_material, model_args
from .plotting import fmt, zero_line_hook
from .workarounds import frozen_document

#: kH grid of the lab spectrum: the Spectrum scene's, so that matched sliders share one cached computation
KH = sp.KH

#: relative difference below which a slider counts as showing the lab value (the URL keeps 6 digits)
MATCH_RTOL = 1e-5

#: the e-folding-time axis of the lab plot: the growth-rate axis's own range, each tick labelled with the time
#: 1/rate in ms (the definition of model.e_folding_time; "∞" at rate 0, "—" where the mode decays)
E_FOLDING_AXIS = "e-folding time"
#: (three significant digits without trailing zeros, as the app's other axes: "2.5", not "2.50")
E_FOLDING_TICKS = ("const step = ticks.length > 1 ? Math.abs(ticks[1] - ticks[0]) : 1;"
                   " if (Math.abs(tick) <= step * 1e-9) return '∞';"
                   " if (tick < 0) return '—';"
                   " const t = 1000 / tick; return t >= 100 ? t.toFixed(0) : String(Number(t.toPrecision(3)));")

RATE_LABEL = "growth rate k Im c [1/s]"
WAVELENGTH_LABEL = "λ [mm]"

ASSUMPTION = """\
**Assumption: rate-and-state friction** (docs/physics.md §12.3). The paper fixes no friction law; to start from
a, b, D_c the panel takes Dieterich–Ruina friction f = f₀ + a ln(v/v*) + b ln(v*θ/D_c) with the aging or the slip
law (both give the same linear stability): ∂_v f = a/v, Δ = 1 − b/a (needs 0 ≤ b < a), D = D_c, so
γ = ρ c_s v/(σ₀ a), ξ = D_c c_s/(H₁ v), η = H₂/H₁. c_d is the bulk (ultrasound) speed; β = c_s/c_d in plane
strain, √((1 − ν)/2) in plane stress. PMMA's density is an assumption (the paper gives none)."""


# --------------------------------------------------------------------------------------------
# cached model calls
# --------------------------------------------------------------------------------------------


@pn.cache(max_items=256)
def compute_lab(rho: float, c_s: float, c_d: float, sigma0: float, f: float, H1: float, H2: float, v: float,
                a: float, b: float, D_c: float, plane: str) -> dict:
    """γ, f, β, η, Δ, ξ of a lab setting in SI units (:func:`model.dimensionless_parameters`), or the model's
    message for bad input (``{"error": ...}``)."""
    try:
        p = model.dimensionless_parameters(rho=rho, c_s=c_s, c_d=c_d, sigma0=sigma0, f=f, H1=H1, H2=H2, v=v, a=a,
                                           b=b, D_c=D_c, plane=plane)
    except ValueError as exc:
        return {"error": str(exc)}
    return {"params": {k: float(p[k]) for k in SpectrumParams.MODEL_ARGS}}


@pn.cache(max_items=64)
def compute_lab_spectrum(gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float, H1: float,
                         c_s: float) -> dict:
    """The spectrum of a lab setting on :data:`KH` in lab units (SI), its fastest-growing mode and unstable band."""
    d = sp.compute_spectrum(gamma, f, beta, eta, Delta, xi)
    with np.errstate(invalid="ignore"):
        lab = model.spectrum_in_lab_units(kH=d["kH"], z=d["z"], H1=H1, c_s=c_s)
    k_star, z_star = model.fastest_growing_mode(d["kH"], gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    if np.isfinite(k_star):
        peak = {k: float(v) for k, v in model.spectrum_in_lab_units(kH=k_star, z=z_star, H1=H1, c_s=c_s).items()}
    else:
        peak = dict.fromkeys(("wavelength", "growth_rate", "e_folding_time", "phase_speed"), math.nan)
    band = (math.nan, math.nan)
    if np.isfinite(d["kH_min"]) and np.isfinite(d["kH_max"]):
        band = tuple(float(w) for w in model.wavelength(kH=np.array([d["kH_max"], d["kH_min"]]), H1=H1))
    return {"kH": d["kH"], "z": d["z"], "status": d["status"], **lab, "kH_star": float(k_star), "z_star": z_star,
            "peak": peak, "band": band, "growth": d["growth"], "kH_min": d["kH_min"], "kH_max": d["kH_max"]}


@pn.cache(max_items=64)
def compute_lab_sliding(gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float, H1: float,
                        c_s: float) -> dict:
    """The fastest growth of every branch over every kH (``sigma`` of :func:`model.sliding_analysis` with
    ``rate=True``, its default floor: the supremum of k Im c over 0 < kH < inf) in lab units, with its family and the
    verdict: ``peak`` where it is attained at a kH, ``limit`` where it is approached as kH -> inf (growth rate,
    e-folding time and phase speed; the wavelength tends to 0), else ``bound`` where only the mode of the largest
    Im c is certified."""
    r = model.sliding_analysis(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi, rate=True)
    out = {"verdict": int(r.verdict), "reason": int(r.verdict_reason), "family": int(r.family_sigma),
           "kH": float(r.kH_at_sigma), "lower_bound": bool(r.lower_bound), "floor": float(r.floor),
           "range": r.kH_range, "rate_limit": float(r.rate_limit)}
    sigma, kh, z = float(r.sigma), float(r.kH_at_sigma), complex(r.z_at_sigma)
    if math.isfinite(sigma) and math.isinf(kh):  # in lab units: k Im c = sigma c_s / H1 (at kH = 1 with Im z = sigma)
        lab = model.spectrum_in_lab_units(kH=1.0, z=complex(z.real, sigma), H1=H1, c_s=c_s)
        out["limit"] = {k: float(lab[k]) for k in ("growth_rate", "e_folding_time", "phase_speed")}
    elif math.isfinite(sigma):
        lab = model.spectrum_in_lab_units(kH=kh, z=z, H1=H1, c_s=c_s)
        out["peak"] = {k: float(v) for k, v in lab.items()}
    elif math.isfinite(float(r.growth)):  # the rate's maximum is not certified: the mode of the largest Im c bounds it
        lab = model.spectrum_in_lab_units(kH=float(r.kH_at_max), z=complex(r.z_at_max), H1=H1, c_s=c_s)
        out.update(bound={k: float(v) for k, v in lab.items()}, bound_kH=float(r.kH_at_max),
                   bound_family=int(r.family))
    return out


def _sigma_line(d: dict, scope: str) -> str:
    """The readout line of the fastest growth over every kH (:func:`compute_lab_sliding`'s peak or limit)."""
    name = FAMILY_NAMES.get(d["family"], "family unknown")
    sign = "≥ " if d["lower_bound"] else ""
    if "limit" in d:
        lm = d["limit"]
        line = (f"**Fastest growth of every branch: approached as kH → ∞** ({name}; {scope}): growth rate → {sign}"
                f"{fmt(lm['growth_rate'])} 1/s, e-folding time → {fmt(lm['e_folding_time'] * 1e3)} ms, phase speed → "
                f"{fmt(lm['phase_speed'])} m/s, as λ → 0")
        if d["verdict"] == model.Verdict.STABLE:
            line += f" (no mode grows over kH {d['range'][0]:g} to {d['range'][1]:g}: only shorter waves do)"
        return line
    pk = d["peak"]
    line = (f"**Fastest-growing mode of every branch** ({name}, at kH = {fmt(d['kH'])}; {scope}): "
            f"λ = {fmt(pk['wavelength'] * 1e3)} mm, growth rate {sign}{fmt(pk['growth_rate'])} 1/s, e-folding time "
            f"{fmt(pk['e_folding_time'] * 1e3)} ms, phase speed {fmt(pk['phase_speed'])} m/s")
    if not d["range"][0] <= d["kH"] <= d["range"][1]:
        line += f" (outside kH {d['range'][0]:g} to {d['range'][1]:g}, where Im c is searched)"
    return line


def sliding_lab_lines(d: dict) -> list[str]:
    """The readout of :func:`compute_lab_sliding`: the fastest growth of every branch over every kH in lab units."""
    lo, hi = d["range"]
    scope = f"every branch, Im c/c_s ≥ {d['floor']:g}, kH {lo:g} to {hi:g}"
    if "peak" in d or "limit" in d:
        return [_sigma_line(d, f"every branch and every kH, Im c/c_s ≥ {d['floor']:g}")]
    if d["verdict"] == model.Verdict.STABLE:
        beyond = ("nor as kH → ∞" if d["rate_limit"] == 0.0 else
                  "and as kH → ∞ undetermined (the limit of k Im c was refused)")
        return [f"**Sliding stable** ({scope}): no mode of any branch grows, {beyond}"]
    if "bound" in d:
        b = d["bound"]
        return [f"**Sliding unstable** ({scope}): the largest growth rate k Im c of every branch is not certified (a "
                "search was refused above it at some kH: the window too wide); the mode of the largest Im c "
                f"({FAMILY_NAMES.get(d['bound_family'], 'family unknown')}, at kH = {fmt(d['bound_kH'])}) grows at "
                f"{fmt(b['growth_rate'])} 1/s (λ = {fmt(b['wavelength'] * 1e3)} mm, e-folding time "
                f"{fmt(b['e_folding_time'] * 1e3)} ms): the fastest grows at least as fast"]
    what = "undetermined" if d["verdict"] == model.Verdict.UNDETERMINED else "unstable"
    return [f"**Sliding {what}** ({scope}): {model.SLIDING_STATUS[d['reason']]}"]


@pn.cache(max_items=256)
def compute_rate_state(gamma: float, Delta: float, xi: float, eta: float, rho: float, c_s: float, sigma0: float,
                       H1: float, v: float) -> dict:
    """a, b, D_c [m] and H₂ [m] that give the sliders' γ, Δ, ξ, η for the lab's material, σ₀, H₁ and v
    (:func:`model.rate_state_parameters`), or the model's message."""
    try:
        r = model.rate_state_parameters(gamma=gamma, Delta=Delta, xi=xi, eta=eta, rho=rho, c_s=c_s, sigma0=sigma0,
                                        H1=H1, v=v)
    except ValueError as exc:
        return {"error": str(exc)}
    return {k: float(x) for k, x in r.items()}


# --------------------------------------------------------------------------------------------
# bad input in the units the user typed
# --------------------------------------------------------------------------------------------

#: the lab fields the panel takes in other units than the model's SI ones (mm, MPa, µm), each with the lower end
#: of its valid range and whether that end is valid (the model's domains: heights and σ₀ > 0, D_c ≥ 0). Both ends
#: are 0 or ∞, the same in either unit; the model stays the judge of validity (these only word its refusal).
UNIT_FIELDS: dict[str, tuple[float, bool]] = {"H1_mm": (0.0, False), "H2_mm": (0.0, False),
                                              "sigma0_MPa": (0.0, False), "D_c_um": (0.0, True)}


def _symbol_and_unit(label: str) -> tuple[str, str]:
    """("H₁", "mm") of a declared label "H₁ [mm]"."""
    symbol, _, unit = label.partition(" [")
    return symbol, unit.rstrip("]")


def unit_field_errors(p: LabParams) -> list[str]:
    """A message for every field of `p` in :data:`UNIT_FIELDS` outside its range, in that field's units and with
    its symbol as the panel labels it, e.g. "H₁ must be in (0, ∞) mm; got -5 mm" (the model, which takes metres,
    says "H1 must be in (0, inf) m; got -0.005")."""
    out = []
    for name, (lo, lo_valid) in UNIT_FIELDS.items():
        if name == "H2_mm" and p.H2_infinite:
            continue  # H₂ = ∞ is ticked: the typed H₂ is not used
        x = float(getattr(p, name))
        if math.isfinite(x) and (x > lo or (lo_valid and x == lo)):
            continue
        symbol, unit = _symbol_and_unit(LabParams.param[name].label)
        interval = f"{'[' if lo_valid else '('}{lo:g}, ∞) {unit}"
        if name == "H2_mm":
            interval += " (or tick H₂ = ∞ for a half-space)"
        out.append(f"{symbol} must be in {interval}; got {x:g} {unit}")
    return out


# --------------------------------------------------------------------------------------------
# lab values -> slider values
# --------------------------------------------------------------------------------------------


def slider_values(derived: dict[str, float]) -> tuple[dict[str, float | bool], list[str]]:
    """The SpectrumParams values for the model arguments `derived` (γ, f, β, η, Δ, ξ), each clamped to its declared
    range, and a message for every clamped value."""
    updates: dict[str, float | bool] = {}
    notes: list[str] = []
    for arg in SpectrumParams.MODEL_ARGS:
        x = derived[arg]
        decl = SpectrumParams.declaration(arg)
        if arg == "eta":
            updates["eta_infinite"] = math.isinf(x)
            if math.isinf(x):
                continue
        lo, hi = decl.physical_bounds()
        shown = min(max(x, lo), hi)
        if shown != x:
            notes.append(f"{decl.label} = {fmt(x)} is outside the slider's range {lo:g} … {hi:g}: set to {shown:g}")
        name = "log10_eta" if arg == "eta" else arg
        updates[name] = math.log10(shown) if decl.log10 else shown
    return updates, notes


def _model_args(values: dict[str, float | bool]) -> tuple[float, ...]:
    """(γ, f, β, η, Δ, ξ) of SpectrumParams values, normalised as :meth:`SpectrumParams.model_args` (ξ = 0 at Δ = 1)."""
    eta = math.inf if values["eta_infinite"] else 10.0 ** values["log10_eta"]
    return model_args(values["gamma"], values["f"], values["beta"], eta, values["Delta"], values["xi"])


def _show(x: float) -> str:
    """A slider value for a message (η may be ∞)."""
    return "∞" if x == math.inf else fmt(x)


def _close(a: float, b: float) -> bool:
    return a == b or math.isclose(a, b, rel_tol=MATCH_RTOL, abs_tol=1e-12)


@dataclass
class LabState:
    """Where the lab values and the sliders stand: the model's message for bad input, or the lab's γ, f, β, η, Δ, ξ,
    the slider values they give, the clamping notes and the sliders that show something else."""

    error: str = ""
    derived: dict[str, float] = field(default_factory=dict)
    updates: dict[str, float | bool] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    mismatches: list[str] = field(default_factory=list)

    @property
    def matches(self) -> bool:
        return not self.error and not self.mismatches


# --------------------------------------------------------------------------------------------
# the plot
# --------------------------------------------------------------------------------------------


def e_folding_axis_hook(plot, _element) -> None:
    """HoloViews plot hook: a right-hand axis on the plot's own y range (the growth rate), labelled with the
    e-folding time in ms; added once to the Bokeh figure."""
    fig = plot.state
    if not any(getattr(a, "name", None) == E_FOLDING_AXIS for a in fig.right):
        fig.add_layout(LinearAxis(name=E_FOLDING_AXIS, axis_label="e-folding time 1/(k Im c) [ms]",
                                  formatter=CustomJSTickFormatter(code=E_FOLDING_TICKS)), "right")


PLOT_OPTIONS = dict(logx=True, responsive=True, height=320, framewise=True, xlabel=WAVELENGTH_LABEL,
                    ylabel=RATE_LABEL, legend_position="top_right", title="Growth rate vs wavelength (lab values)",
                    legend_opts={"background_fill_alpha": 0.6},  # a stable curve runs along zero, under the legend
                    hooks=[zero_line_hook, e_folding_axis_hook])

#: room above the shown rates for the legend (top right; up to three rows) and below them, as fractions of their
#: span (zero included)
LEGEND_ROOM = 0.25
RATE_PADDING = 0.05


def wavelength_window(lam: np.ndarray, band: tuple[float, float], growing: bool) -> tuple[float, float]:
    """The λ range [mm] the lab plot shows: a decade either side of the unstable band `band` [mm] while a mode grows
    (the grid spans six decades of wavelength), otherwise the whole grid `lam` [mm, increasing]."""
    lo, hi = band
    if growing and np.isfinite(lo) and np.isfinite(hi):
        return max(lo / 10.0, float(lam[0])), min(hi * 10.0, float(lam[-1]))
    return float(lam[0]), float(lam[-1])


def rate_window(rate: np.ndarray) -> tuple[float, float]:
    """The growth-rate range [1/s] the lab plot shows for the rates `rate` it shows: their span with zero, padded,
    with room above for the legend. While a mode grows, the decay shown below zero is cut at the largest growth:
    the short wavelengths decay at millions per second and would flatten the growing part (the toolbar zooms
    out)."""
    finite = rate[np.isfinite(rate)]
    top = max(0.0, float(finite.max())) if finite.size else 0.0
    bottom = min(0.0, float(finite.min())) if finite.size else 0.0
    if top > 0.0:
        bottom = max(bottom, -top)
    span = top - bottom if top > bottom else 1.0
    return bottom - RATE_PADDING * span, top + LEGEND_ROOM * span


def plot_ranges(lam: np.ndarray, rate: np.ndarray, band: tuple[float, float],
                peak_rate: float) -> dict[str, tuple[float, float]]:
    """``xlim`` and ``ylim`` of the lab plot for the curve (`lam` [mm, increasing], `rate` [1/s]), the unstable band
    [mm] and the peak growth rate [1/s]; the y range is that of the rates inside the shown λ range.

    Both are set on every frame: a DynamicMap keeps a plot option that a later frame leaves out, so a stable
    setting shown after an unstable one kept the unstable one's ±1000 1/s."""
    growing = bool(np.isfinite(peak_rate) and peak_rate > 0)
    x0, x1 = wavelength_window(lam, band, growing)
    with np.errstate(invalid="ignore"):
        shown = rate[(lam >= x0) & (lam <= x1)]
    return {"xlim": (x0, x1), "ylim": rate_window(shown)}


class LabScene(pn.viewable.Viewer):
    """The Lab-units panel for one :class:`LabParams`, linked to one :class:`SpectrumParams`."""

    params = param.ClassSelector(class_=LabParams)
    spectrum = param.ClassSelector(class_=SpectrumParams)
    #: the lab setting in SI units, the arguments of :func:`compute_lab`
    key = param.Tuple(default=None, length=12, allow_None=True, precedence=-1)
    #: the panel's title, which says whether the sliders show the lab values
    title = param.String("Lab units", precedence=-1)

    def __init__(self, **kwargs) -> None:
        kwargs.setdefault("params", LabParams())
        kwargs.setdefault("spectrum", SpectrumParams())
        super().__init__(**kwargs)
        follow_material(self.params)
        self._update_key()
        lab_names = [n for n in declared_parameters(LabParams) if n != "link"] + ["H2_infinite"]
        self.params.param.watch(self._update_key, lab_names)
        self.param.watch(self._changed, "key")
        self.params.param.watch(self._changed, "link")
        self.spectrum.param.watch(self._update_title, [n for n in self.spectrum.param if n != "name"])
        self._update_title()
        self.plot_dmap = hv.DynamicMap(self.lab_plot)

    # ----------------------------------------------------------------------------------------
    # state
    # ----------------------------------------------------------------------------------------

    def _update_key(self, *_events) -> None:
        p = self.params
        h2 = math.inf if p.H2_infinite else p.H2_mm * 1e-3
        key = (float(p.rho), float(p.c_s), float(p.c_d), p.sigma0_MPa * 1e6, float(p.f), p.H1_mm * 1e-3, h2,
               float(p.v), float(p.a), float(p.b), p.D_c_um * 1e-6, p.plane)
        if key != self.key:
            self.key = key

    def _changed(self, *_events) -> None:
        """A lab value changed or the link was switched on: with the link on, set the sliders."""
        if self.params.link:
            self.apply()
        self._update_title()

    def lab(self) -> dict:
        """γ, f, β, η, Δ, ξ of the lab setting (:func:`compute_lab`), or the model's message."""
        return compute_lab(*self.key)

    def _error_text(self, model_message: str) -> str:
        """What the panel says when the model refused the lab values: the fields typed in mm, MPa or µm that are out
        of range, in those units (the model's message speaks of metres and pascals); otherwise the model's message
        (the other fields are in the model's own units)."""
        return "; ".join(unit_field_errors(self.params)) or model_message

    def state(self) -> LabState:
        """The lab values against the sliders (cheap: the dimensionless parameters are cached)."""
        d = self.lab()
        if "error" in d:
            return LabState(error=self._error_text(d["error"]))
        updates, notes = slider_values(d["params"])
        target = _model_args(updates)
        shown = self.spectrum.model_args()
        mismatches = [f"{SpectrumParams.symbol(n)} = {_show(s)} on the slider, {_show(t)} from the lab values"
                      for n, s, t in zip(SpectrumParams.MODEL_ARGS, shown, target, strict=True) if not _close(s, t)]
        return LabState(derived=d["params"], updates=updates, notes=notes, mismatches=mismatches)

    def apply(self, *_events) -> bool:
        """Set the sliders to the lab values (clamped to their ranges) in one update; False (sliders unchanged) for
        bad input."""
        st = self.state()
        if st.error:
            return False
        with frozen_document():
            self.spectrum.param.update(**st.updates)
        return True

    def _update_title(self, *_events) -> None:
        st, link = self.state(), self.params.link
        if st.error:
            text = "Lab units: the lab values are not valid (sliders unchanged)"
        elif not link:
            text = ("Lab units (link off): the sliders match the lab values" if st.matches else
                    "Lab units: set the sliders from a lab setting (material, heights, σ₀, friction; link off)")
        elif st.mismatches:
            text = "Lab units: the sliders no longer match the lab values"
        else:
            text = "Lab units: the sliders follow the lab values"
        if text != self.title:
            self.title = text

    def lab_args(self) -> tuple[float, ...] | None:
        """The lab setting's (γ, f, β, η, Δ, ξ) for the model (unclamped; ξ = 0 at Δ = 1), None for bad input."""
        d = self.lab()
        if "error" in d:
            return None
        p = d["params"]
        return model_args(p["gamma"], p["f"], p["beta"], p["eta"], p["Delta"], p["xi"])

    def data(self) -> dict | None:
        """The lab spectrum (None for bad input)."""
        args = self.lab_args()
        if args is None:
            return None
        return compute_lab_spectrum(*args, self.key[5], self.key[1])

    # ----------------------------------------------------------------------------------------
    # views
    # ----------------------------------------------------------------------------------------

    @param.depends("key", "params.link", "spectrum.gamma", "spectrum.f", "spectrum.beta", "spectrum.log10_eta",
                   "spectrum.eta_infinite", "spectrum.Delta", "spectrum.xi")
    def status(self) -> pn.viewable.Viewable:
        """The visible message: bad input (the model's words), clamped values, and whether the sliders match."""
        st = self.state()
        if st.error:
            return pn.pane.Alert("**The lab values are not valid; the sliders are unchanged.** "
                                 + html.escape(st.error, quote=False),
                                 alert_type="danger", sizing_mode="stretch_width")
        lines = []
        if st.mismatches and self.params.link:
            lines.append("**The sliders no longer match the lab values** (" + "; ".join(st.mismatches)
                         + "). *Apply the lab values* sets them again.")
        elif st.mismatches:
            lines.append("**The sliders differ from the lab values** (" + "; ".join(st.mismatches)
                         + "). Tick *Sliders follow the lab values*, or *Apply the lab values* once, to set them.")
        elif self.params.link:
            lines.append("**The sliders follow the lab values.**")
        else:
            lines.append("**The sliders match the lab values.** The link is off: lab changes do not move them.")
        if st.notes:
            lines.append("**Clamped to the sliders' ranges:** " + "; ".join(st.notes) + ".")
        kind = "warning" if st.mismatches or st.notes else "success"
        return pn.pane.Alert("\n\n".join(lines), alert_type=kind, sizing_mode="stretch_width")

    @param.depends("key")
    def derived_view(self) -> str:
        """The lab setting's dimensionless parameters."""
        d = self.lab()
        if "error" in d:
            return ""
        p = d["params"]
        eta = "∞" if math.isinf(p["eta"]) else fmt(p["eta"])
        xi = fmt(p["xi"]) + (" (does not enter at Δ = 1)" if p["Delta"] == 1 else "")
        return (f"**Lab values as the model's parameters:** γ = {fmt(p['gamma'])}, f = {fmt(p['f'])}, "
                f"β = {fmt(p['beta'])}, η = {eta}, Δ = {fmt(p['Delta'])}, ξ = {xi}")

    @param.depends("key")
    def readout(self) -> str:
        """The lab setting's fastest-growing mode and unstable band in lab units."""
        d = self.data()
        if d is None:
            return "**Lab units:** — (the lab values are not valid)"
        pk = d["peak"]
        lines = []
        if np.isfinite(pk["growth_rate"]) and pk["growth_rate"] > 0:
            lines += [
                f"**Fastest-growing mode of the Rayleigh branch** (largest k Im c, at kH = {fmt(d['kH_star'])}): "
                f"wavelength "
                f"λ = {fmt(pk['wavelength'] * 1e3)} mm",
                f"**Growth rate** {fmt(pk['growth_rate'])} 1/s, "
                f"**e-folding time** {fmt(pk['e_folding_time'] * 1e3)} ms",
                f"**Phase speed** {fmt(pk['phase_speed'])} m/s",
            ]
        else:
            lines.append("**No growing mode**: steady sliding is stable on the Rayleigh branch over the computed "
                         f"kH = {KH[0]:g} … {KH[-1]:g}")
        lo, hi = d["band"]
        if np.isfinite(lo) and np.isfinite(hi):
            lines.append(f"**Unstable band** {fmt(lo * 1e3)} mm < λ < {fmt(hi * 1e3)} mm")
        elif np.isfinite(d["growth"]) and d["growth"] > 0:
            lines.append("**Unstable band** extends beyond the computed kH range")
        masked = int(np.count_nonzero(~np.isfinite(d["z"])))
        lines.append(f"**Masked** {masked} of {KH.size} kH points (gaps in the plot)" if masked else "**Masked** none")
        args = self.lab_args()
        if args is not None:
            lines += sliding_lab_lines(compute_lab_sliding(*args, self.key[5], self.key[1]))
        return "\n\n".join(lines)

    @param.depends("key", "spectrum.gamma", "spectrum.f", "spectrum.beta", "spectrum.log10_eta",
                   "spectrum.eta_infinite", "spectrum.Delta", "spectrum.xi")
    def point_readout(self) -> str:
        """The sliders' point in lab units while it differs from the lab values (e.g. after a click on the stability
        map): its fastest-growing mode with the panel's H₁ and c_s, and the a, b, D_c, H₂ that give its γ, Δ, ξ, η
        with the panel's material, σ₀, H₁ and v."""
        st = self.state()
        if st.error or st.matches:
            return ""
        gamma, f, beta, eta, Delta, xi = self.spectrum.model_args()
        rho, c_s, _, sigma0, _, H1, _, v = self.key[:8]
        d = compute_lab_spectrum(gamma, f, beta, eta, Delta, xi, H1, c_s)
        pk = d["peak"]
        lines = [f"**The sliders' point in lab units** (H₁ = {fmt(H1 * 1e3)} mm, c_s = {fmt(c_s)} m/s):"]
        if np.isfinite(pk["growth_rate"]) and pk["growth_rate"] > 0:
            lines.append(f"fastest-growing λ = {fmt(pk['wavelength'] * 1e3)} mm, growth rate "
                         f"{fmt(pk['growth_rate'])} 1/s, e-folding time {fmt(pk['e_folding_time'] * 1e3)} ms, phase "
                         f"speed {fmt(pk['phase_speed'])} m/s.")
        else:
            lines.append("no growing mode on the Rayleigh branch.")
        lines += [line.replace("**", "") + "." for line in
                  sliding_lab_lines(compute_lab_sliding(gamma, f, beta, eta, Delta, xi, H1, c_s))]
        r = compute_rate_state(gamma, Delta, xi, eta, rho, c_s, sigma0, H1, v)
        if "error" not in r:
            h2 = "∞" if math.isinf(r["H2"]) else f"{fmt(r['H2'] * 1e3)} mm"
            lines.append(f"Its γ, Δ, ξ, η are a = {fmt(r['a'])}, b = {fmt(r['b'])}, D_c = {fmt(r['D_c'] * 1e6)} µm, "
                         f"H₂ = {h2} at v = {fmt(v)} m/s, σ₀ = {fmt(sigma0 / 1e6)} MPa, ρ = {fmt(rho)} kg/m³ "
                         "(model.rate_state_parameters)" + ("; D_c does not enter at Δ = 1." if Delta == 1 else "."))
        if not _close(beta, st.derived["beta"]):
            lines.append(f"Its β = {fmt(beta)} is not the material's ({fmt(st.derived['beta'])}).")
        return " ".join(lines)

    @param.depends("key")
    def lab_plot(self) -> hv.Overlay:
        """Growth rate [1/s] vs wavelength [mm] of the lab setting, with the unstable band and the fastest-growing
        mode; the right axis reads the same rates as e-folding times [ms]."""
        d = self.data()
        layers: list[hv.Element] = []
        opts = dict(PLOT_OPTIONS)
        if d is None:
            layers.append(hv.Curve(([], []), WAVELENGTH_LABEL, RATE_LABEL, label="growth rate"))
        else:
            lam, rate = d["wavelength"][::-1] * 1e3, d["growth_rate"][::-1]
            lo, hi = d["band"]
            if np.isfinite(lo) and np.isfinite(hi):
                layers.append(hv.VSpans([(lo * 1e3, hi * 1e3)], label="unstable band").opts(color="#f4a582",
                                                                                          alpha=0.35))
            layers.append(hv.Curve((lam, rate), WAVELENGTH_LABEL, RATE_LABEL, label="growth rate").opts(
                color="#1f4e79", line_width=2))
            pk = d["peak"]
            if np.isfinite(pk["growth_rate"]) and pk["growth_rate"] > 0:
                layers.append(hv.Scatter(([pk["wavelength"] * 1e3], [pk["growth_rate"]]), WAVELENGTH_LABEL,
                                         RATE_LABEL, label="fastest-growing mode").opts(color="#b2182b", size=9))
            opts.update(plot_ranges(lam, rate, (lo * 1e3, hi * 1e3), pk["growth_rate"]))
        return hv.Overlay(layers).opts(hv.opts.Overlay(**opts))

    def csv(self) -> io.StringIO:
        """What the lab plot shows, with the phase speed: λ [mm], kH, growth rate [1/s], e-folding time [ms], phase
        speed [m/s] (NaN where the model masked the point; the e-folding time only where the mode grows: NaN where
        it decays, as the plot's right axis shows "—" there)."""
        d = self.data()
        p = self.params
        header = (f"asymslide lab spectrum; material = {p.material}, rho = {p.rho!r} kg/m^3, c_s = {p.c_s!r} m/s, "
                  f"c_d = {p.c_d!r} m/s, plane = {p.plane}, H1 = {p.H1_mm!r} mm, "
                  f"H2 = {'inf' if p.H2_infinite else repr(p.H2_mm)} mm, sigma0 = {p.sigma0_MPa!r} MPa, f = {p.f!r}, "
                  f"a = {p.a!r}, b = {p.b!r}, D_c = {p.D_c_um!r} um, v = {p.v!r} m/s")
        if d is None:
            return csv_table(header + " (not valid)", {"wavelength_mm": [], "kH": [], "growth_rate_per_s": [],
                                                       "e_folding_time_ms": [], "phase_speed_m_per_s": []})
        with np.errstate(invalid="ignore"):
            growing = d["growth_rate"] > 0
        e_folding = np.where(growing, d["e_folding_time"] * 1e3, np.nan)
        return csv_table(header + "; e_folding_time_ms only where the mode grows (NaN: it decays or is masked)",
                         {"wavelength_mm": d["wavelength"] * 1e3, "kH": d["kH"],
                          "growth_rate_per_s": d["growth_rate"], "e_folding_time_ms": e_folding,
                          "phase_speed_m_per_s": d["phase_speed"]})

    def _body(self, with_plot: bool) -> list[pn.viewable.Viewable]:
        w = self.params.make_widgets()
        link = w.pop("link")
        apply = pn.widgets.Button(label="Apply the lab values to the sliders", color="primary", width=280)
        apply.on_click(self.apply)
        fields = pn.GridBox(*w.values(), ncols=3, sizing_mode="stretch_width")
        body: list[pn.viewable.Viewable] = [
            pn.pane.Markdown(ASSUMPTION, sizing_mode="stretch_width"),
            reference_card("12.3"),
            fields,
            pn.Row(link, apply, sizing_mode="stretch_width"),
            pn.panel(self.status),
            pn.pane.Markdown(self.derived_view, sizing_mode="stretch_width"),
            pn.pane.Markdown(self.readout, sizing_mode="stretch_width"),
            pn.pane.Markdown(self.point_readout, sizing_mode="stretch_width"),
        ]
        if with_plot:
            # linked_axes=False: its λ axis must not take over (or be taken over by) another plot's range
            body += [pn.pane.HoloViews(self.plot_dmap, sizing_mode="stretch_width", linked_axes=False),
                     csv_download(self.csv, "lab_spectrum.csv", "Download CSV (lab units)")]
        return body

    def panel(self, with_plot: bool = True) -> pn.Card:
        """The panel: a card, collapsed unless the link is on, whose content is built when it is first opened (a new
        session pays for it only if it is used)."""
        card = pn.Card(title=self.param.title, collapsed=not self.params.link, sizing_mode="stretch_width",
                       header_color="#1f4e79")

        def fill(*_events) -> None:
            if not card.collapsed and not card.objects:
                card.objects = self._body(with_plot)

        card.param.watch(fill, "collapsed")
        fill()
        return card

    def __panel__(self) -> pn.viewable.Viewable:
        return self.panel(with_plot=True)
