"""Shareable state: the parameters in the URL query (``?gamma=3&eta=inf&tab=map``).

Reading is strict and never evaluates anything: each number is parsed with :func:`float`, a choice or a switch is
matched against a fixed list of words; a value that is not a finite number is ignored, a number outside the
parameter's range is clamped to it, unknown keys are ignored, and every such decision becomes a message shown to
the user. Writing replaces ``location.search`` with the current values. The keys, their ranges and their kinds
come from the declarations in app/params.py (:class:`~app.params.Physical`, :class:`~app.params.Choice`,
:class:`~app.params.Switch`).
"""

from __future__ import annotations

import html
import math
import urllib.parse
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import param

from .params import (
    Choice,
    LabParams,
    Physical,
    RuptureParams,
    SpectrumParams,
    Switch,
    ThinOnThickParams,
    declared_parameters,
)

#: longest raw value quoted back in a message (values are HTML-escaped as well)
MAX_QUOTE = 24

#: query value of each tab, in tab order
TABS = ("spectrum", "map", "thin", "rupture", "branches", "atlas")

#: the parameter classes whose declarations have URL keys, by target name (the keys of :data:`Updates`)
TARGETS: dict[str, type[param.Parameterized]] = {
    "spectrum": SpectrumParams, "thin": ThinOnThickParams, "lab": LabParams, "rupture": RuptureParams}

#: words for ∞ (a Physical with ``infinite``) and for a switch
INFINITY_WORDS = {"inf", "infinity", "∞"}
SWITCH_WORDS = {"1": True, "on": True, "true": True, "yes": True, "0": False, "off": False, "false": False,
                "no": False}


@dataclass(frozen=True)
class QueryParam:
    """One URL query key, derived from a declaration with a ``url`` key."""

    key: str  # name in the URL
    target: str  # a key of TARGETS
    attribute: str  # the parameter it sets
    symbol: str  # the paper's symbol (the label), for messages
    lo: float = -math.inf  # valid range of the URL value (numbers)
    hi: float = math.inf
    log10: bool = False  # the parameter stores log10 of the URL value
    kind: str = "number"  # "number", "choice" or "switch"
    infinite: str | None = None  # the Boolean parameter meaning ∞ ("inf" in the URL)
    choices: tuple[str, ...] = ()


def _query_param(target: str, name: str, p: Physical | Choice | Switch) -> QueryParam:
    if isinstance(p, Choice):
        return QueryParam(p.url, target, name, p.label, kind="choice", choices=tuple(p.objects))
    if isinstance(p, Switch):
        return QueryParam(p.url, target, name, p.label, kind="switch")
    lo, hi = p.physical_bounds()
    return QueryParam(p.url, target, name, p.label, lo, hi, p.log10, infinite=p.infinite)


def _query_params() -> tuple[QueryParam, ...]:
    return tuple(_query_param(target, name, p) for target, cls in TARGETS.items()
                 for name, p in declared_parameters(cls).items() if p.url)


#: the query keys, in the order they are written (the declaration order)
QUERY = _query_params()
BY_KEY = {q.key: q for q in QUERY}
assert len(BY_KEY) == len(QUERY), "two declarations share a URL key"


def _quote(raw: str) -> str:
    text = raw if len(raw) <= MAX_QUOTE else raw[:MAX_QUOTE] + "…"
    return html.escape(text, quote=True)


def _decode(value: bytes | str) -> str:
    return value.decode("utf-8", errors="replace") if isinstance(value, bytes) else str(value)


def parse_number(raw: str) -> float | None:
    """A finite float from a query value, or None. Only :func:`float` is applied (no eval)."""
    text = raw.strip()
    if not text or len(text) > 64:
        return None
    try:
        x = float(text)
    except ValueError:
        return None
    return x if math.isfinite(x) else None


Updates = dict[str, dict[str, object]]


def _parse_value(q: QueryParam, raw: str, updates: Updates, messages: list[str]) -> None:
    """Put the validated value of one key into `updates`, or a message into `messages`."""
    target = updates[q.target]
    if q.kind == "choice":
        match = [c for c in q.choices if c.casefold() == raw.strip().casefold()]
        if match:
            target[q.attribute] = match[0]
        else:
            messages.append(f"{q.symbol} = '{_quote(raw)}' is not one of {', '.join(q.choices)}: ignored.")
        return
    if q.kind == "switch":
        word = raw.strip().lower()
        if word in SWITCH_WORDS:
            target[q.attribute] = SWITCH_WORDS[word]
        else:
            messages.append(f"{q.symbol} = '{_quote(raw)}' is not 1 or 0: ignored.")
        return
    if q.infinite and raw.strip().lower() in INFINITY_WORDS:
        target[q.infinite] = True
        return
    x = parse_number(raw)
    if x is None:
        messages.append(f"{q.symbol} = '{_quote(raw)}' is not a finite number: ignored.")
        return
    if q.log10 and x <= 0:
        messages.append(f"{q.symbol} = {x:g} must be positive (range {q.lo:g} … {q.hi:g}): ignored.")
        return
    clamped = min(max(x, q.lo), q.hi)
    if clamped != x:
        messages.append(f"{q.symbol} = {x:g} is outside {q.lo:g} … {q.hi:g}: set to {clamped:g}.")
    target[q.attribute] = math.log10(clamped) if q.log10 else clamped
    if q.infinite:
        target[q.infinite] = False


def parse_query(args: Mapping[str, Iterable[bytes | str]]) -> tuple[Updates, str | None, list[str]]:
    """Validated updates from request arguments (``pn.state.session_args`` form: key -> list of values).

    Returns ``(updates, tab, messages)`` where ``updates[target][attribute] = value`` are ready to be set
    on the parameter objects (targets: the keys of :data:`TARGETS`), ``tab`` is one of :data:`TABS` or None, and
    ``messages`` explains every value that was clamped or ignored.
    """
    updates: Updates = {target: {} for target in TARGETS}
    updates["atlas"] = {}
    tab: str | None = None
    messages: list[str] = []
    for key, values in args.items():
        values = list(values)
        if not values:
            continue
        raw = _decode(values[-1])
        if key == "tab":
            if raw in TABS:
                tab = raw
            else:
                messages.append(f"tab = '{_quote(raw)}' is not one of {', '.join(TABS)}: ignored.")
            continue
        if key == "atlas":  # a name from the listing of the one atlas directory, never a path
            from .atlas import list_atlases

            names = list_atlases()
            if raw in names:
                updates["atlas"]["name"] = raw
            else:
                messages.append(f"atlas = '{_quote(raw)}' is not one of the atlases ({', '.join(names) or 'none'}): "
                                "ignored.")
            continue
        q = BY_KEY.get(key)
        if q is None:
            messages.append(f"unknown parameter '{_quote(key)}': ignored.")
            continue
        _parse_value(q, raw, updates, messages)
    return updates, tab, messages


def _url_value(q: QueryParam, obj: param.Parameterized) -> str:
    v = getattr(obj, q.attribute)
    if q.kind == "choice":
        return str(v)
    if q.kind == "switch":
        return "1" if v else "0"
    if q.infinite and getattr(obj, q.infinite):
        return "inf"
    return f"{10.0 ** v:.6g}" if q.log10 else f"{v:.6g}"


def _is_default(q: QueryParam, obj: param.Parameterized) -> bool:
    names = (q.attribute, q.infinite) if q.infinite else (q.attribute,)
    return all(getattr(obj, n) == obj.param[n].default for n in names)


def query_string(objects: Mapping[str, param.Parameterized], tab: str, atlas: str | None = None) -> str:
    """The URL search string (``?...``) for the current parameter values; `objects` maps targets (keys of
    :data:`TARGETS`) to the parameter objects (a target left out is not written). A class with
    ``URL_CHANGED_ONLY`` writes only the values that differ from its defaults. `atlas`: the Atlas tab's atlas."""
    values: dict[str, str] = {}
    for q in QUERY:
        obj = objects.get(q.target)
        if obj is None:
            continue
        if q.key == "xi" and obj.Delta == 1:
            continue  # xi does not enter the physics at Delta = 1
        if getattr(obj, "URL_CHANGED_ONLY", False) and _is_default(q, obj):
            continue
        values[q.key] = _url_value(q, obj)
    values["tab"] = tab
    if atlas:
        values["atlas"] = atlas
    return "?" + urllib.parse.urlencode(values)
