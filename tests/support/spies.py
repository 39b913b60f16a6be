"""Call spies for the app's tests: how often a scene ran a cached computation or called the model, counted from outside
the product (the app's modules carry no counters).

:func:`spy_calls` counts, by name, for one app module:

- the runs of its ``pn.cache``'d functions (cache misses: the function's body ran; a cache hit is not counted),
- the calls of its other module-level ``compute_*`` functions,
- its calls into the public model API (``model.<name>(...)`` made by the module).

The cached functions are spied on where ``pn.cache`` keeps them: the wrapper Panel returns calls the function held in
its closure cell ``func`` (panel/io/cache.py), which the spy replaces for the test (``monkeypatch`` restores it). The
cache's key does not depend on that function (only on its name, module and arguments), so caching is unchanged.
:func:`cached_body_cell` fails loudly if a Panel release keeps the function elsewhere.
"""

from __future__ import annotations

import collections
import functools
import inspect
import threading
import types
from collections.abc import Callable
from typing import Any

import pytest


class Calls(collections.Counter):
    """A Counter that the spies increment from any thread (the Stability map computes on a background job)."""

    def __init__(self) -> None:
        super().__init__()
        self._lock = threading.Lock()

    def add(self, name: str) -> None:
        with self._lock:
            self[name] += 1


def _counting(fn: Callable[..., Any], name: str, calls: Calls) -> Callable[..., Any]:
    @functools.wraps(fn)
    def spy(*args: Any, **kwargs: Any) -> Any:
        calls.add(name)
        return fn(*args, **kwargs)

    return spy


def cached_body_cell(cached: Callable[..., Any]) -> types.CellType:
    """The closure cell in which ``pn.cache``'s wrapper holds the cached function (its body)."""
    code = cached.__code__
    if "func" not in code.co_freevars or cached.__closure__ is None:
        raise RuntimeError(f"pn.cache no longer keeps {cached.__name__}'s body in a cell named 'func': update "
                           "tests/support/spies.py for this Panel release")
    cell = cached.__closure__[code.co_freevars.index("func")]
    if cell.cell_contents is not getattr(cached, "__wrapped__", None):
        raise RuntimeError(f"the 'func' cell of {cached.__name__} is not the cached function")
    return cell


def _is_pn_cached(obj: Any) -> bool:
    return inspect.isfunction(obj) and callable(getattr(obj, "clear", None)) and hasattr(obj, "__wrapped__")


class _ModelSpy(types.ModuleType):
    """Stands for :mod:`model` inside one app module: every function fetched from it counts its calls."""

    def __init__(self, real: types.ModuleType, calls: Calls) -> None:
        super().__init__(real.__name__, real.__doc__)
        self._real = real
        self._calls = calls

    def __getattr__(self, name: str) -> Any:
        value = getattr(self._real, name)
        if inspect.isfunction(value):
            return _counting(value, name, self._calls)
        return value


def spy_calls(monkeypatch: pytest.MonkeyPatch, module: types.ModuleType, calls: Calls | None = None) -> Calls:
    """Count, in `calls` (a new :class:`Calls` if None), the cache misses of `module`'s ``pn.cache``'d functions, the
    calls of its other ``compute_*`` functions and its calls into :mod:`model` (see the module's docstring); undone
    by `monkeypatch` at the end of the test."""
    calls = Calls() if calls is None else calls
    for name, obj in list(vars(module).items()):
        if getattr(obj, "__module__", None) != module.__name__:
            continue
        if _is_pn_cached(obj):
            cell = cached_body_cell(obj)
            monkeypatch.setattr(cell, "cell_contents", _counting(cell.cell_contents, name, calls))
        elif inspect.isfunction(obj) and name.startswith("compute_"):
            monkeypatch.setattr(module, name, _counting(obj, name, calls))
    real_model = getattr(module, "model", None)
    if isinstance(real_model, types.ModuleType):
        monkeypatch.setattr(module, "model", _ModelSpy(real_model, calls))
    return calls


def spying(*spied: tuple[types.ModuleType, Calls]) -> Callable[..., None]:
    """The autouse fixture of a scene's test module: empty caches (``fresh_caches``), then for each (app module,
    counter) pair the counter cleared and the module's spies installed. Use: ``_spies = spying((sp, calls))``."""

    @pytest.fixture(autouse=True)
    def _spies(fresh_caches: None, monkeypatch: pytest.MonkeyPatch) -> None:
        for module, calls in spied:
            calls.clear()
            spy_calls(monkeypatch, module, calls)

    return _spies
