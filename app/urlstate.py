"""Shareable state: the parameters in the URL query (``?gamma=3&eta=inf&tab=map``).

Reading is strict and never evaluates anything: each number is parsed with :func:`float`, a choice or a switch is
matched against a fixed list of words; a value that is not a finite number is ignored, a number outside the
parameter's range is clamped to it, unknown keys are ignored, and every such decision becomes a message shown to
the user. Writing replaces ``location.search`` with the current values. The keys, their ranges and their kinds
come from the declarations in app/params.py (:class:`~app.declarations.Physical`, :class:`~app.declarations.Choice`,
:class:`~app.declarations.Switch`).
"""

from __future__ import annotations

import html
import math
import urllib.parse
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import partial

import param

from .declarations import Choice, Physical, Switch, declared_parameters
from .params import LabParams, RuptureParams, SpectrumParams, ThinOnThickParams
from .tabs import TABS_REGISTRY

#: longest raw value quoted back in a message (values are HTML-escaped as well)
MAX_QUOTE = 24

#: query value of each tab, in tab order (the keys of app.tabs.TABS_REGISTRY)
TABS = tuple(tab.key for tab in TABS_REGISTRY)

#: the shared parameter classes whose declarations have URL keys, by target name
SHARED_TARGETS: dict[str, type[param.Parameterized]] = {
    "spectrum": SpectrumParams, "thin": ThinOnThickParams, "lab": LabParams, "rupture": RuptureParams}
#: the parameter classes whose declarations have URL keys, by target name (the keys of :data:`Updates`): the shared
#: parameters, then the scenes' own settings under their tab's key (app.tabs.Tab.url_settings: the map's plane and
#: resolution, the All-branches kH and window)
TARGETS: dict[str, type[param.Parameterized]] = {
    **SHARED_TARGETS, **{tab.key: tab.url_settings for tab in TABS_REGISTRY if tab.url_settings is not None}}
assert len(TARGETS) == len(SHARED_TARGETS) + sum(tab.url_settings is not None for tab in TABS_REGISTRY), \
    "a tab's URL settings share a target name with the shared parameters"

#: keys of earlier versions, read as the keys that replaced them (old links keep working): the thin-on-thick and
#: rupture-front material constants are now the one shared set of the Lab-units panel
ALIASES = {"c_s": "lab_cs", "rho": "lab_rho", "sigma0": "lab_sigma0", "rup_cs": "lab_cs", "rup_rho": "lab_rho",
           "rup_sigma0": "lab_sigma0", "rup_material": "material"}

#: the Atlas tab's keys: the atlas (a name listed in the atlas directory), the heat map's axes, the 3-D view's axes
#: (comma-separated) and, per other axis, its value ("at_" + the axis: snapped to the atlas's grid)
ATLAS_KEYS = {"atlas": "name", "ax": "x", "ay": "y", "surface": "surface", "atlas_verdict": "verdict"}
#: the Atlas heat map's colourings (an atlas swept with --sliding) by their URL words (app.sliding_map)
ATLAS_VERDICTS = {"sliding": "sliding (every branch)", "rayleigh": "Rayleigh branch"}
ATLAS_AT = "at_"
ATLAS_AXES = SpectrumParams.MODEL_ARGS

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
    words: tuple[str, ...] = ()  # a choice's URL words, in the order of choices


def _query_param(target: str, name: str, p: Physical | Choice | Switch) -> QueryParam:
    if isinstance(p, Choice):
        words = tuple((p.words or {}).get(o, o) for o in p.objects)
        return QueryParam(p.url, target, name, p.label, kind="choice", choices=tuple(p.objects), words=words)
    if isinstance(p, Switch):
        return QueryParam(p.url, target, name, p.label, kind="switch")
    lo, hi = p.physical_bounds() if p.bounds is not None else (-math.inf, math.inf)
    return QueryParam(p.url, target, name, p.label, lo, hi, p.log10, infinite=p.infinite)


def _query_params() -> tuple[QueryParam, ...]:
    return tuple(_query_param(target, name, p) for target, cls in TARGETS.items()
                 for name, p in declared_parameters(cls).items() if p.url)


#: the query keys, in the order they are written (the declaration order)
QUERY = _query_params()
BY_KEY = {q.key: q for q in QUERY}
assert len(BY_KEY) == len(QUERY), "two declarations share a URL key"


def url_attributes(target: str) -> list[str]:
    """The attributes of the target `target` that the URL holds (with the ∞ switch of a Physical that has one): the
    page rewrites the URL when one of them changes."""
    return [name for q in QUERY if q.target == target for name in (q.attribute, q.infinite) if name]


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
        word = raw.strip().casefold()
        match = [c for c, w in zip(q.choices, q.words or q.choices, strict=True)
                 if word in (c.casefold(), w.casefold())]
        if match:
            target[q.attribute] = match[0]
        else:
            messages.append(f"{q.symbol} = '{_quote(raw)}' is not one of {', '.join(q.words or q.choices)}: ignored.")
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
        if key in ATLAS_KEYS or key.startswith(ATLAS_AT):
            parse = _parse_atlas_verdict if key == "atlas_verdict" else partial(_parse_atlas, key)
            parse(raw, updates["atlas"], messages)
            continue
        q = BY_KEY.get(ALIASES.get(key, key))
        if q is None:
            messages.append(f"unknown parameter '{_quote(key)}': ignored.")
            continue
        _parse_value(q, raw, updates, messages)
    return updates, tab, messages


def _parse_atlas_verdict(raw: str, atlas: dict[str, object], messages: list[str]) -> None:
    """The Atlas heat map's colouring (``atlas_verdict``: one of :data:`ATLAS_VERDICTS`' words), or a message."""
    if raw in ATLAS_VERDICTS:
        atlas["verdict"] = ATLAS_VERDICTS[raw]
    else:
        messages.append(f"atlas_verdict = '{_quote(raw)}' is not one of {', '.join(ATLAS_VERDICTS)}: ignored.")


def _parse_atlas(key: str, raw: str, atlas: dict[str, object], messages: list[str]) -> None:
    """One of the Atlas tab's keys into `atlas` (the fields of app.atlas.request.AtlasRequest), or a message. Only
    names of the atlas directory's listing and of the six parameters are accepted, never a path."""
    if key == "atlas":
        from .atlas.directory import list_atlases

        names = list_atlases()
        if raw in names:
            atlas["name"] = raw
        else:
            messages.append(f"atlas = '{_quote(raw)}' is not one of the atlases ({', '.join(names) or 'none'}): "
                            "ignored.")
        return
    if key in ("ax", "ay"):
        if raw in ATLAS_AXES:
            atlas[ATLAS_KEYS[key]] = raw
        else:
            messages.append(f"{key} = '{_quote(raw)}' is not one of {', '.join(ATLAS_AXES)}: ignored.")
        return
    if key == "surface":
        axes = tuple(a.strip() for a in raw.split(","))
        if len(axes) == 3 and len(set(axes)) == 3 and all(a in ATLAS_AXES for a in axes):
            atlas["surface"] = axes
        else:
            messages.append(f"surface = '{_quote(raw)}' is not three different ones of {', '.join(ATLAS_AXES)}: "
                            "ignored.")
        return
    axis = key[len(ATLAS_AT):]
    x = parse_number(raw)
    if axis not in ATLAS_AXES:
        messages.append(f"unknown parameter '{_quote(key)}': ignored.")
    elif x is None:
        messages.append(f"{key} = '{_quote(raw)}' is not a finite number: ignored.")
    else:
        atlas.setdefault("at", {})[axis] = x


def atlas_query(state: Mapping[str, object]) -> dict[str, str]:
    """The Atlas tab's URL keys for its state (app.atlas.scene.AtlasScene.url_state: name, x, y, at, surface)."""
    out: dict[str, str] = {}
    if state.get("name"):
        out["atlas"] = str(state["name"])
    for key in ("ax", "ay"):
        value = state.get(ATLAS_KEYS[key])
        if value:
            out[key] = str(value)
    for axis, value in dict(state.get("at") or {}).items():
        out[ATLAS_AT + axis] = f"{value:.6g}"
    if state.get("surface"):
        out["surface"] = ",".join(state["surface"])
    words = {v: k for k, v in ATLAS_VERDICTS.items()}
    if state.get("verdict") in words and words[state["verdict"]] != "sliding":  # the default is not written
        out["atlas_verdict"] = words[state["verdict"]]
    return out


def _url_value(q: QueryParam, obj: param.Parameterized) -> str:
    v = getattr(obj, q.attribute)
    if q.kind == "choice":
        return q.words[q.choices.index(v)] if q.words and v in q.choices else str(v)
    if q.kind == "switch":
        return "1" if v else "0"
    if q.infinite and getattr(obj, q.infinite):
        return "inf"
    return f"{10.0 ** v:.6g}" if q.log10 else f"{v:.6g}"


def _is_default(q: QueryParam, obj: param.Parameterized) -> bool:
    names = (q.attribute, q.infinite) if q.infinite else (q.attribute,)
    return all(getattr(obj, n) == obj.param[n].default for n in names)


def query_string(objects: Mapping[str, param.Parameterized], tab: str, atlas: Mapping[str, object] | None = None
                 ) -> str:
    """The URL search string (``?...``) for the current parameter values; `objects` maps targets (keys of
    :data:`TARGETS`) to the parameter objects (a target left out is not written). A class with
    ``URL_CHANGED_ONLY`` writes only the values that differ from its defaults. `atlas`: the Atlas tab's state
    (:func:`atlas_query`)."""
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
        values.update(atlas_query(atlas))
    return "?" + urllib.parse.urlencode(values, safe=",")
