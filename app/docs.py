"""The project's physics reference (docs/physics.md) inside the app: a reference such as "docs/physics.md §12.3" in a
scene is a card that opens on that section's text, rendered, instead of a path the user cannot follow.

The file is read from the source tree (``docs/`` beside ``app/``) or, installed, from the copy inside the app package
(``app/reference/physics.md``, pyproject.toml); where neither exists the card says where the text lives instead.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

import panel as pn

#: the physics reference: the source tree's, else the one installed with the app
PHYSICS = next((p for p in (Path(__file__).resolve().parent.parent / "docs" / "physics.md",
                            Path(__file__).resolve().parent / "reference" / "physics.md") if p.is_file()),
               Path(__file__).resolve().parent.parent / "docs" / "physics.md")

_HEADING = re.compile(r"^(#+) §(\d+(?:\.\d+)*)\b(.*)$")


@functools.cache
def _sections() -> dict[str, tuple[str, str]]:
    """§ number -> (title, Markdown text up to the next heading of the same or a higher level)."""
    try:
        lines = PHYSICS.read_text(encoding="utf-8").splitlines()
    except OSError:
        return {}
    out: dict[str, tuple[str, str]] = {}
    heads = [(i, m) for i, line in enumerate(lines) if (m := _HEADING.match(line))]
    for k, (i, m) in enumerate(heads):
        level = len(m.group(1))
        end = next((j for j, n in heads[k + 1:] if len(n.group(1)) <= level), len(lines))
        out[m.group(2)] = (m.group(3).strip(), "\n".join(lines[i + 1:end]).strip())
    return out


def section(number: str) -> tuple[str, str] | None:
    """(title, text) of section `number` ("12.3") of docs/physics.md, or None where it is not available."""
    return _sections().get(number)


def reference_card(number: str) -> pn.Card:
    """A collapsed card titled "docs/physics.md §`number`: its title" that shows the section when opened (built
    then: a page pays nothing for it until it is read)."""
    found = section(number)
    title = f"docs/physics.md §{number}" + (f": {found[0]}" if found else "")
    card = pn.Card(title=title, collapsed=True, sizing_mode="stretch_width", header_color="#1f4e79")

    def fill(*_events) -> None:
        if not card.collapsed and not card.objects:
            text = (found[1] if found else f"§{number} of docs/physics.md is not installed with this copy of the app; "
                    "it is in the project's source tree (docs/physics.md).")
            card.objects = [pn.pane.Markdown(text, sizing_mode="stretch_width")]

    card.param.watch(fill, "collapsed")
    return card
