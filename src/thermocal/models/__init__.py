"""Temperature-compensation model families (SPEC §4) behind one contract.

Importing this package registers every family in
:data:`thermocal.models.base.MODEL_REGISTRY`: ``poly`` (SPEC §4a),
``piecewise`` (§4b), ``warmup`` (§4c) and ``bank`` (§4d).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from thermocal.models.base import (
    MODEL_REGISTRY,
    Coefficient,
    FitStats,
    ModelStream,
    RunData,
    TemperatureModel,
    get_model_class,
    make_model,
    register,
)

if TYPE_CHECKING:
    from thermocal.models.files import load_model, load_model_dict, save_model

FILE_FUNCTIONS = ("load_model", "load_model_dict", "save_model")
"""Read and write model files: :mod:`thermocal.models.files`, imported on first use (the
maths of the models does not load the file layer)."""


def __getattr__(name: str) -> Any:
    if name in FILE_FUNCTIONS:
        from thermocal.models import files

        return getattr(files, name)
    raise AttributeError(f"module 'thermocal.models' has no attribute {name!r}")


FAMILY_MODULES = ("poly", "piecewise", "warmup", "bank")

for _mod in FAMILY_MODULES:
    try:
        importlib.import_module(f"thermocal.models.{_mod}")
    except ModuleNotFoundError as _exc:
        if _exc.name != f"thermocal.models.{_mod}":
            raise

__all__ = [
    "MODEL_REGISTRY",
    "Coefficient",
    "FitStats",
    "ModelStream",
    "RunData",
    "TemperatureModel",
    "get_model_class",
    "load_model",
    "load_model_dict",
    "make_model",
    "register",
    "save_model",
]
