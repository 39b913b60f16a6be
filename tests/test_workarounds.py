"""The Panel/Bokeh workarounds (app/workarounds.py) were checked against one version of each library: another
installed version fails here, so that someone re-checks them (and the lock) instead of finding out from users."""

from __future__ import annotations

import re
from importlib.metadata import version
from pathlib import Path

import pytest

from app import workarounds

LOCK = Path(__file__).resolve().parent.parent / "requirements.lock"


def _locked(name: str) -> str:
    match = re.search(rf"^{name}==([^\s;]+)", LOCK.read_text(encoding="utf-8"), flags=re.M | re.I)
    assert match, f"{name} is not pinned in {LOCK.name}"
    return match.group(1)


@pytest.mark.parametrize("library", sorted(workarounds.CHECKED_WITH))
def test_workarounds_were_checked_with_the_installed_and_locked_version(library: str) -> None:
    checked = workarounds.CHECKED_WITH[library]
    assert _locked(library) == checked, (
        f"requirements.lock pins {library} {_locked(library)}, app/workarounds.py was checked with {checked}: re-check "
        "every workaround there against the new version, then update CHECKED_WITH")
    assert version(library) == checked, (
        f"{library} {version(library)} is installed, app/workarounds.py was checked with {checked}: re-check every "
        "workaround there against it (or install the locked version: make venv)")


def test_the_patched_library_internals_are_still_there() -> None:
    """What the workarounds reach into exists in the installed versions (a renamed internal fails here, not in a
    served page)."""
    import panel.io.resources
    import panel.reactive
    from bokeh.document import Document

    for module in (panel.io.resources, panel.reactive):
        assert callable(module.patch_stylesheet)
    assert callable(panel.io.resources.patch_model_css) and callable(panel.io.resources.get_dist_path)
    doc = Document()
    assert isinstance(doc._template_variables, dict)
    assert callable(doc.models.freeze) and callable(doc.models.recompute) and callable(doc.models.invalidate)
