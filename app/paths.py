"""Where the app's files are: ``static/`` (CSS, logo, favicon) beside ``app/`` in the source tree, or
inside the installed ``app`` package (the wheel maps ``static/`` to ``app/static``)."""

from __future__ import annotations

from pathlib import Path

_HERE = Path(__file__).resolve().parent

#: the directory served under /assets
STATIC_DIR = _HERE / "static" if (_HERE / "static").is_dir() else _HERE.parent / "static"
LOGO = STATIC_DIR / "logo.svg"
FAVICON = STATIC_DIR / "favicon.svg"
CSS = STATIC_DIR / "asymslide.css"
