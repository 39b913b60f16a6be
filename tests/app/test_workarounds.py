"""The Panel/Bokeh workarounds (app/workarounds.py) were checked against one version of each library: another
installed version fails here, so that someone re-checks them (and the lock) instead of finding out from users."""

from __future__ import annotations

import re
from importlib.metadata import version
from pathlib import Path

import pytest

from asymslide.app import workarounds

LOCK = Path(__file__).resolve().parents[2] / "requirements.lock"


def _locked(name: str) -> str:
    match = re.search(rf"^{name}==([^\s;]+)", LOCK.read_text(encoding="utf-8"), flags=re.M | re.I)
    assert match, f"{name} is not pinned in {LOCK.name}"
    return match.group(1)


@pytest.mark.parametrize("library", sorted(workarounds.CHECKED_WITH))
def test_workarounds_were_checked_with_the_installed_and_locked_version(library: str) -> None:
    checked = workarounds.CHECKED_WITH[library]
    assert _locked(library) == checked, (
        f"requirements.lock pins {library} {_locked(library)}, app/workarounds.py was checked with {checked}: re-check "
        "every workaround there against the new version, then update CHECKED_WITH")
    assert version(library) == checked, (
        f"{library} {version(library)} is installed, app/workarounds.py was checked with {checked}: re-check every "
        "workaround there against it (or install the locked version: make venv)")


def test_the_patched_library_internals_are_still_there() -> None:
    """What the workarounds reach into exists in the installed versions (a renamed internal fails here, not in a
    served page)."""
    import panel.io.resources
    import panel.reactive
    from bokeh.document import Document

    for module in (panel.io.resources, panel.reactive):
        assert callable(module.patch_stylesheet)
    assert callable(panel.io.resources.patch_model_css) and callable(panel.io.resources.get_dist_path)
    doc = Document()
    assert isinstance(doc._template_variables, dict)
    assert callable(doc.models.freeze) and callable(doc.models.recompute) and callable(doc.models.invalidate)


@pytest.mark.slow
def test_the_stream_registry_can_be_copied_while_another_thread_registers_streams() -> None:
    """Workaround 3: app.main installs the lock on every registry method, and copies made while another thread
    registers streams succeed. (The race itself is rare, a few times per full test run under load, so this loop alone
    seldom shows it without the guard: the first assertion is the one that fails without the workaround.)"""
    import threading

    import holoviews as hv
    from holoviews.streams import Stream

    import asymslide.app.main  # noqa: F401 (installs the guard)

    assert all(hasattr(getattr(type(Stream.registry), name), "__wrapped__") for name in workarounds.REGISTRY_METHODS)
    stop = threading.Event()
    kept = []

    def make_streams() -> None:
        while not stop.is_set():
            curve = hv.Curve([])
            kept.append((curve, hv.streams.PointerX(source=curve)))
            del kept[:-50]

    maker = threading.Thread(target=make_streams)
    maker.start()
    try:
        for _ in range(2000):
            list(Stream.registry.items())
    finally:
        stop.set()
        maker.join()


def _dropped_client():
    """A websocket handler whose client the keep-alive job dropped (a ping to a page just closed): what
    ``BokehTornado._keep_alive`` leaves behind before Tornado reports the close."""
    from types import SimpleNamespace
    from unittest import mock

    from bokeh.server.connection import ServerConnection
    from bokeh.server.tornado import BokehTornado

    session = mock.Mock()
    connection = ServerConnection(mock.Mock(), mock.Mock(), mock.Mock(), session)
    tornado = BokehTornado.__new__(BokehTornado)
    tornado._clients = {connection}
    tornado.client_lost(connection)  # what _keep_alive does on WebSocketClosedError
    application = mock.Mock(wraps=tornado)
    handler = SimpleNamespace(connection=connection, application=application, close_code=1001, close_reason=None)
    return handler, session


def test_a_close_after_the_keep_alive_dropped_the_client_logs_no_traceback() -> None:
    """Workaround 4: Bokeh's own on_close fails on such a handler (the AssertionError CI's server log showed); with the
    guard app.main installs, the close is quiet and cleans up nothing twice."""
    from bokeh.server.views.ws import WSHandler

    handler, session = _dropped_client()
    bokehs_own = getattr(WSHandler.on_close, "__wrapped__", WSHandler.on_close)
    with pytest.raises(AssertionError):
        bokehs_own(handler)
    import asymslide.app.main  # noqa: F401 (installs the guard)

    handler, session = _dropped_client()
    WSHandler.on_close(handler)
    session.notify_connection_lost.assert_not_called()
    assert handler.connection is None
    handler.application.client_lost.assert_not_called()
    live, session = _dropped_client()  # an ordinary close: the connection still holds its session
    live.connection._session = session
    connection = live.connection
    WSHandler.on_close(live)
    session.notify_connection_lost.assert_called_once()
    live.application.client_lost.assert_called_once_with(connection)
