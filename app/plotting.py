"""HoloViews and Panel set up for the app (at import: the Bokeh backend, Panel's extensions and session settings,
one tick style and framewise ranges on every plot) and the plot hooks and number formats every scene uses."""

from __future__ import annotations

from typing import Any

import holoviews as hv
import numpy as np
import panel as pn
from bokeh.models import BasicTickFormatter, ColorBar, CustomJSTickFormatter, GlyphRenderer, LogColorMapper, Span

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
#: the Panel extensions the scenes use: Plotly (the Atlas tab's 3-D view) and KaTeX (the equations of the Spectrum and
#: All-branches tabs); a notebook loads them with ``pn.extension(*EXTENSIONS)`` (app/notebook.py)
EXTENSIONS = ("plotly", "katex")
pn.extension(*EXTENSIONS, **SESSION_CONFIG)


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
