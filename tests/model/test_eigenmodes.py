"""Tests of model.eigenmodes, the collocation eigen-solver (docs/physics.md §15), against the other solver.

The expected values never come from the eigen-solver: they are the roots certified by the contour-integral solver
(:func:`model.unstable_modes`, the argument principle on the closed-form F), the Rayleigh branch
(:func:`model.rayleigh_branch`, Newton continuation on F), the closed-form response functions
(:func:`model.response_functions`, for the mode shapes) and the paper's check values (docs/physics.md §7). The two
solvers share no code: the eigen-solver discretises Eq. S-LE and never evaluates G_x, G_y or F
(:func:`test_the_module_imports_no_closed_form`).
"""

from __future__ import annotations

import ast
import importlib
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.polynomial import chebyshev as C

from asymslide import model
from asymslide.model import eigenmodes, mode_shape

em = importlib.import_module("asymslide.model.eigenmodes")  # the module (model.eigenmodes is the function)

PAPER = dict(gamma=3.0, f=0.9, beta=0.3)
RTOL = 1e-8  # the cross-validation's tolerance
SLACK = 1e-6  # relative shrink / enlargement of a window: roots within it of an edge are judged on both sides


# ------------------------------------------------------------------------------------------------
# the cross-validation: every certified root is an eigenvalue and every converged eigenvalue a root
# ------------------------------------------------------------------------------------------------


def _scaled(window: dict, s: float) -> dict:
    """The window enlarged (s > 0) or shrunk (s < 0) by the relative amount |s| on each edge."""
    return dict(
        re_max=window["re_max"] * (1 + s),
        im_min=window["im_min"] * (1 - s) if window["im_min"] > 0 else window["im_min"] * (1 + s),
        im_max=window["im_max"] * (1 + s),
    )


def _inside(z: np.ndarray, window: dict) -> np.ndarray:
    return (np.abs(z.real) <= window["re_max"]) & (z.imag >= window["im_min"]) & (z.imag <= window["im_max"])


def _nearest_rel(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each element of a, the relative distance to the nearest element of b (inf if b is empty)."""
    if b.size == 0:
        return np.full(a.size, np.inf)
    return np.min(np.abs(a[:, None] - b[None, :]), axis=1) / np.abs(a)


def cross_validate(kH: float, params: dict, window: dict) -> tuple[int, float]:
    """Assert that both solvers give the same roots in the window; return (their number, the largest relative
    difference).

    The contour solver counts and locates the roots in the window; the eigen-solver is asked for the slightly
    enlarged window (so that a root on an edge is demanded converged) and must drop nothing there. Every contour
    root is an eigenvalue, every eigenvalue in the slightly shrunk window is a contour root, and the counts agree
    on the enlarged and the shrunk window unless an eigenvalue lies within SLACK of an edge.
    """
    roots = model.unstable_modes(kH, **params, **window)
    big, small = _scaled(window, SLACK), _scaled(window, -SLACK)
    res = eigenmodes(kH, **params, **big)
    assert res.dropped == 0, (res.dropped, res.n)
    eig_small = res.z[_inside(res.z, small)]
    to_eig = _nearest_rel(roots, res.z)
    to_roots = _nearest_rel(eig_small, roots)
    assert np.all(to_eig <= RTOL), (roots, res.z)
    assert np.all(to_roots <= RTOL), (roots, res.z)
    assert eig_small.size <= roots.size <= res.z.size
    if eig_small.size != res.z.size:  # an eigenvalue within SLACK of an edge: which side is not decidable here
        edge = res.z[~_inside(res.z, small)]
        assert np.all(_nearest_rel(edge, roots) <= RTOL) or roots.size == eig_small.size
    else:
        assert roots.size == res.z.size
    worst = float(max(np.max(to_eig, initial=0.0), np.max(to_roots, initial=0.0)))
    return int(roots.size), worst


def _finite_sets(seed: int, n: int, budget: int = 90, qeta_max: float = 120.0) -> list[tuple[float, dict, dict]]:
    """n seeded random parameter sets at finite eta and their windows.

    kH log-uniform over [0.01, 30], eta over [1.5, 100] (redrawn while kH (1 + eta) > qeta_max: the collocation's
    cost grows like kH (1 + eta) |z|, docs/physics.md §15), gamma over [0.3, 30], f uniform over [-1.2, 1.2], beta
    over [0.15, 0.7], Delta = 1 or uniform over [0.2, 1], xi = 0 or log-uniform over [0.01, 100]; the window
    im_min in {1e-3, 3e-3, 1e-2}, im_max = 1.5 and the widest re_max of (10, 8, 5, 3, 2, 1.2) whose coarser
    resolution has at most `budget` points in all.
    """
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        kH = float(10 ** rng.uniform(-2, math.log10(30)))
        eta = float(10 ** rng.uniform(math.log10(1.5), 2))
        if kH * (1 + eta) > qeta_max:
            continue
        p = dict(
            gamma=float(10 ** rng.uniform(-0.5, 1.5)),
            f=float(rng.uniform(-1.2, 1.2)),
            beta=float(rng.uniform(0.15, 0.7)),
            eta=eta,
            Delta=float(rng.choice([1.0, rng.uniform(0.2, 1)])),
            xi=float(rng.choice([0.0, 10 ** rng.uniform(-2, 2)])),
        )
        im_min = float(rng.choice([1e-3, 3e-3, 1e-2]))
        for re_max in (10.0, 8.0, 5.0, 3.0, 2.0, 1.2):
            window = dict(re_max=re_max, im_min=im_min, im_max=1.5)
            if sum(model.eigenmode_resolution(kH, beta=p["beta"], eta=eta, **window)) <= budget:
                break
        out.append((kH, p, window))
    return out


FINITE = _finite_sets(49, 32)
FAST = [
    i
    for i, (kH, p, w) in enumerate(FINITE)
    if sum(model.eigenmode_resolution(kH, beta=p["beta"], eta=p["eta"], **w)) <= 40
][:6]


@pytest.mark.parametrize("i", FAST)
def test_cross_validation_fast(i):
    kH, p, window = FINITE[i]
    cross_validate(kH, p, window)


@pytest.mark.slow
def test_cross_validation_at_seeded_points():
    """32 seeded sets (eta 1.5 ... 100, kH 0.01 ... 30): the same roots, to 1e-8, in every window."""
    found = [cross_validate(kH, p, w) for kH, p, w in FINITE]
    assert sum(n for n, _ in found) >= 100  # the sets do hold roots to compare (175 at this seed, in 18 sets)
    assert sum(1 for kH, p, _ in FINITE if p["eta"] >= 30) >= 5 and sum(1 for kH, *_ in FINITE if kH >= 3) >= 5


CORNERS = [  # the ends of the ranges that the random sets (kH (1 + eta) <= 120) do not reach together
    (30.0, dict(gamma=10.0, f=0.9, beta=0.3, eta=1.5), dict(re_max=1.2, im_min=1e-3, im_max=1.5)),
    (30.0, dict(gamma=30.0, f=-1.1, beta=0.5, eta=1.5, Delta=0.5, xi=1.0), dict(re_max=2.0, im_min=1e-3, im_max=1.5)),
    (0.3, dict(gamma=10.0, f=0.9, beta=0.3, eta=100.0), dict(re_max=3.0, im_min=1e-2, im_max=1.5)),
    (
        0.05,
        dict(gamma=20.0, f=1.0, beta=0.4, eta=100.0, Delta=0.4, xi=10.0),
        dict(re_max=10.0, im_min=1e-3, im_max=1.5),
    ),
]


@pytest.mark.slow
@pytest.mark.parametrize("kH, p, window", CORNERS)
def test_cross_validation_at_the_corners(kH, p, window):
    n, _ = cross_validate(kH, p, window)
    assert n >= 1


def _half_space_sets(seed: int, n: int) -> list[tuple[float, dict, dict]]:
    """n seeded sets at eta = inf (kH log-uniform over [0.05, 10], the rest as :func:`_finite_sets`)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        kH = float(10 ** rng.uniform(math.log10(0.05), 1))
        p = dict(
            gamma=float(10 ** rng.uniform(0.3, 1.5)),
            f=float(rng.uniform(-1.2, 1.2)),
            beta=float(rng.uniform(0.15, 0.7)),
            eta=math.inf,
            Delta=float(rng.choice([1.0, rng.uniform(0.2, 1)])),
            xi=float(rng.choice([0.0, 10 ** rng.uniform(-2, 2)])),
        )
        out.append((kH, p, dict(re_max=5.0, im_min=float(rng.choice([1e-3, 1e-2])), im_max=1.5)))
    return out


@pytest.mark.slow
def test_cross_validation_half_space():
    """eta = inf on the stretched half-space: the same roots in the upper half-plane, none spurious."""
    found = [cross_validate(kH, p, w) for kH, p, w in _half_space_sets(50, 8)]
    found.append(
        cross_validate(
            0.5,
            dict(gamma=23.65, f=0.82, beta=0.3, eta=math.inf),  # the |Re z| <= 100 example of the reading notes
            dict(re_max=10.0, im_min=1e-2, im_max=1.5),
        )
    )
    assert sum(n for n, _ in found) >= 10  # 11 at this seed


# ------------------------------------------------------------------------------------------------
# the paper's check values and the Rayleigh branch
# ------------------------------------------------------------------------------------------------


def _has(z: np.ndarray, ref: complex, rtol: float) -> bool:
    return z.size > 0 and float(np.min(np.abs(z - ref))) <= rtol * abs(ref)


def test_check_value_backward_root_eta_3():
    """docs/physics.md §7: eta = 3, gamma = 3, kH = 0.45: -1.86154054015624 + 0.04806456251133 i (15 digits)."""
    res = eigenmodes(0.45, eta=3.0, **PAPER)
    assert res.complete
    assert _has(res.z, -1.86154054015624 + 0.04806456251133j, 1e-12)


def test_check_value_ten_roots_eta_10():
    """docs/physics.md §7: eta = 10, gamma = 3, kH = 0.77: 10 roots with Im z >= 1e-4, |Re z| <= 5, among them
    the Rayleigh branch 0.8847 + 0.01045 i and the faster 2.3954 + 0.03804 i (4 digits quoted)."""
    res = eigenmodes(0.77, eta=10.0, **PAPER, re_max=5.0, im_min=1e-4, im_max=2.0)
    assert res.complete and res.z.size == 10
    assert _has(res.z, 0.8847 + 0.01045j, 1e-4) and _has(res.z, 2.3954 + 0.03804j, 1e-4)
    assert abs(res.z[0] - (2.3954 + 0.03804j)) < 1e-4  # the fastest first
    cross_validate(0.77, dict(eta=10.0, **PAPER), dict(re_max=5.0, im_min=1e-4, im_max=2.0))


@pytest.mark.slow
@pytest.mark.parametrize(
    "kH, z_ref, rtol",
    [
        (1.0, 0.88336356305352538 + 0.00815518661032729j, 1e-10),  # the Rayleigh branch (17 digits quoted)
        (0.45, 3.53354704617255 + 0.07585981635187j, 1e-9),  # faster than c_d (15 digits)
    ],
)
def test_check_values_half_space(kH, z_ref, rtol):
    res = eigenmodes(kH, eta=math.inf, **PAPER, im_min=1e-3)
    assert res.complete
    assert _has(res.z, z_ref, rtol)


@pytest.mark.parametrize("eta, kH", [(10.0, 0.3), (10.0, 0.77), (10.0, 2.0), (3.0, 5.0), (30.0, 1.0)])
def test_rayleigh_branch_is_an_eigenvalue(eta, kH):
    """The Rayleigh branch (model.rayleigh_branch, continued from kH = 1e4), growing or damped, is an eigenvalue."""
    z_r = complex(model.rayleigh_branch(kH, eta=eta, **PAPER).z)
    res = eigenmodes(kH, eta=eta, **PAPER, re_max=1.2, im_min=-0.1, im_max=0.1)
    assert res.complete
    assert _has(res.z, z_r, RTOL), (z_r, res.z)


@pytest.mark.slow
@pytest.mark.parametrize("kH", [0.5, 1.0])
def test_rayleigh_branch_is_an_eigenvalue_half_space(kH):
    z_r = complex(model.rayleigh_branch(kH, eta=math.inf, **PAPER).z)
    assert z_r.imag > 1e-3
    res = eigenmodes(kH, eta=math.inf, **PAPER, re_max=1.2, im_min=1e-3, im_max=0.1)
    assert res.complete and res.z.size == 1
    assert _has(res.z, z_r, RTOL), (z_r, res.z)


@pytest.mark.parametrize("kH", [0.05, 0.5, 3.0])
def test_symmetric_blocks_have_no_growing_mode(kH):
    """eta = 1: G_y = 0 and no root grows (docs/physics.md §3), and no eigenvalue either."""
    res = eigenmodes(kH, eta=1.0, **PAPER, im_min=1e-4)
    assert res.complete and res.z.size == 0
    assert model.unstable_count(kH, eta=1.0, **PAPER) == 0


# ------------------------------------------------------------------------------------------------
# properties of the result
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("eta", [3.0, 10.0])
def test_mirror_symmetry(eta):
    """F(-conj z; -f) = conj F(z; f): the eigenvalues for -f are -conj of those for f, in a symmetric window."""
    window = dict(re_max=5.0, im_min=-0.5, im_max=1.0)
    plus = eigenmodes(0.6, gamma=3.0, f=0.9, beta=0.3, eta=eta, **window)
    minus = eigenmodes(0.6, gamma=3.0, f=-0.9, beta=0.3, eta=eta, **window)
    assert plus.complete and minus.complete and plus.z.size == minus.z.size > 5
    assert np.all(_nearest_rel(plus.z, -np.conj(minus.z)) <= 1e-10)


def test_result_is_sorted_and_within_its_tolerance():
    res = eigenmodes(0.77, eta=10.0, **PAPER, im_min=-0.2)
    assert np.all(np.diff(res.z.imag) <= 0)
    assert np.all(res.error <= res.tol * np.abs(res.z))
    assert res.n[0] > res.n_coarse[0] and res.n[1] > res.n_coarse[1]
    assert res.window == (5.0, -0.2, 2.0) and res.z_all.size > res.z.size


def test_too_coarse_a_resolution_drops_but_never_returns_a_wrong_eigenvalue():
    """At a fixed, far too coarse n the unresolved eigenvalues in the window are dropped and counted; what is
    returned is still a root of F (the two resolutions agreed on it)."""
    window = dict(re_max=5.0, im_min=1e-3, im_max=2.0)
    roots = model.unstable_modes(1.28, gamma=2.23, f=-0.99, beta=0.48, eta=8.95, Delta=0.24, **window)
    res = eigenmodes(1.28, gamma=2.23, f=-0.99, beta=0.48, eta=8.95, Delta=0.24, n=(10, 20), **window)
    assert roots.size > 10
    assert res.dropped > 0 and not res.complete
    assert res.z.size < roots.size
    assert np.all(_nearest_rel(res.z, roots) <= 1e-6)
    assert np.all(_nearest_rel(res.z, roots) <= 10 * res.error / np.abs(res.z) + 1e-12)


def test_resolution_grows_with_the_window_and_the_height():
    small = model.eigenmode_resolution(0.5, beta=0.3, eta=3.0, re_max=2.0)
    wide = model.eigenmode_resolution(0.5, beta=0.3, eta=3.0, re_max=8.0)
    tall = model.eigenmode_resolution(0.5, beta=0.3, eta=30.0, re_max=2.0)
    assert wide[0] > small[0] and wide[1] > small[1]
    assert tall[0] == small[0] and tall[1] > small[1]


# ------------------------------------------------------------------------------------------------
# mode shapes
# ------------------------------------------------------------------------------------------------


def _derivative(y: np.ndarray, u: np.ndarray) -> np.ndarray:
    """du/dy at the nodes by the test's own means: the interpolating Chebyshev polynomial, differentiated."""
    a, b = y[0], y[-1]
    x = (2 * y - (a + b)) / (b - a)
    series = C.Chebyshev.fit(x, u, deg=y.size - 1, domain=[-1, 1])
    return series.deriv()(x) * 2 / (b - a)


MODES = [  # (kH, parameters, a root of the contour solver's window)
    (0.45, dict(eta=3.0, **PAPER), dict(re_max=5.0, im_min=1e-2, im_max=2.0)),
    (0.77, dict(eta=10.0, **PAPER), dict(re_max=5.0, im_min=1e-2, im_max=2.0)),
    (
        1.28,
        dict(gamma=2.23, f=-0.99, beta=0.48, eta=8.95, Delta=0.24, xi=0.0),
        dict(re_max=2.0, im_min=1e-2, im_max=2.0),
    ),
    (
        0.66,
        dict(gamma=2.45, f=-0.94, beta=0.43, eta=4.59, Delta=0.6, xi=4.78),
        dict(re_max=5.0, im_min=1e-2, im_max=2.0),
    ),
]


@pytest.mark.parametrize("kH, p, window", MODES)
def test_mode_shape_satisfies_its_equations(kH, p, window):
    """Every root of the window: boundary rows, continuity, the friction and state laws, the stresses and the
    Navier equations, each recomputed here from the returned displacements."""
    p = dict(dict(Delta=1.0, xi=0.0), **p)
    roots = model.unstable_modes(kH, **p, **window)
    assert roots.size >= 1
    for z in roots:
        m = mode_shape(kH, z, **p)
        assert m.mismatch <= RTOL
        q, w = kH, kH * m.z
        lam2 = 1 / p["beta"] ** 2
        # normalisation and phase
        u_max = max(
            np.max(np.abs(m.u_x_upper)),
            np.max(np.abs(m.u_y_upper)),
            np.max(np.abs(m.u_x_lower)),
            np.max(np.abs(m.u_y_lower)),
        )
        assert u_max == pytest.approx(1.0, rel=1e-12)
        assert m.slip.real > 0 and abs(m.slip.imag) <= 1e-12 * abs(m.slip)
        tiny = 1e-9 * max(1.0, np.max(np.abs(m.sigma_xy_upper)), np.max(np.abs(m.sigma_yy_upper)))
        # far boundaries (Eq. S-SBC): u_x = 0 and sigma_yy = 0 at y = 1 and y = -eta
        assert m.y_upper[-1] == 1.0 and m.y_lower[0] == pytest.approx(-p["eta"])
        for u, s in ((m.u_x_upper[-1], m.sigma_yy_upper[-1]), (m.u_x_lower[0], m.sigma_yy_lower[0])):
            assert abs(u) <= 1e-12 and abs(s) <= tiny
        # the interface: continuous u_y and tractions; the slip is the jump of u_x (Eq. epsilon)
        assert abs(m.u_y_upper[0] - m.u_y_lower[-1]) <= 1e-12
        assert abs(m.sigma_xy_upper[0] - m.sigma_xy_lower[-1]) <= tiny
        assert abs(m.sigma_yy_upper[0] - m.sigma_yy_lower[-1]) <= tiny
        assert m.slip == pytest.approx(m.u_x_upper[0] - m.u_x_lower[-1], rel=1e-12)
        # the friction law and the state equation (Eq. S-fric_law, Eq. S-delta f RSF_SM)
        friction = p["gamma"] * (m.shear_stress + p["f"] * m.normal_stress) + 1j * w * m.slip
        assert abs(friction - (1 - p["Delta"]) * m.state) <= 1e-9 * abs(w * m.slip)
        assert abs(m.state * (1 - 1j * p["xi"] * w) - 1j * w * m.slip) <= 1e-9 * abs(w * m.slip)
        for y, ux, uy, sxy, syy in (
            (m.y_upper, m.u_x_upper, m.u_y_upper, m.sigma_xy_upper, m.sigma_yy_upper),
            (m.y_lower, m.u_x_lower, m.u_y_lower, m.sigma_xy_lower, m.sigma_yy_lower),
        ):
            dux, duy = _derivative(y, ux), _derivative(y, uy)
            scale = np.max(np.abs(sxy)) + np.max(np.abs(syy)) + q
            assert np.max(np.abs(sxy - (dux + 1j * q * uy))) <= 1e-7 * scale
            assert np.max(np.abs(syy - (1j * q * (lam2 - 2) * ux + lam2 * duy))) <= 1e-7 * scale
            # Navier (Eq. S-LE) at the interior nodes: d_y sigma_xy + i q sigma_xx = -omega^2 u_x, and for u_y
            sxx = 1j * q * lam2 * ux + (lam2 - 2) * duy
            inner = slice(1, -1)
            res_x = (_derivative(y, sxy) + 1j * q * sxx + w * w * ux)[inner]
            res_y = (1j * q * sxy + _derivative(y, syy) + w * w * uy)[inner]
            big = np.max(np.abs(_derivative(y, sxy))) + np.max(np.abs(_derivative(y, syy))) + abs(w) ** 2
            assert np.max(np.abs(res_x)) <= 1e-5 * big and np.max(np.abs(res_y)) <= 1e-5 * big


@pytest.mark.parametrize("kH, p, window", MODES[:2])
def test_mode_shape_interface_gives_the_closed_form_response(kH, p, window):
    """sigma_xy = mu k G_x eps_x and sigma_yy = i mu k G_y eps_x (Eq. G) with the closed-form G_x, G_y of
    Eq. S-G_gen (model.response_functions, the other solver's): the eigenvector's interface is the composite's."""
    for z in model.unstable_modes(kH, **p, **window):
        m = mode_shape(kH, z, **p)
        gx, gy = model.response_functions(m.z, kH, beta=p["beta"], eta=p["eta"])
        assert m.shear_stress / (kH * m.slip) == pytest.approx(complex(gx), rel=1e-7, abs=1e-9)
        assert m.normal_stress / (1j * kH * m.slip) == pytest.approx(complex(gy), rel=1e-7, abs=1e-9)


@pytest.mark.slow
def test_mode_shape_half_space():
    """eta = inf: the upper block and the interface are physical (Eq. G with the eta = inf response functions);
    in the depth the lower block's field on the path y~ = (1 + i s) y decays as the slower of the two waves of
    Eq. S-full_sol, |exp(kH alpha_j y~)|, alpha_j computed here from z."""
    z_ref = 3.53354704617255 + 0.07585981635187j
    m = mode_shape(0.45, z_ref, eta=math.inf, **PAPER)
    assert m.mismatch <= 1e-8 and m.stretch > 0
    gx, gy = model.response_functions(m.z, 0.45, beta=0.3, eta=math.inf)
    assert m.shear_stress / (0.45 * m.slip) == pytest.approx(complex(gx), rel=1e-7)
    assert m.normal_stress / (1j * 0.45 * m.slip) == pytest.approx(complex(gy), rel=1e-7)
    path = 1 + 1j * m.stretch
    rate = 0.45 * min((np.sqrt(1 - m.z**2) * path).real, (np.sqrt(1 - (0.3 * m.z) ** 2) * path).real)
    deep = (m.y_lower > -100) & (m.y_lower < -10)
    ratio = (np.abs(m.u_x_lower) + np.abs(m.u_y_lower))[deep] / np.exp(rate * m.y_lower[deep])
    assert deep.sum() >= 10
    assert np.ptp(ratio) <= 0.01 * np.mean(ratio)


# ------------------------------------------------------------------------------------------------
# bad input and independence
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name, value",
    [
        ("kH", 0.0),
        ("kH", -1.0),
        ("kH", np.array([0.5, 1.0])),
        ("kH", "1"),
        ("gamma", 0.0),
        ("gamma", math.inf),
        ("f", math.nan),
        ("beta", 0.8),
        ("beta", 0.0),
        ("eta", 0.0),
        ("eta", -2.0),
        ("Delta", 0.0),
        ("Delta", 1.5),
        ("xi", -1.0),
        ("tol", 0.0),
        ("tol", 0.5),
        ("n", 3),
        ("n", (10, 2.5)),
        ("n", "ten"),
        ("re_max", 0.0),
        ("im_max", -1.0),
        ("im_min", math.nan),
    ],
)
def test_bad_input_names_the_parameter(name, value):
    args = dict(kH=0.5, gamma=3.0, f=0.9, beta=0.3, eta=3.0)
    args[name] = value
    kH = args.pop("kH")
    with pytest.raises(ValueError, match=name):
        eigenmodes(kH, **args)


def test_half_space_needs_a_window_above_the_axis():
    with pytest.raises(ValueError, match="im_min"):
        eigenmodes(0.5, eta=math.inf, **PAPER, im_min=0.0)


@pytest.mark.parametrize("name, value", [("z", math.nan), ("z", "1+1j"), ("beta", 1.0), ("n", 2)])
def test_mode_shape_bad_input_names_the_parameter(name, value):
    args = dict(z=0.9 + 0.01j, gamma=3.0, f=0.9, beta=0.3, eta=3.0)
    args[name] = value
    z = args.pop("z")
    with pytest.raises(ValueError, match=name):
        mode_shape(0.5, z, **args)


def test_the_module_imports_no_closed_form():
    """The eigen-solver imports numpy, scipy and model._validate only: nothing of the response functions, the
    dispersion function, the kernels or the other solvers (the independence of the second solver)."""
    tree = ast.parse(Path(em.__file__).read_text())
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            imported |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            imported.add(("." * node.level) + (node.module or ""))
    assert imported <= {"__future__", "math", "dataclasses", "numpy", "scipy.linalg", "scipy", "._validate"}, imported
