"""Model-file validation: a schema per family, checked on load before any use.

A model file is the coefficients a user loads into firmware, so a file that is
malformed, hand-edited inconsistently or truncated must be refused with the path of the
bad field (``state.coef[2]: expected a finite number, got 'a'``), never turned into a
``KeyError``, a silent NaN or a shape mismatch deep in a kernel.

The checks are structural (types, shapes, finite values, known units, ordered ranges);
the checksum (:func:`thermocal.models.format.checksum`) separately proves the file is the
one thermocal wrote.  Unknown extra keys are allowed (newer writers may add fields).
Each family's ``state`` layout is documented in its module, which checks it
(``check_state``, made of :mod:`thermocal.models.checks`); this module checks the common
sections and calls the family's.
"""

from __future__ import annotations

from typing import Any

from thermocal import units
from thermocal.errors import ModelFileError
from thermocal.models.checks import (
    Check,
    boolean,
    failure,
    fields,
    integer,
    interval,
    key_path,
    list_of,
    near_range,
    number,
    range_margin,
    string,
)
from thermocal.models.format import check_model_header, checksum
from thermocal.models.poly import MAX_TERM_POWER
from thermocal.models.registry import get_model_class


def _annotation_checks(annotation: Any) -> list[Check] | None:
    """The checks one of which a constructor argument's value must pass, from its type
    annotation (``"int | None"``...); None when the annotation is not understood (then
    anything JSON holds is left to the family)."""
    simple: dict[str, Check] = {
        "int": integer,
        "float": number,
        "bool": boolean,
        "str": string,
        "list[float]": list_of(number),
        "list[str]": list_of(string),
        "list[int]": list_of(integer),
    }
    out: list[Check] = []
    for part in str(annotation).replace(" ", "").split("|"):
        if part == "None":
            out.append(_null)
        elif part in simple:
            out.append(simple[part])
        else:
            return None
    return out or None


def _null(value: Any, path: str) -> None:
    if value is not None:
        raise failure(path, "null", value)


def check_params(params: dict[str, Any], family_class: type, path: str) -> None:
    """Each constructor argument in ``params`` of the type its annotation states (an
    integer where the family takes ``int``, a finite number for ``float``...); an argument
    the family does not take is refused by name.

    Parameters
    ----------
    params : dict
        The ``params`` section.
    family_class : type
        The family's class.
    path : str
        Key path of the section.

    Raises
    ------
    thermocal.errors.ModelFileError
        A value of the wrong type, or an argument the family does not take.
    """
    import inspect

    sig = inspect.signature(family_class.__init__)  # type: ignore[misc]
    for key, value in params.items():
        at = key_path(path, key)
        p = sig.parameters.get(key)
        if p is None or key == "self":
            raise ModelFileError(
                f"{at}: the {getattr(family_class, 'family', '?')} family takes no such parameter"
            )
        checks = _annotation_checks(p.annotation)
        if checks is None:
            continue
        for check in checks:
            try:
                check(value, at)
                break
            except ModelFileError:
                continue
        else:
            raise failure(at, f"{p.annotation} (the family's parameter type)", value)


def _string_map(value: Any, path: str) -> None:
    """An object of string values (or nulls)."""
    _map_of(string, value, path)


def _conversion(value: Any, path: str) -> None:
    """``[gain, offset]`` or ``[gain, offset, "int16"]``."""
    if not isinstance(value, list) or len(value) not in (2, 3):
        raise failure(path, '[gain, offset] or [gain, offset, "int16"]', value)
    number(value[0], f"{path}[0]")
    number(value[1], f"{path}[1]")
    if len(value) == 3:
        string(value[2], f"{path}[2]")


def _positive(value: Any, path: str) -> None:
    number(value, path)
    if not value > 0:
        raise failure(path, "a positive number", value)


INPUTS = fields(
    {},
    optional={
        "time_unit": string,
        "units": _string_map,
        "unit_sources": _string_map,
        "temperature_conversion": lambda v, p: _map_of(_conversion, v, p),
        "temperature_unit": string,
        "sample_interval_s": _positive,
        "known_input": fields({}, optional={"value": number, "unit": string, "what": string}),
        "temperature_rate": fields({}, optional={"interval_s": _positive, "method": string}),
        "scale_factor": fields({}),
        "sensor_id": lambda v, p: None if isinstance(v, str | int) else _fail_now(v, p),
    },
)
"""The ``inputs`` section (base.py docstring): what compensate, validate, report and
export-c read of it, each of its type."""

FIT = fields(
    {},
    optional={
        "n_samples": integer,
        "n_coefficients": integer,
        "rms_residual": number,
        "condition_number": number,
        "r_squared": number,
        "dof": number,
    },
)
"""The ``fit`` statistics the model object and the reports read (nulls allowed)."""


def _map_of(item: Check, value: Any, path: str) -> None:
    """An object whose non-null values pass ``item``."""
    fields({})(value, path)
    for k, v in value.items():
        if v is not None:
            item(v, key_path(path, k))


def _fail_now(value: Any, path: str) -> None:
    raise failure(path, "a string or an integer", value)


def check_model_dict(d: dict[str, Any], root: str = "") -> None:
    """Validate a model file's content; raise :class:`ModelFileError` naming the key path
    (``state.coef[2]``; ``root`` prefixes it, e.g. ``channels[0].model`` in a calibration).

    Checks the common sections (signal, temperatures, range, params against the family's
    constructor types, fit, inputs), and the family's own checks of its ``state``
    (:meth:`~thermocal.models.base.TemperatureModel.check_state`: a poly model's centres
    lie in or near the fitted range, :func:`near_range`).
    Units are checked against thermocal's glossary.

    Parameters
    ----------
    d : dict
        The model file's content.
    root : str, optional
        Key path prefix.  Default ``""``.

    Raises
    ------
    thermocal.errors.ModelFileError
        A section missing or of the wrong type or shape, naming the key path.
    """
    fields(
        {
            "family": string,
            "signal": fields({"name": string, "unit": string}, optional={"target": string}),
            "temperatures": list_of(string, min_len=1),
            "params": fields({}),
            "state": fields({}),
            "range": fields({"temperature_c": fields({})}),
            "fit": FIT,
        },
        optional={
            "inputs": INPUTS,
            "rate": fields({}, optional={"method": string, "interval_s": _positive}),
            "data": list_of(fields({})),
            "temperature_unit": string,
        },
    )(d, root)
    try:
        units.normalize_signal_unit(d["signal"]["unit"])
    except Exception as exc:
        raise ModelFileError(f"{key_path(root, 'signal.unit')}: {exc}") from None
    target = d["signal"].get("target")
    if target is not None and target not in ("bias", "scale_factor"):
        raise failure(key_path(root, "signal.target"), "bias or scale_factor", target)
    temps: list[str] = d["temperatures"]
    if len(set(temps)) != len(temps):
        raise ModelFileError(f"{key_path(root, 'temperatures')}: names repeat: {temps}")
    ranges = d["range"]["temperature_c"]
    for name in temps:
        if name not in ranges:
            raise ModelFileError(f"{key_path(root, 'range.temperature_c')}: no range for {name!r}")
        interval(ranges[name], key_path(root, f"range.temperature_c.{name}"))
    rates = d["range"].get("rate_c_per_min")
    if rates is not None:
        fields({name: interval for name in temps})(rates, key_path(root, "range.rate_c_per_min"))
    klass = get_model_class(d["family"])  # an unknown family is refused, naming it
    check_params(d["params"], klass, key_path(root, "params"))
    klass.check_state(d, root)


def verify_model_dict(d: Any, where: str, root: str = "") -> dict[str, Any]:
    """Check a parsed model dict: header (format, version, sections), checksum and the
    family's schema (:func:`check_model_dict`); errors name ``where`` (the file) and the key
    path, prefixed by ``root`` (``channels[0].model`` in a calibration).

    The checksum guards against accidents (truncation, a hand edit, a bit flip), not
    against tampering: anyone can recompute it, so the content is checked as well.

    Parameters
    ----------
    d : object
        The parsed JSON document.
    where : str
        The file's name, for messages.
    root : str, optional
        Key path prefix.  Default ``""``.

    Returns
    -------
    dict
        ``d``, verified.

    Raises
    ------
    thermocal.errors.ModelFileError
        Wrong header, a checksum mismatch, or a schema error.
    """
    at = f"{where}: {root}" if root else where
    try:
        check_model_header(d)
    except ModelFileError as exc:
        raise ModelFileError(f"{at}: {exc}") from None
    stored = d.get("checksum")
    if stored is None:
        raise ModelFileError(f"{at}: model file has no checksum")
    if stored != checksum(d):
        raise ModelFileError(
            f"{at}: checksum mismatch: the model file was corrupted or edited by hand"
        )
    try:
        check_model_dict(d, root)
    except ModelFileError as exc:
        raise ModelFileError(f"{where}: {exc}") from None
    out: dict[str, Any] = d
    return out


__all__ = [
    "MAX_TERM_POWER",
    "check_model_dict",
    "check_params",
    "near_range",
    "range_margin",
    "verify_model_dict",
]
