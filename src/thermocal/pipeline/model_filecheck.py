"""Reading a model or calibration file's JSON within stated bounds.

A model file is read before anything else looks at it, and refused (:class:`ModelFileError`,
exit 2, naming the file and the key path) when:

* it is larger than :data:`MAX_FILE_BYTES` (64 MiB: a calibration of a hundred channels
  with their covariances is well under 1 MiB);
* its objects and lists nest deeper than :data:`MAX_DEPTH` (a model file nests 7 deep at
  most: ``triads[0].model.parameters[3].covariance[1][2]``);
* it holds a number JSON cannot hold as a finite double: the ``NaN``, ``Infinity`` and
  ``-Infinity`` literals Python's ``json`` accepts, a float literal that overflows
  (``1e309``), or an integer beyond ±2⁵³ (the largest exactly representable in a double;
  a 5000-digit integer is refused before Python converts it).

The checksum a model file carries (:func:`thermocal.models.format.checksum`) is computed
afterwards: it guards against accidents (a truncated copy, a hand edit, a bit flip), not
against tampering — anyone can recompute it — which is why the content itself is checked
(:mod:`thermocal.models.schema`, :meth:`thermocal.turntable.thermal.TriadThermal.from_dict`).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from thermocal.errors import ModelFileError
from thermocal.outputs import refuse_special_input

MAX_FILE_BYTES = 64 * 1024 * 1024
"""Largest model or calibration file read [bytes] (64 MiB)."""
MAX_DEPTH = 32
"""Deepest nesting of objects and lists accepted in a model or calibration file."""
MAX_INT = 2**53
"""Largest integer magnitude accepted (exact in a double)."""
_MAX_INT_DIGITS = len(str(MAX_INT))


class _Bad:
    """A number the parser met that is not a finite double (found afterwards, with its
    key path, by :func:`_first_bad`)."""

    __slots__ = ("why",)

    def __init__(self, why: str) -> None:
        self.why = why


def _parse_constant(text: str) -> _Bad:
    return _Bad(f"{text} is not a finite number (a model file holds finite numbers only)")


def _parse_float(text: str) -> float | _Bad:
    value = float(text)
    if not math.isfinite(value):
        return _Bad(f"{text[:20]} overflows a double (a model file holds finite numbers only)")
    return value


def _parse_int(text: str) -> int | _Bad:
    digits = len(text.lstrip("-"))
    if digits > _MAX_INT_DIGITS:
        return _Bad(f"an integer of {digits} digits (at most ±2^53 is accepted)")
    value = int(text)
    if abs(value) > MAX_INT:
        return _Bad(f"the integer {text} exceeds ±2^53")
    return value


def _key(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


def _first_bad(obj: Any) -> tuple[str, str] | None:
    """(key path, reason) of the first non-finite number or too deep nesting, walking the
    parsed tree without recursion."""
    stack: list[tuple[Any, str, int]] = [(obj, "", 0)]
    while stack:
        value, path, depth = stack.pop()
        if isinstance(value, _Bad):
            return path or "(top level)", value.why
        if isinstance(value, dict | list):
            if depth >= MAX_DEPTH:
                return path or "(top level)", f"nested deeper than {MAX_DEPTH} levels"
            items = (
                [(v, _key(path, str(k))) for k, v in value.items()]
                if isinstance(value, dict)
                else [(v, f"{path}[{i}]") for i, v in enumerate(value)]
            )
            stack.extend((v, p, depth + 1) for v, p in reversed(items))
    return None


def read_json(path: str | Path, what: str = "model file") -> Any:
    """The parsed JSON of a model or calibration file, within the module's bounds (size,
    nesting, finite numbers); :class:`ModelFileError` ``"FILE: KEY.PATH: reason"``
    otherwise.

    Parameters
    ----------
    path : str or Path
        The file to read.
    what : str, optional
        What the file is, for messages (default ``"model file"``).

    Returns
    -------
    Any
        The parsed JSON.

    Raises
    ------
    ModelFileError
        When the file is special, too large, too deeply nested, not JSON, or holds a
        non-finite number.
    """
    p = Path(path)
    refuse_special_input(p, what)  # a FIFO would block the read
    try:
        with open(p, "rb") as fh:
            raw = fh.read(MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        raise ModelFileError(f"{p}: no such {what}") from None
    except IsADirectoryError:
        raise ModelFileError(f"{p}: is a directory, not a {what}") from None
    except OSError as exc:
        raise ModelFileError(f"{p}: cannot read the {what} ({exc.strerror or exc})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ModelFileError(
            f"{p}: larger than {MAX_FILE_BYTES // (1024 * 1024)} MiB: not a thermocal {what}"
        )
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ModelFileError(f"{p}: not a text (JSON) {what}") from None
    try:
        obj = json.loads(
            text,
            parse_constant=_parse_constant,
            parse_float=_parse_float,
            parse_int=_parse_int,
        )
    except json.JSONDecodeError as exc:
        raise ModelFileError(f"{p}: corrupted {what} (invalid JSON: {exc.msg})") from None
    except RecursionError:
        raise ModelFileError(
            f"{p}: objects or lists nested deeper than {MAX_DEPTH} levels: not a thermocal {what}"
        ) from None
    bad = _first_bad(obj)
    if bad is not None:
        raise ModelFileError(f"{p}: {bad[0]}: {bad[1]}")
    return obj


__all__ = ["MAX_DEPTH", "MAX_FILE_BYTES", "MAX_INT", "read_json"]
