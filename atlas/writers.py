"""Writers: where the results of tasks go. One interface (:class:`Writer`) for a dataset in memory, a Zarr store
(chunk by chunk, each marked done after its data: resumable) and an adaptive store's journal.

A store is created by xarray (the template dataset of :mod:`asymslide.atlas.schema`: coordinates, attributes,
encodings) beside its final path and renamed into place, and read back with ``xarray.open_zarr``. Each finished
chunk is written at once (an xarray region write) and then marked done (``done_*`` flags, one Zarr chunk per flag):
Ctrl-C, a killed process or a lost worker loses at most the chunks in flight, and running the same sweep again
computes only the chunks not marked done. A store remembers its plan and the model's fingerprint; a sweep with
another plan or another model refuses to resume it, saying why, and leaves it untouched.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path
from typing import Protocol

import numpy as np

from . import __version__
from .plan import Plan, SweepError
from .refinement import NOT_COMPUTED
from .schema import (
    CROSSING_ALL_VARS,
    CROSSING_VARS,
    CROSSINGS,
    GROWTH_VARS,
    SLIDING_VARS,
    encoding,
    git_revision,
    model_fingerprint,
    template,
)
from .tasks import TASK_POINTS, PointTask, Task, task_points


def _refuse(store: Path, why: str) -> SweepError:
    return SweepError(f"refusing to resume {store}: {why}. Nothing was written; use another --out or remove it.")


def check_resumable(store: Path, plan: Plan) -> None:
    """SweepError saying why the existing store cannot continue this plan (another plan or another model)."""
    import xarray as xr

    try:
        ds = xr.open_zarr(store, consolidated=False)
    except Exception as exc:  # noqa: BLE001 (any failure to read it means: not ours)
        raise _refuse(store, f"it is not a readable atlas ({type(exc).__name__}: {exc})") from None
    attrs = ds.attrs
    if "plan" not in attrs or "model_fingerprint" not in attrs:
        raise _refuse(store, "it was not written by asymslide sweep")
    theirs, ours = json.loads(attrs["plan"]), plan.identity()
    if theirs != ours:
        raise _refuse(store, "it was written with " + _plan_difference(theirs, ours))
    if attrs["model_fingerprint"] != model_fingerprint():
        raise _refuse(store, f"it was written by another model version (asymslide {attrs.get('asymslide_version')}, "
                             f"git {attrs.get('git_revision')}, model {attrs['model_fingerprint'][:12]}; this is "
                             f"asymslide {__version__}, git {git_revision()}, model {model_fingerprint()[:12]})")


def _plan_difference(theirs: dict, ours: dict) -> str:
    def axes_text(p: dict) -> str:
        return ", ".join(f"{k}({len(v)}: {v[0]:g}..{v[-1]:g})" for k, v in p["axes"].items())

    if theirs.get("axes") != ours["axes"]:
        return f"other axes: {axes_text(theirs)}; this sweep asks for {axes_text(ours)}"
    for key in ("adaptive", "fixed", "kH", "rtol", "gamma_c", "gamma_range", "count", "chunks"):
        if theirs.get(key) != ours.get(key):  # "adaptive" is in adaptive plans only
            return f"another {key}: {theirs.get(key)!r:.200}; this sweep asks for {ours.get(key)!r:.200}"
    return "another plan"


def done_chunks(store: Path) -> dict[str, np.ndarray]:
    """kind -> boolean array: which chunks of the store are written."""
    import xarray as xr

    ds = xr.open_zarr(store, consolidated=False)
    return {name[len("done_"):]: ds[name].values.astype(bool) for name in ds.data_vars if name.startswith("done_")}


def store_stamp(store: str | os.PathLike) -> str:
    """A short text that changes whenever a sweep writes to the store (its done flags; an adaptive sweep's summary,
    written when its grid variables are): readers cache an atlas by it."""
    import xarray as xr

    ds = xr.open_zarr(Path(store), consolidated=False)
    flags = {name: int(ds[name].values.sum()) for name in ds.data_vars if name.startswith("done_")}
    adaptive = json.loads(ds.attrs.get("adaptive", "{}"))
    return json.dumps({**flags, "adaptive_evaluated": adaptive.get("evaluated")})


def _write(store: Path, task: Task, result: dict[str, np.ndarray], region_dims: dict[str, tuple[str, ...]]) -> None:
    """Region write of one chunk, then its done flag (atomic files: a kill leaves the chunk unmarked)."""
    import xarray as xr

    dims = region_dims[task.kind]
    region = {n: slice(a, z) for n, (a, z) in zip(task.names, task.block, strict=True)}
    data = {}
    for name, arr in result.items():
        var_dims = (*dims, "kH_count") if name == "unstable_count" else (
            (*dims, "crossing") if name in CROSSING_VARS or name in CROSSING_ALL_VARS else dims)
        data[name] = (var_dims, arr)
    if task.kind == "count":
        region = {**region, "kH_count": slice(0, len(task.count.kH))}  # type: ignore[union-attr]
    if task.kind in ("gamma_c", "gamma_c_all"):
        region = {**region, "crossing": slice(0, CROSSINGS)}
    xr.Dataset(data).to_zarr(store, region=region, consolidated=False)
    flag = np.ones(1, np.int8)
    xr.Dataset({f"done_{task.kind}": (f"{task.kind}_chunk", flag)}).to_zarr(
        store, region={f"{task.kind}_chunk": slice(task.index, task.index + 1)}, consolidated=False)


def memory_dataset(plan: Plan, command: str | None = None):
    """The plan's template in memory, with writable arrays (a sweep without a store fills it)."""
    ds = template(plan, command).compute()
    for name in ds.data_vars:  # writable copies (dask's fill arrays are broadcast views)
        ds[name] = ds[name].copy(data=np.array(ds[name].values))
    return ds


def open_store(plan: Plan, path: Path, command: str | None = None) -> Path:
    """The store of `plan` at `path`: checked if it exists (SweepError if it cannot be resumed), else created."""
    if path.exists():
        check_resumable(path, plan)
        return path
    # created beside it and renamed into place: a store interrupted while being created would be unreadable, and
    # refused, instead of resumed
    ds0 = template(plan, command)
    tmp = path.with_name(f".{path.name}.creating-{os.getpid()}")
    try:
        ds0.to_zarr(tmp, compute=False, mode="w-", encoding=encoding(ds0, fast=plan.adaptive is not None),
                    consolidated=False)
        os.rename(tmp, path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return path


class Writer(Protocol):
    """Where the results of tasks go: a dataset in memory (:class:`MemoryWriter`), a Zarr store
    (:class:`ZarrWriter`), or an adaptive sweep's journal (:class:`JournalWriter`, :class:`MemoryJournal`)."""

    def done(self, task: Task | PointTask) -> bool:
        """Whether the task's results are written already (a resumed sweep skips it)."""

    def write(self, task: Task | PointTask, result: dict[str, np.ndarray]) -> None:
        """The results of one finished task (called in one thread, as tasks finish)."""


class MemoryWriter(Writer):
    """A sweep without a store: the plan's template in memory, filled chunk by chunk."""

    def __init__(self, plan: Plan, command: str | None = None) -> None:
        self.plan = plan
        self.ds = memory_dataset(plan, command)

    def done(self, task: Task) -> bool:
        return bool(self.ds[f"done_{task.kind}"].values[task.index])

    def write(self, task: Task, result: dict[str, np.ndarray]) -> None:
        index = tuple(slice(a, z) for a, z in task.block)
        for name, arr in result.items():
            self.ds[name].values[index] = arr
        self.ds[f"done_{task.kind}"].values[task.index] = 1

    def journal(self) -> MemoryJournal:
        """The adaptive sweep's journal: the dataset's own arrays."""
        return MemoryJournal(self.ds)

    def result(self):
        """The dataset."""
        return self.ds


class ZarrWriter(Writer):
    """A sweep into a Zarr store: opened (checked: SweepError if it cannot be resumed) or created, each chunk a
    region write and then its done flag."""

    def __init__(self, plan: Plan, path: Path, command: str | None = None) -> None:
        self.plan = plan
        self.fresh = not path.exists()
        self.path = open_store(plan, path, command)
        self._done = done_chunks(self.path)
        self._dims = {"growth": plan.names, "gamma_c": plan.gamma_c_names, "count": plan.names,
                      "sliding": plan.names, "gamma_c_all": plan.gamma_c_names}

    def done(self, task: Task) -> bool:
        return bool(self._done[task.kind][task.index])

    def write(self, task: Task, result: dict[str, np.ndarray]) -> None:
        _write(self.path, task, result, self._dims)
        self._done[task.kind][task.index] = True

    def journal(self) -> JournalWriter:
        """The adaptive sweep's journal in the store."""
        return JournalWriter(self.path, journal_rows(self.plan), task_points(self.plan), fresh=self.fresh)

    def result(self):
        """The store, opened lazily by xarray."""
        import xarray as xr

        return xr.open_zarr(self.path, consolidated=False)


def open_writer(plan: Plan, store: str | os.PathLike | None, command: str | None = None) -> MemoryWriter | ZarrWriter:
    """The writer of a sweep: in memory without a store, else the Zarr store `store` (opened or created)."""
    return MemoryWriter(plan, command) if store is None else ZarrWriter(plan, Path(store), command)


class MemoryJournal(Writer):
    """An adaptive sweep without a store: its grid variables are the dataset's arrays (nothing to journal)."""

    def __init__(self, ds) -> None:
        self.ds = ds

    def load(self, names: tuple[str, ...], shape: tuple[int, ...]) -> dict[str, np.ndarray]:  # noqa: ARG002
        """The dataset's own arrays of `names` (written in place by the adaptive rounds)."""
        return {name: self.ds[name].values for name in names}

    def begin(self, level: int, tasks: list[PointTask]) -> None:
        """Nothing to prepare."""

    def done(self, task: PointTask) -> bool:  # noqa: ARG002
        """False: nothing is journaled, so no task is done before it runs."""
        return False

    def write(self, task: PointTask, result: dict[str, np.ndarray]) -> None:
        """Nothing to write: the adaptive rounds keep the values in the arrays :meth:`load` gave."""

    def finish(self, memory: dict[str, np.ndarray], names: tuple[str, ...], filled: dict[str, np.ndarray],  # noqa: ARG002
               summary: str) -> None:
        """The filled verdicts and the summary into the dataset."""
        for name, values in filled.items():
            self.ds[name].values[...] = values
        self.ds.attrs["adaptive"] = summary


#: the Zarr group (inside the store) of the journal: the points evaluated since the grid variables were last written
JOURNAL = "adaptive_journal"
#: the growth variables in a journal entry's rows, after the flat index and the level (an entry records its rows in
#: its attribute ``rows``; entries written before it existed hold these)
_ROWS = ("growth", "kH_at_max", "kH_min", "kH_max", "n_masked", "verdict", "verdict_reason")


def journal_rows(plan: Plan) -> tuple[str, ...]:
    """The variables a journal entry of the plan holds: the growth variables, and the sliding ones where the sweep
    refines the sliding verdict."""
    return _ROWS + (tuple(SLIDING_VARS) if plan.sliding is not None else ())


def state_names(plan: Plan) -> tuple[str, ...]:
    """The grid variables an adaptive sweep keeps in memory and writes at its end (``computed`` last)."""
    return (*journal_rows(plan), "computed")


#: the dtype and fill value of the variables an adaptive sweep keeps in memory (:func:`state_names`)
STATE_FILL = {**{k: v[:2] for k, v in GROWTH_VARS.items()}, **{k: v[:2] for k, v in SLIDING_VARS.items()},
              "computed": (np.int8, NOT_COMPUTED)}


def filled_names(plan: Plan) -> dict[str, str]:
    """The filled verdicts an adaptive sweep writes at its end: variable -> the verdict it fills."""
    return {"verdict_filled": "verdict", **({"verdict_filled_all": "verdict_all"} if plan.sliding is not None else {})}


class JournalWriter(Writer):
    """An adaptive store: the grid variables, and a journal of the points evaluated since they were written.

    Writing the grid variables as points finish would rewrite a Zarr chunk at every level that touches it (the
    coarse levels touch every chunk): ~35 s of writing for a 65^4 atlas whose model calls take ~100 s. So each
    finished task goes to the journal instead (the group :data:`JOURNAL`: per level and run one array, whose chunk k
    holds task k's flat indices, level and values, NaN-padded: one atomic file per task), and the grid variables
    are written once, at the end, before the journal is removed. Reading a store replays its journal, so a killed
    sweep loses only the tasks in flight (a chunk not written reads as NaN: its points are computed again).
    """

    def __init__(self, path: Path, rows: tuple[str, ...] = _ROWS, size: int = TASK_POINTS, fresh: bool = False) -> None:
        import zarr

        self.path = path
        self.rows, self.size, self.fresh = rows, size, fresh
        self.group = zarr.open_group(str(path), mode="r+")
        self._entry = None

    def load(self, names: tuple[str, ...], shape: tuple[int, ...]) -> dict[str, np.ndarray]:
        """The grid variables `names` as stored, with the journal's points applied (a new store: the fill values)."""
        if self.fresh:  # nothing to read
            return {name: np.full(shape, STATE_FILL[name][1], dtype=STATE_FILL[name][0]) for name in names}
        memory = {name: self.group[name][...] for name in names}
        flat = {name: memory[name].reshape(-1) for name in names}
        for index, level, rows in read_journal(self.group):
            for name, values in rows.items():
                if name in flat:
                    flat[name][index] = values
            flat["computed"][index] = level
        return memory

    def begin(self, level: int, tasks: list[PointTask]) -> None:
        """The journal array of one level's tasks in this run (task k writes chunk k)."""
        from zarr.codecs import ZstdCodec

        self._entry = None
        if tasks:
            journal = self.group.require_group(JOURNAL)
            name = f"L{level}-{os.getpid()}-{time.time_ns()}"
            self._entry = journal.create_array(name, shape=(2 + len(self.rows), len(tasks) * self.size),
                                               chunks=(2 + len(self.rows), self.size), dtype="f8", fill_value=np.nan,
                                               compressors=[ZstdCodec(level=1)], attributes={"rows": list(self.rows)})

    def done(self, task: PointTask) -> bool:  # noqa: ARG002 (the adaptive rounds skip evaluated points themselves)
        return False

    def write(self, task: PointTask, result: dict[str, np.ndarray]) -> None:
        """One finished task into its chunk of the level's journal array."""
        rows = np.full((2 + len(self.rows), self.size), np.nan)
        n = task.flat.size
        rows[0, :n] = task.flat
        rows[1, :n] = task.level
        for i, name in enumerate(self.rows):
            rows[2 + i, :n] = result[name]
        self._entry[:, task.index * self.size:(task.index + 1) * self.size] = rows

    def finish(self, memory: dict[str, np.ndarray], names: tuple[str, ...], filled: dict[str, np.ndarray],
               summary: str) -> None:
        """The grid variables (``computed`` last), the filled verdicts (variable -> values) and the summary, then
        the journal removed."""
        for name in names:
            self.group[name][...] = memory[name]
        for name, values in filled.items():
            self.group[name][...] = values
        self.group.attrs["adaptive"] = summary
        if JOURNAL in self.group:
            del self.group[JOURNAL]


def read_journal(group) -> list[tuple[np.ndarray, int, dict[str, np.ndarray]]]:
    """(flat indices, level, variable -> values) of the points in a store's journal (none if it has none): every
    column of its arrays whose index is not NaN (the chunks of tasks that did not finish are)."""
    if JOURNAL not in group:
        return []
    out = []
    for _, entry in sorted(group[JOURNAL].arrays()):
        names = tuple(entry.attrs.get("rows", _ROWS))
        rows = entry[...]
        if rows.shape[0] != 2 + len(names):
            continue
        rows = rows[:, ~np.isnan(rows[0])]
        for level in np.unique(rows[1]):
            at = rows[1] == level
            values = rows[2:, at]
            out.append((rows[0, at].astype(np.intp), int(level), dict(zip(names, values, strict=True))))
    return out


def stored_computed(path: str | os.PathLike) -> np.ndarray:
    """The ``computed`` variable of an adaptive store with its journal applied (how far a sweep got)."""
    import zarr

    group = zarr.open_group(str(path), mode="r")
    computed = group["computed"][...]
    flat = computed.reshape(-1)
    for index, level, _ in read_journal(group):
        flat[index] = level
    return computed
