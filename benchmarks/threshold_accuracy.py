"""Accuracy of the certified thresholds against the independent oracle's neutral modes (issue 24, point 6).

Random parameter sets (half finite eta, most Delta < 1 with xi > 0; the sets of tests/model/test_boundary.py), every
crossing in gamma (and, for sets with a gamma, in eta) in the default ranges: each certified threshold is compared
with tests/oracle.py's neutral mode (Newton on the three real equations at 50 digits, started from the model's);
the relative errors of the threshold, of kH and of Re z are summarised.

    python benchmarks/threshold_accuracy.py [--sets 24]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide import model  # noqa: E402
from tests import oracle  # noqa: E402


def random_sets(n: int, seed: int, which: str) -> list[dict]:
    """As tests/model/test_boundary.py's _random_sets (and, for eta, a gamma in [2, 30] instead of eta)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        delta = 1.0 if i % 4 == 0 else float(rng.uniform(0.2, 1.0))
        out.append(dict(f=float(rng.uniform(0.3, 1.5)), beta=float(rng.uniform(0.05, 0.65)),
                        eta=math.inf if i % 2 == 0 else float(10 ** rng.uniform(0.3, 3.0)), Delta=delta,
                        xi=0.0 if delta == 1.0 else float(10 ** rng.uniform(-1.5, 1.5))))
    if which == "eta":
        rng = np.random.default_rng(seed + 1)
        for p in out:
            p.pop("eta")
            p["gamma"] = float(10 ** rng.uniform(0.3, 1.5))
    return out


def errors(which: str, n: int, seed: int) -> dict:
    sets = random_sets(n, seed, which)
    cols = {k: np.array([p[k] for p in sets]) for k in sets[0]}
    c = model.critical_gammas(**cols) if which == "gamma" else model.critical_etas(**cols)
    err_v, err_q, err_x, refused = [], [], [], 0
    for i, p in enumerate(sets):
        for k in range(c.value.shape[1]):
            if c.reason[i, k] in (0, 1):
                args = {**dict(gamma=1.0, eta=math.inf), **p, which: float(c.value[i, k])}
                x, q, v = oracle.neutral_mode(which, float(c.z[i, k]), float(c.kH[i, k]), float(c.value[i, k]),
                                              args["gamma"], args["f"], args["beta"], args["eta"], args["Delta"],
                                              args["xi"], edge=bool(c.reason[i, k] == 1))
                err_v.append(abs(float(c.value[i, k]) / float(v) - 1))
                err_q.append(abs(float(c.kH[i, k]) / float(q) - 1))
                err_x.append(abs(float(c.z[i, k]) - float(x)) / max(abs(float(x)), 1e-3))
            elif c.reason[i, k] >= 0:
                refused += 1
    return dict(which=which, sets=n, n=len(err_v), refused=refused, v=np.array(err_v), q=np.array(err_q),
                x=np.array(err_x))


def markdown(n: int = 24) -> str:
    rows = [errors("gamma", n, 11), errors("eta", n, 12)]
    lines = ["| parameter | sets | certified thresholds | refused (reason code) | threshold rel. error max / median "
             "| kH max | Re z max |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['which']} | {r['sets']} | {r['n']} | {r['refused']} | {r['v'].max():.1e} / "
                     f"{np.median(r['v']):.1e} | {r['q'].max():.1e} | {r['x'].max():.1e} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sets", type=int, default=24)
    print(markdown(ap.parse_args().sets))
