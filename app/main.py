"""asymslide web app: six scenes in tabs (app/tabs.py), a Lab-units panel, paper-figure presets, and the state in the
URL query.

Serve it with ``make serve`` (``panel serve app/main.py ...``) and open http://localhost:5006.
Tests build the same page through :func:`create_app`.
"""

from __future__ import annotations

import html
from functools import partial
from typing import TypeVar

import panel as pn
import param
from bokeh.models import Tooltip

from asymslide.app import jobs
from asymslide.app.all_branches import AllBranchesScene
from asymslide.app.atlas.scene import AtlasScene
from asymslide.app.lab import LabScene
from asymslide.app.layout import NARROW_PX, PLACEHOLDER, FitPlots, placeholder
from asymslide.app.params import CUSTOM, LabParams, RuptureParams, SpectrumParams, set_with_material
from asymslide.app.paths import CSS, FAVICON, LOGO
from asymslide.app.plotting import configure_session
from asymslide.app.presets import Preset, load_presets, preset_args
from asymslide.app.rupture import RuptureScene
from asymslide.app.server_gc import configure_gc, track_session
from asymslide.app.spectrum import SpectrumScene
from asymslide.app.stability_map.scene import StabilityMapScene
from asymslide.app.tabs import TABS_REGISTRY, Shared
from asymslide.app.thin_on_thick import ThinOnThickParams, ThinOnThickScene
from asymslide.app.urlstate import TABS, Updates, parse_query, query_string, url_attributes
from asymslide.app.workarounds import (
    guard_closed_connections,
    guard_detached_updates,
    guard_stream_registry,
    use_server_stylesheets,
)

guard_detached_updates()  # panes of a tab switched away from keep the page's stylesheets (app/workarounds.py)
guard_stream_registry()  # sessions on several threads build plots at once (app/workarounds.py)
guard_closed_connections()  # a page gone between a keep-alive ping and its close (app/workarounds.py)

TITLE = "asymslide — frictional sliding without reflection symmetry"

#: the page below NARROW_PX (phones): the header's title wraps in a smaller font instead of running off the screen
PAGE_CSS = f"""
@media (max-width: {NARROW_PX}px) {{
  #header {{ padding-top: 4px; padding-bottom: 4px; flex-wrap: nowrap; }}
  #header .title {{ font-size: 0.95rem; white-space: normal; line-height: 1.2; }}
  #header .app-header {{ min-width: 0; flex: 1 1 auto; display: flex; align-items: center; }}
  #header .app-logo {{ height: 26px; }}
}}
"""
#: the tab titles wrap onto a second line where the page is narrower than they are (none is cut off)
TABS_CSS = ":host .bk-headers-wrapper { flex-wrap: wrap; } :host .bk-headers-wrapper .bk-tab { white-space: nowrap; }"


INTRO = """
## Frictional sliding without reflection symmetry

**asymslide** lets you explore how steady frictional sliding between two blocks of the
*same* material but *different* thicknesses can lose stability. Without a mirror symmetry
across the interface, slip along it changes the normal stress on it, and through friction
this feedback can make small perturbations grow.

<div class="tab-list">

**Spectrum**: the Rayleigh branch c(kH) of the linear stability spectrum (Sect. IV, Figs. 4a-b, 5), beside the
fastest root of every branch: the Rayleigh branch can be stable where sliding is not.
**Stability map**: where the Rayleigh branch is unstable in a parameter plane, and the threshold χ_c(β) (Fig. 4c).
**Thin-on-thick**: effective moduli, effective bimaterial coupling G_y and the slip-induced
normal-stress change of a thin block on a thick one (Sect. III, Fig. 3).
**Rupture fronts**: the slip velocity behind a steady rupture front with a cohesive zone, its peak v_m, and the
normal-stress change it causes (supplement S-V C, Figs. 2-3).
**All branches**: every unstable root in the complex plane, beyond the Rayleigh branch.
**Atlas**: a precomputed N-D stability atlas (`asymslide sweep`), explored slice by slice, with the exact
threshold γ_c and the neutral surface in 3-D.
**Lab units** (a panel in the Spectrum and Stability-map tabs): a lab setting (material, block heights, normal
stress, rate-and-state friction) that sets the sliders and reads the spectrum back in mm, 1/s and ms.
The parameters are kept in the page's URL: copy it to share what you see.

</div>

> E. Aldam, Y. Bar-Sinai, I. Svetlizky, E. A. Brener, J. Fineberg and E. Bouchbinder,
> *Frictional sliding without geometrical reflection symmetry*,
> [Phys. Rev. X **6**, 041023 (2016)](https://doi.org/10.1103/PhysRevX.6.041023).
"""


def below(text: str) -> Tooltip:
    """A button's description shown below it, at most 300 px wide."""
    return Tooltip(content=text, position="bottom", stylesheets=[":host { white-space: initial; max-width: 300px; }"])


def request_args() -> dict[str, list[bytes]]:
    """The URL query of the current session (empty outside a server session, e.g. in tests)."""
    try:
        return dict(pn.state.session_args or {})
    except Exception:  # no session context
        return {}


#: a scene class the page wires by name (App._scene)
Scene = TypeVar("Scene", bound=pn.viewable.Viewer)


class SharedState:
    """The state the tabs of one page share (app.tabs.Shared): the parameter objects, set to a URL's validated values
    (`updates`, app.urlstate.parse_query) before the Lab-units panel and the scenes watch them, and that panel."""

    def __init__(self, updates: Updates) -> None:
        self.spectrum_params = SpectrumParams()  # shared by Spectrum, Stability map, All branches and Atlas
        self.thin_params = ThinOnThickParams()
        self.lab_params = LabParams()
        self.rupture_params = RuptureParams()
        # set before the scenes watch them: a shared link shows the sliders it holds, also when its lab values
        # differ from them (the Lab-units panel then says so), and a material named alone brings its values
        apply_updates(self, updates)
        self.lab = LabScene(params=self.lab_params, spectrum=self.spectrum_params)  # in Spectrum and Stability map


class App(SharedState):
    """One browser session: shared parameters, scenes, presets, URL state and messages."""

    def __init__(self, args: dict[str, list[bytes]] | None = None) -> None:
        self.messages = pn.pane.Alert("", alert_type="warning", visible=False, sizing_mode="stretch_width")
        updates, tab, messages = parse_query(request_args() if args is None else args)
        super().__init__(updates)
        # every tab's scene, in tab order (app/tabs.py: what each is built from)
        self._scenes = {t.key: t.build(self, updates) for t in TABS_REGISTRY}
        # the scenes the page wires by name (URL, presets, messages)
        self.spectrum = self._scene("spectrum", SpectrumScene)
        self.map = self._scene("map", StabilityMapScene)
        self.thin = self._scene("thin", ThinOnThickScene)
        self.rupture = self._scene("rupture", RuptureScene)
        self.branches = self._scene("branches", AllBranchesScene)
        self.atlas = self._scene("atlas", AtlasScene)
        # a lazy tab's panel is built when the tab is first shown: a new session pays only for what it opens on
        # (about half of create_app's cost), and parameter changes update only the widgets that exist
        # (StabilityMapScene.ensure_map defers its pane updates for this)
        self._tab_content = {key: pn.Column(sizing_mode="stretch_width") for key in TABS}
        self.tabs = pn.Tabs(
            *((t.title, self._tab_content[t.key]) for t in TABS_REGISTRY),
            active=TABS.index(tab) if tab else 0,
            dynamic=True,  # only the visible scene is rendered (and computes)
            sizing_mode="stretch_width",
            stylesheets=[TABS_CSS],
        )
        for index, t in enumerate(TABS_REGISTRY):
            if not t.lazy or index == self.tabs.active:
                self._build_tab(index)
        self.tabs.param.watch(lambda e: self._build_tab(e.new, later=True), "active")
        self.presets = load_presets()
        messages += self._refused(updates)
        self.show_messages(messages, "Some values in the URL were not used as given")
        self.spectrum_params.param.watch(self.write_url, list(self.spectrum_params.param))
        self.thin_params.param.watch(self.write_url, list(self.thin_params.param))
        self.lab_params.param.watch(self.write_url, list(self.lab_params.param))
        self.rupture_params.param.watch(self.write_url, list(self.rupture_params.param))
        for t in TABS_REGISTRY:  # the scenes' own URL settings (the map's plane, …, the All-branches kH, …)
            if t.url_settings is not None:
                self._scenes[t.key].param.watch(self.write_url, url_attributes(t.key))
        self.tabs.param.watch(self.write_url, "active")
        self.atlas.param.watch(self.write_url, ["atlas", "data", "x_axis", "y_axis", "indices", "surface_axes",
                                                "verdict"])
        # the address bar shows what the page uses: values the banner reports as clamped or ignored are replaced
        if pn.state.curdoc is not None and pn.state.curdoc.session_context is not None:
            pn.state.onload(self.write_url)
        # a hidden All-branches tab defers its (up to ~1.5 s) recomputation until it is shown again
        branches_tab = TABS.index("branches")
        self.branches.active = self.tabs.active == branches_tab
        self.tabs.param.watch(lambda e: setattr(self.branches, "active", e.new == branches_tab), "active")

    def _scene(self, key: str, cls: type[Scene]) -> Scene:
        """The scene of the tab `key`, checked to be a `cls` (the page wires some scenes by name)."""
        scene = self._scenes[key]
        if not isinstance(scene, cls):
            raise TypeError(f"the {key!r} tab's scene is a {type(scene).__name__}, not a {cls.__name__}")
        return scene

    def _build_tab(self, index: int, later: bool = False) -> None:
        """Fill the tab `index` with its scene's panel the first time it is shown. `later` (a tab the user opens on a
        served page): a labelled placeholder is sent at once and the scene is built on the next turn of the event
        loop (building and rendering it takes 1-5 s; the tab was blank meanwhile)."""
        content = self._tab_content[TABS[index]]
        if content.objects:
            return
        doc = jobs.served_document()
        if not later or doc is None:
            content.objects = [self._scenes[TABS[index]].__panel__()]
            return
        content.objects = [placeholder(f"Opening the {TABS_REGISTRY[index].title} tab…")]
        doc.add_next_tick_callback(partial(self._fill_tab, index))

    def _fill_tab(self, index: int) -> None:
        """Replace the placeholder of tab `index` by its scene's panel."""
        content = self._tab_content[TABS[index]]
        if len(content.objects) == 1 and getattr(content.objects[0], "name", "") == PLACEHOLDER:
            content.objects = [self._scenes[TABS[index]].__panel__()]

    def _refused(self, updates: Updates) -> list[str]:
        """Messages for URL values that parse but that the model refuses (a negative height, c ≥ c_R, …): the
        scenes say so too, but the lab panel is folded and the tabs may not be shown."""
        out = []
        if updates["lab"]:
            error = self.lab.state().error
            if error:
                out.append(f"the lab values are not valid, the sliders do not follow them: {html.escape(error)}")
        if updates["rupture"] or updates["lab"]:
            out += [f"rupture fronts: {html.escape(m)} (empty: {', '.join(w)})"
                    for m, w in self.rupture.errors().items()]
        if updates["branches"] and self.branches.window_message:
            out.append(f"All branches: {html.escape(self.branches.window_message)}")
        return out

    def param_objects(self) -> dict[str, param.Parameterized]:
        """The parameter objects by URL target (app.urlstate.TARGETS): the shared ones, then the scenes with their
        own URL settings (app.tabs.Tab.url_settings)."""
        shared = {"spectrum": self.spectrum_params, "thin": self.thin_params, "lab": self.lab_params,
                  "rupture": self.rupture_params}
        return {**shared, **{t.key: self._scenes[t.key] for t in TABS_REGISTRY if t.url_settings is not None}}

    def show_messages(self, messages: list[str], title: str) -> None:
        self.messages.object = f"**{title}:**\n\n" + "\n".join(f"- {m}" for m in messages) if messages else ""
        self.messages.visible = bool(messages)

    def write_url(self, *_events) -> None:
        """Current parameters -> the browser's URL (replaces the query; the page is not reloaded). Served only: in a
        Jupyter notebook (app.notebook) Panel's location is the notebook page's own address, not the app's."""
        location = pn.state.location
        if location is not None and jobs.served_document() is not None:
            tab = TABS[self.tabs.active]
            search = query_string(self.param_objects(), tab, self.atlas.url_state() if tab == "atlas" else None)
            if location.search != search:
                location.search = search

    def apply_preset(self, preset: Preset) -> None:
        """Reset to the defaults, set the preset's values and family of curves, and show its tab.

        Not inside :func:`~app.params.frozen_document`: showing another tab takes the old tab's models out of the
        page and puts the new tab's in, and with the model graph frozen meanwhile Bokeh sent some of them to the
        browser as references it did not know ("reference pNNNN isn't known"; the tab then stayed empty)."""
        updates, _, messages = parse_query(preset_args(preset))
        defaults = {name: p.default for name, p in self.spectrum_params.param.objects().items() if name != "name"}
        self.spectrum_params.param.update(**{**defaults, **updates["spectrum"]})  # one change event
        self.thin_params.param.update(**updates["thin"])
        set_with_material(self.lab_params, updates["lab"])
        rupture = updates["rupture"]
        if preset.tab == "rupture":  # the rupture inputs start from the paper's, like the sliders from Fig. 4's
            rupture = {**{n: p.default for n, p in self.rupture_params.param.objects().items() if n != "name"},
                       **rupture}
        self.rupture_params.param.update(**rupture)
        if preset.tab == "map":  # the map's own settings start from their defaults (Fig. 4c: the Rayleigh branch's)
            self.map.param.update(**{**{n: self.map.param[n].default for n in ("verdict", "floor")}, **updates["map"]})
        if preset.compare_key == "kW":
            self.thin.compare_kW = list(preset.compare_values)
            self.spectrum.param.update(compare_key="", compare_values=[])
        else:
            self.spectrum.param.update(compare_key=preset.compare_key, compare_values=list(preset.compare_values))
            self.thin.compare_kW = []
        self.tabs.active = TABS.index(preset.tab)
        note = " (curve values representative: the paper's legend is not in its text)" if preset.representative else ""
        self.preset_info.object = f"**{preset.label}**: {preset.title}{note}"
        self.show_messages(messages, f"Preset {preset.label}")
        self.write_url()  # also when the preset's values equal the current ones

    def clear_families(self, *_events) -> None:
        self.spectrum.param.update(compare_key="", compare_values=[])
        self.thin.compare_kW = []
        self.preset_info.object = ""

    def preset_bar(self) -> pn.Column:
        """The paper-figure buttons, wrapping onto more lines on a narrow page; a button's description shows below
        it (to its right it covered the next button)."""
        buttons = []
        for preset in self.presets:
            button = pn.widgets.Button(label=preset.label, description=below(preset.title), color="light", width=95)
            button.on_click(lambda _e, p=preset: self.apply_preset(p))
            buttons.append(button)
        clear = pn.widgets.Button(label="Clear curves", color="light", width=110,
                                  description=below("Remove the family of curves drawn by a preset"))
        clear.on_click(self.clear_families)
        self.preset_info = pn.pane.Markdown("", sizing_mode="stretch_width")
        return pn.Column(pn.FlexBox(pn.pane.Markdown("**Paper figures:**", width=120), *buttons, clear,
                                    flex_wrap="wrap", align_items="center", sizing_mode="stretch_width"),
                         self.preset_info, sizing_mode="stretch_width")

    def content(self) -> list[pn.viewable.Viewable]:
        """The page below its header: the introduction, the messages, the paper-figure presets and the tabs (what
        :meth:`template` shows, and a notebook cell: app.notebook)."""
        intro = pn.pane.Markdown(INTRO, stylesheets=[CSS.read_text(encoding="utf-8")], sizing_mode="stretch_width")
        return [intro, self.messages, self.preset_bar(), self.tabs, FitPlots()]  # FitPlots: titles, legends

    def template(self) -> pn.template.BootstrapTemplate:
        template = pn.template.BootstrapTemplate(
            title=TITLE,
            logo=str(LOGO),
            favicon=str(FAVICON),
            main=self.content(),
            header_background="#1f4e79",
            meta_viewport="width=device-width, initial-scale=1",  # phones lay the page out at their own width
        )
        template.config.raw_css = [*template.config.raw_css, PAGE_CSS]
        return template


def apply_updates(shared: Shared, updates: Updates) -> None:
    """Set the shared parameters of a session (:class:`~asymslide.app.tabs.Shared`) to a URL's validated values
    (app.urlstate.parse_query): a material named alone brings its preset's values, and its ν to both scenes that use
    one."""
    shared.spectrum_params.param.update(**updates["spectrum"])
    set_with_material(shared.lab_params, updates["lab"])
    thin, rupture = dict(updates["thin"]), dict(updates["rupture"])
    material = updates["lab"].get("material")
    for scene in (thin, rupture):  # a material named alone brings its ν to both scenes that use one
        if material not in (None, CUSTOM) and "nu" not in scene:
            scene["nu"] = RuptureParams.material_nu(material)
    shared.thin_params.param.update(**thin)
    shared.rupture_params.param.update(**rupture)


def create_app(args: dict[str, list[bytes]] | None = None) -> pn.template.BootstrapTemplate:
    """Build a fresh page (one per browser session); `args` overrides the URL query (tests)."""
    return App(args).template()


if __name__.startswith("bokeh"):
    configure_gc()
    track_session()
    configure_session()  # before the template: it adds the notification area
    create_app().servable()
    use_server_stylesheets()  # sessions created by their websocket (--num-procs, --reuse-sessions)
