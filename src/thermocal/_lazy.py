"""A module imported on first attribute access (start-up, issue 17): heavy libraries a module
needs only inside some functions (scipy.stats for confidence intervals) stay out of the
import of the module itself."""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any


class LazyModule:
    """``LazyModule("scipy.stats").chi2`` imports :mod:`scipy.stats` on that first access."""

    def __init__(self, name: str) -> None:
        self._name = name
        self._module: ModuleType | None = None

    def __getattr__(self, attr: str) -> Any:
        # every attribute, dunders too (``pd.__version__``): a probe costs only the import
        if self._module is None:
            self._module = importlib.import_module(self._name)
        return getattr(self._module, attr)


__all__ = ["LazyModule"]
