"""The test suite's own guard (tests/conftest.py): a session that leaves a process running fails."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.processes import MARKER, alive, command_line

ROOT = Path(__file__).resolve().parents[2]

LEAKY_TEST = '''
import subprocess, sys
def test_starts_a_process_and_forgets_it():
    subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
'''
LEAKY_SPAWNED_WORKER = '''
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
POOL = ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"))  # as app.jobs.process_pool
def test_starts_a_spawned_worker_and_forgets_it():
    assert POOL.submit(abs, -1).result(timeout=60) == 1
'''
LEAKY_AFTER_A_SECOND_IMPORT = f'''
import importlib.util, subprocess, sys
def test_imports_the_conftest_again_then_forgets_a_process():
    spec = importlib.util.spec_from_file_location("conftest_again", "{ROOT / "tests" / "conftest.py"}")
    spec.loader.exec_module(importlib.util.module_from_spec(spec))  # as "from tests.conftest import open_app" does
    subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
'''

CLEAN_TEST = '''
import subprocess, sys
def test_starts_a_process_and_waits():
    subprocess.run([sys.executable, "-c", "pass"], check=True)
'''


def _run_session(tmp_path: Path, body: str) -> subprocess.CompletedProcess:
    """A pytest session over one test file that uses this suite's conftest hooks."""
    (tmp_path / "conftest.py").write_text("from tests.conftest import pytest_sessionfinish  # noqa: F401\n")
    (tmp_path / "test_it.py").write_text(body)
    env = {**os.environ, "ASYMSLIDE_LEFTOVER_GRACE": "1", "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir",
                           str(tmp_path), str(tmp_path / "test_it.py")], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_a_leaked_process_fails_the_session_and_is_killed(tmp_path: Path) -> None:
    result = _run_session(tmp_path, LEAKY_TEST)
    assert result.returncode == 1, result.stdout + result.stderr
    assert "1 passed" in result.stdout
    assert "process(es) started by the tests were still running" in result.stdout
    assert "time.sleep(120)" in result.stdout
    survivors = [p for p in map(int, filter(str.isdigit, os.listdir("/proc")))
                 if "time.sleep(120)" in command_line(p) and alive(p)]
    assert not survivors  # the inner session killed what it had left behind


@pytest.mark.slow
def test_a_leaked_spawned_worker_fails_the_session_instead_of_hanging_it(tmp_path: Path) -> None:
    """A spawned worker holds multiprocessing's resource tracker's pipe: stopping the tracker first waited for ever."""
    result = _run_session(tmp_path, LEAKY_SPAWNED_WORKER)  # times out (120 s) if the session hangs
    assert result.returncode == 1, result.stdout + result.stderr
    assert "1 passed" in result.stdout
    assert "process(es) started by the tests were still running" in result.stdout
    assert "spawn_main" in result.stdout


@pytest.mark.slow
def test_a_second_import_of_the_conftest_keeps_the_sessions_mark(tmp_path: Path) -> None:
    """Tests that import the conftest's helpers import it a second time: its mark of the session's processes holds."""
    result = _run_session(tmp_path, LEAKY_AFTER_A_SECOND_IMPORT)
    assert result.returncode == 1, result.stdout + result.stderr
    assert "process(es) started by the tests were still running" in result.stdout
    assert "time.sleep(120)" in result.stdout


@pytest.mark.slow
def test_a_clean_session_passes(tmp_path: Path) -> None:
    result = _run_session(tmp_path, CLEAN_TEST)
    assert result.returncode == 0, result.stdout + result.stderr


def test_this_session_marks_its_processes() -> None:
    child = subprocess.run([sys.executable, "-c", f"import os; print(os.environ['{MARKER}'])"],
                           capture_output=True, text=True, check=True)
    assert child.stdout.strip() == os.environ[MARKER] and child.stdout.startswith("pytest-")
