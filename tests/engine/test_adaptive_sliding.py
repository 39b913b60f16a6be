"""Adaptive atlases of the sliding verdict (``asymslide sweep --adaptive --verdict sliding``): both verdicts' fields
equal the dense sweep's at every point from a fraction of the points, bitwise the same values where computed, resumable
after a kill (journal entries that name their rows), refusals, and what info prints.

The dense sweep with ``sliding=True`` (tests/engine/test_sweep_sliding.py checks it against model.sliding_analysis) is
the reference. Small grids at eta = inf: every test runs in seconds.
"""

from __future__ import annotations

import json
import math
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
#: the beta-gamma plane at eta = inf where the Rayleigh branch's boundary and the sliding one differ
AXES = {"beta": np.linspace(0.2, 0.7, 17), "gamma": np.geomspace(0.3, 30, 17)}
FIXED = {"eta": math.inf}
VALUES = (*schema.GROWTH_VARS, *schema.SLIDING_VARS)


def _cli(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "asymslide", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=timeout)


@pytest.fixture(scope="module")
def dense() -> xr.Dataset:
    return S.sweep(AXES, fixed=FIXED, kH=KH, gamma_c=False, sliding=True)


def test_refinement_classes_flag_a_cell_where_either_verdict_changes() -> None:
    """Synthetic fields: the Rayleigh branch stable everywhere, the sliding verdict unstable on the right half. On the
    Rayleigh verdict alone no cell is refined; on the pair the cells the sliding boundary crosses are."""
    n = 9
    rayleigh = np.zeros((n, n), np.int8)
    sliding = np.zeros((n, n), np.int8)
    sliding[:, 6:] = 1
    computed = np.full((n, n), -1, np.int8)
    computed[::4, ::4] = 0
    growth = np.full((n, n), -0.1)
    spec = refinement.AdaptiveSpec(levels=2)
    alone = refinement.refine_targets(1, spec, rayleigh, growth, computed)
    pair = refinement.refine_targets(1, spec, rayleigh, growth, computed,
                                     refinement.refinement_classes(rayleigh, sliding))
    assert not alone.any()
    assert pair.any() and not pair[:, :4].any()  # only the cells between x = 4 and 8, where sliding changes
    assert (refinement.refinement_classes(rayleigh, np.full((n, n), -1, np.int8)) == -1).all()  # not computed stays -1


@pytest.mark.slow
def test_the_sliding_verdict_field_equals_the_dense_one_from_a_fraction_of_the_points(dense: xr.Dataset) -> None:
    ad = S.sweep(AXES, fixed=FIXED, kH=KH, gamma_c=False, adaptive=refinement.AdaptiveSpec(levels=2), sliding=True)
    computed = ad.computed.values >= 0
    assert 0 < computed.sum() < 0.6 * computed.size
    for name in VALUES:  # bitwise (NaN == NaN) at the computed points: both verdicts' variables
        np.testing.assert_array_equal(ad[name].values[computed], dense[name].values[computed], err_msg=name)
    np.testing.assert_array_equal(ad.verdict_filled_all.values, dense.verdict_all.values)
    np.testing.assert_array_equal(ad.verdict_filled.values, dense.verdict.values)
    # the plane has both boundaries, and they differ (else the pair refinement would not be shown to matter)
    both = dense.verdict.values, dense.verdict_all.values
    assert all(len(np.unique(v)) > 1 for v in both) and not np.array_equal(*both)
    summary = json.loads(ad.attrs["adaptive"])
    assert summary["verdict"] == "sliding" and summary["evaluated"] == computed.sum()


def test_refining_the_rayleigh_verdict_alone_would_miss_the_sliding_boundary(dense: xr.Dataset) -> None:
    """Why the pair is refined: the points a Rayleigh-only refinement evaluates do not fill the sliding verdict
    right (the same grid, the sliding verdict filled from the cells of a Rayleigh-only sweep)."""
    ray = S.sweep(AXES, fixed=FIXED, kH=KH, gamma_c=False, adaptive=refinement.AdaptiveSpec(levels=2))
    computed = ray.computed.values
    sliding_there = np.where(computed >= 0, dense.verdict_all.values, -1).astype(np.int8)
    filled = refinement.fill_classes(sliding_there, computed, 2)
    assert (filled != dense.verdict_all.values).any()


def test_plans_and_refusals() -> None:
    ray = atlas_plan.make_plan(AXES, fixed=FIXED, kH=KH, gamma_c=False, adaptive=dict(levels=2))
    assert "verdict" not in ray.identity()["adaptive"] and ray.sliding is None  # older stores keep their identity
    implied = atlas_plan.make_plan(AXES, fixed=FIXED, kH=KH, gamma_c=False, adaptive=dict(levels=2, verdict="sliding"))
    assert implied.sliding == atlas_plan.SlidingSpec() and implied.identity()["adaptive"]["verdict"] == "sliding"
    chosen = atlas_plan.make_plan(AXES, fixed=FIXED, kH=KH, gamma_c=False, adaptive=dict(levels=2), sliding=True)
    assert chosen.adaptive.verdict == "sliding"
    with pytest.raises(atlas_plan.SweepError, match="adaptive verdict must be one of rayleigh, sliding"):
        atlas_plan.make_plan(AXES, fixed=FIXED, kH=KH, adaptive=dict(levels=2, verdict="all"))
    with pytest.raises(atlas_plan.SweepError, match="cannot give the sliding verdict"):
        atlas_plan.make_plan(AXES, fixed=FIXED, kH=KH, adaptive=dict(levels=2, verdict="rayleigh"), sliding=True)


def test_a_journal_entry_written_before_entries_named_their_rows_is_read(tmp_path: Path) -> None:
    """Stores killed by an earlier version hold journal arrays without the ``rows`` attribute: the growth rows."""
    group = zarr.open_group(str(tmp_path / "old.zarr"), mode="w")
    rows = np.full((2 + len(writers._ROWS), 4), np.nan)
    rows[0, :2], rows[1, :2], rows[2, :2] = (5, 7), 1, (0.25, -0.5)
    group.require_group(writers.JOURNAL).create_array("L1-old", data=rows)
    [(index, level, values)] = writers.read_journal(group)
    assert index.tolist() == [5, 7] and level == 1 and list(values) == list(writers._ROWS)
    assert values["growth"].tolist() == [0.25, -0.5]


#: the CLI run of a sliding adaptive sweep (small chunks: several tasks per level)
SLIDING_ARGS = ["sweep", "--adaptive", "--verdict", "sliding", "--levels", "2", "--axis", "beta=0.2:0.7:17",
                "--axis", "gamma=0.3:30:17:log", "--fixed", "eta=inf", "--kH", "1e-3:1e3:49:log", "--chunk-points",
                "16", "--workers", "1", "--no-gamma-c", "--quiet"]
#: a child running SLIDING_ARGS that SIGKILLs itself after writing its 2nd level-1 task to the journal
_KILLING_CHILD = """
import os, signal, sys
from asymslide.atlas import writers
from asymslide.cli import main
write, written = writers.JournalWriter.write, []
def write_then_die(self, task, result):
    write(self, task, result)
    written.append(task.level)
    if written.count(1) == 2:
        os.kill(os.getpid(), signal.SIGKILL)
writers.JournalWriter.write = write_then_die
sys.exit(main(sys.argv[1:]))
"""


def _stored(store: Path) -> dict[str, np.ndarray]:
    group = zarr.open_group(str(store), mode="r")
    return {name: group[name][...] for name in (*VALUES, "computed", "verdict_filled", "verdict_filled_all")}


@pytest.mark.slow
def test_a_killed_sliding_sweep_resumes_and_equals_an_uninterrupted_run(tmp_path: Path, dense: xr.Dataset) -> None:
    clean, killed = tmp_path / "clean.zarr", tmp_path / "killed.zarr"
    made = _cli(*SLIDING_ARGS, "--out", str(clean))
    assert made.returncode == 0, made.stderr
    reference = _stored(clean)
    np.testing.assert_array_equal(reference["verdict_filled_all"], dense.verdict_all.values)
    child = subprocess.run([sys.executable, "-c", _KILLING_CHILD, *SLIDING_ARGS, "--out", str(killed)], cwd=ROOT,
                           capture_output=True, text=True, timeout=300)
    assert child.returncode == -signal.SIGKILL, child.stderr
    journal = zarr.open_group(str(killed), mode="r")[writers.JOURNAL]
    assert all(entry.attrs["rows"] == list(writers._ROWS) + list(schema.SLIDING_VARS) for _, entry in journal.arrays())
    before = writers.stored_computed(killed)
    total, done = int((reference["computed"] >= 0).sum()), int((before >= 0).sum())
    assert 0 < done < total
    # the same sweep again, in this process (the plan the command line makes), counting the points it evaluates
    axes = dict(atlas_plan.parse_axis(a) for a in ("beta=0.2:0.7:17", "gamma=0.3:30:17:log"))
    sliding = atlas_plan.SlidingSpec(tuple(atlas_plan.parse_axis("kH=1e-2:1e2:17:log")[1]), 1e-6)
    with mock.patch.object(A, "run_points", wraps=atlas_tasks.run_points) as run_points:
        S.sweep(axes, fixed=FIXED, kH=np.logspace(-3, 3, 49), chunk_points=16, workers=1, gamma_c=False,
                adaptive=refinement.AdaptiveSpec(levels=2, verdict="sliding"), sliding=sliding, store=killed)
    assert sum(call.args[0].points for call in run_points.call_args_list) == total - done
    after = _stored(killed)
    for name, values in reference.items():
        np.testing.assert_array_equal(after[name], values, err_msg=name)
    assert writers.JOURNAL not in zarr.open_group(str(killed), mode="r")
    info = _cli("info", str(killed))
    assert info.returncode == 0, info.stderr
    assert "refined where the sliding verdict (every branch) or the Rayleigh branch's changes" in info.stdout
    assert "verdict_filled_all (sliding, every point)" in info.stdout and "sliding verdict coverage" in info.stdout


def test_cli_refuses_verdict_without_adaptive(tmp_path: Path) -> None:
    r = _cli("sweep", "--verdict", "sliding", "--axis", "gamma=1:3:3", "--quiet", "--out", str(tmp_path / "a.zarr"))
    assert r.returncode != 0 and "--verdict belong to an adaptive sweep" in r.stderr
    assert not (tmp_path / "a.zarr").exists()
