"""Widgets made from the parameter declarations, and their two-way binding (a held slider follows the hand; the
parameter changes at its release)."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import panel as pn
import param
from bokeh.models import CustomJSTickFormatter

from .declarations import Choice, Physical, set_frozen

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
