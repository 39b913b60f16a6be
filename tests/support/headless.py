"""The app as one browser session gets it (:func:`app.main.create_app`: the state, then the page), built without a
server, for tests that read its state and widgets."""

from __future__ import annotations

from asymslide.app.main import App


def build_app(args: dict[str, list[bytes]] | dict[str, list[str]] | None = None) -> App:
    """A fresh :class:`app.main.App` for the URL query `args` (as ``create_app`` builds it: its page is built too)."""
    app = App(args)
    app.template()
    return app
