"""A module imported on first attribute access (start-up time): heavy libraries a module
needs only inside some functions (scipy.stats for confidence intervals) stay out of the
import of the module itself."""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any


class LazyModule:
    """``LazyModule("scipy.stats").chi2`` imports :mod:`scipy.stats` on that first access.

    Parameters
    ----------
    name : str
        The module's dotted name (``"scipy.stats"``).

    Examples
    --------
    >>> json = LazyModule("json")
    >>> json.dumps([1, 2])
    '[1, 2]'
    """

    def __init__(self, name: str) -> None:
        self._name = name
        self._module: ModuleType | None = None

    def __getattr__(self, attr: str) -> Any:
        # every attribute, dunders too (``pd.__version__``): a probe costs only the import
        if self._module is None:
            self._module = importlib.import_module(self._name)
        return getattr(self._module, attr)


def prefetch(*names: str) -> None:
    """Import modules in a background thread while the caller reads its file.

    A command that will need, say, :mod:`scipy.special` after reading a large file starts
    its import first: the file reader and numpy release the GIL, so most of the import's
    0.1–0.2 s overlaps the read.  Python's per-module import locks make a later
    ``import`` of the same module in the main thread wait for this one, never run it twice.
    The thread is not a daemon: an interpreter exiting early waits for it (a daemon killed
    in the middle of an import can crash the interpreter's shutdown).

    Parameters
    ----------
    *names : str
        Dotted names of the modules to import, in that order; an import that fails stops
        the thread silently (the main thread meets the error again when it imports).
    """
    import threading

    def run() -> None:
        for name in names:
            try:
                importlib.import_module(name)
            except ImportError:  # the main thread will meet (and report) it again
                return

    threading.Thread(target=run, name="thermocal-prefetch").start()


__all__ = ["LazyModule", "prefetch"]
