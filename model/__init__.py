"""Physics of frictional sliding without geometrical reflection symmetry (Aldam et al., PRX 6, 041023, 2016).

Public API (NumPy in, NumPy out; physical parameters keyword-only and broadcasting):

- :func:`rayleigh_speed` (PHYSICS section 5)
- :func:`response_functions`, :func:`response_derivatives` (Eq. Gs_general)
- :func:`dispersion`, :func:`dispersion_derivative` (Eq. implicit_spectrum + Eq. delta f RSF)
- :func:`spectrum`, :func:`rayleigh_branch` (Rayleigh branch, PHYSICS section 3)
- :func:`linear_expansion` (Eq. S-dz)
- :func:`bessel_integral_B`, :func:`bessel_term_C`, :func:`effective_moduli`,
  :func:`thin_on_thick_response`, :func:`normal_stress_change` (Sect. III, Eqs. effective_constants, dsigma)
- lab units <-> gamma, eta, Delta, xi, beta and material presets: :mod:`model.lab_units`
  (:func:`dimensionless_parameters`, :func:`rate_state_parameters`, :func:`material`; docs/physics.md §12)
"""

from .elastic import poisson_ratio, shear_modulus, wave_speed_ratio
from .elastodynamics import (
    dispersion,
    dispersion_derivative,
    dispersion_scale,
    response_derivatives,
    response_functions,
)
from .lab_units import (
    Delta_from_lab,
    Delta_from_rate_state,
    Material,
    b_from_Delta,
    dilatational_wave_speed,
    dimensionless_parameters,
    direct_effect_from_gamma,
    direct_effect_from_rate_state,
    e_folding_time,
    eta_from_heights,
    gamma_from_lab,
    growth_rate,
    im_z_from_e_folding_time,
    im_z_from_growth_rate,
    kH_from_wavelength,
    lower_height_from_eta,
    material,
    material_names,
    memory_length_from_xi,
    phase_speed,
    poisson_ratio_from_speeds,
    rate_state_parameters,
    re_z_from_phase_speed,
    shear_wave_speed,
    spectrum_in_lab_units,
    steady_state_effect_from_Delta,
    steady_state_effect_from_rate_state,
    wave_speed_ratio_from_speeds,
    wavelength,
    xi_from_lab,
    xi_from_rate_state,
)
from .modes import unstable_count, unstable_modes
from .rayleigh import rayleigh_speed
from .spectrum import STATUS, SpectrumResult, linear_expansion, rayleigh_branch, spectrum
from .stability import (
    GrowthResult,
    StabilityVerdict,
    criterion_chi,
    critical_chi,
    critical_eta,
    critical_gamma,
    growth_analysis,
    max_growth,
    stability_verdict,
    stable,
    unstable_band,
)
from .thin_on_thick import (
    bessel_integral_B,
    bessel_term_C,
    effective_moduli,
    effective_modulus_excess,
    normal_stress_change,
    one_minus_bessel_integral_B,
    thin_on_thick_response,
)

__all__ = [
    "STATUS",
    "GrowthResult",
    "StabilityVerdict",
    "stability_verdict",
    "stable",
    "critical_chi",
    "critical_eta",
    "critical_gamma",
    "criterion_chi",
    "growth_analysis",
    "max_growth",
    "unstable_band",
    "bessel_integral_B",
    "bessel_term_C",
    "effective_moduli",
    "effective_modulus_excess",
    "normal_stress_change",
    "one_minus_bessel_integral_B",
    "thin_on_thick_response",
    "unstable_count",
    "unstable_modes",
    "SpectrumResult",
    "dispersion",
    "dispersion_derivative",
    "dispersion_scale",
    "linear_expansion",
    "rayleigh_branch",
    "rayleigh_speed",
    "response_derivatives",
    "response_functions",
    "spectrum",
    "poisson_ratio",
    "shear_modulus",
    "wave_speed_ratio",
    "Delta_from_lab",
    "Delta_from_rate_state",
    "Material",
    "b_from_Delta",
    "dilatational_wave_speed",
    "dimensionless_parameters",
    "direct_effect_from_gamma",
    "direct_effect_from_rate_state",
    "e_folding_time",
    "eta_from_heights",
    "gamma_from_lab",
    "growth_rate",
    "im_z_from_e_folding_time",
    "im_z_from_growth_rate",
    "kH_from_wavelength",
    "lower_height_from_eta",
    "material",
    "material_names",
    "memory_length_from_xi",
    "phase_speed",
    "poisson_ratio_from_speeds",
    "rate_state_parameters",
    "re_z_from_phase_speed",
    "shear_wave_speed",
    "spectrum_in_lab_units",
    "steady_state_effect_from_Delta",
    "steady_state_effect_from_rate_state",
    "wave_speed_ratio_from_speeds",
    "wavelength",
    "xi_from_lab",
    "xi_from_rate_state",
]
