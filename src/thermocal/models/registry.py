"""The one registry of model families, keyed by name.

Each family is a :class:`~thermocal.models.base.TemperatureModel` subclass carrying its
:class:`~thermocal.families.FamilyDeclaration` as ``declaration``: its name, its fit
options with their bounds, what it needs of the data, its C generator and the firmware
formats its coefficients fill.  The built-in families are registered by their declarations
in :data:`thermocal.families.BUILTIN_FAMILIES` (the command line's help reads those without
numpy); a family from another package is the entry point ``NAME = "pkg.module:Class"`` of
group ``thermocal.families`` in its distribution's metadata, loaded when this module is
imported (a broken one: one warning, skipped).  Every list of families is derived from
:data:`MODEL_REGISTRY`: the option parser, model files (:func:`model_from_dict`), the
schema of :mod:`thermocal.models.schema`, the C export and the tests.

Layering: :mod:`~thermocal.models.base` (the contract) ← the families ← this registry ←
:mod:`~thermocal.models.schema` (checks a model file against its family) ← the model files.

Examples
--------
>>> from thermocal.models.registry import MODEL_REGISTRY, family
>>> list(MODEL_REGISTRY)[:4]
['poly', 'piecewise', 'warmup', 'bank']
>>> family("poly").declaration.firmware
('px4', 'ardupilot')
"""

from __future__ import annotations

import importlib
import importlib.metadata
import warnings
from dataclasses import dataclass
from typing import Any, TypeVar

from thermocal.errors import ModelFileError, ThermocalWarning
from thermocal.families import (
    BUILTIN_FAMILIES,
    ENTRY_POINT_GROUP,
    FamilyDeclaration,
)
from thermocal.models.base import TemperatureModel
from thermocal.models.format import check_model_header


def _load_class(path: str) -> Any:
    """The object at ``"module:Qualified.name"``."""
    module, _, name = path.partition(":")
    obj: Any = importlib.import_module(module)
    for part in name.split("."):
        obj = getattr(obj, part)
    return obj


def _registry(declarations: tuple[FamilyDeclaration, ...]) -> dict[str, type[TemperatureModel]]:
    """``{name: class}`` of the declared families, in their order; a class that does not
    carry its declaration stops the import (a declaration and its class cannot drift
    apart)."""
    out: dict[str, type[TemperatureModel]] = {}
    for decl in declarations:
        cls = _load_class(decl.model_class)
        if getattr(cls, "declaration", None) is not decl:
            raise ImportError(
                f"{decl.model_class} does not carry the declaration of family {decl.name!r}"
            )
        out[decl.name] = cls
    return out


def _check_plugin(name: str, cls: Any) -> type[TemperatureModel]:
    """A plugin's class, or TypeError saying what it lacks."""
    if not (isinstance(cls, type) and issubclass(cls, TemperatureModel)):
        raise TypeError("not a TemperatureModel subclass")
    decl = getattr(cls, "declaration", None)
    if not isinstance(decl, FamilyDeclaration):
        raise TypeError("no FamilyDeclaration as 'declaration'")
    if decl.name != name:
        raise TypeError(f"its declaration names it {decl.name!r}")
    if name in MODEL_REGISTRY:
        raise TypeError(f"a family {name!r} is already registered")
    return cls


def load_plugins(group: str = ENTRY_POINT_GROUP) -> list[str]:
    """Register the families of the entry points of ``group``; returns their names.

    A plugin that cannot be imported or is not a family is skipped with one
    :class:`~thermocal.errors.ThermocalWarning` naming it and why.

    Parameters
    ----------
    group : str, optional
        The entry-point group.  Default :data:`ENTRY_POINT_GROUP`.

    Returns
    -------
    list of str
        Names of the families registered.
    """
    added: list[str] = []
    for ep in importlib.metadata.entry_points(group=group):
        try:
            cls = _check_plugin(ep.name, ep.load())
        except Exception as exc:  # a broken plugin must not break thermocal
            warnings.warn(
                f"model family plugin {ep.name!r} ({ep.value}) skipped: "
                f"{type(exc).__name__}: {exc}",
                ThermocalWarning,
                stacklevel=2,
            )
            continue
        MODEL_REGISTRY[ep.name] = cls
        added.append(ep.name)
    return added


MODEL_REGISTRY: dict[str, type[TemperatureModel]] = _registry(BUILTIN_FAMILIES)
"""Model families by name: ``poly``, ``piecewise``, ``warmup`` and ``bank``, then the
plugins'."""
load_plugins()

M = TypeVar("M", bound=type[TemperatureModel])


@dataclass(frozen=True)
class Family:
    """What the registry knows of one family: its name, its class and the declaration the
    class carries (options, data needs, C generator, firmware).

    Attributes
    ----------
    name : str
        The family's name.
    model_class : type
        Its :class:`~thermocal.models.base.TemperatureModel` subclass.
    declaration : FamilyDeclaration
        What the class declares of itself.
    """

    name: str
    model_class: type[TemperatureModel]
    declaration: FamilyDeclaration

    @property
    def c_generator(self) -> str | None:
        """The module of :mod:`thermocal.export.c` writing its C code (None: no C export)."""
        return self.declaration.c_generator


def register(cls: M) -> M:
    """Class decorator: add a family to :data:`MODEL_REGISTRY` under its declared name
    (a family defined in a session; a package declares an entry point instead)."""
    decl = getattr(cls, "declaration", None)
    if not isinstance(decl, FamilyDeclaration):
        raise TypeError(f"{cls.__name__} carries no FamilyDeclaration as 'declaration'")
    MODEL_REGISTRY[decl.name] = cls
    return cls


def get_model_class(family: str) -> type[TemperatureModel]:
    """The class of a registered family, or :class:`ModelFileError` naming the known ones.

    Parameters
    ----------
    family : str
        The family's name.

    Returns
    -------
    type

    Raises
    ------
    thermocal.errors.ModelFileError
        An unknown family.

    Examples
    --------
    >>> get_model_class("poly").__name__
    'PolyModel'
    """
    try:
        return MODEL_REGISTRY[family]
    except KeyError:
        raise ModelFileError(
            f"unknown model family {family!r}; known: {', '.join(sorted(MODEL_REGISTRY))}"
        ) from None


def family(name: str) -> Family:
    """The registry's record of one family (:class:`ModelFileError` when unknown).

    Parameters
    ----------
    name : str
        The family's name.

    Returns
    -------
    Family

    Raises
    ------
    thermocal.errors.ModelFileError
        An unknown family.

    Examples
    --------
    >>> family("poly").c_generator
    'thermocal.export.c.poly'
    """
    cls = get_model_class(name)
    return Family(name, cls, cls.declaration)


def families() -> tuple[Family, ...]:
    """Every registered family, in registry order."""
    return tuple(family(name) for name in MODEL_REGISTRY)


def make_model(family: str, **params: Any) -> TemperatureModel:
    """Instantiate a registered family with parameters.

    Parameters
    ----------
    family : str
        The family's name.
    **params
        Constructor arguments.

    Returns
    -------
    TemperatureModel
        The unfitted model.

    Raises
    ------
    thermocal.errors.ModelFileError
        An unknown family.
    """
    return get_model_class(family)(**params)


def model_from_dict(d: dict[str, Any]) -> TemperatureModel:
    """Rebuild a fitted model of any registered family from its
    :meth:`~thermocal.models.base.TemperatureModel.to_dict` output (checks the format, then
    looks the family up: an unknown one is refused, naming the known ones).

    Parameters
    ----------
    d : dict
        A model file's content.

    Returns
    -------
    TemperatureModel
        The fitted model.

    Raises
    ------
    thermocal.errors.ModelFileError
        A bad header or an unknown family.
    """
    check_model_header(d)
    return get_model_class(str(d["family"])).from_dict(d)


__all__ = [
    "MODEL_REGISTRY",
    "Family",
    "families",
    "family",
    "get_model_class",
    "load_plugins",
    "make_model",
    "model_from_dict",
    "register",
]
