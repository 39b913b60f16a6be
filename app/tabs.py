"""The page's tabs, in one place: :data:`TABS_REGISTRY` lists every tab in the order shown, with its URL value
(``?tab=``), its title, how its scene is built and whether it is built only when first shown.

app/main.py (the tabs, their titles, which are built late, the scenes) and app/urlstate.py (the accepted ``tab=``
values, the scenes' own URL settings) both read it, so adding a tab is one entry here. This module imports the
scenes and their parameter classes only, never main.py or urlstate.py (they import it).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol

import panel as pn
import param

from .all_branches import AllBranchesScene
from .atlas.request import AtlasRequest
from .atlas.scene import AtlasScene
from .lab import LabScene
from .params import LabParams, RuptureParams, SpectrumParams, ThinOnThickParams
from .rupture import RuptureScene
from .spectrum import SpectrumScene
from .stability_map.scene import StabilityMapScene
from .thin_on_thick import ThinOnThickScene


class Shared(Protocol):
    """What the scenes of one session share (app.main.App holds it): the parameter objects and the Lab-units panel
    (shown in the Spectrum and Stability-map tabs)."""

    spectrum_params: SpectrumParams  # Spectrum, Stability map, All branches and Atlas
    thin_params: ThinOnThickParams
    lab_params: LabParams  # also the page's one set of material constants (Thin-on-thick, Rupture fronts)
    rupture_params: RuptureParams
    lab: LabScene


#: the URL's validated values by target (app.urlstate.Updates): a scene reads its own settings from it
Settings = Mapping[str, Mapping[str, object]]


@dataclass(frozen=True)
class Tab:
    """One tab of the page."""

    key: str  # its ``tab=`` value in the URL
    title: str  # its title on the page
    build: Callable[[Shared, Settings], pn.viewable.Viewer]  # its scene, from the session's shared state and URL
    #: built when first shown (a new session pays only for the tab it opens on); False: built with the page
    lazy: bool
    #: the scene's class when its own settings are in the URL (its declarations with a ``url`` key, read into
    #: ``updates[key]`` and written from the scene); None: the tab has no such settings
    url_settings: type[param.Parameterized] | None = None


#: every tab of the page, in the order shown
TABS_REGISTRY: tuple[Tab, ...] = (
    Tab("spectrum", "Spectrum", lambda s, _u: SpectrumScene(params=s.spectrum_params, lab=s.lab), lazy=False),
    Tab("map", "Stability map", lambda s, u: StabilityMapScene(params=s.spectrum_params, lab=s.lab, **u["map"]),
        lazy=True, url_settings=StabilityMapScene),
    Tab("thin", "Thin-on-thick", lambda s, _u: ThinOnThickScene(params=s.thin_params, material=s.lab_params),
        lazy=True),
    Tab("rupture", "Rupture fronts", lambda s, _u: RuptureScene(params=s.rupture_params, material=s.lab_params),
        lazy=True),
    Tab("branches", "All branches", lambda s, u: AllBranchesScene(params=s.spectrum_params, **u["branches"]),
        lazy=True, url_settings=AllBranchesScene),
    # its URL keys are its own (app.urlstate.ATLAS_KEYS: an atlas name, axes, values), read into updates["atlas"]
    Tab("atlas", "Atlas", lambda s, u: AtlasScene(params=s.spectrum_params, requested=AtlasRequest(**u["atlas"])),
        lazy=True),
)
assert len({tab.key for tab in TABS_REGISTRY}) == len(TABS_REGISTRY), "two tabs share a URL value"
