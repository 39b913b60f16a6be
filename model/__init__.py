"""Physics of frictional sliding without geometrical reflection symmetry (Aldam et al., PRX 6, 041023, 2016).

Public API (NumPy in, NumPy out; physical parameters keyword-only and broadcasting):

- :func:`rayleigh_speed` (PHYSICS section 5)
- :func:`response_functions`, :func:`response_derivatives` (Eq. Gs_general)
- :func:`dispersion`, :func:`dispersion_derivative` (Eq. implicit_spectrum + Eq. delta f RSF)
- :func:`spectrum`, :func:`rayleigh_branch` (Rayleigh branch, PHYSICS section 3)
- :func:`linear_expansion` (Eq. S-dz)
- :func:`bessel_integral_B`, :func:`bessel_term_C`, :func:`effective_moduli`,
  :func:`thin_on_thick_response`, :func:`normal_stress_change` (Sect. III, Eqs. effective_constants, dsigma)
- :func:`rayleigh_wave_speed`, :func:`plane_modulus`, :func:`mode_ii_universal_function`,
  :func:`cohesive_zone_size`, :func:`peak_cohesive_stress`, :func:`stress_intensity_factor`,
  :func:`universal_slip_profile`, :func:`shear_stress_profile`, :func:`slip_velocity_profile`,
  :func:`peak_slip_velocity`, :func:`peak_slip_location`, :func:`relative_normal_stress_change_at_peak_slip`,
  :class:`RuptureParameters` / ``PAPER_DEFAULTS`` (supplement Sect. S-V, steady mode-II cohesive zone;
  docs/physics.md §13)
"""

from .elastic import poisson_ratio, shear_modulus, wave_speed_ratio
from .elastodynamics import (
    dispersion,
    dispersion_derivative,
    dispersion_scale,
    response_derivatives,
    response_functions,
)
from .modes import unstable_count, unstable_modes
from .rayleigh import rayleigh_speed
from .rupture import (
    PAPER_DEFAULTS,
    PEAK_SLIP_POSITION,
    PEAK_SLIP_PROFILE,
    RuptureParameters,
    cohesive_zone_size,
    mode_ii_universal_function,
    peak_cohesive_stress,
    peak_slip_location,
    peak_slip_velocity,
    plane_modulus,
    rayleigh_wave_speed,
    relative_normal_stress_change_at_peak_slip,
    shear_stress_profile,
    slip_velocity_profile,
    stress_intensity_factor,
    universal_slip_profile,
)
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
    "PAPER_DEFAULTS",
    "PEAK_SLIP_POSITION",
    "PEAK_SLIP_PROFILE",
    "RuptureParameters",
    "cohesive_zone_size",
    "mode_ii_universal_function",
    "peak_cohesive_stress",
    "peak_slip_location",
    "peak_slip_velocity",
    "plane_modulus",
    "rayleigh_wave_speed",
    "relative_normal_stress_change_at_peak_slip",
    "shear_stress_profile",
    "slip_velocity_profile",
    "stress_intensity_factor",
    "universal_slip_profile",
]
