"""The public API of `model` is what `model.__all__` says."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

from asymslide import model


def _public_modules() -> list:
    return [importlib.import_module(f"{model.__name__}.{m.name}") for m in pkgutil.iter_modules(model.__path__)
            if not m.name.startswith("_")]


def test_star_import_gives_every_name_in_all() -> None:
    namespace: dict = {}
    exec(f"from {model.__name__} import *", namespace)  # noqa: S102 (a fixed statement, the check itself)
    missing = [name for name in model.__all__ if name not in namespace]
    assert not missing
    assert len(set(model.__all__)) == len(model.__all__), "duplicate names in __all__"


def test_every_public_function_and_class_of_a_model_module_is_exported() -> None:
    """A function or class defined in a public module of `model` without a leading underscore is part of the API."""
    unexported = []
    for module in _public_modules():
        for name, obj in vars(module).items():
            if name.startswith("_") or not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if getattr(obj, "__module__", None) != module.__name__:
                continue  # imported from elsewhere
            if name not in model.__all__:
                unexported.append(f"{module.__name__}.{name}")
    assert not unexported, f"public-looking but not exported (export them or make them private): {unexported}"


def test_exports_are_documented() -> None:
    doc = model.__doc__ or ""
    undocumented = [name for name in model.__all__ if name not in doc]
    assert not undocumented, f"model's docstring does not list: {undocumented}"
    for name in model.__all__:
        obj = getattr(model, name)
        if inspect.isfunction(obj) or inspect.isclass(obj):
            assert (obj.__doc__ or "").strip(), f"{name} has no docstring"
