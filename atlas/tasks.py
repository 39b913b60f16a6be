"""Tasks: pure functions of one chunk of a plan (or of one adaptive level's points), run wherever the executor puts
them.

A :class:`Task` is one chunk of one kind of variables (``growth``, ``gamma_c``, ``gamma_c_all``, ``count``,
``sliding``): its index ranges and axis values, so that a worker needs nothing else. :func:`run_task` computes it
with the model's calls and nothing else; a :class:`PointTask` holds the scattered points of one Zarr chunk that an
adaptive level evaluates (:func:`run_points`), computed by the same functions, so the dense and the adaptive sweep
give the same bits at a point.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from asymslide import model

from .plan import PARAMETERS, CountSpec, Plan, SlidingSpec, sliding_thresholds
from .schema import CROSSINGS, all_branches_name

#: the task kinds whose model calls hold the GIL (run in processes: :func:`asymslide.atlas.executor.execute`)
GIL_KINDS = ("sliding", "gamma_c_all")


@dataclass(frozen=True)
class Task:
    """One chunk of one variable group: `kind` ("growth", "gamma_c" or "count"), its index among the group's
    chunks, its index ranges and the axis values of the chunk (so a worker needs nothing else)."""

    kind: str
    index: int
    block: tuple[tuple[int, int], ...]
    names: tuple[str, ...]
    values: tuple[tuple[float, ...], ...]
    fixed: tuple[tuple[str, float], ...]
    kH: tuple[float, ...]
    rtol: float | None
    gamma_range: tuple[float, float]
    count: CountSpec | None
    sliding: SlidingSpec | None = None

    @property
    def points(self) -> int:
        """The number of grid points in the task."""
        return math.prod(len(v) for v in self.values)

    @property
    def holds_gil(self) -> bool:
        """Whether the task's model calls hold the GIL (the sliding verdict and its thresholds: Python around the
        compiled kernels), so that threads do not run it in parallel: the executor gives it processes."""
        return self.kind in GIL_KINDS


def _params(task: Task) -> tuple[tuple[int, ...], np.ndarray]:
    """The chunk's grid points as growth_chunk's (6, n) parameter rows (gamma, f, beta, eta, Delta, xi)."""
    shape = tuple(len(v) for v in task.values)
    mesh = np.meshgrid(*(np.asarray(v) for v in task.values), indexing="ij")
    columns = dict(zip(task.names, (m.ravel() for m in mesh), strict=True))
    n = math.prod(shape)
    fixed = dict(task.fixed)
    # a parameter neither in the chunk nor fixed is the one a threshold task solves for (its row is ignored)
    rows = [columns[p] if p in columns else np.full(n, fixed.get(p, math.nan)) for p in PARAMETERS]
    return shape, np.ascontiguousarray(np.stack(rows))


def growth_arrays(s: np.ndarray, params: np.ndarray, rtol: float | None) -> dict[str, np.ndarray]:
    """The growth variables (1-D, one value per column of `params`) of :func:`model.growth_chunk` on the ln kH grid
    `s`: the same operations as model.growth_analysis, so the values are bitwise equal (each point is computed on
    its own: the dense and the adaptive sweep give the same bits at a point whatever else a chunk holds)."""
    r = model.growth_result(model.growth_chunk(s, params, rtol))  # as model.growth_analysis
    return {"growth": r.growth, "kH_at_max": r.kH_at_max, "kH_min": r.kH_min, "kH_max": r.kH_max,
            "n_masked": r.n_masked.astype(np.int16), "verdict": r.verdict, "verdict_reason": r.verdict_reason}


def sliding_arrays(spec: SlidingSpec, params: np.ndarray) -> dict[str, np.ndarray]:
    """The sliding variables (1-D, one per column of `params`) of :func:`model.sliding_chunk`: the numbers
    :func:`model.sliding_analysis` gives at the same point."""
    rows = dict(zip(model.SLIDING_ROWS, model.sliding_chunk(np.log(np.asarray(spec.kH)), params, spec.floor),
                    strict=True))
    reason = rows["verdict_reason_all"].astype(np.int8)
    return {"growth_all": rows["growth_all"], "kH_at_max_all": np.exp(rows["ln_kH_at_max_all"]),
            "re_z_at_max_all": rows["re_z_at_max_all"], "family_all": model.family_codes(rows["family_all"]),
            "verdict_all": model.sliding_verdict(reason), "verdict_reason_all": reason,
            "max_at_end_all": (rows["max_at_end_all"] == 1.0).astype(np.int8),
            "lower_bound_all": np.isfinite(params[PARAMETERS.index("eta")]).astype(np.int8)}


def run_task(task: Task) -> dict[str, np.ndarray]:
    """Compute one chunk (the only code that runs on a worker): model calls, nothing else."""
    shape, params = _params(task)
    s = np.log(np.asarray(task.kH))
    if task.kind == "growth":
        return {name: arr.reshape(shape) for name, arr in growth_arrays(s, params, task.rtol).items()}
    if task.kind == "gamma_c":
        return _crossing_arrays(model.crossings_chunk("gamma", s, params, task.gamma_range, task.rtol, CROSSINGS),
                                shape)
    if task.kind == "gamma_c_all":
        assert task.sliding is not None
        c = model.crossings_chunk("gamma", np.log(np.asarray(task.sliding.kH)), params, task.gamma_range, None,
                                  CROSSINGS, "all", task.sliding.floor)
        return {all_branches_name(name): arr for name, arr in _crossing_arrays(c, shape).items()}
    if task.kind == "count":
        assert task.count is not None
        re_max, im_min, im_max = task.count.window
        counts = np.empty((params.shape[1], len(task.count.kH)), np.int16)
        for i in range(params.shape[1]):
            p = dict(zip(PARAMETERS, (float(x) for x in params[:, i]), strict=True))
            for j, k in enumerate(task.count.kH):
                try:
                    counts[i, j] = model.unstable_count(k, **p, re_max=re_max, im_min=im_min, im_max=im_max)
                except (RuntimeError, ValueError):
                    counts[i, j] = -1  # the count failed (flag in the variable's attributes)
        return {"unstable_count": counts.reshape((*shape, len(task.count.kH)))}
    if task.kind == "sliding":
        assert task.sliding is not None
        return {name: arr.reshape(shape) for name, arr in sliding_arrays(task.sliding, params).items()}
    raise ValueError(f"unknown task kind {task.kind!r}")


def _crossing_arrays(c: model.Crossings, shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """The threshold variables of one chunk from model.crossings_chunk: the first certified crossing, its status,
    every crossing (last dimension ``crossing``) and their summaries."""
    k = (*shape, CROSSINGS)
    return {"gamma_c": c.first.reshape(shape), "gamma_c_reason": c.status.astype(np.int8).reshape(shape),
            "gamma_c_crossing": c.value.reshape(k), "gamma_c_location": c.location.reshape(k),
            "gamma_c_kH": c.kH.reshape(k), "gamma_c_z": c.z.reshape(k),
            "gamma_c_direction": c.direction.astype(np.int8).reshape(k),
            "gamma_c_crossing_reason": c.reason.astype(np.int8).reshape(k),
            "gamma_c_n_crossings": c.count.astype(np.int16).reshape(shape),
            "gamma_c_complete": c.complete.astype(np.int8).reshape(shape)}


def tasks(plan: Plan, kinds: Sequence[str] | None = None) -> dict[str, list[Task]]:
    """Every task of the plan, per kind."""
    common = dict(fixed=tuple(plan.fixed.items()), kH=plan.kH, rtol=plan.rtol, gamma_range=plan.gamma_range,
                  count=plan.count, sliding=plan.sliding)
    groups: dict[str, tuple[tuple[str, ...], list]] = {}
    if plan.growth:
        groups["growth"] = (plan.names, plan.growth_blocks())
    if plan.gamma_c:
        groups["gamma_c"] = (plan.gamma_c_names, plan.gamma_c_blocks())
    if sliding_thresholds(plan):
        groups["gamma_c_all"] = (plan.gamma_c_names, plan.gamma_c_blocks())
    if plan.count is not None:
        groups["count"] = (plan.names, plan.count_blocks())
    if plan.sliding is not None:
        groups["sliding"] = (plan.names, plan.sliding_blocks())
    out: dict[str, list[Task]] = {}
    for kind, (names, blocks) in groups.items():
        if kinds is not None and kind not in kinds:
            continue
        out[kind] = [Task(kind, i, b, names, tuple(plan.axes[n][a:z] for n, (a, z) in zip(names, b, strict=True)),
                          **common) for i, b in enumerate(blocks)]
    return out


#: at most this many points per task of a level (a task never spans two Zarr chunks)
TASK_POINTS = 8192
#: at most this many points per task where the sweep also computes the sliding verdict (~10 ms a point at eta = inf,
#: ~0.1 s at finite eta: 128 points keep both threads busy on a coarse level and lose little to a kill)
SLIDING_TASK_POINTS = 128


@dataclass(frozen=True)
class PointTask:
    """The points of one Zarr chunk that one level evaluates (at most :func:`task_points`): their flat indices in
    the grid and their parameter rows (gamma, f, beta, eta, Delta, xi), so a worker needs nothing else."""

    kind: str
    index: int
    level: int
    chunk: int
    flat: np.ndarray
    params: np.ndarray
    kH: tuple[float, ...]
    rtol: float | None
    #: the sliding verdict's spec (asymslide.atlas.plan.SlidingSpec) where the sweep refines it; None: Rayleigh only
    sliding: Any = None

    @property
    def points(self) -> int:
        """The number of grid points in the task."""
        return int(self.flat.size)

    @property
    def holds_gil(self) -> bool:
        """Whether its model calls hold the GIL: the sliding verdict's (:attr:`Task.holds_gil`)."""
        return self.sliding is not None


def run_points(task: PointTask) -> dict[str, np.ndarray]:
    """Evaluate one task's points (on a worker): :func:`growth_arrays` and, where the sweep
    refines the sliding verdict, :func:`sliding_arrays`, as the dense sweep."""
    out = growth_arrays(np.log(np.asarray(task.kH)), task.params, task.rtol)
    if task.sliding is not None:
        out.update(sliding_arrays(task.sliding, task.params))
    return out


def task_points(plan: Plan) -> int:
    """The most points a task of the plan holds (a journal entry's chunk): :data:`TASK_POINTS`, or
    :data:`SLIDING_TASK_POINTS` where the sliding verdict is computed too."""
    return SLIDING_TASK_POINTS if plan.sliding is not None else TASK_POINTS
