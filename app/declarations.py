"""How a user-facing parameter is declared (:class:`Physical`, :class:`Choice`, :class:`Switch`: a param
parameter with its label, URL key, slider range and stability-map axis), and the helpers that read the declarations."""

from __future__ import annotations

from typing import Any

import param
from param.parameterized import Undefined

from .workarounds import frozen_document


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
