"""app.live writes a held slider's data into the Bokeh models on the page: only what changed is sent."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from bokeh.document import Document
from bokeh.document.events import ColumnDataChangedEvent, ModelChangedEvent
from bokeh.models import ColumnDataSource

from asymslide.app import live


def _layer_on_a_page(data: dict) -> tuple[SimpleNamespace, list]:
    """A rendered layer (what live._write reads: its data source) in a document that records the events the page
    would be sent."""
    source = ColumnDataSource(data=data)
    doc = Document()
    doc.add_root(source)
    events: list = []
    doc.on_change(lambda event: events.append(event))
    return SimpleNamespace(handles={"source": source}), events


def test_only_the_columns_that_changed_are_sent() -> None:
    kH = np.logspace(-3, 3, 7)
    layer, events = _layer_on_a_page({"kH": kH, "Im": np.zeros(7)})
    im = np.linspace(-1, 1, 7)
    assert live._write(layer, (kH.copy(), im))
    assert [type(e) for e in events] == [ColumnDataChangedEvent] and events[0].cols == ["Im"]
    np.testing.assert_array_equal(layer.handles["source"].data["Im"], im)
    np.testing.assert_array_equal(layer.handles["source"].data["kH"], kH)


def test_data_the_page_already_shows_are_not_sent_again() -> None:
    kH, im = np.logspace(-3, 3, 7), np.array([np.nan, 1, 2, 3, 4, 5, np.nan])
    layer, events = _layer_on_a_page({"kH": kH, "Im": im})
    assert live._write(layer, (kH.copy(), im.copy()))  # NaN where NaN was: the same curve
    assert events == []


def test_a_new_length_replaces_every_column_at_once() -> None:
    layer, events = _layer_on_a_page({"start": np.array([1.0]), "end": np.array([2.0])})
    assert live._write(layer, (np.array([]), np.array([])))  # the band vanishes
    assert len(events) == 1 and isinstance(events[0], ColumnDataChangedEvent | ModelChangedEvent)
    assert getattr(events[0], "cols", None) in (None, ["start", "end"], ["end", "start"])  # both columns in one event
    assert {k: len(v) for k, v in layer.handles["source"].data.items()} == {"start": 0, "end": 0}


def test_the_follows_of_every_session_share_one_rate() -> None:
    """Follows asked for at once get consecutive slots of 1 / rate seconds (the tenth of ten sessions waits nine
    slots); once the slots are used up, the next follow runs at once."""
    budget = live.FollowBudget(per_second=20.0)
    waits = [budget.reserve() for _ in range(10)]
    assert waits[0] == 0.0
    np.testing.assert_allclose(np.diff(waits), 0.05, atol=0.01)
    budget._next = 0.0  # the slots all in the past: nothing waits
    assert budget.reserve() == 0.0


def test_unserved_a_follow_runs_at_once() -> None:
    ran: list[int] = []
    live.schedule_follow(lambda: ran.append(1))
    assert ran == [1]
