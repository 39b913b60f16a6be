"""Lab units <-> the paper's dimensionless groups, and the material presets (model/lab_units.py, docs/physics.md §12).

Expected numbers are computed here from the definitions (or taken from the paper / docs/physics.md), never from
the code under test.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from asymslide import model
from asymslide.model import lab_units as L

SETTINGS = settings(max_examples=200, deadline=None)
RTOL = 1e-12


def logs(lo: float, hi: float):
    """Log-uniform positive floats in [10^lo, 10^hi]."""
    return st.floats(lo, hi).map(lambda x: 10.0**x)


def close(a, b, rtol=RTOL) -> bool:
    return bool(np.allclose(a, b, rtol=rtol, atol=0.0))


# --- round trips lab -> dimensionless -> lab -----------------------------------------------------------------


@SETTINGS
@given(mu=logs(3, 12), sigma0=logs(2, 10), c_s=logs(0, 5), de=logs(-8, 6))
def test_gamma_round_trip(mu, sigma0, c_s, de):
    g = L.gamma_from_lab(mu=mu, sigma0=sigma0, c_s=c_s, direct_effect=de)
    assert close(g, mu / (sigma0 * c_s * de))
    assert close(L.direct_effect_from_gamma(gamma=g, mu=mu, sigma0=sigma0, c_s=c_s), de)


@SETTINGS
@given(H1=logs(-6, 4), ratio=logs(-4, 8))
def test_eta_round_trip(H1, ratio):
    H2 = H1 * ratio
    eta = L.eta_from_heights(H1=H1, H2=H2)
    assert close(L.lower_height_from_eta(eta=eta, H1=H1), H2)


def test_eta_half_space():
    assert L.eta_from_heights(H1=0.01, H2=math.inf) == math.inf
    assert L.lower_height_from_eta(eta=math.inf, H1=0.01) == math.inf
    assert L.eta_from_heights(H1=0.02, H2=0.06) == pytest.approx(3.0, rel=1e-15)


@SETTINGS
@given(de=logs(-8, 6), frac=st.floats(1e-6, 1.0))
def test_Delta_round_trip(de, frac):
    sse = frac * de
    d = L.Delta_from_lab(steady_state_effect=sse, direct_effect=de)
    assert close(d, sse / de)
    assert close(L.steady_state_effect_from_Delta(Delta=d, direct_effect=de), sse)


@SETTINGS
@given(D=logs(-9, 0), c_s=logs(0, 5), H1=logs(-6, 4), v=logs(-12, 2), gp=logs(-2, 2))
def test_xi_round_trip(D, c_s, H1, v, gp):
    xi = L.xi_from_lab(D=D, c_s=c_s, H1=H1, v=v, abs_g_prime=gp)
    assert close(xi, D * c_s / (H1 * v * gp))
    assert close(L.memory_length_from_xi(xi=xi, c_s=c_s, H1=H1, v=v, abs_g_prime=gp), D)


@SETTINGS
@given(
    rho=logs(2, 4.5),
    c_s=logs(1, 4.5),
    cd_ratio=st.floats(math.sqrt(2.0), 10.0),
    sigma0=logs(3, 9),
    f=st.floats(0.0, 2.0),
    H1=logs(-5, 3),
    eta_=st.one_of(logs(-2, 8), st.just(math.inf)),
    v=logs(-10, 1),
    a=logs(-5, -0.5),
    b_over_a=st.one_of(st.just(0.0), st.floats(1e-3, 1.0 - 1e-9)),
    D_c=st.one_of(st.just(0.0), logs(-9, -1)),
)
def test_lab_setting_round_trip(rho, c_s, cd_ratio, sigma0, f, H1, eta_, v, a, b_over_a, D_c):
    """a, b, D_c, H2 -> gamma, Delta, xi, eta -> a, b, D_c, H2 (b/a >= 1e-3: Delta = 1 - b/a keeps b to 1e-12)."""
    c_d, b, H2 = cd_ratio * c_s, b_over_a * a, eta_ * H1
    p = L.dimensionless_parameters(rho=rho, c_s=c_s, c_d=c_d, sigma0=sigma0, f=f, H1=H1, H2=H2, v=v, a=a, b=b, D_c=D_c)
    assert set(p) == {"gamma", "f", "beta", "eta", "Delta", "xi"}
    mu = rho * c_s**2
    assert close(p["gamma"], mu * v / (sigma0 * c_s * a))
    assert close(p["beta"], c_s / c_d) or p["beta"] == 1.0 / math.sqrt(2.0)
    assert close(p["xi"], D_c * c_s / (H1 * v)) or (D_c == 0.0 and p["xi"] == 0.0)
    back = L.rate_state_parameters(
        gamma=p["gamma"], Delta=p["Delta"], xi=p["xi"], eta=p["eta"], rho=rho, c_s=c_s, sigma0=sigma0, H1=H1, v=v
    )
    assert close(back["a"], a)
    assert close(back["b"], b, rtol=1e-12) if b else abs(back["b"]) <= 1e-15 * a
    assert close(back["D_c"], D_c)
    assert close(back["H2"], H2)


@SETTINGS
@given(a=logs(-6, 0), b_over_a=st.floats(0.0, 1.0 - 1e-12), v=logs(-12, 2))
def test_rate_state_slopes(a, b_over_a, v):
    b = b_over_a * a
    de = L.direct_effect_from_rate_state(a=a, v=v)
    sse = L.steady_state_effect_from_rate_state(a=a, b=b, v=v)
    assert close(de, a / v)
    assert close(sse, (a - b) / v)
    d = L.Delta_from_rate_state(a=a, b=b)
    assert close(d, L.Delta_from_lab(steady_state_effect=sse, direct_effect=de))
    assert 0.0 < d <= 1.0
    assert close(L.Delta_from_rate_state(a=a, b=L.b_from_Delta(Delta=d, a=a)), d)


@SETTINGS
@given(kH=logs(-4, 4), H1=logs(-6, 4))
def test_wavelength_round_trip(kH, H1):
    lam = L.wavelength(kH=kH, H1=H1)
    assert close(lam, 2.0 * math.pi * H1 / kH)
    assert close(L.kH_from_wavelength(wavelength=lam, H1=H1), kH)


@SETTINGS
@given(
    kH=logs(-4, 4),
    H1=logs(-6, 4),
    c_s=logs(0, 5),
    re=st.floats(-10.0, 10.0),
    im=st.one_of(st.just(0.0), logs(-12, 0), logs(-12, 0).map(lambda x: -x)),
)  # no subnormals
def test_growth_rate_and_phase_speed_round_trip(kH, H1, c_s, re, im):
    z = complex(re, im)
    rate = L.growth_rate(kH=kH, z=z, H1=H1, c_s=c_s)
    assert close(L.im_z_from_growth_rate(growth_rate=rate, kH=kH, H1=H1, c_s=c_s), im)
    speed = L.phase_speed(z=z, c_s=c_s)
    assert close(L.re_z_from_phase_speed(phase_speed=speed, c_s=c_s), re)


@SETTINGS
@given(kH=logs(-4, 4), H1=logs(-6, 4), c_s=logs(0, 5), im=logs(-12, 1))
def test_e_folding_time_round_trip(kH, H1, c_s, im):
    t = L.e_folding_time(kH=kH, z=complex(0.9, im), H1=H1, c_s=c_s)
    assert close(t, H1 / (kH * im * c_s))
    assert close(L.im_z_from_e_folding_time(e_folding_time=t, kH=kH, H1=H1, c_s=c_s), im)


@SETTINGS
@given(c_s=logs(0, 5), cd_ratio=st.floats(2.0 / math.sqrt(3.0) * (1.0 + 1e-6), 30.0))
def test_poisson_ratio_round_trip_plane_strain(c_s, cd_ratio):
    c_d = cd_ratio * c_s
    nu = L.poisson_ratio_from_speeds(c_s=c_s, c_d=c_d)
    b2 = (c_s / c_d) ** 2
    assert abs(nu - (1 - 2 * b2) / (2 * (1 - b2))) <= 1e-12
    assert -1.0 < nu < 0.5
    assert close(L.dilatational_wave_speed(c_s=c_s, nu=nu), c_d)


@SETTINGS
@given(c_s=logs(0, 5), nu=st.floats(-0.999, 0.499), plane=st.sampled_from(["strain", "stress"]))
def test_dilatational_speed_round_trip(c_s, nu, plane):
    c_d = L.dilatational_wave_speed(c_s=c_s, nu=nu, plane=plane)
    expected = c_s * math.sqrt(2 * (1 - nu) / (1 - 2 * nu)) if plane == "strain" else c_s * math.sqrt(2 / (1 - nu))
    assert close(c_d, expected)
    # nu is O(1) and may be 0: compare absolutely
    assert abs(L.poisson_ratio_from_speeds(c_s=c_s, c_d=c_d, plane=plane) - nu) <= 1e-12


@SETTINGS
@given(rho=logs(1, 5), c_s=logs(0, 5))
def test_shear_modulus_round_trip(rho, c_s):
    mu = model.shear_modulus(rho, c_s)
    assert close(L.shear_wave_speed(mu=mu, rho=rho), c_s)


def test_broadcasting():
    H1 = np.array([0.01, 0.1])[:, None]
    a = np.array([0.01, 0.02, 0.03])
    p = L.dimensionless_parameters(
        rho=1180.0, c_s=1345.0, c_d=2700.0, sigma0=4.5e6, f=0.6, H1=H1, H2=np.inf, v=0.1, a=a, b=0.005, D_c=1e-6
    )
    assert p["gamma"].shape == (3,)
    assert p["xi"].shape == (2, 1)
    assert p["Delta"].shape == (3,)
    np.testing.assert_allclose(p["Delta"], 1.0 - 0.005 / a, rtol=1e-15)
    np.testing.assert_allclose(p["xi"][:, 0], 1e-6 * 1345.0 / (np.array([0.01, 0.1]) * 0.1), rtol=1e-15)


# --- hand-computed values ------------------------------------------------------------------------------------


def test_lab_outputs_hand_computed():
    H1, c_s = 0.5, 1000.0
    # kH = 2 pi: one wavelength per H
    assert L.wavelength(kH=2.0 * math.pi, H1=H1) == pytest.approx(0.5, rel=1e-15)
    # kH = 2, z = 0.9 + 0.01 i: k = 4 /m, Im c = 10 m/s, rate = 40 /s, e-folding 25 ms, phase speed 900 m/s
    z = 0.9 + 0.01j
    assert L.growth_rate(kH=2.0, z=z, H1=H1, c_s=c_s) == pytest.approx(40.0, rel=1e-14)
    assert L.e_folding_time(kH=2.0, z=z, H1=H1, c_s=c_s) == pytest.approx(0.025, rel=1e-14)
    assert L.phase_speed(z=z, c_s=c_s) == pytest.approx(900.0, rel=1e-15)
    # decaying, neutral and masked (NaN) modes
    zs = np.array([0.9 - 0.01j, 0.9 + 0.0j, np.nan, complex(np.nan, np.nan)])
    rate = L.growth_rate(kH=2.0, z=zs, H1=H1, c_s=c_s)
    assert rate[0] == pytest.approx(-40.0, rel=1e-14) and rate[1] == 0.0 and np.isnan(rate[2:]).all()
    t = L.e_folding_time(kH=2.0, z=zs, H1=H1, c_s=c_s)
    assert t[0] == math.inf and t[1] == math.inf and np.isnan(t[2:]).all()
    assert np.isnan(L.phase_speed(z=zs, c_s=c_s)[2:]).all()
    out = L.spectrum_in_lab_units(kH=np.array([2.0, 4.0]), z=np.array([z, z]), H1=H1, c_s=c_s)
    np.testing.assert_allclose(out["wavelength"], [2 * math.pi * 0.5 / 2, 2 * math.pi * 0.5 / 4], rtol=1e-15)
    np.testing.assert_allclose(out["growth_rate"], [40.0, 80.0], rtol=1e-14)
    np.testing.assert_allclose(out["e_folding_time"], [0.025, 0.0125], rtol=1e-14)
    np.testing.assert_allclose(out["phase_speed"], [900.0, 900.0], rtol=1e-15)


def test_pmma_setting_hand_computed():
    """PMMA, sigma0 = 4.5 MPa (Sect. III), a = 0.01, b = 0.005, D_c = 1 um, v = 1 mm/s, H1 = 10 cm, H2 = 3 cm."""
    rho, c_s = 1180.0, 1345.0
    p = L.dimensionless_parameters(
        **L.material("PMMA").elastic_constants(),
        sigma0=4.5e6,
        f=0.6,
        H1=0.1,
        H2=0.03,
        v=1e-3,
        a=0.01,
        b=0.005,
        D_c=1e-6,
    )
    direct = 0.01 / 1e-3  # a/v = 10 s/m
    assert p["gamma"] == pytest.approx(rho * c_s**2 / (4.5e6 * c_s * direct), rel=1e-14)
    assert p["gamma"] == pytest.approx(0.0352688888888889, rel=1e-12)
    assert p["Delta"] == pytest.approx(0.5, rel=1e-15)
    assert p["xi"] == pytest.approx(1e-6 * 1345.0 / (0.1 * 1e-3), rel=1e-14)  # 13.45
    assert p["eta"] == pytest.approx(0.3, rel=1e-15)
    assert p["beta"] == pytest.approx(1345.0 / 2700.0, rel=1e-15)
    assert p["f"] == 0.6


def test_dimensionless_parameters_feed_spectrum():
    """A lab setting built to give docs/physics.md §7's check case reproduces its Rayleigh-branch value.

    gamma = 3, f = 0.9, beta = 0.3, eta = inf, Delta = 1, q = 1: z = 0.88336356305352538 + 0.00815518661032729 i.
    """
    rho, c_s, sigma0, H1, v = 1180.0, 1345.0, 4.5e6, 0.1, 0.5
    lab = L.rate_state_parameters(
        gamma=3.0, Delta=1.0, xi=0.0, eta=math.inf, rho=rho, c_s=c_s, sigma0=sigma0, H1=H1, v=v
    )
    assert lab["b"] == 0.0 and lab["D_c"] == 0.0 and lab["H2"] == math.inf
    assert lab["a"] == pytest.approx(v * rho * c_s / (sigma0 * 3.0), rel=1e-14)
    p = L.dimensionless_parameters(
        rho=rho,
        c_s=c_s,
        c_d=c_s / 0.3,
        sigma0=sigma0,
        f=0.9,
        H1=H1,
        H2=lab["H2"],
        v=v,
        a=lab["a"],
        b=lab["b"],
        D_c=lab["D_c"],
    )
    z = model.spectrum(np.array([1.0]), **p)
    expected = 0.88336356305352538 + 0.00815518661032729j
    assert abs(z[0] - expected) <= 1e-12 * abs(expected)
    lab_out = L.spectrum_in_lab_units(kH=np.array([1.0]), z=z, H1=H1, c_s=c_s)
    assert lab_out["growth_rate"][0] == pytest.approx(1.0 * expected.imag * c_s / H1, rel=1e-11)


# --- material presets ----------------------------------------------------------------------------------------


def test_pmma_preset_matches_paper():
    m = L.material("PMMA")
    assert (m.c_s, m.c_d) == (1345.0, 2700.0)
    assert m.beta("strain") == pytest.approx(1345.0 / 2700.0, rel=1e-15)
    b2 = (1345.0 / 2700.0) ** 2
    nu = (1.0 - 2.0 * b2) / (2.0 * (1.0 - b2))
    assert m.nu == pytest.approx(nu, rel=1e-14)
    assert abs(m.nu - 0.335) < 5e-4  # Supplement S-V: "nu ~ 0.335"; the paper rounds to 0.33
    assert abs(m.nu - m.reported["nu"]) < 0.01
    # plane-stress c_d = c_s sqrt(2 / (1 - nu)) = 2332.48 m/s; the paper quotes 2333 +- 10 m/s
    cd_ps = 1345.0 * math.sqrt(2.0 / (1.0 - nu))
    assert m.c_d_plane_stress == pytest.approx(cd_ps, rel=1e-14)
    assert abs(m.c_d_plane_stress - m.reported["c_d_plane_stress"]) < 1.0
    assert m.beta("stress") == pytest.approx(1345.0 / cd_ps, rel=1e-14)
    # Rayleigh speeds quoted in the supplement, to the metre
    assert abs(model.rayleigh_speed(m.beta("stress")) * m.c_s - m.reported["c_R_plane_stress"]) < 0.5
    assert abs(model.rayleigh_speed(m.beta("strain")) * m.c_s - m.reported["c_R_plane_strain"]) < 0.5
    # the density is not in the paper: flagged as an assumption, with its source
    assert m.rho == 1180.0 and m.assumptions == ("rho",)
    assert "NOT stated" in m.rho_source and "CRC" in m.rho_source
    assert m.mu == pytest.approx(1180.0 * 1345.0**2, rel=1e-15)


@pytest.mark.parametrize("name", L.material_names())
def test_every_material_is_physical_and_sourced(name):
    m = L.material(name)
    for src in (m.rho_source, m.c_s_source, m.c_d_source):
        assert isinstance(src, str) and len(src.strip()) > 10
    assert m.rho > 0.0 and m.c_s > 0.0
    nu = (1 - 2 * (m.c_s / m.c_d) ** 2) / (2 * (1 - (m.c_s / m.c_d) ** 2))
    assert -1.0 < nu < 0.5
    assert m.nu == pytest.approx(nu, rel=1e-13)
    assert m.c_d > 2.0 / math.sqrt(3.0) * m.c_s
    assert m.mu > 0.0 and m.mu == pytest.approx(m.rho * m.c_s**2, rel=1e-15)
    # every preset is usable by the stability model (beta <= 1/sqrt(2), i.e. nu >= 0) in both planes
    assert 0.0 <= nu and m.beta("strain") <= 1.0 / math.sqrt(2.0) and m.beta("stress") <= 1.0 / math.sqrt(2.0)
    assert 500.0 < m.rho < 25000.0 and 100.0 < m.c_s < 10000.0  # solids, SI units (not g/cm^3 or km/s)
    assert L.material(name.upper()) is m


def test_material_file_has_a_source_for_every_number():
    data = json.loads(L.MATERIALS_FILE.read_text(encoding="utf-8"))
    seen = 0

    def walk(node):
        nonlocal seen
        if isinstance(node, dict):
            if "value" in node:
                seen += 1
                assert isinstance(node["value"], int | float)
                assert node.get("source", "").strip(), node
                assert node.get("unit", "").strip(), node
            for v in node.values():
                walk(v)
        elif isinstance(node, list):
            for v in node:
                walk(v)

    walk(data)
    assert seen >= 3 * len(L.material_names())
    assert [e["name"] for e in data["materials"]] == list(L.material_names())


def test_material_lookup_and_frozen():
    with pytest.raises(ValueError) as err:
        L.material("unobtainium")
    msg = str(err.value)
    assert "material" in msg and "unobtainium" in msg
    assert all(n in msg for n in L.material_names())
    with pytest.raises(ValueError, match="material"):
        L.material(3)  # type: ignore[arg-type]
    m = L.material("PMMA")
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.rho = 1.0  # type: ignore[misc]
    with pytest.raises(TypeError):
        m.reported["nu"] = 0.3  # type: ignore[index]
    assert m.elastic_constants() == {"rho": 1180.0, "c_s": 1345.0, "c_d": 2700.0}
    assert hash(m) == hash(L.material("pmma"))


# --- bad input names the parameter and its range -------------------------------------------------------------

GOOD = dict(rho=1180.0, c_s=1345.0, c_d=2700.0, sigma0=4.5e6, f=0.6, H1=0.1, H2=0.3, v=1e-3, a=0.01, b=0.005, D_c=1e-6)


@pytest.mark.parametrize(
    "fn, kwargs, needles",
    [
        (L.dimensionless_parameters, dict(GOOD, H1=0.0), ["H1", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, H1=-0.1), ["H1", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, H2=0.0), ["H2", "(0, inf]"]),
        (L.dimensionless_parameters, dict(GOOD, rho=0.0), ["rho", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, rho=-1180.0), ["rho", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, c_s=-1345.0), ["c_s", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, c_d=0.0), ["c_d", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, c_d=1800.0), ["c_d", "sqrt(2) c_s"]),
        (L.dimensionless_parameters, dict(GOOD, sigma0=0.0), ["sigma0", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, sigma0=-4.5e6), ["sigma0", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, v=0.0), ["v must", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, a=0.0), ["a must", "(0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, b=-0.001), ["b must", "[0, inf)"]),
        (L.dimensionless_parameters, dict(GOOD, b=0.02), ["a = 0.01", "b = 0.02", "0 <= b < a"]),
        (L.dimensionless_parameters, dict(GOOD, b=0.01), ["a = 0.01", "b = 0.01", "0 <= b < a"]),
        (L.dimensionless_parameters, dict(GOOD, D_c=-1e-6), ["D_c", "[0, inf)"]),
        # the API speaks SI (the app words it in the units its fields take)
        (L.dimensionless_parameters, dict(GOOD, H1=-0.005), ["H1 must be in (0, inf) m", "-0.005"]),
        (L.dimensionless_parameters, dict(GOOD, H2=-0.03), ["H2 must be in (0, inf] m", "-0.03"]),
        (L.dimensionless_parameters, dict(GOOD, f=math.nan), ["f must"]),
        (L.dimensionless_parameters, dict(GOOD, H1="0.1"), ["H1 must be numeric"]),
        (L.dimensionless_parameters, dict(GOOD, plane="3d"), ["plane must be one of"]),
        (L.dimensionless_parameters, dict(GOOD, H1=np.array([0.1, -1.0])), ["H1", "-1.0"]),
        (
            L.rate_state_parameters,
            dict(gamma=3.0, Delta=1.5, xi=0.0, eta=1.0, rho=1180.0, c_s=1345.0, sigma0=4.5e6, H1=0.1, v=1e-3),
            ["Delta", "(0, 1]"],
        ),
        (
            L.rate_state_parameters,
            dict(gamma=0.0, Delta=1.0, xi=0.0, eta=1.0, rho=1180.0, c_s=1345.0, sigma0=4.5e6, H1=0.1, v=1e-3),
            ["gamma", "(0, inf)"],
        ),
        (
            L.rate_state_parameters,
            dict(gamma=3.0, Delta=1.0, xi=-1.0, eta=1.0, rho=1180.0, c_s=1345.0, sigma0=4.5e6, H1=0.1, v=1e-3),
            ["xi", "[0, inf)"],
        ),
        (
            L.rate_state_parameters,
            dict(gamma=3.0, Delta=1.0, xi=0.0, eta=0.0, rho=1180.0, c_s=1345.0, sigma0=4.5e6, H1=0.1, v=1e-3),
            ["eta", "(0, inf]"],
        ),
        (L.Delta_from_lab, dict(steady_state_effect=2.0, direct_effect=1.0), ["steady_state_effect", "(0, 1]"]),
        (L.Delta_from_lab, dict(steady_state_effect=-1.0, direct_effect=1.0), ["steady_state_effect", "(0, inf)"]),
        (L.gamma_from_lab, dict(mu=1e9, sigma0=1e6, c_s=1e3, direct_effect=0.0), ["direct_effect", "(0, inf)"]),
        (L.xi_from_lab, dict(D=1e-6, c_s=1e3, H1=0.1, v=1e-3, abs_g_prime=0.0), ["abs_g_prime", "(0, inf)"]),
        (L.poisson_ratio_from_speeds, dict(c_s=1000.0, c_d=1100.0), ["c_d", "(2/sqrt(3)) c_s", "(-1, 0.5)"]),
        (L.poisson_ratio_from_speeds, dict(c_s=1000.0, c_d=2100.0, plane="stress"), ["c_d", "2 c_s", "(-1, 0.5)"]),
        (L.dilatational_wave_speed, dict(c_s=1000.0, nu=0.5), ["nu", "(-1, 0.5)"]),
        (L.dilatational_wave_speed, dict(c_s=1000.0, nu=-1.0), ["nu", "(-1, 0.5)"]),
        (L.wavelength, dict(kH=0.0, H1=0.1), ["kH", "(0, inf)"]),
        (L.growth_rate, dict(kH=1.0, z="0.9", H1=0.1, c_s=1e3), ["z must be numeric"]),
        (L.growth_rate, dict(kH=1.0, z=complex(np.inf, 0.0), H1=0.1, c_s=1e3), ["z must be finite"]),
        (L.im_z_from_e_folding_time, dict(e_folding_time=0.0, kH=1.0, H1=0.1, c_s=1e3), ["e_folding_time", "(0, inf]"]),
        (L.shear_wave_speed, dict(mu=-1.0, rho=1000.0), ["mu", "(0, inf)"]),
    ],
)
def test_bad_input_names_the_parameter(fn, kwargs, needles):
    with pytest.raises(ValueError) as err:
        fn(**kwargs)
    msg = str(err.value)
    for needle in needles:
        assert needle in msg, (needle, msg)


def test_public_api_exported():
    for name in (
        "dimensionless_parameters",
        "rate_state_parameters",
        "material",
        "material_names",
        "Material",
        "gamma_from_lab",
        "eta_from_heights",
        "Delta_from_rate_state",
        "xi_from_lab",
        "wavelength",
        "growth_rate",
        "e_folding_time",
        "phase_speed",
        "poisson_ratio_from_speeds",
    ):
        assert name in model.__all__ and getattr(model, name) is getattr(L, name)
