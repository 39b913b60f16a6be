"""Stability of steady sliding over the whole spectrum: the fastest root of every branch (docs/physics.md §14).

Every verdict of :mod:`model.stability` concerns one root of Eq. implicit_spectrum, the Rayleigh branch. The
equation has other roots (guided modes of the finite blocks, faster than the shear or the dilatational wave), and
they often grow where the Rayleigh branch does not, or faster. This module answers *is steady sliding stable?*
over all of them:

- :func:`root_window`: where the roots can be. For Im z >= floor, no root lies outside
  [-re_max, re_max] x [floor, im_max] (a theorem, §14: a lower bound of Re[F/(iz)] at large |z|).
- :func:`fastest_mode`: at each kH the root of largest Im z over every branch (a root found by the argument
  principle and Newton, certified by a count: no other root above it in the window), its family, and the
  number of roots above the floor.
- :func:`sliding_analysis`: over a kH range, the maximum of that growth (and of the temporal rate kH Im z),
  the verdict of sliding (stable: no root with Im z >= floor anywhere in the range; unstable; undetermined,
  with a reason), side by side with the Rayleigh branch's (:func:`growth_analysis`).
- :func:`sliding_chunk`: one chunk of parameter sets for sweeps (rows :data:`SLIDING_ROWS`).

The floor is stated: roots with 0 < Im z < floor are not searched (at finite eta they are dense: §14).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from ._kernels.records import Params
from ._kernels.window import exclusion_radius, top_of_roots
from ._roots.search import M_BELOW, M_FAILED, M_OK, M_WIDE, SAMPLE_LIMIT, Search, Top
from ._roots.track import Analysis, Peak, family, rayleigh_roots
from ._validate import check, check_floor, check_kh_grid
from .growth_limits import growth_rate_limit
from .stability import GrowthResult, Verdict

__all__ = [
    "DEFAULT_FLOOR",
    "FAMILIES",
    "MODE_STATUS",
    "SLIDING_KH",
    "SLIDING_ROWS",
    "SLIDING_STATUS",
    "FastestMode",
    "SlidingResult",
    "fastest_mode",
    "root_window",
    "sliding_analysis",
    "sliding_chunk",
    "sliding_verdict",
    "family_codes",
]

#: the default growth floor: roots with Im z below it are not searched (their e-folding time is > 1e6 H/(c_s kH))
DEFAULT_FLOOR = 1e-6
#: the search limit (samples on a window's bottom edge) of the temporal rate at finite eta: its windows at level
#: sigma/kH need ~ kH x 1e3 samples (the layers' poles), 20x the limit of the Im z search (docs/physics.md §14.15)
RATE_SAMPLE_LIMIT = 4e6
#: from this eta on, the roots of the eta = inf analysis guide the finite-eta one: the lower block's waves decay
#: over its thickness like exp(-eta kH Re alpha), so its roots lie beside eta = inf's, which the cut charts find
#: where the finite-eta grid misses them (docs/physics.md §14.15)
ETA_GUIDE = 10.0
#: the kH -> 0 end of sigma: below the range, quarter decades are searched down to where the bound of
#: docs/physics.md §14.16 excludes a faster root at every smaller kH, but not below this kH (then refused)
KH_LOW_LIMIT = 1e-8
#: the step (in ln kH) of that search below the range
LOW_STEP = math.log(10.0) / 4
#: the default kH grid of :func:`sliding_analysis` (its ends are the range)
SLIDING_KH = np.logspace(-2, 2, 17)

#: the families of a root (FastestMode.family; -1: no root)
FAMILIES = {
    0: "Rayleigh branch",
    1: "sub-shear (|Re z| < 1, not the Rayleigh branch)",
    2: "intersonic guided mode (1 <= |Re z| < 1/beta)",
    3: "supersonic guided mode (|Re z| >= 1/beta)",
}
#: status of the fastest mode at one kH (FastestMode.status)
MODE_STATUS = {
    M_OK: "certified: the root of largest Im z in the window (a count finds no other root above it)",
    M_BELOW: "below the floor: no root with Im z >= floor (the window's count is 0)",
    M_WIDE: "refused: the window at the floor is too wide to search (finite eta, small floor: roots just above the "
    "layers' poles reach far out; more than 2e5 samples on its edge) and no root was found above the level searched",
    M_FAILED: "refused: the contour count failed (a root on an edge that could not be moved, or too many samples)",
}


# ------------------------------------------------------------------------------------------------
# public API
# ------------------------------------------------------------------------------------------------


def _physical(gamma, f, beta, eta, Delta, xi) -> list[np.ndarray]:
    return [check(n, v) for n, v in (("gamma", gamma), ("f", f), ("beta", beta), ("eta", eta),
                                     ("Delta", Delta), ("xi", xi))]


def root_window(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, floor=DEFAULT_FLOOR
                ) -> tuple[np.ndarray, np.ndarray]:
    """The window outside which F(z; kH) (Eq. implicit_spectrum) has no root with Im z >= floor.

    Returns (re_max, im_max), broadcast over the arguments: every root with Im z >= floor has |Re z| < re_max and
    Im z < im_max (docs/physics.md §14: a lower bound of Re[F/(iz)] over |z| >= r, Im z >= floor, positive beyond
    re_max). re_max is inf where no finite bound exists at this floor (it grows like 1/floor at finite eta).
    """
    fl = check_floor(floor)
    q = check("kH", kH)
    arrays = np.broadcast_arrays(q, *_physical(gamma, f, beta, eta, Delta, xi))
    re = np.empty(arrays[0].shape)
    im = np.empty(arrays[0].shape)
    for idx in np.ndindex(re.shape):
        qq, *par = (float(a[idx]) for a in arrays)
        p = Params(*par)
        re[idx] = exclusion_radius(fl, qq, p)
        im[idx] = top_of_roots(fl, qq, p)
    return re, im


# ------------------------------------------------------------------------------------------------
# over a kH range
# ------------------------------------------------------------------------------------------------



class SlidingReason(IntEnum):
    """Why the sliding verdict is what it is (SlidingResult.verdict_reason; atlases' ``verdict_reason_all``): the
    keys of :data:`SLIDING_STATUS`."""

    STABLE = 0
    UNSTABLE = 1
    WIDE = 2
    FAILED = 3
    UNSTABLE_UNCERTIFIED_MAX = 4


S_STABLE, S_UNSTABLE, S_WIDE, S_FAILED, S_UNSTABLE_UNCERTIFIED_MAX = SlidingReason
#: reason codes of the sliding verdict (SlidingResult.verdict_reason; atlases' ``verdict_reason_all``)
SLIDING_STATUS = {
    S_STABLE: "stable: at every kH of the range, no root of any branch has Im z >= floor (the window's count is 0)",
    S_UNSTABLE: "unstable: a certified root has Im z >= floor; the maximum is certified at every kH searched",
    S_WIDE: "undetermined: no root above the floor was found, but at some kH the window at the floor is wider "
    "than the search limit (finite eta: roots just above the layers' poles reach far out as the floor shrinks)",
    S_FAILED: "undetermined: no root above the floor was found, and the contour count failed at some kH",
    S_UNSTABLE_UNCERTIFIED_MAX: "unstable: a certified root has Im z >= floor, but at some kH the search was "
    "refused above that root's growth (the window too wide, or the count failed), so the maximum is not certified "
    "(growth NaN)",
}
# ------------------------------------------------------------------------------------------------
# public API: one kH, a kH range, a chunk
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FastestMode:
    """The fastest root of every branch at each kH (:func:`fastest_mode`), broadcast over the arguments.

    growth : Im z of the fastest root (NaN unless status is 0)
    z : that root (complex; NaN unless status is 0)
    family : int8, its family (a key of :data:`FAMILIES`; -1: none)
    count : number of roots with Im z >= floor in the window (-1: not counted, or refused: the window too wide)
    status : int8, a key of :data:`MODE_STATUS`
    re_max, im_max : the window at the floor (:func:`root_window`)
    floor : the growth floor
    """

    growth: np.ndarray
    z: np.ndarray
    family: np.ndarray
    count: np.ndarray
    status: np.ndarray
    re_max: np.ndarray
    im_max: np.ndarray
    floor: float


def fastest_mode(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, floor=DEFAULT_FLOOR,
                 count: bool = True) -> FastestMode:
    """At each kH, the root of Eq. implicit_spectrum with the largest Im z over every branch (docs/physics.md §14).

    The roots with Im z >= floor lie in the window of :func:`root_window`. The root is located by the argument
    principle (model.modes' contour sampling: cells with the highest top first, Newton in a cell) and certified
    by a count: no other root of F lies above Im z (1 - 1e-6) in the window. Its family (:data:`FAMILIES`)
    compares it with the Rayleigh branch at the same kH (:func:`rayleigh_branch`) and else says how fast
    it travels. With count=True, also the number of roots with Im z >= floor (refused, -1, where the window at the
    floor is too wide to search: finite eta with a small floor). Arguments broadcast.
    """
    fl = check_floor(floor)
    q = check("kH", kH)
    arrays = np.broadcast_arrays(q, *_physical(gamma, f, beta, eta, Delta, xi))
    shape = arrays[0].shape
    out = {k: np.empty(shape, dtype=t) for k, t in (("growth", float), ("z", complex), ("family", np.int8),
                                                    ("count", np.int64), ("status", np.int8), ("re", float),
                                                    ("im", float))}
    warm: dict[tuple, complex] = {}
    for idx in np.ndindex(shape):
        qq, *par = (float(a[idx]) for a in arrays)
        search = Search(*par, fl)
        key = tuple(par)
        top = search.fastest(qq, warm.get(key), with_count=count)
        if top.status == M_OK:
            warm[key] = top.z
        rz = rayleigh_roots(np.array([qq]), par)[0] if top.status == M_OK else complex(math.nan, math.nan)
        out["growth"][idx] = top.z.imag
        out["z"][idx] = top.z
        out["family"][idx] = family(top.z, par[2], rz)
        out["count"][idx] = top.count
        out["status"][idx] = top.status
        out["re"][idx] = search.rho(fl, qq)
        out["im"][idx] = search.top(qq)
    return FastestMode(out["growth"], out["z"], out["family"], out["count"], out["status"], out["re"], out["im"], fl)


#: rows of :func:`sliding_chunk`'s result
SLIDING_ROWS = ("growth_all", "ln_kH_at_max_all", "re_z_at_max_all", "family_all", "rate_all",
                "ln_kH_at_max_rate_all", "re_z_at_max_rate_all", "im_z_at_max_rate_all", "family_rate_all",
                "verdict_reason_all", "max_at_end_all", "rate_at_end_all")


def _verdict_reason(tops: list[Top]) -> int:
    """The sliding verdict's reason code from the searches at every kH (before the maximum is checked)."""
    status = [t.status for t in tops]
    if M_OK in status:
        return S_UNSTABLE
    if all(s == M_BELOW for s in status):
        return S_STABLE
    return S_WIDE if M_WIDE in status else S_FAILED


def _analyse_one(s_grid: np.ndarray, par: tuple, floor: float, rayleigh: np.ndarray, rate: bool) -> list[float]:
    """One column of :data:`SLIDING_ROWS` for one parameter set; rayleigh: its column of model.growth_chunk on the
    same grid (the Rayleigh branch's own maximum, a certified root, is searched first: the sliding maximum is never
    below it, and the other kH are searched only above it)."""
    finite_rate = rate and math.isfinite(par[3])
    an = Analysis(Search(*par, floor, sample_limit=RATE_SAMPLE_LIMIT if finite_rate else SAMPLE_LIMIT), s_grid, rate)
    an.sample_from(rayleigh)
    if math.isfinite(par[3]) and par[3] >= ETA_GUIDE:
        an.seed(_guides(s_grid, par, floor, rate))
    reason = _verdict_reason(list(an.tops.values()))
    if reason == S_STABLE and math.isinf(par[3]) and an.rises_above_floor():
        reason = _verdict_reason(list(an.tops.values()))
    nan = math.nan
    if reason != S_UNSTABLE:
        return [nan] * 9 + [float(reason), nan, nan]
    im, certified = an.certified_peak()
    row_im = [im.value, im.s, im.z.real, nan]
    if not certified:
        row_im, reason = [nan] * 4, S_UNSTABLE_UNCERTIFIED_MAX
    rt, rt_certified = an.certified_peak(rate=True) if rate else (Peak(), False)
    row_rt = [nan] * 5
    if rate and rt_certified:
        row_rt = [rt.value, rt.s, rt.z.real, rt.z.imag, nan]
    ks = [v for v in (row_im[1], row_rt[1]) if math.isfinite(v)]
    rz = dict(zip(ks, rayleigh_roots(np.exp(ks), par), strict=True)) if ks else {}
    if math.isfinite(row_im[1]):
        row_im[3] = float(family(im.z, par[2], rz[row_im[1]]))
    if math.isfinite(row_rt[1]):
        row_rt[4] = float(family(rt.z, par[2], rz[row_rt[1]]))
    return row_im + row_rt + [float(reason), float(im.at_end), float(rt.at_end) if rate else nan]


def _guides(s_grid: np.ndarray, par: tuple, floor: float, rate: bool) -> list[tuple[float, complex]]:
    """The maxima (ln kH, z) of the same set at eta = inf (:func:`_analyse_one`): where a finite-eta analysis is
    guided (eta >= :data:`ETA_GUIDE`)."""
    from .stability import growth_chunk

    inf = (*par[:3], math.inf, *par[4:])
    row = dict(zip(SLIDING_ROWS, _analyse_one(s_grid, inf, floor, growth_chunk(s_grid, np.array(inf)[:, None])[:, 0],
                                              rate), strict=True))
    return [(row["ln_kH_at_max_all"], complex(row["re_z_at_max_all"], row["growth_all"])),
            (row["ln_kH_at_max_rate_all"], complex(row["re_z_at_max_rate_all"], row["im_z_at_max_rate_all"]))]


def sliding_chunk(s_grid: np.ndarray, params: np.ndarray, floor: float = DEFAULT_FLOOR,
                  rayleigh: np.ndarray | None = None, rate: bool = False) -> np.ndarray:
    """Pure function of one chunk: params (6, n) rows gamma, f, beta, eta, Delta, xi -> (12, n) results.

    Rows (:data:`SLIDING_ROWS`): the maximum over ln kH in [s_grid[0], s_grid[-1]] of the fastest root's Im z,
    its ln kH, Re z and family; the maximum of the temporal rate kH Im z, its ln kH, root and family; the verdict
    reason (:data:`SLIDING_STATUS`); 1.0 where a maximum lies at an end of the range (it may go on beyond). The
    maxima are NaN unless the verdict reason is 1 (unstable, maximum certified). rayleigh: the result of
    :func:`growth_chunk` for the same grid and parameters, if already computed (else it is). No shared
    state: a distributed backend can run chunks anywhere.
    """
    from .stability import growth_chunk

    fl = check_floor(floor)
    s = np.asarray(s_grid, dtype=float)
    ray = growth_chunk(s, params) if rayleigh is None else rayleigh
    out = np.empty((len(SLIDING_ROWS), params.shape[1]))
    for j in range(params.shape[1]):
        out[:, j] = _analyse_one(s, tuple(float(v) for v in params[:, j]), fl, ray[:, j], rate)
    return out


def sliding_verdict(reason: np.ndarray) -> np.ndarray:
    """The sliding verdict class (int8: 0 stable, 1 unstable, 2 undetermined; :data:`VERDICTS`) of reason codes
    (:data:`SLIDING_STATUS`, e.g. :func:`sliding_chunk`'s ``verdict_reason_all`` row)."""
    reason = np.asarray(reason)
    unstable = np.isin(reason, (S_UNSTABLE, S_UNSTABLE_UNCERTIFIED_MAX))
    return np.where(reason == S_STABLE, Verdict.STABLE,
                    np.where(unstable, Verdict.UNSTABLE, Verdict.UNDETERMINED)).astype(np.int8)


def family_codes(row: np.ndarray) -> np.ndarray:
    """A family row of :func:`sliding_chunk` (NaN: none) as int8 codes of :data:`FAMILIES` (-1: none)."""
    row = np.asarray(row)
    return np.where(np.isnan(row), -1, row).astype(np.int8)


@dataclass(frozen=True)
class SlidingResult:
    """The stability of steady sliding over every branch and a kH range (:func:`sliding_analysis`).

    Attributes
    ----------
    growth : the maximum over the kH range of the fastest root's Im z (as the paper's c(k) plots; NaN unless the
        verdict is unstable with a certified maximum), kH_at_max, z_at_max and family (:data:`FAMILIES`) there
    rate : the maximum of the temporal growth rate kH Im z (in units of c_s/H), kH_at_max_rate, z_at_max_rate
    max_at_end, rate_at_end : the maximum lies at an end of the range (it may continue beyond)
    lower_bound : True at finite eta: the result holds at the kH grid searched and along the roots followed from
        it (above M/2), but a root can rise higher between two grid points unseen (narrow humps, 0.005 to 0.1
        decades wide in kH, of roots that come up through the real axis beside the layers' poles: docs/physics.md
        §14.7), so growth is a lower bound of the maximum over the continuous range and a stable verdict holds at
        the kH searched; a denser kH grid narrows the gap. False at eta = inf, where the roots beside the branch
        points are followed across the cuts too (§14.7 states what remains unexcluded)
    verdict : int8, 0 stable, 1 unstable, 2 undetermined (:data:`VERDICTS`); verdict_reason :
        :data:`SLIDING_STATUS`
    floor : the growth floor; kH_range : the range searched
    rayleigh : the Rayleigh branch alone on the same grid (:func:`growth_analysis`), side by side
    rate_limit : with rate=True, the supremum of kH Im z approached as kH -> infinity (:func:`growth_rate_limit`;
        0.0 where no root keeps a finite rate, NaN with rate=False),
        rate_limit_re_z its root's Re z there, rate_beyond_range where it is positive and exceeds the maximum over the
        range, or the range gives none (the temporal rate then rises higher beyond the range's end, towards
        rate_limit)
    sigma : with rate=True, the supremum over 0 < kH < inf of the temporal rate kH Im z (c_s/H; docs/physics.md
        §14.16): the largest of the range's maximum, the maximum below the range (searched down to sigma_kH_low,
        below which the bound of §14.3 leaves no root that fast) and rate_limit. kH_at_sigma is where it is attained,
        inf where it is approached as kH -> infinity (rate_limit above the others; z_at_sigma is then the limit's
        Re z, Im z -> 0), family_sigma its family (:data:`FAMILIES`; -1 none). NaN where a part is refused (the
        range's rate, the search below it, or the limit), or where no root grows (verdict stable and rate_limit 0).
        Between the range's end and infinity sigma is the larger of the two, not certified (an approach from above
        by O(1/kH) can exceed both slightly: §14.14)
    """

    growth: np.ndarray
    kH_at_max: np.ndarray
    z_at_max: np.ndarray
    family: np.ndarray
    rate: np.ndarray
    kH_at_max_rate: np.ndarray
    z_at_max_rate: np.ndarray
    family_rate: np.ndarray
    max_at_end: np.ndarray
    rate_at_end: np.ndarray
    lower_bound: np.ndarray
    verdict: np.ndarray
    verdict_reason: np.ndarray
    floor: float
    kH_range: tuple[float, float]
    rayleigh: GrowthResult
    rate_limit: np.ndarray | None = None
    rate_limit_re_z: np.ndarray | None = None
    rate_beyond_range: np.ndarray | None = None
    sigma: np.ndarray | None = None
    kH_at_sigma: np.ndarray | None = None
    z_at_sigma: np.ndarray | None = None
    family_sigma: np.ndarray | None = None
    sigma_kH_low: np.ndarray | None = None


def sliding_analysis(*, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, kH=None, floor=DEFAULT_FLOOR,
                     rate: bool = False) -> SlidingResult:
    """Is steady sliding stable? The fastest root of every branch over a kH range (docs/physics.md §14).

    kH : 1-D increasing grid (default :data:`SLIDING_KH`, 17 points over [1e-2, 1e2]) whose ends are the range.
    The Rayleigh branch's maximum (:func:`growth_analysis`, returned as ``.rayleigh``) is searched first;
    then every grid point, once a growth M is known only above a fraction of it (every root there located in one
    contour, which serves the maximum and the tracking below; branch and bound: a root lower cannot raise the
    maximum, and the contour stays away from the real axis), at the floor until a root above it is found. The
    best point is refined on the root that carries it (followed in kH to where its Im z is stationary,
    Newton, and certified there); then every root above max(floor, M/4) (M/2 at finite eta) at a grid point is
    followed to its peak in the neighbouring intervals, and at eta = inf every root beside a branch point is
    followed across the cuts (``model._roots.cuts``); a peak above the maximum M is certified and taken. What
    is not excluded between the grid points, and how often it matters, is in docs/physics.md §14.7: at finite eta
    the maximum is a lower bound of the continuous one (``lower_bound``; a denser kH narrows the gap). Verdict:
    stable if no root has Im z >= floor at any kH searched, unstable if one does (:data:`SLIDING_STATUS`).
    From eta >= ``ETA_GUIDE`` (10) the eta = inf analysis of the same set runs first and its maxima are searched at
    finite eta too (above the real axis the lower block's waves decay across it, so its roots lie beside eta = inf's:
    large eta gives eta = inf's maxima; docs/physics.md §14.15).
    rate=True also gives the maximum of the temporal rate kH Im z, found as that of Im z (refined, its roots followed
    between the grid points to where their kH Im z peaks; a point is searched above the lower of the two levels, at
    finite eta up to ``RATE_SAMPLE_LIMIT`` (4e6) samples: NaN where even that is refused above it), and its limit as
    kH -> infinity (``rate_limit``, 1-3 s a set; docs/physics.md §14.14-15), and ``sigma``, the supremum over every kH
    (§14.16); else those fields are NaN. 2-8 s a set at finite eta with the rate, 0.2-0.6 s without.
    Parameters broadcast.
    """
    from .stability import growth_chunk, growth_result

    fl = check_floor(floor)
    grid = SLIDING_KH if kH is None else check_kh_grid(kH)
    arrays = np.broadcast_arrays(*_physical(gamma, f, beta, eta, Delta, xi))
    shape = arrays[0].shape
    params = np.stack([a.reshape(-1) for a in arrays])
    s_grid = np.log(grid)
    ray = growth_chunk(s_grid, params)
    rows = sliding_chunk(s_grid, params, fl, ray, rate)
    r = dict(zip(SLIDING_ROWS, (row.reshape(shape) for row in rows), strict=True))
    reason = r["verdict_reason_all"]
    verdict = sliding_verdict(reason)
    fam = family_codes

    z_rate = r["re_z_at_max_rate_all"] + 1j * r["im_z_at_max_rate_all"]
    return SlidingResult(r["growth_all"], np.exp(r["ln_kH_at_max_all"]),
                         r["re_z_at_max_all"] + 1j * r["growth_all"], fam(r["family_all"]), r["rate_all"],
                         np.exp(r["ln_kH_at_max_rate_all"]), z_rate, fam(r["family_rate_all"]),
                         r["max_at_end_all"] == 1.0, r["rate_at_end_all"] == 1.0, np.isfinite(arrays[3]), verdict,
                         reason.astype(np.int8), fl,
                         (float(grid[0]), float(grid[-1])), growth_result(ray, shape),
                         *(limit := _rate_limit(arrays, r["rate_all"], rate))[:3],
                         *_sigma(arrays, s_grid[0], fl, r, z_rate, limit, rate))


def _low_end(par: tuple, s_lo: float, sigma: float, floor: float) -> tuple[float, float, float, complex]:
    """Below the range (ln kH < s_lo): (kH_low, sigma', ln kH, z). kH_low: the kH below which no root has kH Im z >=
    sigma (§14.16: at Im z = sigma/kH the bound of §14.3 at |z| = Im z only rises as kH falls, so it holds for
    every smaller kH once it holds at one); the quarter decades from there to the range's start are searched
    above sigma/kH and their roots followed between them (:meth:`Analysis.track`). sigma' > sigma with its ln kH and
    root where a faster root lies there (certified), else NaN; kH_low NaN where refused (a search refused above
    the level, or no exclusion above KH_LOW_LIMIT)."""
    nan = (math.nan, math.nan, complex(math.nan, math.nan))
    p = Params(*par)

    def excluded(s: float) -> bool:
        y = sigma * math.exp(-s)
        return exclusion_radius(y, math.exp(s), p) <= y

    grid = [s_lo]
    while not excluded(grid[-1]):
        if grid[-1] - LOW_STEP < math.log(KH_LOW_LIMIT):
            return (math.nan, *nan)
        grid.append(grid[-1] - LOW_STEP)
    if len(grid) == 1:
        return (math.exp(s_lo), *nan)
    an = Analysis(Search(*par, floor, sample_limit=RATE_SAMPLE_LIMIT), np.array(grid[::-1]), rate=True)
    an.best_im, an.best_rate = math.inf, sigma  # every point searched above sigma/kH alone
    an.sample()
    found = any(t.status == M_OK for t in an.tops.values()) or an.track(sigma, rate=True)
    if found:  # (best_im stays inf: every search, the refinement's too, is above the rate's level alone)
        pk, certified = an.certified_peak(rate=True)
        if not certified or not pk.value > sigma:
            return (math.nan, *nan)
        return (math.exp(grid[-1]), pk.value, pk.s, pk.z)  # (the bound excludes the faster sigma there too)
    if an.uncertified(sigma, rate=True):
        return (math.nan, *nan)
    return (math.exp(grid[-1]), *nan)


def _sigma(arrays: list[np.ndarray], s_lo: float, floor: float, r: dict, z_rate: np.ndarray,
           limit: tuple[np.ndarray, np.ndarray, np.ndarray], rate: bool) -> tuple[np.ndarray, ...]:
    """(sigma, kH_at_sigma, z_at_sigma, family_sigma, sigma_kH_low) of :class:`SlidingResult` (NaN, -1 without
    rate)."""
    shape = arrays[0].shape
    out = [np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, complex(np.nan, np.nan)),
           np.full(shape, -1, dtype=np.int8), np.full(shape, np.nan)]
    if rate:
        lim, lim_x, _, lim_family = limit
        for idx in np.ndindex(shape):
            kh = float(np.exp(r["ln_kH_at_max_rate_all"][idx]))
            range_max = (float(r["rate_all"][idx]), kh, complex(z_rate[idx]))
            got = _sigma_one(tuple(float(a[idx]) for a in arrays), s_lo, floor, int(r["verdict_reason_all"][idx]),
                             range_max, (float(lim[idx]), float(lim_x[idx]), int(lim_family[idx])))
            for o, v in zip(out, got, strict=True):
                o[idx] = v
    return tuple(out)


def _sigma_one(par: tuple, s_lo: float, floor: float, reason: int, range_max: tuple[float, float, complex],
               limit: tuple[float, float, int]) -> tuple[float, float, complex, int, float]:
    """(sigma, kH_at_sigma, z_at_sigma, family_sigma, sigma_kH_low) of one set from the range's maximum (sigma, kH,
    z), its verdict reason and the limit (sigma_inf, its Re z, its family): the larger of the range's maximum and the
    limit (the range's on a tie: attained), unless the search below the range, above that value, finds a faster
    root."""
    nan = (math.nan, math.nan, complex(math.nan, math.nan), -1, math.nan)
    if not math.isfinite(limit[0]) or reason not in (S_STABLE, S_UNSTABLE):
        return nan
    if reason == S_UNSTABLE and not math.isfinite(range_max[0]):
        return nan
    cands = [range_max] if reason == S_UNSTABLE else []
    if limit[0] > 0.0:
        cands.append((limit[0], math.inf, complex(limit[1], 0.0)))
    if not cands:  # stable over the range, and nothing grows as kH -> infinity
        return nan
    top = max(cands, key=lambda c: c[0])
    kh_low, low, s_low, z_low = _low_end(par, s_lo, top[0], floor)
    if not math.isfinite(kh_low):
        return nan
    if math.isfinite(low):
        top = (low, math.exp(s_low), z_low)
    if math.isinf(top[1]):
        return (*top, limit[2], kh_low)
    return (*top, family(top[2], par[2], rayleigh_roots(np.array([top[1]]), par)[0]), kh_low)


def _rate_limit(arrays: list[np.ndarray], rate_max: np.ndarray, rate: bool
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(rate_limit, its Re z, rate_beyond_range) of :class:`SlidingResult` (NaN/False without rate), and the
    limit's family (-1 without rate)."""
    shape = arrays[0].shape
    lim = np.full(shape, np.nan)
    re_z = np.full(shape, np.nan)
    fam = np.full(shape, -1, dtype=np.int8)
    if rate:
        got = growth_rate_limit(**dict(zip(("gamma", "f", "beta", "eta", "Delta", "xi"), arrays, strict=True)))
        lim[...] = np.where(got.status <= 1, got.sigma, np.nan)
        re_z[...] = got.x
        fam[...] = got.family
    with np.errstate(invalid="ignore"):
        beyond = (lim > 0.0) & ~(lim <= rate_max)  # (also where the range gives no maximum)
    return lim, re_z, beyond, fam
