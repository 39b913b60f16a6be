"""The verdict and reason codes as named integers (model.Verdict, CrossingReason, ThresholdReason, SlidingReason):
the same integers as the results and the atlases hold, one name per text of the STATUS tables."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from asymslide import model
from asymslide.model import _kernels as K

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(("codes", "texts"), [
    (model.CrossingReason, model.CROSSING_STATUS),
    (model.ThresholdReason, model.THRESHOLD_STATUS),
    (model.SlidingReason, model.SLIDING_STATUS),
])
def test_every_reason_has_one_name_and_one_text(codes, texts) -> None:
    assert sorted(texts) == [int(c) for c in codes] == list(range(len(codes)))
    assert all(isinstance(key, codes) for key in texts)  # the tables are keyed by the names


def test_the_verdict_classes_are_the_results_integers() -> None:
    assert model.VERDICTS == {0: "stable", 1: "unstable", 2: "undetermined"}
    assert [v.name for v in model.Verdict] == ["STABLE", "UNSTABLE", "UNDETERMINED"]
    classes = model.verdict_class(np.array([K.V_STABLE, K.V_UNSTABLE, K.V_MARGINAL, np.nan]))
    assert classes.tolist() == [model.Verdict.STABLE, model.Verdict.UNSTABLE, model.Verdict.UNDETERMINED,
                                model.Verdict.UNDETERMINED]
    sliding = model.sliding_verdict(np.array(list(model.SlidingReason)))
    assert sliding.tolist() == [0, 1, 2, 2, 1] and sliding.dtype == np.int8
    r = model.sliding_analysis(gamma=3.0, f=0.9, beta=0.3, eta=math.inf, kH=np.logspace(-0.5, 0.0, 5))
    assert model.Verdict(int(r.verdict)) is model.Verdict.UNSTABLE
    assert model.SlidingReason(int(r.verdict_reason)) is model.SlidingReason.UNSTABLE


def test_the_certified_crossings_are_a_neutral_mode_or_one_at_an_end_of_the_range() -> None:
    assert model.CERTIFIED_CROSSINGS == (model.CrossingReason.CERTIFIED, model.CrossingReason.EDGE)
    assert all(model.CROSSING_STATUS[c].startswith("certified") for c in model.CERTIFIED_CROSSINGS)
    assert not any(t.startswith("certified") for c, t in model.CROSSING_STATUS.items()
                   if c not in model.CERTIFIED_CROSSINGS)


#: a verdict or reason compared with a bare integer (``verdict == 1``, ``d["reason"] != 0``) or a tuple of them
BARE_CODE = re.compile(r"""(verdict|reason)\w*["'\]]*\s*(==|!=)\s*\d|isin\([^)]*(verdict|reason)[^)]*,\s*\(\d""")


def test_the_app_and_the_engine_name_the_codes_they_compare() -> None:
    found = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}"
             for folder in ("app", "atlas", "asymslide")
             for p in sorted((ROOT / folder).rglob("*.py"))
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if BARE_CODE.search(line)]
    assert found == []
