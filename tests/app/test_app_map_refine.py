"""The Stability map's refinement at its neutral curve (app.map_refine, exact boundaries): the rule, its closure,
the values drawn, and the cost against the unrefined map of the same finest resolution."""

from __future__ import annotations

import numpy as np
import pytest

from asymslide.app import map_refine as mr

RANGES = ((0.0, 1.0), (0.0, 1.0))


def _disc(xs: np.ndarray, ys: np.ndarray, calls: list[int] | None = None) -> dict[str, np.ndarray]:
    """Unstable inside a disc of radius 0.3 around (0.5, 0.45), stable outside; NaN in a small square (not
    computable), which must not be refined."""
    if calls is not None:
        calls.append(np.size(xs))
    g = 0.3 - np.hypot(np.asarray(xs) - 0.5, np.asarray(ys) - 0.45)
    g = np.where((np.abs(xs - 0.1) < 0.06) & (np.abs(ys - 0.9) < 0.06), np.nan, g)
    return {"growth": g, "kH_at_max": np.full(np.shape(g), 1.0), "n_masked": np.zeros(np.shape(g), int)}


def _refined(n: int = 12, levels: int = 2, calls: list[int] | None = None) -> tuple[mr.RefinedMap, np.ndarray]:
    x = y = np.linspace(0.0, 1.0, n)
    base = _disc(x[None, :], y[:, None])
    return mr.refine(x, y, False, False, base, levels, RANGES, lambda a, b: _disc(a, b, calls)), x


def test_levels_nest_and_level_zero_is_the_maps_grid() -> None:
    from asymslide.app.stability_map.grids import PLANES

    for ax in (a for pair in PLANES.values() for a in pair):
        base = ax.values(24)
        np.testing.assert_allclose(mr.level_edges(base, ax.log, 0), ax.edges(24), rtol=1e-12)
        coarse, fine = mr.level_edges(base, ax.log, 1), mr.level_edges(base, ax.log, 2)
        np.testing.assert_allclose(fine[::2], coarse, rtol=1e-12)
        centres = mr.level_centres(base, ax.log, 2)
        assert np.all((centres > fine[:-1]) & (centres < fine[1:]))


def test_every_cell_shows_the_value_at_the_point_it_names() -> None:
    r, _ = _refined()
    want = _disc(r.owner_x, r.owner_y)["growth"]
    np.testing.assert_array_equal(r.growth, want)
    assert r.size == 48 and r.level.max() == 2


def test_the_refinement_closes_around_the_neutral_curve() -> None:
    """No stable cell borders an unstable one unless both are of the finest level; not computable cells (NaN) flag
    nothing; the drawn verdict equals the true verdict at every finest cell's centre except next to the curve."""
    r, x = _refined()
    up, down = r.growth > 0, r.growth <= 0
    for a, b, la, lb in ((up[:, 1:], down[:, :-1], r.level[:, 1:], r.level[:, :-1]),
                         (down[:, 1:], up[:, :-1], r.level[:, 1:], r.level[:, :-1]),
                         (up[1:, :], down[:-1, :], r.level[1:, :], r.level[:-1, :]),
                         (down[1:, :], up[:-1, :], r.level[1:, :], r.level[:-1, :])):
        assert np.all((la[a & b] == 2) & (lb[a & b] == 2))
    nan = np.isnan(r.growth)
    assert nan.any() and np.all(r.level[nan] == 0)  # the NaN square stays at the base grid's resolution
    centres = mr.level_centres(x, False, 2)
    truth = _disc(centres[None, :], centres[:, None])["growth"] > 0
    wrong = (truth != up) & ~nan
    assert wrong.sum() == 0


def test_refinement_costs_less_than_the_unrefined_map_of_the_same_resolution() -> None:
    calls: list[int] = []
    r, _ = _refined(n=24, levels=2, calls=calls)
    evaluated = 24 * 24 + sum(calls)
    assert evaluated == 24 * 24 + r.points["x"].size
    assert evaluated < 0.25 * (24 * 4) ** 2  # fewer than a quarter of the 96 x 96 points
    assert r.evaluated(1) + r.evaluated(2) == r.points["x"].size


def test_points_beyond_the_range_are_evaluated_at_its_end() -> None:
    r, _ = _refined()
    assert r.owner_x.min() >= 0.0 and r.owner_x.max() <= 1.0 and r.owner_y.min() >= 0.0
    assert r.x_edges[0] < 0.0 < 1.0 < r.x_edges[-1]  # the cells themselves reach half a base cell beyond


def test_a_map_of_one_class_is_not_refined() -> None:
    x = y = np.linspace(0.0, 1.0, 6)
    base = {"growth": np.full((6, 6), -1.0), "kH_at_max": np.ones((6, 6)), "n_masked": np.zeros((6, 6), int)}
    r = mr.refine(x, y, False, False, base, 2, RANGES, lambda a, b: pytest.fail("nothing to refine"))
    assert r.points["x"].size == 0 and np.all(r.level == 0) and np.all(r.growth == -1.0)
