"""Which atlases the Atlas tab can open, and the default atlas: the atlas directory's names, the default atlas's
name and its computation once per machine in the background (an app.jobs.Job shared by the sessions of a process),
and opening an atlas by name.

Atlases are read from one directory only: ``$ASYMSLIDE_ATLAS_DIR`` (``asymslide serve --atlas-dir``), default
``$XDG_CACHE_HOME/asymslide/atlases`` (~/.cache/asymslide/atlases); a name that is not listed there is never opened
(no other path is ever read). The default atlas (4-D: γ, η, f, β) is not shipped: it is computed on first use into
that directory (~25 s on two cores) and reused afterwards; another server process computing it is waited for (a file
lock, asymslide.atlas.store.compute_once).
"""

from __future__ import annotations

import hashlib
import json
import os
import threading
from pathlib import Path

import numpy as np

from asymslide import model
from asymslide.atlas import store
from asymslide.atlas.plan import make_plan
from asymslide.atlas.schema import model_fingerprint

from .. import jobs

#: the default atlas: 4-D over (γ, η, f, β) at Δ = 1, ξ = 0, with γ_c over (η, f, β)
DEFAULT_AXES = {
    "gamma": np.geomspace(0.1, 30.0, 16),
    "eta": np.geomspace(1.5, 1e4, 9),
    "f": np.linspace(0.3, 1.5, 5),
    "beta": np.linspace(0.1, 0.6, 5),
}
DEFAULT_KH = np.logspace(-3, 3, 49)
#: the default atlas is NAME.zarr with NAME = DEFAULT_PREFIX + a hash (see default_name)
DEFAULT_PREFIX = "default-"

#: where atlases are read from and how they may be named (the store's)
atlas_dir = store.atlas_dir
NAME = store.NAME


def default_name() -> str:
    """The default atlas's name: a hash of the model's fingerprint and the atlas's plan, so that another model
    version or another DEFAULT_AXES computes a new one instead of refusing to resume the old."""
    plan = make_plan(DEFAULT_AXES, kH=DEFAULT_KH).identity()
    key = model_fingerprint() + json.dumps(plan, sort_keys=True)
    return DEFAULT_PREFIX + hashlib.sha256(key.encode()).hexdigest()[:12]


def display_name(name: str) -> str:
    """How the select and the titles call an atlas: its file name, but the current default atlas by what it is
    ("default (γ-η-f-β, 4-D)") rather than by its hash. The URL and the store keep the file name
    (default-<hash>), so shared links stay valid."""
    if name != default_name():
        return name
    symbols = "-".join(model.PARAMETERS[n].symbol if n in model.PARAMETERS else n for n in DEFAULT_AXES)
    return f"default ({symbols}, {len(DEFAULT_AXES)}-D)"


def list_atlases(directory: Path | None = None) -> list[str]:
    """Names of the atlases in the directory (``NAME.zarr`` written by asymslide sweep), the current default first;
    defaults of other model versions are left out."""
    current = default_name()
    names = store.list_atlases(atlas_dir() if directory is None else directory,
                               skip=lambda name: name.startswith(DEFAULT_PREFIX) and name != current)
    return sorted(names, key=lambda n: (n != current, n))


def resolve(name: str) -> Path | None:
    """The store of the atlas `name` if it is listed in the atlas directory (never any other path)."""
    if not isinstance(name, str) or not NAME.match(name) or name not in list_atlases():
        return None
    return atlas_dir() / f"{name}.zarr"


# ------------------------------------------------------------------------------------------------
# the default atlas: computed once per machine, in the background
# ------------------------------------------------------------------------------------------------


#: the phases of an atlas computation, in the order the engine runs them (its task kinds), with their labels
PHASES = {"growth": "Growth rates (max Im[c/c_s] over kH at every grid point)",
          "gamma_c": "Thresholds γ_c (exact, over the other axes)"}


#: how often (s) the default atlas's job re-reads the store while another server process computes it
OTHER_PROCESS_POLL_S = 0.3

_default_lock = threading.Lock()
#: the default atlas's job in this process (app.jobs.Job), followed by every session that opens the tab meanwhile
_default_job: jobs.Job | None = None


def default_ready() -> bool:
    """Whether the default atlas is complete in the atlas directory."""
    return store.is_complete(atlas_dir() / f"{default_name()}.zarr")


def ensure_default() -> jobs.Job:
    """The job computing the default atlas in this process, started once (again if it failed, or if its atlas has gone
    since); its progress phases are the engine's task kinds (:data:`PHASES`)."""
    global _default_job
    with _default_lock:
        job = _default_job
        if job is None or (job.state().finished and not default_ready()):
            job = _default_job = jobs.Job(_compute_default, name="default atlas").start()
        return job


def _compute_default(job: jobs.Job) -> Path:
    """The work of the default atlas's job: compute it into the atlas directory, or, when another server process
    holds the directory's lock for it, follow that process's progress in the store; its path."""
    directory = atlas_dir()
    try:
        return store.compute_once(DEFAULT_AXES, DEFAULT_KH, directory / f"{default_name()}.zarr",
                                  set_totals=job.set_totals, advance=job.advance, set_done=job.set_done,
                                  poll_s=OTHER_PROCESS_POLL_S,
                                  command="the Atlas tab's default atlas (app/atlas/directory.py)")
    except PermissionError as exc:  # a folder this server may read but not write (a mounted volume, say)
        raise jobs.Failed(read_only_message(directory, exc)) from None


def read_only_message(directory: Path, exc: OSError) -> str:
    """What the tab says when the atlas directory cannot be written: why, what still works, and how to fix it."""
    return (f"the atlas directory {directory} is not writable by this server (user id {os.getuid()}; "
            f"{exc.strerror or exc}), so the default atlas cannot be computed there. Atlases already in it still "
            "open (choose one above). To fix it, make the folder writable for this user (e.g. `chown` it), or serve "
            "with `--atlas-dir` (Docker: mount) a folder this user can write.")


# ------------------------------------------------------------------------------------------------
# an atlas in memory (asymslide.atlas.store)
# ------------------------------------------------------------------------------------------------

Atlas = store.Atlas


def load(name: str) -> Atlas:
    """The atlas `name` of the atlas directory, opened (store.open_atlas: cached while its done flags do not
    change); ValueError if the directory does not list it."""
    path = resolve(name)
    if path is None:
        raise ValueError(f"no atlas named {name!r} in {atlas_dir()}")
    return store.open_atlas(name, path)
