"""Physics of frictional sliding without geometrical reflection symmetry (Aldam et al., PRX 6, 041023, 2016).

Public API (NumPy in, NumPy out; physical parameters keyword-only and broadcasting; bad input raises
ValueError naming the parameter and its range). The equations and numerics are in docs/physics.md.

Parameters (§1)
    :data:`PARAMETERS` (name, symbol, meaning and domain of gamma, f, beta, eta, Delta, xi as
    :class:`Parameter`), :func:`check_parameter`.

Elastodynamics of two blocks (docs/physics.md §2-§3, §5)
    :func:`rayleigh_speed` (Rayleigh cubic), :func:`response_functions`, :func:`response_derivatives`
    (Eq. Gs_general), :func:`dispersion`, :func:`dispersion_derivative`, :func:`dispersion_scale`
    (Eq. implicit_spectrum with Eq. delta f RSF), :func:`root_error_estimate` (residual and error of a root).

Rayleigh branch of the spectrum (§3, §4, §8)
    :func:`spectrum`, :func:`rayleigh_branch` returning :class:`SpectrumResult` (masked points and their
    reasons: :data:`STATUS`), :func:`linear_expansion` (Eq. S-dz).

Stability (§4, §9)
    :func:`growth_analysis` returning :class:`GrowthResult` (the continuous max growth over the kH range and its
    verdict: :class:`Verdict`, :data:`VERDICTS`, :data:`VERDICT_STATUS`, :func:`verdict_class`),
    :func:`growth_chunk` (one chunk of a stability map, for distributed sweeps; rows :data:`GROWTH_ROWS`, by name
    :func:`growth_rows` returning :class:`GrowthRows`, as a result :func:`growth_result`),
    :func:`max_growth`, :func:`unstable_band`; thresholds as certified neutral modes: :func:`critical_gammas`,
    :func:`critical_etas` (every crossing, :class:`Crossings`, reason codes :class:`CrossingReason` and
    :data:`CROSSING_STATUS`, the certified ones :data:`CERTIFIED_CROSSINGS`), :func:`critical_gamma`,
    :func:`critical_eta` (the first certified crossing) and, for whole chunks at once, :func:`crossings_chunk`,
    :func:`threshold_chunk` returning :class:`ThresholdChunk`, :func:`critical_gamma_chunk`,
    :func:`critical_eta_chunk` (reason codes :class:`ThresholdReason`, :data:`THRESHOLD_STATUS`);
    :func:`min_gy_at_rayleigh_speed`, :func:`criterion_chi`, :func:`criterion_gy_level` (Eq. criterion),
    :func:`critical_chi` (Fig. 4c), :func:`stability_verdict` returning :class:`StabilityVerdict`, :func:`stable`.

All branches (§10)
    :func:`unstable_modes`, :func:`unstable_count` (argument principle in a stated window).

Every mode at once, a second solver (§15)
    :func:`eigenmodes` returning :class:`Eigenmodes` (Chebyshev collocation of Eq. S-LE in both blocks, one eigenvalue
    problem per kH, the converged eigenvalues of two resolutions), :func:`mode_shape` returning :class:`ModeShape`
    (the fields of one mode), :func:`eigenmode_resolution` (the points it takes for a window).

The whole spectrum: is steady sliding stable? (§14)
    :func:`root_window` (where the roots with Im z >= floor can be: a theorem), :func:`fastest_mode` (the root of
    largest Im z over every branch at each kH, certified, its family :data:`FAMILIES` and the count above the floor,
    :class:`FastestMode`, :data:`MODE_STATUS`), :func:`sliding_analysis` (over a kH range: the maximum of that
    growth and of the temporal rate, and the sliding verdict beside the Rayleigh branch's, :class:`SlidingResult`,
    :class:`SlidingReason`, :data:`SLIDING_STATUS`), :func:`sliding_chunk` (a chunk for sweeps, rows
    :data:`SLIDING_ROWS`; its reason codes as verdict classes :func:`sliding_verdict`, its family row as codes
    :func:`family_codes`); :data:`DEFAULT_FLOOR`, :data:`SLIDING_KH`; :func:`growth_rate_limit` (the supremum of
    the temporal growth rate kH Im z approached as kH -> infinity, eta = inf: :class:`GrowthRateLimit`,
    :data:`LIMIT_STATUS`).

Thin-on-thick (§6)
    :func:`bessel_integral_B`, :func:`one_minus_bessel_integral_B`, :func:`bessel_term_C` (Eq. B(q)C(q)),
    :func:`effective_moduli`, :func:`effective_modulus_excess` (Eq. effective_constants),
    :func:`thin_on_thick_response` (Eq. S-m2s), :func:`limiting_speed` (below the shear speed of both
    effective blocks), :func:`normal_stress_change` (Eq. dsigma).

Elastic constants (§1, §6)
    :func:`wave_speed_ratio`, :func:`poisson_ratio` (plane strain and plane stress), :func:`shear_modulus`,
    :func:`shear_wave_speed`, :func:`dilatational_wave_speed`, :func:`poisson_ratio_from_speeds`,
    :func:`wave_speed_ratio_from_speeds`.

Lab units (§12): the dimensionless groups from lab quantities and back
    :func:`gamma_from_lab`, :func:`direct_effect_from_gamma`, :func:`eta_from_heights`,
    :func:`lower_height_from_eta`, :func:`Delta_from_lab`, :func:`steady_state_effect_from_Delta`,
    :func:`xi_from_lab`, :func:`memory_length_from_xi`; rate-and-state friction (a, b, D_c, v; an assumption
    stated in §12): :func:`direct_effect_from_rate_state`, :func:`steady_state_effect_from_rate_state`,
    :func:`Delta_from_rate_state`, :func:`b_from_Delta`, :func:`xi_from_rate_state`; a whole setting:
    :func:`dimensionless_parameters`, :func:`rate_state_parameters`; results in lab units:
    :func:`wavelength`, :func:`kH_from_wavelength`, :func:`growth_rate`, :func:`im_z_from_growth_rate`,
    :func:`e_folding_time`, :func:`im_z_from_e_folding_time`, :func:`phase_speed`, :func:`re_z_from_phase_speed`,
    :func:`spectrum_in_lab_units`, :func:`fastest_growing_mode` (the maximum of the growth rate k Im c);
    material presets: :func:`material_names`, :func:`material` returning
    :class:`Material`.

Rupture fronts: the steady mode-II cohesive-zone model of the supplement (§13)
    :func:`rayleigh_wave_speed`, :func:`plane_modulus`, :func:`mode_ii_universal_function` (f_II),
    :func:`cohesive_zone_size`, :func:`peak_cohesive_stress`, :func:`stress_intensity_factor`,
    :func:`universal_slip_profile`, :func:`shear_stress_profile`, :func:`slip_velocity_profile`,
    :func:`peak_slip_velocity`, :func:`peak_slip_location` (constants :data:`PEAK_SLIP_POSITION`,
    :data:`PEAK_SLIP_PROFILE`), :func:`relative_normal_stress_change_at_peak_slip` (Eq. dsigma at the peak);
    the paper's inputs: :class:`RuptureParameters`, :data:`PAPER_DEFAULTS`.
"""

from .crossings import (
    CERTIFIED_CROSSINGS,
    CROSSING_STATUS,
    THRESHOLD_STATUS,
    CrossingReason,
    Crossings,
    ThresholdReason,
)
from .eigenmodes import Eigenmodes, ModeShape, eigenmode_resolution, eigenmodes, mode_shape
from .elastic import poisson_ratio, shear_modulus, wave_speed_ratio
from .elastodynamics import (
    dispersion,
    dispersion_derivative,
    dispersion_scale,
    response_derivatives,
    response_functions,
    root_error_estimate,
)
from .growth_limits import LIMIT_STATUS, GrowthRateLimit, growth_rate_limit
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
    fastest_growing_mode,
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
from .parameters import PARAMETERS, Parameter, check_parameter
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
from .sliding import (
    DEFAULT_FLOOR,
    FAMILIES,
    MODE_STATUS,
    SLIDING_KH,
    SLIDING_ROWS,
    SLIDING_STATUS,
    FastestMode,
    SlidingReason,
    SlidingResult,
    family_codes,
    fastest_mode,
    root_window,
    sliding_analysis,
    sliding_chunk,
    sliding_verdict,
)
from .spectrum import STATUS, SpectrumResult, linear_expansion, rayleigh_branch, spectrum
from .stability import (
    GROWTH_ROWS,
    VERDICT_STATUS,
    VERDICTS,
    GrowthResult,
    GrowthRows,
    StabilityVerdict,
    Verdict,
    criterion_chi,
    criterion_gy_level,
    growth_analysis,
    growth_chunk,
    growth_result,
    growth_rows,
    max_growth,
    min_gy_at_rayleigh_speed,
    stability_verdict,
    stable,
    unstable_band,
    verdict_class,
)
from .thin_on_thick import (
    bessel_integral_B,
    bessel_term_C,
    effective_moduli,
    effective_modulus_excess,
    limiting_speed,
    normal_stress_change,
    one_minus_bessel_integral_B,
    thin_on_thick_response,
)
from .thresholds import (
    ThresholdChunk,
    critical_chi,
    critical_eta,
    critical_eta_chunk,
    critical_etas,
    critical_gamma,
    critical_gamma_chunk,
    critical_gammas,
    crossings_chunk,
    threshold_chunk,
)

__all__ = [
    "DEFAULT_FLOOR",
    "FAMILIES",
    "MODE_STATUS",
    "SLIDING_KH",
    "SLIDING_ROWS",
    "SLIDING_STATUS",
    "SlidingReason",
    "FastestMode",
    "SlidingResult",
    "fastest_mode",
    "growth_rate_limit",
    "GrowthRateLimit",
    "LIMIT_STATUS",
    "root_window",
    "sliding_analysis",
    "sliding_chunk",
    "sliding_verdict",
    "family_codes",
    "PARAMETERS",
    "Parameter",
    "check_parameter",
    "STATUS",
    "GrowthResult",
    "StabilityVerdict",
    "stability_verdict",
    "stable",
    "critical_chi",
    "critical_eta",
    "critical_etas",
    "critical_gamma",
    "critical_gammas",
    "CERTIFIED_CROSSINGS",
    "CROSSING_STATUS",
    "CrossingReason",
    "Crossings",
    "crossings_chunk",
    "GROWTH_ROWS",
    "GrowthRows",
    "VERDICT_STATUS",
    "VERDICTS",
    "Verdict",
    "verdict_class",
    "criterion_chi",
    "criterion_gy_level",
    "THRESHOLD_STATUS",
    "ThresholdReason",
    "ThresholdChunk",
    "threshold_chunk",
    "critical_gamma_chunk",
    "critical_eta_chunk",
    "growth_analysis",
    "growth_chunk",
    "growth_result",
    "growth_rows",
    "min_gy_at_rayleigh_speed",
    "max_growth",
    "unstable_band",
    "bessel_integral_B",
    "bessel_term_C",
    "effective_moduli",
    "effective_modulus_excess",
    "normal_stress_change",
    "limiting_speed",
    "one_minus_bessel_integral_B",
    "thin_on_thick_response",
    "unstable_count",
    "unstable_modes",
    "Eigenmodes",
    "ModeShape",
    "eigenmodes",
    "mode_shape",
    "eigenmode_resolution",
    "SpectrumResult",
    "dispersion",
    "dispersion_derivative",
    "dispersion_scale",
    "linear_expansion",
    "rayleigh_branch",
    "rayleigh_speed",
    "response_derivatives",
    "response_functions",
    "root_error_estimate",
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
    "fastest_growing_mode",
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
