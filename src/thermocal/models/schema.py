"""Model-file validation: a schema per family, checked on load before any use.

A model file is the coefficients a user loads into firmware, so a file that is
malformed, hand-edited inconsistently or truncated must be refused with the path of the
bad field (``state.coef[2]: expected a finite number, got 'a'``), never turned into a
``KeyError``, a silent NaN or a shape mismatch deep in a kernel.

The checks are structural (types, shapes, finite values, known units, ordered ranges);
the checksum (:func:`thermocal.models.base.checksum`) separately proves the file is the
one thermocal wrote.  Unknown extra keys are allowed (newer writers may add fields).
Each family's ``state`` layout is documented in its module; the schema here follows it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

from thermocal import units
from thermocal.errors import ModelFileError
from thermocal.models.base import check_model_header, checksum
from thermocal.models.registry import get_model_class

Check = Callable[[Any, str], None]


def _at(path: str, key: str) -> str:
    """The key path of ``key`` inside ``path`` (``state`` + ``coef`` → ``state.coef``)."""
    return f"{path}.{key}" if path else key


def _fail(path: str, what: str, got: Any) -> ModelFileError:
    path = path or "(top level)"
    text = repr(got)
    if len(text) > 60:
        text = text[:57] + "..."
    return ModelFileError(f"{path}: expected {what}, got {text}")


def number(value: Any, path: str) -> None:
    """A finite real number (not a bool, not NaN/inf/null)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise _fail(path, "a finite number", value)


def number_or_null(value: Any, path: str) -> None:
    if value is not None:
        number(value, path)


def integer(value: Any, path: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int):
        raise _fail(path, "an integer", value)


def string(value: Any, path: str) -> None:
    if not isinstance(value, str):
        raise _fail(path, "a string", value)


def boolean(value: Any, path: str) -> None:
    if not isinstance(value, bool):
        raise _fail(path, "true or false", value)


def list_of(item: Check, *, min_len: int = 0) -> Check:
    def check(value: Any, path: str) -> None:
        if not isinstance(value, list):
            raise _fail(path, "a list", value)
        if len(value) < min_len:
            raise _fail(path, f"a list of at least {min_len} items", value)
        for i, v in enumerate(value):
            item(v, f"{path}[{i}]")

    return check


def matrix(value: Any, path: str) -> None:
    """A rectangular list of lists of numbers or nulls (nulls: undefined covariances)."""
    list_of(list_of(number_or_null))(value, path)
    widths = {len(row) for row in value}
    if len(widths) > 1:
        raise _fail(path, "a rectangular matrix", f"rows of lengths {sorted(widths)}")


def fields(spec: dict[str, Check], *, optional: dict[str, Check] | None = None) -> Check:
    """A JSON object with the required keys of ``spec`` and optional keys of ``optional``."""

    def check(value: Any, path: str) -> None:
        if not isinstance(value, dict):
            raise _fail(path, "an object", value)
        for key, sub in spec.items():
            if key not in value:
                raise ModelFileError(f"{path or '(top level)'}: the field {key!r} is missing")
            sub(value[key], _at(path, key))
        for key, sub in (optional or {}).items():
            if key in value and value[key] is not None:
                sub(value[key], _at(path, key))

    return check


def interval(value: Any, path: str) -> None:
    """``[lo, hi]`` finite with lo ≤ hi."""
    list_of(number, min_len=2)(value, path)
    if len(value) != 2 or value[0] > value[1]:
        raise _fail(path, "[low, high] with low ≤ high", value)


def ascending(value: Any, path: str) -> None:
    list_of(number)(value, path)
    if any(b <= a for a, b in itertools.pairwise(value)):
        raise _fail(path, "strictly increasing numbers", value)


def _same_length(state: dict[str, Any], path: str, key: str, n: int, what: str) -> None:
    got = len(state[key])
    if got != n:
        raise ModelFileError(f"{path}.{key}: expected {n} values ({what}), got {got}")


# --- families ----------------------------------------------------------------------------

MAX_TERM_POWER = 32
"""Highest power of a poly term's base variable accepted in a file (a polynomial of
higher order in one temperature is no calibration; a power of 2⁵³ would make export-c
and compensate run for ever)."""

BASE_KEYS = (
    "t_center", "t_scale", "rate_center", "rate_scale", "coupling_center", "coupling_scale"
)  # fmt: skip
"""The poly family's centre and scale of each base variable (:class:`~thermocal.models.
terms.BaseScaling`), centres at even positions."""


def _poly_state(state: Any, path: str, n_temps: int) -> None:
    fields(
        {
            "layout": string,
            "base": list_of(fields({k: number for k in BASE_KEYS}), min_len=1),
            "terms": list_of(
                fields({"sensor": integer, "t_power": integer, "rate_power": integer,
                        "coupling_power": integer})
            ),
            "coef": list_of(number),
            "constant": number,
        },
        optional={"offsets": list_of(number), "cov": matrix, "uses_rate": boolean,
                  "n_sensors": integer},
    )(state, path)  # fmt: skip
    _same_length(state, path, "coef", len(state["terms"]), "one per term")
    for i, base in enumerate(state["base"]):
        for key in BASE_KEYS[1::2]:
            if base[key] == 0:
                raise ModelFileError(f"{path}.base[{i}].{key}: must not be 0")
    for i, term in enumerate(state["terms"]):
        for key in ("t_power", "rate_power", "coupling_power"):
            if not 0 <= term[key] <= MAX_TERM_POWER:
                raise ModelFileError(
                    f"{path}.terms[{i}].{key}: {term[key]} is not a power 0…{MAX_TERM_POWER}"
                )
        if not 0 <= term["sensor"] < len(state["base"]):
            raise ModelFileError(
                f"{path}.terms[{i}].sensor: {term['sensor']} is not one of the "
                f"{len(state['base'])} temperature inputs"
            )
    if len(state["base"]) > n_temps:
        raise ModelFileError(
            f"{path}.base: {len(state['base'])} temperature inputs but the file names {n_temps}"
        )


def _piecewise_state(state: Any, path: str, n_temps: int) -> None:
    fields(
        {"breakpoints": ascending, "intercepts": list_of(number), "slopes": list_of(number)},
        optional={"column_index": integer, "offsets": list_of(number), "line_cov": matrix},
    )(state, path)
    n_lines = len(state["breakpoints"]) + 1
    _same_length(state, path, "intercepts", n_lines, "one per segment")
    _same_length(state, path, "slopes", n_lines, "one per segment")
    col = state.get("column_index", 0)
    if not 0 <= col < n_temps:
        raise ModelFileError(f"{path}.column_index: {col} is not one of the {n_temps} inputs")


def _warmup_state(state: Any, path: str, n_temps: int) -> None:
    del n_temps
    fields(
        {"b": matrix, "order": integer, "t0_order": integer, "sensor_name": string,
         "t0_range_c": interval},
        optional={"b_stderr": matrix, "start_window_s": number, "duration_range_s": interval},
    )(state, path)  # fmt: skip
    rows, cols = len(state["b"]), len(state["b"][0]) if state["b"] else 0
    want = (state["order"] + 1, state["t0_order"] + 1)
    if (rows, cols) not in (want, (want[0] - 1, want[1])):
        raise ModelFileError(
            f"{path}.b: expected a {want[0]}×{want[1]} (or {want[0] - 1}×{want[1]}, without "
            f"the constant) matrix for order {state['order']} and t0_order "
            f"{state['t0_order']}, got {rows}×{cols}"
        )
    for i, row in enumerate(state["b"]):
        for j, v in enumerate(row):
            number(v, f"{path}.b[{i}][{j}]")


def _bank_state(state: Any, path: str, n_temps: int) -> None:
    del n_temps
    fields(
        {
            "sensor_name": string,
            "models": list_of(
                fields({"breakpoints_c": ascending, "values": list_of(number)}), min_len=1
            ),
        },
        optional={"startup_s": number, "deviation": number, "tolerance": number},
    )(state, path)
    for i, m in enumerate(state["models"]):
        if len(m["breakpoints_c"]) < 2:
            raise ModelFileError(f"{path}.models[{i}].breakpoints_c: needs at least 2 points")
        _same_length(m, f"{path}.models[{i}]", "values", len(m["breakpoints_c"]), "one per point")


STATE_SCHEMAS: dict[str, Callable[[Any, str, int], None]] = {
    "poly": _poly_state,
    "piecewise": _piecewise_state,
    "warmup": _warmup_state,
    "bank": _bank_state,
}
"""The ``state`` schema of each family, by family name (as in the model registry)."""


def near_range(value: float, lo: float, hi: float, path: str, what: str) -> None:
    """A reference temperature (TREF, a polynomial's centre) inside the calibrated range
    ``[lo, hi]`` or within :func:`range_margin` of it: polynomials in ``T − TREF`` are exact
    for any TREF in theory, but one far outside the range is a corrupted file, not a fit."""
    margin = range_margin(lo, hi)
    if not lo - margin <= value <= hi + margin:
        raise ModelFileError(
            f"{path}: {what} {value:g} is far outside the calibrated range [{lo:g}, {hi:g}] "
            f"(more than {margin:g} beyond it)"
        )


def range_margin(lo: float, hi: float) -> float:
    """How far beyond a calibrated range ``[lo, hi]`` a reference temperature may lie: the
    range's span, at least 50 (°C, or counts for a model fitted in counts)."""
    return max(hi - lo, 50.0)


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
        raise _fail(path, "null", value)


def check_params(params: dict[str, Any], family_class: type, path: str) -> None:
    """Each constructor argument in ``params`` of the type its annotation states (an
    integer where the family takes ``int``, a finite number for ``float``...); an argument
    the family does not take is refused by name."""
    import inspect

    sig = inspect.signature(family_class.__init__)  # type: ignore[misc]
    for key, value in params.items():
        at = _at(path, key)
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
            raise _fail(at, f"{p.annotation} (the family's parameter type)", value)


def _string_map(value: Any, path: str) -> None:
    """An object of string values (or nulls)."""
    _map_of(string, value, path)


def _conversion(value: Any, path: str) -> None:
    """``[gain, offset]`` or ``[gain, offset, "int16"]``."""
    if not isinstance(value, list) or len(value) not in (2, 3):
        raise _fail(path, '[gain, offset] or [gain, offset, "int16"]', value)
    number(value[0], f"{path}[0]")
    number(value[1], f"{path}[1]")
    if len(value) == 3:
        string(value[2], f"{path}[2]")


def _positive(value: Any, path: str) -> None:
    number(value, path)
    if not value > 0:
        raise _fail(path, "a positive number", value)


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
            item(v, _at(path, k))


def _fail_now(value: Any, path: str) -> None:
    raise _fail(path, "a string or an integer", value)


def check_model_dict(d: dict[str, Any], root: str = "") -> None:
    """Validate a model file's content; raise :class:`ModelFileError` naming the key path
    (``state.coef[2]``; ``root`` prefixes it, e.g. ``channels[0].model`` in a calibration).

    Checks the common sections (signal, temperatures, range, params against the family's
    constructor types, fit, inputs), the family's ``state`` (:data:`STATE_SCHEMAS`), and
    that a poly model's centres lie in or near the fitted range (:func:`near_range`).
    Units are checked against thermocal's glossary.
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
        raise ModelFileError(f"{_at(root, 'signal.unit')}: {exc}") from None
    target = d["signal"].get("target")
    if target is not None and target not in ("bias", "scale_factor"):
        raise _fail(_at(root, "signal.target"), "bias or scale_factor", target)
    temps: list[str] = d["temperatures"]
    if len(set(temps)) != len(temps):
        raise ModelFileError(f"{_at(root, 'temperatures')}: names repeat: {temps}")
    ranges = d["range"]["temperature_c"]
    for name in temps:
        if name not in ranges:
            raise ModelFileError(f"{_at(root, 'range.temperature_c')}: no range for {name!r}")
        interval(ranges[name], _at(root, f"range.temperature_c.{name}"))
    rates = d["range"].get("rate_c_per_min")
    if rates is not None:
        fields({name: interval for name in temps})(rates, _at(root, "range.rate_c_per_min"))
    klass = get_model_class(d["family"])  # an unknown family is refused, naming it
    check_params(d["params"], klass, _at(root, "params"))
    sensor = d["params"].get("sensor")
    if d["family"] in ("warmup", "bank") and sensor is not None and not 0 <= sensor < len(temps):
        raise ModelFileError(
            f"{_at(root, 'params.sensor')}: {sensor} is not one of the {len(temps)} "
            "temperature inputs"
        )
    schema = STATE_SCHEMAS.get(d["family"])
    if schema is not None:
        schema(d["state"], _at(root, "state"), len(temps))
    if d["family"] == "poly":
        used = {t["sensor"] for t in d["state"]["terms"] if t["t_power"] or t["coupling_power"]}
        for k in sorted(used):
            lo, hi = ranges[temps[k]]
            center = d["state"]["base"][k]["t_center"]
            near_range(center, lo, hi, _at(root, f"state.base[{k}].t_center"), "the centre")


def verify_model_dict(d: Any, where: str, root: str = "") -> dict[str, Any]:
    """Check a parsed model dict: header (format, version, sections), checksum and the
    family's schema (:func:`check_model_dict`); errors name ``where`` (the file) and the key
    path, prefixed by ``root`` (``channels[0].model`` in a calibration).

    The checksum guards against accidents (truncation, a hand edit, a bit flip), not
    against tampering: anyone can recompute it, so the content is checked as well."""
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
    "STATE_SCHEMAS",
    "check_model_dict",
    "check_params",
    "near_range",
    "range_margin",
    "verify_model_dict",
]
