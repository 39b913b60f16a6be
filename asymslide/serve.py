"""``asymslide serve``: run ``panel serve app/main.py`` and stop it completely on SIGTERM, SIGINT or SIGHUP.

Why a launcher: with ``--num-procs N`` Panel (through Tornado's ``fork_processes``) forks N worker
processes. SIGTERM kills the forking parent at once and leaves the workers running: they install their
SIGTERM handler on an event loop that never runs, so they ignore it (they do stop on SIGINT).
``docker stop`` and systemd send SIGTERM, so a container or service would keep ~1 GB of orphaned
workers. The launcher starts Panel in its own process group, becomes the "child subreaper" of everything
Panel starts (Linux ``PR_SET_CHILD_SUBREAPER``: orphaned workers are re-parented to it and reaped here,
never left as zombies), and on any stop signal sends SIGINT to the whole group, waits up to
:data:`GRACE_SECONDS` for it to empty, then sends SIGKILL. Workers killed after their parent are not
restarted (Tornado restarts workers only while the parent lives). The forking parent itself gets
SIGTERM first: it only supervises, and SIGINT would end it with a KeyboardInterrupt traceback in the log.
"""

from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path

#: how long the group may take to stop after SIGINT before it is killed (docker stop waits 10 s)
GRACE_SECONDS = 8.0
#: polling interval while waiting for Panel or for its process group to stop
POLL_SECONDS = 0.05
#: signals that stop the server (SIGHUP: the terminal was closed)
STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)
#: prctl option that makes the calling process the reaper of its orphaned descendants (linux/prctl.h)
PR_SET_CHILD_SUBREAPER = 36


def children(pid: int) -> list[int]:
    """Direct children of `pid` (empty if it is gone), from Linux's /proc."""
    try:
        with open(f"/proc/{pid}/task/{pid}/children", encoding="ascii") as fh:
            return [int(p) for p in fh.read().split()]
    except OSError:
        return []


def app_main() -> Path:
    """The app's entry script ``app/main.py`` (in the source tree or the installed package)."""
    from asymslide import app

    return Path(app.__file__).resolve().parent / "main.py"


def static_dir() -> Path:
    """The CSS, logo and favicon served under ``/assets``: ``static/`` of the source tree, or the copy
    installed inside the ``app`` package."""
    from asymslide.app.paths import STATIC_DIR

    return STATIC_DIR


def setup_script() -> Path:
    """The script every Panel process runs before it serves a page (``--setup``): it loads the model's kernels."""
    return Path(__file__).resolve().parent / "panel_setup.py"


def warm_kernels(env: dict[str, str] | None = None) -> int | None:
    """Compile the model's kernels into numba's cache (``asymslide warmup``, in a subprocess: the launcher itself
    stays small), printing "compiling kernels ..." and "kernels ready" before the server starts; the server
    processes then load them from the cache (:func:`setup_script`). A failure is reported and the server starts
    anyway (it then compiles the kernels itself). A stop signal meanwhile stops the warm-up: the exit status to
    return (128 + the signal) is returned; None otherwise."""
    received: list[int] = []
    proc = subprocess.Popen([sys.executable, "-m", "asymslide", "warmup"], env=env)

    def on_signal(signum: int, _frame: object) -> None:
        received.append(signum)
        proc.terminate()

    previous = {sig: signal.signal(sig, on_signal) for sig in STOP_SIGNALS}
    try:
        status = proc.wait()
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if received:
        return 128 + received[0]
    if status != 0:
        print(f"asymslide: compiling the kernels failed (exit status {status}); the server compiles them when they "
              "are first used", file=sys.stderr, flush=True)
    return None


def panel_command(*, port: int, address: str, origins: Sequence[str], num_procs: int, liveness: bool = False,
                  extra: Sequence[str] = ()) -> list[str]:
    """The ``panel serve`` command line: the app, this server's static files, `num_procs` processes, pages
    rendered from one cached session (``--reuse-sessions``), the kernels loaded in every process before it serves
    (``--setup``, :func:`setup_script`), and the hosts whose pages may open the websocket (never '*')."""
    if num_procs < 1:
        raise ValueError(f"num_procs must be >= 1; got {num_procs}")
    if any(o.strip() in ("*", "") for o in origins):
        raise ValueError("allowed websocket origins must be host[:port] names, not '*' or empty")
    cmd = [sys.executable, "-m", "panel", "serve", str(app_main()), "--port", str(port), "--address", address,
           *(f"--allow-websocket-origin={o}" for o in origins), "--static-dirs", f"assets={static_dir()}",
           "--num-procs", str(num_procs), "--reuse-sessions", "--setup", str(setup_script()),
           # the app at / too (not a redirect to /main, which drops the query: a shared /?tab=atlas&... link keeps it)
           "--index", app_main().stem]
    if liveness:
        cmd.append("--liveness")
    return [*cmd, *extra]


def _become_subreaper() -> bool:
    """Ask Linux to re-parent this process's orphaned descendants to it (False where unsupported)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _reap() -> dict[int, int]:
    """Collect every exited child (pid -> wait status) without blocking."""
    done: dict[int, int] = {}
    while True:
        try:
            pid, status = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return done
        if pid == 0:
            return done
        done[pid] = status


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # a process we cannot signal is still in the group
        return True
    return True


def _signal_group(pgid: int, sig: int) -> None:
    try:
        os.killpg(pgid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def stop_group(pgid: int, grace: float = GRACE_SECONDS) -> dict[int, int]:
    """Stop the process group `pgid` (led by Panel's first process): SIGTERM to the leader if it forked
    workers, SIGINT to the group, SIGKILL after `grace` seconds. Returns the statuses reaped on the way, once
    no process of the group is left (all reaped: this process is their subreaper)."""
    statuses: dict[int, int] = {}
    deadline = time.monotonic() + grace
    if children(pgid):
        try:
            os.kill(pgid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        while pgid not in statuses and time.monotonic() < deadline:
            statuses.update(_reap())
            time.sleep(POLL_SECONDS)
    _signal_group(pgid, signal.SIGINT)
    while time.monotonic() < deadline:
        statuses.update(_reap())
        if not _group_alive(pgid):
            return statuses
        time.sleep(POLL_SECONDS)
    _signal_group(pgid, signal.SIGKILL)
    while _group_alive(pgid):
        statuses.update(_reap())
        time.sleep(POLL_SECONDS)
    return statuses


def run(cmd: Sequence[str], *, grace: float = GRACE_SECONDS, env: dict[str, str] | None = None) -> int:
    """Run `cmd` (the server) in its own process group until it exits or a stop signal arrives; then stop
    the whole group (:func:`stop_group`). Returns the server's exit code, or 128 + the signal number.
    env: the server's environment (default: this process's)."""
    _become_subreaper()
    received: list[int] = []

    def on_signal(signum: int, _frame: object) -> None:
        received.append(signum)

    previous = {sig: signal.signal(sig, on_signal) for sig in STOP_SIGNALS}
    try:
        proc = subprocess.Popen(list(cmd), start_new_session=True, env=env)
        status: int | None = None
        while status is None and not received:
            reaped = _reap()
            status = reaped.get(proc.pid)
            if status is None:
                time.sleep(POLL_SECONDS)
        statuses = stop_group(proc.pid, grace)  # also after a normal exit: no worker may outlive Panel
        if status is None:
            status = statuses.get(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here, not by Popen
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if received:
        return 128 + received[0]
    return proc.returncode if proc.returncode >= 0 else 128 - proc.returncode
