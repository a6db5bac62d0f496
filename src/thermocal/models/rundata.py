"""A run as a model sees it: :class:`RunData` (times, temperatures, signal, known input),
built from a recording with the units it was read in; what a model records of the data it
was fitted on (:func:`model_inputs`) and the sensor-identity check of a model applied to
another unit's data (:func:`check_sensor_id`).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from thermocal.errors import (
    ExtrapolationWarning,
    ThermocalInputError,
    UnitError,
    UnitWarning,
)
from thermocal.recording import FloatArray, Recording, all_finite
from thermocal.units import (
    canonical_unit,
)

# --- input data ------------------------------------------------------------------------


@dataclass(frozen=True)
class RunData:
    """One run (one power-on) as a model sees it.

    Attributes
    ----------
    time_s : numpy.ndarray
        Sample times, shape (n,) [s].
    temps_c : numpy.ndarray
        Temperatures, shape (n, k) [°C] (raw counts when ``temperature_unit`` is
        ``counts``), columns in ``temp_names`` order.
    signal : numpy.ndarray or None
        Sensor output in its canonical unit, shape (n,) [°/h] or [mg]; None (default) when
        only predicting from temperatures.
    temp_names : tuple of str
        Names of the temperature columns (default empty).
    name : str
        Where the run came from (file name), for messages and provenance.
    known_input : float
        The known input to remove before fitting (earth rate [°/h], gravity component
        [mg]); subtracted from ``signal`` by :meth:`target`.  Default 0.
    extra : dict
        Family-specific per-run values (default empty).
    signal_unit : str or None
        The canonical unit of ``signal`` (``deg/h``, ``mg`` or ``counts``) when known
        (:meth:`from_recording` sets it); a model fitted on the run records it.
    temperature_unit : str
        ``degC`` (default), or ``counts`` for raw-count temperatures used without a
        conversion (a model fitted on them is in counts).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        ``temps_c`` not of shape (n, k), or ``signal`` not of length n.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(5.0)
    >>> run = RunData(t, (20.0 + t)[:, None], np.full(5, 3.0), ("T1",), known_input=1.0)
    >>> run.n_samples, run.target().tolist()
    (5, [2.0, 2.0, 2.0, 2.0, 2.0])
    """

    time_s: FloatArray
    temps_c: FloatArray
    signal: FloatArray | None = None
    temp_names: tuple[str, ...] = ()
    name: str = ""
    known_input: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)
    signal_unit: str | None = None
    temperature_unit: str = "degC"

    def __post_init__(self) -> None:
        n = self.time_s.shape[0]
        if self.temps_c.ndim != 2 or self.temps_c.shape[0] != n:
            raise ThermocalInputError(
                f"{self.name or 'run'}: temperatures must be (n_samples, n_sensors); got "
                f"{self.temps_c.shape} for {n} samples"
            )
        if self.signal is not None and self.signal.shape != (n,):
            raise ThermocalInputError(
                f"{self.name or 'run'}: signal has {self.signal.shape[0]} samples, time has {n}"
            )

    @property
    def n_samples(self) -> int:
        """Number of samples n."""
        return int(self.time_s.shape[0])

    def target(self) -> FloatArray:
        """The signal minus the known input: what a model is fitted to.

        Returns
        -------
        numpy.ndarray
            :math:`y_i - y_\\mathrm{known}`, shape (n,) [signal unit].

        Raises
        ------
        thermocal.errors.ThermocalInputError
            The run has no signal.
        """
        if self.signal is None:
            raise ThermocalInputError(f"{self.name or 'run'}: no signal to fit")
        return self.signal - self.known_input

    @classmethod
    def from_recording(
        cls,
        rec: Recording,
        signal: str | None = None,
        temps: Sequence[str] | None = None,
        *,
        known_input: float = 0.0,
        require_signal: bool = True,
        temperature_unit: Literal["degC", "counts", "auto"] = "degC",
    ) -> RunData:
        """Pull the time, temperatures and signal (canonical unit) out of a recording.

        ``temperature_unit``: ``degC`` (raw counts converted, a counts column without a
        conversion is an error); ``counts`` (the raw counts as stored, for a model fitted
        in counts; a °C column is an error); ``auto`` (fit): ``counts`` when every used
        temperature is in raw counts with no conversion stated, else ``degC``.
        NaN in the used columns is an input error (never silently dropped).

        Parameters
        ----------
        rec : thermocal.recording.Recording
            The recording as read.
        signal : str, optional
            Signal column; None (default): the recording's only signal.
        temps : sequence of str, optional
            Temperature columns; None (default): every temperature column.
        known_input : float, optional
            Known input to remove [canonical signal unit: °/h or mg].  Default 0.
        require_signal : bool, optional
            True (default): a recording without the signal is an error.
        temperature_unit : {"degC", "counts", "auto"}, optional
            Default ``"degC"``.

        Returns
        -------
        RunData

        Raises
        ------
        thermocal.errors.ThermocalInputError
            No temperature column, no signal (when required), or non-finite values.
        thermocal.errors.UnitError
            A temperature column whose unit does not fit ``temperature_unit``.
        """
        names = tuple(temps) if temps else rec.temperatures
        if not names:
            raise ThermocalInputError(
                f"{rec.name}: no temperature columns named; available: "
                + ", ".join(repr(c) for c in rec.columns)
            )
        t_unit = temperature_unit
        if t_unit == "auto":
            t_unit = _auto_temperature_unit(rec, names)
        if t_unit == "counts":
            temps_c = np.column_stack([rec.temperature_counts(n) for n in names])
        else:
            temps_c = rec.temperatures_c(names)
        sig: FloatArray | None = None
        sig_unit: str | None = None
        if require_signal or signal is not None or rec.signals:
            try:
                sig, sig_unit = rec.signal(signal)
            except ThermocalInputError:
                if require_signal:
                    raise
        for label, arr in [("time", rec.time_s), ("temperatures", temps_c)] + (
            [("signal", sig)] if sig is not None else []
        ):
            if all_finite(arr):  # the usual case: no mask as long as the data
                continue
            bad = ~np.isfinite(arr)
            if bad.any():
                row = int(np.argwhere(bad)[0][0])
                raise ThermocalInputError(
                    f"{rec.name}: {label} has {int(bad.sum())} NaN/non-finite values "
                    f"(first at row {row}); clean or cut the data first"
                )
        return cls(
            time_s=rec.time_s,
            temps_c=temps_c,
            signal=sig,
            temp_names=names,
            name=rec.source or rec.meta.run_id or "",
            known_input=known_input,
            signal_unit=sig_unit,
            temperature_unit=t_unit,
        )


def _auto_temperature_unit(rec: Recording, names: Sequence[str]) -> Literal["degC", "counts"]:
    """``counts`` when every temperature column is in raw counts with no conversion (a
    model in counts), ``degC`` when none is; a mix is an input error naming the columns."""
    raw = [
        n
        for n in names
        if rec.units.get(n) == "counts" and n not in rec.meta.temperature_conversion
    ]
    if not raw:
        return "degC"
    if len(raw) < len(names):
        raise UnitError.naming(
            f"{rec.name}: temperature column(s) {', '.join(map(repr, raw))} are raw counts "
            "without a conversion, the others are in °C; a model takes one temperature "
            "unit: give {temp_conversion} GAIN,OFFSET[,int16] for the counts",
            "temp_conversion",
        )
    warnings.warn(
        UnitWarning(
            f"{rec.name}: temperature column(s) {', '.join(map(repr, raw))} are raw counts "
            "and no conversion to °C is given: the model is fitted in counts (its ranges and "
            "coefficients are per count) and applies to raw-count data only"
        ),
        stacklevel=3,
    )
    return "counts"


def _run_units(runs: Sequence[RunData]) -> tuple[str | None, str]:
    """(canonical signal unit or None, temperature unit) shared by ``runs``; runs that
    disagree are an input error naming both."""
    sig = {r.signal_unit for r in runs if r.signal_unit}
    if len(sig) > 1:
        raise UnitError(f"the runs' signals are in different units: {', '.join(sorted(sig))}")
    temp = {r.temperature_unit for r in runs}
    if len(temp) > 1:
        raise UnitError.naming(
            "some runs give temperatures in °C and some in raw counts without a conversion; "
            "give {temp_conversion} for the counts",
            "temp_conversion",
        )
    return (next(iter(sig)) if sig else None), (next(iter(temp)) if temp else "degC")


def model_inputs(
    rec: Recording,
    signal: str,
    temps: Sequence[str],
    *,
    known_input: float = 0.0,
    known_input_what: str | None = None,
) -> dict[str, Any]:
    """What a model file records of how its fitted data were written (``inputs``): the
    time unit, the signal's and temperatures' units as given (e.g. ``deg/s``, ``counts``)
    and where each was stated, the raw-count temperature conversions, the scale factor of
    a raw-count signal, the known input removed (value in the canonical unit and what
    it is) and, for a temperature from a chamber's own log, how that log was joined
    (``chamber_log``: the log, its channel and unit, the clocks' offset and drift).
    ``rec`` is a recording read by :func:`thermocal.readers.dispatch.read_recording`.

    Parameters
    ----------
    rec : thermocal.recording.Recording
        The recording the model is fitted on.
    signal : str
        The signal column.
    temps : sequence of str
        The temperature columns.
    known_input : float, optional
        Known input removed [canonical signal unit].  Default 0.
    known_input_what : str, optional
        What the known input is (e.g. ``"earth rate"``); None: ``"none"`` or ``"given"``.

    Returns
    -------
    dict
        The ``inputs`` section of the model file.
    """
    used = [signal, *temps]
    out: dict[str, Any] = {
        "time_unit": rec.time_unit,
        "units": {c: rec.units[c] for c in used if rec.units.get(c)},
        "unit_sources": {c: s for c, s in rec.unit_sources.items() if c in used or c == "<time>"},
        "temperature_conversion": {
            c: list(rec.meta.temperature_conversion[c].to_json())
            for c in temps
            if c in rec.meta.temperature_conversion and rec.units.get(c) == "counts"
        },
    }
    sig_unit = rec.units.get(signal)
    if sig_unit == "counts" and rec.meta.scale_factor is not None:
        out["scale_factor"] = {
            "value": rec.meta.scale_factor,
            "unit": rec.meta.scale_factor_unit,
        }
    if rec.meta.sensor_id:
        out["sensor_id"] = str(rec.meta.sensor_id)
    joined = rec.meta.extra.get("chamber_log")
    if joined and any(rec.unit_sources.get(c) == "chamber log" for c in temps):
        out["chamber_log"] = dict(joined)  # the log, channel, offset and drift it was joined by
    if rec.n_samples > 1:  # sizes the Ṫ buffer of the exported C (export-c)
        out["sample_interval_s"] = float(rec.sample_interval_s)
    canon = canonical_unit(sig_unit) if sig_unit else None
    if sig_unit == "counts" and rec.meta.scale_factor is not None:  # the fit's values are
        canon = rec.signal(signal)[1]  # physical (counts / K), and so is the known input
    out["known_input"] = {
        "value": float(known_input),
        "unit": canon,
        "what": known_input_what or ("none" if known_input == 0.0 else "given"),
    }
    return out


def check_sensor_id(
    model_inputs: Mapping[str, Any] | None, data_sensor_id: Any, where: str
) -> None:
    """:class:`ExtrapolationWarning` when the data's sensor id (metadata ``sensor_id``)
    differs from the one the model was fitted on (model file ``inputs.sensor_id``):
    a compensation model belongs to one sensor. Silent when either is unknown.

    Parameters
    ----------
    model_inputs : mapping or None
        The model file's ``inputs`` section.
    data_sensor_id : object
        The data's ``sensor_id`` metadata, or None.
    where : str
        The data's name, for the message.
    """
    fitted = (model_inputs or {}).get("sensor_id")
    if not fitted or not data_sensor_id or str(fitted) == str(data_sensor_id):
        return
    warnings.warn(
        f"{where}: the data come from sensor {str(data_sensor_id)!r} but the model was fitted "
        f"on sensor {str(fitted)!r}; a compensation model belongs to one sensor",
        ExtrapolationWarning,
        stacklevel=2,
    )
