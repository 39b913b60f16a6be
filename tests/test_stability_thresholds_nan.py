"""Thresholds where the Rayleigh branch is masked inside the bracket, and bad search ranges.

Found by tests/test_robustness.py: scipy's brentq used to raise 'function value is NaN; solver
cannot continue' (naming no parameter), and gamma_range/eta_range were not validated.
"""

from __future__ import annotations

import math

import pytest

import model


@pytest.mark.parametrize(("fn", "kwargs", "name"), [
    (model.critical_gamma, dict(f=2.0, beta=1 / math.sqrt(2), eta=10**0.5), "gamma"),
    (model.critical_eta, dict(gamma=0.01, f=2.0, beta=0.01), "eta"),
])
def test_nan_inside_the_bracket_names_the_parameter(fn, kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=f"no stability threshold for {name} located in .*undefined"):
        fn(**kwargs)


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
