"""The neutral surface of a sampled 3-D field (asymslide.atlas.surface, the Atlas tab's 3-D view's geometry): exact
for a linear field, none through a cell with a masked corner, none without a sign change, and the neutral band."""

from __future__ import annotations

import numpy as np

from asymslide.atlas.surface import neutral_surface


def test_neutral_surface_is_exact_for_a_linear_field_and_skips_masked_cells() -> None:
    x, y, z = np.linspace(0, 1, 6), np.linspace(-1, 2, 7), np.geomspace(0.1, 3, 5)
    X, Y, Z = np.meshgrid(x, y, z, indexing="ij")
    field = 0.4 * X + 0.3 * Y - 0.5 * Z - 0.1234  # no grid value within the app's MARGINAL of 0
    vertices, triangles = neutral_surface(x, y, z, field)
    assert len(triangles) > 20 and triangles.max() < len(vertices)
    plane = 0.4 * vertices[:, 0] + 0.3 * vertices[:, 1] - 0.5 * vertices[:, 2] - 0.1234
    np.testing.assert_allclose(plane, 0.0, atol=1e-12)  # linear interpolation on tetrahedron edges is exact here
    # a masked grid point: no triangle in the eight cells around it (the boundary is not guessed there)
    masked = field.copy()
    masked[2, 3, 2] = np.nan
    v2, t2 = neutral_surface(x, y, z, masked)
    centroids = v2[t2].mean(axis=1)
    around = ((centroids[:, 0] > x[1]) & (centroids[:, 0] < x[3]) & (centroids[:, 1] > y[2]) & (centroids[:, 1] < y[4])
              & (centroids[:, 2] > z[1]) & (centroids[:, 2] < z[3]))
    assert 0 < len(t2) < len(triangles) and not around.any()
    assert len(neutral_surface(x, y, z, np.abs(field) + 1)[1]) == 0  # no sign change: no surface


def test_a_value_within_the_neutral_band_is_not_positive() -> None:
    """|value| <= marginal counts as not positive (the app's neutral band, as its heat maps' neutral curve)."""
    x = y = z = np.linspace(0.0, 1.0, 3)
    field = np.full((3, 3, 3), 5e-7)
    field[0, 0, 0] = -1.0
    assert len(neutral_surface(x, y, z, field)[1]) > 0  # 5e-7 > 0: a sign change around the negative corner
    assert len(neutral_surface(x, y, z, field, marginal=1e-6)[1]) == 0  # all within the band or below: no surface


def test_a_grid_of_one_point_along_an_axis_has_no_surface() -> None:
    field = np.linspace(-1.0, 1.0, 9).reshape(1, 3, 3)
    vertices, triangles = neutral_surface(np.array([0.0]), np.linspace(0, 1, 3), np.linspace(0, 1, 3), field)
    assert vertices.shape == (0, 3) and triangles.shape == (0, 3) and triangles.dtype.kind == "i"
