"""Temperature-compensation model families (SPEC §4) behind one contract.

The families are listed once, in :data:`thermocal.models.registry.MODEL_REGISTRY`:
``poly`` (SPEC §4a), ``piecewise`` (§4b), ``warmup`` (§4c) and ``bank`` (§4d).
"""

from __future__ import annotations

from thermocal.models.base import ModelStream, TemperatureModel
from thermocal.models.registry import (
    MODEL_REGISTRY,
    get_model_class,
    make_model,
    model_from_dict,
    register,
)
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData

__all__ = [
    "MODEL_REGISTRY",
    "Coefficient",
    "FitStats",
    "ModelStream",
    "RunData",
    "TemperatureModel",
    "get_model_class",
    "make_model",
    "model_from_dict",
    "register",
]
