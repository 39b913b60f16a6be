"""The app's scenes in a Jupyter notebook (app/notebook.py; docs/examples/jupyter.md), executed headless.

A notebook built with nbformat -- ``pn.extension`` with the scenes' extensions, one cell per tab of
:data:`~asymslide.app.tabs.TABS_REGISTRY` and one for the whole page -- runs in a Jupyter kernel of this interpreter
(the project's .venv python, through a kernelspec written for the test) under nbclient. Every scene cell must display
a Panel output whose Bokeh document holds the scene's models: its figures (one per plot the scene lays out), their
glyphs and data, its widgets; the whole page's holds the six tabs.

Staying live is checked from both ends of the notebook's comm, since no browser renders the outputs: the test plays
the page's part of Panel's JavaScript -- it opens the comm of the displayed Spectrum scene and releases its γ slider
at 2 (the Bokeh patch the browser sends) -- then checks in the kernel that the growth-rate plot's data source now
holds the Rayleigh branch at γ = 2 (the public model API's values), that the kernel sent that source's new data
back over the comm, and that the scene's background job (sliding over every branch) reaches the plot and is sent
too, on the kernel's event loop between the user's actions.

The notebook takes ~15 s (marked slow); nbclient, nbformat and ipykernel come with the docs extra (``make venv``).
The quick tests before it check the helper itself: its keys, its query, its sessions.
"""

from __future__ import annotations

import json
import math
import re
import sys
import time
import uuid
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import nbformat
import pytest
from jupyter_client.kernelspec import KernelSpecManager
from jupyter_client.manager import KernelManager
from nbclient import NotebookClient

from asymslide.app import notebook
from asymslide.app.notebook import EXTENSIONS
from asymslide.app.params import SpectrumParams, ThinOnThickParams
from asymslide.app.tabs import TABS_REGISTRY
from asymslide.app.urlstate import TABS

#: Panel's output of a displayed object: its mime type (the document's root id in its metadata)
EXEC_MIME = "application/vnd.holoviews_exec.v0+json"
#: the values each scene starts from: the map at its coarse resolution (it computes in the kernel meanwhile), the
#: Atlas on the test session's small atlas (without one it computes the default atlas first, ~25 s)
QUERIES = {"map": "map_res=coarse", "atlas": "atlas=small"}
#: the plots each scene lays out (its __panel__), one Bokeh figure each
FIGURES = {
    "spectrum": 3,  # growth rate, phase velocity, G_y criterion (SpectrumScene.plot_pane)
    "map": 2,  # the map and Fig. 4c
    "thin": 4,  # moduli, ν_eff, G_y, stress change (Fig. 3)
    "rupture": 4,  # slip-velocity profile, v_m, stress change, stress change against v_m
    "branches": 2,  # roots in the complex plane, their count
    "atlas": 1,  # the heat map (the 3-D view is in a tab built when shown)
}
#: other models a scene's output must hold
OTHERS = {
    "spectrum": {"panel.models.katex.KaTeX": 1},  # the dispersion relation
    "branches": {"panel.models.katex.KaTeX": 1},
    "atlas": {"Image": 1, "panel.models.tabs.Tabs": 1},  # the small atlas's slice as an image; heat map / 3-D
}
TIMEOUT = 300  # s, per cell


def _source(extensions: tuple[str, ...]) -> list[str]:
    """The notebook's cells: the extensions, then one cell per scene (kept in `scenes` for the later cells) and one
    for the whole page."""
    cells = [f"import panel as pn\npn.extension({', '.join(repr(e) for e in extensions)})",
             "from asymslide.app import notebook\nscenes = {}"]
    for tab in TABS_REGISTRY:
        cells.append(f"scenes[{tab.key!r}] = notebook.scene({tab.key!r}, {QUERIES.get(tab.key, '')!r})\n"
                     f"scenes[{tab.key!r}]")
    cells.append("notebook.app()")
    return cells


#: the kernel's checks of the Spectrum scene's growth-rate plot, before and after the γ slider's release: the data
#: source of its Rayleigh-branch curve holds Im[c/c_s] of the public model API at the scene's parameters (printed:
#: the source's id)
CHECK_PLOT = """
import numpy as np
from asymslide import model
from asymslide.app import live
from asymslide.app.spectrum import KH

spectrum = scenes["spectrum"]
(plot,) = live.rendered_plots(spectrum.panes[0])
(layer,) = [p for p in plot.subplots.values() if p.current_frame.label == "Rayleigh branch"]
source = layer.handles["source"]
want = model.rayleigh_branch(KH, **dict(zip(SpectrumParams.MODEL_ARGS, spectrum.params.model_args()))).z.imag
(column,) = [c for c in source.data if c != "kH"]
assert np.allclose(source.data["kH"], KH) and np.allclose(source.data[column], want, equal_nan=True)
print(json.dumps({"gamma": spectrum.params.gamma, "source": source.id}))
"""
#: the kernel waits (on its event loop, as between a user's actions) for the sliding job the release started, then
#: checks that the plot shows its result: the fastest root of every branch at each kH (printed: that layer's source)
CHECK_SLIDING = """
import asyncio
for _ in range(600):
    if spectrum.sliding is not None and spectrum.sliding["kH"].size:
        break
    await asyncio.sleep(0.1)
assert spectrum.sliding is not None, f"the sliding job never reached the scene ({spectrum.sliding_progress!r})"
await asyncio.sleep(0.5)  # the follower's update of the plot (app.jobs.UPDATE_INTERVAL)
(layer,) = [p for p in plot.subplots.values() if p.current_frame.label == "fastest root, every branch"]
source = layer.handles["source"]
assert np.allclose(source.data["kH"], spectrum.sliding["kH"])
assert np.allclose(source.data[column], spectrum.sliding["growth"], equal_nan=True)
print(json.dumps({"sliding": source.id, "points": len(source.data["kH"])}))
"""


def _docs_json(output: dict) -> dict:
    """The Bokeh document a Panel output embeds (the ``docs_json`` of its script)."""
    match = re.search(r"var docs_json = (.*?);\n\s*var render_items", output["data"]["text/html"], re.S)
    assert match, "a Panel output without its Bokeh document"
    return json.loads(match.group(1))


def _models(node: Any) -> Iterator[dict]:
    """Every model serialized in a Bokeh document's JSON (each once: later mentions are references by id)."""
    if isinstance(node, dict):
        if node.get("type") == "object" and "name" in node and "id" in node:
            yield node
        for value in node.values():
            yield from _models(value)
    elif isinstance(node, list):
        for value in node:
            yield from _models(value)


def _panel_output(cell: dict) -> dict:
    """The cell's Panel output (its value displayed), failing if it has none."""
    outputs = [o for o in cell["outputs"] if EXEC_MIME in o.get("data", {})]
    assert len(outputs) == 1, f"cell {cell['source']!r} displayed {len(outputs)} Panel outputs: {cell['outputs']}"
    return outputs[0]


def _printed(cell: dict) -> dict:
    """The JSON line a check cell printed."""
    text = "".join(o["text"] for o in cell["outputs"] if o["output_type"] == "stream" and o["name"] == "stdout")
    return json.loads(text.strip().splitlines()[-1])


def _errors(nb: nbformat.NotebookNode) -> list[str]:
    """The errors the notebook's cells raised, with their tracebacks (without the terminal's colours)."""
    return [f"cell {i} ({cell.source.strip().splitlines()[0]!r}): {o['ename']}: {o['evalue']}\n"
            + re.sub(r"\x1b\[[0-9;]*m", "", "\n".join(o["traceback"]))
            for i, cell in enumerate(nb.cells) for o in cell.get("outputs", []) if o["output_type"] == "error"]


class Client(NotebookClient):
    """nbclient's client, also keeping the comm messages the kernel sends while a cell runs (by cell)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.comm_messages: dict[int, list[dict]] = {}

    def handle_comm_msg(self, outs: list, msg: dict, cell_index: int) -> None:
        self.comm_messages.setdefault(cell_index, []).append(msg)
        super().handle_comm_msg(outs, msg, cell_index)


class Frontend:
    """What a notebook page's JavaScript does for a displayed Panel object, played on the kernel's channels: open its
    comm (Panel's comm manager opens the output's client comm, and the kernel then opens its own to send updates)
    and send a Bokeh patch of its widgets; the messages the kernel sends on iopub in reply are returned."""

    def __init__(self, client: NotebookClient) -> None:
        self.kc = client.kc

    def send(self, msg_type: str, content: dict) -> list[dict]:
        """Send a shell message; the kernel's iopub messages in reply to it, until it is idle again."""
        msg = self.kc.session.msg(msg_type, content)
        self.kc.shell_channel.send(msg)
        replies, deadline = [], time.monotonic() + TIMEOUT
        while time.monotonic() < deadline:
            reply = self.kc.get_iopub_msg(timeout=TIMEOUT)  # a blocking client (the kernel manager's)
            if reply["parent_header"].get("msg_id") != msg["header"]["msg_id"]:
                continue
            if reply["msg_type"] == "status" and reply["content"]["execution_state"] == "idle":
                return replies
            replies.append(reply)
        raise TimeoutError(f"the kernel did not answer the {msg_type}")

    def open(self, client_comm_id: str) -> list[dict]:
        return self.send("comm_open", {"comm_id": client_comm_id, "target_name": client_comm_id, "data": {}})

    def patch(self, client_comm_id: str, events: list[dict]) -> list[dict]:
        """A Bokeh PATCH-DOC message of `events`, as BokehJS sends a widget's change."""
        bokeh_msg = {"header": {"msgid": uuid.uuid4().hex, "msgtype": "PATCH-DOC"}, "metadata": {},
                     "content": {"events": events}}
        return self.send("comm_msg", {"comm_id": client_comm_id, "data": bokeh_msg})


def _patched(messages: list[dict]) -> set[str]:
    """The ids of the models whose changes the kernel sent in `messages` (its comm messages: a Bokeh message is sent as
    its header, metadata and content, each a JSON string, then its binary buffers)."""
    ids = set()
    for msg in messages:
        data = msg["content"].get("data")
        if msg["msg_type"] != "comm_msg" or not isinstance(data, str):
            continue
        try:
            part = json.loads(data)
        except json.JSONDecodeError:
            continue
        for event in part.get("events", []) if isinstance(part, dict) else []:
            model = event.get("model") or event.get("column_source")
            if isinstance(model, dict):
                ids.add(model.get("id"))
    return ids


@pytest.fixture
def kernel_manager(tmp_path: Path) -> Iterator[KernelManager]:
    """A kernel manager for a kernelspec that runs this interpreter (the project's .venv python, with ipykernel from
    the docs extra), not whichever ``python3`` kernel the machine has; its kernel is shut down afterwards."""
    spec = tmp_path / "kernels" / "asymslide-test"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "asymslide tests", "language": "python"}), encoding="utf-8")
    km = KernelManager(kernel_name="asymslide-test", kernel_spec_manager=KernelSpecManager(kernel_dirs=[
        str(spec.parent)]))
    try:
        yield km
    finally:
        if km.has_kernel:
            km.shutdown_kernel(now=False)


def test_every_tab_is_a_scene_and_an_unknown_key_is_refused() -> None:
    assert notebook.KEYS == TABS
    with pytest.raises(ValueError, match="'spectrum', 'map'"):
        notebook.scene("spectra")


def test_a_query_sets_the_values_as_the_pages_url_does_and_what_it_clamps_is_a_warning() -> None:
    session = notebook.Session("gamma=2&f=0.5&eta=inf&material=Homalite-100")
    assert (session.spectrum_params.gamma, session.spectrum_params.f) == (2.0, 0.5)
    assert math.isinf(session.spectrum_params.eta) and session.lab_params.material == "Homalite-100"
    with pytest.warns(UserWarning, match="kW = 1e\\+09 is outside") as warned:
        thin = notebook.scene("thin", "kW=1e9")
    assert thin.params.kW == pytest.approx(10 ** ThinOnThickParams.param.log10_kW.bounds[1])
    assert [w.filename for w in warned] == [__file__]  # the warning names the caller's line (a notebook's cell)


def test_the_scenes_of_one_session_share_its_parameters() -> None:
    session = notebook.Session()
    thin, rupture = notebook.scene("thin", session=session), notebook.scene("rupture", "rho=2000", session=session)
    assert thin.material is rupture.material is session.lab_params and thin.material.rho == 2000.0
    stability_map = notebook.scene("map", "map_res=coarse", session=session)
    assert stability_map.params is session.spectrum_params and stability_map.resolution == "coarse"


def _check_outputs(nb: nbformat.NotebookNode, cells: dict[str, int]) -> dict[str, list[dict]]:
    """Check the Panel output of each scene's cell (`cells`: by tab key, and "app") and return its Bokeh models: the
    scene's figures (with glyphs and data) and widgets; the page's six tabs and the figures of the tab it opens on."""
    documents = {}
    for key, index in cells.items():
        documents[key] = models = list(_models(_docs_json(_panel_output(nb.cells[index]))))
        names = Counter(m["name"] for m in models)
        figures = [m for m in models if m["name"] == "Figure"]
        assert all(f["attributes"]["renderers"] for f in figures), f"{key}: a figure without glyphs"
        assert names["ColumnDataSource"] >= len(figures)
        assert names["Slider"] + names["Spinner"] >= 1, f"{key}: no widgets in {dict(names)}"
        if key == "app":
            (tabs,) = [m for m in models if m["name"] == "panel.models.tabs.Tabs"]
            titles = [m["attributes"]["title"] for m in _models(tabs) if m["name"] == "TabPanel"]
            assert titles == [t.title for t in TABS_REGISTRY]
            assert len(figures) == FIGURES["spectrum"]  # the tab it opens on (the others are built when shown)
            continue
        assert len(figures) == FIGURES[key], f"{key}: {len(figures)} figures, expected {FIGURES[key]}"
        for name, count in OTHERS.get(key, {}).items():
            assert names[name] >= count, f"{key}: no {name} in {dict(names)}"
    return documents


def _run(client: Client, source: str) -> tuple[dict, list[dict]]:
    """Run one more cell: its printed JSON line and the comm messages the kernel sent while it ran."""
    cell = nbformat.v4.new_code_cell(source)
    client.nb.cells.append(cell)
    index = len(client.nb.cells) - 1
    client.execute_cell(cell, index)
    assert not _errors(client.nb), "\n\n".join(_errors(client.nb))
    return _printed(cell), client.comm_messages.get(index, [])


def test_the_whole_page_in_a_notebook_leaves_the_notebooks_address_alone(monkeypatch: pytest.MonkeyPatch) -> None:
    """In a notebook Panel's location is the notebook page's (the first output registers it): the page does not write
    its parameters into it, as it writes them into its own address when served."""
    import panel as pn
    from panel.io.location import Location

    location = Location()
    monkeypatch.setattr(pn.state, "_location", location)
    page = notebook.app("tab=thin")
    (tabs,) = [o for o in page.objects if isinstance(o, pn.Tabs)]
    assert tabs.active == TABS.index("thin")
    tabs.active = TABS.index("rupture")
    assert location.search == ""


@pytest.mark.slow
def test_every_scene_displays_inline_and_stays_live(kernel_manager: KernelManager, atlas_with_small: Path,
                                                    tmp_path: Path) -> None:
    # the kernel inherits this process's environment: ASYMSLIDE_ATLAS_DIR (the small atlas) is set by the fixture
    cells = _source(EXTENSIONS)
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in cells])
    client = Client(nb, km=kernel_manager, timeout=TIMEOUT, allow_errors=True,
                    resources={"metadata": {"path": str(tmp_path)}})
    with client.setup_kernel():
        for index, cell in enumerate(nb.cells):
            client.execute_cell(cell, index)
        assert not _errors(nb), "\n\n".join(_errors(nb))
        documents = _check_outputs(nb, {**{tab.key: 2 + i for i, tab in enumerate(TABS_REGISTRY)},
                                        "app": len(cells) - 1})
        spectrum = documents["spectrum"]
        sliders = {m["attributes"]["title"]: m for m in spectrum if m["name"] == "Slider"}
        assert set(sliders) == {SpectrumParams.symbol(name) for name in SpectrumParams.MODEL_ARGS}
        (manager,) = [m["attributes"] for m in spectrum if m["name"] == "panel.models.comm_manager.CommManager"]
        sources = {m["id"] for m in spectrum if m["name"] == "ColumnDataSource"}

        # stays live: the kernel's plot before the change ...
        before, _ = _run(client, "import json\nfrom asymslide.app.params import SpectrumParams\n" + CHECK_PLOT)
        assert before["gamma"] == SpectrumParams.param.gamma.default and before["source"] in sources

        # ... the page's comm opened and the γ slider released at 2 ...
        frontend = Frontend(client)
        opened = frontend.open(manager["client_comm_id"])
        assert [m["content"]["target_name"] for m in opened if m["msg_type"] == "comm_open"] == [
            manager["comm_id"]]  # the kernel's side of the comm, for its updates
        gamma = sliders[SpectrumParams.symbol("gamma")]["id"]
        sent = frontend.patch(manager["client_comm_id"], [
            {"kind": "ModelChanged", "model": {"id": gamma}, "attr": attr, "new": 2.0}
            for attr in ("value", "value_throttled")])
        assert not [m for m in sent if m["msg_type"] == "error"]

        # ... the kernel's plot shows γ = 2, and its new data went back to the page
        after, _ = _run(client, CHECK_PLOT)
        assert after == {"gamma": 2.0, "source": before["source"]}
        assert before["source"] in _patched(sent), "the new curve was not sent to the page"

        # the background job the release started (sliding over every branch) reaches the plot and the page
        sliding, messages = _run(client, CHECK_SLIDING)
        assert sliding["points"] > 0 and sliding["sliding"] in sources
        assert sliding["sliding"] in _patched(messages), "the sliding job's result was not sent to the page"
