"""The user-facing parameters, declared once, and what is derived from the declarations: widgets, URL keys,
stability-map axes (see :class:`Physical`); plus the helpers every scene uses (readout numbers, CSV export,
the frozen-document context for parameter changes, the zero line of the plots).

Data flow: widget (sliders on release) -> parameter -> cached model call -> HoloViews element.
"""

from __future__ import annotations

import contextlib
import io
import math
from collections.abc import Callable, Iterator, Mapping
from typing import Any

import holoviews as hv
import numpy as np
import panel as pn
import param
from bokeh.models import CustomJSTickFormatter, Span
from param.parameterized import Undefined

hv.extension("bokeh", logo=False)
# Canvas, not WebGL: the plots hold at most a few thousand points, and copying the WebGL layer onto
# the canvas (blit_webgl -> drawImage) took ~58 ms of every ~100 ms browser update in Chromium's
# profile (benchmarks/latency.py; software GL without a GPU). Image-based plots are unaffected.
hv.renderer("bokeh").webgl = False
# Axes follow the data when the parameters change. HoloViews takes `framewise` from each element's
# options: set on the Overlays only (as before), every plot kept the ranges of its first frame and a
# curve that grew beyond them was cut off (tests/test_app_ranges.py).
hv.opts.defaults(*(getattr(hv.opts, kind)(framewise=True) for kind in (
    "Curve", "Scatter", "Points", "Path", "QuadMesh", "HLine", "VLine", "VLines", "VSpans", "Bounds")))

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
    (one subplot less to refresh, ~4 ms per plot and update) and never needs re-sending.
    """
    fig = plot.state
    if not any(getattr(r, "name", None) == ZERO_LINE for r in fig.center):
        fig.add_layout(Span(location=0, dimension="width", line_color="black", line_width=1, name=ZERO_LINE))


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


def _skip_recompute() -> None:
    """Stands in for ``doc.models.recompute`` when the model graph is known not to have changed."""


@contextlib.contextmanager
def frozen_document() -> Iterator[None]:
    """Defer the Bokeh model-graph recompute to the end of a parameter change, and skip it when the
    graph did not change.

    HoloViews freezes the document around each plot it refreshes, and Bokeh walks every model of the
    page when the outermost freeze ends (~12 ms here) whether or not a model reference changed. Inside
    this context: nested freezes do not walk; at the end the walk happens once, and only if Bokeh
    reported a changed reference (``models.invalidate``) or a root was added or removed. A slider
    release that only sends new data (the usual case) walks nothing. Events are still sent as they
    happen (unlike ``pn.io.hold``), so the first plot is not delayed by the others. A no-op outside a
    Bokeh document (tests, scripts).
    """
    doc = pn.state.curdoc
    models = getattr(doc, "models", None)
    if models is None or "invalidate" in vars(models):  # no document, or inside another frozen_document
        yield
        return
    roots = list(doc.roots)
    changed = False

    def invalidate() -> None:  # Bokeh calls this when a property change adds or drops model references
        nonlocal changed
        changed = True

    models.invalidate = invalidate
    error: BaseException | None = None
    try:
        with models.freeze():
            try:
                yield
            except BaseException as exc:  # Bokeh's freeze() would stay frozen (no try/finally there)
                error = exc
            finally:
                del models.invalidate
                if not changed and list(doc.roots) == roots:
                    models.recompute = _skip_recompute  # the walk freeze() ends with
    finally:
        vars(models).pop("recompute", None)
    if error is not None:
        raise error


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
    - ``widget``: "slider" or "input" (a number field, for values typed rather than dragged).
    """

    __slots__ = ["url", "log10", "axis", "widget"]
    _slot_defaults = dict(param.Number._slot_defaults, url=None, log10=False, axis=None, widget="slider")

    def __init__(self, default: Any = Undefined, *, url: Any = Undefined, log10: Any = Undefined,
                 axis: Any = Undefined, widget: Any = Undefined, **params: Any) -> None:
        super().__init__(default=default, **params)
        self.url = url
        self.log10 = log10
        self.axis = axis
        self.widget = widget

    def physical_bounds(self) -> tuple[float, float]:
        """The valid range of the physical value (10**bounds for a log10 parameter)."""
        lo, hi = self.bounds
        return (10.0**lo, 10.0**hi) if self.log10 else (lo, hi)


def physical_parameters(cls: type[param.Parameterized]) -> dict[str, Physical]:
    """Name -> declaration of every :class:`Physical` parameter of `cls`, in declaration order."""
    return {name: p for name, p in cls.param.objects("existing").items() if isinstance(p, Physical)}


class SpectrumParams(param.Parameterized):
    """The physical parameters of the spectrum (paper Sect. IV; docs/physics.md §1), shared by the Spectrum,
    Stability-map and All-branches scenes. Defaults: the paper's Fig. 4 (γ = 3, f = 0.9, β = 0.3, η = ∞, Δ = 1)."""

    gamma = Physical(3.0, bounds=(1e-2, 1e3), softbounds=(0.1, 30.0), step=0.01, label="γ", url="gamma",
                     axis=(0.1, 30.0, True),
                     doc="γ = μ/(σ₀ c_s ∂_v f): elastodynamic stiffness over the direct velocity effect of friction")
    f = Physical(0.9, bounds=(0.0, 2.0), step=0.01, label="f", url="f", axis=(0.0, 2.0, False),
                 doc="f: the steady-state friction coefficient")
    beta = Physical(0.3, bounds=(0.01, 0.7071), step=0.001, label="β", url="beta", axis=(0.01, 0.7071, False),
                    doc="β = c_s/c_d: shear over dilatational wave speed (β² = (1 − 2ν)/(2 − 2ν))")
    log10_eta = Physical(8.0, bounds=(-2.0, 12.0), step=0.1, label="η", url="eta", log10=True,
                         axis=(1.0, 1e8, True),
                         doc="η = H₂/H₁: the lower block's height over the upper block's (slider: log10 η)")
    eta_infinite = param.Boolean(True, label="η = ∞", doc="the lower block is a half-space (η = ∞)")
    Delta = Physical(1.0, bounds=(0.01, 1.0), step=0.01, label="Δ", url="Delta", axis=(0.01, 1.0, False),
                     doc="Δ = d_v f/∂_v f: steady-state over direct velocity dependence of friction (1: no state)")
    xi = Physical(0.0, bounds=(0.0, 1e4), softbounds=(0.0, 10.0), step=0.01, label="ξ", url="xi",
                  axis=(1e-2, 1e3, True),
                  doc="ξ = D c_s/(H v |g′(1)|): the memory length of the interface state (irrelevant at Δ = 1)")

    #: the model's keyword arguments, in the order of :meth:`model_args`
    MODEL_ARGS = ("gamma", "f", "beta", "eta", "Delta", "xi")

    @property
    def eta(self) -> float:
        return math.inf if self.eta_infinite else 10.0**self.log10_eta

    def model_args(self) -> tuple[float, float, float, float, float, float]:
        """(gamma, f, beta, eta, Delta, xi) as passed to the model; xi is normalised to 0 when Delta == 1
        (it does not enter F then), so that changing it is not a new cache key."""
        xi = 0.0 if self.Delta == 1 else float(self.xi)
        return (float(self.gamma), float(self.f), float(self.beta), float(self.eta), float(self.Delta), xi)

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
        w["log10_eta"].disabled = self.eta_infinite
        self.param.watch(lambda e: setattr(w["xi"], "disabled", e.new == 1), "Delta")
        self.param.watch(lambda e: setattr(w["log10_eta"], "disabled", e.new), "eta_infinite")
        return w


class ThinOnThickParams(param.Parameterized):
    """The parameters of the thin-on-thick scene (paper Sect. III; docs/physics.md §6). Defaults: the PMMA
    experiment of Sect. S-V (kW = 5, ν = 0.33, c_s = 1345 m/s, σ₀ = 4.5 MPa; ρ = 1180 kg/m³ is assumed: the
    paper does not state it)."""

    log10_kW = Physical(math.log10(5.0), bounds=(-2.0, 2.0), step=0.01, label="kW", url="kW", log10=True,
                        doc="kW: wavenumber k times the thin block's width W (slider: log10 kW)")
    nu = Physical(0.33, bounds=(0.0, 0.49), step=0.005, label="ν", url="nu", doc="Poisson ratio ν")
    c_s = Physical(1345.0, bounds=(1.0, 1e4), step=1.0, label="c_s [m/s]", url="c_s", widget="input",
                   doc="shear wave speed c_s [m/s] (PMMA: 1345)")
    rho = Physical(1180.0, bounds=(1.0, 3e4), step=10.0, label="ρ [kg/m³]", url="rho", widget="input",
                   doc="density ρ [kg/m³]; μ = ρ c_s²")
    sigma0_MPa = Physical(4.5, bounds=(1e-3, 1e4), step=0.1, label="σ₀ [MPa]", url="sigma0", widget="input",
                          doc="normal stress σ₀ [MPa]")

    @property
    def kW(self) -> float:
        return from_log10(self.log10_kW)

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`)."""
        return make_widgets(self)


#: tick labels of a log10 slider show the physical value
LOG10_TICKS = "return Math.pow(10, tick).toPrecision(3)"


def make_widget(p: param.Parameter, value: Any) -> pn.widgets.Widget:
    """The widget of one declared parameter: a slider over its soft range (widened to include `value`, which a
    URL or a preset may put outside), a number field, or a checkbox."""
    if isinstance(p, param.Boolean):
        return pn.widgets.Checkbox(label=p.label, value=value)
    if getattr(p, "widget", "slider") == "input":
        lo, hi = p.bounds if p.bounds is not None else (None, None)
        return pn.widgets.FloatInput(label=p.label, start=lo, end=hi, step=p.step, value=value,
                                     sizing_mode="stretch_width")
    lo, hi = p.softbounds if p.softbounds is not None else p.bounds
    options: dict[str, Any] = {"format": CustomJSTickFormatter(code=LOG10_TICKS)} if getattr(p, "log10", False) else {}
    return pn.widgets.FloatSlider(label=p.label, start=min(lo, value), end=max(hi, value), step=p.step, value=value,
                                  sizing_mode="stretch_width", **options)


def make_widgets(obj: param.Parameterized) -> dict[str, pn.widgets.Widget]:
    """Widgets for every user-facing parameter of `obj` (:class:`Physical` ones and Booleans with a
    non-negative precedence), in declaration order, built from the declarations and bound both ways
    (:func:`bind_two_way`)."""
    widgets = {}
    for name, p in obj.param.objects("existing").items():
        if name == "name" or (p.precedence is not None and p.precedence < 0):
            continue
        if isinstance(p, Physical | param.Boolean):
            widgets[name] = make_widget(p, getattr(obj, name))
    bind_two_way(obj, widgets)
    return widgets


def bind_two_way(obj: param.Parameterized, widgets: dict[str, pn.widgets.Widget]) -> None:
    """Widget -> parameter (sliders on release, `value_throttled`; other widgets on `value`) and back."""
    for name, widget in widgets.items():
        event = "value_throttled" if isinstance(widget, pn.widgets.FloatSlider) else "value"
        widget.param.watch(lambda e, n=name: set_frozen(obj, n, e.new), event)

    def to_widget(*events: param.parameterized.Event) -> None:
        for event in events:
            widget = widgets[event.name]
            if widget.value == event.new or (event.new != event.new and widget.value != widget.value):
                continue  # already shown (NaN != NaN would otherwise loop)
            if isinstance(widget, pn.widgets.FloatSlider):  # a value set from the URL or a preset may lie
                widget.start = min(widget.start, event.new)  # outside the slider's soft range: widen it
                widget.end = max(widget.end, event.new)
            widget.value = event.new

    obj.param.watch(to_widget, list(widgets))


def controls_column(widgets: dict[str, pn.widgets.Widget], readout) -> pn.Column:
    """The left column of a scene: parameter widgets, then the readout."""
    return pn.Column("### Parameters", *widgets.values(), pn.pane.Markdown(readout, sizing_mode="stretch_width"),
                     width=320)
