"""The server stops completely, workers included, on the signals that stop it in practice.

``asymslide serve --num-procs 2`` is how ``make serve`` and the Docker image run the app (tests/infra/test_infra.py
checks that they do). ``docker stop`` and systemd send SIGTERM to that process; Ctrl-C in a terminal sends
SIGINT to the foreground process group (make and everything it started). Each must leave no process behind
within 10 s (docker stop's default grace period).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from tests.conftest import _find_free_port
from tests.support.processes import alive, children, descendants

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
#: docker stop's default grace period
STOP_WITHIN = 10.0


def _wait_until_serving(proc: subprocess.Popen, port: int, workers: int, timeout: float = 120.0) -> list[int]:
    """Wait for the page and for `workers` forked Panel workers; return every process under `proc`."""
    deadline = time.monotonic() + timeout
    url = f"http://127.0.0.1:{port}/static/js/bokeh.min.js"
    while time.monotonic() < deadline:
        assert proc.poll() is None, "the server exited while starting"
        tree = descendants(proc.pid)
        panel = [p for p in tree if "panel" in _cmdline(p) and "serve" in _cmdline(p)]
        try:
            with urllib.request.urlopen(url, timeout=5) as response:
                if response.status == 200 and len(panel) >= 1 + workers:
                    return tree
        except OSError:
            pass
        time.sleep(0.2)
    raise RuntimeError(f"server on port {port} did not come up with {workers} workers")


def _sliding_workers_then_a_page(proc: subprocess.Popen, port: int, panels: int, timeout: float = 120.0) -> list[int]:
    """Each of the `panels` Panel processes starts its worker for the sliding computation at start-up (app.jobs,
    asymslide/panel_setup.py), before any page is asked for; then GET the app's page (its session computes in that
    worker). Return every process under `proc`."""
    deadline = time.monotonic() + timeout
    while sum("spawn_main" in _cmdline(p) for p in descendants(proc.pid)) < panels:
        assert time.monotonic() < deadline, "no worker process for the sliding computation was started"
        time.sleep(0.2)
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=timeout) as response:
        assert response.status == 200
    return descendants(proc.pid)


def _assert_no_traceback(log: Path) -> None:
    """The server's output after the stop holds no Traceback (CI's Docker smoke test fails on one)."""
    text = log.read_text(errors="replace")
    assert "Traceback" not in text, text[-3000:]


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""


def _assert_all_gone(proc: subprocess.Popen, tree: list[int]) -> None:
    """`proc` exits within STOP_WITHIN s of the signal, and every process it had started is gone by then."""
    try:
        proc.wait(timeout=STOP_WITHIN)
    except subprocess.TimeoutExpired:
        left = [p for p in [proc.pid, *tree] if alive(p)]
        for p in left:
            os.kill(p, signal.SIGKILL)
        proc.wait(timeout=10)
        pytest.fail(f"still running {STOP_WITHIN:g} s after the signal: {[_cmdline(p) for p in left]}")
    left = [p for p in tree if alive(p)]
    for p in left:
        os.kill(p, signal.SIGKILL)
    assert not left, f"left behind: {[_cmdline(p) for p in left]}"


def test_sigterm_to_the_launcher_stops_every_worker(tmp_path: Path) -> None:
    """What docker stop and systemd do: SIGTERM to the process the image's CMD execs."""
    port = _find_free_port()
    log = tmp_path / "server.log"
    with log.open("wb") as out:
        proc = subprocess.Popen([sys.executable, "-m", "asymslide", "serve", "--port", str(port), "--address",
                                 "127.0.0.1", "--num-procs", "2"], cwd=ROOT, stdout=out, stderr=subprocess.STDOUT)
    try:
        _wait_until_serving(proc, port, workers=2)
        assert len(children(children(proc.pid)[0])) == 2  # launcher -> panel -> two workers
        tree = _sliding_workers_then_a_page(proc, port, panels=2)
        proc.send_signal(signal.SIGTERM)
        _assert_all_gone(proc, tree)
        assert proc.returncode == 0  # a stop that was asked for and done is a clean exit (docker stop: "Exited (0)")
        _assert_no_traceback(log)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


@pytest.mark.skipif(not (ROOT / ".venv" / "bin" / "asymslide").exists(), reason="make serve needs the .venv")
def test_ctrl_c_on_make_serve_stops_every_worker(tmp_path: Path) -> None:
    """What a terminal does on Ctrl-C: SIGINT to the whole foreground process group of `make serve`."""
    port = _find_free_port()
    log = tmp_path / "server.log"
    with log.open("wb") as out:
        proc = subprocess.Popen(["make", "--no-print-directory", "serve", f"PORT={port}", "ADDRESS=127.0.0.1",
                                 "NUM_PROCS=2"], cwd=ROOT, stdout=out, stderr=subprocess.STDOUT,
                                start_new_session=True)  # its own group, as a terminal's foreground job
    try:
        _wait_until_serving(proc, port, workers=2)
        tree = _sliding_workers_then_a_page(proc, port, panels=2)
        os.killpg(proc.pid, signal.SIGINT)
        _assert_all_gone(proc, tree)
        _assert_no_traceback(log)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
