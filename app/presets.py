"""Presets that reproduce the paper's figures in one click (data: ``app/presets.json``).

A preset's values are URL-query values and go through the same validation as a URL
(:func:`app.urlstate.parse_query`), so a bad preset file cannot put the app in an invalid state.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from .urlstate import BY_KEY, TABS, parse_query

PRESETS_FILE = Path(__file__).resolve().parent / "presets.json"


@dataclass(frozen=True)
class Preset:
    """One figure: target values, the tab that shows it, and an optional family of curves."""

    id: str
    label: str
    title: str
    tab: str
    values: dict[str, str]
    compare_key: str = ""
    compare_values: tuple[float, ...] = ()
    representative: bool = False


def _compare_value(key: str, raw: object) -> float:
    if key == "eta" and str(raw).lower() == "inf":
        return math.inf
    x = float(str(raw))  # float() of a string: numbers only, nothing evaluated
    q = BY_KEY[key]
    if not (math.isfinite(x) and q.lo <= x <= q.hi):
        raise ValueError(f"compare value {key} = {raw!r} outside {q.lo:g} … {q.hi:g}")
    return x


def load_presets(path: Path = PRESETS_FILE) -> list[Preset]:
    """Read and validate the preset file; raises ValueError naming the preset on any problem."""
    data = json.loads(path.read_text(encoding="utf-8"))
    out = []
    for item in data["presets"]:
        pid = item["id"]
        values = {k: str(v) for k, v in item.get("values", {}).items()}
        _, _, messages = parse_query({k: [v] for k, v in values.items()})
        if messages:
            raise ValueError(f"preset {pid}: " + " ".join(messages))
        if item["tab"] not in TABS:
            raise ValueError(f"preset {pid}: tab must be one of {TABS}")
        compare = item.get("compare") or {}
        key = compare.get("key", "")
        if key and key not in BY_KEY:
            raise ValueError(f"preset {pid}: unknown compare key {key!r}")
        cvals = tuple(_compare_value(key, v) for v in compare.get("values", ()))
        out.append(Preset(pid, item["label"], item["title"], item["tab"], values, key, cvals,
                          bool(compare.get("representative", False))))
    return out


def preset_args(preset: Preset) -> dict[str, list[str]]:
    """The preset's values in request-argument form, for :func:`app.urlstate.parse_query`."""
    return {k: [v] for k, v in preset.values.items()}
