"""Reading atlases back: the atlas directory, the atlases in it, one atlas opened as arrays, and computing an atlas
into the directory once per machine (a file lock). The app opens atlases only through here; it never reads Zarr.

An atlas directory holds ``NAME.zarr`` stores written by :func:`asymslide.atlas.sweep.sweep` (``asymslide sweep``):
only names matching :data:`NAME` that are a store with a plan are listed, and only listed names are ever opened, so a
name from a URL cannot reach another path.
"""

from __future__ import annotations

import fcntl
import functools
import json
import math
import os
import re
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from asymslide import model

from . import sweep as engine  # called through the module: a test can spy on engine.sweep
from .plan import Plan, make_plan, plan_points
from .refinement import fill_levels
from .schema import axis_scale
from .writers import done_chunks, store_stamp

#: atlases whose variables are larger than this are read slice by slice from the store instead of held in memory
MAX_IN_MEMORY = 512e6
#: the names an atlas may have (NAME.zarr in the atlas directory)
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,99}$")
#: the crossing variables of the boundary in γ (atlas/schema.py; docs/physics.md §9)
CROSSING_VARIABLES = ("gamma_c_crossing", "gamma_c_location", "gamma_c_direction", "gamma_c_crossing_reason")


def atlas_dir() -> Path:
    """The one directory atlases are read from: ``$ASYMSLIDE_ATLAS_DIR``, else ``$XDG_CACHE_HOME/asymslide/atlases``
    (~/.cache/asymslide/atlases)."""
    configured = os.environ.get("ASYMSLIDE_ATLAS_DIR")
    if configured:
        return Path(configured).expanduser()
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return cache / "asymslide" / "atlases"


def list_atlases(directory: Path, skip: Callable[[str], bool] = lambda _name: False) -> list[str]:
    """Names of the atlases in `directory` (``NAME.zarr`` stores with a plan), sorted; names for which `skip` is true
    are left out. An unreadable directory lists nothing."""
    try:
        entries = sorted(directory.iterdir())
    except OSError:
        return []
    names = []
    for entry in entries:
        name = entry.name[:-5] if entry.name.endswith(".zarr") else ""
        if not name or not NAME.match(name) or skip(name):
            continue
        try:
            attrs = json.loads((entry / "zarr.json").read_text(encoding="utf-8")).get("attributes", {})
        except (OSError, ValueError):
            continue
        if "plan" in attrs:
            names.append(name)
    return names


def is_complete(path: Path) -> bool:
    """Whether the store at `path` exists and every one of its chunks is written."""
    if not (path / "zarr.json").exists():
        return False
    try:
        return all(flags.all() for flags in done_chunks(path).values())
    except (OSError, ValueError, KeyError):
        return False


def points_done(path: Path, plan: Plan) -> dict[str, int]:
    """Grid points per task kind that are written to the store at `path` (by any process)."""
    try:
        done = done_chunks(path)
    except (OSError, ValueError, KeyError):
        return {}
    blocks = {"growth": plan.growth_blocks(), "gamma_c": plan.gamma_c_blocks(), "gamma_c_all": plan.gamma_c_blocks(),
              "count": plan.count_blocks(),
              "sliding": plan.sliding_blocks()}
    return {kind: sum(math.prod(b - a for a, b in blocks[kind][i]) for i in np.flatnonzero(flags))
            for kind, flags in done.items()}


def compute_once(axes: Mapping[str, np.ndarray], kH: np.ndarray, path: Path, *, set_totals: Callable[[dict], None],
                 advance: Callable[[str, int], None], set_done: Callable[[dict], None], poll_s: float,
                 command: str) -> Path:
    """Compute the atlas `axes` x `kH` into `path`, once per machine: under an exclusive lock on a file beside it.
    When another process holds the lock, follow its progress in the store (`set_done`, every `poll_s` seconds) until
    the atlas is complete. `set_totals` gets the points per task kind first, `advance` the points as they finish.
    PermissionError if the directory cannot be written."""
    if is_complete(path):
        return path
    path.parent.mkdir(parents=True, exist_ok=True)
    plan = make_plan(axes, kH=kH)
    totals = plan_points(plan)
    set_totals(totals)
    with open(path.parent / f".{path.name.removesuffix('.zarr')}.lock", "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:  # another process computes it: follow its progress
            while not is_complete(path):
                set_done(points_done(path, plan))
                time.sleep(poll_s)
            set_done(totals)
            return path
        engine.sweep(axes, kH=kH, store=path, progress=advance, command=command)
    return path


@dataclass(frozen=True, eq=False)
class Atlas:
    """An opened atlas: axes, display coordinates, the growth cube and gamma_c (numpy, or lazily read from a large
    store), and its provenance."""

    name: str
    path: Path
    axes: dict[str, np.ndarray]
    log: dict[str, bool]
    fixed: dict[str, float]
    growth: object  # numpy array or a lazy xarray.DataArray (dims in the order of axes)
    gamma_c: object | None  # over the axes without gamma
    gamma_c_reason: object | None
    attrs: dict
    clim: float  # symmetric colour range of the growth over the whole atlas
    #: the verdict class (0 stable, 1 unstable, 2 undetermined, -1 not computed) and its reason code
    #: (model.VERDICT_STATUS), as the growth; None in atlases written before verdicts existed
    verdict: object | None = None
    verdict_reason: object | None = None
    #: the whole boundary in γ (over the axes without gamma, last dimension `crossing`): gamma_c_crossing,
    #: gamma_c_location, gamma_c_direction, gamma_c_crossing_reason; empty in atlases written before crossings existed
    crossings: dict[str, np.ndarray] = field(default_factory=dict)
    #: an adaptive atlas (asymslide sweep --adaptive): the level at which each point was computed (-1: not computed,
    #: its growth NaN), the verdict class of every point (from its cell where not computed) and the refinement's
    #: summary (levels, margin, guard, evaluated fractions); None / {} for a dense atlas
    computed: object | None = None
    verdict_filled: object | None = None
    adaptive: dict = field(default_factory=dict)
    #: the level of the cell a not computed point's class was filled from (asymslide.atlas.refinement.fill_levels; -1 at
    #: computed points); None for a dense atlas or one read lazily from a large store
    filled_level: object | None = None
    #: the sliding verdict over every branch (asymslide sweep --sliding; docs/physics.md §14): the variables of
    #: :data:`SLIDING_FIELDS` that the store holds (as the growth: numpy, or lazy), and the growth floor and kH range
    #: of their search; {} in an atlas of the Rayleigh branch only
    sliding: dict = field(default_factory=dict)
    sliding_floor: float = math.nan
    sliding_kH: tuple[float, float] = (math.nan, math.nan)
    #: the largest growth over every branch in the atlas (the sliding colour range's top; NaN: none)
    sliding_top: float = math.nan
    #: the threshold of sliding in γ over every branch (asymslide sweep --sliding-thresholds): the crossings as
    #: ``crossings`` (CROSSING_VARIABLES, named with ``gamma_c_all``: see :func:`crossing_name`); {} without them
    crossings_all: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def has_sliding(self) -> bool:
        """Whether the atlas holds the sliding verdict over every branch (else: "Rayleigh branch only")."""
        return "verdict_all" in self.sliding

    @property
    def finished(self) -> bool:
        """False for an adaptive atlas whose sweep has not ended (its grid variables are written at the end)."""
        return not self.adaptive or bool(self.adaptive.get("evaluated"))

    @property
    def names(self) -> list[str]:
        """The atlas's axes, in order."""
        return list(self.axes)

    def display(self, name: str) -> np.ndarray:
        """Plotted coordinates of an axis: log10 of its values on a log axis."""
        v = self.axes[name]
        return np.log10(v) if self.log[name] else v

    def read(self, variable: str, index: tuple) -> np.ndarray | None:
        """Another of the store's variables over the atlas's axes, at `index`, read from the store; None if the store
        has none over the same axes."""
        import xarray as xr

        with xr.open_zarr(self.path, consolidated=False) as ds:
            if variable not in ds or list(ds[variable].dims) != self.names:
                return None
            return ds[variable].values[index]

    def label(self, name: str) -> str:
        """The paper's symbol of an axis (model.PARAMETERS)."""
        return model.PARAMETERS[name].symbol if name in model.PARAMETERS else name


def crossing_name(name: str, sliding: bool) -> str:
    """The store's name of a crossing variable (CROSSING_VARIABLES) of the Rayleigh branch or of sliding."""
    return name.replace("gamma_c", "gamma_c_all", 1) if sliding else name


def _is_log(values: np.ndarray, attrs: dict) -> bool:
    if attrs.get("scale") in ("log", "linear"):
        return attrs["scale"] == "log"
    return axis_scale(values) == "log"


#: the sliding variables the app reads (asymslide.atlas.schema.SLIDING_VARS; an adaptive atlas of the sliding verdict
#: also its filled verdict, and ``filled_level_all``, the level of the cell each filled class comes from)
SLIDING_FIELDS = ("growth_all", "kH_at_max_all", "re_z_at_max_all", "family_all", "verdict_all", "verdict_reason_all",
                  "lower_bound_all", "verdict_filled_all")


def _sliding(ds, small: bool, adaptive: dict) -> dict:
    """The sliding fields of an atlas (Atlas.sliding, sliding_floor, sliding_kH, sliding_top); none in an atlas of
    the Rayleigh branch only."""
    if "verdict_all" not in ds:
        return {}
    fields = {v: (ds[v].values if small else ds[v]) for v in SLIDING_FIELDS if v in ds}
    if adaptive and small and adaptive.get("evaluated") and "verdict_filled_all" in ds:
        fields["filled_level_all"] = fill_levels(fields["verdict_all"], ds["computed"].values, int(adaptive["levels"]))
    g = ds["growth_all"].values if small else np.asarray(ds["growth_all"].max().values)
    finite = g[np.isfinite(g)]
    kh = ds["kH_sliding"].values if "kH_sliding" in ds else np.array([math.nan])
    return {"sliding": fields, "sliding_floor": float(ds["verdict_all"].attrs.get("floor", math.nan)),
            "sliding_kH": (float(kh[0]), float(kh[-1])),
            "sliding_top": float(finite.max()) if finite.size else math.nan}


@functools.lru_cache(maxsize=4)
def read_atlas(name: str, path: Path, stamp: str) -> Atlas:
    """Read the atlas at `path` (cached by its name, path and `stamp`, the state of its done flags:
    :func:`open_atlas`)."""
    import xarray as xr

    ds = xr.open_zarr(path, consolidated=False)
    plan = json.loads(ds.attrs["plan"])
    axes = {n: np.asarray(ds[n].values, dtype=float) for n in plan["axes"]}
    log_axes = {n: _is_log(axes[n], dict(ds[n].attrs)) for n in axes}
    fixed = {k: (math.inf if v == "inf" else float(v)) for k, v in plan["fixed"].items()}
    if "growth" not in ds:
        raise ValueError(f"atlas {name} has no growth variable (computed with --no-growth)")
    growth = ds["growth"]
    small = growth.nbytes <= MAX_IN_MEMORY
    g = growth.values if small else growth
    finite = np.abs(growth.values[np.isfinite(growth.values)]) if small else np.abs(growth.max().values)
    clim = float(np.max(finite)) if np.size(finite) else 1e-3
    gc = reason = None
    if "gamma_c" in ds:
        gc, reason = ds["gamma_c"].values, ds["gamma_c_reason"].values
    verdicts = {v: (ds[v].values if small else ds[v]) if v in ds else None
                for v in ("verdict", "verdict_reason", "computed", "verdict_filled")}
    crossings = {v: ds[v].values for v in CROSSING_VARIABLES if v in ds}
    crossings_all = {v: ds[crossing_name(v, True)].values for v in CROSSING_VARIABLES if crossing_name(v, True) in ds}
    adaptive = json.loads(ds.attrs["adaptive"]) if "adaptive" in ds.attrs and "computed" in ds else {}
    filled_level = None
    if adaptive and small and adaptive.get("evaluated"):
        filled_level = fill_levels(verdicts["verdict"], verdicts["computed"], int(adaptive["levels"]))
    return Atlas(name, path, axes, log_axes, fixed, g, gc, reason, dict(ds.attrs), max(clim, 1e-12),
                 crossings=crossings if len(crossings) == len(CROSSING_VARIABLES) else {}, adaptive=adaptive,
                 crossings_all=crossings_all if len(crossings_all) == len(CROSSING_VARIABLES) else {},
                 filled_level=filled_level, **verdicts, **_sliding(ds, small, adaptive))


def open_atlas(name: str, path: Path) -> Atlas:
    """The atlas `name` stored at `path`, read again only when chunks were written to it since."""
    return read_atlas(name, path, store_stamp(path))
