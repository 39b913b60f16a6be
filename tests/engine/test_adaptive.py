"""Adaptive atlases: the verdict field of the dense sweep from a fraction of its points, bitwise the same values where
computed, resumable after a kill, refusals and what info prints.

Small grids: every test runs in seconds. The dense sweep (tests/engine/test_sweep.py checks it against the model) is the
reference.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
import xarray as xr
import zarr

from asymslide.atlas import adaptive as A
from asymslide.atlas import plan as atlas_plan
from asymslide.atlas import refinement, schema, writers
from asymslide.atlas import sweep as S
from asymslide.atlas import tasks as atlas_tasks

ROOT = Path(__file__).resolve().parents[2]
KH = np.logspace(-3, 3, 49)
GROWTH_VARS = tuple(schema.GROWTH_VARS)


def _cli(*args: str, timeout: float = 180) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "asymslide", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=timeout)


def _assert_agrees_with_dense(ad: xr.Dataset, dense: xr.Dataset) -> np.ndarray:
    """Computed points: every growth variable bitwise the dense sweep's; the rest NaN / fill; the verdict field
    equal everywhere. Returns the computed mask."""
    computed = ad.computed.values >= 0
    for name in GROWTH_VARS:
        a, d = ad[name].values, dense[name].values
        np.testing.assert_array_equal(a[computed], d[computed], err_msg=name)  # bitwise (NaN == NaN)
        fill = schema.GROWTH_VARS[name][1]
        if np.isnan(fill):
            assert np.isnan(a[~computed]).all(), name
        else:
            assert (a[~computed] == fill).all(), name
    np.testing.assert_array_equal(ad.verdict_filled.values, dense.verdict.values)
    return computed


# ------------------------------------------------------------------------------------------------
# the refinement on synthetic fields (pure functions)
# ------------------------------------------------------------------------------------------------


def _simulate(verdict: np.ndarray, growth: np.ndarray, spec: refinement.AdaptiveSpec,
              interrupted: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The adaptive sweep on a field known everywhere: (computed, filled). interrupted: every round's points are
    evaluated in two random halves, the follow targets taken between them (as a killed sweep, resumed, does)."""
    v = np.full(verdict.shape, -1, np.int8)
    g = np.full(verdict.shape, np.nan)
    c = np.full(verdict.shape, -1, np.int8)
    rng = np.random.default_rng(0)
    for level in range(spec.levels + 1):
        target = refinement.refine_targets(level, spec, v, g, c)
        while target.any():  # the level's first round, then its follow rounds
            assert not (c[target] >= 0).any()  # a point is evaluated once
            if interrupted:  # a killed run resumed: the round's points come in two parts, the second a round later
                part = target & (rng.random(target.shape) < 0.5)
                c[part], v[part], g[part] = level, verdict[part], growth[part]
                target &= ~part
                if not spec.follow:
                    continue
                target = refinement.follow_targets(level, spec, v, c) | target
                continue
            c[target], v[target], g[target] = level, verdict[target], growth[target]
            if not spec.follow:
                break
            target = refinement.follow_targets(level, spec, v, c)
    return c, refinement.fill_classes(v, c, spec.levels)


def test_a_smooth_boundary_is_found_from_a_fraction_of_the_points() -> None:
    x, y, z = np.meshgrid(*(np.linspace(-1, 1, 33),) * 3, indexing="ij")
    growth = 0.6 - np.sqrt(x**2 + 1.3 * y**2 + 0.8 * z**2) + 0.1 * np.sin(3 * x)
    verdict = (growth > 0).astype(np.int8)
    verdict[(x > 0.5) & (y > 0.5)] = 2  # an undetermined block: a class of its own
    spec = refinement.resolve_spec(refinement.AdaptiveSpec(), verdict.shape)
    assert spec.levels == 2  # a coarse grid of 9 points per axis
    computed, filled = _simulate(verdict, growth, spec)
    np.testing.assert_array_equal(filled, verdict)
    counts = refinement.level_counts(computed, 2)
    assert counts[0] == 9**3 and 0 < counts[1] and 0 < counts[2]
    assert (computed >= 0).mean() < 0.5
    # a cell whose corners agree is left alone: its points are never computed, but take its class
    assert ((computed < 0) & (verdict == 1)).any() and ((computed < 0) & (verdict == 0)).any()


def test_fill_levels_name_the_cell_each_filled_class_comes_from() -> None:
    """For every point not computed, the cell of the level fill_levels gives (side 2^(L - level) grid steps, the
    one holding the point) has every corner computed and of the point's filled class; computed points get -1."""
    x, y = np.meshgrid(np.linspace(-1, 1, 33), np.linspace(-1, 1, 33), indexing="ij")
    growth = 0.5 - np.hypot(x - 0.2, y)
    verdict = (growth > 0).astype(np.int8)
    spec = refinement.AdaptiveSpec(levels=3)
    computed, filled = _simulate(verdict, growth, spec)
    level = refinement.fill_levels(np.where(computed >= 0, verdict, -1).astype(np.int8), computed, 3)
    assert (level[computed >= 0] == -1).all()
    gaps = np.argwhere(computed < 0)
    assert len(gaps) and (level[computed < 0] >= 0).all() and len(np.unique(level[computed < 0])) > 1
    for i, j in gaps:
        side = 2 ** (3 - int(level[i, j]))
        i0, j0 = min(i // side * side, 32 - side), min(j // side * side, 32 - side)
        corners = [(i0 + a, j0 + b) for a in (0, side) for b in (0, side)]
        # a point on a cell face belongs to two cells: one of them has its class
        candidates = [corners] if (i % side and j % side) else None
        if candidates is None:
            candidates = [[(ci + a, cj + b) for a in (0, side) for b in (0, side)]
                          for ci in {i0, max(i0 - side, 0)} if ci <= i <= ci + side
                          for cj in {j0, max(j0 - side, 0)} if cj <= j <= cj + side]
        assert any(all(computed[c] >= 0 and verdict[c] == filled[i, j] for c in cell) for cell in candidates), (i, j)


def test_margin_zero_evaluates_less_and_margin_two_more() -> None:
    x, y = np.meshgrid(np.linspace(-1, 1, 65), np.linspace(-1, 1, 65), indexing="ij")
    growth = 0.5 - np.hypot(x, y)
    verdict = (growth > 0).astype(np.int8)
    fractions = []
    for margin in (0, 1, 2):
        computed, filled = _simulate(verdict, growth, refinement.AdaptiveSpec(levels=3, margin=margin))
        np.testing.assert_array_equal(filled, verdict)
        fractions.append((computed >= 0).mean())
    assert fractions[0] < fractions[1] < fractions[2] < 1


def _tongue() -> tuple[np.ndarray, np.ndarray]:
    """33 x 33, 2 levels (coarse stride 4): a stable disk around the coarse point (8, 8) and a stable tongue from it
    along 9 <= y <= 11 to x = 18, between the coarse rows y = 8 and 12, through two coarse cells whose four corners
    are all unstable (it crosses their edges x = 12 and x = 16 between two unstable coarse points)."""
    x, y = np.meshgrid(np.arange(33.0), np.arange(33.0), indexing="ij")
    stable = (np.hypot(x - 8, y - 8) <= 2) | ((x >= 8) & (x <= 18) & (y >= 9) & (y <= 11))
    return (~stable).astype(np.int8), np.where(stable, -1.0, 1.0)


def test_following_finds_a_boundary_that_leaves_the_refined_cells_between_agreeing_corners() -> None:
    verdict, growth = _tongue()
    computed, filled = _simulate(verdict, growth, refinement.AdaptiveSpec(levels=2, margin=0, follow=False))
    missed = filled != verdict
    assert missed.any() and (verdict[missed] == 0).all()  # part of the tongue, filled from unstable corners
    assert (np.argwhere(missed)[:, 0] > 12).all()
    computed, filled = _simulate(verdict, growth, refinement.AdaptiveSpec(levels=2))  # the default: margin 0, following
    np.testing.assert_array_equal(filled, verdict)
    assert (computed[13:19, 10] >= 0).all()  # followed to the tongue's end
    assert (computed >= 0).mean() < 0.4


def test_follow_rounds_close_each_level_and_end_the_same_in_any_order() -> None:
    """After the sweep no cell of any level has evaluated corners of two classes and a corner not evaluated; a run
    whose rounds are cut in random halves (a killed sweep resumed) evaluates exactly the same points."""
    x, y, z = np.meshgrid(*(np.linspace(-1, 1, 33),) * 3, indexing="ij")
    growth = 0.5 - np.sqrt(x**2 + 1.3 * y**2 + 0.8 * z**2) + 0.15 * np.sin(7 * x) * np.cos(5 * y)
    verdict = (growth > 0).astype(np.int8)
    verdict[(x > 0.4) & (z > 0.3)] = 2
    spec = refinement.resolve_spec(refinement.AdaptiveSpec(), verdict.shape)
    computed, filled = _simulate(verdict, growth, spec)
    np.testing.assert_array_equal(filled, verdict)
    v = np.where(computed >= 0, verdict, -1).astype(np.int8)
    for level in range(spec.levels + 1):
        assert not refinement.follow_targets(level, spec, v, computed).any(), level
    again, filled_again = _simulate(verdict, growth, spec, interrupted=True)
    np.testing.assert_array_equal(again, computed)
    np.testing.assert_array_equal(filled_again, filled)


def test_the_guard_finds_an_island_between_coarse_points_that_the_verdicts_miss() -> None:
    """A nearly neutral paraboloid whose minimum dips below zero between the points of the coarse grid: every
    computed corner is unstable, so refinement by verdict never looks inside; the curvature guard does."""
    h = 2 / 8  # the coarse spacing (33 points, 2 levels: stride 4)
    x, y = np.meshgrid(np.linspace(-1, 1, 33), np.linspace(-1, 1, 33), indexing="ij")
    x0, y0 = 0.5 * h + 1 / 32, 0.5 * h  # between coarse points
    growth = 1e-6 * (((x - x0) ** 2 + (y - y0) ** 2) / h**2 - 0.3)
    verdict = (growth > 0).astype(np.int8)
    island = verdict == 0
    assert 1 <= island.sum() <= 42
    computed, filled = _simulate(verdict, growth, refinement.AdaptiveSpec(levels=2))
    assert (filled[island] == 1).all()  # missed: the sign-only refinement sees one class
    computed, filled = _simulate(verdict, growth, refinement.AdaptiveSpec(levels=2, guard=1.0))
    np.testing.assert_array_equal(filled, verdict)
    assert (computed >= 0).mean() < 0.5  # the guard refines near the island, not everywhere


def test_fill_leaves_no_point_without_a_class_and_sizes_are_checked() -> None:
    assert [refinement.adaptive_size(n, 3) for n in (64, 65, 1)] == [65, 65, 1]
    assert [refinement.default_levels(s) for s in ([65, 65, 9], [33], [9, 5])] == [3, 2, 0]
    with pytest.raises(atlas_plan.SweepError, match=r"axis gamma has 64 points: .* use 65"):
        atlas_plan.make_plan({"gamma": np.geomspace(0.1, 30, 64)}, adaptive=refinement.AdaptiveSpec(levels=3))
    with pytest.raises(atlas_plan.SweepError, match="margin"):
        atlas_plan.make_plan({"gamma": np.geomspace(0.1, 30, 9)}, adaptive={"margin": -1})
    with pytest.raises(atlas_plan.SweepError, match="needs the growth"):
        atlas_plan.make_plan({"f": np.linspace(0.1, 1, 9)}, growth=False, adaptive=True)
    # a dense plan's identity is unchanged (stores written before adaptive sweeps existed still resume)
    assert "adaptive" not in atlas_plan.make_plan({"gamma": [1.0, 2.0]}).identity()


# ------------------------------------------------------------------------------------------------
# against the dense sweep: the model's numbers
# ------------------------------------------------------------------------------------------------

#: γ × f × β × Δ at η = ∞, ξ = 1 (the ranges of the 64^4 benchmark)
AXES_INF = {"gamma": np.geomspace(0.1, 30, 17), "f": np.linspace(0.1, 1.5, 17), "beta": np.linspace(0.05, 0.7, 9),
            "Delta": np.linspace(0.05, 1.0, 9)}


@pytest.mark.slow
def test_eta_inf_verdict_field_equals_the_dense_one_and_values_are_bitwise(tmp_path: Path) -> None:
    fixed = {"xi": 1.0}
    dense = S.sweep(AXES_INF, fixed=fixed, kH=KH, gamma_c=False)
    ad = S.sweep(AXES_INF, fixed=fixed, kH=KH, gamma_c=False, adaptive=True, store=tmp_path / "a.zarr")
    computed = _assert_agrees_with_dense(ad, dense)
    assert set(np.unique(dense.verdict.values)) >= {0, 1}
    assert 0.2 < computed.mean() < 0.9
    info = json.loads(ad.attrs["adaptive"])
    assert info["levels"] == 1 and info["margin"] == 0 and info["guard"] == 0.0 and info["follow"] is True
    assert info["coarse_shape"] == [9, 9, 5, 5]
    assert info["evaluated_fraction"] == pytest.approx(computed.mean())
    assert [lv["points"] for lv in info["per_level"]] == refinement.level_counts(ad.computed.values, 1)
    assert json.loads(ad.computed.attrs["flag_meanings"])["-1"].startswith("not computed")


@pytest.mark.slow
def test_eta_10_with_the_guard_equals_the_dense_verdict_field_where_the_islands_were() -> None:
    """η = 10, ξ = 0 over γ × f × β down to small γ: stable, unstable and undetermined (pole-dense) cells. Stable
    islands of 1-42 points were once found in a nearly neutral region at small γ there; with the certified verdicts
    (docs/physics.md §9) that region is pole-dense (undetermined) or certified stable, with no islands on the grids
    checked (docs/guide/atlases.md, adaptive atlases). The guard must still reproduce the dense field, refining more
    than without."""
    axes = {"gamma": np.geomspace(0.05, 5, 33), "f": np.linspace(0.2, 1.2, 9), "beta": np.linspace(0.08, 0.68, 9)}
    fixed = {"eta": 10.0, "xi": 0.0}
    dense = S.sweep(axes, fixed=fixed, kH=KH, gamma_c=False)
    assert set(np.unique(dense.verdict.values)) == {0, 1, 2}
    assert set(np.unique(dense.verdict_reason.values)) >= {0, 1, 4}  # 4: pole-dense
    guarded = S.sweep(axes, fixed=fixed, kH=KH, gamma_c=False, adaptive={"guard": 1.0})
    computed = _assert_agrees_with_dense(guarded, dense)
    plain = S.sweep(axes, fixed=fixed, kH=KH, gamma_c=False, adaptive=True)
    _assert_agrees_with_dense(plain, dense)
    assert (plain.computed.values >= 0).sum() < computed.sum() < computed.size
    assert json.loads(guarded.attrs["adaptive"])["guard"] == 1.0


# ------------------------------------------------------------------------------------------------
# resumable: a killed adaptive sweep computes only what is missing and ends as an uninterrupted one
# ------------------------------------------------------------------------------------------------

#: ~5-10 s on one thread: finite eta, small chunks (many tasks per level)
RESUME_ARGS = ["sweep", "--adaptive", "--axis", "gamma=0.5:20:33:log", "--axis", "eta=2:1e4:9",
               "--axis", "f=0.5:1.0:9", "--kH", "1e-3:1e3:33:log", "--chunk-points", "16", "--workers", "1",
               "--no-gamma-c", "--quiet"]


def _store_arrays(store: Path) -> dict[str, np.ndarray]:
    group = zarr.open_group(str(store), mode="r")
    return {name: group[name][...] for name in (*GROWTH_VARS, "computed", "verdict_filled")}


#: the same CLI run in a child that SIGKILLs itself right after writing its KILL_AFTER-th level-1 task to the journal:
#: a kill at a known point of the run, however fast the host (polling the store from outside raced the sweep: on a
#: quiet CI host it finished every level between two reads)
KILL_AFTER = 3
_KILLING_CHILD = f"""
import os, signal, sys
from asymslide.atlas import writers
from asymslide.cli import main
write, written = writers.JournalWriter.write, []
def write_then_die(self, task, result):
    write(self, task, result)
    written.append(task.level)
    if written.count(1) == {KILL_AFTER}:
        os.kill(os.getpid(), signal.SIGKILL)
writers.JournalWriter.write = write_then_die
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.slow
def test_killed_adaptive_sweep_resumes_and_equals_an_uninterrupted_run(tmp_path: Path) -> None:
    clean, killed = tmp_path / "clean.zarr", tmp_path / "killed.zarr"
    assert _cli(*RESUME_ARGS, "--out", str(clean)).returncode == 0
    final = _store_arrays(clean)["computed"]
    total = int((final >= 0).sum())
    assert final.max() == 2 and total < final.size
    child = subprocess.run([sys.executable, "-c", _KILLING_CHILD, *RESUME_ARGS, "--out", str(killed)], cwd=ROOT,
                           capture_output=True, text=True, timeout=180)
    assert child.returncode == -signal.SIGKILL, child.stderr
    before = writers.stored_computed(killed)
    done_before = int((before >= 0).sum())
    assert (before == 0).sum() == (final == 0).sum() and 0 < (before == 1).sum() < (final == 1).sum()
    assert done_before < total
    assert writers.JOURNAL in zarr.open_group(str(killed), mode="r")  # the grid variables are written at the end
    # the same command again, in this process, counting the points it evaluates
    spy = mock.patch.object(A, "run_points", wraps=atlas_tasks.run_points)
    axes = dict(atlas_plan.parse_axis(a) for a in ("gamma=0.5:20:33:log", "eta=2:1e4:9", "f=0.5:1.0:9"))
    with spy as run_points:
        S.sweep(axes, kH=np.logspace(-3, 3, 33), chunk_points=16, workers=1, gamma_c=False, adaptive=True,
                store=killed)
    assert sum(call.args[0].points for call in run_points.call_args_list) == total - done_before
    resumed, reference = _store_arrays(killed), _store_arrays(clean)
    for name, values in reference.items():
        np.testing.assert_array_equal(resumed[name], values, err_msg=name)
    assert writers.JOURNAL not in zarr.open_group(str(killed), mode="r")
    a, b = (json.loads(xr.open_zarr(p, consolidated=False).attrs["adaptive"]) for p in (killed, clean))
    assert a == b


def test_resuming_a_finished_adaptive_store_computes_nothing(tmp_path: Path) -> None:
    axes = {"gamma": np.geomspace(0.3, 30, 17), "beta": np.linspace(0.1, 0.6, 9)}
    store = tmp_path / "a.zarr"
    S.sweep(axes, kH=KH, gamma_c=False, adaptive=True, store=store)
    before = _store_arrays(store)
    with mock.patch.object(A, "run_points", wraps=atlas_tasks.run_points) as run_points:
        S.sweep(axes, kH=KH, gamma_c=False, adaptive=True, store=store)
    assert run_points.call_count == 0
    after = _store_arrays(store)
    for name in before:
        np.testing.assert_array_equal(after[name], before[name])


# ------------------------------------------------------------------------------------------------
# the command line: rounding, refusals, info; gamma_c beside an adaptive growth
# ------------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_cli_rounds_axes_up_and_info_prints_the_fraction_per_level(tmp_path: Path) -> None:
    store = tmp_path / "a.zarr"
    made = _cli("sweep", "--adaptive", "--axis", "gamma=0.3:30:30:log", "--axis", "beta=0.1:0.6:8",
                "--fixed", "f=0.9", "--out", str(store))
    assert made.returncode == 0, made.stderr
    assert "axis gamma: 30 points rounded up to 33 = 8·2^2 + 1" in made.stderr
    assert "axis beta: 8 points rounded up to 9 = 2·2^2 + 1" in made.stderr
    assert "level0" in made.stderr and "level2" in made.stderr  # a progress bar per level
    assert "evaluated fraction: " in made.stdout
    ds = xr.open_zarr(store, consolidated=False)
    assert (ds.sizes["gamma"], ds.sizes["beta"]) == (33, 9)
    assert np.isfinite(ds.gamma_c.values).any()  # gamma_c over beta, computed as in the dense sweep
    info = _cli("info", str(store))
    assert info.returncode == 0, info.stderr
    counts = refinement.level_counts(ds.computed.values, 2)
    for needle in ("adaptive: levels 0..2, coarse grid 9 x 3 (stride 4), margin 0, guard off, boundary followed",
                   f"level 0 (stride 4): {counts[0]} points evaluated", f"level 2 (stride 1): {counts[2]} points",
                   "evaluated fraction: ", "verdict_filled (every point): stable", "gamma_c: found at"):
        assert needle in info.stdout, (needle, info.stdout)


@pytest.mark.slow
def test_adaptive_and_dense_stores_refuse_each_other(tmp_path: Path) -> None:
    store = tmp_path / "a.zarr"
    args = ["sweep", "--axis", "gamma=1:10:9:log", "--axis", "beta=0.2:0.4:5", "--no-gamma-c", "--quiet",
            "--out", str(store)]
    assert _cli(*args, "--adaptive").returncode == 0
    dense = _cli(*args)
    assert dense.returncode == 2 and "refusing to resume" in dense.stderr and "another adaptive" in dense.stderr
    other = _cli(*args, "--adaptive", "--margin", "2")
    assert other.returncode == 2 and "another adaptive" in other.stderr
    bad = _cli(*args[:-2], "--margin", "2", "--out", str(tmp_path / "b.zarr"))
    assert bad.returncode == 2 and "add --adaptive" in bad.stderr
    bad = _cli(*args[:-2], "--no-follow", "--out", str(tmp_path / "b.zarr"))
    assert bad.returncode == 2 and "add --adaptive" in bad.stderr
    unfollowed = _cli(*args, "--adaptive", "--no-follow")
    assert unfollowed.returncode == 2 and "another adaptive" in unfollowed.stderr
    listed = _cli("sweep", "--adaptive", "--levels", "2", "--axis", "gamma=1,2,3,4", "--no-gamma-c",
                  "--out", str(tmp_path / "c.zarr"))
    assert listed.returncode == 2 and "axis gamma has 4 points" in listed.stderr
    assert not (tmp_path / "b.zarr").exists() and not (tmp_path / "c.zarr").exists()


def test_the_command_line_default_chunks_are_the_engines() -> None:
    from asymslide import cli

    assert cli.ADAPTIVE_CHUNK_POINTS == refinement.CHUNK_POINTS


@pytest.mark.slow
def test_local_cluster_gives_the_same_adaptive_atlas(tmp_path: Path) -> None:
    from distributed import Client, LocalCluster

    axes = {"gamma": np.geomspace(0.3, 30, 17), "beta": np.linspace(0.1, 0.6, 9), "f": np.array([0.5, 0.7, 0.9])}
    local = S.sweep(axes, kH=KH, gamma_c=False, adaptive=True, chunk_points=32)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        ds = S.sweep(axes, kH=KH, gamma_c=False, adaptive=True, chunk_points=32, store=tmp_path / "a.zarr",
                     client=client)
    for name in (*GROWTH_VARS, "computed", "verdict_filled"):
        np.testing.assert_array_equal(ds[name].values, local[name].values, err_msg=name)
