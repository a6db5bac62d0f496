"""Temperature-compensation model families behind one contract.

The families are listed once, in :data:`thermocal.models.registry.MODEL_REGISTRY`:
``poly`` ([Seed-RLG]), ``piecewise`` ([Seed-FOG]), ``warmup`` ([Seed-Plan]) and ``bank``
([Seed-Accel]); the sources are listed in the References of the methods chapter
(``docs/methods.md``).  Each family declares its options, data needs and firmware support
(:mod:`thermocal.families`).
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
