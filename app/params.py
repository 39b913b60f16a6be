"""User-facing parameters of the spectrum scene and their widgets (paper symbols as labels).

Data flow: widget (throttled) -> :class:`SpectrumParams` parameter -> cached model call -> plot.
"""

from __future__ import annotations

import contextlib
import io
import math
from collections.abc import Callable, Iterator, Mapping

import holoviews as hv
import numpy as np
import panel as pn
import param
from bokeh.models import CustomJSTickFormatter, Span

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

#: the widget labels, in display order (the paper's symbols)
LABELS = {
    "gamma": "γ",
    "f": "f",
    "beta": "β",
    "log10_eta": "η",
    "eta_infinite": "η = ∞",
    "Delta": "Δ",
    "xi": "ξ",
}


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


class SpectrumParams(param.Parameterized):
    """Physical parameters of the Rayleigh-branch spectrum (paper Sect. IV)."""

    gamma = param.Number(3.0, bounds=(1e-2, 1e3), softbounds=(0.1, 30), label=LABELS["gamma"],
                         doc="gamma: ratio of the elastic to the frictional (rate-and-state) stiffness")
    f = param.Number(0.9, bounds=(0, 2), label=LABELS["f"], doc="friction coefficient f")
    beta = param.Number(0.3, bounds=(0.01, 0.7071), label=LABELS["beta"], doc="beta = c_s / c_d")
    log10_eta = param.Number(8.0, bounds=(-2, 12), label=LABELS["log10_eta"],
                             doc="log10 of the viscosity parameter eta (used when eta_infinite is False)")
    eta_infinite = param.Boolean(True, label=LABELS["eta_infinite"], doc="eta = inf (no viscous dissipation)")
    Delta = param.Number(1.0, bounds=(0.01, 1), label=LABELS["Delta"],
                         doc="Delta (1 = no rate dependence of the normal stress)")
    xi = param.Number(0.0, bounds=(0, 1e4), softbounds=(0, 10), label=LABELS["xi"],
                      doc="xi: normal-stress relaxation length (irrelevant when Delta = 1)")

    @property
    def eta(self) -> float:
        return math.inf if self.eta_infinite else 10.0**self.log10_eta

    def model_args(self) -> tuple[float, float, float, float, float, float]:
        """(gamma, f, beta, eta, Delta, xi) as passed to the model; xi is normalised to 0 when Delta == 1
        (it does not enter F then), so that changing it is not a new cache key."""
        xi = 0.0 if self.Delta == 1 else float(self.xi)
        return (float(self.gamma), float(self.f), float(self.beta), float(self.eta), float(self.Delta), xi)

    # ----------------------------------------------------------------------------------------
    # widgets
    # ----------------------------------------------------------------------------------------

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object: sliders update it on release (value_throttled)."""
        w: dict[str, pn.widgets.Widget] = {}
        for name, step in (("gamma", 0.01), ("f", 0.01), ("beta", 0.001), ("Delta", 0.01), ("xi", 0.01)):
            p = self.param[name]
            lo, hi = p.softbounds if p.softbounds is not None else p.bounds
            lo, hi = min(lo, getattr(self, name)), max(hi, getattr(self, name))  # e.g. gamma = 1e3 from a URL
            w[name] = pn.widgets.FloatSlider(label=LABELS[name], start=lo, end=hi, step=step,
                                             value=getattr(self, name), sizing_mode="stretch_width")
        w["log10_eta"] = pn.widgets.FloatSlider(
            label=LABELS["log10_eta"], start=self.param.log10_eta.bounds[0], end=self.param.log10_eta.bounds[1],
            step=0.1, value=self.log10_eta, disabled=self.eta_infinite, sizing_mode="stretch_width",
            format=CustomJSTickFormatter(code="return '10^' + tick.toFixed(1)"),
        )
        w["eta_infinite"] = pn.widgets.Checkbox(label=LABELS["eta_infinite"], value=self.eta_infinite)
        w = {name: w[name] for name in LABELS}  # display order
        w["xi"].disabled = self.Delta == 1

        bind_two_way(self, w)
        self.param.watch(lambda e: setattr(w["xi"], "disabled", e.new == 1), "Delta")
        self.param.watch(lambda e: setattr(w["log10_eta"], "disabled", e.new), "eta_infinite")
        return w
