"""The "Stability map" scene: the map and Fig. 4c equal the model's functions, caching by dependency, the
background computation (progress, cancellation, errors), clicks on the map, CSV export (headless), and one
real-browser test that the served map shows the model's values."""

from __future__ import annotations

import csv
import io
import math
import threading

import holoviews as hv
import numpy as np
import pytest

from asymslide import model
from asymslide.app import jobs
from asymslide.app.common import MARGINAL
from asymslide.app.params import SpectrumParams
from asymslide.app.sliding_map import RAYLEIGH, SLIDING
from asymslide.app.stability_map import compute, fig4c, grids, preview
from asymslide.app.stability_map.grids import KH, PLANES
from asymslide.app.stability_map.scene import StabilityMapScene
from tests.conftest import open_app
from tests.support.headless import build_app
from tests.support.spies import Calls, spying

DEFAULT_RESOLUTION = StabilityMapScene.param.resolution.default


pytestmark = pytest.mark.usefixtures("fresh_caches")

#: the scene's cache misses and model calls in the current test (tests/support/spies.py)
calls = Calls()


_spies = spying((compute, calls), (fig4c, calls), (preview, calls))


@pytest.fixture(autouse=True)
def _rayleigh_colouring(monkeypatch: pytest.MonkeyPatch) -> None:
    """These tests are of the Rayleigh branch's map (the paper's): its scenes are coloured by it (the sliding verdict,
    the default colouring, is tested in tests/app/test_app_sliding_map.py)."""
    monkeypatch.setattr(StabilityMapScene.param.verdict, "default", RAYLEIGH)


@pytest.fixture
def small(monkeypatch):
    """8 x 8 maps at the default resolution (4 chunks of 2 rows), not refined: the logic tests do not need the real
    one (the refinement is tested by test_map_equals_model_max_growth and tests/app/test_app_map_refine.py)."""
    monkeypatch.setitem(grids.RESOLUTIONS, DEFAULT_RESOLUTION, 8)
    monkeypatch.setitem(grids.LEVELS, DEFAULT_RESOLUTION, 0)


def _computed(scene: StabilityMapScene) -> compute.MapResult:
    """Render the map (which starts the computation), wait for it, render again; the finished map."""
    scene.view()[()]
    scene.wait()
    scene.view()[()]
    res = scene.result
    assert res is not None and res.key == scene.map_key, scene.status
    return res


def _expected(plane: str, n: int, p: SpectrumParams) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """x, y and model.max_growth over the whole plane in one call (independent of the scene's chunking)."""
    ax, ay = PLANES[plane]
    x, y = grids.plane_axes(plane, n)
    args = dict(zip(("gamma", "f", "beta", "eta", "Delta", "xi"), p.model_args(), strict=True))
    args[ax.name], args[ay.name] = x[None, :], y[:, None]
    growth, kh = model.max_growth(KH, **args)
    return x, y, growth, kh


def _assert_drawn_values_are_the_models(plane: str, p: SpectrumParams, mesh: hv.QuadMesh, x: np.ndarray,
                                        y: np.ndarray, growth: np.ndarray) -> None:
    """Every drawn cell's growth is model.max_growth at the point its hover names ("computed at"), computed here
    point by point; at the default resolution the map is refined (96 x 96 cells over the 24 x 24 grid); cells are
    refined (drawn with a value computed off the base grid) exactly where the base grid's Rayleigh verdict
    changes."""
    drawn = mesh.dimension_values("growth", flat=False)
    at_x, at_y = (mesh.dimension_values(d, flat=False) for d in ("at_x", "at_y"))
    levels = grids.LEVELS[DEFAULT_RESOLUTION]
    assert levels == 2 and drawn.shape == (y.size * 2**levels, x.size * 2**levels)
    points = np.unique(np.column_stack([at_x.ravel(), at_y.ravel()]), axis=0)
    ax, ay = PLANES[plane]
    args = dict(zip(("gamma", "f", "beta", "eta", "Delta", "xi"), p.model_args(), strict=True))
    args[ax.name], args[ay.name] = points[:, 0], points[:, 1]
    expected, _ = model.max_growth(KH, **args)
    index = {(px, py): g for (px, py), g in zip(map(tuple, points), expected, strict=True)}
    want = np.array([index[px, py] for px, py in zip(at_x.ravel(), at_y.ravel(), strict=True)]).reshape(drawn.shape)
    np.testing.assert_array_equal(drawn, want)
    refined = ~np.isin(at_x, x) | ~np.isin(at_y, y)
    up, down = growth > MARGINAL, growth <= MARGINAL  # NaN is neither
    changes = [(a[:, 1:] & b[:, :-1]) | (a[:, :-1] & b[:, 1:]) for a, b in ((up, down), (up.T, down.T))]
    assert refined.any() == any(c.any() for c in changes)


def _layer(overlay: hv.Overlay, kind: type, label: str = "") -> hv.Element:
    (el,) = [el for el in overlay if isinstance(el, kind) and el.label.startswith(label)]
    return el


# --------------------------------------------------------------------------------------------
# nothing computes until the map is shown
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_building_the_page_computes_nothing() -> None:
    scene = build_app({"tab": ["map"]}).map
    assert scene.result is None and scene.computation.job is None and scene.status == "idle"
    assert sum(calls.values()) == 0
    assert "Not computed yet" in scene.readout()


# --------------------------------------------------------------------------------------------
# the map is the model's
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("plane", "p"),
    [
        ("η-γ", dict(f=0.8, beta=0.35, Delta=0.6, xi=2.0)),
        ("Δ-ξ", dict(gamma=4.0, f=0.9, beta=0.3)),
        ("f-γ", dict(beta=0.25, eta_infinite=False, log10_eta=1.0)),
        ("β-γ", dict(f=1.2, Delta=0.5, xi=0.3)),
    ],
)
@pytest.mark.slow
def test_map_equals_model_max_growth(plane: str, p: dict) -> None:
    params = SpectrumParams(**p)
    scene = StabilityMapScene(params=params, plane=plane)
    res = _computed(scene)
    n = grids.RESOLUTIONS[DEFAULT_RESOLUTION]
    x, y, growth, kh = _expected(plane, n, params)
    np.testing.assert_array_equal(res.x, x)
    np.testing.assert_array_equal(res.y, y)
    np.testing.assert_array_equal(res.growth, growth)  # NaN where the model gives NaN
    np.testing.assert_array_equal(res.kH_at_max, kh)
    assert res.chunks_total == len(grids.chunk_rows(n)) == calls["compute_chunk"]

    overlay = scene.view()[()]
    mesh = _layer(overlay, hv.QuadMesh)
    drawn = mesh.dimension_values("growth", flat=False)
    _assert_drawn_values_are_the_models(plane, params, mesh, x, y, growth)
    ax, ay = PLANES[plane]
    assert [d.label for d in mesh.kdims] == [ax.label, ay.label]
    lo, hi = mesh.opts.get().kwargs["clim"]
    assert lo == -hi and hi == np.nanmax(np.abs(drawn))  # diverging around 0

    finite = np.isfinite(growth)
    text = scene.readout()
    frac = np.sum(growth[finite] > MARGINAL) / finite.sum()
    assert f"**Unstable (Rayleigh branch)** {100 * frac:.1f} %" in text
    # the not computable points, by reason (NaN rows once had n_masked_kH = 0 under a legend saying the branch was
    # masked at every kH)
    args = dict(zip(("gamma", "f", "beta", "eta", "Delta", "xi"), params.model_args(), strict=True))
    ax, ay = PLANES[plane]
    args[ax.name], args[ay.name] = x[None, :], y[:, None]
    n_masked = model.growth_analysis(KH, **args).n_masked
    everywhere = int((~finite & (n_masked == KH.size)).sum())
    refinement = int((~finite & (n_masked < KH.size)).sum())
    if everywhere:
        assert f"**Not computable** {everywhere} point(s) (dark grey): the Rayleigh branch could not be followed at " \
               "any kH" in text
    if refinement:
        assert f"**Not computable** {refinement} point(s) (dark grey): the branch was followed" in text
    if not (everywhere or refinement):
        assert "**Not computable** none" in text
    assert f"{n} × {n} points" in text and "**Time**" in text


def test_neutral_curve_separates_stable_from_unstable() -> None:
    """f-γ plane at η = ∞, Δ = 1: near f = 0.9 the zero contour lies at the model's critical γ (within a cell)."""
    scene = StabilityMapScene(plane="f-γ")
    res = _computed(scene)
    path = _layer(scene.view()[()], hv.Path)
    pts = np.concatenate([np.column_stack([s[:, 0], s[:, 1]]) for s in path.split(datatype="array")])
    gamma_c = model.critical_gamma(f=0.9, beta=0.3)
    near = pts[np.abs(pts[:, 0] - 0.9) < 0.05]
    assert near.size
    cell = np.log10(res.y[1] / res.y[0])
    assert np.min(np.abs(np.log10(near[:, 1] / gamma_c))) < cell


# --------------------------------------------------------------------------------------------
# caching: what the map depends on
# --------------------------------------------------------------------------------------------


def test_plane_parameters_move_only_the_marker(small) -> None:
    scene = StabilityMapScene()  # η-γ plane
    _computed(scene)
    n_chunks = len(grids.chunk_rows(8))
    assert calls["compute_chunk"] == calls["growth_analysis"] == n_chunks
    fired = []
    scene.param.watch(fired.append, "map_key")
    scene.params.param.update(gamma=5.0, eta_infinite=False, log10_eta=3.0)
    scene.view()[()]
    scene.wait()
    assert fired == [] and calls["compute_chunk"] == n_chunks and scene.status == "done"
    marker = _layer(scene.view()[()], hv.Points, "current parameters")
    np.testing.assert_allclose(marker.array()[0], [1e3, 5.0])


def test_other_parameters_recompute_exactly_once(small) -> None:
    scene = StabilityMapScene()
    _computed(scene)
    n_chunks = len(grids.chunk_rows(8))
    scene.params.f = 0.5
    res = _computed(scene)
    scene.view()[()]
    scene.readout()
    assert calls["compute_chunk"] == calls["growth_analysis"] == 2 * n_chunks
    np.testing.assert_array_equal(res.growth, _expected("η-γ", 8, scene.params)[2])
    scene.params.f = 0.9  # back: every chunk from the cache
    res = _computed(scene)
    assert calls["compute_chunk"] == 2 * n_chunks
    assert res.chunks_computed == 0 and "from the cache" in scene.readout()


def test_xi_at_delta_one_recomputes_nothing(small) -> None:
    scene = StabilityMapScene()
    _computed(scene)
    key = scene.map_key
    scene.params.xi = 3.0
    scene.view()[()]
    scene.wait()
    assert scene.map_key == key and calls["compute_chunk"] == len(grids.chunk_rows(8))
    scene.params.Delta = 0.5  # now xi matters
    _computed(scene)
    assert calls["compute_chunk"] == 2 * len(grids.chunk_rows(8))


def test_plane_and_resolution_are_part_of_the_key(small) -> None:
    scene = StabilityMapScene()
    _computed(scene)
    scene.plane = "f-γ"
    scene.params.f = 1.5  # a parameter of the f-γ plane: nothing new
    res = _computed(scene)
    assert res.plane == "f-γ" and calls["compute_chunk"] == 2 * len(grids.chunk_rows(8))
    scene.params.param.update(eta_infinite=False, log10_eta=2.0)  # off the f-γ plane: recomputes
    _computed(scene)
    assert calls["compute_chunk"] == 3 * len(grids.chunk_rows(8))
    key = scene.map_key
    scene.resolution = "coarse"  # another grid: a new key, so the next render computes it
    assert scene.map_key[1] == grids.RESOLUTIONS["coarse"] != key[1] and scene.map_key[::2] == key[::2]
    assert scene.map_download.disabled and "Not computed yet" in scene.readout()


# --------------------------------------------------------------------------------------------
# background computation: progress, cancellation, errors
# --------------------------------------------------------------------------------------------


def test_two_sessions_compute_their_maps_at_the_same_time(small, monkeypatch) -> None:
    """No process-wide lock: a chunk of one session's map is computed while another session's chunk is (the
    barrier is passed only if both computations are inside compute_chunk together)."""
    both_inside = threading.Barrier(2, timeout=30)
    real = compute.compute_chunk
    met: list[bool] = []

    def meeting_chunk(plane, n, start, stop, fixed):
        if start == 0:
            try:
                both_inside.wait()
                met.append(True)
            except threading.BrokenBarrierError:
                met.append(False)
        return real(plane, n, start, stop, fixed)

    monkeypatch.setattr(compute, "compute_chunk", meeting_chunk)
    one, two = StabilityMapScene(), StabilityMapScene()
    two.params.f = 0.5  # another map: no chunk in common
    one.view()[()]
    two.view()[()]
    one.wait()
    two.wait()
    assert met == [True, True]
    assert one.status == two.status == "done" and one.result.key != two.result.key


def test_stale_computation_stops_after_its_chunk(small, monkeypatch) -> None:
    seen: list[tuple] = []
    first_started, go_on = threading.Event(), threading.Event()
    real = compute.compute_chunk

    def blocking_chunk(plane, n, start, stop, fixed):
        seen.append(fixed)
        if len(seen) == 1:  # hold the first chunk until the inputs have changed
            first_started.set()
            assert go_on.wait(30)
        return real(plane, n, start, stop, fixed)

    monkeypatch.setattr(compute, "compute_chunk", blocking_chunk)
    scene = StabilityMapScene()
    scene.view()[()]
    assert first_started.wait(30)
    old_fixed = scene.map_key[2]
    stale = scene.computation.job
    scene.params.beta = 0.45  # mid-way: the map's inputs change
    current = scene.computation.job
    assert current is not stale and current.key == scene.map_key  # the new computation started at once
    assert scene.status == "computing"
    go_on.set()
    assert stale.wait(30).status == jobs.CANCELLED
    scene.wait()
    n_chunks = len(grids.chunk_rows(8))
    assert sum(f == old_fixed for f in seen) == 1  # the stale one stopped after its current chunk
    assert stale.state().done["chunks"] == 1 and stale.state().result is None
    assert sum(f == scene.map_key[2] for f in seen) == n_chunks
    res = scene.result
    assert res.key == scene.map_key and dict(res.key[2])["beta"] == 0.45
    np.testing.assert_array_equal(res.growth, _expected("η-γ", 8, scene.params)[2])
    assert scene.progress.value == scene.progress.max == n_chunks


def test_model_error_is_shown_and_the_scene_recovers(small, monkeypatch) -> None:
    real = compute.compute_chunk

    def failing(*_args):
        raise ValueError("beta out of range (test)")

    monkeypatch.setattr(compute, "compute_chunk", failing)
    scene = StabilityMapScene()
    scene.view()[()]
    scene.wait()
    assert scene.status.startswith("error") and "beta out of range (test)" in scene.readout()
    monkeypatch.setattr(compute, "compute_chunk", real)
    scene.params.f = 0.7
    _computed(scene)
    assert scene.status == "done" and "**Failed**" not in scene.readout()


# --------------------------------------------------------------------------------------------
# clicks on the map
# --------------------------------------------------------------------------------------------


def test_tap_sets_the_shared_parameters(small) -> None:
    params = SpectrumParams()
    scene = StabilityMapScene(params=params)
    key = scene.map_key
    scene.view()
    scene.tap_streams["η-γ", RAYLEIGH].event(x=100.0, y=5.123)
    assert (params.eta_infinite, params.log10_eta, params.gamma) == (False, 2.0, 5.12)
    assert scene.map_key == key  # the plane's own parameters: the map stays
    scene.tap_streams["η-γ", RAYLEIGH].event(x=1e20, y=1e9)  # clamped to the parameters' bounds
    assert (params.log10_eta, params.gamma) == (params.param.log10_eta.bounds[1], params.param.gamma.bounds[1])
    for plane, (x, y), expected in [
        ("β-γ", (0.9, 0.001), {"beta": 0.7071, "gamma": 0.01}),
        ("f-γ", (-1.0, 2.0), {"f": 0.0, "gamma": 2.0}),
        ("Δ-ξ", (0.004, 1e7), {"Delta": 0.01, "xi": 1e4}),
        ("Δ-ξ", (0.456, 0.0123), {"Delta": 0.46, "xi": 0.0123}),
    ]:
        scene.plane = plane
        scene.view()
        scene.tap_streams[plane, RAYLEIGH].event(x=x, y=y)
        assert {k: getattr(params, k) for k in expected} == pytest.approx(expected, rel=1e-12)
    assert calls["compute_chunk"] == 0  # clicking computes nothing by itself


def test_marker_is_clipped_to_the_plotted_range() -> None:
    scene = StabilityMapScene()  # eta = inf
    x, y, notes = scene.marker_position()
    assert (x, y) == (PLANES["η-γ"][0].hi, 3.0) and "∞" in notes[0]
    scene.plane = "Δ-ξ"  # xi = 0 on a log axis
    x, y, notes = scene.marker_position()
    assert (x, y) == (1.0, PLANES["Δ-ξ"][1].lo) and notes


# --------------------------------------------------------------------------------------------
# Fig. 4c
# --------------------------------------------------------------------------------------------


def test_fig4c_equals_model_and_is_cached_by_f_only() -> None:
    scene = StabilityMapScene()
    overlay = scene.fig4c_dmap[()]
    scatter, curve = _layer(overlay, hv.Scatter, "exact threshold"), _layer(overlay, hv.Curve)
    np.testing.assert_array_equal(scatter.dimension_values(0), fig4c.BETA_EXACT)
    np.testing.assert_array_equal(scatter.dimension_values(1), model.critical_chi(fig4c.BETA_EXACT, f=0.9))
    np.testing.assert_array_equal(curve.dimension_values(0), fig4c.BETA_CRITERION)
    np.testing.assert_array_equal(curve.dimension_values(1), model.criterion_chi(fig4c.BETA_CRITERION))
    star = _layer(overlay, hv.Points)
    np.testing.assert_allclose(star.array()[0], [0.3, 3.0 * 0.9])
    assert calls["compute_fig4c"] == 1
    scene.params.param.update(gamma=2.0, beta=0.5)
    overlay = scene.fig4c_dmap[()]
    np.testing.assert_allclose(_layer(overlay, hv.Points).array()[0], [0.5, 2.0 * 0.9])
    assert calls["compute_fig4c"] == 1 and calls["compute_chunk"] == 0
    scene.params.f = 1.5
    scene.fig4c_dmap[()]
    assert calls["compute_fig4c"] == 2 and calls["compute_criterion"] == 1
    scene.params.eta_infinite = False  # Fig. 4c is for eta = inf: no star
    assert len(_layer(scene.fig4c_dmap[()], hv.Points)) == 0
    assert "not drawn" in scene.fig4c_readout()


@pytest.mark.slow
def test_fig4c_shows_the_sliding_threshold_where_the_model_certifies_it() -> None:
    """Beside the Rayleigh branch's exact threshold, the threshold of sliding over every branch (model.critical_gammas
    with branches="all": its first certified crossing), computed as a job when Fig. 4c is drawn; a β without a certified
    one is named with the model's reason; the CSV holds it."""
    scene = StabilityMapScene()
    comment, header, _ = _read_csv(scene.fig4c_csv())
    assert "chi_c_sliding (every branch) not computed yet" in comment and "chi_c_sliding" not in header
    scene.fig4c_dmap[()]  # drawing Fig. 4c starts the job
    scene.wait_fig4c(180)
    ref = model.critical_gammas(f=0.9, beta=fig4c.BETA_EXACT, branches="all")
    first = np.array([next((ref.value[i, k] for k in range(ref.value.shape[1]) if ref.reason[i, k] in (0, 1)),
                           np.nan) for i in range(fig4c.BETA_EXACT.size)])
    points = _layer(scene.fig4c_dmap[()], hv.Scatter, "sliding threshold")
    np.testing.assert_array_equal(points.dimension_values(0), fig4c.BETA_EXACT)
    np.testing.assert_array_equal(points.dimension_values(1), first * 0.9)
    found = np.isfinite(first)
    assert 0 < found.sum() < found.size  # certified at most β; refused (NaN, with the reason) at the others
    rayleigh = model.critical_chi(fig4c.BETA_EXACT, f=0.9)
    assert np.all(first[found] * 0.9 < rayleigh[found])  # another branch goes unstable first (docs §14.10)
    text = scene.fig4c_readout()
    assert f"**Sliding threshold (every branch, f = 0.9)** certified at {int(found.sum())} of 14 β" in text
    assert "the end of the kH range searched" in text
    for b, status in zip(fig4c.BETA_EXACT[~found], ref.status[~found], strict=True):
        assert f"β = {b:.4g}: {model.THRESHOLD_STATUS[int(status)]}" in text
    comment, header, data = _read_csv(scene.fig4c_csv())
    assert header[-1] == "chi_c_sliding" and "first certified crossing" in comment
    np.testing.assert_array_equal(data[1::2, 3], first * 0.9)
    scene.params.f = 0.7  # another f: its points are not shown for it until computed
    assert len(_layer(scene.fig4c_dmap[()], hv.Scatter, "sliding threshold")) == 0
    scene.fig4c_computation.cancel()


def test_fig4c_without_threshold_is_masked_with_the_reason() -> None:
    d = fig4c.compute_fig4c(0.0)  # f = 0: no coupling, no threshold
    assert np.all(np.isnan(d["exact"])) and "no stability threshold" in d["reason"]
    np.testing.assert_array_equal(d["criterion"], model.criterion_chi(fig4c.BETA_CRITERION))


# --------------------------------------------------------------------------------------------
# CSV export
# --------------------------------------------------------------------------------------------


def _read_csv(buf: io.StringIO) -> tuple[str, list[str], np.ndarray]:
    lines = buf.getvalue().splitlines()
    assert lines[0].startswith("# ")
    header = next(csv.reader([lines[1]]))
    data = np.array([[float(v) for v in row] for row in csv.reader(lines[2:])]).reshape(-1, len(header))
    return lines[0], header, data


def test_map_csv_is_what_the_map_shows(small) -> None:
    scene = StabilityMapScene(params=SpectrumParams(f=0.7))
    assert scene.map_download.disabled
    comment, header, data = _read_csv(scene.map_csv())
    assert "not computed yet" in comment and data.size == 0
    res = _computed(scene)
    assert not scene.map_download.disabled
    comment, header, data = _read_csv(scene.map_download.callback())
    assert header == ["eta", "gamma", "max_growth", "kH_at_max", "n_masked_kH"]
    assert "f = 0.7" in comment and "plane eta-gamma" in comment
    x, y, growth, kh = _expected("η-γ", 8, scene.params)
    for i, j in np.ndindex(growth.shape):  # row-major: y outer, x inner
        row = data[i * x.size + j]
        np.testing.assert_array_equal(row[:4], [x[j], y[i], growth[i, j], kh[i, j]])
    np.testing.assert_array_equal(data[:, 2].reshape(res.growth.shape), res.growth)
    scene.params.beta = 0.5  # the map is stale now: the button is disabled until it is recomputed
    assert scene.map_download.disabled


def test_the_refined_maps_csv_adds_its_refined_points(monkeypatch) -> None:
    """At the default resolution (refined at the neutral curve) the CSV holds the base grid (level 0) and, below it,
    every point added by the refinement with its level: each row the model's value at the row's point."""
    monkeypatch.setitem(grids.RESOLUTIONS, DEFAULT_RESOLUTION, 10)
    scene = StabilityMapScene(params=SpectrumParams(f=0.7), plane="β-γ")
    res = _computed(scene)
    comment, header, data = _read_csv(scene.map_download.callback())
    assert header == ["beta", "gamma", "max_growth", "kH_at_max", "n_masked_kH", "level"]
    assert "level 0: the 10 × 10 grid" in comment
    levels = data[:, 5]
    assert np.all(levels[:100] == 0) and set(levels[100:]) == {1, 2} and np.all(np.diff(levels[100:]) >= 0)
    assert data.shape[0] == 100 + res.refined.points["x"].size
    args = dict(zip(SpectrumParams.MODEL_ARGS, scene.params.model_args(), strict=True))
    args["beta"], args["gamma"] = data[:, 0], data[:, 1]
    growth, kh = model.max_growth(KH, **args)
    np.testing.assert_array_equal(data[:, 2], growth)
    np.testing.assert_array_equal(data[:, 3], kh)
    assert "**Refined**" in scene.readout() and "refined to 40 × 40" in scene.readout()


def test_the_opaque_map_has_no_seams_between_its_cells(small) -> None:
    """The finished map's cells are stroked in their own fill colour (white seams showed between the 96 x 96 refined
    cells); a faded map (stale inputs) is not stroked."""
    from bokeh.models import GlyphRenderer

    scene = StabilityMapScene()
    _computed(scene)

    def quads(fig) -> list:
        return [r.glyph for r in fig.renderers if isinstance(r, GlyphRenderer) and type(r.glyph).__name__ == "Quad"]

    (glyph,) = quads(hv.render(scene.view()[()]))
    assert glyph.fill_alpha == 1 and glyph.line_alpha == 1 and glyph.line_color == glyph.fill_color
    scene.params.f = 0.5  # stale: the previous map is drawn faded while the new one is computed
    (glyph,) = quads(hv.render(scene.view()[()]))
    assert glyph.fill_alpha < 1 and glyph.line_alpha == 0
    scene.wait()


def test_fig4c_csv_is_what_fig4c_shows() -> None:
    scene = StabilityMapScene()
    comment, header, data = _read_csv(scene.fig4c_download.callback())
    assert header == ["beta", "chi_c_criterion", "chi_c_exact"] and "f = 0.9" in comment  # sliding: not yet
    np.testing.assert_array_equal(data[:, 0], fig4c.BETA_CRITERION)
    np.testing.assert_array_equal(data[:, 1], model.criterion_chi(fig4c.BETA_CRITERION))
    np.testing.assert_array_equal(data[1::2, 2], model.critical_chi(fig4c.BETA_EXACT, f=0.9))
    assert np.all(np.isnan(data[0::2, 2]))


# --------------------------------------------------------------------------------------------
# the Bokeh figure
# --------------------------------------------------------------------------------------------


def test_bokeh_map_has_log_axes_symbols_colorbar_and_tap(small) -> None:
    scene = StabilityMapScene()
    _computed(scene)
    plot = hv.renderer("bokeh").get_plot(scene.view())
    fig = plot.state
    assert type(fig.x_scale).__name__ == "LogScale" and type(fig.y_scale).__name__ == "LogScale"
    assert (fig.xaxis[0].axis_label, fig.yaxis[0].axis_label) == ("η", "γ")
    (bar,) = [r for r in fig.right if type(r).__name__ == "ColorBar"]
    assert bar.title == "max Im[c/c_s]"
    assert bar.color_mapper.low == -bar.color_mapper.high
    taps = [cb for sub in plot.subplots.values() for cb in sub.callbacks if type(cb).__name__ == "TapCallback"]
    assert len(taps) == 1 and scene.tap_streams["η-γ", RAYLEIGH] in taps[0].streams  # clicks reach the Tap stream
    scene.plane = "f-γ"
    fig = hv.render(scene.view(), backend="bokeh")
    assert type(fig.x_scale).__name__ == "LinearScale" and fig.xaxis[0].axis_label == "f"


# --------------------------------------------------------------------------------------------
# browser
# --------------------------------------------------------------------------------------------

_MAP_JS = """() => {
  for (const m of Bokeh.documents[0].all_models) {
    const d = m.data;
    if (d === undefined || d === null || typeof d !== 'object') continue;
    if (d.growth === undefined || d.left === undefined || d.bottom === undefined) continue;
    const g = Array.from(d.growth);
    if (!g.some(v => Number.isFinite(v) && v !== 0)) continue;  // the blank shown while computing is all 0
    const f = a => Array.from(a);
    return {left: f(d.left), right: f(d.right), bottom: f(d.bottom), top: f(d.top),
            growth: g.map(v => Number.isFinite(v) ? v : null),
            at_x: d.at_x === undefined ? null : f(d.at_x), at_y: d.at_y === undefined ? null : f(d.at_y)};
  }
  return null;
}"""


_PROGRESS_JS = """(n) => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.bar_color !== undefined && m.max !== undefined && m.value !== undefined) return m.max === n && m.value === n;
  }
  return false;
}"""


@pytest.mark.ui
@pytest.mark.slow
def test_served_map_shows_the_model_values(served_app: str, browser_page) -> None:
    page = browser_page
    open_app(page, served_app, "Stability map")
    page.wait_for_function(_MAP_JS, timeout=60_000)
    d = page.evaluate(_MAP_JS)
    n, levels = grids.RESOLUTIONS[DEFAULT_RESOLUTION], grids.LEVELS[DEFAULT_RESOLUTION]
    cells = n * 2**levels  # the map refined at its neutral curve: every cell drawn with the value at its hover's point
    assert len(d["growth"]) == cells * cells and len(d["at_x"]) == cells * cells
    args = dict(zip(("gamma", "f", "beta", "eta", "Delta", "xi"), SpectrumParams().model_args(), strict=True))
    args["eta"], args["gamma"] = np.array(d["at_x"]), np.array(d["at_y"])
    expected, _ = model.max_growth(KH, **args)
    shown = np.array([np.nan if g is None else g for g in d["growth"]])
    np.testing.assert_allclose(shown, expected, rtol=1e-12, atol=0)
    x, y, growth, _ = _expected("η-γ", n, SpectrumParams())  # the base grid's points are drawn where not refined
    at = set(zip(d["at_x"], d["at_y"], strict=True))
    assert sum((float(px), float(py)) in at for px in x for py in y) > n * n // 2
    n_chunks = len(grids.chunk_rows(n)) + levels
    try:
        page.wait_for_function(_PROGRESS_JS, arg=n_chunks, timeout=10_000)  # the bar shows the finished chunks
    except Exception:
        state = page.evaluate("() => Array.from(Bokeh.documents[0].all_models).filter(m => m.bar_color !== undefined"
                              " && m.max !== undefined).map(m => [m.max, m.value, m.type])")
        raise AssertionError(f"progress bar {state}, expected max = value = {n_chunks}") from None
    assert page.console_errors == []


def test_the_progress_bar_is_labelled(small, monkeypatch) -> None:
    """Every long phase has a labelled progress bar (the map's said nothing of what it counts); it ends at the last
    chunk."""
    held, go_on = threading.Event(), threading.Event()
    real = compute.compute_chunk

    def held_after_the_first(plane, n, start, stop, fixed):
        if start > 0 and not go_on.is_set():
            held.set()
            assert go_on.wait(30)
        return real(plane, n, start, stop, fixed)

    monkeypatch.setattr(compute, "compute_chunk", held_after_the_first)
    scene = StabilityMapScene(plane="f-γ")
    scene.view()[()]
    assert held.wait(30)
    scene.computation.update()  # headless: show the job's state now (served: the session's next tick does)
    assert scene.progress_label.object == "Computing the f-γ map (8 × 8 points): 1 of 4 chunks"
    assert (scene.progress.value, scene.progress.max, scene.status) == (1, 4, "computing") and scene.progress.visible
    go_on.set()
    scene.wait()
    assert scene.progress_label.object == "The f-γ map (8 × 8 points)" and scene.progress.value == scene.progress.max
    assert not scene.progress.visible  # a finished bar once stayed on the page as a plain blue bar


@pytest.mark.ui
@pytest.mark.slow
def test_new_inputs_mid_computation_cancel_it_in_the_browser(served_app: str, browser_page, monkeypatch,
                                                             fresh_caches) -> None:
    """A user changes the resolution while the map is being computed: the page shows the new map's progress at once,
    then the new map; the stale computation stops after its chunk and never reaches the page. (Empty caches: a coarse
    map an earlier test of this process computed would come back from the cache at once, with no progress to see.)"""
    held, go_on = threading.Event(), threading.Event()
    real = compute.compute_chunk
    computed: list[int] = []

    def held_first(plane, n, start, stop, fixed):
        computed.append(n)
        if len(computed) == 1:  # the first chunk of the first map waits until the user has changed the inputs
            held.set()
            assert go_on.wait(60)
        return real(plane, n, start, stop, fixed)

    monkeypatch.setattr(compute, "compute_chunk", held_first)
    page = browser_page
    open_app(page, served_app, "Stability map")
    medium, fine = grids.RESOLUTIONS["medium"], grids.RESOLUTIONS["fine"]
    medium_words = grids.grid_words(medium, grids.LEVELS["medium"])
    page.get_by_text(f"Computing the η-γ map ({medium_words}): 0 of").first.wait_for(timeout=60_000)
    assert held.wait(60)
    page.get_by_role("button", name="fine").first.click()
    fine_words = grids.grid_words(fine, grids.LEVELS["fine"])
    page.get_by_text(f"Computing the η-γ map ({fine_words})").first.wait_for(timeout=60_000)
    go_on.set()
    page.get_by_text(f"The η-γ map ({fine_words})", exact=True).first.wait_for(timeout=120_000)
    page.wait_for_function(_MAP_JS, timeout=60_000)
    assert len(page.evaluate(_MAP_JS)["growth"]) == (fine * 2 ** grids.LEVELS["fine"]) ** 2
    assert computed.count(medium) == 1  # the stale map stopped after its current chunk
    assert page.console_errors == []


#: the shown map (JS): its title, how many cells have a finite non-zero growth, and the range of the cells' edges
_SHOWN_MAP_JS = """() => {
  for (const m of Bokeh.documents[0].all_models) {
    if (!(m.title && m.title.text && m.title.text.includes(' plane'))) continue;
    const view = Bokeh.index.find_one(m);
    if (!view || !view.el.isConnected) continue;
    for (const r of m.renderers) {
      const d = r.data_source ? r.data_source.data : undefined;
      if (!d || d.growth === undefined || d.left === undefined) continue;
      const g = Array.from(d.growth).filter(v => Number.isFinite(v) && v !== 0);
      const f = a => Array.from(a);
      return {title: m.title.text, n: g.length, cells: f(d.growth).length, x0: Math.min(...f(d.left)),
              x1: Math.max(...f(d.right)), y0: Math.min(...f(d.bottom)), y1: Math.max(...f(d.top))};
    }
  }
  return null;
}"""

_CSV_ENABLED_JS = """() => Array.from(Bokeh.documents[0].all_models).some(
  m => m.type.endsWith('FileDownload') && m.label === 'Download map (CSV)' && !m.disabled)"""


@pytest.mark.ui
@pytest.mark.slow
def test_every_plane_revisited_shows_its_own_map(served_app: str, browser_page) -> None:
    """A user clicks through the four planes and back (every plane twice, in both orders). Each time the page shows
    that plane's finished map (title, the plane's ranges, every cell computed), says so above it, offers its CSV and
    names it in the readout. A revisited plane once stayed faded with "Not computed yet" under the previous
    plane's heading, its CSV disabled."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=map&map_res=coarse&map_verdict=rayleigh")
    n = grids.RESOLUTIONS["coarse"]
    planes = list(PLANES)
    for plane in planes + planes[::-1] + planes[1:]:
        page.locator("button", has_text=plane).first.click()
        page.wait_for_function(f"() => {{ const s = ({_SHOWN_MAP_JS})(); return s !== null && s.title.endsWith("
                               f"'the {plane} plane') && s.n > 0; }}", timeout=120_000)
        page.get_by_text(f"The {plane} map ({n} × {n} points)", exact=True).first.wait_for(timeout=120_000)
        page.wait_for_function(_CSV_ENABLED_JS, timeout=30_000)
        shown = page.evaluate(_SHOWN_MAP_JS)
        xe, ye = PLANES[plane][0].edges(n), PLANES[plane][1].edges(n)
        assert shown["cells"] == n * n, plane
        assert (shown["x0"], shown["x1"], shown["y0"], shown["y1"]) == pytest.approx(
            (xe[0], xe[-1], ye[0], ye[-1]), rel=1e-9), plane
        page.locator("p", has_text=f"Plane {plane}:").first.wait_for(timeout=30_000)  # the readout
        assert page.get_by_text("Not computed yet").count() == 0, plane


def test_a_held_slider_moves_the_marker_and_the_map_waits_for_the_release(small) -> None:
    """While f is held (off the η-γ plane) the marker and the readout follow the hand and no map is computed (a
    whole map takes seconds); the readout says the map is of the previous values. The release computes the map of
    the new f once."""
    scene = StabilityMapScene()
    first = _computed(scene)
    key = scene.map_key
    chunks = calls["compute_chunk"]
    for f in (0.7, 0.5, 0.4):
        scene.params.param.update(dragging=True, f=f)
        assert scene.map_key == key and calls["compute_chunk"] == chunks
        assert "Slider held" in scene.readout()
    scene.params.gamma = 5.0  # a value on the plane: only the marker moves
    assert scene.marker_position()[1] == 5.0 and scene.map_key == key  # γ is the plane's y
    scene.params.dragging = False  # the release
    assert scene.map_key != key and dict(scene.map_key[2])["f"] == 0.4
    second = _computed(scene)
    assert second.key == scene.map_key and second is not first and "Slider held" not in scene.readout()


def test_the_neutral_curve_is_drawn_through_the_models_certified_thresholds(small) -> None:
    """The neutral curve of a plane with γ is not the contour of the grid (a staircase) but passes through every
    certified threshold γ_c of each column (model.critical_gammas, computed here independently); between the grid's
    rows around each, the grid's growth changes sign."""
    scene = StabilityMapScene(plane="f-γ")
    res = _computed(scene)
    n = res.x.size
    edges = PLANES["f-γ"][1].edges(n)
    want = model.critical_gammas(f=res.x, beta=0.3, eta=math.inf, Delta=1.0, xi=0.0, kH=KH,
                                 gamma_range=(float(edges[0]), float(edges[-1])), max_crossings=4)
    overlay = scene._neutral("f-γ")
    path, dots, crosses = overlay.values()[:3]  # then the sliding boundary's layers (tests/app/test_app_sliding_map.py)
    ok = np.isin(want.reason, (0, 1)) & np.isfinite(want.value)
    assert ok.sum() >= n // 2  # the threshold crosses most of this plane
    np.testing.assert_allclose(np.sort(dots.dimension_values(1)), np.sort(want.value[ok]), rtol=1e-12)
    for i in range(n):
        for g in want.value[i][ok[i]]:
            below, above = np.searchsorted(res.y, g) - 1, np.searchsorted(res.y, g)
            if 0 <= below and above < n and np.isfinite(res.growth[[below, above], i]).all():
                assert np.sign(res.growth[below, i]) != np.sign(res.growth[above, i]) or abs(
                    res.growth[below, i]) <= MARGINAL or abs(res.growth[above, i]) <= MARGINAL
    segments = path.split()
    assert segments and all(set(np.round(seg.dimension_values(1), 12)) <= set(np.round(want.value[ok], 12))
                            for seg in segments)
    assert "exact in γ" in scene.readout()


def test_a_plane_without_gamma_keeps_the_grid_contour_and_says_so(small) -> None:
    scene = StabilityMapScene(plane="Δ-ξ")
    res = _computed(scene)
    assert res.crossings is None and "contour of the grid" in scene.readout()


# --------------------------------------------------------------------------------------------
# the preview while a slider is held
# --------------------------------------------------------------------------------------------


@pytest.fixture
def sixteen(monkeypatch):
    """16 x 16 maps at the default resolution: finer than the 12 x 12 preview, as every real resolution is."""
    monkeypatch.setitem(grids.RESOLUTIONS, DEFAULT_RESOLUTION, 16)
    monkeypatch.setitem(grids.LEVELS, DEFAULT_RESOLUTION, 0)


def _growth(plane: str, n: int, p: SpectrumParams) -> np.ndarray:
    """model.growth_analysis over the plane at n x n points, in one call (independent of the scene's chunks)."""
    ax, ay = PLANES[plane]
    x, y = grids.plane_axes(plane, n)
    args = dict(zip(SpectrumParams.MODEL_ARGS, p.model_args(), strict=True))
    args[ax.name], args[ay.name] = x[None, :], y[:, None]
    return np.asarray(model.growth_analysis(KH, **args).growth, float)


def _hold(scene: StabilityMapScene, **values: float) -> None:
    """A held slider moved to `values`, and the map rendered (which starts the preview, as a shown map does)."""
    scene.params.param.update(dragging=True, **values)
    scene.view()[()]


PREVIEW_12 = "Preview while the slider is held: 12 × 12 points; the full map is computed at the release"


def test_a_held_slider_off_the_plane_draws_a_labelled_preview_of_the_held_inputs(sixteen) -> None:
    """While f is held (off the η-γ plane) the map shows a coarse preview of the held f (the Rayleigh branch's
    growth at 12 x 12 points, model.growth_analysis), said so in its title, hover, progress label and readout, with
    an uncertified dashed grey contour; the full map is not computed per move."""
    scene = StabilityMapScene()
    first = _computed(scene)
    _hold(scene, f=0.6)
    assert scene.preview_key is not None and dict(scene.preview_key[2])["f"] == 0.6
    scene.wait_preview()
    assert scene.map_key == first.key and calls["compute_map"] == 1 and calls["compute_crossings"] == 1
    pv = scene.preview
    want = _growth("η-γ", 12, scene.params)
    np.testing.assert_array_equal(pv.growth, want)  # NaN where the model gives NaN
    overlay = scene.view()[()]
    mesh = _layer(overlay, hv.QuadMesh)
    np.testing.assert_array_equal(mesh.dimension_values("growth", flat=False), want)
    assert set(mesh.dimension_values("shown")) == {"preview, 12 × 12 points (the full map is computed at the release)"}
    path = _layer(overlay, hv.Path)
    assert path.label.endswith("preview contour, not certified")
    assert path.opts.get("style").kwargs["line_dash"] == "dashed"
    assert len(_layer(overlay, hv.Points, "threshold γ_c")) == 0  # no certified point is drawn over a preview
    assert scene.progress_label.object == PREVIEW_12
    text = scene.readout()
    assert f"**Slider held** {PREVIEW_12}. The map drawn is a preview of f = 0.6" in text
    assert "preview contour, not certified" in text
    assert "Drawn now: a preview of the held values; its dashed grey line" in scene.legend()
    fig = hv.render(scene.view(), backend="bokeh")
    assert fig.title.text == "Max growth rate of the Rayleigh branch over the η-γ plane: preview, 12 × 12 points"
    # the map's chunks, then the preview's
    assert calls["compute_chunk"] == len(grids.chunk_rows(16)) + len(grids.chunk_rows(12))


def test_each_move_cancels_the_previous_preview_and_the_last_value_wins(sixteen, monkeypatch) -> None:
    """Three moves while the first preview computes: the first two jobs are cancelled, the second never computes
    anything (a preview starts computing once the previous one has stopped: no backlog), the last is shown."""
    held, go_on = threading.Event(), threading.Event()
    real = compute.compute_chunk
    computed: list[float] = []

    def held_first(plane, n, start, stop, fixed):
        if n == preview.PREVIEW_POINTS:
            computed.append(dict(fixed)["f"])
            if dict(fixed)["f"] == 0.7 and start == 0:
                held.set()
                assert go_on.wait(30)
        return real(plane, n, start, stop, fixed)

    monkeypatch.setattr(compute, "compute_chunk", held_first)
    scene = StabilityMapScene()
    _computed(scene)
    started = []
    for f in (0.7, 0.6, 0.5):
        _hold(scene, f=f)
        started.append(scene.preview_computation.job)
        assert held.wait(30)
    first, second, third = started
    assert len({id(j) for j in started}) == 3 and first.cancelled and second.cancelled and not third.cancelled
    assert scene.preview is None
    go_on.set()
    scene.wait_preview()
    assert first.wait(30).status == second.wait(30).status == jobs.CANCELLED
    assert third.state().status == jobs.DONE
    assert computed.count(0.7) == 1 and 0.6 not in computed and computed.count(0.5) == len(grids.chunk_rows(12))
    assert dict(scene.preview.key[2])["f"] == 0.5
    np.testing.assert_array_equal(scene.preview.growth, _growth("η-γ", 12, scene.params))
    assert calls["compute_map"] == 1


def test_a_held_slider_on_the_plane_only_moves_the_marker(sixteen) -> None:
    scene = StabilityMapScene()  # η-γ
    _computed(scene)
    key = scene.map_key
    _hold(scene, gamma=5.0)
    _hold(scene, eta_infinite=False, log10_eta=2.0)
    assert scene.preview_key is None and scene.preview_computation.job is None and scene.preview is None
    assert calls["compute_preview"] == 0 and calls["compute_map"] == 1
    np.testing.assert_allclose(_layer(scene.view()[()], hv.Points, "current parameters").array()[0], [100.0, 5.0])
    assert "Slider held" not in scene.readout() and not scene.map_download.disabled
    scene.params.dragging = False
    assert scene.map_key == key


def test_a_held_slider_back_at_the_maps_value_draws_the_map_again(sixteen) -> None:
    scene = StabilityMapScene()
    res = _computed(scene)
    _hold(scene, f=0.6)
    scene.wait_preview()
    assert scene.preview is not None and scene.map_download.disabled
    _hold(scene, f=0.9)  # the map's own value, still held: its map is drawn, no preview is computed
    assert scene.preview is None and scene.preview_key is None and scene.preview_computation.job is None
    mesh = _layer(scene.view()[()], hv.QuadMesh)
    np.testing.assert_array_equal(mesh.dimension_values("growth", flat=False), res.growth)
    assert scene.progress_label.object == "The η-γ map (16 × 16 points)" and not scene.map_download.disabled
    assert "Slider held" not in scene.readout() and calls["compute_preview"] == 1
    scene.params.dragging = False
    assert scene.map_key == res.key and scene.result is res


@pytest.mark.slow
def test_the_csv_is_never_a_preview(sixteen) -> None:
    scene = StabilityMapScene()
    res = _computed(scene)
    assert not scene.map_download.disabled
    _hold(scene, f=0.6)
    scene.wait_preview()
    assert scene.preview is not None and scene.map_download.disabled  # what is drawn is not what it would export
    comment, _, data = _read_csv(scene.map_csv())
    assert "f = 0.9" in comment and data.shape[0] == 16 * 16  # still the full map of the values it says
    np.testing.assert_array_equal(data[:, 2].reshape(16, 16), res.growth)
    scene.params.dragging = False  # the release: disabled until the full map of f = 0.6 is done
    assert scene.map_download.disabled
    _computed(scene)
    assert not scene.map_download.disabled
    comment, _, data = _read_csv(scene.map_download.callback())
    assert "f = 0.6" in comment and data.shape[0] == 16 * 16
    np.testing.assert_array_equal(data[:, 2].reshape(16, 16), _growth("η-γ", 16, scene.params))


@pytest.mark.slow
def test_the_release_computes_the_full_map_and_the_preview_disappears(sixteen) -> None:
    scene = StabilityMapScene()
    _computed(scene)
    _hold(scene, f=0.6)
    scene.wait_preview()
    pv = scene.preview
    scene.params.dragging = False  # released at the previewed value
    assert scene.map_key == pv.key and scene.preview_key is None
    mesh = _layer(scene.view()[()], hv.QuadMesh)  # renders: the full map starts; its preview is drawn meanwhile
    np.testing.assert_array_equal(mesh.dimension_values("growth", flat=False), pv.growth)
    assert "**Released** the full map of f = 0.6" in scene.readout()
    assert scene.progress_label.object.startswith("Computing the η-γ map (16 × 16 points)")
    scene.wait()
    assert scene.preview is None and scene.result.key == scene.map_key
    overlay = scene.view()[()]
    mesh = _layer(overlay, hv.QuadMesh)
    np.testing.assert_array_equal(mesh.dimension_values("growth", flat=False), _growth("η-γ", 16, scene.params))
    assert set(mesh.dimension_values("shown")) == {"the map"}
    assert _layer(overlay, hv.Path).label == "Rayleigh branch neutral curve: certified γ_c"
    text = scene.readout()
    assert "Preview" not in text and "preview" not in text and "Released" not in text
    assert "preview" not in scene.legend()
    assert scene.progress_label.object == "The η-γ map (16 × 16 points)"
    assert hv.render(scene.view(), backend="bokeh").title.text.endswith("over the η-γ plane")
    assert calls["compute_map"] == 2


@pytest.mark.slow
def test_a_stale_preview_never_replaces_a_newer_full_map(sixteen, monkeypatch) -> None:
    """f held at 0.7 (preview shown), moved to 0.6 (its preview held in its last chunk), released there: the preview
    of 0.7 is dropped at once, the full map of 0.6 is drawn, and the preview job of 0.6 ending afterwards (even
    completed) is never shown."""
    held, go_on = threading.Event(), threading.Event()
    real = compute.compute_chunk
    last = grids.chunk_rows(12)[-1][0]

    def held_last(plane, n, start, stop, fixed):
        if n == preview.PREVIEW_POINTS and dict(fixed)["f"] == 0.6 and start == last:
            held.set()
            assert go_on.wait(30)
        return real(plane, n, start, stop, fixed)

    monkeypatch.setattr(compute, "compute_chunk", held_last)
    scene = StabilityMapScene()
    _computed(scene)
    _hold(scene, f=0.7)
    scene.wait_preview()
    assert dict(scene.preview.key[2])["f"] == 0.7
    _hold(scene, f=0.6)
    assert held.wait(30)
    stale = scene.preview_computation.job
    scene.params.dragging = False
    assert scene.preview is None  # the preview of 0.7 is not of the released inputs
    res = _computed(scene)
    assert dict(res.key[2])["f"] == 0.6
    go_on.set()
    assert stale.wait(30).status in (jobs.DONE, jobs.CANCELLED)
    scene.wait_preview()
    scene.preview_computation.update()
    assert scene.preview is None
    mesh = _layer(scene.view()[()], hv.QuadMesh)
    np.testing.assert_array_equal(mesh.dimension_values("growth", flat=False), res.growth)
    assert "Preview" not in scene.readout() and not scene.map_download.disabled


@pytest.mark.slow
def test_a_held_slider_previews_the_sliding_verdict_chunk_by_chunk(monkeypatch) -> None:
    """Coloured by the sliding verdict (f-γ plane, η = ∞): a held β shows the sliding verdict of the held β at 6 x 6
    points (model.sliding_analysis), published after each chunk (the first one already draws), labelled as a preview;
    at the release the full sliding map replaces it."""
    monkeypatch.setitem(grids.RESOLUTIONS, DEFAULT_RESOLUTION, 8)
    monkeypatch.setitem(grids.LEVELS, DEFAULT_RESOLUTION, 0)
    published: list[preview.MapPreview] = []
    real_publish = jobs.Job.publish

    def publish(self, partial):
        if isinstance(partial, preview.MapPreview):
            published.append(partial)
        real_publish(self, partial)

    monkeypatch.setattr(jobs.Job, "publish", publish)
    scene = StabilityMapScene(plane="f-γ", verdict=SLIDING)
    scene.view()[()]
    scene.wait()
    scene.view()[()]
    scene.sliding_computation.wait(120)
    assert scene.sliding.complete
    _hold(scene, beta=0.45)
    scene.wait_preview(120)
    pv = scene.preview
    assert pv.complete and pv.sliding.x.size == preview.PREVIEW_SLIDING_POINTS == 6
    chunk = preview.PREVIEW_SLIDING_CHUNK
    assert [p.sliding.computed for p in published] == list(range(chunk, 36, chunk))  # every chunk but the last
    assert int((published[0].sliding.shown()["verdict"] >= 0).sum()) == 12  # the first chunk draws two rows
    x, y = grids.plane_axes("f-γ", 6)
    want = model.sliding_analysis(f=x[None, :], gamma=y[:, None], beta=0.45, eta=math.inf, Delta=1.0, xi=0.0,
                                  floor=model.DEFAULT_FLOOR)
    for name, field in (("verdict", "verdict"), ("reason", "verdict_reason"), ("growth", "growth"),
                        ("family", "family")):
        np.testing.assert_array_equal(pv.sliding.fields[name], getattr(want, field))
    np.testing.assert_array_equal(pv.growth, _growth("f-γ", 12, scene.params))
    classes, heat = [el for el in scene.view()[()] if isinstance(el, hv.QuadMesh)]
    np.testing.assert_array_equal(classes.dimension_values(2, flat=False), want.verdict.astype(float))
    assert all(v.startswith("preview, 6 × 6 points") for v in heat.dimension_values("value_of"))
    assert scene.progress_label.object == ("Preview while the slider is held: 6 × 6 points; the full map is computed "
                                           "at the release")
    assert "**Slider held** Preview while the slider is held: 6 × 6 points" in scene.readout()
    scene.params.dragging = False
    scene.view()[()]
    scene.wait()
    scene.view()[()]
    assert scene.preview is pv  # the Rayleigh map alone does not replace a sliding preview
    scene.sliding_computation.wait(120)
    assert scene.preview is None
    classes, heat = [el for el in scene.view()[()] if isinstance(el, hv.QuadMesh)]
    x8, y8 = grids.plane_axes("f-γ", 8)
    full = model.sliding_analysis(f=x8[None, :], gamma=y8[:, None], beta=0.45, eta=math.inf, Delta=1.0, xi=0.0,
                                  floor=model.DEFAULT_FLOOR)
    np.testing.assert_array_equal(classes.dimension_values(2, flat=False), full.verdict.astype(float))
    assert set(heat.dimension_values("value_of")) == {"this point"}
    assert "Preview" not in scene.readout()
