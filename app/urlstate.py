"""Shareable state: the parameters in the URL query (``?gamma=3&eta=inf&tab=map``).

Reading is strict and never evaluates anything: each value is parsed with :func:`float` (or matched
against a fixed list of words); a value that is not a finite number is ignored, a number outside the
parameter's range is clamped to it, unknown keys are ignored, and every such decision becomes a
message shown to the user. Writing replaces ``location.search`` with the current values.
"""

from __future__ import annotations

import html
import math
import urllib.parse
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from .params import SpectrumParams, ThinOnThickParams, physical_parameters

#: longest raw value quoted back in a message (values are HTML-escaped as well)
MAX_QUOTE = 24

#: query value of each tab, in tab order
TABS = ("spectrum", "map", "thin", "branches")


@dataclass(frozen=True)
class QueryParam:
    """One URL query key, derived from a :class:`~app.params.Physical` declaration with a ``url`` key."""

    key: str  # name in the URL
    target: str  # "spectrum" (SpectrumParams) or "thin" (ThinOnThickParams)
    attribute: str  # the parameter it sets
    symbol: str  # the paper's symbol, for messages
    lo: float  # valid range of the URL value
    hi: float
    log10: bool = False  # the parameter stores log10 of the URL value


def _query_params() -> tuple[QueryParam, ...]:
    out = []
    for target, cls in (("spectrum", SpectrumParams), ("thin", ThinOnThickParams)):
        for name, p in physical_parameters(cls).items():
            if p.url:
                lo, hi = p.physical_bounds()
                out.append(QueryParam(p.url, target, name, p.label, lo, hi, p.log10))
    return tuple(out)


#: the query keys, in the order they are written (the declaration order)
QUERY = _query_params()
BY_KEY = {q.key: q for q in QUERY}


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


def parse_query(args: Mapping[str, Iterable[bytes | str]]) -> tuple[Updates, str | None, list[str]]:
    """Validated updates from request arguments (``pn.state.session_args`` form: key -> list of values).

    Returns ``(updates, tab, messages)`` where ``updates[target][attribute] = value`` are ready to be set
    on the parameter objects, ``tab`` is one of :data:`TABS` or None, and ``messages`` explains every
    value that was clamped or ignored.
    """
    updates: dict[str, dict[str, object]] = {"spectrum": {}, "thin": {}}
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
        q = BY_KEY.get(key)
        if q is None:
            messages.append(f"unknown parameter '{_quote(key)}': ignored.")
            continue
        attr = q.attribute
        if key == "eta" and raw.strip().lower() in {"inf", "infinity", "∞"}:
            updates["spectrum"]["eta_infinite"] = True
            continue
        x = parse_number(raw)
        if x is None:
            messages.append(f"{q.symbol} = '{_quote(raw)}' is not a finite number: ignored.")
            continue
        if q.log10 and x <= 0:
            messages.append(f"{q.symbol} = {x:g} must be positive (range {q.lo:g} … {q.hi:g}): ignored.")
            continue
        clamped = min(max(x, q.lo), q.hi)
        if clamped != x:
            messages.append(f"{q.symbol} = {x:g} is outside {q.lo:g} … {q.hi:g}: set to {clamped:g}.")
        value = math.log10(clamped) if q.log10 else clamped
        updates[q.target][attr] = value
        if key == "eta":
            updates["spectrum"]["eta_infinite"] = False
    return updates, tab, messages


def query_string(spectrum, thin, tab: str) -> str:
    """The URL search string (``?...``) for the current parameter values."""
    values: dict[str, str] = {}
    for q in QUERY:
        obj = spectrum if q.target == "spectrum" else thin
        if q.key == "eta" and spectrum.eta_infinite:
            values["eta"] = "inf"
            continue
        if q.key == "xi" and spectrum.Delta == 1:
            continue  # xi does not enter the physics at Delta = 1
        v = getattr(obj, q.attribute)
        values[q.key] = f"{10.0 ** v:.6g}" if q.log10 else f"{v:.6g}"
    values["tab"] = tab
    return "?" + urllib.parse.urlencode(values)
