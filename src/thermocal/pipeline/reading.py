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


def read_options(
    *,
    time: str | None = None,
    time_unit: str | None = None,
    signal: str | None = None,
    temps: str | None = None,
    signal_unit: str | tuple[str, ...] | None = None,
    temp_unit: str | None = None,
    temp_conversion: str | None = None,
    topic: str | None = None,
    names: str | None = None,
    rate: float | None = None,
    on_bad_lines: str = "error",
    delimiter: str | None = None,
    decimal: str | None = None,
    stamp: str = "header",
) -> ReadOptions:
    """The :class:`~thermocal.readers.options.ReadOptions` of the texts a user typed to say
    how a file is read (each parameter named after its field of ``ReadOptions``, or after
    the command line's spelling where the two differ: ``signal``, ``temps``, ``rate``).

    Parameters
    ----------
    time, time_unit, temp_unit, topic, delimiter, decimal : str, optional
        As the fields of the same names.
    signal_unit : str or tuple of str, optional
        One unit for every signal, or ``"U1,…,Un"`` (or a tuple), one per signal in the
        order of ``signal``.
    signal, temps, names : str, optional
        Comma-separated column names (an empty ``signal`` is none given; an empty
        ``temps`` states there is none).
    temp_conversion : str, optional
        ``"GAIN,OFFSET[,int16]"``: raw counts → °C.
    rate : float, optional
        Sample rate [Hz] of a log without a time column (field ``rate_hz``).
    on_bad_lines : str
        ``"error"`` or ``"skip"``.
    stamp : str
        ``"header"`` or ``"receive"``: the time of a ROS bag's messages.

    Returns
    -------
    ReadOptions

    Raises
    ------
    thermocal.errors.UnitError
        ``temp_conversion`` is not ``GAIN,OFFSET[,int16]`` (naming ``temp_conversion``).
    thermocal.errors.ParameterError
        A value no file can have, naming the :class:`ReadOptions` field.

    Examples
    --------
    >>> r = read_options(signal="gx, gy", signal_unit="rad/s,deg/s", rate=100.0)
    >>> r.signals, r.signal_unit, r.rate_hz
    (('gx', 'gy'), ('rad/s', 'deg/s'), 100.0)
    """
    from thermocal import units
    from thermocal.readers.options import ReadOptions

    conv = (
        None
        if temp_conversion is None
        else units.temperature_conversion(
            temp_conversion, "{temp_conversion}", ("temp_conversion",)
        )
    )
    return ReadOptions(
        time=time, time_unit=time_unit,
        signals=tuple(split_names(signal) or ()) if signal else None,
        temperatures=tuple(split_names(temps) or ()) if temps is not None else None,
        signal_unit=split_units(signal_unit), temp_unit=temp_unit, temp_conversion=conv,
        topic=topic,
        names=names, rate_hz=rate, on_bad_lines=on_bad_lines,  # type: ignore[arg-type]
        delimiter=delimiter, decimal=decimal,  # type: ignore[arg-type]
        stamp=stamp,  # type: ignore[arg-type]
    )  # fmt: skip


def split_units(text: str | tuple[str, ...] | None) -> str | tuple[str, ...] | None:
    """The signal units a user typed: ``"U1,…,Un"`` → one unit per signal (a tuple);
    one unit (stripped), a tuple or None as given.

    Parameters
    ----------
    text : str or tuple of str or None
        ``"deg/s"`` (one unit for every signal) or ``"rad/s, deg/s"`` (one per signal; an
        empty item states none for its signal).

    Returns
    -------
    str or tuple of str or None
        What :attr:`ReadOptions.signal_unit <thermocal.readers.options.ReadOptions>` takes.

    Examples
    --------
    >>> split_units("rad/s, deg/s"), split_units(" deg/s")
    (('rad/s', 'deg/s'), 'deg/s')
    """
    if isinstance(text, str) and "," in text:
        return tuple(u.strip() for u in text.split(","))
    return text.strip() if isinstance(text, str) else text


def read_options_of(o: Any) -> ReadOptions:
    """The :class:`~thermocal.readers.options.ReadOptions` of a command's options object.

    Parameters
    ----------
    o : object
        ``FitOptions``, ``ValidateOptions`` or any object with (some of) the fields
        ``time``, ``time_unit``, ``signal``, ``temps``, ``signal_unit``, ``temp_unit``,
        ``temp_conversion``, ``topic``, ``names``, ``rate``, ``on_bad_lines``,
        ``delimiter``, ``decimal`` (the texts as typed).

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
        A recording with no signal at all is an input error naming ``signals`` and the
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

        raise ThermocalInputError.naming(
            f"{path}: name the signal column with {{signals}}; available: "
            + (names_list(names) or "see thermocal inspect FILE"),  # 20 and how many more
            "signals",
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
    "split_names",
    "split_units",
]
