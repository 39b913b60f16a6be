"""The executor: runs tasks and hands each result, as it finishes, to one callback in one thread.

Without a client: Dask's threaded scheduler on this machine (the compiled kernels release the GIL;
``benchmarks/bench_sweep.py`` compares it with a ``distributed.LocalCluster``), and for the tasks whose model calls
hold the GIL (the sliding verdict) spawned processes. With ``client=`` a ``distributed.Client`` of any cluster runs
the same tasks (``asymslide sweep --scheduler tcp://HOST:PORT``). The executor knows nothing of plans or stores: a
task is anything with a ``kind``, an ``index`` and ``holds_gil``, run by the function it is given.
"""

from __future__ import annotations

import contextlib
import os
import queue
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import numpy as np

#: seconds a scheduler address may take to answer (the command then fails within ~10 s of its start)
CONNECT_TIMEOUT = 8
Progress = Callable[[str, int], None]


class _ResultQueue:
    """Hands finished chunks to one thread that calls `on_result` on them in order of completion, so that a worker
    thread starts its next chunk at once instead of waiting while the last one is written (Dask's threaded
    scheduler runs its callbacks before it gives a worker new work). An error of `on_result` stops the sweep.

    At most `backlog` finished chunks wait: beyond that :meth:`put` blocks, and with it the scheduler's next task,
    so that the workers never run far ahead of a slow writer (many small chunks, a slow disk). The backlog is what a
    Ctrl-C still writes before the sweep stops, and what memory holds."""

    def __init__(self, on_result: Callable[[Any, dict[str, np.ndarray]], None], backlog: int) -> None:
        self._on_result = on_result
        self._queue: queue.Queue = queue.Queue(maxsize=backlog)
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="asymslide-writer", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while (item := self._queue.get()) is not None:
            if self._error is None:
                try:
                    self._on_result(*item)
                except BaseException as exc:  # noqa: BLE001 (handed to the sweep's thread by put/close)
                    self._error = exc

    def put(self, task: Any, result: dict[str, np.ndarray]) -> None:
        if self._error is not None:
            raise self._error
        self._queue.put((task, result))

    def close(self) -> None:
        """Write what is queued (a Ctrl-C keeps every finished chunk), then re-raise a writing error."""
        self._queue.put(None)
        self._thread.join()
        if self._error is not None:
            raise self._error


#: chunks handed to Dask's threaded scheduler at once: it keeps their results until the batch is done (memory),
#: and a batch ends with one worker waiting for the other's last chunk (~half a chunk's time lost per batch)
THREADED_BATCH = 256


def _spawnable() -> bool:
    """Whether spawned processes can start here: they import the main module by its path, which a script read from
    stdin has not (``python -c``, ``-m`` and notebooks have or need none)."""
    import sys

    main = getattr(sys.modules.get("__main__"), "__file__", None)
    return main is None or os.path.exists(main)


#: the process pools of the sweep running (workers -> pool): started when its first tasks that hold the GIL come,
#: shut down when the sweep ends (:func:`sweep_processes`)
_POOLS: dict[int, Any] = {}
#: open :func:`sweep_processes` blocks (a sweep in a sweep keeps the outer one's pools)
_SCOPES: list[None] = []


@contextlib.contextmanager
def sweep_processes() -> Iterator[None]:
    """Keep the process pools started inside (by ``_process_pool``) until the block ends, then shut them down
    (a pool kept for the life of the process hung pytest's exit)."""
    outer = set(_POOLS)
    _SCOPES.append(None)
    try:
        yield
    finally:
        _SCOPES.pop()
        for key in [k for k in _POOLS if k not in outer]:
            _POOLS.pop(key).shutdown(wait=True, cancel_futures=True)


def _process_pool(workers: int):
    """The process pool for tasks that hold the GIL (:attr:`Task.holds_gil`): `workers` spawned processes, each
    importing the model once (the compiled kernels come from their on-disk cache), kept while the sweep runs."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    if workers not in _POOLS:
        _POOLS[workers] = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
    return _POOLS[workers]


def _execute_in_processes(todo: Sequence[Any], on_result: Callable[[Any, dict[str, np.ndarray]], None],
                          workers: int, run: Callable[[Any], dict[str, np.ndarray]]) -> None:
    """Run `todo` in ``_process_pool``, calling `on_result` in this thread as each task finishes; the tasks
    not started are cancelled if this is interrupted (a task running finishes in its process)."""
    with contextlib.ExitStack() as stack:
        if not _SCOPES:  # outside a sweep (a direct call): a pool for this call only
            stack.enter_context(sweep_processes())
        pool = _process_pool(workers)
        _collect(pool, todo, on_result, run)


def _collect(pool, todo: Sequence[Any], on_result: Callable[[Any, dict[str, np.ndarray]], None],
             run: Callable[[Any], dict[str, np.ndarray]]) -> None:
    """Submit `todo` to `pool` and hand each result to `on_result` as it comes; cancel what has not started if
    interrupted."""
    from concurrent.futures import as_completed

    futures = {pool.submit(run, t): t for t in todo}
    try:
        for future in as_completed(futures):
            on_result(futures[future], future.result())
    finally:
        for future in futures:
            future.cancel()


def execute(todo: Sequence[Any], on_result: Callable[[Any, dict[str, np.ndarray]], None],
            run: Callable[[Any], dict[str, np.ndarray]], client=None, workers: int | None = None) -> None:
    """Run `todo` (tasks with a `kind` and an `index`, unique together), calling `on_result` in one thread as each
    task finishes (in any order); `run`: the function of a task (:func:`asymslide.atlas.tasks.run_task`,
    :func:`~asymslide.atlas.tasks.run_points`). Without a client: Dask's
    threaded scheduler, and for the tasks that hold the GIL (the sliding verdict: threads would run them one at a
    time; docs/design-notes.md) `workers` processes."""
    if not todo:
        return
    if client is not None:
        from distributed import as_completed

        futures = client.map(run, todo, pure=False)
        by_key = {f.key: t for f, t in zip(futures, todo, strict=True)}
        try:
            for future, result in as_completed(futures, with_results=True):
                on_result(by_key[future.key], result)
                future.release()
        finally:
            client.cancel(futures)
        return
    n_workers = workers or os.cpu_count() or 1
    gil = [t for t in todo if getattr(t, "holds_gil", False)]
    if n_workers > 1 and len(gil) > 1 and _spawnable():  # threads would run them one at a time
        todo = [t for t in todo if not getattr(t, "holds_gil", False)]
        _execute_threaded(todo, on_result, n_workers, run)
        _execute_in_processes(gil, on_result, n_workers, run)
        return
    _execute_threaded(todo, on_result, n_workers, run)


def _execute_threaded(todo: Sequence[Any], on_result: Callable[[Any, dict[str, np.ndarray]], None], n_workers: int,
                      run: Callable[[Any], dict[str, np.ndarray]]) -> None:
    """Run `todo` on Dask's threaded scheduler (`n_workers` threads; the compiled kernels release the GIL), in
    batches of :data:`THREADED_BATCH`, handing each result to `on_result` in a writer thread."""
    if not todo:
        return
    import dask.threaded
    from dask.callbacks import Callback

    results: dict[str, Any] = {}
    writer = _ResultQueue(on_result, backlog=2 * n_workers)

    class _Handover(Callback):
        def _posttask(self, key, result, dsk, state, worker_id):  # noqa: ARG002 (dask's signature)
            writer.put(results[key], result)

    try:
        for start in range(0, len(todo), THREADED_BATCH):
            part = todo[start:start + THREADED_BATCH]
            graph = {}
            for t in part:
                key = f"{t.kind}-{t.index}"
                results[key] = t
                graph[key] = (run, t)
            with _Handover():
                dask.threaded.get(graph, list(graph), num_workers=n_workers)
            for key in graph:
                results.pop(key, None)
    finally:
        writer.close()
