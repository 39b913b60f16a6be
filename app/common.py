"""What several scenes share, defined once: the growth-map colours and labels, log-axis tick labels, and the neutral
curve of the Stability-map and Atlas heat maps. (How often a session shows a background computation's progress:
:data:`app.jobs.UPDATE_INTERVAL`; the phone breakpoint: :data:`app.layout.NARROW_PX`; the order of the model's
arguments: :attr:`app.params.SpectrumParams.MODEL_ARGS`.)
"""

from __future__ import annotations

import contourpy
import numpy as np
from bokeh.palettes import RdBu11

from asymslide import model

#: |max growth| at or below this is drawn as neutral: not counted unstable and not a neutral-curve crossing (where
#: the branch only tends to Im z = 0 at the end of the kH grid the maximum is 0 up to round-off)
MARGINAL = 1e-6

#: the heat maps' colour label
GROWTH_LABEL = "max Im[c/c_s]"

#: the Atlas heat map's diverging palette, lowest first (ColorBrewer RdBu: growth < 0 blue, ~0 white, > 0 red); the
#: Stability map draws the same colours continuously (HoloViews' "RdBu_r")
GROWTH_PALETTE = tuple(RdBu11)
GROWTH_CMAP = "RdBu_r"

#: where the growth is not computable (NaN): a dark grey, far in lightness from the palette's white centre (growth
#: ~ 0), so that "nearly neutral" and "not computable" never look alike
NAN_COLOR = "#636363"

#: the short name of each family of roots (model.FAMILIES), for legends and readouts
FAMILY_NAMES = {k: v.split(" (")[0] for k, v in model.FAMILIES.items()}

#: the heat maps' legend
COLOUR_LEGEND = ("Red: unstable (max growth > 0), blue: stable, white: nearly neutral; dark grey: not computable; "
                 "black line: neutral curve (max growth = 0). Rayleigh branch only: other branches can be unstable "
                 "where it is stable (sliding over every branch: the Spectrum and All-branches tabs, asymslide sweep "
                 "--sliding)")

#: tick labels of a linear axis whose coordinate is log10 of a value (the Atlas heat map's log axes): a power of ten
#: as 10ⁿ, as Bokeh's log axes write it (10⁻¹, 10⁰, 10³), a value between two to two significant digits, plain from
#: 0.01 to 10⁴ ("0.32", "3.2", "320") and with its power of ten outside ("3.2×10⁴"). The app's linear axes:
#: :data:`app.plotting.TICKS_JS`; its log10 sliders: :data:`app.widgets.LOG10_TICKS`.
LOG_COORDINATE_TICKS = """
const sup = n => String(n).replace(/./g, c => '⁻⁰¹²³⁴⁵⁶⁷⁸⁹'['-0123456789'.indexOf(c)]);
const n = Math.round(tick);
if (Math.abs(tick - n) < 1e-9) return '10' + sup(n);
const v = Math.pow(10, tick);
if (v >= 0.01 && v < 1e4) return String(Number(v.toPrecision(2)));
const e = Math.floor(tick + 1e-9);
return String(Number((v / Math.pow(10, e)).toPrecision(2))) + '×10' + sup(e);
"""


def neutral_lines(x: np.ndarray, y: np.ndarray, z: np.ndarray, *, log_x: bool = False,
                  log_y: bool = False) -> list[np.ndarray]:
    """The neutral curve: the line(s) z = 0 of z[y, x] (|z| <= MARGINAL counts as not unstable, NaN is masked),
    interpolated in the plotted coordinates: log10 of an axis drawn on a log scale (`log_x`, `log_y`), the values
    themselves otherwise. Each line is an (m, 2) array of (x, y) in the coordinates x and y were given in, clipped to
    the grid (contourpy puts a vertex on a cell edge at y0 + t dy, which can stick out by an ulp). A grid with fewer
    than two points along an axis, or without a finite value, has none."""
    if log_x or log_y:
        lines = neutral_lines(np.log10(x) if log_x else x, np.log10(y) if log_y else y, z)
        return [np.column_stack([10.0 ** s[:, 0] if log_x else s[:, 0], 10.0 ** s[:, 1] if log_y else s[:, 1]])
                for s in lines]
    z = np.asarray(z, dtype=float)
    if z.ndim != 2 or z.shape != (y.size, x.size) or x.size < 2 or y.size < 2:
        return []
    zz = np.where(np.abs(z) <= MARGINAL, -MARGINAL, z)
    if not np.isfinite(zz).any():
        return []
    gen = contourpy.contour_generator(x, y, np.ma.masked_invalid(zz), line_type="Separate")
    lo = [x.min(), y.min()]
    hi = [x.max(), y.max()]
    return [np.clip(s, lo, hi) for s in gen.lines(0.0) if len(s) > 1]
