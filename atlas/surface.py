"""The neutral surface of a field sampled on a 3-D grid (an atlas's max growth over three of its axes): where the field
changes sign, as a triangle mesh, by marching tetrahedra that skip masked cells.

Pure NumPy geometry, so it sits in the atlas layer, below the app that draws it (the Atlas tab's 3-D view,
``asymslide.app.atlas.surface_view``), and is tested without a store or a browser (tests/engine/test_surface.py).
Why tetrahedra rather than marching cubes: linear interpolation on the edges of each cell's six tetrahedra has no
ambiguous case and is exact for a linear field. Why not Plotly's isosurface: a cell with a NaN corner (growth not
computable) must get no surface rather than a guessed one, and Plotly's isosurface draws nothing at all once one
value is NaN.
"""

from __future__ import annotations

import numpy as np

#: a cube cell's corners (offsets along x, y, z) and its six tetrahedra around the diagonal from corner 0 to 6
_CORNERS = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)])
_TETRAHEDRA = np.array([(0, 5, 1, 6), (0, 1, 2, 6), (0, 2, 3, 6), (0, 3, 7, 6), (0, 7, 4, 6), (0, 4, 5, 6)])


def _empty() -> tuple[np.ndarray, np.ndarray]:
    """A mesh without a triangle."""
    return np.empty((0, 3)), np.empty((0, 3), dtype=int)


def neutral_surface(x: np.ndarray, y: np.ndarray, z: np.ndarray, values: np.ndarray, *,
                    marginal: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The surface values = 0 of values[i, j, k] on the grid (x[i], y[j], z[k]), as (vertices (n, 3), triangles
    (m, 3) of vertex indices): marching tetrahedra, i.e. linear interpolation along the edges of each grid cell's six
    tetrahedra, exact for a linear field. |value| <= `marginal` counts as not positive (the app passes its neutral
    band, app.common.MARGINAL, as its heat maps' neutral curve does). A cell with a masked (NaN) corner gets no
    surface: where the field is not computable the surface is not drawn, rather than guessed. Fewer than two grid
    points along an axis, or no sign change: no triangle."""
    v = np.where(np.abs(values) <= marginal, -marginal, np.asarray(values, dtype=float))
    nx, ny, nz = v.shape
    if min(nx, ny, nz) < 2:
        return _empty()
    cells = np.stack(np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), np.arange(nz - 1), indexing="ij"), -1)
    cells = cells.reshape(-1, 3)
    corner_idx = cells[:, None, :] + _CORNERS[None, :, :]  # (cells, 8, 3)
    cell_finite = np.isfinite(v[corner_idx[..., 0], corner_idx[..., 1], corner_idx[..., 2]]).all(1)
    tet_idx = corner_idx[:, _TETRAHEDRA, :].reshape(-1, 4, 3)  # (cells * 6, 4, 3)
    val = v[tet_idx[..., 0], tet_idx[..., 1], tet_idx[..., 2]]  # (tets, 4)
    pos = np.stack([x[tet_idx[..., 0]], y[tet_idx[..., 1]], z[tet_idx[..., 2]]], -1)  # (tets, 4, 3)
    positive = val > 0
    n_pos = positive.sum(1)
    keep = np.repeat(cell_finite, len(_TETRAHEDRA)) & (n_pos > 0) & (n_pos < 4)
    val, pos, positive, n_pos = val[keep], pos[keep], positive[keep], n_pos[keep]

    def cross(a: np.ndarray, b: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Where the field is 0 on the edge between vertex a[r] and b[r] of each tetrahedron r of rows."""
        va, vb = val[rows, a], val[rows, b]
        t = (va / (va - vb))[:, None]
        return pos[rows, a] + t * (pos[rows, b] - pos[rows, a])

    tris: list[np.ndarray] = []
    order = np.argsort(~positive, axis=1, kind="stable")  # the positive vertices first
    # one vertex apart from the other three (1 or 3 positive): one triangle
    for n_odd, odd_first in ((1, True), (3, False)):
        rows = np.flatnonzero(n_pos == n_odd)
        if rows.size:
            o = order[rows]
            odd, rest = (o[:, 0], o[:, 1:]) if odd_first else (o[:, 3], o[:, :3])
            tris.append(np.stack([cross(odd, rest[:, i], rows) for i in range(3)], 1))
    # two positive, two negative: a quadrilateral, as two triangles
    rows = np.flatnonzero(n_pos == 2)
    if rows.size:
        o = order[rows]
        p0, p1, m0, m1 = o[:, 0], o[:, 1], o[:, 2], o[:, 3]
        a, b, c, e = cross(p0, m0, rows), cross(p0, m1, rows), cross(p1, m1, rows), cross(p1, m0, rows)
        tris += [np.stack([a, b, c], 1), np.stack([a, c, e], 1)]
    if not tris:
        return _empty()
    corners = np.concatenate(tris)  # (m, 3 corners, 3 coordinates)
    return corners.reshape(-1, 3), np.arange(corners.shape[0] * 3).reshape(-1, 3)
