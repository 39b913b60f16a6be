"""asymslide web app: one tab per scene ("Spectrum", "Thin-on-thick").

Serve it with ``make serve`` (``panel serve app/main.py ...``) and open http://localhost:5006.
Tests build the same page through :func:`create_app`.
"""

from __future__ import annotations

from pathlib import Path

import panel as pn

from app.all_branches import AllBranchesScene
from app.params import SpectrumParams
from app.spectrum import SpectrumScene
from app.stability_map import StabilityMapScene
from app.thin_on_thick import ThinOnThickScene

TITLE = "asymslide — frictional sliding without reflection symmetry"

STATIC_DIR = Path(__file__).resolve().parent.parent / "static"
LOGO = STATIC_DIR / "logo.svg"
FAVICON = STATIC_DIR / "favicon.svg"
CSS = STATIC_DIR / "asymslide.css"

INTRO = """
## Frictional sliding without reflection symmetry

**asymslide** lets you explore how steady frictional sliding between two blocks of the
*same* material but *different* thicknesses can lose stability. Without a mirror symmetry
across the interface, slip along it changes the normal stress on it, and through friction
this feedback can make small perturbations grow.

The **Spectrum** tab shows the Rayleigh branch of the linear stability spectrum (Sect. IV,
Fig. 4a-b); the **Thin-on-thick** tab shows a thin block sliding on a thick one: the
effective moduli, the effective bimaterial response G_y and the slip-induced normal-stress change
(Sect. III, Fig. 3). Stability maps and the other paper figures will follow in further tabs.

> E. Aldam, Y. Bar-Sinai, I. Svetlizky, E. A. Brener, J. Fineberg and E. Bouchbinder,
> *Frictional sliding without geometrical reflection symmetry*,
> [Phys. Rev. X **6**, 041023 (2016)](https://doi.org/10.1103/PhysRevX.6.041023).
"""


def create_app() -> pn.template.BootstrapTemplate:
    """Build a fresh page (one per browser session)."""
    intro = pn.pane.Markdown(
        INTRO,
        stylesheets=[CSS.read_text(encoding="utf-8")],
        sizing_mode="stretch_width",
    )
    params = SpectrumParams()  # shared by the Spectrum, Stability-map and All-branches scenes
    tabs = pn.Tabs(
        ("Spectrum", SpectrumScene(params=params).panel()),
        ("Stability map", StabilityMapScene(params=params).panel()),
        ("Thin-on-thick", ThinOnThickScene().panel()),
        ("All branches", AllBranchesScene(params=params).panel()),
        dynamic=True,  # only the visible scene is rendered (and computes)
        sizing_mode="stretch_width",
    )
    return pn.template.BootstrapTemplate(
        title=TITLE,
        logo=str(LOGO),
        favicon=str(FAVICON),
        main=[intro, tabs],
        header_background="#1f4e79",
    )


if __name__.startswith("bokeh"):
    create_app().servable()
