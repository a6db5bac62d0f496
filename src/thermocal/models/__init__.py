"""Temperature-compensation model families (SPEC §4) behind one contract.

The families are listed once, in :data:`thermocal.models.registry.MODEL_REGISTRY`:
``poly`` (SPEC §4a), ``piecewise`` (§4b), ``warmup`` (§4c) and ``bank`` (§4d).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from thermocal.models.base import (
    Coefficient,
    FitStats,
    ModelStream,
    RunData,
    TemperatureModel,
)
from thermocal.models.registry import (
    MODEL_REGISTRY,
    get_model_class,
    make_model,
    model_from_dict,
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
    "model_from_dict",
    "register",
    "save_model",
]
