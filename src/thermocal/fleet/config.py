"""A fleet configuration : the TOML file read and
checked (:func:`load_config`).

``[fit]`` names the ``thermocal fit`` options once, by their long names without dashes,
``[validate]`` the ``thermocal validate`` options; both are checked against the options
dataclasses (:func:`thermocal.pipeline.options.options_from_table`: an unknown option or a
value of the wrong type is an error naming it and the file).  ``[limits]`` gives pass/fail
limits (:class:`Limit`) and each ``[[unit]]`` a device: ``id``, ``modeling`` (its files) and
optionally ``validation`` (a file); paths are relative to the configuration."""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from thermocal.errors import ThermocalInputError
from thermocal.fleet.stats import FIGURES
from thermocal.outputs import refuse_special_input
from thermocal.pipeline.options import FitOptions, ValidateOptions, options_from_table
from thermocal.readers.station import is_station_path

_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$")


@dataclass(frozen=True)
class UnitSpec:
    """One device of the batch.

    Parameters
    ----------
    id : str
        The unit's id (letters, digits, ``.``, ``_``, ``-``; a folder name).
    modeling : tuple of str
        Its modelling files (absolute paths).
    validation : str, optional
        Its validation file (absolute path).
    """

    id: str
    modeling: tuple[str, ...]
    validation: str | None = None


@dataclass(frozen=True)
class Limit:
    """A pass/fail threshold on a figure, for every channel or for the one named.

    Parameters
    ----------
    figure : str
        A figure of :data:`thermocal.fleet.stats.FIGURES` (``"rms_after"``).
    bound : {"max", "min"}
        ``figure ≤ value`` or ``figure ≥ value``.
    value : float
        The threshold, in the channel's data unit.
    channel : str, optional
        The channel it applies to (None: every channel).

    Examples
    --------
    >>> lim = Limit("rms_after", "max", 0.15, channel="gyro_x")
    >>> lim.label, lim.check(0.1), lim.check(0.2), lim.check(float("nan"))
    ('gyro_x.rms_after ≤ 0.15', True, False, False)
    """

    figure: str
    bound: str
    value: float
    channel: str | None = None

    def check(self, value: float | None) -> bool:
        """Whether ``value`` (finite) meets the limit; a missing or non-finite value fails.

        Parameters
        ----------
        value : float or None
            The figure.

        Returns
        -------
        bool
        """
        if value is None or not math.isfinite(value):
            return False
        return value <= self.value if self.bound == "max" else value >= self.value

    @property
    def label(self) -> str:
        """The limit as the report and the messages write it (``gyro.rms_after ≤ 0.15``)."""
        where = f"{self.channel}." if self.channel else ""
        return f"{where}{self.figure} {'≤' if self.bound == 'max' else '≥'} {self.value:g}"


@dataclass(frozen=True)
class FleetConfig:
    """A parsed fleet configuration (:func:`load_config`).

    Parameters
    ----------
    path : pathlib.Path
        The TOML file.
    fit_args, validate_args : tuple of str
        The ``[fit]`` and ``[validate]`` tables as command-line arguments.
    limits : tuple of Limit
        The ``[limits]``.
    units : tuple of UnitSpec
        The ``[[unit]]`` entries.
    """

    path: Path
    fit_args: tuple[str, ...]
    validate_args: tuple[str, ...]
    limits: tuple[Limit, ...]
    units: tuple[UnitSpec, ...]
    fit_options: dict[str, Any] = field(default_factory=dict)
    """The ``[fit]`` table as written (shown in the report)."""
    fit: FitOptions | None = None
    """``[fit]`` as :class:`~thermocal.pipeline.options.FitOptions` (what each unit runs)."""
    validate: ValidateOptions = field(default_factory=ValidateOptions)
    """``[validate]`` as :class:`~thermocal.pipeline.options.ValidateOptions`."""


def _limits(table: Mapping[str, Any], where: str, channel: str | None = None) -> list[Limit]:
    out: list[Limit] = []
    for key, value in table.items():
        if isinstance(value, Mapping) and channel is None:  # [limits.<channel>]
            out += _limits(value, f"{where}.{key}", channel=str(key))
            continue
        m = re.fullmatch(r"(.+)_(max|min)", str(key))
        if m is None or m.group(1) not in FIGURES:
            raise ThermocalInputError(
                f"{where}: {key!r} is not a limit; write <figure>_max or <figure>_min with a "
                f"figure among {', '.join(FIGURES)}"
            )
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ThermocalInputError(f"{where}: {key}: expected a number")
        out.append(Limit(m.group(1), m.group(2), float(value), channel))
    return out


def load_config(path: str | Path) -> FleetConfig:
    """Read and check a fleet configuration (module docstring).  Every error is a
    :class:`ThermocalInputError` naming the file and the entry (``thermocal fleet`` exits 2);
    a missing data file is not one: that unit fails and the others go on.

    Parameters
    ----------
    path : str or pathlib.Path
        The TOML file.

    Returns
    -------
    FleetConfig

    Raises
    ------
    ThermocalInputError
        The file is missing, special, not TOML, or holds an unknown table, key, option or
        limit, a bad unit id or a unit without modelling files.
    """
    p = Path(path)
    refuse_special_input(p, "configuration file")
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ThermocalInputError(f"{p}: no such configuration file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ThermocalInputError(f"{p}: not a valid TOML file ({exc})") from None
    except RecursionError:  # thousands of nested brackets
        raise ThermocalInputError(f"{p}: not a fleet configuration (nested too deeply)") from None
    unknown = sorted(set(doc) - {"fit", "validate", "limits", "unit"})
    if unknown:
        raise ThermocalInputError(
            f"{p}: unknown table(s) {', '.join(unknown)}; use fit, validate, limits, unit"
        )
    fit = doc.get("fit", {})
    if not isinstance(fit, dict) or not fit:
        raise ThermocalInputError(f"{p}: a [fit] table with the options of thermocal fit is needed")
    fit_opts, fit_args = options_from_table("fit", fit, f"{p} [fit]")
    val_table = doc.get("validate", {})
    if not isinstance(val_table, dict):
        raise ThermocalInputError(f"{p}: [validate] must be a table")
    val_opts, validate_args = options_from_table("validate", val_table, f"{p} [validate]")
    lim_table = doc.get("limits", {})
    if not isinstance(lim_table, dict):
        raise ThermocalInputError(f"{p}: [limits] must be a table")
    limits = _limits(lim_table, f"{p} [limits]")
    raw_units = doc.get("unit", [])
    if not isinstance(raw_units, list) or not raw_units:
        raise ThermocalInputError(f"{p}: no [[unit]] entries")
    base = p.resolve().parent
    units: list[UnitSpec] = []
    seen: set[str] = set()
    for i, u in enumerate(raw_units, start=1):
        where = f"{p} [[unit]] #{i}"
        if not isinstance(u, dict):
            raise ThermocalInputError(f"{where}: must be a table")
        extra = sorted(set(u) - {"id", "modeling", "validation"})
        if extra:
            raise ThermocalInputError(
                f"{where}: unknown key(s) {', '.join(extra)}; use id, modeling, validation"
            )
        uid = u.get("id")
        if not isinstance(uid, str) or not _ID.fullmatch(uid):  # "$" matches before a "\n"
            raise ThermocalInputError(
                f"{where}: id must be letters, digits, '.', '_' or '-' (it names a directory), "
                f"got {uid!r}"
            )
        if uid in seen:
            raise ThermocalInputError(f"{where}: id {uid!r} is used twice")
        seen.add(uid)
        mod = u.get("modeling")
        if isinstance(mod, str):
            mod = [mod]
        if not isinstance(mod, list) or not mod or not all(isinstance(m, str) for m in mod):
            raise ThermocalInputError(
                f"{where} ({uid}): modeling must be a file or a list of files"
            )
        val = u.get("validation")
        if val is not None and not isinstance(val, str):
            raise ThermocalInputError(f"{where} ({uid}): validation must be one file")
        for f in (*mod, *([val] if val is not None else [])):
            refuse_special_input(base / f, f"data file of unit {uid}")  # a FIFO: a hang
            if (base / f).is_dir() and not is_station_path(base / f):
                raise ThermocalInputError(
                    f"{where} ({uid}): {base / f}: is a directory, not a recording file (a "
                    "folder is read only when `thermocal station run` wrote it)"
                )
        units.append(
            UnitSpec(
                uid,
                tuple(str(base / m) for m in mod),
                str(base / val) if val is not None else None,
            )
        )
    return FleetConfig(
        p, tuple(fit_args), tuple(validate_args), tuple(limits), tuple(units), fit,
        fit_opts, val_opts,
    )  # fmt: skip


__all__ = ["FleetConfig", "Limit", "UnitSpec", "load_config"]
