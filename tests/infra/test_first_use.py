"""First use: the kernels are compiled, or loaded from numba's cache, before the server accepts a page, and the log says
so; every server process has them before it serves (``panel serve --setup``).

The times (first page after start <= 10 s with the cache, All branches first open <= 3 s) are measured by
``make bench`` (benchmarks/first_page.py), never asserted here.
"""

from __future__ import annotations

import io
import runpy
import time
import urllib.request
from unittest import mock

import pytest

from asymslide import serve, warmup
from tests.support.served_app import ServedApp


def test_every_server_process_loads_the_kernels_before_it_serves() -> None:
    cmd = serve.panel_command(port=5006, address="127.0.0.1", origins=["localhost:5006"], num_procs=2)
    assert cmd[cmd.index("--setup") + 1] == str(serve.setup_script()) and serve.setup_script().is_file()
    with mock.patch.object(warmup, "compile_kernels", wraps=warmup.compile_kernels) as spy, \
            mock.patch("sys.stderr", new_callable=io.StringIO) as stderr:
        runpy.run_path(str(serve.setup_script()))  # what panel serve --setup does in each process
    assert spy.call_count == 1
    lines = stderr.getvalue().splitlines()
    assert "compiling kernels" in lines[0] and "kernels ready" in lines[1] and "server process" in lines[1]


@pytest.mark.slow
@pytest.mark.parametrize("num_procs", [1, 2])
def test_the_log_says_compiling_kernels_then_ready_before_the_server_accepts_a_page(num_procs: int) -> None:
    """``asymslide serve`` as ``make serve`` runs it: the kernels' lines come before Bokeh's "app running" line; with
    several processes the launcher compiles them once first, then each worker loads them."""
    with ServedApp(num_procs=num_procs) as server:
        deadline = time.monotonic() + 300
        while (sum("kernels ready" in line and "server process" in line for line in server.log) < num_procs
               and time.monotonic() < deadline):
            time.sleep(0.2)
        # a shared link to the root keeps its query: / is the app itself, not a redirect to /main that drops it
        root = server.url.rsplit("/", 1)[0] + "/?tab=atlas&gamma=5"
        with urllib.request.urlopen(root, timeout=120) as answer:
            assert answer.status == 200 and answer.url == root
        log = list(server.log)
        assert server.error_lines == []
    running = next(i for i, line in enumerate(log) if "Bokeh app running" in line)
    compiling = [i for i, line in enumerate(log) if "compiling kernels" in line]
    ready = [i for i, line in enumerate(log) if "kernels ready" in line]
    assert compiling and ready and compiling[0] < ready[0] < running
    if num_procs == 1:  # the server process itself, before it starts serving
        assert "server process" in log[ready[0]]
    else:  # the launcher, then every worker (on its event loop's first turn, before it handles a request)
        assert "server process" not in log[ready[0]]
        workers = {line.rsplit("server process ", 1)[1] for line in log if "kernels ready" in line
                   and "server process" in line}
        assert len(workers) == num_procs, log
