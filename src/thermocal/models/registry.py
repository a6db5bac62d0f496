"""The one registry of model families (STYLE rule 8), keyed by name.

Each family is a :class:`~thermocal.models.base.TemperatureModel` subclass that declares,
next to its maths, everything the rest of thermocal asks of it: its name (``family``), its
``thermocal fit`` options (its constructor parameters, or ``CLI_KEYS``: read by
:meth:`~thermocal.models.base.TemperatureModel.from_cli_options`) and the module of
:mod:`thermocal.export.c` that writes its C code (``C_GENERATOR``).  This module lists the
classes once, under the names of :data:`thermocal.defaults.MODEL_FAMILIES` (the names
``--help`` shows without loading numpy); every other list of families is derived from
:data:`MODEL_REGISTRY`: the option parser, model files (:func:`model_from_dict`, the schema
of :mod:`thermocal.models.schema`), the C export and the tests.

Layering: :mod:`~thermocal.models.base` (the contract) ← the families ← this registry ←
:mod:`~thermocal.models.schema` (checks a model file against its family) ← the model files.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, TypeVar

from thermocal.defaults import MODEL_FAMILIES
from thermocal.errors import ModelFileError
from thermocal.models.bank import BankModel
from thermocal.models.base import TemperatureModel, check_model_header
from thermocal.models.piecewise import PiecewiseModel
from thermocal.models.poly import PolyModel
from thermocal.models.warmup import WarmupModel


def _registry(classes: tuple[type[TemperatureModel], ...]) -> dict[str, type[TemperatureModel]]:
    """``{name: class}`` in the order of :data:`MODEL_FAMILIES`; a class whose name is not
    there, or a name without its class, stops the import (the two cannot drift apart)."""
    by_name = {cls.family: cls for cls in classes}
    if set(by_name) != set(MODEL_FAMILIES) or len(by_name) != len(classes):
        raise ImportError(
            f"model families {sorted(by_name)} differ from defaults.MODEL_FAMILIES "
            f"{sorted(MODEL_FAMILIES)}"
        )
    return {name: by_name[name] for name in MODEL_FAMILIES}


MODEL_REGISTRY: dict[str, type[TemperatureModel]] = _registry(
    (PolyModel, PiecewiseModel, WarmupModel, BankModel)
)
"""Model families by name: ``poly`` (SPEC §4a), ``piecewise`` (§4b), ``warmup`` (§4c) and
``bank`` (§4d).  A family added from outside registers with :func:`register`."""

M = TypeVar("M", bound=type[TemperatureModel])


@dataclass(frozen=True)
class Family:
    """What the registry knows of one family, as the class declares it.

    ``options``: ``thermocal fit`` option key → constructor parameter (the one parser,
    :meth:`~thermocal.models.base.TemperatureModel.from_cli_options`); ``c_generator``: the
    module of :mod:`thermocal.export.c` whose ``generate(ctx)`` writes its C code (None: no
    C export)."""

    name: str
    model_class: type[TemperatureModel]
    options: Mapping[str, str]
    c_generator: str | None


def register(cls: M) -> M:
    """Class decorator: add a family to :data:`MODEL_REGISTRY` under ``cls.family``."""
    if not cls.family:
        raise TypeError(f"{cls.__name__} has no family name")
    MODEL_REGISTRY[cls.family] = cls
    return cls


def get_model_class(family: str) -> type[TemperatureModel]:
    """The class of a registered family, or :class:`ModelFileError` naming the known ones."""
    try:
        return MODEL_REGISTRY[family]
    except KeyError:
        raise ModelFileError(
            f"unknown model family {family!r}; known: {', '.join(sorted(MODEL_REGISTRY))}"
        ) from None


def family(name: str) -> Family:
    """The registry's record of one family (:class:`ModelFileError` when unknown)."""
    cls = get_model_class(name)
    return Family(name, cls, cls.cli_keys(), cls.C_GENERATOR)


def families() -> tuple[Family, ...]:
    """Every registered family, in registry order."""
    return tuple(family(name) for name in MODEL_REGISTRY)


def make_model(family: str, **params: Any) -> TemperatureModel:
    """Instantiate a registered family with parameters."""
    return get_model_class(family)(**params)


def model_from_dict(d: dict[str, Any]) -> TemperatureModel:
    """Rebuild a fitted model of any registered family from its
    :meth:`~thermocal.models.base.TemperatureModel.to_dict` output (checks the format, then
    looks the family up: an unknown one is refused, naming the known ones)."""
    check_model_header(d)
    return get_model_class(str(d["family"])).from_dict(d)


__all__ = [
    "MODEL_REGISTRY",
    "Family",
    "families",
    "family",
    "get_model_class",
    "make_model",
    "model_from_dict",
    "register",
]
