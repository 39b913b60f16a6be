"""The user-facing parameters, declared once, and what is derived from the declarations: widgets, URL keys,
stability-map axes (see :class:`Physical`); plus the helpers every scene uses (readout numbers, CSV export,
the frozen-document context for parameter changes, the zero line of the plots).

Data flow: widget (sliders on release) -> parameter -> cached model call -> HoloViews element.
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import holoviews as hv
import numpy as np
import panel as pn
import param
from bokeh.models import BasicTickFormatter, ColorBar, CustomJSTickFormatter, GlyphRenderer, LogColorMapper, Span
from panel.custom import JSComponent
from param.parameterized import Undefined

from asymslide import model

from .workarounds import frozen_document

hv.extension("bokeh", logo=False)
# plotly.js with every page (served by this server from Panel's bundle): the Atlas tab's 3-D view is created after
# the page has loaded (a lazily built tab), when it is too late to add a JavaScript library to the page
#: Panel settings every session needs. A lost server (stopped, restarted, network gone) is said on the page: the plots
#: stop following the controls, and without it nothing but the unchanged plots would tell. Set inside a session, Panel
#: keeps them for that session only: :func:`configure_session` sets them in each served one (app/main.py).
SESSION_CONFIG: dict[str, Any] = {
    "notifications": True,
    "disconnect_notification": "Connection to the asymslide server lost: the plots no longer follow the controls. "
                               "Reload the page once the server is back.",
}
pn.extension("plotly", "katex", **SESSION_CONFIG)  # katex: the equations of the Spectrum and All-branches tabs


def configure_session() -> None:
    """Apply :data:`SESSION_CONFIG` to the current session. Panel keeps a setting made while a session is being built
    (``pn.extension`` above runs when this module is first imported: inside the server process's first session) for
    that session alone. Without it, the next sessions had no notification area: no banner when the server is lost,
    and with ``--reuse-sessions`` (every page is the first session's HTML, whose roots a session's document fills in
    order) one root fewer, so the page's introduction was drawn in the header's busy-indicator slot."""
    for name, value in SESSION_CONFIG.items():
        setattr(pn.config, name, value)
# Canvas, not WebGL: the plots hold at most a few thousand points, and copying the WebGL layer onto
# the canvas (software GL without a GPU) was most of a browser update in Chromium's profile
# (benchmarks/design_measurements.md). Image-based plots are unaffected.
hv.renderer("bokeh").webgl = False

#: tick labels of a linear axis or colour bar (a CustomJSTickFormatter's code: `tick` and all the axis's `ticks`), one
#: style on every plot: zero as "0" (Bokeh's default wrote "0.000e+0" beside "5.000e-4"), plain numbers with the
#: fewest digits that tell the ticks apart ("0.05", "0.15", "120"), and where the largest |tick| is 10⁴ or more or
#: below 10⁻³ one power of ten for the axis ("2×10⁻⁵", "1.5×10⁵"). Log axes keep Bokeh's 10ⁿ labels.
TICKS_JS = """
const finite = ticks.filter(t => Number.isFinite(t));
const step = finite.length > 1 ? Math.abs(finite[1] - finite[0]) : (Math.abs(tick) || 1);
if (!Number.isFinite(tick)) return '';
if (Math.abs(tick) <= step * 1e-9) return '0';
const big = Math.max(...finite.map(t => Math.abs(t)));
const sci = big >= 1e4 || big < 1e-3;
const e = sci ? Math.floor(Math.log10(big) + 1e-9) : 0;
const scale = Math.pow(10, e);
let d = 0;  // the fewest decimals (of the mantissas, with a power of ten) that write every tick to 1e-6 of the step
while (d < 12 && !finite.every(t => Math.abs(Number((t / scale).toFixed(d)) * scale - t) <= step * 1e-6)) d++;
const m = String(Number((tick / scale).toFixed(d))).replace('-', '−');
if (!sci) return m;
const sup = String(e).replace(/./g, c => '⁻⁰¹²³⁴⁵⁶⁷⁸⁹'['-0123456789'.indexOf(c)]);
return m + '×10' + sup;
"""


def readable_ticks() -> CustomJSTickFormatter:
    """A new formatter with :data:`TICKS_JS` (a Bokeh model belongs to one document: one per axis)."""
    return CustomJSTickFormatter(code=TICKS_JS)


def readable_ticks_hook(plot, _element) -> None:
    """HoloViews plot hook (every element's by default, below): the figure's linear axes and linear colour bars
    label their ticks with :data:`TICKS_JS` instead of Bokeh's BasicTickFormatter. Formatters set on purpose (log
    axes, the Lab panel's wavelength axis) are kept."""
    fig = plot.state
    for axis in fig.axis:
        if type(axis.formatter) is BasicTickFormatter:
            axis.formatter = readable_ticks()
    for bar in (m for m in (*fig.right, *fig.left, *fig.above, *fig.below) if isinstance(m, ColorBar)):
        if (type(bar.formatter) is BasicTickFormatter or bar.formatter == "auto") and not isinstance(
                bar.color_mapper, LogColorMapper):
            bar.formatter = readable_ticks()


#: the elements the app draws (and a few more), for the defaults below
ELEMENT_KINDS = ("Curve", "Scatter", "Points", "Path", "QuadMesh", "HLine", "VLine", "VLines", "VSpans", "Bounds",
                 "Area", "Spread", "Image", "HSpans", "Segments", "Rectangles")
# Axes follow the data when the parameters change. HoloViews takes `framewise` from each element's
# options: set on the Overlays only (as before), every plot kept the ranges of its first frame and a
# curve that grew beyond them was cut off (tests/app/test_app_ranges.py). Every element's plot also runs
# readable_ticks_hook: the hooks of an element's plot run even when it is overlaid, and the app sets hooks on
# Overlays only, so none replaces it.
hv.opts.defaults(*(getattr(hv.opts, kind)(framewise=True, hooks=[readable_ticks_hook]) for kind in ELEMENT_KINDS))

#: colours of families of curves (colour-blind safe, Okabe-Ito)
PALETTE = ("#E69F00", "#56B4E9", "#009E73", "#CC79A7", "#D55E00", "#0072B2", "#999999", "#F0E442")


def fmt(x: float, digits: int = 4) -> str:
    """A number for a readout, or an em dash where the model returned NaN/inf."""
    return "—" if not np.isfinite(x) else f"{x:.{digits}g}"


#: name of the Bokeh Span drawn by :func:`zero_line_hook`
ZERO_LINE = "zero line"


def zero_line_hook(plot, _element) -> None:
    """HoloViews plot hook: a black horizontal line at y = 0, added once to the Bokeh figure.

    A Bokeh ``Span`` instead of an ``hv.HLine`` element: it takes no part in HoloViews' per-update work
    (one subplot less to refresh per plot and update) and never needs re-sending.
    """
    fig = plot.state
    if not any(getattr(r, "name", None) == ZERO_LINE for r in fig.center):
        fig.add_layout(Span(location=0, dimension="width", line_color="black", line_width=1, name=ZERO_LINE))


#: fraction of the data's span added above and below it by :func:`fit_y_hook`
Y_PADDING = 0.05


def y_extent(fig) -> tuple[float, float] | None:
    """(lowest, highest) finite y of what a Bokeh figure shows: its visible glyphs' y columns and its horizontal
    lines (Spans: the zero line, a criterion level); None if it shows nothing."""
    values = [np.array([s.location], dtype=float) for s in fig.center
              if isinstance(s, Span) and s.dimension == "width" and s.visible and s.location is not None]
    for r in fig.renderers:
        if not isinstance(r, GlyphRenderer) or not r.visible:
            continue
        field = getattr(r.glyph, "y", None)
        if isinstance(field, str) and field in r.data_source.data:
            values.append(np.asarray(r.data_source.data[field], dtype=float).ravel())
    finite = np.concatenate(values) if values else np.empty(0)
    finite = finite[np.isfinite(finite)]
    return (float(finite.min()), float(finite.max())) if finite.size else None


def fit_y_hook(plot, _element) -> None:
    """HoloViews plot hook: the y range spans every curve shown, with :data:`Y_PADDING`.

    HoloViews computes an overlay's range from the layers of its first frame: the curves a preset adds later (a
    family of γ, Δ or kW values) went off the plot. Hooks run after HoloViews' own range update, at every frame."""
    extent = y_extent(plot.state)
    if extent is None:
        return
    lo, hi = extent
    pad = Y_PADDING * (hi - lo) if hi > lo else max(abs(lo) * 0.1, 1e-3)
    plot.state.y_range.update(start=lo - pad, end=hi + pad)


def csv_table(header: str, columns: Mapping[str, np.ndarray]) -> io.StringIO:
    """Columns of equal length as CSV with full float precision; `header` becomes a '#' comment line."""
    out = io.StringIO()
    data = np.column_stack([np.asarray(c, dtype=float) for c in columns.values()])
    np.savetxt(out, data, delimiter=",", fmt="%.17g", comments="",
               header="# " + header.replace("\n", " ") + "\n" + ",".join(columns))
    out.seek(0)
    return out


def csv_download(callback: Callable[[], io.StringIO], filename: str, label: str) -> pn.widgets.FileDownload:
    """A button that downloads what `callback` returns (computed on click, from the cached data)."""
    return pn.widgets.FileDownload(callback=callback, filename=filename, label=label, color="primary",
                                   width=200)


def set_frozen(obj: param.Parameterized, name: str, value: object) -> None:
    """``setattr(obj, name, value)`` with the document frozen (:func:`frozen_document`)."""
    with frozen_document():
        setattr(obj, name, value)


def from_log10(x: float) -> float:
    """10**x rounded to 12 significant digits (10**log10(5) is 5, not 4.999999999999999)."""
    return float(f"{10.0 ** x:.12g}")


class Physical(param.Number):
    """A number the user sets, declared once with everything the app derives from it.

    The standard slots give the paper's symbol (``label``), the valid range (``bounds``), the slider range
    (``softbounds``, default: bounds), the slider ``step`` and the ``doc``. The extra slots say how the
    parameter appears elsewhere:

    - ``url``: its key in the URL query (None: not in the URL);
    - ``log10``: the parameter holds log10 of the physical value (URL values, slider ticks and map axes are in
      the physical value);
    - ``axis``: ``(lo, hi, log)`` of its stability-map axis, in the physical value (None: never a map axis);
    - ``widget``: "slider" or "input" (a number field, for values typed rather than dragged);
    - ``infinite``: the name of the Boolean parameter that, when True, makes the value ∞ (η = ∞, H₂ = ∞; "inf" in
      the URL).
    """

    __slots__ = ["url", "log10", "axis", "widget", "infinite"]
    _slot_defaults = dict(param.Number._slot_defaults, url=None, log10=False, axis=None, widget="slider",
                          infinite=None)

    def __init__(self, default: Any = Undefined, *, url: Any = Undefined, log10: Any = Undefined,
                 axis: Any = Undefined, widget: Any = Undefined, infinite: Any = Undefined, **params: Any) -> None:
        super().__init__(default=default, **params)
        self.url = url
        self.log10 = log10
        self.axis = axis
        self.widget = widget
        self.infinite = infinite

    def physical_bounds(self) -> tuple[float, float]:
        """The valid range of the physical value (10**bounds for a log10 parameter)."""
        lo, hi = self.bounds
        return (10.0**lo, 10.0**hi) if self.log10 else (lo, hi)


class Choice(param.Selector):
    """A choice from a fixed list (a material preset, plane strain or stress), declared once like :class:`Physical`:
    ``label`` is shown, ``url`` is its key in the URL query, where only the listed ``objects`` are accepted, or the
    ASCII ``words`` given for them (object -> word: "eta-gamma" for the plane "η-γ")."""

    __slots__ = ["url", "words"]
    _slot_defaults = dict(param.Selector._slot_defaults, url=None, words=None)

    def __init__(self, default: Any = Undefined, *, objects: Any = Undefined, url: Any = Undefined,
                 words: Any = Undefined, **params: Any) -> None:
        super().__init__(default=default, objects=objects, **params)
        self.url = url
        self.words = words


class Switch(param.Boolean):
    """An on/off setting with a URL key (``url``; written 1 or 0), declared once like :class:`Physical`."""

    __slots__ = ["url"]
    _slot_defaults = dict(param.Boolean._slot_defaults, url=None)

    def __init__(self, default: Any = Undefined, *, url: Any = Undefined, **params: Any) -> None:
        super().__init__(default=default, **params)
        self.url = url


def physical_parameters(cls: type[param.Parameterized]) -> dict[str, Physical]:
    """Name -> declaration of every :class:`Physical` parameter of `cls`, in declaration order."""
    return {name: p for name, p in cls.param.objects("existing").items() if isinstance(p, Physical)}


def declared_parameters(cls: type[param.Parameterized]) -> dict[str, Physical | Choice | Switch]:
    """Name -> declaration of every :class:`Physical`, :class:`Choice` and :class:`Switch` parameter of `cls`, in
    declaration order (what the URL query can hold)."""
    return {name: p for name, p in cls.param.objects("existing").items() if isinstance(p, Physical | Choice | Switch)}


#: the paper's symbols and meanings of the model's parameters (declared once, in model.PARAMETERS); the app adds the
#: user-interface side: slider ranges and steps, URL keys, map axes
_SYMBOL = {name: p.symbol for name, p in model.PARAMETERS.items()}
#: the paper's default values of the model's parameters (model.Parameter.default)
_DEFAULT = {name: p.default for name, p in model.PARAMETERS.items()}
_MEANING = {name: p.description for name, p in model.PARAMETERS.items()}


def model_args(gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float) -> tuple[float, ...]:
    """(γ, f, β, η, Δ, ξ) as every scene passes them to the model: floats, and ξ = 0 at Δ = 1 (ξ does not enter F
    then), so that moving the ξ slider at Δ = 1 is not a new cache key. The one place this rule is written."""
    return (float(gamma), float(f), float(beta), float(eta), float(Delta), 0.0 if Delta == 1 else float(xi))


class SpectrumParams(param.Parameterized):
    """The physical parameters of the spectrum (paper Sect. IV; docs/physics.md §1), shared by the Spectrum,
    Stability-map and All-branches scenes. Defaults: the paper's, declared once in model.PARAMETERS (γ = 3, f = 0.9,
    β = 0.3, η = ∞, Δ = 1, ξ = 0: Fig. 5; the η slider shows 10⁸ while η = ∞ is ticked)."""

    gamma = Physical(_DEFAULT["gamma"], bounds=(1e-2, 1e3), softbounds=(0.1, 30.0), step=0.01, label=_SYMBOL["gamma"],
                     url="gamma", axis=(0.1, 30.0, True), doc=_MEANING["gamma"])
    f = Physical(_DEFAULT["f"], bounds=(0.0, 2.0), step=0.01, label=_SYMBOL["f"], url="f", axis=(0.0, 2.0, False),
                 doc=_MEANING["f"])
    beta = Physical(_DEFAULT["beta"], bounds=(0.01, 0.7071), step=0.001, label=_SYMBOL["beta"], url="beta",
                    axis=(0.01, 0.7071, False), doc=_MEANING["beta"] + " (β² = (1 − 2ν)/(2 − 2ν))")
    #: True while a slider of these parameters is held (app.params.bind_two_way): the plots follow the hand, the
    #: background jobs and maps wait for the release
    dragging = param.Boolean(False, precedence=-1)

    log10_eta = Physical(8.0, bounds=(-2.0, 12.0), step=0.1, label=_SYMBOL["eta"], url="eta", log10=True,
                         axis=(1.0, 1e8, True), infinite="eta_infinite", doc=_MEANING["eta"] + " (slider: log10 η)")
    eta_infinite = param.Boolean(math.isinf(_DEFAULT["eta"]), label=f"{_SYMBOL['eta']} = ∞",
                                 doc="the lower block is a half-space (η = ∞)")
    Delta = Physical(_DEFAULT["Delta"], bounds=(0.01, 1.0), step=0.01, label=_SYMBOL["Delta"], url="Delta",
                     axis=(0.01, 1.0, False), doc=_MEANING["Delta"])
    xi = Physical(_DEFAULT["xi"], bounds=(0.0, 1e4), softbounds=(0.0, 10.0), step=0.01, label=_SYMBOL["xi"], url="xi",
                  axis=(1e-2, 1e3, True), doc=_MEANING["xi"])

    #: the model's keyword arguments, in the order of :meth:`model_args`
    MODEL_ARGS = ("gamma", "f", "beta", "eta", "Delta", "xi")

    @property
    def eta(self) -> float:
        return math.inf if self.eta_infinite else 10.0**self.log10_eta

    def model_args(self) -> tuple[float, float, float, float, float, float]:
        """(gamma, f, beta, eta, Delta, xi) as passed to the model (:func:`model_args`)."""
        return model_args(self.gamma, self.f, self.beta, self.eta, self.Delta, self.xi)

    @classmethod
    def declaration(cls, model_arg: str) -> Physical:
        """The declaration behind a model argument (``eta`` is held as ``log10_eta``)."""
        return cls.param["log10_eta" if model_arg == "eta" else model_arg]

    @classmethod
    def symbol(cls, model_arg: str) -> str:
        """The paper's symbol of a model argument."""
        return cls.declaration(model_arg).label

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`); ξ is disabled while Δ = 1 and η while
        η = ∞ is ticked."""
        w = make_widgets(self)
        w["xi"].disabled = self.Delta == 1

        def show_eta(infinite: bool) -> None:
            """While η = ∞ is ticked the slider is disabled and shows no number (not its last finite value; the
            box below it says ∞). BokehJS does not redraw a slider's title for a new `format`: a formatter that read
            ∞ kept reading ∞ after the box was unticked, so the number is hidden instead."""
            w["log10_eta"].param.update(disabled=infinite, show_value=not infinite)

        show_eta(self.eta_infinite)
        self.param.watch(lambda e: setattr(w["xi"], "disabled", e.new == 1), "Delta")
        self.param.watch(lambda e: show_eta(e.new), "eta_infinite")
        return w


class ThinOnThickParams(param.Parameterized):
    """The parameters of the thin-on-thick scene (paper Sect. III; docs/physics.md §6). Defaults: the PMMA
    experiment of Sect. S-V (kW = 5, ν = 0.33). Its material constants c_s, ρ and σ₀ are the shared ones of the
    Lab-units panel (:class:`LabParams`: PMMA, c_s = 1345 m/s, ρ = 1180 kg/m³ assumed, σ₀ = 4.5 MPa)."""

    log10_kW = Physical(math.log10(5.0), bounds=(-2.0, 2.0), step=0.01, label="kW", url="kW", log10=True,
                        doc="kW: wavenumber k times the thin block's width W (slider: log10 kW)")
    nu = Physical(0.33, bounds=(0.0, 0.49), step=0.005, label="ν", url="nu", doc="Poisson ratio ν")

    #: the URL holds only the values that differ from the defaults
    URL_CHANGED_ONLY = True

    @property
    def kW(self) -> float:
        return from_log10(self.log10_kW)

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`)."""
        return make_widgets(self)


#: the material choice that keeps the typed values (a preset's values edited by hand)
CUSTOM = "custom"

# The lab and rupture quantities are typed, and the model decides whether they are physical (positive heights and
# speeds, b < a, a Poisson ratio in (-1, 0.5), c < c_R; docs/physics.md §12.8, §13): their declared bounds only cap
# the magnitude, so that, e.g., a negative height reaches the model and its message is shown instead of the field
# silently refusing it.


class LabParams(param.Parameterized):
    """A laboratory setting in lab units (docs/physics.md §12), mapped onto γ, f, β, η, Δ, ξ by
    :func:`model.dimensionless_parameters` (the Lab-units panel of the Spectrum and Stability-map scenes).

    Its material constants (:data:`SHARED_MATERIAL`: the material, ρ, c_s, σ₀) are the page's one set: the
    Thin-on-thick and Rupture-fronts scenes use them too and show widgets bound to them.

    Defaults: the PMMA preset (ρ = 1180 kg/m³, an assumption; c_s = 1345 m/s, c_d = 2700 m/s), plane strain (the
    paper's Sect. IV), H₁ = 10 mm on a half-space (η = ∞), σ₀ = 4.5 MPa, f = 0.9, and rate-and-state a = 0.01,
    b = 0 (Δ = 1), D_c = 1 µm at v = 0.08506 m/s: γ = 3.000, f, η and Δ are the paper's Fig. 4 values; β = 0.498
    is PMMA's (no preset has the paper's β = 0.3, ν = 0.45); ξ = 1.58 does not enter at Δ = 1.
    """

    material = Choice("PMMA", objects=[*model.material_names(), CUSTOM], label="Material", url="material",
                      doc="material preset: fills in ρ, c_s, c_d (model/materials.json); editing them makes it custom")
    rho = Physical(1180.0, bounds=(-1e6, 1e6), step=10.0, label="ρ [kg/m³]", url="lab_rho", widget="input",
                   doc="density ρ [kg/m³]; μ = ρ c_s²")
    c_s = Physical(1345.0, bounds=(-1e6, 1e6), step=1.0, label="c_s [m/s]", url="lab_cs", widget="input",
                   doc="shear wave speed c_s [m/s]")
    c_d = Physical(2700.0, bounds=(-1e6, 1e6), step=1.0, label="c_d [m/s] (bulk)", url="lab_cd", widget="input",
                   doc="dilatational wave speed c_d [m/s], the bulk (3-D) value that ultrasound measures")
    plane = Choice("strain", objects=["strain", "stress"], label="Plane", url="plane",
                   doc="plane strain (thick blocks, the paper's Sect. IV) or plane stress (thin plates): sets β")
    H1_mm = Physical(10.0, bounds=(-1e6, 1e6), step=1.0, label="H₁ [mm]", url="H1", widget="input",
                     doc="height H₁ = H of the upper block [mm] (the H of kH)")
    H2_mm = Physical(30.0, bounds=(-1e6, 1e6), step=1.0, label="H₂ [mm]", url="H2", widget="input",
                     infinite="H2_infinite", doc="height H₂ of the lower block [mm]; η = H₂/H₁")
    H2_infinite = param.Boolean(True, label="H₂ = ∞ (half-space)", doc="the lower block is a half-space (η = ∞)")
    sigma0_MPa = Physical(4.5, bounds=(-1e6, 1e6), step=0.1, label="σ₀ [MPa]", url="lab_sigma0", widget="input",
                          doc="normal stress σ₀ [MPa]")
    f = Physical(0.9, bounds=(-100.0, 100.0), step=0.01, label="f (friction coefficient)", url="lab_f",
                 widget="input", doc="steady-state friction coefficient f at the sliding velocity v")
    a = Physical(0.01, bounds=(-100.0, 100.0), step=0.001, label="a (direct effect)", url="a", widget="input",
                 doc="rate-and-state a: ∂_v f = a/v (Dieterich-Ruina, an assumption: docs/physics.md §12.3)")
    b = Physical(0.0, bounds=(-100.0, 100.0), step=0.001, label="b (state effect)", url="b", widget="input",
                 doc="rate-and-state b, 0 ≤ b < a: Δ = 1 − b/a")
    D_c_um = Physical(1.0, bounds=(-1e9, 1e9), step=0.1, label="D_c [µm]", url="Dc", widget="input",
                      doc="rate-and-state memory length D_c [µm]: ξ = D_c c_s/(H₁ v)")
    v = Physical(0.08506, bounds=(-1e6, 1e6), step=0.001, label="v [m/s]", url="v", widget="input",
                 doc="steady sliding velocity v [m/s]: γ = ρ c_s v/(σ₀ a)")
    link = Switch(False, label="Sliders follow the lab values", url="lab",
                  doc="while on, every change of a lab value sets the sliders γ, f, β, η, Δ, ξ")

    #: which lab values a material preset fills in (model.Material attributes)
    MATERIAL_FIELDS = ("rho", "c_s", "c_d")
    #: the URL holds only the values that differ from the defaults
    URL_CHANGED_ONLY = True

    @staticmethod
    def material_values(name: str) -> dict[str, float]:
        """ρ, c_s, c_d of the material preset `name` (model/materials.json)."""
        m = model.material(name)
        return {"rho": m.rho, "c_s": m.c_s, "c_d": m.c_d}

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`); H₂ is disabled while H₂ = ∞ is ticked."""
        w = make_widgets(self)
        w["H2_mm"].disabled = self.H2_infinite
        self.param.watch(lambda e: setattr(w["H2_mm"], "disabled", e.new), "H2_infinite")
        return w


class RuptureParams(param.Parameterized):
    """The inputs of the steady mode-II cohesive-zone model of a rupture front (supplement S-V C; docs/physics.md
    §13) and of Eq. dsigma at its peak slip velocity. Defaults: the paper's (model.PAPER_DEFAULTS: Γ = 1.1 J/m²,
    X_c0 = 2.5 mm, ν = 0.33; kW = 3, 4, 5), at c = 0.9 c_R. Its material constants ρ, c_s and σ₀ are the shared ones
    of the Lab-units panel (:class:`LabParams`; the paper's PMMA c_s = 1345 m/s, σ₀ = 4.5 MPa, assumed
    ρ = 1180 kg/m³); ν follows the shared material's preset (the source's ν where it reports one) and can be edited.
    """

    c_over_cR = Physical(0.9, bounds=(0.01, 0.999), step=0.001, label="c/c_R", url="c_cR",
                         doc="rupture speed c over the Rayleigh speed c_R (plane stress); the model needs 0 < c < c_R")
    Gamma = Physical(model.PAPER_DEFAULTS.Gamma, bounds=(-1e6, 1e6), step=0.1, label="Γ [J/m²]", url="Gamma",
                     widget="input", doc="fracture energy Γ [J/m²], constant in c")
    X_c0_mm = Physical(model.PAPER_DEFAULTS.X_c0 * 1e3, bounds=(-1e6, 1e6), step=0.1, label="X_c0 [mm]", url="Xc0",
                       widget="input", doc="cohesive zone size X_c0 = X_c(c → 0) [mm]")
    nu = Physical(model.PAPER_DEFAULTS.nu, bounds=(-100.0, 100.0), step=0.01, label="ν", url="rup_nu",
                  widget="input", doc="Poisson ratio ν (3-D); the plates are in plane stress")
    kW1 = Physical(model.PAPER_DEFAULTS.kW[0], bounds=(-1e6, 1e6), step=0.5, label="kW₁", url="kW1", widget="input",
                   doc="first kW of the Δσ_yy/σ₀ curves (wavenumber times the thin block's width)")
    kW2 = Physical(model.PAPER_DEFAULTS.kW[1], bounds=(-1e6, 1e6), step=0.5, label="kW₂", url="kW2", widget="input",
                   doc="second kW of the Δσ_yy/σ₀ curves")
    kW3 = Physical(model.PAPER_DEFAULTS.kW[2], bounds=(-1e6, 1e6), step=0.5, label="kW₃", url="kW3", widget="input",
                   doc="third kW of the Δσ_yy/σ₀ curves")

    URL_CHANGED_ONLY = True

    @staticmethod
    def material_nu(name: str) -> float:
        """ν of the material preset `name` as the source reports it where it does, else from the bulk speeds
        (model.Material.nu)."""
        m = model.material(name)
        return float(m.reported.get("nu", m.nu))

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`)."""
        return make_widgets(self)


#: the material constants of :class:`LabParams` that every scene uses (one set per page)
SHARED_MATERIAL = ("material", "rho", "c_s", "sigma0_MPa")


def material_heading(used_by: str) -> pn.pane.Markdown:
    """The heading of a scene's shared material widgets, saying where else they act."""
    return pn.pane.Markdown(f"### Material and normal stress\n\nShared with {used_by}: a change here changes them "
                            "there too.", stylesheets=[HEADING_CSS], sizing_mode="stretch_width")


def material_readout(lab: LabParams) -> str:
    """The shared material constants a scene uses, in one line."""
    return (f"**Lab values used** (shared): {lab.material}, ρ = {fmt(lab.rho)} kg/m³, c_s = {fmt(lab.c_s)} m/s, "
            f"σ₀ = {fmt(lab.sigma0_MPa)} MPa")


def set_with_material(obj: LabParams, updates: dict[str, Any]) -> None:
    """Set `updates` on `obj`; a material named there brings its preset's values, except those `updates` sets
    itself (a URL or a preset naming only the material gets its values; values given with it win, and the material
    then reads custom if they differ from the preset's)."""
    updates = dict(updates)
    name = updates.pop("material", None)
    if name is None:
        obj.param.update(**updates)
        return
    if name != CUSTOM:
        updates = {**obj.material_values(name), **updates}
    obj.material = name
    obj.param.update(**updates)
    if name != CUSTOM and any(getattr(obj, k) != v for k, v in obj.material_values(name).items()):
        obj.material = CUSTOM


def follow_material(obj: LabParams) -> None:
    """Keep `obj`'s material choice and its values consistent: picking a preset fills in its values (those not set
    in the same update), and values that differ from the preset make the choice custom."""
    fields = set(obj.MATERIAL_FIELDS)

    def changed(*events: param.parameterized.Event) -> None:
        names = {e.name for e in events}
        if "material" in names and obj.material != CUSTOM:
            fill = {k: v for k, v in obj.material_values(obj.material).items() if k not in names}
            if any(getattr(obj, k) != v for k, v in fill.items()):
                obj.param.update(**fill)
        if obj.material != CUSTOM and any(getattr(obj, k) != v for k, v in obj.material_values(obj.material).items()):
            obj.material = CUSTOM

    obj.param.watch(changed, ["material", *sorted(fields)])
    changed()


#: tick labels of a log10 slider show the physical value
LOG10_TICKS = """
const v = Math.pow(10, tick);
if (v >= 0.01 && v < 1e4) return String(Number(v.toPrecision(3)));  // 0.0501, 3.98, 100, 5000
const e = Math.floor(Math.log10(v) + 1e-9), m = Number((v / Math.pow(10, e)).toPrecision(3));
const sup = String(e).replace(/./g, c => '⁻⁰¹²³⁴⁵⁶⁷⁸⁹'['-0123456789'.indexOf(c)]);
return (m === 1 ? '' : m + '×') + '10' + sup;  // 10⁸, 2.5×10⁵, 10⁻³: one style, not 1.00e+4 beside 100 and 1.00
"""


class LabelledCheckbox(pn.widgets.CheckBoxGroup):
    """A checkbox whose label toggles it as well (Bokeh's Checkbox draws its label as a separate element that
    ignores clicks): a CheckBoxGroup of one option, the label, whose ``checked`` is True while it is ticked."""

    checked = param.Boolean(default=False, doc="whether the box is ticked")

    _rename = {**pn.widgets.CheckBoxGroup._rename, "checked": None}  # not a property of the Bokeh model

    def __init__(self, *, label: str, checked: bool = False, **params: Any) -> None:
        super().__init__(label=label, options=[label], value=[label] if checked else [], checked=checked, **params)
        self.param.watch(lambda e: self.param.update(checked=bool(e.new)), "value")
        self.param.watch(lambda e: self.param.update(value=[self.label] if e.new else []), "checked")


def decimals(step: float) -> int:
    """How many decimals a slider with this step shows (0.001: 3, so that 0.996 does not read 1)."""
    return max(0, -math.floor(math.log10(step) + 1e-9)) if step > 0 else 2


def make_widget(p: param.Parameter, value: Any) -> pn.widgets.Widget:
    """The widget of one declared parameter: a slider over its soft range (widened to include `value`, which a
    URL or a preset may put outside) showing its step's decimals, a number field, or a checkbox."""
    if isinstance(p, param.Boolean):
        return LabelledCheckbox(label=p.label, checked=value)
    if isinstance(p, param.Selector):
        return pn.widgets.Select(label=p.label, options=list(p.objects), value=value, sizing_mode="stretch_width")
    if getattr(p, "widget", "slider") == "input":
        lo, hi = p.bounds if p.bounds is not None else (None, None)
        return pn.widgets.FloatInput(label=p.label, start=lo, end=hi, step=p.step, value=value,
                                     sizing_mode="stretch_width")
    lo, hi = p.softbounds if p.softbounds is not None else p.bounds
    options: dict[str, Any] = {"format": CustomJSTickFormatter(code=LOG10_TICKS) if getattr(p, "log10", False)
                               else "0." + "0" * decimals(p.step) if decimals(p.step) else "0"}
    return FollowedSlider(label=p.label, start=min(lo, value), end=max(hi, value), step=p.step, value=value,
                          sizing_mode="stretch_width", **options)


class FollowedSlider(pn.widgets.FloatSlider):
    """A FloatSlider whose handle's moves (``value``, ~20 a second while held) do not raise Panel's busy flag.

    Panel counts every widget event as busy work in one process-wide flag, and every session's busy indicator
    (the header spinner) follows it: each move of a held handle sent two updates to every open session, which
    took ~18 % of the server's time with ten sessions dragging (py-spy, benchmarks/drag.py). Panel exempts events
    in the same way (``_busy__ignore``, e.g. a layout's scroll position). The release (``value_throttled``) still
    counts as busy."""

    _busy__ignore: ClassVar[list[str]] = ["value"]


def make_widgets(obj: param.Parameterized, names: tuple[str, ...] | None = None) -> dict[str, pn.widgets.Widget]:
    """Widgets for every user-facing parameter of `obj` (:class:`Physical`, :class:`Choice` and Boolean ones with a
    non-negative precedence), or for those in `names`, in declaration order, built from the declarations and bound
    both ways (:func:`bind_two_way`)."""
    widgets = {}
    for name, p in obj.param.objects("existing").items():
        if name == "name" or (p.precedence is not None and p.precedence < 0) or (names and name not in names):
            continue
        if isinstance(p, Physical | Choice | param.Boolean):
            widgets[name] = make_widget(p, getattr(obj, name))
    bind_two_way(obj, widgets)
    return widgets


#: the parameter of a Parameterized that says a slider of it is held (see :func:`bind_two_way`)
DRAGGING = "dragging"


def _attribute(widget: pn.widgets.Widget) -> str:
    """The attribute of `widget` that holds its parameter's value."""
    return "checked" if isinstance(widget, LabelledCheckbox) else "value"


def _set_or_restore(obj: param.Parameterized, name: str, event: param.parameterized.Event) -> None:
    """Set `name` of `obj` from a widget's event; a value the parameter refuses puts the parameter's value back into
    the widget."""
    value = event.new
    # a slider's 0.9 arrives as 0.8999999999999999 (its steps are added in binary): the value shown, in the URL and
    # the CSVs. Not a log10 slider's value: the parameter is 10**value (rounded by from_log10), and rounding its
    # exponent would move it by ~1e-12 relative
    if isinstance(value, float) and math.isfinite(value) and not getattr(obj.param[name], "log10", False):
        value = float(f"{value:.12g}")
    try:
        set_frozen(obj, name, value)
    except ValueError:
        event.obj.param.update({_attribute(event.obj): getattr(obj, name)})


def _slider_moved(obj: param.Parameterized, name: str, events: tuple[param.parameterized.Event, ...]) -> None:
    """A slider's value while its handle moves (the plots follow it), and whether it is still held: ``value``
    differs from ``value_throttled`` (its value at the last release) until the release."""
    slider = events[0].obj
    held = slider.value != slider.value_throttled
    tracked = DRAGGING in obj.param
    moved = [e for e in events if e.name == "value" and getattr(obj, name) != e.new]
    if not moved and any(e.name == "value" for e in events):
        return  # the echo of the parameter into a second slider bound to it (another tab's): neither move nor release
    if moved:
        if tracked and held and not obj.dragging:
            obj.param.update(dragging=True)  # before the value: its watchers see a drag in progress
        _set_or_restore(obj, name, moved[-1])
    if tracked and obj.dragging != held:
        set_frozen(obj, DRAGGING, held)


def bind_two_way(obj: param.Parameterized, widgets: dict[str, pn.widgets.Widget]) -> None:
    """Widget -> parameter (every widget on `value`: a slider's plots follow its handle while it is dragged) and
    back. If `obj` has a Boolean ``dragging`` parameter, it is True while one of its sliders is held (its value moved
    since its last release, `value_throttled`): work too slow to follow the hand (background jobs, whole maps)
    waits for the release.

    A value the parameter refuses (an emptied number field, a number beyond the declared bounds) puts the
    parameter's value back into the widget: the session never sees an invalid parameter. The binding keeps its own
    copy of `widgets`: a caller may take widgets out of its dict to lay them out (the lab panel's link checkbox was
    popped, and every change of it raised KeyError 'link' here).
    """
    widgets = dict(widgets)

    def to_param(event: param.parameterized.Event, name: str) -> None:
        _set_or_restore(obj, name, event)

    for name, widget in widgets.items():
        if isinstance(widget, pn.widgets.FloatSlider):
            widget.param.watch(lambda *e, n=name: _slider_moved(obj, n, e), ["value", "value_throttled"])
        else:
            widget.param.watch(lambda e, n=name: to_param(e, n), _attribute(widget))

    def to_widget(*events: param.parameterized.Event) -> None:
        for event in events:
            widget = widgets[event.name]
            shown = getattr(widget, _attribute(widget))
            if shown == event.new or (event.new != event.new and shown != shown):
                continue  # already shown (NaN != NaN would otherwise loop)
            if isinstance(widget, pn.widgets.FloatSlider):  # a value set from the URL or a preset may lie
                widget.start = min(widget.start, event.new)  # outside the slider's soft range: widen it
                widget.end = max(widget.end, event.new)
                with param.edit_constant(widget):  # set, not dragged: value_throttled too (else it reads "held")
                    widget.param.update(value=event.new, value_throttled=event.new)
                continue
            setattr(widget, _attribute(widget), event.new)

    obj.param.watch(to_widget, list(widgets))


#: a displayed equation (KaTeX): it scrolls sideways within the page on a phone instead of overflowing it (458 px
#: wide at 390)
EQUATION_STYLES = {"font-size": "1.15em", "overflow-x": "auto", "overflow-y": "hidden", "max-width": "100%"}

#: the name of a placeholder (what replaces it checks that it is still there)
PLACEHOLDER = "placeholder"


def placeholder(text: str, min_height: int = 0) -> pn.Row:
    """What a part of the page shows until it is drawn: a spinner and `text` (a blank area read as broken)."""
    return pn.Row(pn.indicators.LoadingSpinner(value=True, size=22, margin=(8, 6)),
                  pn.pane.Markdown(f"*{text}*", margin=(4, 4)), name=PLACEHOLDER, min_height=min_height,
                  sizing_mode="stretch_width")


#: a section heading's size, whatever the page's theme: the Bootstrap design gives the components of a tab
#: rendered after the page has loaded its full bootstrap.css (h3 at 28 px), those of the first tab not (14 px)
HEADING_CSS = ":host h3 { font-size: 1.1rem; font-weight: 600; margin: 0.6em 0 0.3em; }"


def heading(text: str) -> pn.pane.Markdown:
    """A section heading of a scene's controls (the same size in every tab)."""
    return pn.pane.Markdown(f"### {text}", stylesheets=[HEADING_CSS])


def controls_column(widgets: dict[str, pn.widgets.Widget], readout, extra: tuple = ()) -> pn.Column:
    """The left column of a scene: parameter widgets, `extra` components (e.g. the shared material's widgets), then
    the readout."""
    return pn.Column(heading("Parameters"), *widgets.values(), *extra,
                     pn.pane.Markdown(readout, sizing_mode="stretch_width"), width=320)


def shared_material_widgets(lab: LabParams, used_by: str) -> tuple:
    """The heading and widgets of the page's shared material constants (:data:`SHARED_MATERIAL`) for a scene's
    controls."""
    return (material_heading(used_by), *make_widgets(lab, SHARED_MATERIAL).values())


#: below this page width (px) a scene's controls stack above its plots and both take the whole width (phones)
NARROW_PX = 800
#: the controls column of a scene: full width on a narrow page
NARROW_CONTROLS_CSS = (f"@media (max-width: {NARROW_PX}px) {{ :host {{ width: 100% !important; "
                       "min-width: 0 !important; flex: 1 1 100% !important; }} }}")


def scene_layout(controls: pn.layout.ListLike, plots: pn.layout.ListLike, name: str) -> pn.FlexBox:
    """A scene's tab: its controls column (fixed width) left of its plots (the rest of the width); on a page
    narrower than :data:`NARROW_PX` the plots wrap below the controls and both span the page."""
    controls.stylesheets = [*controls.stylesheets, NARROW_CONTROLS_CSS]
    controls.styles = {**controls.styles, "flex": "0 0 auto"}
    plots.styles = {**plots.styles, "flex": "1 1 440px", "min-width": "0"}
    return pn.FlexBox(controls, plots, flex_wrap="wrap", align_items="flex-start", sizing_mode="stretch_width",
                      name=name)


#: the browser side of :class:`FitPlots` (an ES module): every Bokeh figure of the page, checked when its size or
#: content changes and a few times a second for new ones. A title wider than the figure's canvas wraps onto more
#: lines (Bokeh draws a title on one line, cut at the canvas's edge); on a page narrower than `narrow_px` a legend
#: beside the frame or wider than it moves below the plot, in as many columns as fit, and the figure grows by its
#: height (it stays where HoloViews put it on a wider page, and goes back there when the page widens). The figures'
#: models are changed as a user's tool would change them (the server learns the new title, legend place and height);
#: HoloViews sets a title's text only when its own title changes, and this module wraps the new one.
FIT_PLOTS_JS = """
const SIDES = ["above", "below", "left", "right", "center"];
// figure id -> {title: {original, wrapped}, legends: Map(legend id -> where it was), base: its height without the
// legends moved below, set: the height this module gave it}
const state = new Map();
let measure = null;

function textWidth(text, font) {
  measure ??= document.createElement("canvas").getContext("2d");
  measure.font = font;
  return Math.max(...text.split("\\n").map(line => measure.measureText(line).width));
}

// `text` broken at spaces into lines at most `width` wide (a longer word stays whole on its own line)
function wrapText(text, font, width) {
  const lines = [];
  for (const paragraph of text.split("\\n")) {
    let line = "";
    for (const word of paragraph.split(" ")) {
      const next = line ? `${line} ${word}` : word;
      if (line && textWidth(next, font) > width) {
        lines.push(line);
        line = word;
      } else {
        line = next;
      }
    }
    lines.push(line);
  }
  return lines.join("\\n");
}

function fitTitle(view, s) {
  const title = view.model.title;
  const tv = title ? Bokeh.index.find_one(title) : null;
  if (!title || !title.text || !tv || !tv.visuals) return;
  if (s.title === undefined || title.text !== s.title.wrapped) s.title = {original: title.text, wrapped: null};
  const width = view.canvas_view.bbox.width - view.frame.bbox.left - 4;  // the title starts at the frame's left
  const font = tv.visuals.text.font_value();
  const original = s.title.original.replace(/\\n/g, " ");
  const wanted = textWidth(s.title.original, font) > width ? wrapText(original, font, width) : s.title.original;
  s.title.wrapped = wanted;
  if (s.relayout) {  // Bokeh keeps a title's old height until the plot is laid out again (its new text is set
    s.relayout = false;  // asynchronously: the next round)
    view.request_layout(true);
  }
  if (title.text !== wanted) {
    title.text = wanted;
    s.relayout = true;
  }
}

// the smallest font a legend's labels are given to fit a phone's width (px)
const MIN_LABEL_PX = 10;

// a CSS font size in px ("13px", "10pt", "1em" as 16px)
function fontPx(size) {
  const value = parseFloat(size);
  return size.endsWith("pt") ? value * 4 / 3 : size.endsWith("em") ? value * 16 : value;
}

// one change of both panels (two would leave the legend out of the figure in between: BokehJS drops its view)
function move(fig, legend, from, to) {
  fig.setv({[from]: fig[from].filter(m => m !== legend), [to]: [...fig[to], legend]});
}

function fitLegends(view, s, narrow) {
  const fig = view.model;
  let extra = 0;
  for (const legend of SIDES.flatMap(p => fig[p]).filter(m => m.type === "Legend")) {
    const lv = Bokeh.index.find_one(legend);
    if (!lv || !lv.el) continue;
    const panel = SIDES.find(p => fig[p].includes(legend));
    const saved = s.legends.get(legend.id);
    if (!narrow) {  // a wide page: the legend where it was
      if (saved !== undefined && panel === "below" && saved.panel !== "below") {
        move(fig, legend, "below", saved.panel);
        legend.setv({ncols: saved.ncols, location: saved.location});
        if (saved.font !== undefined) legend.label_text_font_size = saved.font;
      }
      s.legends.delete(legend.id);
      continue;
    }
    if (saved === undefined) {
      const frame = view.frame.bbox, box = lv.bbox;
      if (panel === "left" || panel === "right" ||
          (panel === "center" && (box.left < frame.left - 1 || box.right > frame.right + 1))) {
        s.legends.set(legend.id, {panel, ncols: legend.ncols, location: legend.location});
        move(fig, legend, panel, "below");  // its columns fitted once it is laid out there
        legend.location = "top_left";  // not a side legend's offset (it ran past the figure's bottom)
      }
      continue;
    }
    if (panel !== "below") {  // put back by the server (HoloViews places side legends at each update)
      s.legends.delete(legend.id);
      continue;
    }
    const entries = (lv.entries ?? []).filter(e => e.el.isConnected && e.item.visible !== false);
    if (entries.length > 0) {
      // below the frame, from its left edge to the canvas's right edge
      const room = view.canvas_view.bbox.width - view.frame.bbox.left - legend.margin - 2 * legend.padding - 2;
      const widest = Math.max(...entries.map(e => e.el.getBoundingClientRect().width));
      if (widest > room) {  // a label wider than the room: a smaller font, down to MIN_LABEL_PX
        const px = fontPx(legend.label_text_font_size);
        const smaller = `${Math.max(MIN_LABEL_PX, Math.floor(px * room / widest))}px`;
        if (px > MIN_LABEL_PX && smaller !== legend.label_text_font_size) {
          saved.font ??= legend.label_text_font_size;
          legend.label_text_font_size = smaller;
          continue;  // measured again once drawn in it
        }
      }
      const ncols = Math.max(1, Math.min(entries.length,
                                         Math.floor((room + legend.spacing) / (widest + legend.spacing))));
      if (legend.ncols !== ncols) legend.ncols = ncols;
    }
    extra += Math.max(lv.bbox.height, lv.el.getBoundingClientRect().height) + 2 * legend.margin;
  }
  if (s.base === undefined || fig.height !== s.set) s.base = fig.height;  // first seen, or set by the server
  const height = Math.round(s.base + extra);
  if (fig.height !== height) fig.height = height;
  s.set = height;
}

function fit(view, narrow) {
  if (!view.el.isConnected || !view.canvas_view || !view.frame) return;
  let s = state.get(view.model.id);
  if (s === undefined) {
    s = {legends: new Map()};
    state.set(view.model.id, s);
  }
  fitTitle(view, s);
  if (view.model.height != null) fitLegends(view, s, narrow);
}

function fitAll(narrowPx) {
  if (window.Bokeh === undefined || Bokeh.index === undefined) return;
  const narrow = window.matchMedia(`(max-width: ${narrowPx}px)`).matches;
  for (const view of Bokeh.index.all_views()) {
    if (view.model.type === "Figure" || view.model.type === "Plot") {
      try {
        fit(view, narrow);
      } catch (error) {
        console.debug("asymslide: a figure could not be fitted", error);
      }
    }
  }
}

export function render({ model }) {
  if (window.asymslideFitPlots === undefined) {  // once per page, whatever the number of renders
    window.asymslideFitPlots = () => fitAll(model.narrow_px);
    setInterval(window.asymslideFitPlots, 300);
    window.addEventListener("resize", window.asymslideFitPlots);
  }
  return document.createElement("span");
}
"""


class FitPlots(JSComponent):
    """Keeps every plot's title and legends inside the page on a phone (:data:`FIT_PLOTS_JS`). Bokeh knows the
    width a figure gets only in the browser, so the fitting happens there; one instance per page (it takes no
    space)."""

    narrow_px = param.Integer(default=NARROW_PX, doc="below this page width legends move below their plots")

    _esm = FIT_PLOTS_JS

    def __init__(self, **params: Any) -> None:
        super().__init__(**{"width": 0, "height": 0, "margin": 0, "sizing_mode": "fixed", **params})
