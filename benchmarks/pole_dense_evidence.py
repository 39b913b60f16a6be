"""The evidence behind the pole-dense status (docs/physics.md §9, issue 24 point 3).

1. Resolution dependence. For random parameter sets with finite eta, the Rayleigh branch is continued twice from
   kH = 1e4: with the growth maps' coarse path (predictor target 1e-3, nodes to 1e-10) and with a 100x finer one
   (1e-5, nodes at full accuracy). At the 97 kH of the atlases' grid the exact roots (solve_at) are compared: where
   both give a root they must agree to 1e-9, and both must give one or neither. Counted separately for roots below
   the shear speed (|Re z| <= 1) and above it, and, on a 1501-point sampling, where (in the continuation's
   direction, from large kH down) the two first part: the lower block's attenuation eta kH Re alpha_s there.
2. The all-branch count (model.unstable_count, argument principle) at a pole-dense point: how many roots lie in
   |Re z| <= 6 above Im z = im_min for im_min = 1e-3, 1e-5, 1e-7: the independent check of what "the" growth
   there would mean.

    python benchmarks/pole_dense_evidence.py [--sets 150] [--seed 21]
"""

from __future__ import annotations

import argparse
import cmath
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide import model  # noqa: E402
from asymslide.model._kernels.continuation import MAP_NODE_TOL, PRED_TOL  # noqa: E402
from asymslide.model._kernels.newton import FULL_TOL  # noqa: E402
from asymslide.model._kernels.path import OK, build_path, solve_at  # noqa: E402
from asymslide.model._kernels.rayleigh import rayleigh_z  # noqa: E402
from asymslide.model._kernels.records import Params  # noqa: E402

S = np.log(np.logspace(-3, 3, 97))
DENSE = np.log(np.logspace(3, -3, 1501))  # from large kH down: the continuation's direction
FINE_PRED = 1e-5


def _paths(p: Params):
    z_r = rayleigh_z(p.beta)
    coarse = build_path(S[0], S[-1], z_r, p, PRED_TOL, MAP_NODE_TOL)
    fine = build_path(S[0], S[-1], z_r, p, FINE_PRED, FULL_TOL)
    return coarse, fine


def real_root(path_code, s: float, p: Params) -> tuple[complex, int]:
    path, code = path_code
    if code != OK:
        return complex(math.nan, math.nan), code
    z, st, *_ = solve_at(s, path, p, 0.0)
    return z, st


def _same(a: tuple[complex, int], b: tuple[complex, int]) -> bool:
    (za, sa), (zb, sb) = a, b
    return (sa == sb == OK and abs(za - zb) <= 1e-9 * abs(zb)) or (sa != OK and sb != OK)


def _first_parting(coarse, fine, p: Params) -> tuple[float, complex, str] | None:
    """Where, from large kH down, the two continuations first part (1501 kH): (attenuation there, z, how)."""
    prev = None
    for s in DENSE:
        a, b = real_root(coarse, s, p), real_root(fine, s, p)
        if not _same(a, b):
            zp, sp = prev if prev is not None else (b[0], s)
            att = p.eta * math.exp(sp) * cmath.sqrt(1 - zp * zp).real
            how = "different roots" if a[1] == b[1] == OK else f"one lost (coarse status {a[1]}, fine {b[1]})"
            return att, zp, how
        if a[1] == OK:
            prev = (a[0], s)
    return None


def resolution(n_sets: int, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    points = {"sub": [0, 0], "super": [0, 0]}  # [agree, disagree]
    sets_super = sets_parting_super = sets_parting_sub_only = 0
    partings = []
    for _ in range(n_sets):
        p = Params(float(10 ** rng.uniform(-1, 1.5)), float(rng.uniform(0.2, 1.2)), float(rng.uniform(0.08, 0.68)),
                     float(10 ** rng.uniform(math.log10(1.5), math.log10(300))),
                     1.0 if rng.random() < 0.3 else float(rng.uniform(0.2, 1.0)), 1.0)
        coarse, fine = _paths(p)
        sup = dis_sup = dis_sub = False
        for s in S:
            a, b = real_root(coarse, s, p), real_root(fine, s, p)
            ref = b[0] if b[1] == OK else a[0]
            region = "super" if (np.isfinite(ref) and abs(ref.real) > 1) else "sub"
            same = _same(a, b)
            points[region][0 if same else 1] += 1
            sup |= region == "super"
            dis_sup |= region == "super" and not same
            dis_sub |= region == "sub" and not same
        sets_super += sup
        sets_parting_super += dis_sup
        sets_parting_sub_only += dis_sub and not dis_sup
        if dis_sup or dis_sub:
            part = _first_parting(coarse, fine, p)
            if part is not None:
                partings.append(part)
    return dict(n=n_sets, points=points, sets_super=sets_super, sets_parting_super=sets_parting_super,
                sets_parting_sub_only=sets_parting_sub_only, partings=partings)


def counts(kH: float = 9.1896, gamma: float = 0.12, eta: float = 10.0) -> dict:
    p = dict(gamma=gamma, f=0.9, beta=0.3, eta=eta)
    z = complex(model.spectrum(np.array([kH]), **p)[0])
    att = eta * kH * cmath.sqrt(1 - z * z).real
    c = {m: model.unstable_count(kH, **p, re_max=6.0, im_min=m, im_max=1.0) for m in (1e-3, 1e-5, 1e-7)}
    return dict(p=p, kH=kH, z=z, att=att, counts=c)


def markdown(n_sets: int = 150, seed: int = 21) -> str:
    r = resolution(n_sets, seed)
    (sa, sd), (pa, pd) = r["points"]["sub"], r["points"]["super"]
    lines = [f"{r['n']} random sets (gamma in [0.1, 30], f in [0.2, 1.2], beta in [0.08, 0.68], eta in [1.5, 300], "
             f"Delta in [0.2, 1], xi = 1), the coarse path against a {1e-3 / FINE_PRED:.0f}x finer one at 97 kH in "
             "[1e-3, 1e3]:", "",
             "| roots | kH points compared | coarse and fine disagree |", "|---|---|---|",
             f"| below the shear speed, abs(Re z) <= 1 | {sa + sd} | {sd} |",
             f"| above it, abs(Re z) > 1 | {pa + pd} | {pd} |", "",
             f"Sets reaching abs(Re z) > 1: {r['sets_super']}; of them {r['sets_parting_super']} with a disagreement "
             f"there; sets with disagreements only below the shear speed: {r['sets_parting_sub_only']}.", "",
             "Where the two continuations first part (1501 kH, from large kH down; eta kH Re alpha_s of the last "
             "common root):", ""]
    for att, z, how in sorted(r["partings"], key=lambda t: t[0]):
        lines.append(f"- {att:.3g} at z = {z.real:.6f}{z.imag:+.2e}i: {how}")
    c = counts()
    lines += ["", f"All-branch count at eta = {c['p']['eta']:g}, gamma = {c['p']['gamma']:g}, f = 0.9, beta = 0.3, "
                  f"kH = {c['kH']:g} (the branch: z = {c['z'].real:.6f}{c['z'].imag:+.2e}i, eta kH Re alpha_s = "
                  f"{c['att']:.2g}), roots with abs(Re z) <= 6 and Im z >= im_min: "
                  + ", ".join(f"{n} for im_min = {m:g}" for m, n in c["counts"].items()) + "."]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sets", type=int, default=150)
    ap.add_argument("--seed", type=int, default=21)
    a = ap.parse_args()
    print(markdown(a.sets, a.seed))
