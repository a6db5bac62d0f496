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

from thermocal.errors import ModelFileError

Check = Callable[[Any, str], None]


def _fail(path: str, what: str, got: Any) -> ModelFileError:
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
                raise ModelFileError(f"{path}: the field {key!r} is missing")
            sub(value[key], f"{path}.{key}")
        for key, sub in (optional or {}).items():
            if key in value and value[key] is not None:
                sub(value[key], f"{path}.{key}")

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


def _poly_state(state: Any, path: str, n_temps: int) -> None:
    fields(
        {
            "layout": string,
            "base": list_of(
                fields({"t_center": number, "t_scale": number}), min_len=1
            ),
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
        if base["t_scale"] == 0:
            raise ModelFileError(f"{path}.base[{i}].t_scale: must not be 0")
    for i, term in enumerate(state["terms"]):
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


def check_model_dict(d: dict[str, Any]) -> None:
    """Validate a model file's content; raise :class:`ModelFileError` naming the field.

    Checks the common sections (signal, temperatures, range, params, fit) and the family's
    ``state`` (:data:`STATE_SCHEMAS`).  Units are checked against thermocal's glossary.
    """
    from thermocal import units

    fields(
        {
            "family": string,
            "signal": fields({"name": string, "unit": string}),
            "temperatures": list_of(string, min_len=1),
            "params": fields({}),
            "state": fields({}),
            "range": fields({"temperature_c": fields({})}),
            "fit": fields({}),
        }
    )(d, "model")
    try:
        units.normalize_signal_unit(d["signal"]["unit"])
    except Exception as exc:
        raise ModelFileError(f"model.signal.unit: {exc}") from None
    temps: list[str] = d["temperatures"]
    if len(set(temps)) != len(temps):
        raise ModelFileError(f"model.temperatures: names repeat: {temps}")
    ranges = d["range"]["temperature_c"]
    for name in temps:
        if name not in ranges:
            raise ModelFileError(f"model.range.temperature_c: no range for {name!r}")
        interval(ranges[name], f"model.range.temperature_c.{name}")
    rates = d["range"].get("rate_c_per_min")
    if rates is not None:
        fields({name: interval for name in temps})(rates, "model.range.rate_c_per_min")
    schema = STATE_SCHEMAS.get(d["family"])
    if schema is not None:  # an unknown family is refused by the registry, naming it
        schema(d["state"], "model.state", len(temps))


__all__ = ["STATE_SCHEMAS", "check_model_dict"]
