"""The user-facing parameters, declared once (:class:`Physical`, :class:`Choice`, :class:`Switch`), and what is
derived from the declarations: widgets (:mod:`asymslide.app.widgets`), URL keys, stability-map axes; the parameter
classes of the scenes (:class:`SpectrumParams`, :class:`ThinOnThickParams`, :class:`LabParams`,
:class:`RuptureParams`) and the one normalisation of the model's arguments (:func:`model_args`).

Data flow: widget (sliders on release) -> parameter -> cached model call -> HoloViews element.
"""

from __future__ import annotations

import math
from typing import Any

import panel as pn
import param

from asymslide import model

from .declarations import Choice, Physical, Switch, from_log10
from .widgets import make_widgets

#: the paper's symbols and meanings of the model's parameters (declared once, in model.PARAMETERS); the app adds the
#: user-interface side: slider ranges and steps, URL keys, map axes
_SYMBOL = {name: p.symbol for name, p in model.PARAMETERS.items()}
#: the paper's default values of the model's parameters (model.Parameter.default)
_DEFAULT = {name: p.default for name, p in model.PARAMETERS.items()}
_MEANING = {name: p.description for name, p in model.PARAMETERS.items()}


def model_args(gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float) -> tuple[float, ...]:
    """(γ, f, β, η, Δ, ξ) as every scene passes them to the model: floats, and ξ = 0 at Δ = 1 (ξ does not enter F
    then), so that moving the ξ slider at Δ = 1 is not a new cache key. The one place this rule is written."""
    return (float(gamma), float(f), float(beta), float(eta), float(Delta), 0.0 if Delta == 1 else float(xi))


class SpectrumParams(param.Parameterized):
    """The physical parameters of the spectrum (paper Sect. IV; docs/physics.md §1), shared by the Spectrum,
    Stability-map and All-branches scenes. Defaults: the paper's, declared once in model.PARAMETERS (γ = 3, f = 0.9,
    β = 0.3, η = ∞, Δ = 1, ξ = 0: Fig. 5; the η slider shows 10⁸ while η = ∞ is ticked)."""

    gamma = Physical(_DEFAULT["gamma"], bounds=(1e-2, 1e3), softbounds=(0.1, 30.0), step=0.01, label=_SYMBOL["gamma"],
                     url="gamma", axis=(0.1, 30.0, True), doc=_MEANING["gamma"])
    f = Physical(_DEFAULT["f"], bounds=(0.0, 2.0), step=0.01, label=_SYMBOL["f"], url="f", axis=(0.0, 2.0, False),
                 doc=_MEANING["f"])
    beta = Physical(_DEFAULT["beta"], bounds=(0.01, 0.7071), step=0.001, label=_SYMBOL["beta"], url="beta",
                    axis=(0.01, 0.7071, False), doc=_MEANING["beta"] + " (β² = (1 − 2ν)/(2 − 2ν))")
    #: True while a slider of these parameters is held (app.widgets.bind_two_way): the plots follow the hand, the
    #: background jobs and maps wait for the release
    dragging = param.Boolean(False, precedence=-1)

    log10_eta = Physical(8.0, bounds=(-2.0, 12.0), step=0.1, label=_SYMBOL["eta"], url="eta", log10=True,
                         axis=(1.0, 1e8, True), infinite="eta_infinite", doc=_MEANING["eta"] + " (slider: log10 η)")
    eta_infinite = param.Boolean(math.isinf(_DEFAULT["eta"]), label=f"{_SYMBOL['eta']} = ∞",
                                 doc="the lower block is a half-space (η = ∞)")
    Delta = Physical(_DEFAULT["Delta"], bounds=(0.01, 1.0), step=0.01, label=_SYMBOL["Delta"], url="Delta",
                     axis=(0.01, 1.0, False), doc=_MEANING["Delta"])
    xi = Physical(_DEFAULT["xi"], bounds=(0.0, 1e4), softbounds=(0.0, 10.0), step=0.01, label=_SYMBOL["xi"], url="xi",
                  axis=(1e-2, 1e3, True), doc=_MEANING["xi"])

    #: the model's keyword arguments, in the order of :meth:`model_args`
    MODEL_ARGS = ("gamma", "f", "beta", "eta", "Delta", "xi")

    @property
    def eta(self) -> float:
        return math.inf if self.eta_infinite else 10.0**self.log10_eta

    def model_args(self) -> tuple[float, float, float, float, float, float]:
        """(gamma, f, beta, eta, Delta, xi) as passed to the model (:func:`model_args`)."""
        return model_args(self.gamma, self.f, self.beta, self.eta, self.Delta, self.xi)

    @classmethod
    def declaration(cls, model_arg: str) -> Physical:
        """The declaration behind a model argument (``eta`` is held as ``log10_eta``)."""
        return cls.param["log10_eta" if model_arg == "eta" else model_arg]

    @classmethod
    def symbol(cls, model_arg: str) -> str:
        """The paper's symbol of a model argument."""
        return cls.declaration(model_arg).label

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`); ξ is disabled while Δ = 1 and η while
        η = ∞ is ticked."""
        w = make_widgets(self)
        w["xi"].disabled = self.Delta == 1

        def show_eta(infinite: bool) -> None:
            """While η = ∞ is ticked the slider is disabled and shows no number (not its last finite value; the
            box below it says ∞). BokehJS does not redraw a slider's title for a new `format`: a formatter that read
            ∞ kept reading ∞ after the box was unticked, so the number is hidden instead."""
            w["log10_eta"].param.update(disabled=infinite, show_value=not infinite)

        show_eta(self.eta_infinite)
        self.param.watch(lambda e: setattr(w["xi"], "disabled", e.new == 1), "Delta")
        self.param.watch(lambda e: show_eta(e.new), "eta_infinite")
        return w


class ThinOnThickParams(param.Parameterized):
    """The parameters of the thin-on-thick scene (paper Sect. III; docs/physics.md §6). Defaults: the PMMA
    experiment of Sect. S-V (kW = 5, ν = 0.33). Its material constants c_s, ρ and σ₀ are the shared ones of the
    Lab-units panel (:class:`LabParams`: PMMA, c_s = 1345 m/s, ρ = 1180 kg/m³ assumed, σ₀ = 4.5 MPa)."""

    log10_kW = Physical(math.log10(5.0), bounds=(-2.0, 2.0), step=0.01, label="kW", url="kW", log10=True,
                        doc="kW: wavenumber k times the thin block's width W (slider: log10 kW)")
    nu = Physical(0.33, bounds=(0.0, 0.49), step=0.005, label="ν", url="nu", doc="Poisson ratio ν")

    #: the URL holds only the values that differ from the defaults
    URL_CHANGED_ONLY = True

    @property
    def kW(self) -> float:
        return from_log10(self.log10_kW)

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`)."""
        return make_widgets(self)


#: the material choice that keeps the typed values (a preset's values edited by hand)
CUSTOM = "custom"


class LabParams(param.Parameterized):
    """A laboratory setting in lab units (docs/physics.md §12), mapped onto γ, f, β, η, Δ, ξ by
    :func:`model.dimensionless_parameters` (the Lab-units panel of the Spectrum and Stability-map scenes).

    Its material constants (:data:`SHARED_MATERIAL`: the material, ρ, c_s, σ₀) are the page's one set: the
    Thin-on-thick and Rupture-fronts scenes use them too and show widgets bound to them.

    Defaults: the PMMA preset (ρ = 1180 kg/m³, an assumption; c_s = 1345 m/s, c_d = 2700 m/s), plane strain (the
    paper's Sect. IV), H₁ = 10 mm on a half-space (η = ∞), σ₀ = 4.5 MPa, f = 0.9, and rate-and-state a = 0.01,
    b = 0 (Δ = 1), D_c = 1 µm at v = 0.08506 m/s: γ = 3.000, f, η and Δ are the paper's Fig. 4 values; β = 0.498
    is PMMA's (no preset has the paper's β = 0.3, ν = 0.45); ξ = 1.58 does not enter at Δ = 1.
    """

    material = Choice("PMMA", objects=[*model.material_names(), CUSTOM], label="Material", url="material",
                      doc="material preset: fills in ρ, c_s, c_d (model/materials.json); editing them makes it custom")
    rho = Physical(1180.0, bounds=(-1e6, 1e6), step=10.0, label="ρ [kg/m³]", url="lab_rho", widget="input",
                   doc="density ρ [kg/m³]; μ = ρ c_s²")
    c_s = Physical(1345.0, bounds=(-1e6, 1e6), step=1.0, label="c_s [m/s]", url="lab_cs", widget="input",
                   doc="shear wave speed c_s [m/s]")
    c_d = Physical(2700.0, bounds=(-1e6, 1e6), step=1.0, label="c_d [m/s] (bulk)", url="lab_cd", widget="input",
                   doc="dilatational wave speed c_d [m/s], the bulk (3-D) value that ultrasound measures")
    plane = Choice("strain", objects=["strain", "stress"], label="Plane", url="plane",
                   doc="plane strain (thick blocks, the paper's Sect. IV) or plane stress (thin plates): sets β")
    H1_mm = Physical(10.0, bounds=(-1e6, 1e6), step=1.0, label="H₁ [mm]", url="H1", widget="input",
                     doc="height H₁ = H of the upper block [mm] (the H of kH)")
    H2_mm = Physical(30.0, bounds=(-1e6, 1e6), step=1.0, label="H₂ [mm]", url="H2", widget="input",
                     infinite="H2_infinite", doc="height H₂ of the lower block [mm]; η = H₂/H₁")
    H2_infinite = param.Boolean(True, label="H₂ = ∞ (half-space)", doc="the lower block is a half-space (η = ∞)")
    sigma0_MPa = Physical(4.5, bounds=(-1e6, 1e6), step=0.1, label="σ₀ [MPa]", url="lab_sigma0", widget="input",
                          doc="normal stress σ₀ [MPa]")
    f = Physical(0.9, bounds=(-100.0, 100.0), step=0.01, label="f (friction coefficient)", url="lab_f",
                 widget="input", doc="steady-state friction coefficient f at the sliding velocity v")
    a = Physical(0.01, bounds=(-100.0, 100.0), step=0.001, label="a (direct effect)", url="a", widget="input",
                 doc="rate-and-state a: ∂_v f = a/v (Dieterich-Ruina, an assumption: docs/physics.md §12.3)")
    b = Physical(0.0, bounds=(-100.0, 100.0), step=0.001, label="b (state effect)", url="b", widget="input",
                 doc="rate-and-state b, 0 ≤ b < a: Δ = 1 − b/a")
    D_c_um = Physical(1.0, bounds=(-1e9, 1e9), step=0.1, label="D_c [µm]", url="Dc", widget="input",
                      doc="rate-and-state memory length D_c [µm]: ξ = D_c c_s/(H₁ v)")
    v = Physical(0.08506, bounds=(-1e6, 1e6), step=0.001, label="v [m/s]", url="v", widget="input",
                 doc="steady sliding velocity v [m/s]: γ = ρ c_s v/(σ₀ a)")
    link = Switch(False, label="Sliders follow the lab values", url="lab",
                  doc="while on, every change of a lab value sets the sliders γ, f, β, η, Δ, ξ")

    #: which lab values a material preset fills in (model.Material attributes)
    MATERIAL_FIELDS = ("rho", "c_s", "c_d")
    #: the URL holds only the values that differ from the defaults
    URL_CHANGED_ONLY = True

    @staticmethod
    def material_values(name: str) -> dict[str, float]:
        """ρ, c_s, c_d of the material preset `name` (model/materials.json)."""
        m = model.material(name)
        return {"rho": m.rho, "c_s": m.c_s, "c_d": m.c_d}

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`); H₂ is disabled while H₂ = ∞ is ticked."""
        w = make_widgets(self)
        w["H2_mm"].disabled = self.H2_infinite
        self.param.watch(lambda e: setattr(w["H2_mm"], "disabled", e.new), "H2_infinite")
        return w


class RuptureParams(param.Parameterized):
    """The inputs of the steady mode-II cohesive-zone model of a rupture front (supplement S-V C; docs/physics.md
    §13) and of Eq. dsigma at its peak slip velocity. Defaults: the paper's (model.PAPER_DEFAULTS: Γ = 1.1 J/m²,
    X_c0 = 2.5 mm, ν = 0.33; kW = 3, 4, 5), at c = 0.9 c_R. Its material constants ρ, c_s and σ₀ are the shared ones
    of the Lab-units panel (:class:`LabParams`; the paper's PMMA c_s = 1345 m/s, σ₀ = 4.5 MPa, assumed
    ρ = 1180 kg/m³); ν follows the shared material's preset (the source's ν where it reports one) and can be edited.
    """

    c_over_cR = Physical(0.9, bounds=(0.01, 0.999), step=0.001, label="c/c_R", url="c_cR",
                         doc="rupture speed c over the Rayleigh speed c_R (plane stress); the model needs 0 < c < c_R")
    Gamma = Physical(model.PAPER_DEFAULTS.Gamma, bounds=(-1e6, 1e6), step=0.1, label="Γ [J/m²]", url="Gamma",
                     widget="input", doc="fracture energy Γ [J/m²], constant in c")
    X_c0_mm = Physical(model.PAPER_DEFAULTS.X_c0 * 1e3, bounds=(-1e6, 1e6), step=0.1, label="X_c0 [mm]", url="Xc0",
                       widget="input", doc="cohesive zone size X_c0 = X_c(c → 0) [mm]")
    nu = Physical(model.PAPER_DEFAULTS.nu, bounds=(-100.0, 100.0), step=0.01, label="ν", url="rup_nu",
                  widget="input", doc="Poisson ratio ν (3-D); the plates are in plane stress")
    kW1 = Physical(model.PAPER_DEFAULTS.kW[0], bounds=(-1e6, 1e6), step=0.5, label="kW₁", url="kW1", widget="input",
                   doc="first kW of the Δσ_yy/σ₀ curves (wavenumber times the thin block's width)")
    kW2 = Physical(model.PAPER_DEFAULTS.kW[1], bounds=(-1e6, 1e6), step=0.5, label="kW₂", url="kW2", widget="input",
                   doc="second kW of the Δσ_yy/σ₀ curves")
    kW3 = Physical(model.PAPER_DEFAULTS.kW[2], bounds=(-1e6, 1e6), step=0.5, label="kW₃", url="kW3", widget="input",
                   doc="third kW of the Δσ_yy/σ₀ curves")

    URL_CHANGED_ONLY = True

    @staticmethod
    def material_nu(name: str) -> float:
        """ν of the material preset `name` as the source reports it where it does, else from the bulk speeds
        (model.Material.nu)."""
        m = model.material(name)
        return float(m.reported.get("nu", m.nu))

    def make_widgets(self) -> dict[str, pn.widgets.Widget]:
        """Fresh widgets bound to this object (:func:`make_widgets`)."""
        return make_widgets(self)


#: the material constants of :class:`LabParams` that every scene uses (one set per page)
SHARED_MATERIAL = ("material", "rho", "c_s", "sigma0_MPa")


def set_with_material(obj: LabParams, updates: dict[str, Any]) -> None:
    """Set `updates` on `obj`; a material named there brings its preset's values, except those `updates` sets
    itself (a URL or a preset naming only the material gets its values; values given with it win, and the material
    then reads custom if they differ from the preset's)."""
    updates = dict(updates)
    name = updates.pop("material", None)
    if name is None:
        obj.param.update(**updates)
        return
    if name != CUSTOM:
        updates = {**obj.material_values(name), **updates}
    obj.material = name
    obj.param.update(**updates)
    if name != CUSTOM and any(getattr(obj, k) != v for k, v in obj.material_values(name).items()):
        obj.material = CUSTOM


def follow_material(obj: LabParams) -> None:
    """Keep `obj`'s material choice and its values consistent: picking a preset fills in its values (those not set
    in the same update), and values that differ from the preset make the choice custom."""
    fields = set(obj.MATERIAL_FIELDS)

    def changed(*events: param.parameterized.Event) -> None:
        names = {e.name for e in events}
        if "material" in names and obj.material != CUSTOM:
            fill = {k: v for k, v in obj.material_values(obj.material).items() if k not in names}
            if any(getattr(obj, k) != v for k, v in fill.items()):
                obj.param.update(**fill)
        if obj.material != CUSTOM and any(getattr(obj, k) != v for k, v in obj.material_values(obj.material).items()):
            obj.material = CUSTOM

    obj.param.watch(changed, ["material", *sorted(fields)])
    changed()
