"""Tests of the mpmath oracle (tests/oracle.py) against the check values of docs/physics.md
(sections 3, 4, 6, 7) and against internal consistency (independent formulas, symmetries, precision).

Tolerances follow the number of digits quoted in docs/physics.md §7. Equation labels refer to
paper/aldam2016_geometric_asymmetry.tex.
"""

from __future__ import annotations

import math

import oracle as o
import pytest
from mpmath import mp

INF = math.inf
F0, BETA0 = 0.9, 0.3  # f and beta of docs/physics.md §7


@pytest.fixture(autouse=True)
def _test_arithmetic_at_50_digits():
    """Arithmetic inside the tests runs at 50 digits (the oracle sets its own precision internally)."""
    with mp.workdps(50):
        yield


def close(a, b, tol: float) -> bool:
    """|a - b| <= tol (absolute), evaluated at high precision."""
    with mp.workdps(50):
        return abs(mp.mpmathify(a) - mp.mpmathify(b)) <= tol


def rel_close(a, b, tol: float) -> bool:
    with mp.workdps(50):
        a, b = mp.mpmathify(a), mp.mpmathify(b)
        return abs(a - b) <= tol * abs(b)


# =============================================================================================
# Rayleigh speed (docs/physics.md §5, §7)
# =============================================================================================


def test_rayleigh_speed_check_values() -> None:
    assert close(o.rayleigh_speed(0.3), "0.9490317274618273", 1e-16)
    with mp.workdps(40):
        beta_nu025 = mp.sqrt(mp.mpf(1) / 3)  # nu = 0.25
        beta_nu0 = mp.sqrt(mp.mpf(1) / 2)  # nu = 0
        exact025 = mp.sqrt(2 - 2 / mp.sqrt(3))
        exact0 = mp.sqrt(3 - mp.sqrt(5))
    assert close(o.rayleigh_speed(beta_nu025), "0.9194016867619661", 1e-16)
    assert close(o.rayleigh_speed(beta_nu025), exact025, 1e-29)
    assert close(o.rayleigh_speed(beta_nu0), "0.8740320488976421", 1e-16)
    assert close(o.rayleigh_speed(beta_nu0), exact0, 1e-29)


def test_rayleigh_speed_solves_rayleigh_equation() -> None:
    for beta in (1e-3, 0.3, 0.5, 0.7071):
        z = o.rayleigh_speed(beta)
        with mp.workdps(50):
            b = mp.mpf(beta) ** 2
            a_s, a_d = mp.sqrt(1 - z**2), mp.sqrt(1 - b * z**2)
            assert abs((1 + a_s**2) ** 2 - 4 * a_s * a_d) < 1e-28
            assert 0 < z < 1


def test_pmma_plane_stress_rayleigh_speed() -> None:
    """docs/physics.md §6: plane stress nu = 0.33 -> nu/(1+nu); z_R = 0.91909, c_R ~ 1237 m/s with c_s = 1345."""
    with mp.workdps(40):
        nu1 = mp.mpf("0.33") / mp.mpf("1.33")
        beta = mp.sqrt((1 - 2 * nu1) / (2 - 2 * nu1))
    z_r = o.rayleigh_speed(beta)
    assert close(z_r, "0.91909", 5e-6)
    assert abs(z_r * 1345 - 1237) < 1.5


# =============================================================================================
# Response functions (Eq. Gs_general = S-G_gen)
# =============================================================================================


@pytest.mark.parametrize("z", [0.5, 0.9 + 0.01j, 1.3 + 0.2j, -0.7 + 0.05j, 2.4 + 0.03j, 1e-3 + 1e-4j])
@pytest.mark.parametrize("q", [1e-3, 0.45, 3.0])
def test_gy_vanishes_exactly_for_eta_one(z, q) -> None:
    assert o.response_functions(z, q, BETA0, 1)[1] == 0


@pytest.mark.parametrize("eta", [0.01, 0.5, 3, 10, 1e3, INF])
@pytest.mark.parametrize("z", [0.3, 0.88 + 0.008j, 1.2 + 0.1j, -1.86 + 0.048j, 3.5 + 0.07j])
@pytest.mark.parametrize("q", [0.01, 0.77, 5.0])
def test_exponential_form_matches_literal_tanh_form(eta, z, q) -> None:
    """The oracle's exp/expm1 rewriting agrees with Eq. S-G_gen evaluated literally with tanh."""
    g = o.response_functions(z, q, BETA0, eta)
    h = o.response_functions_tanh(z, q, BETA0, eta)
    for a, b in zip(g, h, strict=True):
        assert close(a, b, 1e-27 * max(1, abs(b)))


@pytest.mark.parametrize("z", [0.5, 0.949, 0.9 + 0.02j, 1.5 + 0.1j])
@pytest.mark.parametrize("q", [1e-4, 0.8, 20.0])
def test_eta_inf_matches_main_text_forms(z, q) -> None:
    """Eqs. Gx_LSA, Gy_LSA (T2 -> +1, the misprint of Sect. S-III A corrected)."""
    g_x, g_y = o.response_functions(z, q, BETA0, INF)
    with mp.workdps(60):
        zz, b = mp.mpmathify(z), mp.mpf(BETA0) ** 2
        a_s, a_d = mp.sqrt(1 - zz**2), mp.sqrt(1 - b * zz**2)
        gx = ((a_s**2 + 1) ** 2 / a_s / (1 + mp.tanh(q * a_s)) - 4 * a_d / (1 + mp.tanh(q * a_d))) / zz**2
        gy = 2 * (a_s**2 + 1) * (1 / (1 + mp.tanh(q * a_d)) - 1 / (1 + mp.tanh(q * a_s))) / zz**2
    assert close(g_x, gx, 1e-27 * max(1, abs(gx)))
    assert close(g_y, gy, 1e-27 * max(1, abs(gy)))


def test_large_eta_equals_half_space() -> None:
    """eta = 1e8: tanh(eta q alpha) = 1 to far beyond 30 digits for q >= 1e-4 and |z| < 1."""
    for q in (1e-4, 1.0, 1e4):
        a = o.response_functions(0.9 + 0.01j, q, BETA0, 1e8)
        b = o.response_functions(0.9 + 0.01j, q, BETA0, INF)
        for x, y in zip(a, b, strict=True):
            assert close(x, y, 1e-28 * max(1, abs(y)))


@pytest.mark.parametrize("eta", [3, INF])
@pytest.mark.parametrize("q", [1e-4, 1.0, 30.0])
def test_small_z_no_cancellation(eta, q) -> None:
    """At |z| = 1e-6 the formula cancels catastrophically; the adaptive result must still agree with the
    literal tanh form evaluated at much higher precision, and approach the finite z -> 0 limit as z^2."""
    z = 1e-6
    g = o.response_functions(z, q, BETA0, eta)
    h = o.response_functions_tanh(z, q, BETA0, eta)
    for a, b in zip(g, h, strict=True):
        assert rel_close(a, b, 1e-26)
    g2 = o.response_functions(z / 10, q, BETA0, eta)
    g3 = o.response_functions(z / 100, q, BETA0, eta)
    for i in range(2):  # Richardson: differences shrink by 100 per decade of z
        d1, d2 = g[i] - g2[i], g2[i] - g3[i]
        assert abs(d2) <= abs(d1) / 50 + 1e-28 * abs(g3[i])


def test_gy_near_eta_one_is_linear_in_eta_minus_one() -> None:
    """eta = 1 + 1e-9: G_y ~ (eta - 1) dG_y/deta, computed without the T2 - T1 cancellation."""
    with mp.workdps(40):
        eta1, eta2 = 1 + mp.mpf("1e-9"), 1 + mp.mpf("2e-9")
    a = o.response_functions(0.9 + 0.01j, 0.7, BETA0, eta1)[1]
    b = o.response_functions(0.9 + 0.01j, 0.7, BETA0, eta2)[1]
    assert a != 0
    assert rel_close(b, 2 * a, 1e-8)
    with mp.workdps(60):
        deriv = mp.diff(
            lambda e: o.response_functions_core(mp.mpc(0.9, 0.01), mp.mpf(0.7), mp.mpf(0.09), e)[1], 1
        )
    assert rel_close(a, deriv * mp.mpf("1e-9"), 1e-8)


def test_dispersion_mirror_symmetry() -> None:
    """z -> -conj(z) maps solutions for f to those for -f (docs/physics.md §3): F(-conj z; -f) = conj F(z; f)."""
    z = 0.88 + 0.01j
    for eta in (3, INF):
        a = o.dispersion(z, 0.6, 3, F0, BETA0, eta, 0.5, 1.0)
        b = o.dispersion(-z.conjugate(), 0.6, 3, -F0, BETA0, eta, 0.5, 1.0)
        assert close(b, mp.conj(a), 1e-28)


def test_dispersion_dz_against_cauchy_integral() -> None:
    """dF/dz = (1/2 pi i) \\oint F(w)/(w - z)^2 dw on a small circle (independent of mp.diff)."""
    z, r = mp.mpc(0.88, 0.01), mp.mpf("1e-3")
    p = o.Params.make(3, F0, BETA0, 10, 0.5, 2.0)
    with mp.workdps(40):
        integral = mp.quad(
            lambda t: o.dispersion_core(z + r * mp.expj(t), mp.mpf(0.77), p) * mp.expj(-t), [0, 2 * mp.pi]
        )
        ref = integral / (2 * mp.pi * r)
    assert close(o.dispersion_dz(z, 0.77, 3, F0, BETA0, 10, 0.5, 2.0), ref, 1e-25 * abs(ref))


# =============================================================================================
# Rayleigh branch (docs/physics.md §3, §7)
# =============================================================================================


@pytest.mark.slow
def test_rayleigh_branch_check_value_q1() -> None:
    z = o.rayleigh_branch([1.0], 3, F0, BETA0, INF)[0]
    assert close(mp.re(z), "0.88336356305352538", 2e-17)
    assert close(mp.im(z), "0.00815518661032729", 2e-17)
    assert abs(o.dispersion(z, 1.0, 3, F0, BETA0, INF)) < 1e-27


@pytest.mark.slow
def test_rayleigh_branch_independent_of_requested_q() -> None:
    o._path.cache_clear()
    alone = o.rayleigh_branch(0.77, 3, F0, BETA0, INF)[0]
    o._path.cache_clear()
    many = o.rayleigh_branch([30.0, 0.05, 0.77, 0.1, 2.0], 3, F0, BETA0, INF)
    again = o.rayleigh_branch([2.0, 0.77], 3, F0, BETA0, INF)
    assert close(alone, many[2], 1e-27)
    assert close(again[1], many[2], 1e-27)
    assert close(again[0], many[4], 1e-27)


@pytest.mark.slow
def test_full_continuation_roots() -> None:
    """1e4 -> 1e-4 at eta = inf: every returned z solves F = 0 (run time is not asserted: benchmarks only)."""
    o._path.cache_clear()
    qs = [10 ** (k / 2) for k in range(-8, 9)]
    zs = o.rayleigh_branch(qs, 3, F0, BETA0, INF)
    for q, z in zip(qs, zs, strict=True):
        assert abs(o.dispersion(z, q, 3, F0, BETA0, INF)) < 1e-26
    # large q: the root of the q -> inf limit, close to z_R; small q (eta = inf): back near z_R
    assert abs(zs[-1] - o.rayleigh_speed(BETA0)) < 0.03
    assert abs(zs[0] - o.rayleigh_speed(BETA0)) < 0.02
    stats = o.rayleigh_branch_stats(3, F0, BETA0, INF)
    assert stats["lost_down"] is None and stats["start_note"] == ""


@pytest.mark.slow
@pytest.mark.parametrize("eta", [1, 3, 10, 1e8])
def test_finite_eta_full_continuation(eta) -> None:
    """Finite eta: the branch can be followed from 1e4 down to 1e-4 (Re z -> 0 like q for eta < inf)."""
    qs = [1e-4, 1e-2, 0.45, 1.0, 100.0]
    zs = o.rayleigh_branch(qs, 3, F0, BETA0, eta)
    for q, z in zip(qs, zs, strict=True):
        assert abs(o.dispersion(z, q, 3, F0, BETA0, eta)) < 1e-25
    if eta == 1:
        assert all(mp.im(z) < 0 for z in zs)  # symmetric system: stable for all k (Fig. 5a)
    if eta == 1e8:  # indistinguishable from the half-space
        z_inf = o.rayleigh_branch(qs, 3, F0, BETA0, INF)
        assert all(close(a, b, 1e-25) for a, b in zip(zs, z_inf, strict=True))
    else:
        assert abs(zs[0]) < 2e-3  # |z| = O(q) at small q


@pytest.mark.slow
def test_eta10_rayleigh_branch_and_faster_mode() -> None:
    """docs/physics.md §3: eta = 10, q = 0.77: Rayleigh branch 0.8847 + 0.01045 i; another root 2.3954 + 0.03804 i
    grows faster."""
    z = o.rayleigh_branch(0.77, 3, F0, BETA0, 10)[0]
    assert close(mp.re(z), "0.8847", 5e-5)
    assert close(mp.im(z), "0.01045", 5e-6)
    p = o.Params.make(3, F0, BETA0, 10)
    with mp.workdps(40):
        other = mp.findroot(
            lambda w: o.dispersion_core(w, mp.mpf(0.77), p),
            (mp.mpc(2.3954, 0.03804), mp.mpc(2.3955, 0.038)),
            solver="secant",
        )
    assert close(mp.re(other), "2.3954", 5e-5)
    assert close(mp.im(other), "0.03804", 5e-6)
    assert mp.im(other) > mp.im(z)  # the Rayleigh branch is not the dominant instability here


@pytest.mark.parametrize(
    ("z_ref", "q", "eta"),
    [
        (("-1.86154054015624", "0.04806456251133"), 0.45, 3),
        (("3.53354704617255", "0.07585981635187"), 0.45, INF),
    ],
)
def test_other_branch_reference_roots(z_ref, q, eta) -> None:
    """docs/physics.md §3: the quoted other-branch roots (14 digits) are roots of F."""
    with mp.workdps(40):
        z_ref = mp.mpc(*z_ref)
    f_val = o.dispersion(z_ref, q, 3, F0, BETA0, eta)
    f_dz = o.dispersion_dz(z_ref, q, 3, F0, BETA0, eta)
    assert abs(f_val / f_dz) < 1e-14  # Newton distance to the root
    p = o.Params.make(3, F0, BETA0, eta)
    with mp.workdps(40):
        root = mp.findroot(
            lambda w: o.dispersion_core(w, mp.mpf(q), p),
            (z_ref, z_ref * (1 + mp.mpf("1e-9"))),
            solver="secant",
        )
    assert close(root, z_ref, 1e-14)


def _count_roots_in_rectangle(fun, x0, x1, y0, y1, n=200) -> mp.mpf:
    """Argument principle on the rectangle boundary (phase steps refined below pi/8)."""

    def arc(a, fa, b, fb, depth):
        dphi = mp.arg(fb / fa)
        if abs(dphi) < mp.pi / 8 or depth > 40:
            return dphi
        m = (a + b) / 2
        fm = fun(m)
        return arc(a, fa, m, fm, depth + 1) + arc(m, fm, b, fb, depth + 1)

    corners = [mp.mpc(x0, y0), mp.mpc(x1, y0), mp.mpc(x1, y1), mp.mpc(x0, y1), mp.mpc(x0, y0)]
    total = mp.mpf(0)
    for k in range(4):
        a, b = corners[k], corners[k + 1]
        pts = [a + (b - a) * j / n for j in range(n + 1)]
        vals = [fun(w) for w in pts]
        total += mp.fsum(arc(pts[j], vals[j], pts[j + 1], vals[j + 1], 0) for j in range(n))
    return total / (2 * mp.pi)


def test_eta10_ten_unstable_roots_in_window() -> None:
    """docs/physics.md §3: eta = 10, q = 0.77: ten roots with Im z >= 1e-4 and |Re z| <= 5 (window Im z <= 3)."""
    p = o.Params.make(3, F0, BETA0, 10)
    with mp.workdps(20):
        count = _count_roots_in_rectangle(lambda w: o.dispersion_core(w, mp.mpf(0.77), p), -5, 5, 1e-4, 3)
    assert abs(count - 10) < 1e-6


@pytest.mark.slow
def test_max_growth_eta_inf() -> None:
    """docs/physics.md §7: max_q Im z = 0.0106758 at q ~ 0.767 (eta = inf, gamma = 3, Delta = 1)."""
    q_star, im_max = o.rayleigh_branch_max_growth(0.77, 3, F0, BETA0, INF)
    assert close(im_max, "0.0106758", 5e-8)
    assert abs(q_star - mp.mpf("0.767")) < 1e-3


@pytest.mark.slow
def test_max_growth_state_dependent_friction() -> None:
    """docs/physics.md §7: Delta = 0.5, xi = 1, eta = inf, gamma = 3: max_q Im z = 0.028570."""
    _, im_max = o.rayleigh_branch_max_growth(0.75, 3, F0, BETA0, INF, 0.5, 1)
    assert close(im_max, "0.028570", 5e-7)


@pytest.mark.slow
def test_critical_gamma() -> None:
    """docs/physics.md §7: critical gamma = 2.4149 (eta = inf, Delta = 1): max_q Im z(gamma) = 0."""
    state = {"q": mp.mpf("0.72")}

    def growth(g):
        state["q"], im = o.rayleigh_branch_max_growth(state["q"], g, F0, BETA0, INF)
        return im

    with mp.workdps(20):
        g_c = mp.findroot(growth, (mp.mpf("2.40"), mp.mpf("2.43")), solver="secant", tol=1e-24)
    assert close(g_c, "2.4149", 5e-5)
    assert 2 < g_c < 3  # paper: "between 2 and 3"


@pytest.mark.slow
def test_critical_eta() -> None:
    """docs/physics.md §7: critical eta = 3.2982 at gamma = 3, Delta = 1, onset at q ~ 0.976 (paper: ~3.3)."""
    state = {"q": mp.mpf("0.976")}

    def growth(e):
        state["q"], im = o.rayleigh_branch_max_growth(state["q"], 3, F0, BETA0, e)
        return im

    with mp.workdps(20):
        e_c = mp.findroot(growth, (mp.mpf("3.29"), mp.mpf("3.31")), solver="secant", tol=1e-24)
    assert close(e_c, "3.2982", 5e-5)
    assert abs(state["q"] - mp.mpf("0.976")) < 1e-3


@pytest.mark.slow
def test_small_gamma_branch_runs_into_the_cut() -> None:
    """Edge case: for small gamma the q = 1e4 root sits just past the branch point z = 1 (findroot from z_R
    lands on a far root on the imaginary axis; the gamma homotopy finds the nearer one), and continuing
    down in q it reaches the cut z > 1 of eta = inf: the oracle must report BranchLost, not another root."""
    z_top = o.rayleigh_branch(1e4, 0.3, F0, BETA0, INF)[0]
    assert mp.re(z_top) > 1 and mp.im(z_top) < 0
    with pytest.raises(o.BranchLost):
        o.rayleigh_branch(1.0, 0.3, F0, BETA0, INF)
    assert o.rayleigh_branch([1.0, 20.0], 0.3, F0, BETA0, INF, strict=False)[0] is None


# =============================================================================================
# Linear expansion and criterion (docs/physics.md §4, Eqs. S-dz, S-fffff, criterion)
# =============================================================================================


@pytest.mark.parametrize("q", [0.3, 0.86, 2.0])
def test_linear_expansion_matches_explicit_real_imag_parts(q) -> None:
    """Eq. S-dz against its real/imaginary parts written out in Eq. S-fffff (G's real at z_R < 1).

    Misprint found here: in Im[delta z] of Eq. S-fffff the term (G_x/G_x')(1 + gamma f G_y') must carry a
    MINUS sign (Im of -(A - iB)/(C - iE) is -(A E - B C)/(C^2 + E^2)); with the printed "+" the test fails.
    """
    gamma = 3
    z = o.linear_expansion(q, gamma, F0, BETA0)
    z_r = o.rayleigh_speed(BETA0)
    with mp.workdps(50):
        f = mp.mpf(F0)  # keep gamma * f out of float arithmetic
        g = o.response_functions(z_r, q, BETA0, INF)
        gx, gy = mp.re(g[0]), mp.re(g[1])
        dgx = mp.re(
            mp.diff(lambda w: o.response_functions_core(w, mp.mpf(q), mp.mpf(BETA0) ** 2, mp.inf)[0], z_r)
        )
        dgy = mp.re(
            mp.diff(lambda w: o.response_functions_core(w, mp.mpf(q), mp.mpf(BETA0) ** 2, mp.inf)[1], z_r)
        )
        den = (gamma * f * dgy + 1) ** 2 + gamma**2 * dgx**2
        re_dz = -((gamma * f * dgy + 1) * (gamma * f * gy + z_r) + gamma**2 * gx * dgx) / den
        im_dz = -gamma * dgx * ((z_r + gamma * f * gy) - gx / dgx * (1 + gamma * f * dgy)) / den
    assert close(mp.re(z) - z_r, re_dz, 1e-25)
    assert close(mp.im(z), im_dz, 1e-25)


def test_criterion_min_gy() -> None:
    """docs/physics.md §7: min_q G_y(z_R, q) = -0.475111 at q = 0.86438, chi_c = z_R / |min| = 1.99750."""
    q_min, gy_min = o.criterion_min_gy(BETA0, INF)
    assert close(gy_min, "-0.475111", 5e-7)
    assert close(q_min, "0.86438", 5e-6)
    assert close(o.rayleigh_speed(BETA0) / abs(gy_min), "1.99750", 5e-6)


# =============================================================================================
# Thin-on-thick (docs/physics.md §6)
# =============================================================================================


def test_B_check_values() -> None:
    assert close(o.B(2), "0.79100634", 5e-9)
    assert close(o.B(10), "0.99782980", 5e-9)


@pytest.mark.parametrize("q", [0.01, 0.5, 2.0, 4.0, 10.0])
def test_B_against_struve_closed_form(q) -> None:
    """Int_0^x K0 = (pi x / 2) [K0(x) L_{-1}(x) + K1(x) L_0(x)] (modified Struve L), x = q/2."""
    with mp.workdps(60):
        x = mp.mpf(q) / 2
        ref = x * (mp.besselk(0, x) * mp.struvel(-1, x) + mp.besselk(1, x) * mp.struvel(0, x))
    assert close(o.B(q), ref, 1e-28)
    assert close(o.B(q) + o.one_minus_B(q), 1, 1e-29)


def test_one_minus_B_keeps_relative_precision() -> None:
    """Large q: Int_x^inf K0 ~ sqrt(pi/(2x)) e^{-x} (1 - 5/(8x) + 129/(128 x^2) - 2655/(1024 x^3) + ...),
    x = q/2 (next coefficient ~ +9.19)."""
    for q in (100.0, 200.0, 1000.0):
        val = o.one_minus_B(q)
        with mp.workdps(40):
            x = mp.mpf(q) / 2
            series = 1 - mp.mpf(5) / (8 * x) + mp.mpf(129) / (128 * x**2) - mp.mpf(2655) / (1024 * x**3)
            asym = 2 / mp.pi * mp.sqrt(mp.pi / (2 * x)) * mp.exp(-x) * series
        assert rel_close(val, asym, 10 / float(x) ** 4)
    for q in (2.0, 10.0):
        assert close(o.B(q) + o.one_minus_B(q), 1, 1e-29)


def test_C() -> None:
    with mp.workdps(40):
        assert close(o.C(5), 5 / mp.pi * mp.besselk(0, 2.5), 1e-29)
        assert close(o.C(-5), -5 / mp.pi * mp.besselk(0, 2.5), 1e-29)


def test_effective_moduli_check_values() -> None:
    for kw, ref in ((1, "1.52182858"), (3, "1.08044869"), (5, "1.01886667")):
        m, nu_eff = o.effective_moduli(kw, 0.33)
        assert close(m, mp.mpf(ref), 5e-9)
        assert nu_eff > 0.33  # mu_eff > mu and nu_eff > nu at experimentally relevant kW (Fig. 3a)
        assert close(o.mu_eff_minus_one(kw, 0.33), m - 1, 1e-28)


def test_effective_moduli_limits() -> None:
    m, nu_eff = o.effective_moduli(1e3, 0.33)
    assert close(m, 1, 1e-28) and close(nu_eff, 0.33, 1e-28)  # nu = the float 0.33 here
    assert -1e-100 < o.mu_eff_minus_one(1e3, 0.33) < 0  # approached from below, tiny
    assert o.effective_moduli(1e-3, 0.33)[0] > 100  # kW -> 0: the thick block looks very stiff


@pytest.mark.parametrize(
    ("nu", "q_ref", "q_tol", "depth_ref", "depth_tol"),
    [
        (0.2, "8.5897", 5e-5, "7.0327e-4", 5e-9),
        (0.3, "15.119", 5e-4, "1.13875e-5", 5e-11),
        (0.33, "19.3", 0.05, "9.7e-7", 5e-9),  # the supplement's "nu = 0.3" numbers (misprint)
        (0.4, "45.345", 5e-4, "5.847e-13", 5e-17),  # the supplement says 1 - 8e-8 at q = 45 (misprint)
    ],
)
def test_mu_eff_minimum(nu, q_ref, q_tol, depth_ref, depth_tol) -> None:
    q_min, depth = o.mu_eff_minimum(nu)
    assert close(q_min, mp.mpf(q_ref), q_tol)
    assert close(depth, mp.mpf(depth_ref), depth_tol)
    for dq in (-0.1, 0.1):  # it is a minimum of mu_eff/mu
        assert o.mu_eff_minus_one(q_min + dq, nu) > -depth


def test_thin_on_thick_check_values() -> None:
    """docs/physics.md §6 (nu = 0.33)."""
    assert close(o.thin_on_thick_response(0.919, 5, 0.33)[1], "-0.0544266880084", 5e-14)
    assert close(o.thin_on_thick_response(0.9, 3, 0.33)[1], "-0.101096689153", 5e-13)
    assert close(o.thin_on_thick_quasistatic_gy(5, 0.33), "-0.04921931781306", 5e-15)
    assert close(o.thin_on_thick_response(1e-4, 5, 0.33)[1], "-0.04921931774306", 5e-15)


def _thin_on_thick_gy_brute(z, kw, nu, dps) -> mp.mpf:
    """Eq. S-m2s literally, at a fixed (huge) precision, independent of the oracle's helpers."""
    with mp.workdps(dps):
        nu, z = mp.mpf(nu), mp.mpf(z)
        m, nu2 = o.effective_moduli(kw, nu)
        nu1 = nu / (1 + nu)

        def m_half(zz, nu_, mu_, sign):
            b = (1 - 2 * nu_) / (2 - 2 * nu_)
            a_s, a_d = mp.sqrt(1 - zz**2), mp.sqrt(1 - b * zz**2)
            d = mu_ * ((1 + a_s**2) ** 2 - 4 * a_s * a_d)
            off = 1 + a_s**2 - 2 * a_s * a_d
            return mp.matrix(
                [
                    [sign * a_s * (1 - a_s**2) / d, 1j * off / d],
                    [-1j * off / d, sign * a_d * (1 - a_s**2) / d],
                ]
            )

        g = (m_half(z, nu1, 1, 1) - m_half(z / mp.sqrt(m), nu2, m, -1)) ** -1
        return g[1, 0] / 1j


@pytest.mark.parametrize("z", [1e-8, 1e-4, 0.5, 0.919])
def test_thin_on_thick_against_brute_force_precision(z) -> None:
    ref = _thin_on_thick_gy_brute(z, 5, 0.33, 150)
    assert close(o.thin_on_thick_response(z, 5, 0.33)[1], ref, 1e-28)


def test_thin_on_thick_quasistatic_limit_is_approached_quadratically() -> None:
    """z = 1e-8 is right to 20+ digits: G_y(z) - G_y(0) = a z^2 with the same a as at z = 1e-4."""
    g0 = o.thin_on_thick_quasistatic_gy(5, 0.33)
    a4 = (o.thin_on_thick_response(1e-4, 5, 0.33)[1] - g0) / mp.mpf("1e-8")
    a8 = (o.thin_on_thick_response(1e-8, 5, 0.33)[1] - g0) / mp.mpf("1e-16")
    assert rel_close(a8, a4, 1e-6)
    for kw in (1e-3, 1, 3, 1e3):
        assert close(
            o.thin_on_thick_response(1e-9, kw, 0.33)[1], o.thin_on_thick_quasistatic_gy(kw, 0.33), 1e-15
        )


def test_thin_on_thick_gy_negative_and_growing_towards_cR() -> None:
    """Fig. 3b: G_y < 0 (thin block effectively softer) and |G_y| grows as c -> c_R (it is not monotonic
    at small c for kW = 4, 5)."""
    for kw in (3, 4, 5):
        vals = [mp.re(o.thin_on_thick_response(z, kw, 0.33)[1]) for z in (0.85, 0.9, 0.919, 0.95)]
        assert all(v < 0 for v in vals)
        assert all(abs(a) < abs(b) for a, b in zip(vals, vals[1:], strict=False))


def test_normal_stress_change() -> None:
    """Eq. dsigma: Delta sigma_yy = -(mu/c) G_y v; > 0 (less compression) since G_y < 0."""
    c_s, rho = 1345.0, 1180.0
    mu = rho * c_s**2
    c = 0.91909 * c_s
    ds = o.normal_stress_change(1.0, c, c_s, 5, 0.33, mu)
    g_y = o.thin_on_thick_response(mp.mpf(c) / c_s, 5, 0.33)[1]
    assert close(ds, -(mu / mp.mpf(c)) * g_y, 1e-30 * mu)
    assert mp.re(ds) > 0 and mp.im(ds) == 0
    assert close(o.normal_stress_change(2.0, c, c_s, 5, 0.33, mu), 2 * ds, 1e-28 * abs(ds))
