"""app/jobs.py, the one background-job helper of the app: progress, cancellation on new inputs, errors shown, and a
session shown only the job it follows (headless here: the served path is exercised by the browser tests)."""

from __future__ import annotations

import threading
import weakref

import pytest

from asymslide.app import jobs


def _held(release: threading.Event, chunks: int = 3):
    """Work of `chunks` chunks that waits for `release` after the first."""

    def work(job: jobs.Job) -> str:
        job.set_totals({"chunks": chunks})
        for i in range(chunks):
            job.check()
            if i == 1:
                assert release.wait(30)
            job.advance("chunks")
        return "result"

    return work


def test_a_job_reports_progress_and_its_result() -> None:
    release = threading.Event()
    job = jobs.Job(_held(release), name="test", key=1, totals={"chunks": 3}).start()
    assert job.state().totals == {"chunks": 3}  # known at once
    release.set()
    state = job.wait(30)
    assert (state.status, state.done, state.result, state.error) == (jobs.DONE, {"chunks": 3}, "result", "")


def test_a_cancelled_job_stops_after_its_current_chunk() -> None:
    release = threading.Event()
    job = jobs.Job(_held(release), name="test").start()
    job.cancel()
    release.set()
    state = job.wait(30)
    assert state.status == jobs.CANCELLED and state.result is None and state.done["chunks"] <= 2


def test_errors_end_the_job_with_their_message() -> None:
    def broken(_job: jobs.Job) -> None:
        raise ValueError("beta out of range (test)")

    def explained(_job: jobs.Job) -> None:
        raise jobs.Failed("the folder is read-only (test)")

    assert jobs.Job(broken, name="t").start().wait(30).error == "ValueError: beta out of range (test)"
    state = jobs.Job(explained, name="t").start().wait(30)
    assert (state.status, state.error) == (jobs.FAILED, "the folder is read-only (test)")


def test_a_follower_shows_only_the_job_it_follows_and_cancels_the_one_it_left() -> None:
    shown: list[tuple[object, str]] = []
    follower = jobs.Follower(lambda job, state: shown.append((job.key, state.status)))
    first_release, second_release = threading.Event(), threading.Event()
    first = follower.run(_held(first_release), name="t", key="first", totals={"chunks": 3})
    assert shown == [("first", jobs.RUNNING)]  # headless: shown at once
    second = follower.run(_held(second_release), name="t", key="second", totals={"chunks": 3})
    assert first.cancelled and follower.job is second
    first_release.set()
    assert first.wait(30).status == jobs.CANCELLED
    second_release.set()
    assert follower.wait(30).status == jobs.DONE
    assert shown == [("first", jobs.RUNNING), ("second", jobs.RUNNING), ("second", jobs.DONE)]
    follower.update()  # an end is shown once
    assert len(shown) == 3


def test_a_shared_job_is_not_cancelled_by_a_follower_that_leaves() -> None:
    release = threading.Event()
    shared = jobs.Job(_held(release), name="shared").start()
    one, two = jobs.Follower(lambda *_: None), jobs.Follower(lambda *_: None)
    one.follow(shared)
    two.follow(shared)
    one.cancel()
    assert not shared.cancelled and one.job is None and two.job is shared
    release.set()
    assert two.wait(30).status == jobs.DONE


def test_wait_times_out() -> None:
    release = threading.Event()
    job = jobs.Job(_held(release), name="slow").start()
    with pytest.raises(TimeoutError):
        job.wait(0.05)
    release.set()
    job.wait(30)


def test_in_a_notebook_the_follower_shows_the_job_on_the_kernels_event_loop(monkeypatch: pytest.MonkeyPatch) -> None:
    """Without a server session but with an asyncio loop running where the job is followed (a Jupyter kernel's: cells
    run on it), every change is shown on that loop, in order and at the end, never from the worker's thread."""
    import asyncio

    monkeypatch.setattr(jobs, "in_kernel", lambda: True)  # tests/app/test_notebook_scenes.py: in a real kernel

    shown: list[tuple[str, int, bool]] = []

    async def cell() -> None:
        loop_thread = threading.get_ident()
        follower = jobs.Follower(lambda _job, state: shown.append(
            (state.status, state.done.get("chunks", 0), threading.get_ident() == loop_thread)), interval=0.0)
        release = threading.Event()
        job = follower.run(_held(release), name="t", key="k", totals={"chunks": 3})
        release.set()
        while not (shown and shown[-1][0] == jobs.DONE):  # the cell awaits: the loop runs the updates
            await asyncio.sleep(0.01)
        assert job.state().finished

    # the kernel's loop in a thread of its own: in the whole suite this thread runs the session's Playwright, whose
    # sync API keeps an asyncio loop running here (asyncio.run refuses to start another; and kernel_loop() ignores
    # that loop outside a kernel: test_outside_a_kernel_a_running_loop_is_not_a_notebooks)
    errors: list[BaseException] = []

    def kernel() -> None:
        try:
            asyncio.run(asyncio.wait_for(cell(), 30))
        except BaseException as exc:  # noqa: BLE001 (re-raised below, in the test's thread)
            errors.append(exc)

    thread = threading.Thread(target=kernel, name="kernel")
    thread.start()
    thread.join(60)
    assert not thread.is_alive(), "the kernel's loop did not end"
    if errors:
        raise errors[0]
    assert shown[0][0] == jobs.RUNNING and shown[-1] == (jobs.DONE, 3, True)
    assert all(on_loop for *_, on_loop in shown)
    assert [done for _, done, _ in shown] == sorted(done for _, done, _ in shown)


def test_outside_a_kernel_a_running_loop_is_not_a_notebooks() -> None:
    """A script's own asyncio loop (or Playwright's sync API in these tests) is not a notebook's: there the follower
    stays headless (the job's state shown when asked), nothing is scheduled on that loop."""
    import asyncio

    assert not jobs.in_kernel()

    async def script() -> asyncio.AbstractEventLoop | None:
        return jobs.kernel_loop()

    found: list[object] = []
    thread = threading.Thread(target=lambda: found.append(asyncio.run(script())))
    thread.start()
    thread.join(30)
    assert found == [None]


def test_a_job_outlives_the_destroyed_document_of_its_session() -> None:
    """Bokeh destroys an ended session's document before its destroy hooks cancel the session's job; the worker's
    notifications meanwhile must not raise (the load test's server log showed an AttributeError from
    add_next_tick_callback on a destroyed document, and the job ended as failed)."""
    from bokeh.document import Document
    from panel.io.state import set_curdoc

    class _Context:  # what Bokeh's server gives a served document: a session context
        pass

    context = _Context()
    doc = Document()
    doc._session_context = weakref.ref(context)  # served: served_document() returns it
    session = _Context()  # what the server session registers, and Document.destroy(session) removes
    doc.callbacks.on_change_dispatch_to(session)
    release = threading.Event()
    shown: list[str] = []
    follower = jobs.Follower(lambda job, state: shown.append(state.status))
    with set_curdoc(doc):
        job = follower.run(_held(release), name="t", key="k", totals={"chunks": 3})
    for callback in list(doc.session_callbacks):  # the session's event loop runs the update scheduled
        doc.remove_next_tick_callback(callback)
        callback.callback()
    assert shown == [jobs.RUNNING]
    doc.destroy(session)  # the session ended: its hooks (the cancel) have not run yet
    release.set()
    state = job.wait(30)
    assert (state.status, state.error) == (jobs.DONE, "")
    assert shown == [jobs.RUNNING]  # nothing reached the destroyed document


@pytest.mark.usefixtures("worker_pool")
def test_a_call_in_process_runs_in_another_process_and_returns_its_result() -> None:
    """Job.call runs its function in the worker process (served sessions' sliding job; keeps the server's GIL)."""
    import os

    job = jobs.Job(lambda job: (job.call(os.getpid), job.call(os.getpid, in_process=False)), name="pid").start()
    state = job.wait(120)
    assert state.status == jobs.DONE, state.error
    worker, here = state.result
    assert here == os.getpid() and worker != here


@pytest.mark.usefixtures("worker_pool")
@pytest.mark.slow
def test_background_work_runs_in_its_own_worker_and_never_queues_in_front_of_interactive_work() -> None:
    """A long call in the background pool (a map's sliding boundary) leaves the interactive pool (the Spectrum's
    sliding markers) free: its call runs at once, in another process."""
    import os
    import time

    started = threading.Event()

    def long(job: jobs.Job) -> int:
        started.set()
        job.call(time.sleep, 20.0, pool=jobs.BACKGROUND)
        return 0

    background = jobs.Job(long, name="long").start()
    assert started.wait(30)
    time.sleep(1.0)  # the 20 s call runs in the background worker
    interactive = jobs.Job(lambda job: job.call(os.getpid), name="pid").start().wait(30)
    assert interactive.status == jobs.DONE, interactive.error
    assert not background.state().finished  # it ran while the long call was running
    behind = jobs.Job(lambda job: job.call(os.getpid, pool=jobs.BACKGROUND), name="pid").start()
    time.sleep(1.0)
    assert not behind.state().finished  # the background pool's next call waits for the long one
    background.cancel()
    behind.cancel()
    assert background.wait(10).status == jobs.CANCELLED and behind.wait(10).status == jobs.CANCELLED
    assert len({interactive.result, os.getpid()}) == 2
    with pytest.raises(ValueError, match="kind must be"):
        jobs.process_pool("fast")


@pytest.mark.usefixtures("worker_pool")
def test_a_cancelled_call_in_process_ends_the_job_without_waiting_for_the_worker() -> None:
    """A job cancelled while its call runs in the worker ends at once as cancelled (the call's result is dropped)."""
    import time

    started = threading.Event()

    def work(job: jobs.Job) -> None:
        job.call(time.sleep, 0.0)  # the worker process has started
        started.set()
        job.call(time.sleep, 30.0)

    job = jobs.Job(work, name="sleep").start()
    assert started.wait(120)
    time.sleep(0.5)  # the 30 s call runs in the worker
    t0 = time.monotonic()
    job.cancel()
    assert job.wait(10).status == jobs.CANCELLED
    assert time.monotonic() - t0 < 5
