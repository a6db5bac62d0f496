"""PX4's whole thermal calibration from one ULog: ``thermocal px4-tempcal``.

The PX4 dialect of the one pipeline (:mod:`thermocal.tempcal.pipeline`): the topics
``sensor_gyro``/``sensor_accel`` (and ``sensor_baro``/``sensor_mag`` as offsets), the ``TC_*``
parameters, the reference temperature TREF (mid-range unless given).

PX4's ``Tools/process_sensor_caldata.py`` fits, for every ``sensor_gyro`` and
``sensor_accel`` instance, a cubic per axis in ``T − TREF`` (TREF mid-range; accelerometers
relative to their median because gravity is in the data) and writes ``TC_*`` parameters.
thermocal does the same with three differences (each stated in the summary):

* **equal weight across the temperature range**: the samples are first reduced to the
  median of each temperature bin (:func:`thermocal.firmware.binning.temperature_bins`), so a
  slow end of the sweep does not outweigh a fast middle — PX4 bins the temperature for the
  same reason;
* **robust to spikes**: the bin statistic is the median, not the mean;
* **judged on data it was not fitted to**: a cubic fitted on the even bins is evaluated on
  the odd ones (hold-out rms per axis, in the report and the JSON), before the final fit on
  every bin.

The fitted cubics form a calibration (one channel per axis, roles gyro/accel x/y/z, in the
log's units rad/s and m/s²); :func:`thermocal.export.params.export_params` writes the
parameter file.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import adequacy
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.firmware.formats import FORMATS
from thermocal.firmware.px4 import px4_coefficients
from thermocal.heater import HeaterOptions
from thermocal.models.calibration import Calibration
from thermocal.outputs import check_outputs
from thermocal.recording import FloatArray, Recording
from thermocal.tempcal.compare import CoefficientComparison, px4_comparison
from thermocal.tempcal.flightlog import FlightLog, open_px4_log
from thermocal.tempcal.learning import Px4Emulation, px4_overall
from thermocal.tempcal.pipeline import (
    AXES,
    OutputSet,
    Reporter,
    ReportRequest,
    SensorFit,
    calibration_of,
    check_output_dir,
    end_warning,
    fit_sensor,
    gyro_unit_warning,
    report_worker,
    require_fields,
    staged_set,
    stall_warning,
    step_warnings,
    summary,
    warn_gates,
)
from thermocal.tempcal.thermometers import (
    TemperatureMode,
    TempsFrom,
    ThermometerPlan,
    px4_plan,
    record_thermometer,
    sensor_temperature,
)

TOPICS = ("sensor_gyro", "sensor_accel")


# --- barometers and magnetometers --------------------------------------------------------

OFFSET_TOPICS = {"sensor_baro": ("baro", ("pressure",), "Pa"), "sensor_mag": ("mag", AXES, "gauss")}
"""PX4 topics calibrated as offsets in the firmware's unit (uORB ``SensorBaro.msg`` pressure
[Pa], ``SensorMag.msg`` x, y, z [gauss]) with the polynomial order of their parameters
(:data:`thermocal.firmware.formats.FORMATS`: 5 for TC_B, 3 for TC_M)."""


@dataclass(frozen=True)
class OffsetFit:
    """A barometer or magnetometer instance: the polynomial about ``tref_c`` per axis
    (``coefficients[axis][k]`` of ``(T − TREF)^k`` [unit], relative to the median of the
    log — the weather's pressure and the Earth's field are in the data, as PX4's own script
    fits them), judged like the IMU on held-out temperature bins (``holdout_rms`` [unit]).

    Attributes
    ----------
    topic, kind : str
        The log topic and the sensor kind (barometer or magnetometer).
    instance, device_id : int
        The instance and its device id.
    unit : str
        Its unit.
    sweep_c : (float, float)
        Its temperature sweep [°C].
    tref_c : float
        Reference temperature [°C].
    n_samples, n_bins : int
        Samples and temperature bins.
    order : int
        Polynomial order.
    coefficients : tuple of tuple of float
        ``coefficients[axis][k]`` [unit/°C^k].
    holdout_rms : dict of str to float
        Per axis, the hold-out rms [unit].
    adequacy : dict
        The data's judgement.
    """

    topic: str
    kind: str
    instance: int
    device_id: int
    unit: str
    sweep_c: tuple[float, float]
    tref_c: float
    n_samples: int
    n_bins: int
    order: int
    coefficients: tuple[tuple[float, ...], ...]
    holdout_rms: dict[str, float]
    adequacy: dict[str, Any]


def fit_offset_sensor(
    time_s: FloatArray,
    temp_c: FloatArray,
    values: FloatArray,
    topic: str,
    instance: int,
    device_id: int,
    *,
    tref_c: float | None = None,
    overrides: tuple[str, ...] = (),
) -> OffsetFit:
    r"""Judge, then fit PX4's polynomial to one barometer or magnetometer.

    Judged by :func:`thermocal.adequacy.judge` (sweep, bins, ends), then fitted by
    :func:`thermocal.firmware.px4.px4_coefficients` (medians of 0.5 °C bins, equal weight
    across the range, robust to spikes; judged on held-out bins; a polynomial of PX4's order in
    ``T − TREF``, fitted to every bin).

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    temp_c : numpy.ndarray
        Temperatures [°C].
    values : numpy.ndarray
        Values (n, axes) in the topic's unit (:data:`OFFSET_TOPICS`: Pa or gauss).
    topic : str
        The ULog topic (a key of :data:`OFFSET_TOPICS`).
    instance : int
        Topic instance.
    device_id : int
        PX4's device id of the sensor.
    tref_c : float, optional
        ``TC_*_TREF`` [°C]; default mid-range.
    overrides : tuple of str, optional
        Adequacy tests the user accepts anyway.

    Returns
    -------
    OffsetFit
        Sweep and TREF [°C], counts, coefficients ``X_k`` [unit/°C^k], hold-out rms per axis.

    Raises
    ------
    ThermocalInputError
        When the data are judged inadequate (not overridden) or the temperature cannot carry
        the polynomial.

    Notes
    -----
    Per axis, least squares over the bin medians :math:`(T_j, v_j)`:

    .. math:: \min_X \sum_j \Big(v_j - \sum_{k=0}^{n} X_k (T_j - T_{ref})^k\Big)^2

    References
    ----------
    - PX4 ``Tools/process_sensor_caldata.py`` and
      ``src/modules/sensors/temperature_compensation/TemperatureCompensation.cpp``.
    """
    kind, fields, unit = OFFSET_TOPICS[topic]
    order = FORMATS["px4"].sensors[kind].order
    where = f"{topic}.{instance}"
    vals = np.asarray(values, dtype=np.float64).reshape(len(temp_c), -1)
    temp = np.asarray(temp_c, dtype=np.float64)
    tname = f"{where} temperature"
    record = (
        adequacy.judge(
            adequacy.Needs({tname: order}, order + 1), [np.asarray(time_s, dtype=np.float64)],
            [temp.reshape(-1, 1)], [tname], kind=kind, name=where, overrides=overrides,
        )
        .enforce()
        .to_dict()
    )  # fmt: skip
    try:
        fit = px4_coefficients(temp, vals, kind=kind, tref_c=tref_c)
    except ParameterError as exc:
        if exc.parameter != "temperature_c":
            raise
        raise ThermocalInputError(f"{where}: {exc.named('the temperature')}") from None
    names = fields if len(fields) > 1 else ("pressure",)
    return OffsetFit(
        topic, kind, instance, device_id, unit, (fit.tmin_c, fit.tmax_c), fit.tref_c,
        fit.n_samples, fit.n_bins, order, fit.coefficients,
        dict(zip(names, fit.holdout_rms, strict=True)), record,
    )  # fmt: skip


def offset_summary(fits: Sequence[OffsetFit]) -> dict[str, Any]:
    """The JSON summary of the barometers and magnetometers.

    Parameters
    ----------
    fits : sequence of OffsetFit
        The fitted sensors.

    Returns
    -------
    dict
        ``TOPIC.N`` → the fields of :class:`OffsetFit` plus ``holdout_rms_unit``.
    """
    return {
        f"{f.topic}.{f.instance}": {**dataclasses.asdict(f), "holdout_rms_unit": f.unit}
        for f in fits
    }


# --- the whole command -----------------------------------------------------------------------


@dataclass(frozen=True)
class Px4TempcalResult:
    """What :func:`px4_tempcal` wrote and found: the files of the set, every IMU instance's
    fit, every barometer/magnetometer's, the notes of the parameter file.

    Attributes
    ----------
    log : Path
        The log read.
    params_path, calibration_path : Path
        The parameter file and the calibration file.
    reports : tuple of Path
        The HTML reports.
    fits : tuple of SensorFit
        Every IMU instance's fit.
    offset_fits : tuple of OffsetFit
        Every barometer's and magnetometer's.
    notes : tuple of str
        The parameter file's notes.
    previous : dict of str to CoefficientComparison
        Per sensor, the log's ``TC_*`` against the new ones.
    """

    log: Path
    params_path: Path
    calibration_path: Path
    reports: tuple[Path, ...]
    fits: tuple[SensorFit, ...]
    offset_fits: tuple[OffsetFit, ...]
    notes: tuple[str, ...]
    previous: dict[str, CoefficientComparison] = dataclasses.field(default_factory=dict)
    """Per sensor, the log's ``TC_*`` for its device against the new ones."""
    emulated_learning: dict[str, Px4Emulation] = dataclasses.field(default_factory=dict)
    """Per gyro and accelerometer instance, PX4's on-board temperature calibration emulated
    on the log (``emulate_learning``; :mod:`thermocal.tempcal.learning`)."""

    def to_dict(self) -> dict[str, Any]:
        """The result as a JSON object (what the ``px4-tempcal`` command prints as JSON)."""
        return {
            "log": str(self.log),
            "params": str(self.params_path),
            "calibration": str(self.calibration_path),
            "reports": [str(p) for p in self.reports],
            "sensors": {
                k: {**v, "previous": p.to_dict() if (p := self.previous.get(k)) else None}
                for k, v in {**summary(self.fits), **offset_summary(self.offset_fits)}.items()
            },
            "notes": list(self.notes),
        } | (
            {"emulated_learning": px4_overall(self.emulated_learning)}
            if self.emulated_learning
            else {}
        )


NO_SENSOR = "no sensor_gyro or sensor_accel topic with a temperature in the log"
NO_ALLAN = (
    "The Allan deviation of each axis is not drawn; "
    "thermocal px4-tempcal LOG -o DIR --allan draws it."  # cli-words: the command that draws it
)
"""The report's note when its Allan section is left out (``allan`` False)."""


def px4_tempcal(
    log: Path,
    output: Path,
    *,
    tref_c: float | None = None,
    overrides: tuple[str, ...] = (),
    reporter: Reporter | None = None,
    allan: bool = False,
    heater: HeaterOptions | None = None,
    emulate_learning: bool = False,
    temperature: TemperatureMode = "reconstructed",
    temps_from: TempsFrom | None = None,
) -> Px4TempcalResult:
    """PX4's thermal calibration of every sensor instance of a ULog, written as one set.

    Parameters
    ----------
    log : Path
        A PX4 ULog recorded with the thermal-calibration logging profile (``sensor_gyro``,
        ``sensor_accel``, ``sensor_baro``, ``sensor_mag`` with their temperatures).
    output : Path
        The directory of the set: ``calibration.json``, ``px4.params`` (``TC_*``) and
        ``report_<topic>_<n>.html`` per instance; built beside it and moved into place whole.
    tref_c : float, optional
        ``TREF`` of every polynomial [°C]; default the middle of each instance's range.
    overrides : tuple of str
        Adequacy checks let through (``"narrow"``, ``"motion"``).
    reporter : callable, optional
        Writes one report (the presentation layer's); None: no report written.
    allan : bool, optional
        The gyro and accelerometer reports draw each axis's overlapping Allan deviation
        before and after compensation with its noise terms (IEEE Std 952-1997 Annex C);
        default False: left out (on a long log, most of a report's cost).
    heater : HeaterOptions, optional
        How a heater's hold is looked for (default: the set-point ``SENS_IMU_TEMP`` when
        ``SENS_EN_THERMAL`` is on, else inferred; ±0.5 °C for 60 s; a cut range said,
        :class:`thermocal.heater.HeaterOptions`), in the temperature fitted on
        (``temperature``, ``temps_from``).
    emulate_learning : bool, optional
        Also emulate PX4's on-board temperature calibration (``SYS_CAL_TDEL``,
        ``SYS_CAL_TMIN``, ``SYS_CAL_TMAX`` from the log, else PX4's defaults) on each gyro
        and accelerometer instance (:func:`thermocal.tempcal.learning.emulate_px4`);
        default False.
    temperature : {"reconstructed", "raw"}, optional
        A quantised or slow thermometer (:mod:`thermocal.thermometer`) is fitted on the
        temperature reconstructed at each sample (default), or on its reading as logged.
    temps_from : TempsFrom, optional
        Calibrate against another instance's (or the first barometer's) thermometer, joined
        by time (:func:`.thermometers.sensor_temperature`); default each its own.

    Returns
    -------
    Px4TempcalResult
        The files written, each instance's fit and hold-out rms, the notes of the
        parameter file, the log's previous ``TC_*`` compared with the new ones.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        An unreadable log, no sensor with a temperature, data that cannot support the fit
        (sweep, bins, motion) unless overridden, an output that is the log or not a
        directory.

    Notes
    -----
    The log is read once into a :class:`~thermocal.tempcal.flightlog.FlightLog`.  Each IMU
    instance goes through the pipeline (:func:`.pipeline.fit_sensor`: a cubic per axis in
    the temperature, fitted to the medians of 0.5 °C bins); barometers and magnetometers
    are offsets (:func:`fit_offset_sensor`, :func:`thermocal.firmware.px4.px4_coefficients`).
    The firmware subtracts, per axis,

    .. math::

        o(T) = \\sum_{k=0}^{n} X_k\\,(\\operatorname{clamp}(T, T_\\mathrm{min},
        T_\\mathrm{max}) - T_\\mathrm{ref})^k .

    References
    ----------
    * PX4-Autopilot, ``Tools/process_sensor_caldata.py``,
      https://github.com/PX4/PX4-Autopilot/blob/main/Tools/process_sensor_caldata.py
    * PX4-Autopilot, ``src/modules/temperature_compensation/TemperatureCompensation.cpp``,
      https://github.com/PX4/PX4-Autopilot/tree/main/src/modules/temperature_compensation
    """

    # DIR may hold the log; the files of the set (replaced by name) may not be it
    check_outputs(
        [output / "calibration.json", output / FORMATS["px4"].params_file], [log], dirs=[output]
    )
    check_output_dir(output)
    with (
        report_worker(reporter, log) as pool,  # starts while the log is read
        open_px4_log(log, (*TOPICS, *OFFSET_TOPICS)) as flight,  # the log is parsed once
    ):
        return _px4_tempcal(
            flight, output, tref_c, overrides, reporter, pool, allan,
            heater or HeaterOptions(), {} if emulate_learning else None,
            px4_plan(flight, temperature, temps_from),
        )  # fmt: skip


def _px4_tempcal(
    flight: FlightLog,
    output: Path,
    tref_c: float | None,
    overrides: tuple[str, ...],
    reporter: Reporter | None,
    pool: Any = None,
    allan: bool = False,
    heater: HeaterOptions | None = None,
    emulated: dict[str, Px4Emulation] | None = None,
    plan: ThermometerPlan | None = None,
) -> Px4TempcalResult:
    """:func:`px4_tempcal` after its output checks (``pool``: the report worker;
    ``emulated``: filled with the on-board calibration emulated, when given; ``plan``: the
    temperature each instance is fitted on)."""
    from thermocal.export.params import ParamSet

    log, topics = flight.path, flight.instances
    if not topics:
        raise ThermocalInputError(f"{log}: {NO_SENSOR}")
    check_outputs([output / f"report_{n}_{i}.html" for n, i in topics], [log], dirs=[output])
    fits: list[SensorFit] = []
    offset_fits: list[OffsetFit] = []
    gates: list[str | None] = []
    heater_said: dict[int, dict[str, tuple[str, ...]]] = {}
    series: dict[str, tuple[FloatArray, FloatArray]] = {}
    motions: dict[str, adequacy.Motion] = {}
    params = ParamSet("px4")
    old = _Prior(_tc_in_force(flight, params.notes), {})  # the TC_* the log was recorded with
    with staged_set(output, reporter, pool) as out_set:  # moved into place whole, or removed
        for name, inst in topics:
            if name in OFFSET_TOPICS:  # barometers and magnetometers: TC_B / TC_M
                ofit = _offset_instance(
                    flight, name, inst, tref_c, overrides, params, out_set, old, gates
                )
                if ofit is not None:
                    offset_fits.append(ofit)
                continue
            fit, more, heat = _imu_instance(
                flight, name, inst, tref_c, overrides, params, out_set, (series, motions), old,
                allan, heater or HeaterOptions(), emulated, plan or ThermometerPlan(),
            )  # fmt: skip
            fits.append(fit)
            heater_said.setdefault(inst, {})[name] = heat
            gates.extend(more)
        gates.extend(_heater_warnings(heater_said))
        gates.extend(step_warnings(fits, series, motions))
        warn_gates(gates)
        if not fits:
            raise ThermocalInputError(f"{log}: {NO_SENSOR}")
        out_set.commit(calibration_of(fits), FORMATS["px4"].params_file, params.text())
    if any(f.kind == "accel" for f in fits):
        params.notes.append(
            "accelerometers: offsets relative to mid-range (gravity is in the data), as PX4's "
            "own script does"
        )
    return Px4TempcalResult(
        log, output / FORMATS["px4"].params_file, output / "calibration.json",
        tuple(out_set.reports),
        tuple(fits), tuple(offset_fits), tuple(params.notes), old.found, emulated or {},
    )  # fmt: skip


def _tc_in_force(flight: FlightLog, notes: list[str]) -> dict[str, float]:
    """The log's parameters the new ``TC_*`` are compared with: the initial ones
    (``flight.parameters``) updated by every ``TC_*`` changed during the recording
    (``flight.parameter_changes``), i.e. those
    in force at the end of the log, the board's calibration the new one replaces.  PX4 logs
    ``sensor_gyro``/``_accel``/``_baro``/``_mag`` before its temperature compensation
    (applied downstream, sensors/vehicle_imu), so such a change leaves the data as they are;
    each is said in ``notes`` (name, old → new, log time) with the values compared."""
    params = dict(flight.parameters)
    said: list[str] = []
    for t, name, value in flight.parameter_changes:
        before = params.get(name)
        if name.startswith("TC_") and before is not None and before != value:
            said.append(f"{name} {before:g} → {value:g} at log time {t:.3f} s")
        params[name] = value
    if said:
        notes.append(
            "TC_* parameters changed during the recording (" + "; ".join(said) + "): the "
            "logged sensor data are uncompensated, so the fit is unaffected; the coefficients "
            "compared (previous) are those in force at the end of the log"
        )
    return params


@dataclass(frozen=True)
class _Prior:
    """The log's parameters (:attr:`.flightlog.FlightLog.parameters`) and,
    per sensor, its ``TC_*`` compared with the new ones (:func:`.compare.px4_comparison`)."""

    params: dict[str, float]
    found: dict[str, CoefficientComparison]

    def compare(
        self, key: str, new: dict[str, float], kind: str, inst: int, device_id: int, unit: str,
        sweep_c: tuple[float, float],
    ) -> CoefficientComparison | None:  # fmt: skip
        """Compare and remember sensor ``key``'s old and new parameters (None: none old)."""
        cmp = px4_comparison(self.params, new, kind, inst, device_id, unit, sweep_c)
        if cmp is not None:
            self.found[key] = cmp
        return cmp


def _offset_instance(
    flight: FlightLog,
    name: str,
    inst: int,
    tref_c: float | None,
    overrides: tuple[str, ...],
    params: Any,
    out_set: OutputSet,
    old: _Prior,
    gates: list[str | None],
) -> OffsetFit | None:
    """A barometer or magnetometer instance: read, judged by the gates of
    :mod:`.offset_gates` (implausible: left out, None, its sentence in ``gates``; odd samples
    set aside, said in ``gates``), fit (:func:`fit_offset_sensor`), its ``TC_B``/``TC_M``
    parameters merged into ``params``, its report (:func:`.offset_report.offset_report_request`)."""
    from thermocal.export.params import px4_offset_params
    from thermocal.tempcal.offset_gates import screen_baro, screen_mag
    from thermocal.tempcal.offset_report import offset_report_request

    log = flight.path
    df, _info = flight.table(f"{name}.{inst}")
    fields = OFFSET_TOPICS[name][1]
    require_fields(df, ["timestamp", "temperature", *fields], log, f"{name}.{inst}")
    ids = df["device_id"].to_numpy() if "device_id" in df.columns else np.zeros(1)
    time_s, temp_c, values = (
        df["timestamp"].to_numpy() * 1e-6, df["temperature"].to_numpy(),
        np.column_stack([df[f].to_numpy() for f in fields]),
    )  # fmt: skip
    screen = screen_baro if name == "sensor_baro" else screen_mag
    judged = screen(f"{log}: {name}.{inst}", time_s, temp_c, values)
    gates.extend(judged.notes)
    if judged.keep is None:
        gates.append(judged.left_out)
        return None
    time_s, temp_c, values = time_s[judged.keep], temp_c[judged.keep], values[judged.keep]
    ofit = fit_offset_sensor(
        time_s, temp_c, values, name, inst,
        int(np.median(ids)), tref_c=tref_c, overrides=overrides,
    )  # fmt: skip
    ps = px4_offset_params(
        ofit.kind, inst, ofit.device_id, *ofit.sweep_c, ofit.tref_c, ofit.coefficients
    )
    params.merge(ps, f"{name}.{inst}")
    prev = old.compare(
        f"{name}.{inst}", ps.params, ofit.kind, inst, ofit.device_id, ofit.unit, ofit.sweep_c
    )
    out_set.report(
        f"report_{name}_{inst}.html",
        offset_report_request(ofit, temp_c, values, str(log), "thermocal px4-tempcal", prev),
    )
    return ofit


def _heater_warnings(said: dict[int, dict[str, tuple[str, ...]]]) -> list[str]:
    """The heater's warnings once per IMU: instance i's gyro and accelerometer are one chip
    on one heater; the gyro's said, else the accelerometer's."""
    out: list[str] = []
    for _, by_topic in sorted(said.items()):
        out.extend(by_topic.get("sensor_gyro") or by_topic.get("sensor_accel") or ())
    return out


def _imu_instance(
    flight: FlightLog,
    name: str,
    inst: int,
    tref_c: float | None,
    overrides: tuple[str, ...],
    params: Any,
    out_set: OutputSet,
    found: tuple[dict[str, tuple[FloatArray, FloatArray]], dict[str, adequacy.Motion]],
    old: _Prior,
    allan: bool = False,
    heater: HeaterOptions | None = None,
    emulated: dict[str, Px4Emulation] | None = None,
    plan: ThermometerPlan | None = None,
) -> tuple[SensorFit, list[str | None], tuple[str, ...]]:
    """A gyro or accelerometer instance through the pipeline: read, fit, its gates (its
    heater's warnings apart: said once per IMU by the caller), its
    ``TC_G``/``TC_A`` parameters merged into ``params``, its report (``allan``: with its
    Allan section); ``found`` (series, motions) gets its (time [s], x/y/z in the canonical
    unit) and its stillness result for the step check across instances; ``heater``: how its
    heater's hold is looked for (:func:`.heated.judge_instance`) in the temperature fitted
    on; ``plan``: that temperature (reconstructed, or borrowed)."""
    from thermocal.export.params import export_params
    from thermocal.readers.ulog import release_parsed_topic
    from thermocal.tempcal.heated import judge_instance

    kind = "gyro" if name == "sensor_gyro" else "accel"
    where = f"{name}.{inst}"
    log = flight.path
    rec = flight.recording(where)
    release_parsed_topic(log, where)  # read once: its raw messages are not needed again
    series, motions = found
    logged = rec if emulated is not None else None  # the firmware learns on its own, as logged
    rec, thermo = _planned_temperature(rec, where, kind, inst, plan or ThermometerPlan())
    temp_c = rec.temperature_c("temperature")
    held = judge_instance(
        f"{log}: {where}", rec.time_s, temp_c, flight.parameters, "px4",
        heater or HeaterOptions(), own_minus_c=thermo.get("own_minus_source_c"),
    )  # fmt: skip
    fit = fit_sensor(rec, name, kind, inst, overrides=overrides, motions=motions)
    fit.heater = held.to_dict()
    said = record_thermometer(fit, thermo, where)
    # the step check across instances reads the stillness result (motions), not the values
    series[where] = (rec.time_s, np.empty((0, len(AXES))))
    gates: list[str | None] = []
    if held.hold is None or held.hold.setpoint_source == "inferred":  # a stall, or a heater?
        gates.append(stall_warning(where, rec.time_s, temp_c))
    if kind == "gyro":
        vals = np.column_stack([rec.signal(a)[0] for a in AXES])
        gates.append(gyro_unit_warning(f"{log}: {where}", vals))
        del vals
    if tref_c is not None:
        gates.append(end_warning(where, "TREF", tref_c, *fit.sweep_c))
    sub = Calibration(fit.channels)
    with warnings.catch_warnings():  # accelerometers: relative offsets, as PX4's script
        warnings.simplefilter("ignore")
        ps = export_params(
            sub, "px4", instance=inst, device_id={kind: fit.device_id}, tref_c=tref_c
        )
    params.merge(ps, where)
    params.notes.extend([said] if said else [])
    params.notes.extend(f"{where}: {n}" for n in held.notes if held.hold is not None)
    prev = old.compare(
        where, ps.params, kind, inst, fit.device_id, "rad/s" if kind == "gyro" else "m/s^2",
        fit.sweep_c,
    )  # fmt: skip
    em = None if logged is None else _emulate(flight, logged, where, kind, inst, fit, ps.params)
    if em is not None and emulated is not None:
        emulated[where] = em
    shown = (*AXES, "temperature")  # what the report reads: the device id column left here
    rec = dataclasses.replace(
        rec, columns={k: v for k, v in rec.columns.items() if k in shown},
        units={k: u for k, u in rec.units.items() if k in shown},
    )  # fmt: skip
    out_set.report(
        f"report_{name}_{inst}.html",
        ReportRequest(
            calibration=sub, recording=rec, recording_path=str(log),
            title=f"PX4 thermal calibration — {where}",
            sensor=f"device id {fit.device_id}", generated_by="thermocal px4-tempcal",
            extra={"hold-out rms": dict(zip(
                [c.name for c in fit.channels], fit.holdout_rms.values(), strict=True
            ))},
            notes=(
                "Each axis: a cubic in the temperature fitted to the medians of 0.5 °C "
                "temperature bins (equal weight across the range, robust to spikes); "
                "'hold-out rms' is the rms of a cubic fitted to the even bins on the odd "
                "ones, in the canonical unit (°/h or mg).",
                *(f"Firmware: {n}" for n in ps.notes),
                *((f"Temperature: {said}",) if said else ()),
                *(f"Heater: {n}" for n in held.notes),
                *(() if allan else (NO_ALLAN,)),
            ),
            previous=prev,
            allan=allan,
            emulated_learning=None if em is None else em.against_thermocal,
        ),
    )  # fmt: skip
    return fit, gates, held.warnings


def _planned_temperature(
    rec: Recording, where: str, kind: str, inst: int, plan: ThermometerPlan
) -> tuple[Recording, dict[str, Any]]:
    """Instance ``where``'s recording with the temperature it is fitted on (``plan``: its
    own reconstructed when coarse or slow, or another's joined by time) and what was done
    (:func:`.thermometers.sensor_temperature`)."""
    return sensor_temperature(
        rec, where, temperature=plan.temperature, source=plan.source_for(kind, inst)
    )


def _emulate(
    flight: FlightLog, rec: Recording, where: str, kind: str, inst: int, fit: SensorFit,
    new_params: Any,
) -> Px4Emulation:  # fmt: skip
    """PX4's on-board calibration of one instance emulated on its samples in PX4's units
    (rad/s, m/s²; the time since boot)."""
    from thermocal.tempcal.learning import emulate_px4
    from thermocal.units import convert

    unit = "rad/s" if kind == "gyro" else "m/s^2"
    vals = np.column_stack([convert(*rec.signal(a), unit, where) for a in AXES])
    return emulate_px4(
        kind, inst, rec.time_s, vals, rec.temperature_c("temperature"),
        parameters=flight.parameters, new_params=new_params, device_id=fit.device_id,
    )  # fmt: skip


__all__ = [
    "OFFSET_TOPICS",
    "TOPICS",
    "OffsetFit",
    "Px4TempcalResult",
    "fit_offset_sensor",
    "offset_summary",
    "px4_tempcal",
]
