"""Run by ``panel serve --setup`` in every server process before it serves a page (asymslide/serve.py passes it):
the model's kernels are loaded from numba's cache -- or compiled, without one -- so that no user's first page waits
for them. With ``--num-procs N`` Panel runs it in each worker on its event loop's first turn, before the worker
handles a request.

It then starts the process's worker for the sliding computation (app.jobs.process_pool) and has it load the same
kernels: spawning it and importing the model takes seconds, which the first page's sliding markers would otherwise
wait for."""

from __future__ import annotations

import os
import sys

from asymslide.app import jobs
from asymslide.warmup import compile_kernels


def _log(line: str) -> None:
    """On stderr, as the server's own log lines (in one stream they keep their order), written in one call: the
    workers of --num-procs share the stream, and print() writes the line and its end separately."""
    sys.stderr.write(f"{line} (server process {os.getpid()})\n")
    sys.stderr.flush()


compile_kernels(log=_log)
jobs.process_pool().submit(compile_kernels)  # the worker warms while the server starts serving
