"""Scene "Stability map" (placeholder; being built)."""

from __future__ import annotations

import panel as pn
import param

from .params import SpectrumParams


class StabilityMapScene(param.Parameterized):
    """Heat map of the maximal growth rate over a parameter plane (to be built)."""

    params = param.ClassSelector(class_=SpectrumParams)

    def __init__(self, **kwargs):
        if "params" not in kwargs:
            kwargs["params"] = SpectrumParams()
        super().__init__(**kwargs)

    def panel(self) -> pn.viewable.Viewable:
        return pn.Column(pn.pane.Markdown("Stability map: coming next."), name="Stability map")
