"""One list of the page's tabs (app/tabs.py, TABS_REGISTRY): the page's titles, their order and which tabs are built
when first shown, the URL's accepted ``tab=`` values and the scenes' own URL settings all come from it, and no other
module of the app lists the tabs."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from asymslide.app import urlstate
from asymslide.app.tabs import TABS_REGISTRY
from asymslide.app.urlstate import SHARED_TARGETS, TARGETS, parse_query
from tests.support.headless import build_app

ROOT = Path(__file__).resolve().parents[2]
KEYS = tuple(tab.key for tab in TABS_REGISTRY)
TITLES = tuple(tab.title for tab in TABS_REGISTRY)


def test_the_page_shows_the_registrys_tabs_in_order() -> None:
    app = build_app({})
    root = app.tabs.get_root()  # the Bokeh model the browser receives
    assert [panel.title for panel in root.tabs] == list(TITLES)
    assert list(app._scenes) == list(KEYS)
    for tab, content in zip(TABS_REGISTRY, app.tabs.objects, strict=True):
        assert content is app._tab_content[tab.key]


@pytest.mark.parametrize("opened", [None, "thin"])
def test_only_the_registrys_eager_tabs_and_the_one_opened_are_built(opened: str | None) -> None:
    app = build_app({"tab": [opened]} if opened else {})
    assert app.tabs.active == (KEYS.index(opened) if opened else 0)
    built = {tab.key for tab, content in zip(TABS_REGISTRY, app.tabs.objects, strict=True) if content.objects}
    eager = {tab.key for tab in TABS_REGISTRY if not tab.lazy}
    assert eager and built == eager | {opened or KEYS[0]}


def test_the_url_accepts_exactly_the_registrys_tab_values() -> None:
    assert urlstate.TABS == KEYS
    for key in KEYS:
        _, tab, messages = parse_query({"tab": [key]})
        assert (tab, messages) == (key, [])
    for other in ("Spectrum", "lab", "tabs", " map", ""):
        _, tab, messages = parse_query({"tab": [other]})
        assert tab is None and len(messages) == 1 and ", ".join(KEYS) in messages[0]


def test_the_scenes_own_url_settings_are_the_registrys() -> None:
    """A tab with url_settings owns the URL target named by its key: parsed into updates[key], written from its
    scene (App.param_objects), after the shared parameters."""
    owned = {tab.key: tab.url_settings for tab in TABS_REGISTRY if tab.url_settings is not None}
    assert owned == {"map": TARGETS["map"], "branches": TARGETS["branches"]}
    assert list(TARGETS.items()) == [*SHARED_TARGETS.items(), *owned.items()]
    objects = build_app({}).param_objects()
    assert list(objects) == list(TARGETS)
    assert all(isinstance(objects[key], cls) for key, cls in owned.items())


def _tab_lists(source: str) -> list[str]:
    """The literal collections in `source` that list two or more tab keys or titles (a tuple, list or set of them, or
    a dict whose keys or values are titles): line and words."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Tuple | ast.List | ast.Set):
            words = {e.value for e in node.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)}
            if len(words & set(KEYS)) >= 2 or len(words & set(TITLES)) >= 2:
                found.append(f"{node.lineno}: {sorted(words)}")
        elif isinstance(node, ast.Dict):
            words = {e.value for e in (*node.keys, *node.values) if isinstance(e, ast.Constant)
                     and isinstance(e.value, str)}
            if len(words & set(TITLES)) >= 2:
                found.append(f"{node.lineno}: {sorted(words)}")
    return found


def test_no_other_module_lists_the_tabs() -> None:
    """The registry is the app's one list of tabs: app/main.py's titles and lazy tabs and app/urlstate.py's tab values
    were three parallel tuples; what they gave is derived now (urlstate.TABS: the registry's keys). Checked on the
    source of every module of app/ and asymslide/ (not the tests, which name tabs to open them)."""
    for old in ('LAZY_TABS = ("map", "thin", "rupture", "branches", "atlas")',
                'TAB_TITLES = ("Spectrum", "Stability map", "Thin-on-thick")', 'TABS = ["spectrum", "map"]',
                'TITLES = {"spectrum": "Spectrum", "map": "Stability map"}'):
        assert _tab_lists(old), old  # the check finds each form the lists had, or could have
    modules = sorted({*(ROOT / "app").rglob("*.py"), *(ROOT / "asymslide").rglob("*.py")} - {ROOT / "app/tabs.py"})
    assert ROOT / "app/main.py" in modules and ROOT / "app/urlstate.py" in modules
    found = [f"{path.relative_to(ROOT)}:{hit}" for path in modules for hit in _tab_lists(path.read_text("utf-8"))]
    assert found == []


def test_the_registry_imports_neither_the_page_nor_the_url_state() -> None:
    """main.py and urlstate.py import app/tabs.py: it must not import them back (nor presets.py, which imports
    urlstate.py)."""
    tree = ast.parse((ROOT / "app/tabs.py").read_text(encoding="utf-8"))
    imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module}
    imported |= {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
    assert not {name.rpartition(".")[2] for name in imported} & {"main", "urlstate", "presets"}
