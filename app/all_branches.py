"""Scene "All branches" (placeholder; being built)."""

from __future__ import annotations

import panel as pn
import param

from .params import SpectrumParams


class AllBranchesScene(param.Parameterized):
    """Every unstable root in the z-plane (to be built)."""

    params = param.ClassSelector(class_=SpectrumParams)

    def __init__(self, **kwargs):
        if "params" not in kwargs:
            kwargs["params"] = SpectrumParams()
        super().__init__(**kwargs)

    def panel(self) -> pn.viewable.Viewable:
        return pn.Column(pn.pane.Markdown("All branches: coming next."), name="All branches")
