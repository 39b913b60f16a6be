"""Atlases of the sliding verdict over every branch: the sweep's ``*_all`` variables equal model.sliding_analysis at
every point, a store says which verdicts it holds, old stores read as Rayleigh branch only.

Small grids only (about 10 ms a point at eta = inf).
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from asymslide import model
from asymslide.atlas import executor, schema, summary, writers
from asymslide.atlas import plan as atlas_plan
from asymslide.atlas import sweep as S

ROOT = Path(__file__).resolve().parents[2]
KH = np.logspace(-3, 3, 25)
AXES = {"gamma": np.array([1.0, 2.0, 3.0]), "beta": np.array([0.3, 0.6])}
# gamma = 2 at the paper's f = 0.9, beta = 0.3, eta = inf: the Rayleigh branch is stable (gamma_c = 2.41), sliding is
# not (a backward root just beyond the shear speed, docs/physics.md §14.9)
RAYLEIGH_STABLE_SLIDING_UNSTABLE = (1, 0)


def _cli(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "asymslide", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=timeout)


def _expected(axes: dict[str, np.ndarray], fixed: dict[str, float]) -> model.SlidingResult:
    n = len(axes)
    args = {name: np.asarray(v).reshape([-1 if i == j else 1 for j in range(n)])
            for i, (name, v) in enumerate(axes.items())}
    return model.sliding_analysis(**{**atlas_plan.DEFAULT_FIXED, **fixed, **args})


def _assert_sliding_equal(ds: xr.Dataset, r: model.SlidingResult) -> None:
    np.testing.assert_array_equal(ds["growth_all"].values, r.growth)
    np.testing.assert_array_equal(ds["kH_at_max_all"].values, r.kH_at_max)
    np.testing.assert_array_equal(ds["re_z_at_max_all"].values, r.z_at_max.real)
    np.testing.assert_array_equal(ds["family_all"].values, r.family)
    np.testing.assert_array_equal(ds["verdict_all"].values, r.verdict)
    np.testing.assert_array_equal(ds["verdict_reason_all"].values, r.verdict_reason)
    np.testing.assert_array_equal(ds["max_at_end_all"].values, r.max_at_end.astype(np.int8))
    np.testing.assert_array_equal(ds["lower_bound_all"].values, r.lower_bound.astype(np.int8))


@pytest.mark.slow
def test_sliding_variables_equal_sliding_analysis_and_name_both_verdicts() -> None:
    ds = S.sweep(AXES, kH=KH, gamma_c=False, sliding=True)
    r = _expected(AXES, {})
    _assert_sliding_equal(ds, r)
    np.testing.assert_array_equal(ds["kH_sliding"].values, model.SLIDING_KH)
    assert ds["verdict_all"].attrs["floor"] == model.DEFAULT_FLOOR
    i = RAYLEIGH_STABLE_SLIDING_UNSTABLE
    assert int(ds["verdict"].values[i]) == 0 and int(ds["verdict_all"].values[i]) == 1
    assert model.FAMILIES[int(ds["family_all"].values[i])].startswith("intersonic")
    assert float(ds["growth_all"].values[i]) > model.DEFAULT_FLOOR
    # the sliding maximum is never below the Rayleigh branch's where both are unstable and certified
    both = (ds["verdict"].values == 1) & (ds["verdict_reason_all"].values == model.sliding.S_UNSTABLE)
    assert both.any()
    assert np.all(ds["growth_all"].values[both] >= ds["growth"].values[both] * (1 - 1e-12))


@pytest.mark.slow
def test_finite_eta_a_floor_and_a_kh_grid_of_ones_own() -> None:
    axes = {"gamma": np.array([2.0, 5.0])}
    spec = atlas_plan.SlidingSpec(tuple(np.logspace(-1, 1, 9)), 1e-4)
    ds = S.sweep(axes, fixed={"eta": 10.0}, kH=KH, gamma_c=False, sliding=spec)
    r = model.sliding_analysis(**{**atlas_plan.DEFAULT_FIXED, "eta": 10.0, "gamma": axes["gamma"]},
                               kH=np.logspace(-1, 1, 9), floor=1e-4)
    _assert_sliding_equal(ds, r)
    assert (ds["lower_bound_all"].values == 1).all()
    assert ds["growth_all"].attrs["floor"] == 1e-4


@pytest.mark.slow
def test_a_store_with_sliding_resumes_reads_back_and_exports(tmp_path: Path) -> None:
    store = tmp_path / "a.zarr"
    S.sweep(AXES, kH=KH, gamma_c=False, sliding=True, store=store)
    again = S.sweep(AXES, kH=KH, gamma_c=False, sliding=True, store=store)  # resumed: nothing left to compute
    _assert_sliding_equal(again, _expected(AXES, {}))
    assert all(flags.all() for flags in writers.done_chunks(store).values()) and "sliding" in writers.done_chunks(store)
    with pytest.raises(atlas_plan.SweepError, match="refusing to resume"):  # another floor is another plan
        S.sweep(AXES, kH=KH, gamma_c=False, sliding=atlas_plan.SlidingSpec(floor=1e-5), store=store)
    nc = S.export_netcdf(store, tmp_path / "a.nc")
    back = xr.open_dataset(nc, engine="scipy")
    np.testing.assert_array_equal(back["verdict_all"].values, again["verdict_all"].values)
    text = "\n".join(summary.iter_summary(store))
    assert "Rayleigh branch verdict coverage: 100.0 % of 6" in text
    assert "sliding verdict coverage: 100.0 % of 6" in text
    assert "Rayleigh branch stable but sliding unstable at" in text


def test_a_plan_without_sliding_keeps_its_identity_and_its_store_says_rayleigh_only(tmp_path: Path) -> None:
    plan = atlas_plan.make_plan(AXES, kH=KH)
    assert "sliding" not in plan.identity()  # stores written before the sliding variables resume as before
    store = tmp_path / "old.zarr"
    S.sweep(AXES, kH=KH, gamma_c=False, store=store)
    text = "\n".join(summary.iter_summary(store))
    assert "covers the Rayleigh branch only" in text and "sliding verdict coverage" not in text


@pytest.mark.parametrize(("kwargs", "message"), [
    (dict(sliding=atlas_plan.SlidingSpec(floor=0.0)), "floor"),
    (dict(sliding=atlas_plan.SlidingSpec(floor=math.nan)), "floor"),
    (dict(sliding=atlas_plan.SlidingSpec(kH=(1.0,))), "sliding kH grid"),
    (dict(sliding=atlas_plan.SlidingSpec(kH=(1.0, 0.5))), "sliding kH grid"),
])
def test_bad_sliding_settings_are_refused(kwargs: dict, message: str) -> None:
    with pytest.raises(atlas_plan.SweepError, match=message):
        atlas_plan.make_plan(AXES, kH=KH, **kwargs)


def test_an_adaptive_sweep_on_the_rayleigh_verdict_refuses_the_sliding_one_with_a_reason() -> None:
    with pytest.raises(atlas_plan.SweepError, match="cannot give the sliding verdict"):
        atlas_plan.make_plan({"gamma": np.linspace(1, 3, 5)}, kH=KH, adaptive=dict(levels=1, verdict="rayleigh"),
                             sliding=True)


@pytest.mark.slow
def test_cli_sweep_sliding_and_info(tmp_path: Path) -> None:
    out = tmp_path / "cli.zarr"
    r = _cli("sweep", "--axis", "gamma=1:3:3", "--fixed", "beta=0.3", "--kH", "1e-3:1e3:25:log", "--no-gamma-c",
             "--sliding", "--quiet", "--out", str(out))
    assert r.returncode == 0, r.stderr
    info = _cli("info", str(out))
    assert info.returncode == 0, info.stderr
    assert "sliding verdict coverage" in info.stdout and "Rayleigh branch verdict" in info.stdout
    bad = _cli("sweep", "--axis", "gamma=1:3:3", "--sliding", "--floor", "abc", "--quiet", "--out",
               str(tmp_path / "bad.zarr"))
    assert bad.returncode != 0 and "--floor" in bad.stderr and "not a number" in bad.stderr
    assert not (tmp_path / "bad.zarr").exists()


def test_a_gamma_axis_of_one_value_without_gamma_c_is_a_valid_sweep() -> None:
    """A one-value gamma axis gave gamma_range (v, v) and a refusal even without gamma_c; it now searches the default
    range (1e-2, 1e3) when gamma_c is asked for."""
    plan = atlas_plan.make_plan({"gamma": [3.0]}, kH=KH, gamma_c=False, sliding=True)
    assert plan.gamma_range == (1e-2, 1e3)
    ds = S.sweep({"gamma": [3.0]}, kH=KH, gamma_c=False, sliding=True)
    assert float(ds["growth_all"].values[0]) == float(model.sliding_analysis(gamma=3.0, f=0.9, beta=0.3).growth)


# the threshold of sliding in gamma over every branch (asymslide sweep --sliding-thresholds)
THRESHOLD_AXES = {"gamma": np.geomspace(0.5, 4.0, 8), "f": np.array([0.5, 0.9, 1.2])}


@pytest.mark.slow
def test_sliding_thresholds_equal_the_models_and_resume(tmp_path: Path) -> None:
    """gamma_c_all and its crossings are model.critical_gammas(branches="all") over the other axes (its first
    certified crossing and status), beside the Rayleigh branch's gamma_c; written chunk by chunk and resumed; info
    names both; a plan without them keeps its identity."""
    store = tmp_path / "t.zarr"
    spec = atlas_plan.SlidingSpec(thresholds=True)
    assert "thresholds" not in atlas_plan.SlidingSpec().identity() and spec.identity()["thresholds"] is True
    S.sweep(THRESHOLD_AXES, fixed={"beta": 0.3}, kH=KH, sliding=spec, store=store)
    ds = S.sweep(THRESHOLD_AXES, fixed={"beta": 0.3}, kH=KH, sliding=spec, store=store)  # nothing left
    assert writers.done_chunks(store)["gamma_c_all"].all()
    ref = model.critical_gammas(f=THRESHOLD_AXES["f"], beta=0.3, branches="all", gamma_range=(0.5, 4.0))
    np.testing.assert_array_equal(ds["gamma_c_all_crossing"].values, ref.value)
    np.testing.assert_array_equal(ds["gamma_c_all_crossing_reason"].values, ref.reason)
    np.testing.assert_array_equal(ds["gamma_c_all_reason"].values, ref.status)
    first = [model.critical_gamma(f=f, beta=0.3, branches="all", gamma_range=(0.5, 4.0)) for f in THRESHOLD_AXES["f"]]
    np.testing.assert_array_equal(ds["gamma_c_all"].values, first)
    rayleigh = ds["gamma_c"].values
    assert np.all(np.asarray(first) < np.where(np.isnan(rayleigh), np.inf, rayleigh))  # sliding goes first here
    assert "over every branch" in ds["gamma_c_all"].attrs["long_name"]
    text = "\n".join(summary.iter_summary(store))
    assert "gamma_c_all (sliding, every branch): found at 3 of 3 points" in text and "gamma_c: found at" in text


@pytest.mark.slow
def test_cli_sliding_thresholds(tmp_path: Path) -> None:
    out = tmp_path / "cli.zarr"
    r = _cli("sweep", "--axis", "gamma=0.5:4:5:log", "--axis", "f=0.9:1.2:2", "--fixed", "beta=0.3", "--kH",
             "1e-3:1e3:25:log", "--sliding-thresholds", "--quiet", "--out", str(out))
    assert r.returncode == 0, r.stderr
    ds = xr.open_zarr(out, consolidated=False)
    assert "gamma_c_all" in ds and "verdict_all" in ds  # implies --sliding
    assert np.isfinite(ds["gamma_c_all"].values).all()


@pytest.mark.slow
def test_sliding_tasks_run_in_processes_and_give_the_same_bits(monkeypatch: pytest.MonkeyPatch) -> None:
    """The sliding verdict holds the GIL, so with two workers its tasks run in two processes (the growth's on
    threads); the numbers are bitwise those of one worker."""
    handed: list[list[str]] = []
    real = executor._execute_in_processes

    def spy(todo, *args):
        handed.append([t.kind for t in todo])
        return real(todo, *args)

    monkeypatch.setattr(executor, "_execute_in_processes", spy)
    two = S.sweep(AXES, kH=KH, gamma_c=False, sliding=True, workers=2, chunk_points=1)
    assert handed and all(kind == "sliding" for kinds in handed for kind in kinds) and len(handed[0]) == 6
    handed.clear()
    one = S.sweep(AXES, kH=KH, gamma_c=False, sliding=True, workers=1, chunk_points=1)
    assert handed == []  # one worker: in this process
    for name in (*schema.SLIDING_VARS, *schema.GROWTH_VARS):
        np.testing.assert_array_equal(two[name].values, one[name].values, err_msg=name)
