"""model.PARAMETERS carries the paper's defaults: written once in model/, valid, and the same as the keyword
defaults of the public functions."""

from __future__ import annotations

import inspect
import math
from pathlib import Path

import pytest

from asymslide import model

#: from the paper's captions: Fig. 4 (Linear stability: simplified analysis) "f = 0.9 and beta = 0.3", a half-space
#: and velocity-only friction; Fig. 5 "the same as in Fig. 4 with gamma = 3"; xi does not enter at Delta = 1
PAPER = {"gamma": 3.0, "f": 0.9, "beta": 0.3, "eta": math.inf, "Delta": 1.0, "xi": 0.0}


def test_every_parameter_carries_the_papers_default() -> None:
    assert {name: p.default for name, p in model.PARAMETERS.items()} == PAPER
    assert list(model.PARAMETERS) == list(PAPER)  # the order of the model's keyword arguments


@pytest.mark.parametrize("name", list(PAPER))
def test_the_default_lies_in_the_parameters_domain(name: str) -> None:
    p = model.PARAMETERS[name]
    assert float(p.check(p.default)) == p.default
    assert float(model.check_parameter(name, p.default)) == p.default


def test_keyword_defaults_of_the_public_functions_are_the_papers() -> None:
    """Where a public function gives a physical parameter a default (eta, Delta, xi), it is Parameter.default."""
    seen = 0
    for name in model.__all__:
        obj = getattr(model, name)
        if not inspect.isfunction(obj):
            continue
        for arg, spec in inspect.signature(obj).parameters.items():
            if arg in model.PARAMETERS and spec.default is not inspect.Parameter.empty:
                assert spec.default == model.PARAMETERS[arg].default, (name, arg)
                seen += 1
    assert seen >= 50  # about 20 functions with eta, Delta and xi defaults


def test_the_default_beta_gives_the_papers_rayleigh_speed() -> None:
    """The paper, by Fig. 4: "here c_R ~ 0.95 c_s" (for its beta = 0.3)."""
    assert float(model.rayleigh_speed(model.PARAMETERS["beta"].default)) == pytest.approx(0.95, abs=0.005)


def test_the_command_line_help_states_the_model_defaults() -> None:
    """asymslide sweep --help names the defaults without importing the model (fast --help); they are the model's."""
    import re

    from asymslide import cli

    text = Path(cli.__file__).read_text(encoding="utf-8")
    stated = dict(re.findall(r"(gamma|f|beta|eta|Delta|xi)=(inf|[0-9.]+)", text.split('"--fixed"', 1)[1][:400]))
    assert stated.keys() == model.PARAMETERS.keys()
    for name, value in stated.items():
        assert float(value) == model.PARAMETERS[name].default, name
