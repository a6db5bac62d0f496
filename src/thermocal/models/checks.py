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
    """The key path of ``key`` inside ``path`` (``state`` + ``coef`` → ``state.coef``).

    Parameters
    ----------
    path : str
        The enclosing key path (``""`` at the top level).
    key : str
        The key inside it.

    Returns
    -------
    str
        The joined path.

    Examples
    --------
    >>> key_path("state", "coef"), key_path("", "params")
    ('state.coef', 'params')
    """
    return f"{path}.{key}" if path else key


def failure(path: str, what: str, got: Any) -> ModelFileError:
    """The error ``PATH: expected WHAT, got VALUE`` (the value's repr cut at 60 characters).

    Parameters
    ----------
    path : str
        Key path of the value.
    what : str
        What was expected.
    got : object
        The value found.

    Returns
    -------
    thermocal.errors.ModelFileError
        The error to raise.
    """
    path = path or "(top level)"
    text = repr(got)
    if len(text) > 60:
        text = text[:57] + "..."
    return ModelFileError(f"{path}: expected {what}, got {text}")


def number(value: Any, path: str) -> None:
    """A finite real number (not a bool, not NaN/inf/null).

    Parameters
    ----------
    value : object
        The value read from the model file.
    path : str
        Its key path, for the message (e.g. ``state.coef[2]``).

    Raises
    ------
    thermocal.errors.ModelFileError
        Not a finite number, naming ``path``.

    Examples
    --------
    >>> number(1.5, "state.tref")
    >>> number("a", "state.coef[2]")
    Traceback (most recent call last):
    ...
    thermocal.errors.ModelFileError: state.coef[2]: expected a finite number, got 'a'
    """
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise failure(path, "a finite number", value)


def number_or_null(value: Any, path: str) -> None:
    """A finite number or null (None).

    Parameters
    ----------
    value : object
        The value read from the model file.
    path : str
        Its key path, for the message (e.g. ``state.coef[2]``).

    Raises
    ------
    thermocal.errors.ModelFileError
        Neither null nor a finite number, naming ``path``.
    """
    if value is not None:
        number(value, path)


def integer(value: Any, path: str) -> None:
    """An integer (not a bool).

    Parameters
    ----------
    value : object
        The value read from the model file.
    path : str
        Its key path, for the message (e.g. ``state.coef[2]``).

    Raises
    ------
    thermocal.errors.ModelFileError
        Not an integer, naming ``path``.
    """
    if isinstance(value, bool) or not isinstance(value, int):
        raise failure(path, "an integer", value)


def string(value: Any, path: str) -> None:
    """A string.

    Parameters
    ----------
    value : object
        The value read from the model file.
    path : str
        Its key path, for the message (e.g. ``state.coef[2]``).

    Raises
    ------
    thermocal.errors.ModelFileError
        Not a string, naming ``path``.
    """
    if not isinstance(value, str):
        raise failure(path, "a string", value)


def boolean(value: Any, path: str) -> None:
    """``true`` or ``false``.

    Parameters
    ----------
    value : object
        The value read from the model file.
    path : str
        Its key path, for the message (e.g. ``state.coef[2]``).

    Raises
    ------
    thermocal.errors.ModelFileError
        Not a boolean, naming ``path``.
    """
    if not isinstance(value, bool):
        raise failure(path, "true or false", value)


def list_of(item: Check, *, min_len: int = 0) -> Check:
    """The check of a list whose items each pass ``item`` (item paths ``path[i]``).

    Parameters
    ----------
    item : callable
        The check of one item, ``item(value, path)``.
    min_len : int, optional
        Fewest items allowed.  Default 0.

    Returns
    -------
    callable
        ``check(value, path)``, raising :class:`~thermocal.errors.ModelFileError` for a
        non-list, a list shorter than ``min_len`` or a bad item.

    Examples
    --------
    >>> list_of(number, min_len=2)([1.0, 2.0], "state.x")
    >>> list_of(number, min_len=2)([1.0], "state.x")
    Traceback (most recent call last):
    ...
    thermocal.errors.ModelFileError: state.x: expected a list of at least 2 items, got [1.0]
    """

    def check(value: Any, path: str) -> None:
        if not isinstance(value, list):
            raise failure(path, "a list", value)
        if len(value) < min_len:
            raise failure(path, f"a list of at least {min_len} items", value)
        for i, v in enumerate(value):
            item(v, f"{path}[{i}]")

    return check


def matrix(value: Any, path: str) -> None:
    """A rectangular list of lists of numbers or nulls (nulls: undefined covariances).

    Parameters
    ----------
    value : object
        The value read from the model file.
    path : str
        Its key path, for the message (e.g. ``state.coef[2]``).

    Raises
    ------
    thermocal.errors.ModelFileError
        Not a rectangular matrix of numbers or nulls, naming ``path``.
    """
    list_of(list_of(number_or_null))(value, path)
    widths = {len(row) for row in value}
    if len(widths) > 1:
        raise failure(path, "a rectangular matrix", f"rows of lengths {sorted(widths)}")


def fields(spec: dict[str, Check], *, optional: dict[str, Check] | None = None) -> Check:
    """A JSON object with the required keys of ``spec`` and optional keys of ``optional``.

    Parameters
    ----------
    spec : dict of str to callable
        Required key → its check.
    optional : dict of str to callable, optional
        Optional key → its check (a null value is skipped).  Default None.

    Returns
    -------
    callable
        ``check(value, path)``, raising :class:`~thermocal.errors.ModelFileError` for a
        non-object, a missing required key or a bad value.
    """

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
    """``[lo, hi]`` finite with lo ≤ hi.

    Parameters
    ----------
    value : object
        The value read from the model file.
    path : str
        Its key path, for the message (e.g. ``state.coef[2]``).

    Raises
    ------
    thermocal.errors.ModelFileError
        Not two finite numbers in order, naming ``path``.
    """
    list_of(number, min_len=2)(value, path)
    if len(value) != 2 or value[0] > value[1]:
        raise failure(path, "[low, high] with low ≤ high", value)


def ascending(value: Any, path: str) -> None:
    """A list of strictly increasing numbers (breakpoints, table temperatures).

    Parameters
    ----------
    value : object
        The value read from the model file.
    path : str
        Its key path, for the message (e.g. ``state.coef[2]``).

    Raises
    ------
    thermocal.errors.ModelFileError
        Not strictly increasing numbers, naming ``path``.
    """
    list_of(number)(value, path)
    if any(b <= a for a, b in itertools.pairwise(value)):
        raise failure(path, "strictly increasing numbers", value)


def same_length(state: dict[str, Any], path: str, key: str, n: int, what: str) -> None:
    """``state[key]`` has ``n`` values.

    Parameters
    ----------
    state : dict
        The section holding the list.
    path : str
        The section's key path.
    key : str
        The list's key.
    n : int
        The expected length.
    what : str
        What the n values are, for the message.

    Raises
    ------
    thermocal.errors.ModelFileError
        Another length, naming ``path.key``.
    """
    got = len(state[key])
    if got != n:
        raise ModelFileError(f"{path}.{key}: expected {n} values ({what}), got {got}")


def near_range(value: float, lo: float, hi: float, path: str, what: str) -> None:
    """A reference temperature (TREF, a polynomial's centre) inside the calibrated range
    ``[lo, hi]`` or within :func:`range_margin` of it: polynomials in ``T − TREF`` are exact
    for any TREF in theory, but one far outside the range is a corrupted file, not a fit.

    Parameters
    ----------
    value : float
        The reference temperature [°C] (or [counts] for a model in counts).
    lo, hi : float
        The calibrated range [°C] (or [counts]).
    path : str
        Key path of ``value``.
    what : str
        What the value is, for the message.

    Raises
    ------
    thermocal.errors.ModelFileError
        ``value`` outside :math:`[lo - m, hi + m]`, m = :func:`range_margin`.
    """
    margin = range_margin(lo, hi)
    if not lo - margin <= value <= hi + margin:
        raise ModelFileError(
            f"{path}: {what} {value:g} is far outside the calibrated range [{lo:g}, {hi:g}] "
            f"(more than {margin:g} beyond it)"
        )


def range_margin(lo: float, hi: float) -> float:
    """How far beyond a calibrated range ``[lo, hi]`` a reference temperature may lie: the
    range's span, at least 50 (°C, or counts for a model fitted in counts).

    Parameters
    ----------
    lo, hi : float
        The calibrated range [°C] (or [counts]).

    Returns
    -------
    float
        :math:`m = \\max(hi - lo, 50)` [°C] (or [counts]).

    Examples
    --------
    >>> range_margin(-40.0, 85.0), range_margin(20.0, 30.0)
    (125.0, 50.0)
    """
    return max(hi - lo, 50.0)


def sensor_param(d: dict[str, Any], root: str) -> None:
    """A model's ``params.sensor`` (the temperature column it uses), when given, is one of
    the file's temperature inputs.

    Parameters
    ----------
    d : dict
        The model file's content.
    root : str
        Key path prefix for the message.

    Raises
    ------
    thermocal.errors.ModelFileError
        ``params.sensor`` not an index into ``temperatures``.
    """
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
