"""The small stored atlas the browser tests open (the Atlas tab's journeys, the phone layout): its axes and kH grid.

The fixtures that store it (``small_atlas``, once per test session) and copy it into a fresh atlas directory
(``atlas_with_small``) are in tests/conftest.py."""

from __future__ import annotations

import numpy as np

#: the kH grid of the test atlases (coarse: a sweep of :data:`SMALL` takes about a second)
KH = np.logspace(-3, 3, 33)
#: the axes of the small atlas: 8 × 5 × 4 points of γ, β and f (η = ∞, Δ = 1)
SMALL = {"gamma": np.geomspace(0.3, 30, 8), "beta": np.linspace(0.1, 0.6, 5), "f": np.linspace(0.3, 1.5, 4)}
