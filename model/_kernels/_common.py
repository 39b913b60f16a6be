"""The kernels' one decorator, :func:`jitted`, and the on-disk cache that follows every kernel module.

numba keeps a compiled function on disk (``cache=True``) with a stamp of the function's own source file and checks
only that stamp when it loads the function again. A kernel compiles every kernel it calls *into* its own machine code
(``inline="always"`` at numba's IR level, the others by LLVM), so with numba's own stamp a caller whose file did not
change keeps running the old code of a callee in another module that did. :class:`KernelCache` stamps every entry
with the file's stamp *and* :data:`SOURCES`, the sha256 of every module of this package: a change of any kernel
module invalidates the cache of every kernel (and of every function compiled with :func:`jitted` elsewhere, such as
model.modes). The package docstring describes the mechanism; tests/model/test_kernel_cache.py shows it on a copy.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from numba import njit
from numba.core.caching import FunctionCache, IndexDataCacheFile

#: the compile options of every kernel (:func:`jitted` takes overrides, e.g. inline="always" for the small ones):
#: on-disk cache, and the GIL released (map chunks run on threads); no fastmath: results are bit-reproducible
OPTIONS: dict[str, Any] = {"cache": True, "nogil": True}


def sources_fingerprint(folder: Path = Path(__file__).parent) -> str:
    """sha256 of the names and contents of every module (``*.py``) in `folder`, in name order ("unknown" if a
    module cannot be read, e.g. from a zip: then numba's own stamp alone decides)."""
    h = hashlib.sha256()
    try:
        for path in sorted(folder.glob("*.py")):
            h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    except OSError:
        return "unknown"
    return h.hexdigest()


#: the fingerprint of the kernel package's sources, computed once at import
SOURCES = sources_fingerprint()


class KernelCache(FunctionCache):
    """numba's per-function cache with :data:`SOURCES` in the stamp of its index: an index written with other kernel
    sources is stale (numba then compiles again and overwrites it, as after a change of the function's own file).

    The files are named after the package the module was imported from as well (numba names them after the file
    alone): a kernel cached as ``model._kernels.growth`` (the source folder imported by its own name, as
    ../shared/check_contract.py does) and as ``asymslide.model._kernels.growth`` are two entries, so that neither
    loads the other's machine code, whose references name the other's modules (loading it would import the model a
    second time under the other name)."""

    def __init__(self, py_func: Callable) -> None:
        super().__init__(py_func)
        stamp = (self._impl.locator.get_source_stamp(), SOURCES)
        package = py_func.__module__.rpartition(".")[0]
        self._cache_file = IndexDataCacheFile(cache_path=self._cache_path,
                                              filename_base=f"{package}-{self._impl.filename_base}",
                                              source_stamp=stamp)


def jitted(fn: Callable | None = None, /, **overrides: Any) -> Any:
    """``numba.njit`` with :data:`OPTIONS` (updated by `overrides`) and, with cache=True, a :class:`KernelCache`.

    Use as ``@jitted`` or ``@jitted(inline="always")``.
    """
    options = {**OPTIONS, **overrides}
    cache = options.pop("cache")

    def compile_later(f: Callable) -> Any:
        dispatcher = njit(**options)(f)
        if cache:
            dispatcher._cache = KernelCache(f)  # what Dispatcher.enable_caching does, with this cache class
        return dispatcher

    return compile_later if fn is None else compile_later(fn)
