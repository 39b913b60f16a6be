"""Finding processes on Linux through /proc: descendants, and processes carrying a marker in their environment (how
the test suite and the benchmarks check that nothing they started outlives them). `make bench` ends with
``python -m tests.support.processes $ASYMSLIDE_RUN_ID``."""

from __future__ import annotations

import os
from pathlib import Path

from asymslide.serve import children  # the launcher's own (it waits for Panel's workers)

#: environment variable whose value marks the processes started by one test session or benchmark run
MARKER = "ASYMSLIDE_RUN_ID"


def descendants(pid: int) -> list[int]:
    """Children, grandchildren, ... of `pid`, parents before their children."""
    out: list[int] = []
    todo = children(pid)
    while todo:
        p = todo.pop(0)
        out.append(p)
        todo.extend(children(p))
    return out


def alive(pid: int) -> bool:
    """True if `pid` exists and is not a zombie (an exited process not yet reaped by its parent)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as fh:
            state = fh.read().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def command_line(pid: int) -> str:
    try:
        raw = Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return "?"
    return raw.replace(b"\0", b" ").decode("utf-8", "replace").strip()


def marked(value: str, exclude: tuple[int, ...] = ()) -> list[int]:
    """Live processes whose environment has ``MARKER=value`` (inherited from whoever set it), except `exclude`."""
    needle = f"{MARKER}={value}".encode()
    found = []
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit() or int(entry.name) in exclude:
            continue
        try:
            env = Path(entry.path, "environ").read_bytes()
        except OSError:
            continue
        if needle in env.split(b"\0") and alive(int(entry.name)):
            found.append(int(entry.name))
    return found


def stop_marked(value: str, grace: float, exclude: tuple[int, ...] = ()) -> list[str]:
    """Wait up to `grace` s for the processes marked with `value` to exit; SIGKILL the rest and return their
    command lines (empty: none was left)."""
    import signal
    import time

    deadline = time.monotonic() + grace
    while (left := marked(value, exclude)) and time.monotonic() < deadline:
        time.sleep(0.2)
    lines = [f"{pid}: {command_line(pid)[:200]}" for pid in left]
    for pid in left:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    return lines


def main(argv: list[str] | None = None) -> int:
    """``python -m tests.support.processes RUN_ID [GRACE]``: exit 1 (listing and killing them) if processes marked
    with RUN_ID are still running after GRACE seconds (default 20). `make bench` ends with it."""
    import sys

    args = sys.argv[1:] if argv is None else argv
    if not args:
        print(main.__doc__)
        return 2
    lines = stop_marked(args[0], float(args[1]) if len(args) > 1 else 20.0, exclude=(os.getpid(), os.getppid()))
    for line in lines:
        print(f"left running (killed now): {line}")
    return 1 if lines else 0


if __name__ == "__main__":
    raise SystemExit(main())
