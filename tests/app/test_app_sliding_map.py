"""The Stability map coloured by the sliding verdict over every branch: the default colouring. The map equals
model.sliding_analysis over the plane; it is computed coarse to fine (every point once, previews published); the readout
and hover name both verdicts and the fastest mode's family; switching to the Rayleigh branch gives the paper's map; new
inputs cancel the job; the CSV holds both; and a browser journey at a point where only another branch is unstable."""

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
from asymslide.app import sliding_map as slm
from asymslide.app.common import MARGINAL
from asymslide.app.params import SpectrumParams
from asymslide.app.stability_map import grids, map_plot
from asymslide.app.stability_map.grids import PLANES
from asymslide.app.stability_map.scene import StabilityMapScene
from tests.conftest import open_app, save_screenshot

pytestmark = pytest.mark.usefixtures("fresh_caches")


@pytest.fixture
def small(monkeypatch: pytest.MonkeyPatch) -> None:
    """12 x 12 maps at the default resolution: passes of strides 8, 4, 2, 1 (4, 5, 27 and 108 points)."""
    monkeypatch.setitem(grids.RESOLUTIONS, StabilityMapScene.param.resolution.default, 12)
    monkeypatch.setitem(grids.LEVELS, StabilityMapScene.param.resolution.default, 0)


def _rayleigh_map(scene: StabilityMapScene) -> None:
    """Render (which starts the Rayleigh branch's map), wait for it, render again (which starts the sliding job)."""
    scene.view()[()]
    scene.wait()
    scene.view()[()]


def _sliding(scene: StabilityMapScene, timeout: float = 300.0) -> slm.SlidingMap:
    """The Rayleigh map, then the sliding job waited for, and a render; the finished sliding map."""
    _rayleigh_map(scene)
    scene.sliding_computation.wait(timeout)
    scene.view()[()]
    sl = scene.sliding
    assert sl is not None and sl.key == scene.sliding_key and sl.complete, (scene.status, scene.sliding_status)
    return sl


def _expected(plane: str, n: int, p: SpectrumParams, floor: float) -> model.SlidingResult:
    """model.sliding_analysis over the whole plane in one call (independent of the passes and chunks)."""
    ax, ay = PLANES[plane]
    x, y = grids.plane_axes(plane, n)
    args = dict(zip(SpectrumParams.MODEL_ARGS, p.model_args(), strict=True))
    args[ax.name], args[ay.name] = x[None, :], y[:, None]
    return model.sliding_analysis(**args, floor=floor)


def _layers(overlay: hv.Overlay) -> list[hv.QuadMesh]:
    return [el for el in overlay if isinstance(el, hv.QuadMesh)]


# --------------------------------------------------------------------------------------------
# the passes
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 5, 12, 24, 40, 64])
def test_the_passes_compute_every_point_once_coarsest_first(n: int) -> None:
    parts = slm.passes(n)
    every = np.concatenate(parts)
    assert np.array_equal(np.sort(every), np.arange(n * n))
    iy, ix = np.divmod(parts[0], n)
    assert set(iy) == set(range(0, n, slm.STRIDES[0])) and set(ix) == set(range(0, n, slm.STRIDES[0]))
    chunks = slm.chunks(n)
    assert np.array_equal(np.concatenate([c for _, c in chunks]), every)
    assert max(c.size for _, c in chunks) <= slm.CHUNK_POINTS


def test_a_preview_cell_shows_its_blocks_lower_left_point() -> None:
    for stride in slm.STRIDES:
        idx = slm.preview_index(12, stride)
        assert np.all(idx % stride == 0) and np.all((idx <= np.arange(12)) & (np.arange(12) - idx < stride))


def test_the_auto_floor_is_the_models_at_eta_infinity_and_higher_at_finite_eta() -> None:
    assert slm.floor_value(slm.AUTO, finite_eta=False) == model.DEFAULT_FLOOR
    assert slm.floor_value(slm.AUTO, finite_eta=True) == slm.FINITE_ETA_FLOOR
    assert slm.floor_value("1e-4", finite_eta=True) == 1e-4
    assert StabilityMapScene(plane="β-γ").sliding_key[-1] == model.DEFAULT_FLOOR
    assert StabilityMapScene(plane="η-γ").sliding_key[-1] == slm.FINITE_ETA_FLOOR  # η is the x axis
    finite = SpectrumParams(eta_infinite=False, log10_eta=1.0)
    assert StabilityMapScene(plane="β-γ", params=finite).sliding_key[-1] == slm.FINITE_ETA_FLOOR


# --------------------------------------------------------------------------------------------
# the map is the model's
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_the_default_map_is_coloured_by_the_sliding_verdict_and_equals_the_model(small) -> None:
    params = SpectrumParams(f=0.9, beta=0.3)
    scene = StabilityMapScene(params=params, plane="β-γ")
    assert scene.verdict == slm.SLIDING
    sl = _sliding(scene)
    r = _expected("β-γ", 12, params, model.DEFAULT_FLOOR)
    np.testing.assert_array_equal(sl.fields["verdict"], r.verdict)
    np.testing.assert_array_equal(sl.fields["reason"], r.verdict_reason)
    np.testing.assert_array_equal(sl.fields["growth"], r.growth)
    np.testing.assert_array_equal(sl.fields["kH_at_max"], r.kH_at_max)
    np.testing.assert_array_equal(sl.fields["family"], r.family)
    assert sl.computed == 144 and sl.floor == model.DEFAULT_FLOOR

    classes, heat = _layers(scene.view()[()])
    np.testing.assert_array_equal(classes.dimension_values(2, flat=False), r.verdict.astype(float))
    growth = heat.dimension_values("growth_all", flat=False)
    np.testing.assert_array_equal(growth, np.where(r.verdict == 1, r.growth, np.nan))
    words = heat.dimension_values("sliding", flat=False)
    for (iy, ix), v in np.ndenumerate(r.verdict):
        fam = int(r.family[iy, ix])
        if v == 1 and fam >= 0:
            assert words[iy, ix] == f"unstable: {slm.FAMILY_NAMES[fam]}"
        elif v == 0:
            assert words[iy, ix].startswith("stable: no root of any branch with Im z ≥ 1e-06")
    assert set(heat.dimension_values("value_of")) == {"this point"}

    text = scene.readout()
    unstable, stable = int((r.verdict == 1).sum()), int((r.verdict == 0).sum())
    assert f"**Sliding (every branch)** unstable at {unstable} of 144 points" in text
    assert f"stable at {stable}, undetermined at {int((r.verdict == 2).sum())} (Im z ≥ 1e-06, kH 0.01 to 100)" in text
    hidden = int(((r.verdict == 1) & ~(scene.result.growth > MARGINAL)).sum())
    assert hidden > 0  # f = 0.9, beta = 0.3: some cells are stable on the Rayleigh branch only
    assert f"**Rayleigh-branch stable, sliding unstable** {hidden} point(s)" in text
    assert "**Unstable (Rayleigh branch)**" in text


@pytest.mark.slow
def test_the_sliding_boundary_is_drawn_through_the_models_thresholds_of_sliding_at_every_column(small) -> None:
    """After the sliding map, its boundary on a plane with γ: every certified crossing in γ of the max growth over
    every branch at each column (model.critical_gammas with branches="all", computed here independently), drawn
    purple and counted in the readout; between the grid's rows around each threshold the sliding verdict flips."""
    params = SpectrumParams(f=0.9, beta=0.3)
    scene = StabilityMapScene(params=params, plane="β-γ")
    assert scene.boundary_download.disabled
    sl = _sliding(scene)
    scene.wait_boundary()
    b = scene.boundary
    assert b is not None and b["key"] == scene.sliding_key and b["done"].all(), scene.boundary_status
    edges = PLANES["β-γ"][1].edges(12)
    want = model.critical_gammas(f=0.9, beta=sl.x, gamma_range=(float(edges[0]), float(edges[-1])), branches="all",
                                 floor=sl.floor, max_crossings=4)
    np.testing.assert_array_equal(b["reason"], want.reason)
    np.testing.assert_allclose(b["value"], want.value, rtol=1e-12, equal_nan=True)
    ok = np.isin(want.reason, (0, 1)) & np.isfinite(want.value)
    assert ok.any(axis=1).sum() >= 6  # the boundary crosses most columns of this plane
    v = sl.fields["verdict"]
    for i in np.flatnonzero((want.count == 1) & ok[:, 0]):  # one threshold in the column: no cell on its stable
        g, d = want.value[i, 0], want.direction[i, 0]  # side is unstable (the verdict flips where the growth passes
        stable_side = sl.y < g if d > 0 else sl.y > g  # the floor, at or beyond the neutral threshold)
        assert not (v[stable_side, i] == 1).any(), (i, g)
        assert (v[~stable_side, i] == 1).any(), (i, g)
    layers = scene._neutral("β-γ").values()
    path, dots = layers[3], layers[4]
    assert path.label.startswith("sliding boundary")
    assert path.opts.get().kwargs["color"] == map_plot.SLIDING_BOUNDARY_COLOR
    np.testing.assert_allclose(np.sort(dots.dimension_values(1)), np.sort(want.value[ok]), rtol=1e-12)
    assert all(set(np.round(seg.dimension_values(1), 12)) <= set(np.round(want.value[ok], 12))
               for seg in path.split())
    assert f"{int(ok.sum())} certified threshold(s) at 12 of 12 x values" in scene.readout()
    assert not scene.boundary_download.disabled  # its CSV: every crossing found, as the model gives it
    text = scene.boundary_csv().getvalue()
    assert text.startswith("# asymslide stability map, plane beta-gamma: crossings in gamma")
    rows = list(csv.reader(io.StringIO(text)))
    assert rows[1] == ["beta", "crossing", "gamma_c", "location", "direction", "reason", "kH", "re_z"]
    table = np.array(rows[2:], float)
    found = want.reason >= 0
    assert len(table) == int(found.sum())
    np.testing.assert_array_equal(table[:, 0], np.broadcast_to(sl.x[:, None], found.shape)[found])
    np.testing.assert_array_equal(table[:, 2], want.value[found])
    np.testing.assert_array_equal(table[:, 5], want.reason[found])
    np.testing.assert_array_equal(table[:, 6], want.kH[found])
    scene.verdict = slm.RAYLEIGH  # the paper's map: no sliding boundary
    assert len(scene._neutral("β-γ").values()) == 3
    assert scene.boundary_download.disabled
    assert scene.boundary_computation.job is None or scene.boundary_computation.job.state().finished


def test_a_plane_without_gamma_says_why_it_has_no_sliding_boundary(small) -> None:
    scene = StabilityMapScene(params=SpectrumParams(f=0.9, beta=0.3), plane="Δ-ξ")
    assert not scene.boundary_applies()
    assert "this plane has no γ axis" in "\n".join(scene.boundary_lines())


def test_previews_are_published_pass_by_pass_and_never_recompute_a_point(small, monkeypatch) -> None:
    seen: list[np.ndarray] = []
    real = slm.compute_chunk

    def spy(x, y, names, fixed, floor, idx):
        if names == ("Delta", "xi"):  # this scene's (a served session of an earlier test may still compute another)
            seen.append(idx)
        return real(x, y, names, fixed, floor, idx)

    monkeypatch.setattr(slm, "compute_chunk", spy)
    published: list[int] = []
    real_publish = jobs.Job.publish

    def publish(self, partial):
        if partial.key[0] != "Δ-ξ":  # another session's job
            real_publish(self, partial)
            return
        published.append(partial.stride)
        assert partial.computed == sum(p.size for p in slm.passes(12)[:slm.STRIDES.index(partial.stride) + 1])
        shown = partial.shown()["verdict"]
        assert np.all(shown >= 0)  # every cell shows a computed point
        real_publish(self, partial)

    monkeypatch.setattr(jobs.Job, "publish", publish)
    scene = StabilityMapScene(plane="Δ-ξ")
    _sliding(scene)
    assert published == [8, 4, 2]
    idx = np.concatenate(seen)
    assert np.array_equal(np.sort(idx), np.arange(144))
    # again: every chunk from the cache
    seen.clear()
    scene.params.gamma = 4.0
    scene.params.gamma = 3.0
    _sliding(scene)
    assert seen == []


@pytest.mark.slow
def test_a_preview_is_drawn_with_its_hover_saying_so(small, monkeypatch) -> None:
    held, go_on = threading.Event(), threading.Event()
    real = slm.compute_chunk

    def held_after_the_first_pass(x, y, names, fixed, floor, idx):
        if names == ("beta", "gamma") and idx[0] not in slm.passes(12)[0]:
            held.set()
            assert go_on.wait(60)
        return real(x, y, names, fixed, floor, idx)

    monkeypatch.setattr(slm, "compute_chunk", held_after_the_first_pass)
    scene = StabilityMapScene(plane="β-γ")
    _rayleigh_map(scene)
    assert held.wait(60)
    scene.sliding_computation.update()  # headless: show the job's state now
    try:
        assert scene.sliding is not None and scene.sliding.stride == 8
        _, heat = _layers(scene.view()[()])
        values = set(heat.dimension_values("value_of"))
        assert values == {"this point", "preview: its block's lower-left point"}
        assert "preview** of 4 points" in scene.readout()
        assert not scene.map_download.disabled  # the Rayleigh map is complete: the CSV says sliding is not
        assert "Sliding over every branch: not in this file" in scene.map_csv().getvalue()
    finally:
        go_on.set()
    scene.sliding_computation.wait(120)
    assert scene.sliding.complete and "max_growth_all" in scene.map_csv().getvalue()


# --------------------------------------------------------------------------------------------
# the switch, cancellation, export
# --------------------------------------------------------------------------------------------


def test_colouring_by_the_rayleigh_branch_is_the_papers_map_and_stops_the_sliding_job(small, monkeypatch) -> None:
    go_on = threading.Event()
    real = slm.compute_chunk

    def slow(x, y, names, *args):
        if names == ("f", "gamma"):  # this scene's
            assert go_on.wait(60)
        return real(x, y, names, *args)

    monkeypatch.setattr(slm, "compute_chunk", slow)
    scene = StabilityMapScene(plane="f-γ")
    _rayleigh_map(scene)
    job = scene.sliding_computation.job
    assert job is not None and not job.state().finished
    scene.verdict = slm.RAYLEIGH
    go_on.set()
    assert job.wait(60).status == jobs.CANCELLED
    overlay = scene.view()[()]
    (mesh,) = _layers(overlay)
    np.testing.assert_array_equal(mesh.dimension_values("growth", flat=False), scene.result.growth)
    assert "Rayleigh branch" in overlay.opts.get("plot").kwargs["title"]
    assert "colour by the sliding verdict to compute it" in scene.readout()
    assert not scene.map_download.disabled


@pytest.mark.slow
def test_the_progress_label_names_the_colouring_shown(small) -> None:
    """The label above the map names the colouring shown, each way, with no render in between (after switching the
    colouring to the Rayleigh branch it once still read "The sliding verdict over the β-γ map")."""
    scene = StabilityMapScene(plane="β-γ")
    _sliding(scene)
    assert scene.progress_label.object == "The sliding verdict over the β-γ map (12 × 12 points)"
    scene.verdict = slm.RAYLEIGH
    assert scene.progress_label.object == "The β-γ map (12 × 12 points)" and not scene.progress.visible
    scene.verdict = slm.SLIDING  # the sliding map of these inputs is still held: shown again at once
    assert scene.progress_label.object == "The sliding verdict over the β-γ map (12 × 12 points)"
    scene.verdict = slm.RAYLEIGH
    scene.params.beta = 0.31  # a new Rayleigh map is computed, then back to the sliding colouring: not the stale name
    scene.verdict = slm.SLIDING
    assert not scene.progress_label.object.startswith("The β-γ map"), scene.progress_label.object
    _sliding(scene)
    assert scene.progress_label.object == "The sliding verdict over the β-γ map (12 × 12 points)"


@pytest.mark.slow
def test_new_inputs_cancel_the_sliding_job_and_start_the_new_one(small, monkeypatch) -> None:
    go_on = threading.Event()
    real = slm.compute_chunk
    floors: list[float] = []

    def slow(x, y, names, fixed, floor, idx):
        if names != ("beta", "gamma"):  # a served session of an earlier test may still compute another map
            return real(x, y, names, fixed, floor, idx)
        floors.append(floor)
        assert go_on.wait(60)
        return real(x, y, names, fixed, floor, idx)

    monkeypatch.setattr(slm, "compute_chunk", slow)
    scene = StabilityMapScene(plane="β-γ")
    _rayleigh_map(scene)
    first = scene.sliding_computation.job
    scene.floor = "1e-2"
    second = scene.sliding_computation.job
    assert second is not first and second.key[-1] == 1e-2
    go_on.set()
    assert first.wait(60).status == jobs.CANCELLED
    sl = _sliding(scene)
    assert sl.floor == 1e-2 and floors[0] == model.DEFAULT_FLOOR and set(floors[1:]) <= {model.DEFAULT_FLOOR, 1e-2}


@pytest.mark.slow
def test_a_plane_revisited_is_computed_again(small) -> None:
    """Tour of the app: β-γ (sliding), Rayleigh colouring, η-γ, back to β-γ and to the sliding colouring. The view of
    β-γ is shown again without a new render: showing it must start its Rayleigh map (it read 'Not computed yet')."""
    scene = StabilityMapScene(plane="β-γ")
    scene.__panel__()
    _sliding(scene)
    scene.verdict = slm.RAYLEIGH
    scene.plane = "η-γ"
    scene.wait()
    assert scene.result.plane == "η-γ"
    scene.plane = "β-γ"
    scene.verdict = slm.SLIDING
    scene.wait()
    assert scene.result is not None and scene.result.key == scene.map_key and scene.result.plane == "β-γ"
    assert "Not computed yet" not in scene.readout() and "**Sliding (every branch)** unstable" in scene.readout()


@pytest.mark.slow
def test_the_csv_holds_both_verdicts(small) -> None:
    params = SpectrumParams(f=0.9, beta=0.3)
    scene = StabilityMapScene(params=params, plane="β-γ")
    _sliding(scene)
    text = scene.map_csv().getvalue()
    header, body = text.split("\n", 1)
    assert "Sliding over every branch (model.sliding_analysis, kH 0.01 to 100.0, floor 1e-06)" in header
    rows = list(csv.DictReader(io.StringIO(body)))
    r = _expected("β-γ", 12, params, model.DEFAULT_FLOOR)
    assert len(rows) == 144
    assert [int(row["verdict_all"]) for row in rows] == r.verdict.ravel().tolist()
    assert [int(row["family_all"]) for row in rows] == r.family.ravel().tolist()
    got = np.array([float(row["max_growth_all"]) for row in rows])
    np.testing.assert_array_equal(got, r.growth.ravel())


@pytest.mark.slow
def test_the_star_cell_readout_names_both_verdicts_and_the_family(small) -> None:
    """beta = 0.46, gamma = 2.5 (f = 0.9, eta = inf): the Rayleigh branch is stable, an intersonic mode grows."""
    params = SpectrumParams(f=0.9, beta=0.46, gamma=2.5)
    scene = StabilityMapScene(params=params, plane="β-γ")
    _sliding(scene)
    iy, ix = scene.star_cell()
    x, y = grids.plane_axes("β-γ", 12)
    r = model.sliding_analysis(gamma=y[iy], f=0.9, beta=x[ix])
    assert r.verdict == 1 and r.rayleigh.verdict == 0, (x[ix], y[iy])
    text = scene.readout()
    assert "**The star's cell**" in text and "Rayleigh branch stable" in text
    line = next(s for s in text.split("\n\n") if s.startswith("**The star's cell, sliding"))
    assert f"unstable: {slm.FAMILY_NAMES[int(r.family)]}" in line
    assert f"z = {float(r.z_at_max.real):.6g}"[:10] in line


# --------------------------------------------------------------------------------------------
# in the browser
# --------------------------------------------------------------------------------------------

_HEAT_JS = """() => {
  const r = Array.from(Bokeh.documents[0].all_models).find(m => m.type === 'GlyphRenderer' && m.data_source
      && m.data_source.data.sliding !== undefined);
  if (!r) return null;
  return {sliding: Array.from(r.data_source.data.sliding), value_of: Array.from(r.data_source.data.value_of)};
}"""


@pytest.mark.ui
@pytest.mark.slow
def test_the_map_says_where_only_another_branch_is_unstable(served_app: str, browser_page) -> None:
    """A user opens the β-γ map at β = 0.46, γ = 2.5 (coarse): the map is coloured by the sliding verdict, the star's
    cell reads Rayleigh branch stable and sliding unstable (intersonic guided mode), the hover fields name the families;
    switching to the Rayleigh branch shows the paper's map, and back."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1600})
    open_app(page, served_app + "?tab=map&map=beta-gamma&map_res=coarse&beta=0.46&gamma=2.5")
    cell = page.locator("p", has_text="The star's cell, sliding").first
    cell.wait_for(timeout=180_000)
    text = cell.text_content()
    assert "unstable: intersonic guided mode" in text, text
    assert "Rayleigh branch stable" in page.locator("p", has_text="The star's cell (").first.text_content()
    page.wait_for_function(f"() => {{ const d = ({_HEAT_JS})(); return d && d.value_of.every(v => v === "
                           "'this point'); }", timeout=60_000)
    d = page.evaluate(_HEAT_JS)
    assert any(s.startswith("unstable: intersonic") for s in d["sliding"])
    assert any(s.startswith("stable: no root") for s in d["sliding"])
    save_screenshot(page, "map_sliding_beta_gamma.png", full_page=False)
    sliding_label = "The sliding verdict over the β-γ map (24 × 24 points)"
    page.get_by_text(sliding_label, exact=True).first.wait_for(timeout=60_000)
    for _ in range(2):  # there and back twice: the label above the map names the colouring shown
        page.get_by_role("button", name=slm.RAYLEIGH).click()
        page.locator("p", has_text="colour by the sliding verdict to compute it").first.wait_for(timeout=60_000)
        page.wait_for_function(f"() => ({_HEAT_JS})() === null", timeout=60_000)
        page.get_by_text("The β-γ map (24 × 24 points)", exact=True).first.wait_for(timeout=60_000)
        assert page.get_by_text(sliding_label, exact=True).count() == 0
        page.get_by_role("button", name=slm.SLIDING).click()
        page.wait_for_function(f"() => ({_HEAT_JS})() !== null", timeout=60_000)
        page.locator("p", has_text="The star's cell, sliding").first.wait_for(timeout=60_000)
        page.get_by_text(sliding_label, exact=True).first.wait_for(timeout=60_000)
    assert math.isfinite(len(d["sliding"])) and len(d["sliding"]) == 24 * 24
    assert page.console_errors == []


_FIG4C_JS = """() => {
  const r = Array.from(Bokeh.documents[0].all_models).find(m => m.type === 'LegendItem'
      && JSON.stringify(m.label).includes('sliding threshold'));
  if (!r) return null;
  const source = r.renderers[0].data_source;
  const ys = Array.from(source.data[Object.keys(source.data).find(k => k !== 'beta' && k !== 'index')] || []);
  return {n: ys.filter(v => Number.isFinite(v)).length};
}"""


@pytest.mark.ui
@pytest.mark.slow
def test_fig4c_draws_the_sliding_threshold_beside_the_paper_s(served_app: str, browser_page) -> None:
    """A user opens the Stability map (Rayleigh colouring: nothing else computes) and scrolls to Fig. 4c: the
    readout follows the sliding threshold's job, then the triangles (every branch) are drawn beside the paper's
    circles and the readout names the β where it is not certified; a page at another f computes and draws its own
    (a change of f within a session: test_app_stability_map.py)."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=map&map_verdict=rayleigh")
    readout = page.locator("p", has_text="Sliding threshold (every branch, f = 0.9) certified at").first
    readout.wait_for(timeout=180_000)
    text = readout.text_content()
    assert "certified at 13 of 14 β" in text and "No certified threshold at β = 0.5" in text, text
    page.wait_for_function(f"() => {{ const d = ({_FIG4C_JS})(); return d && d.n === 13; }}", timeout=60_000)
    page.get_by_text("Download Fig. 4c (CSV)").first.wait_for(timeout=30_000)
    page.goto(served_app + "?tab=map&map_verdict=rayleigh&f=0.7")
    page.locator("p", has_text="Sliding threshold (every branch, f = 0.7) certified at").first.wait_for(
        timeout=180_000)
    page.wait_for_function(f"() => {{ const d = ({_FIG4C_JS})(); return d && d.n > 0; }}", timeout=60_000)
    assert page.console_errors == []
