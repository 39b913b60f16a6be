"""The page furniture every scene shares: headings, placeholders, the controls column, the scene layout (controls
beside or above the plots), the shared material widgets and :class:`FitPlots` (plots sized to the page)."""

from __future__ import annotations

from typing import Any

import panel as pn
import param
from panel.custom import JSComponent

from .params import SHARED_MATERIAL, LabParams
from .plotting import fmt
from .widgets import make_widgets


def material_heading(used_by: str) -> pn.pane.Markdown:
    """The heading of a scene's shared material widgets, saying where else they act."""
    return pn.pane.Markdown(f"### Material and normal stress\n\nShared with {used_by}: a change here changes them "
                            "there too.", stylesheets=[HEADING_CSS], sizing_mode="stretch_width")


def material_readout(lab: LabParams) -> str:
    """The shared material constants a scene uses, in one line."""
    return (f"**Lab values used** (shared): {lab.material}, ρ = {fmt(lab.rho)} kg/m³, c_s = {fmt(lab.c_s)} m/s, "
            f"σ₀ = {fmt(lab.sigma0_MPa)} MPa")


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
