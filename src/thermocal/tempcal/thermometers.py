"""The temperature a flight controller's sensor is calibrated against: its own thermometer,
reconstructed when it is quantised or slow, or another instance's (or the barometer's),
joined by time (:mod:`thermocal.thermometer`).

``px4-tempcal`` and ``ardupilot-tempcal`` call :func:`sensor_temperature` on each IMU
instance before the pipeline (:func:`.pipeline.fit_sensor`) and :func:`record_thermometer`
after it; what was done is in the fit (``SensorFit.thermometer``), every channel's
``inputs`` in the calibration, and the parameter file's notes.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.recording import FloatArray, Recording
from thermocal.thermometer import (
    TemperatureMode,
    ThermometerWarning,
    borrowed_temperature,
    reconstruct_temperature,
)

TEMPERATURE_MODES: tuple[TemperatureMode, ...] = ("reconstructed", "raw")
"""The values of the ``temperature`` parameter."""


@dataclass(frozen=True)
class TempsFrom:
    """Whose thermometer the IMU instances are calibrated against.

    Attributes
    ----------
    source : int or "baro"
        Another IMU instance's number (the same kind: a gyro against that instance's gyro
        temperature, an accelerometer against its accelerometer's), or ``"baro"``: the
        first barometer's temperature.
    targets : tuple of int or None
        The instances that borrow it; None: every instance but the source.
    """

    source: int | Literal["baro"]
    targets: tuple[int, ...] | None = None

    def __post_init__(self) -> None:
        """Check the source and the targets."""
        if isinstance(self.source, bool) or not (
            self.source == "baro" or (isinstance(self.source, int) and self.source >= 0)
        ):
            raise ParameterError(
                "temps_from", f"{{name}} must be an instance number or baro, got {self.source!r}"
            )
        if self.targets is not None and any(int(t) < 0 for t in self.targets):
            raise ParameterError("temps_from", "{name}: instance numbers are 0 or more")

    def applies(self, instance: int) -> bool:
        """Whether instance ``instance`` borrows the thermometer.

        Parameters
        ----------
        instance : int
            The IMU instance.

        Returns
        -------
        bool
        """
        if self.targets is not None:
            return instance in self.targets
        return self.source == "baro" or instance != self.source


@dataclass(frozen=True)
class TemperatureSeries:
    """A thermometer's series, read from the log.

    Attributes
    ----------
    name : str
        Where it is in the log (``sensor_gyro.1``, ``IMU.1``, ``sensor_baro.0``, ``BARO.0``).
    time_s : numpy.ndarray
        Its sample times [s].
    temp_c : numpy.ndarray
        Its readings [°C].
    """

    name: str
    time_s: FloatArray
    temp_c: FloatArray


def missing_source(log: object, wanted: str, found: list[str]) -> ThermocalInputError:
    """The refusal of a thermometer to borrow that the log does not hold.

    Parameters
    ----------
    log : object
        The log (its path), for the message.
    wanted : str
        The topic or message instance asked for.
    found : list of str
        Those the log holds.

    Returns
    -------
    ThermocalInputError
        Naming ``temps_from``.
    """
    have = ", ".join(found) if found else "none"
    return ThermocalInputError.naming(
        f"{log}: {{temps_from}} names {wanted}, which the log does not hold with a "
        f"temperature (it has: {have}); give one of those, or leave {{temps_from}} out",
        "temps_from",
    )


def sensor_temperature(
    rec: Recording,
    where: str,
    *,
    temperature: TemperatureMode = "reconstructed",
    source: TemperatureSeries | None = None,
) -> tuple[Recording, dict[str, Any]]:
    """The recording with the temperature it is calibrated against.

    Parameters
    ----------
    rec : thermocal.recording.Recording
        One IMU instance: time [s], axes, ``temperature`` [°C].
    where : str
        Its name in the log (``sensor_gyro.0``, ``IMU.0``), for messages.
    temperature : {"reconstructed", "raw"}, optional
        ``"reconstructed"`` (default): a quantised or slow thermometer is replaced by the
        temperature reconstructed at each sample
        (:func:`thermocal.thermometer.reconstruct_temperature`); ``"raw"``: as logged.
    source : TemperatureSeries, optional
        Another thermometer to use instead of the instance's own, joined by time
        (:func:`thermocal.thermometer.borrowed_temperature`): samples outside its record are
        left out.

    Returns
    -------
    (Recording, dict)
        The recording with its ``temperature`` replaced (and rows left out when borrowed),
        and what was done: the thermometer's description
        (:meth:`thermocal.thermometer.Reconstruction.to_dict`), ``source`` (where the
        temperature came from), ``samples_kept`` and ``own_minus_source_c`` (borrowed: the
        median of the sensor's own reading less the borrowed one [°C]; else None).

    Raises
    ------
    ThermocalInputError
        ``temperature`` unknown; a borrowed thermometer that does not overlap the record.

    Warns
    -----
    ThermometerWarning
        The borrowed thermometer covers only part of the record, or reads more than
        :data:`APART_C` from the sensor's own (median or spread).

    Notes
    -----
    A thermometer with a single level is left as it is: the data's judgement that follows
    refuses it (no sweep).
    """
    if temperature not in TEMPERATURE_MODES:
        raise ParameterError(
            "temperature", f"{{name}} must be reconstructed or raw, got {temperature!r}"
        )
    own = rec.temperature_c("temperature")
    if source is None:
        if np.unique(own[np.isfinite(own)]).size < 2:
            return rec, {}
        made = reconstruct_temperature(rec.time_s, own, mode=temperature)
        out = rec.with_columns({"temperature": made.temp_c}, {"temperature": "degC"})
        return out, {
            **made.to_dict(), "source": where, "samples_kept": int(own.size),
            "own_minus_source_c": None,
        }  # fmt: skip
    try:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always", ThermometerWarning)
            made, keep = borrowed_temperature(
                rec.time_s, source.time_s, source.temp_c, source=source.name, mode=temperature
            )
    except ThermocalInputError as exc:
        raise ThermocalInputError.naming(
            f"{where}: {exc}; give {{temps_from}} a thermometer recorded with it", "temps_from"
        ) from None
    except ParameterError as exc:  # a constant borrowed thermometer
        raise ThermocalInputError.naming(
            f"{where}: {source.name}'s thermometer: {exc.named('its temperature')}; give "
            "{temps_from} another one",
            "temps_from",
        ) from None
    for w in said:
        warnings.warn(ThermometerWarning(f"{where}: {w.message}"), stacklevel=2)
    out = rec.select(keep) if not keep.all() else rec
    out = out.with_columns({"temperature": made.temp_c}, {"temperature": "degC"})
    apart = _apart(where, source.name, own[keep], made.temp_c)
    return out, {
        **made.to_dict(), "source": source.name, "samples_kept": int(keep.sum()),
        "own_minus_source_c": apart,
    }  # fmt: skip


APART_C = 1.0
"""Own and borrowed thermometers further apart than this (median, or the 95th percentile
about it) are said in a warning [°C]."""


def _apart(where: str, source: str, own: FloatArray, borrowed: FloatArray) -> float | None:
    """The median of own − borrowed [°C] (None: no finite own reading), a warning when the
    two read apart by more than :data:`APART_C` (in flight the firmware reads its own)."""
    d = own - borrowed
    d = d[np.isfinite(d)]
    if d.size == 0:
        return None
    med = float(np.median(d))
    spread = float(np.percentile(np.abs(d - med), 95))
    if abs(med) > APART_C or spread > APART_C:
        warnings.warn(
            ThermometerWarning(
                f"{where}: its own thermometer reads {med:+.2f} °C from {source}'s (95 % "
                f"within ±{spread:.2f} °C about that): in flight the firmware compensates "
                "with its own, so the correction will be applied at other temperatures"
            ),
            stacklevel=3,
        )
    return med


@dataclass(frozen=True)
class ThermometerPlan:
    """How a run's IMU instances get their temperature.

    Attributes
    ----------
    temperature : {"reconstructed", "raw"}
        Reconstructed when quantised or slow, or as logged.
    temps_from : TempsFrom or None
        The thermometer borrowed, and by which instances.
    series : dict of str to TemperatureSeries
        The borrowed series per sensor kind (``"gyro"``, ``"accel"``), read before the
        instances are (the log's parse of an instance is released once it is fitted).
    """

    temperature: TemperatureMode = "reconstructed"
    temps_from: TempsFrom | None = None
    series: dict[str, TemperatureSeries] = field(default_factory=dict)

    def source_for(self, kind: str, instance: int) -> TemperatureSeries | None:
        """The borrowed series of instance ``instance`` of ``kind``, or None (its own).

        Parameters
        ----------
        kind : str
            ``"gyro"`` or ``"accel"``.
        instance : int
            The IMU instance.

        Returns
        -------
        TemperatureSeries or None
        """
        if self.temps_from is None or not self.temps_from.applies(instance):
            return None
        return self.series.get(kind)


def _series(name: str, df: Any, time: str, scale: float, temp: str) -> TemperatureSeries:
    """A table's time (× ``scale`` → s) and temperature columns as a series."""
    return TemperatureSeries(
        name,
        np.asarray(df[time].to_numpy(), dtype=np.float64) * scale,
        np.asarray(df[temp].to_numpy(), dtype=np.float64),
    )


def px4_plan(
    flight: Any, temperature: TemperatureMode, temps_from: TempsFrom | None
) -> ThermometerPlan:
    """The plan of a PX4 log: the borrowed series read (``sensor_gyro.N`` and
    ``sensor_accel.N`` for an instance, the first ``sensor_baro`` for ``"baro"``).

    Parameters
    ----------
    flight : thermocal.tempcal.flightlog.FlightLog
        The log, read once.
    temperature : {"reconstructed", "raw"}
        How the temperature is used.
    temps_from : TempsFrom or None
        The thermometer borrowed.

    Returns
    -------
    ThermometerPlan

    Raises
    ------
    ThermocalInputError
        ``temps_from`` names an instance the log does not hold with a temperature.
    """
    if temps_from is None:
        return ThermometerPlan(temperature)
    have = {f"{n}.{i}" for n, i in flight.instances}
    if temps_from.source == "baro":
        baros = sorted(k for k in have if k.startswith("sensor_baro."))
        if not baros:
            raise missing_source(flight.path, "sensor_baro", sorted(have))
        df, _info = flight.table(baros[0])
        one = _series(baros[0], df, "timestamp", 1e-6, "temperature")
        return ThermometerPlan(temperature, temps_from, {"gyro": one, "accel": one})
    series = {}
    for kind, topic in (("gyro", "sensor_gyro"), ("accel", "sensor_accel")):
        name = f"{topic}.{temps_from.source}"
        if name in have:
            df, _info = flight.table(name)
            series[kind] = _series(name, df, "timestamp", 1e-6, "temperature")
    if not series:
        raise missing_source(
            flight.path, f"sensor_gyro/sensor_accel instance {temps_from.source}", sorted(have)
        )
    return ThermometerPlan(temperature, temps_from, series)


def ardupilot_plan(
    flight: Any, temperature: TemperatureMode, temps_from: TempsFrom | None
) -> ThermometerPlan:
    """The plan of an ArduPilot log: the borrowed series read (``IMU`` instance N's ``T``
    for both its sensors, ``BARO`` instance 0's ``Temp`` for ``"baro"``).

    Parameters
    ----------
    flight : thermocal.tempcal.flightlog.DataflashFlightLog
        The log, read once.
    temperature : {"reconstructed", "raw"}
        How the temperature is used.
    temps_from : TempsFrom or None
        The thermometer borrowed.

    Returns
    -------
    ThermometerPlan

    Raises
    ------
    ThermocalInputError
        ``temps_from`` names an instance the log does not hold with a temperature.
    """
    from thermocal.errors import MissingColumnError

    if temps_from is None:
        return ThermometerPlan(temperature)
    msg, inst = ("BARO", 0) if temps_from.source == "baro" else ("IMU", int(temps_from.source))
    try:  # only the fields read: the log's other fields are not copied
        df, _info = flight.table(msg, inst, ("T", "Temp"))
    except MissingColumnError:
        df = None
    col = next((c for c in ("T", "Temp") if df is not None and c in df.columns), None)
    if df is None or col is None:
        raise missing_source(flight.path, f"{msg}.{inst}", _ardupilot_have(flight))
    one = _series(f"{msg}.{inst}", df, "TimeUS", 1e-6, col)
    return ThermometerPlan(temperature, temps_from, {"gyro": one, "accel": one})


def _ardupilot_have(flight: Any) -> list[str]:
    """The IMU and BARO instances of a DataFlash log."""
    from thermocal.errors import MissingColumnError

    found = []
    for msg, n in (("IMU", 3), ("BARO", 1)):
        for i in range(n):
            try:
                flight.table(msg, i, ("T", "Temp"))
            except MissingColumnError:
                break
            found.append(f"{msg}.{i}")
    return found


def record_thermometer(fit: Any, record: dict[str, Any], own: str) -> str | None:
    """Record what was done to the temperature on a fit and its channels' ``inputs``.

    Parameters
    ----------
    fit : thermocal.tempcal.pipeline.SensorFit
        The instance's fit (its ``thermometer`` set, each channel's model ``inputs_``
        given ``thermometer``).
    record : dict
        What :func:`sensor_temperature` returned.
    own : str
        The name of the sensor's own thermometer (``sensor_gyro.0``, ``IMU.0``), as given to
        :func:`sensor_temperature`.

    Returns
    -------
    str or None
        The sentence for the parameter file's notes (None: an own, continuous thermometer).
    """
    fit.thermometer = dict(record)
    for ch in fit.channels:
        ch.model.inputs_ = {**(ch.model.inputs_ or {}), "thermometer": dict(record)}
    if not record:
        return None
    borrowed = record.get("source") not in (None, own)
    if not borrowed and not record.get("note"):
        return None
    parts = []
    if borrowed:
        parts.append(
            f"calibrated against {record['source']}'s thermometer (in flight the firmware "
            "compensates with this sensor's own: the two must read alike)"
        )
    if record.get("note"):
        parts.append(str(record["note"]))
    return f"{own}: " + "; ".join(parts)


__all__ = [
    "TEMPERATURE_MODES",
    "TemperatureMode",
    "TemperatureSeries",
    "TempsFrom",
    "ThermometerPlan",
    "ardupilot_plan",
    "missing_source",
    "px4_plan",
    "record_thermometer",
    "sensor_temperature",
]
