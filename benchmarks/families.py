"""The families of roots of Eq. implicit_spectrum and which one limits the stability of steady sliding.

Computes, for the paper's defaults (gamma = 3, f = 0.9, beta = 0.3, Delta = 1; docs/physics.md §1):

(a) eta = inf: every root with Im z >= 1e-6 (the floor) in the complete window of ``model.root_window`` at 60 kH in
    [1e-2, 1e2] (``model.unstable_modes``), each classified as the Rayleigh branch (equal to
    ``model.rayleigh_branch`` to 1e-8 relative) or by |Re z| as ``model.FAMILIES`` does, beside the Rayleigh branch
    and the fastest root (``model.fastest_mode``);
(b) eta = 10: the fastest root (``model.fastest_mode``) at 40 kH and the Rayleigh branch;
(c)-(f) the maxima of ``model.sliding_analysis`` (all branches) and of its Rayleigh branch (``.rayleigh``) over kH in
    [1e-2, 1e2] against gamma, eta, f and beta, the others at the defaults (eta = inf).

The sweeps run ``sliding_analysis`` twice: on its default grid (17 kH) and on a grid of 65 kH. The figure and the
first table show the 65-point results; the table's last column gives the default grid's verdict or growth where it
differs. (Between grid points, sliding_analysis follows the roots it finds above a fraction of the maximum to their
peaks, docs/physics.md §14.7; a root that lives above the floor only between two grid points is missed: the
supersonic mode's narrow peak near Re z = 1/beta at gamma = 2.66, kH 0.44-0.56, lies between the default grid's
0.316 and 0.562.)

Writes docs/families.png (2x3 panels; growth axes log above the floor, linear within +-floor, compressed log below;
family by colour, filled for Re z > 0 and open for Re z < 0) and prints Markdown tables: the sweeps, and the
e-folding times H1 / (c_s kH Im z) of modes with Im z = 1e-6 and 1e-3 at kH = 1, H1 = 0.1 m for every material preset
(``model.e_folding_time``). Run ``python benchmarks/families.py`` (about 3-4 minutes on 2 cores: the sweeps run on
2 processes, and eta = 1, where no root lies above the floor and every window is counted at it, takes most of it).
"""

from __future__ import annotations

import math
import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import NullLocator  # noqa: E402

from asymslide import model  # noqa: E402

PAPER: dict[str, float] = {"gamma": 3.0, "f": 0.9, "beta": 0.3, "eta": math.inf, "Delta": 1.0, "xi": 0.0}
FLOOR = 1e-6
OUT = ROOT / "docs" / "families.png"
KH_A = np.logspace(-2, 2, 60)  # panel (a): every root at these kH
KH_B = np.logspace(-2, 2, 40)  # panel (b): the fastest root at these kH
KH_LINE = np.logspace(-2, 2, 400)  # the Rayleigh branch's line
DENSE_KH = np.logspace(-2, 2, 65)  # the sweeps' grid (the default grid, SLIDING_KH, is every 4th point)
ETA_B = 10.0
NEG_SQUEEZE = 0.6  # units of the growth axis per decade below -floor (a decade above the floor is 1)
SWEEPS: dict[str, np.ndarray] = {
    "gamma": np.geomspace(0.3, 30.0, 20),
    "eta": np.append(np.geomspace(1.0, 1e3, 12), math.inf),
    "f": np.linspace(0.1, 1.5, 15),
    "beta": np.linspace(0.1, 0.7, 13),
}
SYMBOL = {"gamma": r"$\gamma$", "eta": r"$\eta$", "f": r"$f$", "beta": r"$\beta$"}
ETA_INF_X = 4e3  # where eta = inf is drawn in panel (d)
FAMILY_COLOR = {0: "tab:blue", 1: "tab:green", 2: "tab:orange", 3: "tab:red"}
FAMILY_LABEL = {
    0: "Rayleigh branch",
    1: r"sub-shear, other ($|\mathrm{Re}\,z|<1$)",
    2: r"intersonic ($1\leq|\mathrm{Re}\,z|<1/\beta$)",
    3: r"supersonic ($|\mathrm{Re}\,z|\geq 1/\beta$)",
}
IM_Z = r"$\mathrm{Im}\,z = \mathrm{Im}\,c/c_s$"


# ------------------------------------------------------------------------------------------------
# computations
# ------------------------------------------------------------------------------------------------


def classify(z: complex, z_rayleigh: complex, beta: float) -> int:
    """The family (model.FAMILIES) of a root z, given the Rayleigh branch's root at the same kH (NaN if masked)."""
    if np.isfinite(z_rayleigh) and abs(z - z_rayleigh) <= 1e-8 * abs(z):
        return 0
    x = abs(z.real)
    return 1 if x < 1.0 else (2 if x < 1.0 / beta else 3)


def rayleigh_line(eta: float) -> np.ndarray:
    """The Rayleigh branch's roots on KH_LINE (NaN where masked)."""
    p = {**PAPER, "eta": eta}
    res = model.rayleigh_branch(KH_LINE, **p)
    return np.where(np.asarray(res.status) == 0, np.asarray(res.z, dtype=complex), complex(math.nan, math.nan))


def all_roots_eta_inf() -> dict[str, Any]:
    """Panel (a): every root above the floor in the complete window at each kH of KH_A (eta = inf)."""
    p = PAPER
    ray = np.asarray(model.rayleigh_branch(KH_A, **p).z, dtype=complex)
    fm = model.fastest_mode(KH_A, **p, floor=FLOOR)
    kh, zs, fams, problems = [], [], [], []
    for i, q in enumerate(KH_A):
        re_max, im_max = (float(v) for v in model.root_window(q, **p, floor=FLOOR))
        try:
            roots = model.unstable_modes(q, **p, re_max=re_max, im_min=FLOOR, im_max=im_max)
        except RuntimeError as err:
            problems.append(f"kH = {q:.4g}: unstable_modes failed ({err})")
            continue
        for z in roots:
            kh.append(q)
            zs.append(complex(z))
            fams.append(classify(complex(z), complex(ray[i]), p["beta"]))
        top = max((r.imag for r in roots), default=math.nan)
        if fm.status[i] == 0 and not abs(top - fm.growth[i]) <= 1e-9 * fm.growth[i]:
            problems.append(f"kH = {q:.4g}: fastest_mode {fm.growth[i]:.6g} != top of unstable_modes {top:.6g}")
        if fm.count[i] >= 0 and fm.count[i] != len(roots):
            problems.append(f"kH = {q:.4g}: fastest_mode count {fm.count[i]} != {len(roots)} roots listed")
    return {"kH": np.array(kh), "z": np.array(zs), "family": np.array(fams, dtype=int), "fastest": fm,
            "rayleigh": rayleigh_line(math.inf), "problems": problems, "counts": fm.count}


def fastest_eta_b() -> dict[str, Any]:
    """Panel (b): the fastest root at each kH of KH_B for eta = ETA_B."""
    p = {**PAPER, "eta": ETA_B}
    fm = model.fastest_mode(KH_B, **p, floor=FLOOR, count=False)
    return {"fastest": fm, "rayleigh": rayleigh_line(ETA_B)}


def _maxima(res: model.SlidingResult) -> dict[str, Any]:
    ray = res.rayleigh
    return {
        "verdict": int(res.verdict), "reason": int(res.verdict_reason), "growth": float(res.growth),
        "kH": float(res.kH_at_max), "z": complex(res.z_at_max), "family": int(res.family),
        "at_end": bool(res.max_at_end),
        "ray_verdict": int(ray.verdict), "ray_reason": int(ray.verdict_reason), "ray_growth": float(ray.growth),
        "ray_kH": float(ray.kH_at_max),
    }


def sweep_point(name: str, value: float, dense: bool) -> dict[str, Any]:
    """sliding_analysis at one parameter value of a sweep, on the dense or the default kH grid (in a worker)."""
    p = {**PAPER, name: value}
    t0 = time.perf_counter()
    res = _maxima(model.sliding_analysis(**p, kH=DENSE_KH if dense else None, floor=FLOOR))
    return {"name": name, "value": value, "dense": dense, **res, "seconds": time.perf_counter() - t0}


def run_sweeps(workers: int = 2) -> dict[str, list[dict[str, Any]]]:
    """Every sweep point on both grids, on `workers` processes (the slowest first: finite eta, dense grid), printing
    progress; per point the dense grid's results plus the default grid's verdict and growth."""
    tasks = [(n, float(v), d) for n, vals in SWEEPS.items() for v in vals for d in (True, False)]
    tasks.sort(key=lambda t: (t[0] != "eta" or math.isinf(t[1]), not t[2]))
    got: dict[tuple[str, float, bool], dict[str, Any]] = {}
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        futures = [pool.submit(sweep_point, *t) for t in tasks]
        for done, fut in enumerate(as_completed(futures), 1):
            r = fut.result()
            got[r["name"], r["value"], r["dense"]] = r
            print(f"  [{done:3d}/{len(tasks)}] {r['name']} = {r['value']:.4g} ({'65' if r['dense'] else '17'}-point "
                  f"grid): verdict {r['verdict']}, growth {r['growth']:.4g} ({r['seconds']:.1f} s)", flush=True)
    out: dict[str, list[dict[str, Any]]] = {n: [] for n in SWEEPS}
    for (name, value, dense), r in sorted(got.items(), key=lambda kv: kv[0][1]):
        if dense:
            default = got[name, value, False]
            out[name].append({**r, "default_growth": default["growth"], "default_verdict": default["verdict"]})
    return out


# ------------------------------------------------------------------------------------------------
# figure
# ------------------------------------------------------------------------------------------------


def _growth_forward(y: np.ndarray) -> np.ndarray:
    """The growth axis: log above the floor (a decade per unit), linear within it, log compressed below -floor."""
    y = np.asarray(y, dtype=float)
    a = np.maximum(np.abs(y) / FLOOR, 1.0)
    return np.where(y > FLOOR, 1.0 + np.log10(a), np.where(y < -FLOOR, -1.0 - NEG_SQUEEZE * np.log10(a), y / FLOOR))


def _growth_inverse(t: np.ndarray) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    return np.where(t > 1.0, FLOOR * 10.0 ** (t - 1.0),
                    np.where(t < -1.0, -FLOOR * 10.0 ** ((-1.0 - t) / NEG_SQUEEZE), t * FLOOR))


def _growth_axis(ax: Axes) -> None:
    """Im z on the growth axis (log above the floor, linear within +-floor, squeezed log below); the floor marked."""
    ax.set_yscale("function", functions=(_growth_forward, _growth_inverse))
    ax.set_ylim(-0.1, 1.0)
    pos = [10.0**k for k in range(-6, 1)]
    neg = [-1e-6, -1e-4, -1e-2]
    labels = [rf"$10^{{{k}}}$" for k in range(-6, 1)] + [rf"$-10^{{{k}}}$" for k in (-6, -4, -2)]
    ax.set_yticks([*pos, 0.0, *neg], [*labels[:7], "0", *labels[7:]])
    ax.yaxis.set_minor_locator(NullLocator())
    ax.axhline(FLOOR, color="0.6", lw=0.8, ls=":")
    ax.axhline(0.0, color="0.3", lw=0.6)
    ax.axhspan(-0.1, 0.0, color="0.93", zorder=0)
    ax.grid(True, which="major", alpha=0.3)


def _family_points(ax: Axes, x: np.ndarray, z: np.ndarray, fam: np.ndarray, size: float = 22.0) -> None:
    """Points coloured by family: filled for Re z > 0, open for Re z < 0."""
    for code, color in FAMILY_COLOR.items():
        sel = fam == code
        fwd = sel & (z.real > 0)
        bwd = sel & (z.real <= 0)
        ax.scatter(x[fwd], z.imag[fwd], s=size, color=color, edgecolor=color, zorder=3, lw=0.8)
        ax.scatter(x[bwd], z.imag[bwd], s=size, facecolor="none", edgecolor=color, zorder=3, lw=1.0)


def _family_handles() -> list[Line2D]:
    handles = [Line2D([], [], ls="", marker="o", color=c, label=FAMILY_LABEL[k]) for k, c in FAMILY_COLOR.items()]
    return handles + [Line2D([], [], ls="", marker="o", mfc="0.3", mec="0.3", label=r"$\mathrm{Re}\,z>0$ (filled)"),
                      Line2D([], [], ls="", marker="o", mfc="none", mec="0.3", label=r"$\mathrm{Re}\,z<0$ (open)")]


def _line_legend(ax: Axes, handles: list[Line2D], loc: str) -> None:
    ax.legend(handles=handles, fontsize=7, loc=loc, framealpha=0.9)


RAYLEIGH_LINE = Line2D([], [], color=FAMILY_COLOR[0], lw=1.4, label="Rayleigh branch (line)")
FASTEST_LINE = Line2D([], [], color="k", lw=0.7, label="fastest root")
FLOOR_LINE = Line2D([], [], color="0.6", lw=0.8, ls=":", label=r"floor $\mathrm{Im}\,z=10^{-6}$")


def panel_a(ax: Axes, a: dict[str, Any]) -> None:
    fm = a["fastest"]
    _family_points(ax, a["kH"], a["z"], a["family"], size=14.0)
    ax.plot(KH_LINE, a["rayleigh"].imag, color=FAMILY_COLOR[0], lw=1.4, zorder=2)
    ax.plot(KH_A, fm.growth, color="k", lw=0.7, zorder=4)
    ax.set_xscale("log")
    _growth_axis(ax)
    ax.set_xlabel(r"$kH$")
    ax.set_ylabel(IM_Z)
    ax.set_title(r"(a) $\eta=\infty$: every root with $\mathrm{Im}\,z\geq10^{-6}$ (complete window)" "\n"
                 r"$\gamma=3$, $f=0.9$, $\beta=0.3$, $\Delta=1$", fontsize=9)
    _line_legend(ax, [RAYLEIGH_LINE, FASTEST_LINE, FLOOR_LINE], "lower right")


def panel_b(ax: Axes, b: dict[str, Any]) -> None:
    fm = b["fastest"]
    ok = fm.status == 0
    ax.plot(KH_B, np.where(ok, fm.growth, np.nan), color="k", lw=0.7, zorder=2)
    _family_points(ax, KH_B[ok], fm.z[ok], fm.family[ok].astype(int), size=22.0)
    ax.plot(KH_LINE, b["rayleigh"].imag, color=FAMILY_COLOR[0], lw=1.4)
    ax.set_xscale("log")
    _growth_axis(ax)
    ax.set_xlabel(r"$kH$")
    ax.set_ylabel(IM_Z)
    ax.set_title(rf"(b) $\eta={ETA_B:g}$ (others as (a)): the fastest root only; at finite $\eta$" "\n"
                 r"roots lie just above the layers' poles at every $|\mathrm{Re}\,z|$ "
                 r"($\mathrm{Im}\,z\,|\mathrm{Re}\,z|\sim$ const)", fontsize=9)
    note = ("small $kH$: the stack's\ndilatational thickness\nresonances, " r"$n=1,2$:" "\n"
            r"$|\mathrm{Re}\,z|\approx n\pi/[\beta(1+\eta)kH]$," "\n"
            r"$\mathrm{Im}\,z\to$ const, $kH\,\mathrm{Im}\,z\to0$")
    ax.text(0.011, 3e-4, note, fontsize=6.5, va="center", linespacing=1.3)
    _line_legend(ax, [RAYLEIGH_LINE, FASTEST_LINE, FLOOR_LINE], "lower right")


def _sweep_x(rows: list[dict[str, Any]]) -> np.ndarray:
    return np.array([ETA_INF_X if math.isinf(r["value"]) else r["value"] for r in rows])


def _setting(name: str) -> str:
    """'$\\gamma=3$' etc.: a parameter at the paper's default, for titles."""
    v = PAPER[name]
    return SYMBOL[name][:-1] + (r"=\infty$" if math.isinf(v) else f"={v:g}$")


def _sweep_axes(ax: Axes, name: str, letter: str, inf_point: bool) -> None:
    if name in ("gamma", "eta"):
        ax.set_xscale("log")
    if inf_point:
        ax.axvline(2e3, color="0.5", lw=0.8, ls="--")
        ax.set_xticks([1, 10, 100, 1000, ETA_INF_X], ["1", "10", "$10^2$", "$10^3$", r"$\infty$"])
        ax.xaxis.set_minor_locator(NullLocator())
    ax.set_xlabel(SYMBOL[name])
    ax.set_ylabel(r"max over $kH\in[10^{-2},10^2]$ of $\mathrm{Im}\,z$", fontsize=8.5)
    others = ", ".join(_setting(k) for k in SYMBOL if k != name)
    ax.set_title(f"({letter}) max growth vs {SYMBOL[name]} ({others}, " r"$\Delta=1$)", fontsize=9)


def panel_sweep(ax: Axes, name: str, rows: list[dict[str, Any]], letter: str) -> set[str]:
    """Sliding growth (markers by family) and the Rayleigh branch's growth (line) against one parameter; returns the
    keys of SWEEP_HANDLES whose markers it drew."""
    x = _sweep_x(rows)
    col = {k: np.array([r[k] for r in rows]) for k in ("growth", "ray_growth", "family", "z", "verdict", "at_end",
                                                          "default_growth")}
    g, verdict = col["growth"], col["verdict"]
    fin = x != ETA_INF_X
    unstable = verdict == 1
    ax.plot(x[fin], col["ray_growth"][fin], color=FAMILY_COLOR[0], lw=1.4, marker=".", ms=5)
    ax.plot(x[fin], np.where(unstable, g, np.nan)[fin], color="0.5", lw=0.6, zorder=2)
    _family_points(ax, x[unstable], col["z"][unstable], col["family"][unstable], size=32.0)
    end = unstable & col["at_end"].astype(bool)
    ax.scatter(x[end], g[end], s=110, facecolor="none", edgecolor="k", lw=0.8, zorder=4)
    low = unstable & ~(col["default_growth"] >= g * (1 - 1e-6))
    ax.scatter(x[low], np.where(np.isfinite(col["default_growth"][low]), col["default_growth"][low], 0.0), marker="x",
               s=22, color="k", lw=0.9, zorder=4)
    _growth_axis(ax)
    for v, marker, color in ((0, "v", "0.55"), (2, "X", "m")):
        ax.scatter(x[verdict == v], np.full(int((verdict == v).sum()), -0.05), marker=marker, s=22, color=color,
                   zorder=3)
    if not fin.all():  # eta = inf: a separate point at the right
        ax.plot(x[~fin], col["ray_growth"][~fin], color=FAMILY_COLOR[0], marker="s", ms=5, ls="")
    _sweep_axes(ax, name, letter, not fin.all())
    used = {"stable": bool((verdict == 0).any()), "undetermined": bool((verdict == 2).any()),
            "end": bool(end.any()), "default": bool(low.any())}
    return {k for k, v in used.items() if v}


SWEEP_HANDLES = {
    "all": Line2D([], [], ls="", marker="o", ms=7, color="0.35", label="(c)-(f): max over $kH$, all branches"),
    "rayleigh": Line2D([], [], color=FAMILY_COLOR[0], lw=1.4, marker=".",
                       label=r"Rayleigh branch alone (■: $\eta=\infty$)"),
    "stable": Line2D([], [], ls="", marker="v", color="0.55", label="stable above the floor"),
    "undetermined": Line2D([], [], ls="", marker="X", color="m", label="undetermined"),
    "end": Line2D([], [], ls="", marker="o", ms=10, mfc="none", mec="k", label="max at $kH=10^{-2}$ (range end)"),
    "default": Line2D([], [], ls="", marker="x", color="k", label="default 17-pt grid, where lower (at 0: stable)"),
}


def make_figure(a: dict[str, Any], b: dict[str, Any], sweeps: dict[str, list[dict[str, Any]]]) -> None:
    fig, axes = plt.subplots(2, 3, figsize=(13.6, 8.2))
    panel_a(axes[0, 0], a)
    panel_b(axes[0, 1], b)
    used = {"all", "rayleigh"}
    for ax, (name, letter) in zip(axes.flat[2:], (("gamma", "c"), ("eta", "d"), ("f", "e"), ("beta", "f")),
                                  strict=True):
        used |= panel_sweep(ax, name, sweeps[name], letter)
    fig.suptitle(r"Families of roots of $F(z;kH)=0$ (Aldam et al., PRX 2016): growth "
                 r"$\mathrm{Im}\,z=\mathrm{Im}\,c/c_s$; axis log above $10^{-6}$, linear within $\pm10^{-6}$, "
                 "compressed log below (grey)",
                 fontsize=10, y=0.995)
    fig.legend(handles=_family_handles(), loc="upper center", ncol=6, fontsize=8, bbox_to_anchor=(0.5, 0.975),
               frameon=False)
    sweep_handles = [h for k, h in SWEEP_HANDLES.items() if k in used]
    fig.legend(handles=sweep_handles, loc="upper center", ncol=len(sweep_handles), fontsize=8,
               bbox_to_anchor=(0.5, 0.948), frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.935))
    fig.savefig(OUT, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------
# tables
# ------------------------------------------------------------------------------------------------


def _fmt(v: float, spec: str = ".4g") -> str:
    return "—" if not np.isfinite(v) else format(v, spec)


def _default_cell(r: dict[str, Any]) -> str:
    """The default grid's result where it differs from the dense grid's (bold), else 'same'."""
    g, d = r["growth"], r["default_growth"]
    if r["default_verdict"] != r["verdict"]:
        return f"**{model.VERDICTS[r['default_verdict']]}**" + (f" **{d:.4g}**" if np.isfinite(d) else "")
    if (np.isnan(g) and np.isnan(d)) or abs(d - g) <= 1e-6 * abs(g):
        return "same"
    return f"**{_fmt(d)}**"


def _row(r: dict[str, Any]) -> str:
    verdicts = model.VERDICTS
    value = "∞" if math.isinf(r["value"]) else f"{r['value']:.4g}"
    ray = f"{verdicts[r['ray_verdict']]} ({r['ray_reason']})"
    slide = f"{verdicts[r['verdict']]} ({r['reason']})"
    fam, z, kh, ratio = "—", "—", "—", "—"
    if r["verdict"] == 1:
        fam = model.FAMILIES.get(r["family"], "—").split(" (")[0]
        z = f"{r['z'].real:.4f} + {r['z'].imag:.4g}i"
        kh = _fmt(r["kH"]) + (" (end)" if r["at_end"] else "")
        ratio = f"{r['growth'] / r['ray_growth']:.3g}" if r["ray_growth"] > 0 else "Rayleigh stable"
    cells = [value, ray, _fmt(r["ray_growth"]), slide, _fmt(r["growth"]), fam, kh, z, ratio, _default_cell(r)]
    return "| " + " | ".join(cells) + " |"


def print_sweep_tables(sweeps: dict[str, list[dict[str, Any]]]) -> None:
    head = ("| {p} | Rayleigh verdict (reason) | Rayleigh growth | sliding verdict (reason) | sliding growth | "
            "family at max | kH at max | z at max | growth ratio | default-grid growth |")
    for name, rows in sweeps.items():
        others = ", ".join(f"{k} = {PAPER[k]:g}" for k in ("gamma", "f", "beta", "eta", "Delta") if k != name)
        print(f"\n**Sweep in {name}** ({others}; floor 1e-6; kH in [1e-2, 1e2], 65 points)\n")
        print(head.format(p=name))
        print("|" + "---|" * 10)
        for r in rows:
            print(_row(r))
    print("\nReason codes: Rayleigh `model.VERDICT_STATUS`, sliding `model.SLIDING_STATUS`. Growth ratio = sliding "
          "growth / Rayleigh growth. (end): the maximum lies at an end of the kH range. Default-grid growth: "
          "`sliding_analysis` on its default 17-point grid (bold where the verdict or the growth differs).")


def print_material_table(kH: float = 1.0, H1: float = 0.1) -> None:
    print(f"\n**e-folding time t = H1 / (c_s kH Im z)** at kH = {kH:g}, H1 = {H1:g} m (model.e_folding_time)\n")
    print("| material | c_s [m/s] | t at Im z = 1e-6 [s] | t at Im z = 1e-3 [s] |")
    print("|---|---|---|---|")
    for name in model.material_names():
        m = model.material(name)
        t6, t3 = (float(model.e_folding_time(kH=kH, z=complex(0.0, im), H1=H1, c_s=m.c_s)) for im in (1e-6, 1e-3))
        print(f"| {name} | {m.c_s:.0f} | {t6:.4g} | {t3:.4g} |")


def main() -> None:
    t0 = time.perf_counter()
    print(f"(a) eta = inf: every root above the floor at {KH_A.size} kH ...", flush=True)
    a = all_roots_eta_inf()
    print(f"    {a['z'].size} roots; counts per kH {a['counts'].min()}..{a['counts'].max()} "
          f"({time.perf_counter() - t0:.1f} s)", flush=True)
    for p in a["problems"]:
        print("    WARNING", p)
    print(f"(b) eta = {ETA_B:g}: the fastest root at {KH_B.size} kH ...", flush=True)
    t1 = time.perf_counter()
    b = fastest_eta_b()
    bad = int((b["fastest"].status != 0).sum())
    print(f"    done ({time.perf_counter() - t1:.1f} s; {bad} kH without a certified root)", flush=True)
    print(f"(c)-(f) sliding_analysis sweeps ({sum(v.size for v in SWEEPS.values())} values x 2 grids) ...",
          flush=True)
    t2 = time.perf_counter()
    sweeps = run_sweeps()
    print(f"    done ({time.perf_counter() - t2:.1f} s)", flush=True)
    make_figure(a, b, sweeps)
    print(f"wrote {OUT.relative_to(ROOT)}")
    print_sweep_tables(sweeps)
    print_material_table()
    print(f"\ntotal run time {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
