"""Values and messages as the command line shows them: plain JSON types (:func:`jsonable`),
one-line texts (:func:`one_line`) and the ``warning:`` lines of caught warnings
(:func:`warning_lines`).  Used by the command line and by the fleet, which records the same
warnings and writes the same JSON without running the command line."""

from __future__ import annotations

import dataclasses
import errno
import json
import math
import warnings
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal._lazy import LazyModule
from thermocal.errors import NamesParameters, ThermocalInputError, ThermocalWarning

if TYPE_CHECKING:
    import numpy as np
else:
    np = LazyModule("numpy")


def one_line(text: object) -> str:
    r"""``text`` with every run of white space (newlines included) made one space.

    Parameters
    ----------
    text : object
        Any object; its ``str()`` is used.

    Returns
    -------
    str
        One line, stripped.

    Examples
    --------
    >>> one_line("a.csv:\n  no column   'gx'")
    "a.csv: no column 'gx'"
    """
    return " ".join(str(text).split())


def jsonable(obj: Any) -> Any:
    """Convert results to plain JSON types: dataclasses → dicts, numpy → Python,
    NaN/inf → ``None``, paths → strings.

    Parameters
    ----------
    obj : Any
        A result: dataclass, dict, list, tuple, numpy array or scalar, float, path, …

    Returns
    -------
    Any
        The same content in JSON types (nested dicts, lists, numbers, strings, ``None``).

    Examples
    --------
    >>> import numpy as np
    >>> jsonable({"rms": np.float64(0.25), "nan": float("nan"), "v": np.arange(3)})
    {'rms': 0.25, 'nan': None, 'v': [0, 1, 2]}
    """
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return jsonable(obj.item())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def json_text(obj: Any) -> str:
    """The one line ``--json`` prints: :func:`jsonable` of ``obj``, newline-terminated.

    Parameters
    ----------
    obj : Any
        A result (see :func:`jsonable`).

    Returns
    -------
    str
        Compact JSON ending with ``"\\n"``; never ``NaN`` or ``Infinity``.
    """
    return json.dumps(jsonable(obj), allow_nan=False) + "\n"


def warning_text(message: Warning | str, options: Mapping[str, str] | None = None) -> str:
    """One warning's text as the command line shows it: one line, with options where it
    names the library's parameters (:func:`option_name`).

    Parameters
    ----------
    message : Warning or str
        A caught warning's ``message``.
    options : mapping of str to str, optional
        ``{parameter: option}`` of the running command where it differs from
        :func:`option_name`'s rule.

    Returns
    -------
    str

    Examples
    --------
    >>> from thermocal.errors import UnitWarning
    >>> warning_text(UnitWarning.naming("host clock?   give {rate_hz}", "rate_hz"))
    'host clock? give --rate'
    """
    if isinstance(message, NamesParameters):
        return one_line(message.spelled(lambda p: option_name(p, options)))
    return one_line(message)


def warning_lines(
    caught: Iterable[warnings.WarningMessage], options: Mapping[str, str] | None = None
) -> list[str]:
    """The text of each ``warning:`` line the command line prints for ``caught``, each
    message once: thermocal warnings as they are, with options where they name the library's
    parameters (:func:`option_name`), numerical ``RuntimeWarning``\\ s with their class name in
    front; other warnings are not shown.

    Parameters
    ----------
    caught : iterable of warnings.WarningMessage
        Warnings recorded by ``warnings.catch_warnings(record=True)``.
    options : mapping of str to str, optional
        ``{parameter: option}`` of the running command where it differs from
        :func:`option_name`'s rule.

    Returns
    -------
    list of str
        The texts, in order, without the ``warning:`` prefix.
    """
    seen: set[str] = set()
    out: list[str] = []
    for w in caught:
        msg = warning_text(w.message, options)
        if msg in seen:
            continue
        seen.add(msg)
        if issubclass(w.category, ThermocalWarning):
            out.append(msg)
        elif issubclass(w.category, RuntimeWarning):  # numerical trouble: never hidden
            out.append(f"{w.category.__name__}: {msg}")
    return out


USER_OS_ERRORS: frozenset[int] = frozenset(
    {
        errno.EACCES,
        errno.EPERM,
        errno.EROFS,
        errno.ENOSPC,
        errno.EDQUOT,
        errno.ENAMETOOLONG,
        errno.ENOTDIR,
        errno.EISDIR,
        errno.ENOENT,
        errno.EEXIST,
        errno.EMFILE,
    }
)
"""OS errors a user causes (exit 2 with ``error:``), as opposed to bugs (exit 1)."""


OPTION_OF: dict[str, str] = {
    "rate_hz": "--rate",
    "signals": "--signal",
    "temperatures": "--temps",
    "latitude_deg": "--latitude",
    "alpha_offset_deg": "--alpha-offset",
    "tref_c": "--tref",
    "rate_interval_s": "--rate-interval",
    "start_window_s": "--start-window",
    "select": "--select-method",
    "file_format": "--format",
    "averaging_s": "--average",
    "drift_reference_s": "--drift-reference",
    "dynamic_s": "--dynamic",
    "deviations": "--deviation",
    "sample_interval_s": "--sample-interval",
    "use_float": "--float",
    "gravity_m_s2": "--gravity",
    "alpha_column": "--alpha",
    "beta_column": "--beta",
    "params": "--param",
    "rate_c_per_min": "--rate",
    "cycle_rate_c_per_min": "--cycle-rate",
    "rates_c_per_min": "--rates",
    "listen_s": "--listen",
    "models": "--model",
    "validations": "--validation",
    "labels": "--label",
    "rates_dps": "--rates",
    "width_c": "--temp-bins",
    "turn_rate_dps": "--turn-rate",
    "start_angle_deg": "--start-angle",
    "angle_tolerance_deg": "--angle-tolerance",
}
"""Library parameters whose command-line option is not the parameter's name with dashes
(``time_unit`` → ``--time-unit`` needs no entry)."""


def option_name(parameter: str, options: Mapping[str, str] | None = None) -> str:
    """The command-line option of a library parameter.

    Parameters
    ----------
    parameter : str
        The library's parameter name (``"rate_interval"``).
    options : mapping, optional
        ``{parameter: option}`` of the running command (its own spelling wins: ``simulate``
        takes ``--rate-hz`` where ``fit`` takes ``--rate``).

    Returns
    -------
    str
        ``options[parameter]``, else :data:`OPTION_OF`, else the name with dashes.

    Examples
    --------
    >>> option_name("rate_interval")
    '--rate-interval'
    >>> option_name("rate_hz"), option_name("rate_hz", {"rate_hz": "--rate-hz"})
    ('--rate', '--rate-hz')
    """
    if options and parameter in options:
        return options[parameter]
    return OPTION_OF.get(parameter, "--" + parameter.replace("_", "-"))


def error_text(exc: Exception, options: Mapping[str, str] | None = None) -> tuple[str, bool]:
    """The text of the ``error:`` line the command line prints for ``exc`` and whether it is
    the user's (exit 2: bad input, a missing file, permissions, a full disk) rather than
    thermocal's own failure (exit 1, ``internal: TYPE: message``).  A
    :class:`~thermocal.errors.ParameterError`, or any input error built with
    :meth:`~thermocal.errors.ThermocalInputError.naming`, names the option
    (:func:`option_name`) where the library names its parameter.

    Parameters
    ----------
    exc : Exception
        The exception raised by the library.
    options : mapping of str to str or None, optional
        Option name by parameter name where it differs from :func:`option_name`'s rule
        (default ``None``).

    Returns
    -------
    text : str
        The message, one line, without the ``error:`` prefix.
    user : bool
        True for the user's error (exit status 2), False for an internal one (exit 1).

    Examples
    --------
    >>> from thermocal.errors import ParameterError
    >>> error_text(ParameterError("min_dwell", "{name} must be positive, got -1"))
    ('--min-dwell must be positive, got -1', True)
    >>> from thermocal.errors import UnitError
    >>> error_text(UnitError.naming("no unit: give {time_unit}", "time_unit"))
    ('no unit: give --time-unit', True)
    >>> error_text(ZeroDivisionError("division by zero"))
    ('internal: ZeroDivisionError: division by zero', False)
    """
    if isinstance(exc, ThermocalInputError) and exc.template is not None:
        return one_line(exc.spelled(lambda p: option_name(p, options))), True
    if isinstance(exc, ThermocalInputError | FileNotFoundError | IsADirectoryError):
        return one_line(exc), True
    if isinstance(exc, OSError) and exc.errno in USER_OS_ERRORS:
        where = exc.filename if exc.filename is not None else "output"
        return one_line(f"{where}: {exc.strerror or exc}"), True  # a name holding "\n"
    return f"internal: {type(exc).__name__}: {one_line(exc)}", False


__all__ = [
    "OPTION_OF",
    "USER_OS_ERRORS",
    "error_text",
    "json_text",
    "jsonable",
    "one_line",
    "option_name",
    "warning_lines",
    "warning_text",
]
