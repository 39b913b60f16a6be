"""Shared pytest fixtures: a free port, the app served on a thread, and a headless Chromium page.

Tests marked ``ui`` drive Debian's Chromium (``apt-get install -y chromium``) through Playwright.
Without /usr/bin/chromium they are skipped with a visible note, except under CI (``CI=true``),
where a missing browser is an error.
"""

from __future__ import annotations

import hashlib
import logging
import os
import re
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.support.layers import LAYERS
from tests.support.processes import MARKER, stop_marked

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
REPO_ROOT = Path(__file__).resolve().parent.parent
MISSING_BROWSER = f"{CHROMIUM} not found (apt-get install -y chromium)"
#: set to 1 (``make screenshots``) to refresh the screenshots of the README and the docs site in docs/; otherwise the
#: browser tests write theirs under build/screenshots/ (ignored by git), so that ``make test`` leaves the working tree
#: unchanged
UPDATE_SCREENSHOTS = os.environ.get("ASYMSLIDE_UPDATE_SCREENSHOTS", "") == "1"

_ui_skipped: list[str] = []

#: every process this test session starts inherits MARKER=RUN_ID in its environment: pytest_sessionfinish
#: finds the ones still running at the end (servers, workers, browsers) and fails the session
#: (kept when this module is imported a second time, as tests.conftest by the tests that import its helpers: a new
#: RUN_ID would mark the processes started after that import with a value the check does not look for)
_INHERITED = os.environ.get(MARKER, "")
RUN_ID = (_INHERITED if _INHERITED.startswith(f"pytest-{os.getpid()}-")
          else f"pytest-{os.getpid()}-{uuid.uuid4().hex[:8]}")
os.environ[MARKER] = RUN_ID
#: how long processes may take to exit after the last test before they count as left behind
LEFTOVER_GRACE = float(os.environ.get("ASYMSLIDE_LEFTOVER_GRACE", "20"))


def pytest_configure(config: pytest.Config) -> None:
    for layer, selects in LAYERS.items():  # each test folder's conftest marks its tests with its layer's name
        config.addinivalue_line("markers", f"{layer}: {selects}")
    config.addinivalue_line(
        "markers", "expected_errors(server=(), browser=()): regular expressions of server log errors and browser "
                   "console/page errors a test provokes on purpose (any other one fails the test)")


def in_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in {"true", "1", "yes"}


def pytest_runtest_setup(item: pytest.Item) -> None:
    if item.get_closest_marker("ui") is None or CHROMIUM.exists():
        return
    if in_ci():
        pytest.fail(f"browser test cannot run in CI: {MISSING_BROWSER}", pytrace=False)
    _ui_skipped.append(item.nodeid)
    pytest.skip(f"browser test skipped: {MISSING_BROWSER}")


def _worktree_state() -> dict[str, str] | None:
    """{path: status and content hash} of the repository's changed and untracked files (those git does not
    ignore), or None outside a git checkout."""
    try:
        out = subprocess.run(["git", "status", "--porcelain=v1", "-z", "--untracked-files=all"], cwd=REPO_ROOT,
                             capture_output=True, timeout=60, check=True).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    state = {}
    for entry in filter(None, out.decode(errors="replace").split("\0")):
        path = REPO_ROOT / entry[3:]
        digest = hashlib.sha1(path.read_bytes()).hexdigest() if path.is_file() else "-"
        state[entry[3:]] = entry[:2] + " " + digest
    return state


#: the working tree when the session started: the tests must leave it as they found it (their output goes to
#: build/, tmp_path or ignored caches; the screenshots in docs/ change only with ASYMSLIDE_UPDATE_SCREENSHOTS=1)
_WORKTREE_AT_START = _worktree_state()


def _worktree_changes() -> list[str]:
    """Files of the working tree that the session created, changed or removed."""
    if _WORKTREE_AT_START is None or UPDATE_SCREENSHOTS:
        return []
    now = _worktree_state() or {}
    return sorted(p for p in set(now) | set(_WORKTREE_AT_START) if now.get(p) != _WORKTREE_AT_START.get(p))


def _bare_project_modules() -> list[str]:
    """Modules of model/, atlas/ or app/ this process imported as ``model``, ``atlas`` or ``app`` rather than as
    asymslide.model, ... (two copies of one module: two numba caches of the same kernels, two app states)."""
    root = str(Path(__file__).resolve().parent.parent)
    return sorted(name for name, mod in list(sys.modules.items())
                  if name.partition(".")[0] in ("model", "atlas", "app", "atlas_engine")
                  and str(getattr(mod, "__file__", None) or "").startswith(root))


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """Fail the session if any process it started outlives it (they are killed, so none keeps running) or if it
    changed the working tree.

    multiprocessing's resource tracker (started for spawned processes: the robustness worker, Dask's local
    clusters, the app's worker pool) belongs to this process and ends with it; it is stopped after the check, as
    multiprocessing itself does at exit. (Stopped before, it waited for ever on a spawned process left running,
    which holds its pipe open: the session hung instead of failing.)"""
    from multiprocessing import resource_tracker

    tracker = resource_tracker._resource_tracker
    lines = stop_marked(RUN_ID, LEFTOVER_GRACE, exclude=(os.getpid(), getattr(tracker, "_pid", None) or -1))
    stop_tracker = getattr(tracker, "_stop", None)
    if stop_tracker is not None:
        stop_tracker()
    changed = _worktree_changes()
    bare = _bare_project_modules()
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if lines and reporter is not None:
        reporter.write_sep("!", f"{len(lines)} process(es) started by the tests were still running (killed now)",
                           red=True, bold=True)
        for line in lines:
            reporter.write_line(line)
    if changed and reporter is not None:
        reporter.write_sep("!", f"{len(changed)} file(s) of the working tree changed during the tests "
                                "(tests write to build/ or tmp_path)", red=True, bold=True)
        for path in changed:
            reporter.write_line(path)
    if bare and reporter is not None:
        reporter.write_sep("!", "the project's folders were imported by their folder names, beside asymslide.*: "
                                + ", ".join(bare), red=True, bold=True)
    if lines or changed or bare:
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_terminal_summary(terminalreporter) -> None:
    if _ui_skipped:
        terminalreporter.write_sep(
            "!", f"SKIPPED {len(_ui_skipped)} browser (ui) test(s): {MISSING_BROWSER}", yellow=True, bold=True
        )


# --------------------------------------------------------------------------------------------
# server fixtures
# --------------------------------------------------------------------------------------------


def _find_free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def free_port() -> int:
    """A TCP port on localhost that was free a moment ago."""
    return _find_free_port()


def _wait_until_up(url: str, server_thread, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    last_error: Exception | None = None
    while time.monotonic() < deadline:
        if not server_thread.is_alive():
            raise RuntimeError(f"the server thread for {url} died while starting (see the log above)")
        try:
            with urllib.request.urlopen(url, timeout=5) as response:
                if response.status == 200:
                    return
        except OSError as exc:  # connection refused while the thread starts
            last_error = exc
        time.sleep(0.1)
    raise RuntimeError(f"app at {url} did not come up within {timeout} s: {last_error!r}")


def expected_errors(request: pytest.FixtureRequest, kind: str) -> list[re.Pattern[str]]:
    """The patterns of the errors of `kind` ("server" or "browser") the test names as expected
    (``@pytest.mark.expected_errors(server=[...], browser=[...])``)."""
    marker = request.node.get_closest_marker("expected_errors")
    return [re.compile(p) for p in (marker.kwargs.get(kind, ()) if marker else ())]


def unexpected(errors: list[str], patterns: list[re.Pattern[str]]) -> list[str]:
    """The errors no pattern matches."""
    return [e for e in errors if not any(p.search(e) for p in patterns)]


class ServerLog(logging.Handler):
    """Collects what an in-process server logs as a failure: records at ERROR or above, or with a traceback (Bokeh
    and Panel log callback errors, periodic-callback errors and failed messages this way), and warnings that report
    a failure (a HoloViews plot hook that raised). Attached to the root logger, to Bokeh's (which does not propagate
    to the root when Bokeh installed its own handler) and to param's (HoloViews' warnings)."""

    LOGGERS = ("", "bokeh", "param")

    def __init__(self) -> None:
        super().__init__(level=logging.DEBUG)
        self.errors: list[str] = []
        self._seen: set[int] = set()
        self.setFormatter(logging.Formatter("%(name)s %(levelname)s: %(message)s"))

    #: exceptions of a connection the browser closed (a test's page closing while the server still writes to it):
    #: not the app's errors
    DISCONNECTS = ("WebSocketClosedError", "StreamClosedError", "CancelledError")

    #: warnings that report a failure all the same (HoloViews: a plot hook that raised)
    FAILURE_WARNINGS = ("could not be applied", "Traceback")

    def emit(self, record: logging.LogRecord) -> None:
        failed_warning = record.levelno >= logging.WARNING and any(w in record.getMessage()
                                                                   for w in self.FAILURE_WARNINGS)
        if not (record.levelno >= logging.ERROR or record.exc_info or failed_warning) or id(record) in self._seen:
            return
        self._seen.add(id(record))
        exc = record.exc_info[1] if record.exc_info else None
        if exc is not None and type(exc).__name__ in self.DISCONNECTS:
            return
        if exc is None and any(name in record.getMessage() for name in self.DISCONNECTS):
            return
        self.errors.append(self.format(record))

    def __enter__(self) -> ServerLog:
        for name in self.LOGGERS:
            logging.getLogger(name).addHandler(self)
        return self

    def __exit__(self, *_exc: object) -> None:
        for name in self.LOGGERS:
            logging.getLogger(name).removeHandler(self)


@pytest.fixture
def server_log(request: pytest.FixtureRequest) -> Iterator[ServerLog]:
    """The in-process server's errors while the test runs; the test fails at teardown on any it does not name as
    expected (``expected_errors(server=...)``)."""
    with ServerLog() as log:
        yield log
    errors = unexpected(log.errors, expected_errors(request, "server"))
    if errors:
        pytest.fail("the server logged errors:\n" + "\n\n".join(errors), pytrace=False)


@pytest.fixture
def served_app(free_port: int, server_log: ServerLog, worker_pool: None) -> Iterator[str]:
    """Serve ``app.main.create_app`` on a background thread; yield its URL; stop it afterwards. The test fails on
    any error the server logs meanwhile (:func:`server_log`). The worker pool its sessions start (app.jobs) is shut
    afterwards (:func:`worker_pool`)."""
    import panel as pn

    from asymslide.app.main import create_app

    server = pn.serve(
        create_app,  # a function: each session gets a fresh page
        port=free_port,
        address="127.0.0.1",
        websocket_origin=[f"localhost:{free_port}", f"127.0.0.1:{free_port}"],
        static_dirs={"assets": str(REPO_ROOT / "static")},
        threaded=True,
        show=False,
        start=True,
        verbose=False,
    )
    url = f"http://127.0.0.1:{free_port}/"
    try:
        _wait_until_up(url, server)
        yield url
    finally:
        server.stop()
        server.join(timeout=10)
        clear_patched_curdocs()


def clear_patched_curdocs() -> None:
    """Forget the documents a served session left patched in as Bokeh's curdoc(). bokeh.io.doc.patch_curdoc pushes
    the session's document on a global stack and pops it after its ``yield`` without try/finally, so a session's
    code that raised, or a coroutine closed when the server stopped, leaves it there: curdoc() then returns that
    served document in every thread, panel's state.curdoc falls back to it, and the headless tests after it took the
    served path of app.jobs.Follower (their jobs stayed "idle": CI failed 29 such tests after the served tests)."""
    from bokeh.io import doc as bokeh_doc

    bokeh_doc._PATCHED_CURDOCS.clear()


# --------------------------------------------------------------------------------------------
# browser fixtures
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="session")
def _browser():
    if not CHROMIUM.exists():  # pytest_runtest_setup has already skipped or failed the test
        pytest.skip(MISSING_BROWSER)
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True)
        try:
            yield browser
        finally:
            browser.close()


def watch_errors(page) -> list[str]:
    """Collect the page's console errors and uncaught page errors (BokehJS reports a failed update, e.g. an unknown
    model reference, as one) into a list, also set as ``page.console_errors``."""
    errors: list[str] = []
    page.console_errors = errors
    page.on("console", lambda msg: errors.append(f"console.{msg.type}: {msg.text}") if msg.type == "error" else None)
    page.on("pageerror", lambda exc: errors.append(f"pageerror: {exc}"))
    return errors


@pytest.fixture
def browser_context(_browser, request: pytest.FixtureRequest):
    """A factory of fresh browser pages (each in its own context, e.g. a phone's): ``new_page(**context_options)``.
    Every page's console and page errors are collected; the test fails at teardown on any it does not name as
    expected (``expected_errors(browser=...)``)."""
    contexts, all_errors = [], []

    def new_page(**options):
        context = _browser.new_context(**{"viewport": {"width": 1280, "height": 800}, **options})
        contexts.append(context)
        page = context.new_page()
        all_errors.append(watch_errors(page))
        return page

    try:
        yield new_page
    finally:
        for context in contexts:
            context.close()
    errors = unexpected([e for errs in all_errors for e in errs], expected_errors(request, "browser"))
    if errors:
        pytest.fail("browser console errors:\n" + "\n".join(errors), pytrace=False)


@pytest.fixture
def browser_page(browser_context):
    """A fresh Chromium page (1280 x 800). Console errors and uncaught page errors are collected in
    ``page.console_errors``; the test fails at teardown on any it does not name as expected."""
    return browser_context()


def screenshot_path(name: str) -> Path:
    """Where a browser test saves the screenshot `name`: docs/ when refreshing them, else build/screenshots/."""
    folder = REPO_ROOT / "docs" if UPDATE_SCREENSHOTS else REPO_ROOT / "build" / "screenshots"
    folder.mkdir(parents=True, exist_ok=True)
    return folder / name


def save_screenshot(page, name: str, *, paint_ms: int = 500, full_page: bool = True) -> Path:
    """Once Bokeh is idle and the last plot painted (paint_ms), save the page as `name` (see screenshot_path)."""
    page.wait_for_function("() => Bokeh.documents[0].is_idle", timeout=30_000)
    page.wait_for_timeout(paint_ms)
    path = screenshot_path(name)
    page.screenshot(path=str(path), full_page=full_page)
    assert path.stat().st_size > 0
    return path


def open_app(page, url: str, tab: str | None = None) -> None:
    """Load the served app in `page`, wait until Bokeh has rendered and is idle, then show `tab`."""
    page.goto(url, wait_until="load")
    page.wait_for_function("() => window.Bokeh !== undefined && Bokeh.documents.length > 0", timeout=30_000)
    page.wait_for_function("() => Bokeh.documents[0].is_idle", timeout=30_000)
    if tab is not None:
        page.locator(".bk-tab", has_text=tab).first.click()


@pytest.fixture
def fresh_caches() -> Iterator[None]:
    """Empty the app's caches (pn.cache and the map chunks) around a test."""
    import panel as pn

    from asymslide.app import spectrum
    from asymslide.app.stability_map import compute as stability_map_compute

    def clear() -> None:
        pn.state.clear_caches()
        stability_map_compute.CHUNKS.clear()
        spectrum.SLIDING_CACHE.clear()

    clear()
    yield
    clear()


_SET_SLIDER_JS = """([title, value]) => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.title === title && m.start !== undefined && m.end !== undefined) {
      m.value = value;
      m.value_throttled = value;
      return true;
    }
  }
  return false;
}"""


def set_slider(page, title: str, value: float) -> bool:
    """Set the Bokeh slider labelled `title` as a release of its handle would (value and value_throttled)."""
    return page.evaluate(_SET_SLIDER_JS, [title, value])


@pytest.fixture
def worker_pool():
    """Shut the app's worker pools (app.jobs.process_pool) that a test started: a pool left running would keep pytest
    from exiting."""
    from asymslide.app import jobs

    yield
    jobs.shutdown_pools(terminate=True)  # a call still running (a cancelled job's) ends now


@pytest.fixture(scope="session", autouse=True)
def _app_worker_pools_end_with_the_session() -> Iterator[None]:
    """The app's worker pools (app.jobs.process_pool) live as long as their process, as in a server: a headless
    scene test starts one and the next tests reuse it. The test session is that process: they are shut at its end
    (before the check that no process outlives the session)."""
    yield

    jobs = sys.modules.get("asymslide.app.jobs")
    if jobs is not None:
        jobs.shutdown_pools(terminate=True)


@pytest.fixture(scope="session")
def small_atlas(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The small atlas (tests/support/atlases.py: SMALL over KH), stored once per test session."""
    from asymslide.atlas import sweep
    from tests.support.atlases import KH, SMALL

    path = tmp_path_factory.mktemp("small-atlas") / "small.zarr"
    sweep.sweep(SMALL, kH=KH, store=path)
    return path


@pytest.fixture
def atlas_with_small(small_atlas: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh atlas directory holding a copy of the small atlas (the Atlas tab opens it as atlas=small)."""
    shutil.copytree(small_atlas, tmp_path / "small.zarr")
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path))
    return tmp_path


def download(page, label: str, timeout: float = 300_000) -> str:
    """Click the download button `label` (of the shown tab) once it is enabled (within `timeout` ms) and return the
    file's text."""
    button = page.get_by_role("button", name=label, exact=True).first
    button.wait_for(state="visible", timeout=timeout)
    page.wait_for_function("(b) => !b.disabled", arg=button.element_handle(), timeout=timeout)
    with page.expect_download(timeout=timeout) as info:
        button.click()
    return Path(info.value.path()).read_text(encoding="utf-8")
