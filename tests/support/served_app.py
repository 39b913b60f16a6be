"""The app served as ``make serve`` and the Docker image serve it (``asymslide serve`` in a subprocess, on a free port):
its URL, processes, memory, CPU and the errors in its log. Used by the browser tests of the served app and by the
benchmarks (benchmarks/load_test.py, latency.py, atlas_latency.py, first_page.py)."""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from collections.abc import Sequence
from pathlib import Path

from asymslide.serve import children
from tests.support.processes import descendants

ROOT = Path(__file__).resolve().parents[2]

#: server lines that count as errors
ERROR_LINE = re.compile(r"\bERROR\b|Traceback|Exception in callback|Uncaught exception")
#: a log line of its own (a timestamp first): the end of the traceback before it
LOG_LINE = re.compile(r"^\d{4}-\d\d-\d\d[ T]\d\d:\d\d")
#: exceptions of a connection the client closed while the server still wrote to it (a page closed, or a load-test
#: session replaced): not the app's errors (as tests/conftest.py's ServerLog.DISCONNECTS for in-process servers)
DISCONNECTS = ("WebSocketClosedError", "StreamClosedError", "CancelledError")


def is_disconnect(block: list[str]) -> bool:
    """Whether a traceback block (its lines) ends in a disconnect: every exception it names (the unindented lines
    after a 'Traceback' header, e.g. 'tornado.websocket.WebSocketClosedError') is one of :data:`DISCONNECTS`."""
    raised = [ln for ln in block if ln and not ln[0].isspace() and not ln.startswith(("Traceback", "During handling"))]
    return bool(raised) and all(any(d in ln for d in DISCONNECTS) for ln in raised)


def serve_args(port: int, num_procs: int) -> list[str]:
    """``asymslide serve`` as ``make serve`` and the Docker image run it (the launcher adds the static files and
    ``--reuse-sessions``: a page request then costs ~20 ms, and each user's document is built once, when its
    websocket connects, in whichever process accepts it), on 127.0.0.1:`port` with `num_procs` processes."""
    return ["serve", "--port", str(port), "--address", "127.0.0.1", "--allow-websocket-origin", f"127.0.0.1:{port}",
            "--allow-websocket-origin", f"localhost:{port}", "--num-procs", str(num_procs)]


def free_port() -> int:
    """A TCP port on localhost that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class ServedApp:
    """``panel serve app/main.py`` in a subprocess: its URL, processes, memory, CPU and log errors."""

    def __init__(self, extra_args: Sequence[str] = (), port: int | None = None, num_procs: int = 1) -> None:
        self.port = port or free_port()
        self.num_procs = num_procs
        self.url = f"http://127.0.0.1:{self.port}/main"
        self.ws_url = f"ws://127.0.0.1:{self.port}/main/ws"
        self.args = [sys.executable, "-m", "asymslide", *serve_args(self.port, num_procs), "--", *extra_args]
        self.log: list[str] = []
        self.log_times: list[float] = []  # time.monotonic() when each line of `log` arrived
        self._log_lock = threading.Lock()
        self.error_lines: list[str] = []
        #: how long the server may take to answer after its start (the launcher compiles numba's kernels first:
        #: minutes without a cache on a busy host)
        self.start_timeout = 300.0
        self.proc: subprocess.Popen[str] | None = None
        self._readers: list[threading.Thread] = []

    def __enter__(self) -> ServedApp:
        env = dict(os.environ)
        env.setdefault("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache"))
        self.proc = subprocess.Popen(self.args, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True, encoding="utf-8", errors="replace")
        for stream in (self.proc.stdout, self.proc.stderr):
            t = threading.Thread(target=self._read, args=(stream,), daemon=True)
            t.start()
            self._readers.append(t)
        try:
            self._wait_until_up(self.start_timeout)
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _read(self, stream) -> None:
        """Collect the log; error lines, and each traceback as a block (up to the next log line of its own), into
        error_lines, except a traceback that ends in a client's disconnect (:func:`is_disconnect`)."""
        block: list[str] = []  # the traceback being read

        def end_block() -> None:
            if block and not is_disconnect(block):
                self.error_lines.extend(block)
            block.clear()

        for line in stream:
            line = line.rstrip("\n")
            with self._log_lock:  # stdout's and stderr's readers: each line with its own time, in arrival order
                self.log_times.append(time.monotonic())
                self.log.append(line)
            if block and (LOG_LINE.match(line) or line.startswith("Traceback")):
                end_block()
            if line.startswith("Traceback") or block:
                block.append(line)
            elif ERROR_LINE.search(line):
                self.error_lines.append(line)
        end_block()

    def _wait_until_up(self, timeout: float = 120.0) -> None:
        """Wait for a static file (requesting the app page would open a session, which on a clean
        checkout first compiles numba's kernels)."""
        probe = f"http://127.0.0.1:{self.port}/static/js/bokeh.min.js"
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            assert self.proc is not None
            if self.proc.poll() is not None:
                raise RuntimeError("panel serve exited while starting:\n" + "\n".join(self.log[-30:]))
            try:
                with urllib.request.urlopen(probe, timeout=5) as response:
                    if response.status == 200:
                        return
            except OSError:
                pass
            time.sleep(0.2)
        raise RuntimeError(f"{self.url} did not come up within {timeout} s:\n" + "\n".join(self.log[-30:]))

    @property
    def pid(self) -> int:
        """The first Panel process (the launcher's child): the server, or with ``--num-procs`` > 1 the parent
        that forked the workers."""
        assert self.proc is not None
        deadline = time.monotonic() + 10.0
        while not (kids := children(self.proc.pid)):
            if time.monotonic() > deadline:
                raise RuntimeError("asymslide serve started no panel process")
            time.sleep(0.05)
        return kids[0]

    def pids(self) -> list[int]:
        """The Panel processes: the first one and, with ``--num-procs`` > 1, the workers it forked (which serve)."""
        return [self.pid, *children(self.pid)]

    def workers(self) -> list[int]:
        """The processes that serve sessions: the forked workers, or the one process."""
        if self.num_procs == 1:
            return [self.pid]
        return self.pids()[1:] or [self.pid]

    def memory_mb(self) -> float:
        """Memory of the server's processes in MB: the sum of their proportional set sizes (Pss of
        /proc/<pid>/smaps_rollup; pages the forked workers share are counted once). One process: its RSS."""
        if self.num_procs == 1:
            return _proc_kb(self.pid, "status", "VmRSS:") / 1024.0
        return sum(_proc_kb(pid, "smaps_rollup", "Pss:") for pid in self.pids()) / 1024.0

    def cpu_seconds(self) -> float:
        """user + system CPU time of the server's processes, in seconds."""
        return sum(cpu_seconds(pid) for pid in self.pids())

    def session_states(self, polls: int = 1) -> dict[str, bool] | None:
        """Session id -> live (not destroyed yet), from the REST endpoint (needs --rest-session-info and
        --session-history). Each request is answered by one process, so `polls` answers are merged; a
        session is live if any answer says so. None if the endpoint did not answer."""
        states: dict[str, bool] = {}
        answered = False
        for _ in range(polls):
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{self.port}/rest/session_info",
                                            timeout=5) as response:
                    info = json.loads(response.read())
            except (OSError, ValueError):
                continue
            answered = True
            for sid, s in info.get("session_info", info).get("sessions", {}).items():
                states[sid] = states.get(sid, False) or s.get("ended") is None
        return states if answered else None

    def stop(self) -> None:
        """SIGTERM to the launcher, which stops every Panel process (asymslide/serve.py) before it exits."""
        if self.proc is None or self.proc.poll() is not None:
            return
        self.proc.terminate()
        try:
            self.proc.wait(timeout=15)
        except subprocess.TimeoutExpired:  # the launcher itself hung: kill it and its process tree
            for pid in [*reversed(descendants(self.proc.pid)), self.proc.pid]:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, signal.SIGKILL)
            self.proc.wait(timeout=15)
        for t in self._readers:
            t.join(timeout=5)


def _proc_kb(pid: int, name: str, key: str) -> int:
    """The ``key`` line (kB) of /proc/<pid>/<name>."""
    with open(f"/proc/{pid}/{name}", encoding="ascii") as fh:
        for line in fh:
            if line.startswith(key):
                return int(line.split()[1])
    raise RuntimeError(f"{key} not in /proc/{pid}/{name}")


def cpu_seconds(pid: int) -> float:
    """user + system CPU time of a process (/proc/<pid>/stat), in seconds."""
    with open(f"/proc/{pid}/stat", encoding="ascii") as fh:
        fields = fh.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
