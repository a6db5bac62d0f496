"""The checks a model file's sections are made of: each takes the value and its key path
and raises :class:`~thermocal.errors.ModelFileError` naming the path (``state.coef[2]:
expected a finite number, got 'a'``).  The families check their own ``state`` with them
(``check_state``, next to the state they write); :mod:`thermocal.models.schema` checks the
common sections and calls the family's."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

from thermocal.errors import ModelFileError

Check = Callable[[Any, str], None]


def key_path(path: str, key: str) -> str:
    """The key path of ``key`` inside ``path`` (``state`` + ``coef`` → ``state.coef``)."""
    return f"{path}.{key}" if path else key


def failure(path: str, what: str, got: Any) -> ModelFileError:
    path = path or "(top level)"
    text = repr(got)
    if len(text) > 60:
        text = text[:57] + "..."
    return ModelFileError(f"{path}: expected {what}, got {text}")


def number(value: Any, path: str) -> None:
    """A finite real number (not a bool, not NaN/inf/null)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise failure(path, "a finite number", value)


def number_or_null(value: Any, path: str) -> None:
    if value is not None:
        number(value, path)


def integer(value: Any, path: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int):
        raise failure(path, "an integer", value)


def string(value: Any, path: str) -> None:
    if not isinstance(value, str):
        raise failure(path, "a string", value)


def boolean(value: Any, path: str) -> None:
    if not isinstance(value, bool):
        raise failure(path, "true or false", value)


def list_of(item: Check, *, min_len: int = 0) -> Check:
    def check(value: Any, path: str) -> None:
        if not isinstance(value, list):
            raise failure(path, "a list", value)
        if len(value) < min_len:
            raise failure(path, f"a list of at least {min_len} items", value)
        for i, v in enumerate(value):
            item(v, f"{path}[{i}]")

    return check


def matrix(value: Any, path: str) -> None:
    """A rectangular list of lists of numbers or nulls (nulls: undefined covariances)."""
    list_of(list_of(number_or_null))(value, path)
    widths = {len(row) for row in value}
    if len(widths) > 1:
        raise failure(path, "a rectangular matrix", f"rows of lengths {sorted(widths)}")


def fields(spec: dict[str, Check], *, optional: dict[str, Check] | None = None) -> Check:
    """A JSON object with the required keys of ``spec`` and optional keys of ``optional``."""

    def check(value: Any, path: str) -> None:
        if not isinstance(value, dict):
            raise failure(path, "an object", value)
        for key, sub in spec.items():
            if key not in value:
                raise ModelFileError(f"{path or '(top level)'}: the field {key!r} is missing")
            sub(value[key], key_path(path, key))
        for key, sub in (optional or {}).items():
            if key in value and value[key] is not None:
                sub(value[key], key_path(path, key))

    return check


def interval(value: Any, path: str) -> None:
    """``[lo, hi]`` finite with lo ≤ hi."""
    list_of(number, min_len=2)(value, path)
    if len(value) != 2 or value[0] > value[1]:
        raise failure(path, "[low, high] with low ≤ high", value)


def ascending(value: Any, path: str) -> None:
    list_of(number)(value, path)
    if any(b <= a for a, b in itertools.pairwise(value)):
        raise failure(path, "strictly increasing numbers", value)


def same_length(state: dict[str, Any], path: str, key: str, n: int, what: str) -> None:
    got = len(state[key])
    if got != n:
        raise ModelFileError(f"{path}.{key}: expected {n} values ({what}), got {got}")


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


def sensor_param(d: dict[str, Any], root: str) -> None:
    """A model's ``params.sensor`` (the temperature column it uses), when given, is one of
    the file's temperature inputs."""
    sensor = d["params"].get("sensor")
    temps = d["temperatures"]
    if sensor is not None and not 0 <= sensor < len(temps):
        raise ModelFileError(
            f"{key_path(root, 'params.sensor')}: {sensor} is not one of the {len(temps)} "
            "temperature inputs"
        )


__all__ = [
    "Check",
    "ascending",
    "boolean",
    "failure",
    "fields",
    "integer",
    "interval",
    "key_path",
    "list_of",
    "matrix",
    "near_range",
    "number",
    "number_or_null",
    "range_margin",
    "same_length",
    "sensor_param",
    "string",
]
