"""Thresholds where the Rayleigh branch used to be masked inside the bracket, and bad search ranges.

Found by tests/model/test_robustness.py: scipy's brentq used to raise 'function value is NaN; solver cannot continue'
(naming no parameter), and gamma_range/eta_range were not validated. With the continuous max growth over the
part of the kH range where the branch is the Rayleigh mode (docs/physics.md §9) the first case has a certified
threshold (checked against the independent oracle), the second none in the range, said with its reason.
"""

from __future__ import annotations

import math

import pytest

from asymslide import model
from tests import oracle


def test_former_nan_bracket_cases_give_an_oracle_threshold_or_a_named_reason() -> None:
    kw = dict(f=2.0, beta=1 / math.sqrt(2), eta=10**0.5)
    c = model.critical_gammas(**kw)
    assert c.count == 1 and c.reason[0] == 0 and c.direction[0] == 1
    x, q, g = oracle.neutral_mode("gamma", float(c.z[0]), float(c.kH[0]), float(c.value[0]), 1.0, **kw)
    assert float(c.value[0]) == pytest.approx(float(g), rel=1e-12) and model.critical_gamma(**kw) == c.value[0]
    assert float(c.kH[0]) == pytest.approx(float(q), rel=1e-9) and float(c.z[0]) == pytest.approx(float(x), rel=1e-12)
    with pytest.raises(ValueError, match=r"no stability threshold for eta in \[1, 1e\+08\]: stable throughout: max "
                                         r"growth stays between .* \(but the verdict is undetermined at \d+ of the "
                                         r"scan values"):
        model.critical_eta(gamma=0.01, f=2.0, beta=0.01)


BAD_RANGES = [(0, 10), (-1, 10), (-5, -1), (float("nan"), 10), (1, float("inf")), (10, 1), (3, 3), (1,),
              (1, 2, 3), "1,10", None, 5.0, ("a", "b"), (1 + 1j, 2), [[1, 2]]]


@pytest.mark.parametrize("bad", BAD_RANGES, ids=repr)
def test_gamma_range_is_validated(bad) -> None:
    with pytest.raises(ValueError, match="gamma_range must be a pair"):
        model.critical_gamma(f=0.9, beta=0.3, gamma_range=bad)


@pytest.mark.parametrize("bad", BAD_RANGES, ids=repr)
def test_eta_range_is_validated(bad) -> None:
    with pytest.raises(ValueError, match="eta_range must be a pair"):
        model.critical_eta(gamma=3.0, f=0.9, beta=0.3, eta_range=bad)


def test_valid_ranges_as_list_or_array_still_work() -> None:
    import numpy as np

    g = model.critical_gamma(f=0.9, beta=0.3, gamma_range=[1, 10])
    e = model.critical_eta(gamma=3.0, f=0.9, beta=0.3, eta_range=np.array([1.0, 100.0]))
    assert abs(g - 2.4149) < 1e-4 and abs(e - 3.2982) < 1e-4
