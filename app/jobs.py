"""Background jobs: every long computation of the app runs through here (not physics, not layout).

Two pieces, one for each side of the thread boundary:

- :class:`Job` -- one computation, ``work(job)``, on its own daemon thread. The work reports its progress per
  phase (:meth:`Job.set_totals`, :meth:`Job.advance`, :meth:`Job.set_done`), may publish a preview of its result
  (:meth:`Job.publish`), and calls :meth:`Job.check` between
  chunks: once the job is cancelled, ``check`` raises :class:`Cancelled`, so a stale computation stops after its
  current chunk. An exception ends the job "failed" with its message (logged with its traceback; a :class:`Failed`
  raised by the work is a failure it explains itself: its message is shown as it is, without a traceback). A job
  knows nothing of sessions: several may follow one job (the default atlas is computed once per process for all).
- :class:`Follower` -- shows one job at a time in one session by calling ``show(job, state)``, always with the
  session's document locked on its event loop, never from the worker. The worker only says that something
  changed; the follower then schedules one update on the session's next tick (``Document.add_next_tick_callback``,
  the one Document method Bokeh allows from another thread), at most every :data:`UPDATE_INTERVAL` seconds, and
  that update reads the job's latest state: updates cannot arrive out of order (a progress bar's maximum after its
  values) and a burst of progress is one update. A job the follower has left (new inputs) is never shown again, so
  its result cannot replace the current one.

Served (``panel serve``, one or several processes) that is all. In a Jupyter notebook (no server session, but the
kernel's asyncio event loop runs in the thread that follows the job: :func:`kernel_loop`) the updates are scheduled
the same way on that loop (``call_soon_threadsafe``): they run between cells, and Panel sends what they change to
the notebook's output through its comm, as it does for a widget's change. Without either (tests, scripts, a scene
built headless) nothing is scheduled: :meth:`Follower.update` shows the job's current state, and
:meth:`Follower.wait` waits for its end and shows it.

A job's work may hand its heaviest pieces to a worker process (:meth:`Job.call`, served only): the server's own
process then keeps its share of the GIL for the sessions' events (the Spectrum's sliding job held it part of the
time, and ten sessions dragging sliders at once saturated the one process; benchmarks/results.md "Live while
dragging").

Why threads and not Panel's async callbacks (``pn.state.execute`` of a coroutine awaiting ``asyncio.to_thread``):
an async callback runs without the document lock (the Atlas tab updates Bokeh models directly), needs a running
event loop (tests build scenes without one), and belongs to one session, while the default atlas is shared by every
session of a process.
"""

from __future__ import annotations

import asyncio
import atexit
import concurrent.futures
import logging
import multiprocessing
import signal
import sys
import threading
import time
from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import panel as pn
from panel.io.state import set_curdoc

log = logging.getLogger(__name__)

#: the shortest time (s) between two updates of a session by the same follower (progress of a fast computation
#: would otherwise keep the session's event loop and websocket busy)
UPDATE_INTERVAL = 0.15

RUNNING, DONE, FAILED, CANCELLED = "running", "done", "failed", "cancelled"

#: worker processes beside a served process for :meth:`Job.call`, per pool (the machine this was measured on has 2
#: cores: the server's process on one, the workers on the other)
PROCESS_WORKERS = 1
#: how often (s) a job waiting for its worker process looks whether it has been cancelled
CALL_POLL = 0.05
#: the pools: work a user waits for at a release (the Spectrum's sliding markers: ~0.5 s), and long background work
#: (a map's exact sliding boundary: seconds a call) that must not queue in front of it
INTERACTIVE, BACKGROUND = "interactive", "background"

_pools: dict[str, concurrent.futures.ProcessPoolExecutor] = {}
_pool_lock = threading.Lock()


def process_pool(kind: str = INTERACTIVE) -> concurrent.futures.ProcessPoolExecutor:
    """The process's pool `kind` (:data:`INTERACTIVE`, :data:`BACKGROUND`) of :data:`PROCESS_WORKERS` spawned
    workers, started at its first use (spawned, not forked: the server has threads; a worker imports only what the
    calls need, e.g. app.sliding_work and model). It lives as long as the server's process; ``asymslide serve``
    stops its whole process group, workers included."""
    if kind not in (INTERACTIVE, BACKGROUND):
        raise ValueError(f"kind must be {INTERACTIVE!r} or {BACKGROUND!r}, not {kind!r}")
    with _pool_lock:
        if kind not in _pools:
            # a stop signal goes to the server's whole process group (asymslide serve, Ctrl-C): the workers ignore
            # SIGINT and end when the server shuts the pool down (at its exit: :func:`shutdown_pools`)
            _pools[kind] = concurrent.futures.ProcessPoolExecutor(PROCESS_WORKERS,
                                                                  mp_context=multiprocessing.get_context("spawn"),
                                                                  initializer=signal.signal,
                                                                  initargs=(signal.SIGINT, signal.SIG_IGN))
        return _pools[kind]


@atexit.register
def shutdown_pools(*, terminate: bool = False) -> None:
    """Stop the worker processes and drop the pools while the interpreter is whole (a pool collected during the
    interpreter's teardown logs "Exception ignored in ... weakref_cb" from concurrent.futures). `terminate`: a call
    still running ends now (tests), rather than being waited for."""
    with _pool_lock:
        pools = list(_pools.values())
        _pools.clear()
    for pool in pools:
        if terminate:
            for process in list((pool._processes or {}).values()):
                process.terminate()
        pool.shutdown(wait=True, cancel_futures=True)


def _drop_pool(pool: concurrent.futures.ProcessPoolExecutor) -> None:
    """Forget a broken pool (a worker died): the next call starts a new one."""
    with _pool_lock:
        for kind, p in list(_pools.items()):
            if p is pool:
                del _pools[kind]
    pool.shutdown(wait=False, cancel_futures=True)


class Cancelled(Exception):  # noqa: N818 (not an error: how a cancelled job's work stops)
    """Raised by :meth:`Job.check` in the worker once the job is cancelled: the work stops there."""


class Failed(Exception):  # noqa: N818 (the job's outcome, as Cancelled)
    """Raised by a job's work for a failure it explains itself: the message is shown as it is (no traceback)."""


@dataclass(frozen=True)
class JobState:
    """A consistent snapshot of a job: its status, its progress per phase, and its result or error."""

    status: str = RUNNING
    done: Mapping[str, int] = field(default_factory=dict)
    totals: Mapping[str, int] = field(default_factory=dict)
    result: Any = None
    error: str = ""
    #: the latest partial result the work published (:meth:`Job.publish`: a preview shown before the end)
    partial: Any = None

    @property
    def finished(self) -> bool:
        return self.status != RUNNING


class Job:
    """``work(job)`` on a daemon thread named `name`, for the inputs `key`; `totals` are the phases' sizes if
    they are known before the work starts (they are shown at once). :meth:`start` starts it."""

    def __init__(self, work: Callable[[Job], Any], *, name: str, key: Hashable = None,
                 totals: Mapping[str, int] | None = None) -> None:
        self.key = key
        self.name = name
        self._work = work
        self._lock = threading.Lock()
        self._cancelled = threading.Event()
        self._ended = threading.Event()
        self._state = JobState(totals=MappingProxyType(dict(totals or {})),
                               done=MappingProxyType(dict.fromkeys(totals or {}, 0)))
        self._listeners: list[Callable[[], None]] = []
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def __repr__(self) -> str:
        return f"<Job {self.name} {self.key!r}: {self._state.status}>"

    def start(self) -> Job:
        self._thread.start()
        return self

    # -- any thread ---------------------------------------------------------------------------

    def state(self) -> JobState:
        """The job's state now (a snapshot: progress, status and result are read together)."""
        with self._lock:
            return self._state

    @property
    def cancelled(self) -> bool:
        return self._cancelled.is_set()

    def cancel(self) -> None:
        """Ask the work to stop at its next :meth:`check` (after its current chunk)."""
        self._cancelled.set()

    def wait(self, timeout: float | None = 60.0) -> JobState:
        """Block until the job has ended (TimeoutError after `timeout` seconds; None: no limit); its final state."""
        if not self._ended.wait(timeout):
            raise TimeoutError(f"{self.name} did not finish within {timeout} s")
        return self.state()

    def subscribe(self, listener: Callable[[], None]) -> None:
        """Call `listener()` after every change of the state, from the thread that changed it (the worker): it must
        be quick and must not touch a document (:class:`Follower` schedules an update of its session)."""
        with self._lock:
            if listener not in self._listeners:
                self._listeners.append(listener)

    def unsubscribe(self, listener: Callable[[], None]) -> None:
        with self._lock:
            if listener in self._listeners:
                self._listeners.remove(listener)

    # -- the worker ---------------------------------------------------------------------------

    def check(self) -> None:
        """Raise :class:`Cancelled` if the job has been cancelled (call it between chunks)."""
        if self._cancelled.is_set():
            raise Cancelled(self.name)

    def call(self, fn: Callable[..., Any], *args: Any, in_process: bool = True, pool: str = INTERACTIVE) -> Any:
        """``fn(*args)`` in a worker process of :func:`process_pool` `pool` (`fn` and its arguments must pickle), or
        here when not `in_process`. Cancelling the job withdraws a call not started yet and raises
        :class:`Cancelled`; a call already running finishes in its process and its result is dropped. A worker that
        died fails the job (the next call starts a new pool)."""
        if not in_process:
            self.check()
            return fn(*args)
        executor = process_pool(pool)
        future = executor.submit(fn, *args)
        while True:
            try:
                return future.result(timeout=CALL_POLL)
            except concurrent.futures.TimeoutError:
                if self._cancelled.is_set():
                    future.cancel()
                    raise Cancelled(self.name) from None
            except concurrent.futures.process.BrokenProcessPool as exc:
                _drop_pool(executor)
                raise Failed(f"the worker process stopped ({exc})") from exc

    def set_totals(self, totals: Mapping[str, int]) -> None:
        """The size of each phase (grid points, chunks, ...), in the order the phases run."""
        with self._lock:
            done = {k: min(self._state.done.get(k, 0), n) for k, n in totals.items()}
            self._state = replace(self._state, totals=MappingProxyType(dict(totals)), done=MappingProxyType(done))
        self._notify()

    def advance(self, phase: str, n: int = 1) -> None:
        """`n` more units of `phase` done."""
        with self._lock:
            done = {**self._state.done, phase: self._state.done.get(phase, 0) + n}
            self._state = replace(self._state, done=MappingProxyType(done))
        self._notify()

    def set_done(self, done: Mapping[str, int]) -> None:
        """The units done of each phase named in `done` (e.g. read back from a store another process writes)."""
        with self._lock:
            self._state = replace(self._state, done=MappingProxyType({**self._state.done, **done}))
        self._notify()

    def publish(self, partial: Any) -> None:
        """A partial result (a coarse preview of the result): followers show it before the job ends."""
        with self._lock:
            self._state = replace(self._state, partial=partial)
        self._notify()

    def _end(self, **outcome: Any) -> None:
        with self._lock:
            self._state = replace(self._state, **outcome)
        self._ended.set()
        self._notify()

    def _notify(self) -> None:
        with self._lock:
            listeners = list(self._listeners)
        for listener in listeners:
            listener()

    def _run(self) -> None:
        try:
            result = self._work(self)
        except Cancelled:
            self._end(status=CANCELLED)
        except Failed as exc:
            log.warning("%s failed: %s", self.name, exc)
            self._end(status=FAILED, error=str(exc))
        except Exception as exc:  # shown in the page; the session keeps working
            log.exception("%s failed for %r", self.name, self.key)
            self._end(status=FAILED, error=f"{type(exc).__name__}: {exc}")
        else:
            self._end(status=DONE, result=result)


def served_document():
    """The current session's Bokeh document, or None without a server session (tests, scripts)."""
    doc = pn.state.curdoc
    return doc if doc is not None and doc.session_context is not None else None


def in_kernel() -> bool:
    """Whether this process is a Jupyter kernel (IPython's shell with a kernel): only there is a running asyncio loop
    the notebook's (a script's own loop, or Playwright's sync API in the tests, is not)."""
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return shell is not None and getattr(shell, "kernel", None) is not None


def kernel_loop() -> asyncio.AbstractEventLoop | None:
    """The asyncio event loop running in this thread outside a server session in a Jupyter kernel (its cells run as
    tasks on it), or None (a server session, a script, a test)."""
    if served_document() is not None or not in_kernel():
        return None
    try:
        return asyncio.get_running_loop()
    except RuntimeError:  # no loop runs in this thread
        return None


class Follower:
    """Shows the job it follows in one session: ``show(job, state)`` on the session's event loop after the job
    changed (see the module's docstring), and once more at its end; never again once it follows another job.

    Create it where the session is current (a scene's constructor or a render): the session is taken from
    :func:`served_document` when a job is followed (in a notebook: the kernel's event loop, :func:`kernel_loop`).
    When the session ends, a job started by :meth:`run` is cancelled.
    """

    def __init__(self, show: Callable[[Job, JobState], None], *, interval: float = UPDATE_INTERVAL) -> None:
        self._show = show
        self.interval = interval
        self._lock = threading.Lock()
        self._job: Job | None = None
        self._owned = False
        self._ended_shown: Job | None = None  # the job whose end has been shown
        self._doc = None
        self._loop: asyncio.AbstractEventLoop | None = None  # a notebook's kernel loop (no served document)
        self._docs: set[int] = set()  # documents whose end is watched
        self._pending = False
        self._last = 0.0

    @property
    def job(self) -> Job | None:
        """The job followed (None: none, or it was cancelled)."""
        return self._job

    def run(self, work: Callable[[Job], Any], *, name: str, key: Hashable = None,
            totals: Mapping[str, int] | None = None) -> Job:
        """Start ``work`` as a new job of this session and follow it; the job followed before is cancelled (it
        stops after its current chunk and is never shown)."""
        job = Job(work, name=name, key=key, totals=totals)
        self.follow(job, owned=True)
        return job.start()

    def follow(self, job: Job, *, owned: bool = False) -> None:
        """Show `job` from now on. `owned`: the session's own job, cancelled with :meth:`cancel`, when another job
        is followed, and when the session ends (a job shared by sessions is not)."""
        self._leave()
        doc = served_document()
        loop = None if doc is not None else kernel_loop()
        with self._lock:
            self._job, self._owned, self._doc, self._loop = job, owned, doc, loop
        if doc is not None and id(doc) not in self._docs:
            self._docs.add(id(doc))
            doc.on_session_destroyed(lambda _context: self.cancel())
        job.subscribe(self._changed)
        if doc is None:  # headless or in a notebook: its state now (a notebook's next ones on the kernel's loop)
            self.update()
        else:
            self._changed()  # the first update on the next tick: a tab being built is in the document by then

    def cancel(self) -> None:
        """Stop following the current job (its state is never shown again) and cancel it if it is the session's."""
        self._leave()

    def _leave(self) -> None:
        with self._lock:
            job, owned, self._job = self._job, self._owned, None
        if job is not None:
            job.unsubscribe(self._changed)
            if owned:
                job.cancel()

    def wait(self, timeout: float | None = 60.0) -> JobState | None:
        """Block until the followed job has ended; without a server session also show its end (tests, scripts).
        None if no job is followed."""
        job = self._job
        if job is None:
            return None
        state = job.wait(timeout)
        if self._doc is None:
            self.update()
        return state

    def update(self) -> None:
        """Show the followed job's state now (served: called on the session's event loop; in a notebook on the
        kernel's; headless: by the caller). A job's end is shown once."""
        job = self._job
        if job is None or self._ended_shown is job:
            return
        state = job.state()
        if state.finished:
            self._ended_shown = job
            job.unsubscribe(self._changed)
        self._show(job, state)

    # -- served (or in a notebook): carry the worker's changes to the session -----------------------

    def _changed(self) -> None:
        """A change of the followed job (any thread): schedule one update of the session unless one is pending."""
        doc, loop = self._doc, self._loop
        if loop is None and (doc is None or doc.session_context is None):  # headless, or the session has ended
            return
        with self._lock:
            if self._pending:
                return
            self._pending = True
        if loop is not None:  # a notebook: on the kernel's event loop
            self._call_on_loop(loop, self._tick)
        else:
            self._schedule(doc)

    def _call_on_loop(self, loop: asyncio.AbstractEventLoop, callback: Callable[[], None],
                      delay: float = 0.0) -> None:
        """Run `callback` on a notebook kernel's event loop (from any thread), after `delay` seconds; dropped when the
        loop has been closed (the kernel is shutting down)."""
        def call() -> None:
            if delay > 0:
                loop.call_later(delay, callback)
            else:
                callback()

        try:
            loop.call_soon_threadsafe(call)
        except RuntimeError:  # the loop is closed
            log.debug("%s: the kernel's event loop is closed; its update is dropped",
                      self._job.name if self._job else "job")

    def _schedule(self, doc) -> None:
        """Ask the session's event loop for a :meth:`_tick`. Bokeh destroys an ended session's document (its callback
        registry is deleted, the session context cleared) before it runs the session-destroyed hooks that cancel the
        job, and the worker may notify in between: the update of a destroyed document is dropped, not raised in the
        worker (which would end the job as failed with an AttributeError in the server log)."""
        try:
            doc.add_next_tick_callback(self._tick)
        except AttributeError:
            if doc.session_context is not None:  # a live document: a real error
                raise
            log.debug("%s: the session ended; its update is dropped", self._job.name if self._job else "job")

    def _tick(self) -> None:
        """On the session's event loop (in a notebook the kernel's): update, or wait until :attr:`interval` has passed
        since the last update."""
        doc, loop = self._doc, self._loop
        early = self._last + self.interval - time.monotonic()
        if early > 0 and loop is not None:
            self._call_on_loop(loop, self._tick, early)
            return
        if early > 0 and doc is not None:
            doc.add_timeout_callback(self._tick, int(early * 1000) + 1)
            return
        with self._lock:
            self._pending = False
        self._last = time.monotonic()
        if doc is None:  # a notebook: no session document to make current
            self.update()
            return
        with set_curdoc(doc):
            self.update()
