"""The physical parameters of the spectrum, declared once for every layer: name, the paper's symbol, meaning, the
paper's default and valid domain (docs/physics.md §1). The app's widgets and the atlas engine's metadata take them
from here."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._validate import DOMAINS, check


@dataclass(frozen=True)
class Parameter:
    """One physical parameter of F(z; kH) (Eq. implicit_spectrum with Eq. delta f RSF)."""

    name: str  #: the keyword of the model functions
    symbol: str  #: the paper's symbol
    description: str  #: what it is, with its definition
    #: the paper's value (docs/physics.md §1): Fig. 5 takes Fig. 4's f = 0.9, beta = 0.3 with gamma = 3; eta = inf
    #: and Delta = 1 are Fig. 4's setting (a half-space, velocity-only friction: xi does not enter, 0 here)
    default: float

    @property
    def domain(self) -> str:
        """The valid range, as the ValueErrors state it."""
        return DOMAINS[self.name][5]

    def check(self, value) -> np.ndarray:
        """`value` as an array after checking it lies in the domain (ValueError naming the parameter otherwise)."""
        return check(self.name, value)


#: gamma, f, beta, eta, Delta, xi: the order of the model's keyword arguments
PARAMETERS: dict[str, Parameter] = {p.name: p for p in (
    Parameter("gamma", "γ", "γ = μ/(σ₀ c_s ∂_v f): elastodynamic stiffness over the direct velocity effect", 3.0),
    Parameter("f", "f", "f: the steady-state friction coefficient", 0.9),
    Parameter("beta", "β", "β = c_s/c_d: shear over dilatational wave speed", 0.3),
    Parameter("eta", "η", "η = H₂/H₁: the lower block's height over the upper block's (∞: a half-space)", math.inf),
    Parameter("Delta", "Δ", "Δ = d_v f/∂_v f: steady-state over direct velocity dependence of friction (1: no state)",
              1.0),
    Parameter("xi", "ξ", "ξ = D c_s/(H v |g′(1)|): the memory length of the interface state (irrelevant at Δ = 1)",
              0.0),
)}


def check_parameter(name: str, value) -> np.ndarray:
    """`value` of the physical parameter `name` as an array, after checking its domain (docs/physics.md §1).

    Raises ValueError naming the parameter and its valid range (also for an unknown name)."""
    if name not in PARAMETERS:
        raise ValueError(f"unknown parameter {name!r}; the parameters are {', '.join(PARAMETERS)}")
    return PARAMETERS[name].check(value)
