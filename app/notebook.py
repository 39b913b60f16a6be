"""The app's scenes in a Jupyter notebook: each tab's scene, or the whole page, as a Panel object that displays inline
and stays live while the kernel runs (docs/examples/jupyter.md)::

    import panel as pn
    pn.extension("plotly", "katex")         # EXTENSIONS: the JavaScript the scenes need
    from asymslide.app import notebook
    notebook.scene("spectrum")              # the Spectrum tab, inline
    notebook.app()                          # the whole page: every tab

A scene is built as the page builds it (``asymslide.app.tabs.TABS_REGISTRY``), from the state the tabs of one
page share: a :class:`Session`. Scenes built from one session share their parameters, as the tabs of one page do. A
query string, as in the page's URL (``"gamma=2&eta=inf"``, ``"atlas=small"``), sets the values to start from, read
and validated as the page reads its URL (app/urlstate.py).

The scenes' background work (the Spectrum's sliding over every branch, the Stability map, the default atlas) runs on
threads as in a served page; its progress and results reach the notebook's output on the kernel's event loop, between
cells (app.jobs.Follower). Nothing here computes physics: it only builds the app's own scenes.
"""

from __future__ import annotations

import html
import sys
import urllib.parse
import warnings

import panel as pn

from .main import App, SharedState, apply_updates
from .plotting import EXTENSIONS
from .tabs import TABS_REGISTRY, Tab
from .urlstate import Updates, parse_query

__all__ = ["EXTENSIONS", "KEYS", "Session", "app", "scene"]

#: the scenes' keys, in the page's tab order (their ``?tab=`` values): spectrum, map, thin, rupture, branches, atlas
KEYS: tuple[str, ...] = tuple(t.key for t in TABS_REGISTRY)


class Session(SharedState):
    """The state the scenes of one page share (the ``asymslide.app.tabs.Shared`` protocol): the parameter
    objects and the Lab-units panel of the Spectrum and Stability-map scenes.

    Parameters
    ----------
    query : str, optional
        The values to start from, as in the page's URL (``"gamma=2&material=Homalite-100"``); default: the app's
        defaults. A value the page would clamp or ignore is a ``UserWarning``.

    Attributes
    ----------
    spectrum_params : SpectrumParams
        γ, f, β, η, Δ, ξ of the Spectrum, Stability-map, All-branches and Atlas scenes.
    thin_params : ThinOnThickParams
        kW and ν of the Thin-on-thick scene.
    lab_params : LabParams
        The lab setting, and the page's one set of material constants (Thin-on-thick, Rupture fronts).
    rupture_params : RuptureParams
        The inputs of the Rupture-fronts scene.
    lab : LabScene
        The Lab-units panel.
    updates : dict
        The validated values of `query` (the scenes' own settings among them: the map's plane, the atlas).
    """

    def __init__(self, query: str = "") -> None:
        self.updates = _parse(query)
        super().__init__(self.updates)


def _tab(key: str) -> Tab:
    """The tab `key` of ``asymslide.app.tabs.TABS_REGISTRY``."""
    for tab in TABS_REGISTRY:
        if tab.key == key:
            return tab
    raise ValueError(f"no scene {key!r}: the scenes are {', '.join(repr(k) for k in KEYS)}")


def _args(query: str) -> dict[str, list[str]]:
    """A query string (``"gamma=2&eta=inf"``, a leading ``?`` allowed) as the page's URL arguments."""
    return urllib.parse.parse_qs(query.lstrip("?"), keep_blank_values=True)


def _parse(query: str) -> Updates:
    """The validated updates of `query` (app.urlstate.parse_query); each value it clamps or ignores is a
    ``UserWarning``, as the page says it in a banner."""
    updates, _tab_key, messages = parse_query(_args(query))
    for message in messages:
        warnings.warn(f"query {query!r}: {html.unescape(message)}", UserWarning, stacklevel=_caller_level())
    return updates


def _caller_level() -> int:
    """The ``stacklevel`` of a warning that names the first caller outside this module (a notebook's cell)."""
    frame, level = sys._getframe(1), 1
    while frame is not None and frame.f_globals.get("__name__") == __name__:
        frame, level = frame.f_back, level + 1
    return level


def scene(key: str, query: str = "", *, session: Session | None = None) -> pn.viewable.Viewer:
    """The scene of the tab `key`, built as the page builds it. Displayed as a notebook cell's value, it shows
    inline (Panel's extensions loaded: ``EXTENSIONS``), its widgets driving its plots through the running kernel.

    Parameters
    ----------
    key : str
        The tab's ``?tab=`` value (:data:`KEYS`): ``"spectrum"``, ``"map"``, ``"thin"``, ``"rupture"``,
        ``"branches"`` or ``"atlas"``.
    query : str, optional
        Values to start from, as in the page's URL (``"gamma=2&f=0.5"``; the map's ``"map=beta-gamma"``, the
        Atlas's ``"atlas=NAME"``), validated as the page validates its URL: a value it clamps or ignores is a
        ``UserWarning``.
    session : Session, optional
        The shared state to build it from: scenes of one session share their parameters (a slider of one moves the
        other's plots); `query` then sets that session's values. Default: a new session, ``Session(query)``.

    Returns
    -------
    panel.viewable.Viewer
        The scene (e.g. ``asymslide.app.spectrum.SpectrumScene``); the shared parameters it shows are its
        ``params`` (for the Thin-on-thick and Rupture-fronts scenes: ``params`` and ``material``).

    Raises
    ------
    ValueError
        If `key` names no tab.
    """
    tab = _tab(key)
    if session is None:
        session = Session(query)
        updates = session.updates
    else:
        updates = _parse(query)
        apply_updates(session, updates)
    return tab.build(session, updates)


def app(query: str = "") -> pn.Column:
    """The whole page, for one new session, as the server shows it below its header: the introduction, the
    paper-figure presets and the six tabs (each built when first shown).

    Parameters
    ----------
    query : str, optional
        As the page's URL query (``"tab=map&gamma=2"``): the values and the tab to open with; values it clamps or
        ignores are said in the page's banner, as served.

    Returns
    -------
    panel.Column
        The page's content (a notebook cell shows no template: the served page's header is left out).
    """
    return pn.Column(*App(_args(query)).content(), sizing_mode="stretch_width")
