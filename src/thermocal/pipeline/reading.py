"""How the commands read a data file: their options (strings) become one
:class:`~thermocal.readers.options.ReadOptions` (:func:`read_options`, :func:`read_options_of`),
the file is read by :func:`thermocal.readers.read_recording`, and what a command needs of the
recording is checked in a second step (:func:`check_recording`)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal.errors import GapWarning, ThermocalInputError

if TYPE_CHECKING:
    from thermocal.readers.options import ReadOptions
    from thermocal.recording import Recording


def split_names(text: str | None) -> list[str] | None:
    """``"T1, T2,T 3"`` → ``["T1", "T2", "T 3"]`` (None stays None).

    Parameters
    ----------
    text : str or None
        Comma-separated names.

    Returns
    -------
    list of str or None
        The names, stripped, empty ones dropped.

    Examples
    --------
    >>> split_names("T1, T2,T 3,")
    ['T1', 'T2', 'T 3']
    """
    if text is None:
        return None
    names = [t.strip() for t in text.split(",")]
    return [n for n in names if n]


def split_floats(text: str | None, what: str) -> list[float] | None:
    """``"25, 30"`` → ``[25.0, 30.0]`` (None stays None); an input error naming the option
    ``what`` when an item is not a number.

    Parameters
    ----------
    text : str or None
        Comma-separated numbers.
    what : str
        The option, named in the error.

    Returns
    -------
    list of float or None
        The numbers.

    Raises
    ------
    ThermocalInputError
        When an item is not a number.

    Examples
    --------
    >>> split_floats("25, 30.5", "--breakpoints")
    [25.0, 30.5]
    """
    names = split_names(text)
    if names is None:
        return None
    try:
        return [float(v) for v in names]
    except ValueError:
        raise ThermocalInputError(
            f"{what}: expected comma-separated numbers, got {text!r}"
        ) from None


def read_options(
    *,
    time: str | None = None,
    time_unit: str | None = None,
    signal: str | None = None,
    temps: str | None = None,
    signal_unit: str | None = None,
    temp_unit: str | None = None,
    temp_conversion: str | None = None,
    topic: str | None = None,
    names: str | None = None,
    rate: float | None = None,
    on_bad_lines: str = "error",
    delimiter: str | None = None,
    decimal: str | None = None,
) -> ReadOptions:
    """The :class:`~thermocal.readers.options.ReadOptions` of the command-line options that
    say how a file is read.

    Parameters
    ----------
    time, time_unit, signal_unit, temp_unit, topic, delimiter, decimal : str, optional
        ``--time``, ``--time-unit``, ``--signal-unit``, ``--temp-unit``, ``--topic``,
        ``--delimiter``, ``--decimal`` as given.
    signal, temps, names : str, optional
        ``--signal``, ``--temps``, ``--names``: comma-separated column names (an empty
        ``--signal`` is none given; an empty ``--temps`` states there is none).
    temp_conversion : str, optional
        ``--temp-conversion GAIN,OFFSET[,int16]``: raw counts → °C.
    rate : float, optional
        ``--rate`` [Hz].
    on_bad_lines : str
        ``--on-bad-lines``: ``error`` or ``skip``.

    Returns
    -------
    ReadOptions

    Raises
    ------
    thermocal.errors.UnitError
        ``temp_conversion`` is not ``GAIN,OFFSET[,int16]`` (named ``--temp-conversion``).
    thermocal.errors.ParameterError
        A value no file can have, naming the :class:`ReadOptions` field.
    """
    from thermocal import units
    from thermocal.readers.options import ReadOptions

    conv = (
        None
        if temp_conversion is None
        else units.temperature_conversion(temp_conversion, "--temp-conversion")
    )
    return ReadOptions(
        time=time, time_unit=time_unit,
        signals=tuple(split_names(signal) or ()) if signal else None,
        temperatures=tuple(split_names(temps) or ()) if temps is not None else None,
        signal_unit=signal_unit, temp_unit=temp_unit, temp_conversion=conv, topic=topic,
        names=names, rate_hz=rate, on_bad_lines=on_bad_lines,  # type: ignore[arg-type]
        delimiter=delimiter, decimal=decimal,  # type: ignore[arg-type]
    )  # fmt: skip


def read_options_of(o: Any) -> ReadOptions:
    """The :class:`~thermocal.readers.options.ReadOptions` of a command's options object.

    Parameters
    ----------
    o : object
        ``FitOptions``, ``ValidateOptions`` or any object with (some of) the fields
        ``time``, ``time_unit``, ``signal``, ``temps``, ``signal_unit``, ``temp_unit``,
        ``temp_conversion``, ``topic``, ``names``, ``rate``, ``on_bad_lines``,
        ``delimiter``, ``decimal`` (the options' strings).

    Returns
    -------
    ReadOptions
        As :func:`read_options` builds it from those fields.
    """
    fields = ("time", "time_unit", "signal", "temps", "signal_unit", "temp_unit",
              "temp_conversion", "topic", "names", "rate", "delimiter", "decimal")  # fmt: skip
    given = {f: getattr(o, f) for f in fields if getattr(o, f, None) is not None}
    return read_options(on_bad_lines=getattr(o, "on_bad_lines", "error"), **given)


def check_recording(
    rec: Recording,
    read: ReadOptions | None = None,
    *,
    require_signal: bool = True,
    validate: bool = True,
) -> Recording:
    """What a command needs of a recording it has read: a signal, time and values it can use.

    Parameters
    ----------
    rec : Recording
        As :func:`thermocal.readers.read_recording` read it (``rec.source``: its file).
    read : ReadOptions, optional
        How it was read (to list the file's columns when no signal is named).
    require_signal : bool
        A recording with no signal at all is an input error naming ``--signal`` and the
        available columns.
    validate : bool
        The time column must be finite and strictly increasing and the signal and
        temperature columns free of NaN (:meth:`Recording.validate`, an input error naming
        the file, column and row); gaps are allowed and said in one :class:`GapWarning`.

    Returns
    -------
    Recording
        ``rec`` itself.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        No signal (with ``require_signal``), or time or values unusable (with ``validate``).
    """
    path = Path(rec.source or "recording")
    if require_signal and not rec.signals:
        names = list(rec.columns)
        if not names:  # only the named columns were read: list them all
            names = _all_columns(path, read)
        from thermocal.readers.common import names_list

        raise ThermocalInputError(
            f"{path}: name the signal column with --signal; available: "
            + (names_list(names) or "see thermocal inspect FILE")  # 20 and how many more
        )
    if validate:
        rec.validate()
        gaps = rec.gaps()
        if gaps:
            total = sum(g.length_s for g in gaps)
            warnings.warn(
                GapWarning(
                    f"{path}: {len(gaps)} gaps in time ({total:.6g} s in all), first after "
                    f"row {gaps[0].index} at {gaps[0].start_s:.6g} s"
                ),
                stacklevel=2,
            )
    return rec


def _all_columns(path: Path, read: ReadOptions | None) -> list[str]:
    """Every column of the file, read again with its time column and layout (a courtesy
    listing: empty when that read fails)."""
    from thermocal.readers.dispatch import read_recording
    from thermocal.readers.options import ReadOptions

    r = read or ReadOptions()
    try:
        with warnings.catch_warnings():  # said once already, by the first read
            warnings.simplefilter("ignore")
            again = read_recording(
                path,
                ReadOptions(time=r.time, topic=r.topic, names=r.names, rate_hz=r.rate_hz,
                            on_bad_lines=r.on_bad_lines, delimiter=r.delimiter,
                            decimal=r.decimal),
            )  # fmt: skip
        return list(again.columns)
    except Exception:  # the listing is a courtesy; the error stands as it is
        return []


__all__ = [
    "check_recording",
    "read_options",
    "read_options_of",
    "split_floats",
    "split_names",
]
