"""Scene "Stability map" (paper Sect. IV, Figs. 4c and 5): where steady sliding is unstable in a parameter plane.

The map is the maximal growth rate max_kH Im[c/c_s] on the Rayleigh branch (:func:`model.growth_analysis`, the
function behind :func:`model.max_growth`) over a plane of two parameters (η-γ, Δ-ξ, f-γ or β-γ), the other four
taken from the sliders shared with the other scenes. It shows the neutral curve (zero contour of the growth) and a
marker at the sliders' values; clicking the map moves the two sliders there. The second plot is Fig. 4c: the exact
threshold χ_c(β) = γ_c f (:func:`model.critical_chi`) and the approximate criterion (:func:`model.criterion_chi`).

The app computes no physics: every number comes from a ``pn.cache``'d call into the public :mod:`model` API.

Computation on demand. The map is computed only when its plot is rendered (dynamic tabs render the visible scene only,
and building the page computes nothing), as a background job (:mod:`app.jobs`), in chunks of rows; each chunk is a
pure cached call (:func:`~.compute.compute_chunk`), so a map seen before, or the unchanged part of one, comes back
from the cache. A labelled progress bar advances per chunk. When the map's inputs change, the running job is cancelled
(it stops after its current chunk and is never shown) and the new one starts.

What the map depends on: its plane, resolution, and the four parameters off the plane (ξ normalised to 0 at Δ = 1,
where it does not enter F). Moving a parameter of the plane moves only the marker.

While a slider is held (:attr:`SpectrumParams.dragging`) the map waits for the release. If the held value is off the
plane, a coarse preview of the held inputs is drawn in place of the map meanwhile (:func:`~.preview.compute_preview`,
its own job: each move cancels the previous one, and a new one starts only once the previous one has stopped, so the
latest value wins and no work piles up): the Rayleigh branch's growth at :data:`~.preview.PREVIEW_POINTS` per axis
(the map's cached chunks; its neutral curve the grid's contour, dashed grey, not certified), and coloured by the
sliding verdict the verdict at :data:`~.preview.PREVIEW_SLIDING_POINTS` per axis, published chunk by chunk. Its title,
hover, progress label and readout say so; the CSV never holds it. It is dropped once the full map (or the sliding
map's first pass) of the released inputs is shown.

Its modules, from the bottom up (each imports only those above it in this list):

- :mod:`~asymslide.app.stability_map.grids` -- the kH grid, the resolutions, the planes and their axes, the chunks of
  rows, a map's key;
- :mod:`~asymslide.app.stability_map.compute` -- the cached model calls (the chunks, shared by the sessions) and the
  computed map (its refinement at the neutral curve, its certified thresholds γ_c);
- :mod:`~asymslide.app.stability_map.fig4c` -- Fig. 4c: its thresholds, its sliding threshold's job, its plot,
  readout and CSV;
- :mod:`~asymslide.app.stability_map.preview` -- the preview of a held slider's inputs and its job;
- :mod:`~asymslide.app.stability_map.map_jobs` -- the scene's jobs: started, their progress and results shown;
- :mod:`~asymslide.app.stability_map.held` -- the scene while a slider is held: the held key, the preview drawn;
- :mod:`~asymslide.app.stability_map.map_plot` -- the map's HoloViews layers and hooks;
- :mod:`~asymslide.app.stability_map.readout` -- the readout and legend in words;
- :mod:`~asymslide.app.stability_map.downloads` -- the map's and the sliding boundary's CSVs;
- :mod:`~asymslide.app.stability_map.scene` -- :class:`~asymslide.app.stability_map.scene.StabilityMapScene`, the
  state and the page.

Import from the modules themselves; this package re-exports nothing.
"""
