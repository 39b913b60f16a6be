"""model.fastest_growing_mode against its definition: the Rayleigh-branch mode with the largest growth rate
k Im c = (kH Im z) c_s/H, i.e. the maximum over kH of kH Im z (docs/physics.md §12.5)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from asymslide import model

KH = np.logspace(-3, 3, 400)

CASES = [
    dict(gamma=3.0, f=0.9, beta=0.3),  # the paper's Fig. 4
    dict(gamma=3.0, f=0.9, beta=1345.0 / 2700.0),  # PMMA in plane strain (the Lab-units defaults)
    dict(gamma=5.0, f=0.6, beta=0.3, eta=5.0, Delta=0.5, xi=1.0),
]


def _rate(kH: np.ndarray, p: dict) -> np.ndarray:
    return kH * model.spectrum(kH, **p).imag


@pytest.mark.parametrize("p", CASES)
def test_no_mode_grows_faster(p: dict) -> None:
    k, z = model.fastest_growing_mode(KH, **p)
    assert z == complex(model.spectrum(np.array([k]), **p)[0])  # z is the branch at k
    best = k * z.imag
    assert best > 0
    assert best >= np.nanmax(_rate(KH, p))  # the grid
    fine = k * np.linspace(0.98, 1.02, 801)  # around it, 5e-5 apart
    assert best >= np.nanmax(_rate(fine, p)) * (1.0 - 1e-13)


@pytest.mark.parametrize("p", CASES)
def test_is_stationary(p: dict) -> None:
    """d(kH Im z)/d ln kH = 0 at k: the centred first difference is a small fraction of the second difference."""
    k, z = model.fastest_growing_mode(KH, **p)
    h = 1e-3
    lo, mid, hi = _rate(k * np.exp([-h, 0.0, h]), p)
    assert mid == pytest.approx(k * z.imag, rel=1e-14)
    second = lo + hi - 2.0 * mid
    assert second < 0
    # (hi - lo)/second = 2 delta/h for a peak off by delta in ln kH: here delta < 5e-6
    assert abs(hi - lo) < 1e-2 * abs(second)


@pytest.mark.parametrize("p", CASES)
def test_lies_beyond_the_maximum_of_im_z(p: dict) -> None:
    """At the maximum of kH Im z, Im z + kH d(Im z)/dkH = 0, so Im z decreases there: the fastest-growing mode
    has a shorter wavelength than the maximum of Im z (model.growth_analysis) whenever a mode grows."""
    k, _ = model.fastest_growing_mode(KH, **p)
    g = model.growth_analysis(KH, **p)
    assert g.kH_min < g.kH_at_max < k < g.kH_max


def test_lab_units_of_the_mode() -> None:
    """Its growth rate in 1/s is the largest of model.growth_rate on the grid, for any H and c_s."""
    p = CASES[1]
    k, z = model.fastest_growing_mode(KH, **p)
    zs = model.spectrum(KH, **p)
    for H1, c_s in ((0.01, 1345.0), (0.3, 3000.0)):
        peak = float(model.growth_rate(kH=k, z=z, H1=H1, c_s=c_s))
        assert peak >= np.nanmax(model.growth_rate(kH=KH, z=zs, H1=H1, c_s=c_s))
        assert peak == pytest.approx(k * z.imag * c_s / H1, rel=1e-15)


def test_stable_setting_and_grid_ends() -> None:
    """A stable setting returns the least-damped grid point (not refined at the end of the grid)."""
    p = dict(gamma=0.5, f=0.9, beta=CASES[1]["beta"])
    k, z = model.fastest_growing_mode(KH, **p)
    rate = _rate(KH, p)
    assert k * z.imag <= 0 and np.nanmax(rate) <= 0
    i = int(np.nanargmax(rate))
    assert i == 0 and (k, z) == (KH[0], complex(model.spectrum(KH, **p)[0]))


def test_masked_branch_gives_nan() -> None:
    k, z = model.fastest_growing_mode(KH, gamma=0.01, f=0.9, beta=CASES[1]["beta"])
    assert math.isnan(k) and math.isnan(z.real) and math.isnan(z.imag)


@pytest.mark.parametrize(("kH", "kwargs", "needle"), [
    (np.array([1.0, 2.0]), {}, "at least 3 points"),
    (np.array([3.0, 2.0, 1.0]), {}, "increasing"),
    (np.array([-1.0, 1.0, 2.0]), {}, "kH"),
    (KH, {"gamma": np.array([1.0, 2.0])}, "gamma must be a scalar"),
    (KH, {"beta": 0.9}, "beta"),
])
def test_bad_input_names_the_problem(kH, kwargs: dict, needle: str) -> None:
    p = {**CASES[0], **kwargs}
    with pytest.raises(ValueError, match=needle):
        model.fastest_growing_mode(kH, **p)
