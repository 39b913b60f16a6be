"""Exports of a scene's data: CSV text and the download button that gives it."""

from __future__ import annotations

import io
from collections.abc import Callable, Mapping

import numpy as np
import panel as pn


def csv_table(header: str, columns: Mapping[str, np.ndarray]) -> io.StringIO:
    """Columns of equal length as CSV with full float precision; `header` becomes a '#' comment line."""
    out = io.StringIO()
    data = np.column_stack([np.asarray(c, dtype=float) for c in columns.values()])
    np.savetxt(out, data, delimiter=",", fmt="%.17g", comments="",
               header="# " + header.replace("\n", " ") + "\n" + ",".join(columns))
    out.seek(0)
    return out


def csv_download(callback: Callable[[], io.StringIO], filename: str, label: str) -> pn.widgets.FileDownload:
    """A button that downloads what `callback` returns (computed on click, from the cached data)."""
    return pn.widgets.FileDownload(callback=callback, filename=filename, label=label, color="primary",
                                   width=200)
