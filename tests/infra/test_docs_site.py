"""The documentation site's own checks (docs/_ext/asymslide_docs.py): the internal link check, the equation labels,
the docstring check and the documented constants. The site itself is built by ``make docs`` (CI runs it after
``make test``, warnings as errors)."""

from __future__ import annotations

import importlib
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
pytest.importorskip("sphinx", reason="the docs extra (make venv installs it)")
sys.path.insert(0, str(ROOT / "docs" / "_ext"))
site = importlib.import_module("asymslide_docs")


def test_the_link_check_finds_a_missing_page_and_a_missing_anchor_and_passes_good_links(tmp_path: Path) -> None:
    (tmp_path / "api").mkdir()
    (tmp_path / "_static").mkdir()
    (tmp_path / "_static" / "theme.css").write_text("")
    (tmp_path / "_static" / "macros.html").write_text('<a href="{{ pathto(x) }}">template</a>')
    (tmp_path / "api" / "model.html").write_text('<dt id="asymslide.model.spectrum">spectrum</dt>')
    (tmp_path / "index.html").write_text(
        '<link href="_static/theme.css"><h1 id="top">t</h1><a href="#top">self</a>'
        '<a href="api/model.html#asymslide.model.spectrum">ok</a><a href="https://example.org/x#y">external</a>'
        '<a href="api/model.html#asymslide.model.nothing">bad anchor</a><a href="guide/missing.html">bad page</a>'
        '<img src="missing.png">')
    broken = site.broken_links(tmp_path)
    assert broken == ["index.html: api/model.html#asymslide.model.nothing (no such anchor)",
                      "index.html: guide/missing.html (no such file)",
                      "index.html: missing.png (no such file)"]


def test_every_equation_label_the_physics_page_cites_is_parsed_with_its_sections() -> None:
    where = site._physics_labels(ROOT / "docs")
    text = (ROOT / "docs" / "physics.md").read_text(encoding="utf-8")
    cited = set(site.EQ_LABEL.findall(text))
    # "Eq. X" and "Eq. S-X" in the page's preamble explain the notation: they are not labels
    assert cited and set(where) == cited - {"X", "S-X"}
    assert "§4" in where["S-dz"] and "§4" in where["criterion"]
    assert {"delta f RSF", "S-delta f RSF_SM", "B(q)C(q)"} <= set(where)  # the labels with a space or parentheses
    assert "delta" not in where and "B" not in where


def test_the_labels_docstrings_cite_name_their_implementing_functions() -> None:
    implemented = site._implementers()
    assert "linear_expansion" in implemented["S-dz"]
    assert {"criterion_chi", "min_gy_at_rayleigh_speed"} <= set(implemented["criterion"])
    assert "response_functions" in implemented["Gs_general"]
    assert "dispersion" in implemented["delta f RSF"] and "bessel_integral_B" in implemented["B(q)C(q)"]


def test_every_public_function_class_and_method_of_the_model_atlas_and_notebook_helper_has_a_docstring() -> None:
    names = dict(site._public_callables())
    assert "asymslide.model.spectrum" in names and "asymslide.atlas.sweep.sweep" in names
    assert "asymslide.atlas.plan.Plan.size" in names  # methods and properties are included
    assert "asymslide.app.notebook.scene" in names  # and the notebook helper
    missing = [n for n, obj in names.items() if not (site.inspect.getdoc(obj) or "").strip()]
    assert missing == []


def test_every_public_constant_of_the_model_has_a_doc_comment_where_it_is_defined() -> None:
    from asymslide import model

    constants = [n for n in model.__all__ if site._is_constant(getattr(model, n))]
    docs = site._constant_docs()
    assert {"STATUS", "VERDICT_STATUS", "SLIDING_STATUS", "DEFAULT_FLOOR", "PAPER_DEFAULTS"} <= set(constants)
    assert [n for n in constants if n not in docs] == []


def _screenshot_names() -> set[str]:
    """The images `make screenshots` writes into docs/: the names its tests pass to save_screenshot."""
    recipe = subprocess.run(["make", "-n", "screenshots"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    files = {ROOT / m.split("::")[0] for m in re.findall(r"tests/\S+\.py(?:::\S+)?", recipe)}
    assert files, recipe
    names: set[str] = set()
    for path in files:
        names.update(re.findall(r'save_screenshot\(\s*\w+,\s*"([^"]+\.png)"', path.read_text(encoding="utf-8")))
    return names


def test_every_picture_of_the_site_and_the_readme_is_a_screenshot_make_screenshots_refreshes_or_a_scripts_figure(
) -> None:
    """A picture comes from `make screenshots` (the browser tests that walk through the app), or is a figure whose
    page names the script that makes it (and the script writes that file)."""
    screenshots = _screenshot_names()
    assert {"screenshot.png", "screenshot_atlas.png", "screenshot_lab.png"} <= screenshots
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    checked = 0
    for page in pages:
        text = page.read_text(encoding="utf-8")
        images = re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", text)
        images += re.findall(r"^```\{(?:image|figure)\} (\S+)", text, re.M)
        for target in images:
            image = (page.parent / target).resolve()
            assert image.is_file(), f"{page.relative_to(ROOT)}: {target} does not exist"
            assert image.parent == ROOT / "docs", f"{page.relative_to(ROOT)}: {target} is not in docs/"
            checked += 1
            if image.name in screenshots:
                continue
            scripts = re.findall(r"python (benchmarks/\w+\.py)", text)
            assert any(image.name in (ROOT / s).read_text(encoding="utf-8") for s in scripts), (
                f"{page.relative_to(ROOT)}: {image.name} is neither refreshed by make screenshots nor made by a "
                "script the page names")
    assert checked >= 6


def test_the_site_refuses_broken_references_and_runs_its_own_checks() -> None:
    """docs/conf.py: nitpicky (a reference to an undocumented object is a warning, an error under make docs' -W),
    the notebooks' errors raised, and this extension loaded with its checks connected."""
    conf: dict[str, object] = {"__file__": str(ROOT / "docs" / "conf.py")}
    exec(compile((ROOT / "docs" / "conf.py").read_text(encoding="utf-8"), "conf.py", "exec"), conf)  # noqa: S102
    assert conf["nitpicky"] is True and conf["nb_execution_raise_on_error"] is True
    assert "asymslide_docs" in conf["extensions"]
    connected: list[str] = []

    class App:
        def add_directive(self, name: str, _cls: type) -> None:
            connected.append(name)

        def connect(self, event: str, _handler: object) -> None:
            connected.append(event)

    site.setup(App())
    assert {"model-constants", "equation-index", "builder-inited", "build-finished", "missing-reference"} <= set(
        connected)
