"""What the wheel installs (issue 15, point 6): the import names model, app and asymslide (kept short on purpose,
see the README's Packaging section), every data file the app needs, and the asymslide console script."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import asymslide

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> zipfile.ZipFile:
    """The wheel built from a copy of the working tree (setuptools writes build/ into the tree it builds)."""
    out = tmp_path_factory.mktemp("wheel")
    src = out / "src"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(".venv", ".git", "build", "*.egg-info", "__pycache__",
                                                              ".numba_cache", ".pytest_cache", ".hypothesis"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(out), str(src)],
                   check=True, capture_output=True, timeout=600)
    (path,) = out.glob("asymslide-*.whl")
    return zipfile.ZipFile(path)


def test_wheel_installs_three_import_names_and_the_data_files(wheel: zipfile.ZipFile) -> None:
    names = wheel.namelist()
    top = {n.split("/")[0] for n in names if not n.split("/")[0].endswith((".dist-info", ".data"))}
    assert top == set(asymslide.IMPORT_NAMES)
    for needed in ("app/presets.json", "app/static/asymslide.css", "app/static/logo.svg", "app/static/favicon.svg",
                   "model/materials.json", "app/main.py", "asymslide/cli.py", "asymslide/sweep.py"):
        assert needed in names, needed
    assert not [n for n in names if n.startswith(("tests/", "benchmarks/"))]
    entry = next(n for n in names if n.endswith("entry_points.txt"))
    assert "asymslide = asymslide.cli:main" in wheel.read(entry).decode()


def test_a_clash_of_import_names_is_reported(monkeypatch: pytest.MonkeyPatch) -> None:
    fake = {"model": ["asymslide", "someone-elses-model"], "app": ["asymslide"], "asymslide": ["asymslide"]}
    monkeypatch.setattr(asymslide, "packages_distributions", lambda: fake)
    assert asymslide.import_name_clashes() == {"model": ["someone-elses-model"]}


def test_this_environment_has_no_clash() -> None:
    assert asymslide.import_name_clashes() == {}
