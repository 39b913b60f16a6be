"""The Stability map's sliding boundary (app.sliding_boundary): every certified crossing in γ of the max growth over
every branch at each column, computed chunk by chunk as a job, published as it grows, cached per chunk."""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest

from asymslide import model
from asymslide.app import jobs, sliding_work
from asymslide.app import sliding_boundary as sb
from asymslide.app.stability_map.compute import ChunkCache

#: three columns of the f-γ plane at η = ∞, β = 0.3 (f = 0.3: no threshold in range; 0.6, 0.9: one each)
X = np.array([0.3, 0.6, 0.9])
FIXED = (("beta", 0.3), ("eta", float("inf")), ("Delta", 1.0), ("xi", 0.0))
FLOOR = 1e-6
GAMMA_RANGE = (0.1, 30.0)
KEY = ("f-γ", 3, FIXED, FLOOR)


def _run(cache: ChunkCache) -> tuple[jobs.JobState, list[dict]]:
    published: list[dict] = []
    job = jobs.Job(partial(sb.compute_boundary, KEY, X, "f", GAMMA_RANGE, cache.get, cache.put), name="boundary",
                   key=KEY, totals={"columns": X.size})
    job.subscribe(lambda: published.append(job.state().partial))
    state = job.start().wait(300)
    return state, [p for p in published if p is not None]


@pytest.fixture(scope="module")
def computed() -> tuple[jobs.JobState, list[dict], ChunkCache]:
    cache = ChunkCache(64)
    state, published = _run(cache)
    return state, published, cache


def test_the_boundary_is_the_models_crossings_at_every_column(computed) -> None:
    """Column by column, the model's own answer for all three x at once (model.critical_gammas, branches="all")."""
    state, _, _ = computed
    assert state.status == jobs.DONE, state.error
    b = state.result
    ref = model.critical_gammas(f=X, beta=0.3, gamma_range=GAMMA_RANGE, branches="all", floor=FLOOR,
                                max_crossings=sb.MAX_CROSSINGS)
    np.testing.assert_array_equal(b["reason"], ref.reason)
    np.testing.assert_array_equal(b["direction"], ref.direction)
    np.testing.assert_allclose(b["value"], ref.value, rtol=1e-12, equal_nan=True)
    assert b["done"].all() and np.array_equal(b["x"], X) and b["cached"] == 0
    certified = np.isin(b["reason"], model.CERTIFIED_CROSSINGS) & np.isfinite(b["value"])
    assert certified[1:].any(axis=1).all()  # f = 0.6 and 0.9 have a threshold of sliding in (0.1, 30)
    assert "certified threshold(s) at 3 of 3 x values" in sb.summary(b)


def test_the_columns_done_are_published_before_the_end(computed) -> None:
    _, published, _ = computed
    assert published, "no partial boundary was published"
    first = published[0]
    assert first["done"].sum() == sb.COLUMNS_PER_CHUNK < X.size
    assert np.isnan(first["value"][~first["done"]]).all()
    assert "at 2 of 3 x values" in sb.summary(first)


def test_a_boundary_computed_before_comes_from_the_cache(computed, monkeypatch: pytest.MonkeyPatch) -> None:
    _, _, cache = computed
    calls: list[tuple] = []
    monkeypatch.setattr(sliding_work, "sliding_gamma_crossings", lambda *a: calls.append(a))
    state, _ = _run(cache)
    assert state.status == jobs.DONE and not calls and state.result["cached"] == X.size
    np.testing.assert_array_equal(state.result["reason"], computed[0].result["reason"])


def test_a_cancelled_boundary_stops_after_its_chunk() -> None:
    job = jobs.Job(partial(sb.compute_boundary, KEY, X, "f", GAMMA_RANGE, ChunkCache(8).get, ChunkCache(8).put),
                   name="boundary", key=KEY, totals={"columns": X.size})
    job.cancel()
    assert job.start().wait(60).status == jobs.CANCELLED
