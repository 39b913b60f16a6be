"""The load test of benchmarks/load_test.py at reduced size: concurrent sessions against a served app.

``panel serve app/main.py`` runs as a subprocess, as the Docker image runs it (two processes,
``--reuse-sessions``); a few Bokeh-protocol clients request the page, open its session, release the
Spectrum sliders, close and are replaced, over several rounds. This asserts what must hold under
concurrency: no error anywhere (client, server log), every update arrives and plots the model's
curve for that session's parameters (no cross-talk between sessions or processes), every closed
session is destroyed by the server (only the page cache of ``--reuse-sessions`` stays, one per
process), and the server's memory does not grow from round to round. Latencies
are printed, not asserted (timings never gate tests; `make bench` reports them), except a sanity
bound far above any healthy figure.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import pytest

from benchmarks.load_test import report, run_load

pytestmark = pytest.mark.slow


def test_concurrent_sessions_error_free_and_memory_bounded() -> None:
    # on a worker thread: it runs its own asyncio loop, and the main thread may hold Playwright's
    with ThreadPoolExecutor(max_workers=1) as pool:
        r = pool.submit(run_load, sessions=4, duration=15.0, rounds=3, think=(0.5, 1.5), arrival_gap=0.25, timeout=60.0,
                        check_ms=500, lifetime_ms=500, mem_tolerance=15.0, num_procs=2).result()
    print(report(r))
    assert r.errors == [] and r.server_errors == [], report(r)
    assert r.updates >= 4 and r.verified == r.updates  # real work, every plotted curve checked against the model
    assert r.opened >= 3 * 4 and r.opened == r.closed
    assert r.sessions_cleaned, f"the server still holds sessions after clean-up: {r.live_after_round}"
    assert r.memory_bounded, report(r)
    assert r.latency["max"] < 60.0  # sanity bound only (a lost update is an error above)
