"""The Atlas tab: a stored stability atlas (``asymslide sweep``) explored slice by slice, and its 3-D neutral
surface. Its modules, from the bottom up (each imports only those above it in this list):

- :mod:`~asymslide.app.atlas.directory` -- the atlas directory's names, the default atlas (computed once per machine
  in the background) and opening an atlas;
- :mod:`~asymslide.app.atlas.readout` -- a whole atlas in words, and the short texts of the verdict and crossing codes;
- :mod:`~asymslide.app.atlas.request` -- what a URL asks the tab to show, fitted to the atlas once it is open;
- :mod:`~asymslide.app.atlas.slicing` -- the current 2-D slice, read from the stored cube (values, boundary in γ,
  the cell under a click, its readout and CSV);
- :mod:`~asymslide.app.atlas.heatmap` -- the Bokeh heat map a slice change updates in place;
- :mod:`~asymslide.app.atlas.surface_view` -- the Plotly 3-D view of the neutral surface (its geometry:
  :mod:`asymslide.atlas.surface`);
- :mod:`~asymslide.app.atlas.widgets` -- the selects, the sliders of the other axes and the default atlas's progress;
- :mod:`~asymslide.app.atlas.scene` -- :class:`~asymslide.app.atlas.scene.AtlasScene`, the state and the page.

Import from the modules themselves; this package re-exports nothing.
"""
