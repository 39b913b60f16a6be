"""Compile (or load from numba's cache) every model kernel the app and the atlas engine call.

numba compiles a kernel at its first call. Without this, the first page a fresh server renders waits for the
compilation (minutes on a busy 2-core host); with it, the launcher (``asymslide serve``) and the Docker build
pay that cost before a page is served. The kernels are cached on disk (``NUMBA_CACHE_DIR``), so a second warm-up
only loads them (seconds).

``asymslide warmup`` runs :func:`compile_kernels` and prints what it did.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np


def _calls() -> list[tuple[str, Callable[[], object]]]:
    """(what, call): one call per compiled entry point, with the argument types the app and engine pass."""
    from asymslide import model

    kh = np.logspace(-2, 2, 9)
    base = dict(gamma=3.0, f=0.9, beta=0.3)
    read_only = np.full(1, 0.5)
    read_only.flags.writeable = False  # numba compiles another specialisation for a read-only array (the app's)
    return [
        ("Rayleigh speed", lambda: model.rayleigh_speed(0.5)),
        ("Rayleigh speed, read-only input", lambda: model.rayleigh_speed(read_only)),
        ("response functions", lambda: model.response_functions(0.5 + 0.1j, 1.0, beta=0.3, eta=2.0)),
        ("dispersion", lambda: model.dispersion(0.5 + 0.1j, 1.0, **base, eta=2.0)),
        ("Rayleigh branch, eta = inf", lambda: model.spectrum(kh, **base)),
        ("Rayleigh branch, finite eta", lambda: model.spectrum(kh, **base, eta=10.0, Delta=0.5, xi=0.5)),
        ("Rayleigh branch, one set", lambda: model.rayleigh_branch(kh, **base)),
        ("growth analysis", lambda: model.growth_analysis(kh, gamma=np.array([3.0, 1.0]), f=0.9, beta=0.3,
                                                          eta=np.array([math.inf, 10.0]), workers=1)),
        ("growth analysis, rtol", lambda: model.growth_analysis(kh, **base, rtol=1e-8, workers=1)),
        ("thresholds (neutral modes), gamma", lambda: model.critical_gammas(f=0.9, beta=0.3, gamma_range=(1.0, 10.0),
                                                                             workers=1)),
        ("thresholds (neutral modes), eta", lambda: model.critical_etas(gamma=3.0, f=0.9, beta=0.3,
                                                                         eta_range=(2.0, 20.0), workers=1)),
        ("all branches", lambda: model.unstable_modes(1.0, **base, eta=10.0)),
        # the Spectrum tab's sliding over every branch (its first page runs these in the background)
        ("fastest root of every branch, eta = inf", lambda: model.fastest_mode(kh, **base)),
        ("fastest root of every branch, finite eta", lambda: model.fastest_mode(kh, **base, eta=10.0, count=False)),
        ("sliding over every branch, eta = inf", lambda: model.sliding_analysis(**base)),
        ("sliding over every branch, finite eta", lambda: model.sliding_analysis(**base, eta=10.0)),
    ]


def compile_kernels(log: Callable[[str], None] | None = None) -> float:
    """Call every compiled entry point once (compiling it or loading it from numba's cache); returns the
    seconds it took. `log` receives one line before and one after ("compiling kernels…", "… ready")."""
    say = log or (lambda _line: None)
    say("asymslide: compiling kernels (loaded from the cache if it exists) ...")
    t0 = time.perf_counter()
    for _what, call in _calls():
        call()
    dt = time.perf_counter() - t0
    say(f"asymslide: kernels ready in {dt:.1f} s")
    return dt
