"""A data file read with the options of the commands (options win over the file): the one
reading path of ``fit`` and ``validate`` (their main files and ``validate --modeling``),
through :func:`thermocal.readers.dispatch.read_recording`."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal.errors import GapWarning, ThermocalInputError

if TYPE_CHECKING:
    from thermocal.models.base import TemperatureModel
    from thermocal.readers.text import TextOptions
    from thermocal.recording import Metadata, Recording


def split_names(text: str | None) -> list[str] | None:
    """``"T1, T2,T 3"`` → ``["T1", "T2", "T 3"]`` (None stays None)."""
    if text is None:
        return None
    names = [t.strip() for t in text.split(",")]
    return [n for n in names if n]


def split_floats(text: str | None, what: str) -> list[float] | None:
    """``"25, 30"`` → ``[25.0, 30.0]`` (None stays None); an input error naming the option
    ``what`` when an item is not a number."""
    names = split_names(text)
    if names is None:
        return None
    try:
        return [float(v) for v in names]
    except ValueError:
        raise ThermocalInputError(
            f"{what}: expected comma-separated numbers, got {text!r}"
        ) from None


def text_options(
    names: str | None,
    rate: float | None,
    on_bad_lines: str,
    delimiter: str | None,
    decimal: str | None,
) -> TextOptions | None:
    """The text-log options ``--names a,b,c``, ``--rate HZ``, ``--on-bad-lines``,
    ``--delimiter``, ``--decimal`` (None when none is given)."""
    from thermocal.readers.text import TextOptions

    if names is None and rate is None and on_bad_lines == "error" and not delimiter and not decimal:
        return None
    return TextOptions(
        names=tuple(split_names(names) or []) if names is not None else None,
        rate_hz=rate,
        on_bad_lines=on_bad_lines,
        delimiter=delimiter,
        decimal=decimal,
    )


def load_recording(
    path: Path,
    *,
    time: str | None = None,
    time_unit: str | None = None,
    signal: str | None = None,
    temps: str | None = None,
    signal_unit: str | None = None,
    temp_unit: str | None = None,
    meta: Metadata | None = None,
    require_signal: bool = True,
    check: bool = True,
    temp_conversion: str | None = None,
    model_inputs: dict[str, Any] | None = None,
    model: TemperatureModel | None = None,
    keep_other: bool = True,
    text: TextOptions | None = None,
    topic: str | None = None,
    ask_units: dict[str, str] | None = None,
) -> Recording:
    """Read a recording with the command line's options (options win over the file).

    ``keep_other=False`` reads only the time, signal and temperature columns (8 bytes a
    row less for every other column, for commands that use no other).

    A signal named with ``--signal`` becomes the first signal; without it the
    file's sidecar roles are used.  With ``require_signal`` a recording with no
    signal at all is an input error.  With ``check`` (INTERFACE.md common rules)
    the time column must be finite and strictly increasing and the signal and
    temperature columns free of NaN (:meth:`Recording.validate`, an input error
    naming the file, column and row); gaps are allowed and reported as one
    :class:`GapWarning`.  ``temp_conversion`` (``"GAIN,OFFSET[,int16]"``) sets the raw-count
    conversion ``T[°C] = GAIN·counts + OFFSET`` of every temperature column.
    ``model`` (a fitted model; or ``model_inputs``, a model file's ``inputs``) fills in
    what the options and the file leave unstated: the time unit, column units and
    temperature conversions as fitted (:meth:`TemperatureModel.input_units`).  Every unit
    is resolved once, by :func:`thermocal.units.resolve_inputs`.  ``text`` (the text-log
    options, :func:`text_options`) and ``topic`` (a ULog topic) choose how the file is read.
    ``ask_units`` maps a column to the option that states its unit: asked for, not assumed.
    """
    from thermocal import units
    from thermocal.readers.dispatch import read_recording

    stated: units.StatedUnits | None = None
    if model is not None:
        stated = model.input_units()
    elif model_inputs is not None:
        stated = units.StatedUnits.from_model_inputs(model_inputs)
    conv = (
        None
        if temp_conversion is None
        else units.temperature_conversion(temp_conversion, "--temp-conversion")
    )
    rec = read_recording(
        path, time=time, time_unit=time_unit,
        signals=split_names(signal) if signal else None,  # "gx,gy,gz": several channels
        temperatures=split_names(temps), signal_unit=signal_unit, temp_unit=temp_unit,
        meta=meta, model=stated, keep_other=keep_other, text=text, topic=topic,
        temp_conversion=conv, ask_units=ask_units,
    )  # fmt: skip
    if model is not None or model_inputs is not None:
        from thermocal.models.rundata import check_sensor_id

        fitted = getattr(model, "inputs_", None) if model is not None else model_inputs
        check_sensor_id(fitted, rec.meta.sensor_id, str(path))
    if require_signal and not rec.signals:
        names = list(rec.columns)
        if not names and not keep_other:  # only the named columns were read: list them all
            try:
                with warnings.catch_warnings():  # said once already, by the first read
                    warnings.simplefilter("ignore")
                    again = read_recording(path, time=time, text=text, topic=topic)
                names = list(again.columns)
            except Exception:  # the listing is a courtesy; the error stands as it is
                names = []
        from thermocal.readers.common import names_list

        raise ThermocalInputError(
            f"{path}: name the signal column with --signal; available: "
            + (names_list(names) or "see thermocal inspect FILE")  # 20 and how many more
        )
    if check:
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


__all__ = ["load_recording", "split_floats", "split_names", "text_options"]
