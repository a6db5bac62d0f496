"""The one pipeline of ``px4-tempcal`` and ``ardupilot-tempcal``; the firmware dialects
(:mod:`.px4`, :mod:`.ardupilot`) say which topics or messages hold the sensors, what the
parameters are called and about which temperature the polynomial is written.

Per sensor instance, three axes:

1. **judge the data** (:func:`thermocal.adequacy.judge`: a cubic's sweep, the sensor still,
   the firmware's minimum sweep): refused or stated before anything is fitted;
2. **bin** (:func:`.binning.temperature_bins`): the medians of 0.5 °C temperature bins, equal
   weight across the range, robust to spikes;
3. **hold-out check**: a cubic fitted to the even bins is evaluated on the odd ones (rms per
   axis, in the canonical unit °/h or mg);
4. **fit** a cubic per axis to every bin: a calibration channel (roles gyro/accel x/y/z);
5. **gates** (:func:`stall_warning`, :func:`step_warnings`, :func:`end_warning`): a usable
   but doubtful log is said in a :class:`GateWarning`;
6. **the output set** (calibration, firmware parameters, one report per sensor) is built in a
   staging directory and moved into place whole (:class:`OutputSet`), or removed.
"""

from __future__ import annotations

import contextlib
import dataclasses
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal import adequacy, units
from thermocal.errors import ThermocalInputError, ThermocalWarning
from thermocal.firmware.binning import BIN_WIDTH_C, MIN_BINS, even_odd_split, temperature_bins
from thermocal.models.calibration import Calibration, Channel
from thermocal.models.poly import PolyModel
from thermocal.models.rundata import RunData, model_inputs
from thermocal.recording import FloatArray, Recording
from thermocal.tempcal.ardupilot_baro import ArdupilotBaroReportRequest
from thermocal.tempcal.compare import CoefficientComparison
from thermocal.tempcal.offset_report import OffsetReportRequest

MIN_SWEEP_C = adequacy.ARDUPILOT_MIN_SPAN_C
"""ArduPilot's learning requires a 10 °C sweep (the firmware minimum of the adequacy check)."""
AXES = ("x", "y", "z")


@dataclass
class SensorFit:
    """One sensor instance: its topic, device id, sweep, per-axis hold-out rms [its unit].

    Attributes
    ----------
    topic : str
        The log topic.
    kind : str
        The sensor kind (gyroscope or accelerometer).
    instance : int
        The instance.
    device_id : int
        Its device id.
    unit : str
        Its unit.
    sweep_c : (float, float)
        Its temperature sweep [°C].
    n_samples, n_bins : int
        Samples and temperature bins.
    holdout_rms : dict of str to float
        Per axis, the rms of the odd bins about the even bins' fit [``unit``].
    channels : list of Channel
        The fitted channels.
    adequacy : dict
        The data's judgement.
    thermometer : dict
        The temperature fitted on: its thermometer (lattice step, update period), whether
        reconstructed, and whose (:func:`.thermometers.sensor_temperature`).
    heater : dict or None
        The heater's hold (:class:`thermocal.heater.HeaterHold`), None: none found.
    """

    topic: str
    kind: str
    instance: int
    device_id: int
    unit: str
    sweep_c: tuple[float, float]
    n_samples: int
    n_bins: int
    holdout_rms: dict[str, float] = field(default_factory=dict)
    channels: list[Channel] = field(default_factory=list)
    adequacy: dict[str, Any] = field(default_factory=dict)
    thermometer: dict[str, Any] = field(default_factory=dict)
    heater: dict[str, Any] | None = None
    """The heater's hold found in its temperature (:meth:`thermocal.heater.HeaterHold.to_dict`),
    None: none."""


def _cubic(t: FloatArray, y: FloatArray, unit: str, name: str) -> PolyModel:
    """A cubic in T fitted to bin medians (the bins are the samples; their index the time)."""
    run = RunData(
        time_s=np.arange(t.size, dtype=np.float64),
        temps_c=t.reshape(-1, 1),
        signal=y,
        temp_names=("temperature",),
        name=name,
        signal_unit=unit,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # bin medians: few samples, correlated by design
        return PolyModel(order=3, per_run_offset=False).fit([run])


def holdout_rms(t_med: FloatArray, v_med: FloatArray, unit: str, name: str) -> float:
    r"""The rms of a cubic fitted to the even temperature bins, evaluated on the odd ones.

    Parameters
    ----------
    t_med : numpy.ndarray
        Bin median temperatures, ascending [°C].
    v_med : numpy.ndarray
        Bin median values of one axis, same length [``unit``].
    unit : str
        Unit of ``v_med`` (canonical: ``°/h`` or ``mg``).
    name : str
        Name given to the fitted channel.

    Returns
    -------
    float
        Hold-out rms [``unit``].

    Notes
    -----
    With :math:`p_{even}` the cubic least-squares fit to the even bins
    (:func:`thermocal.firmware.binning.even_odd_split`):

    .. math:: \mathrm{rms} = \sqrt{\tfrac{1}{n_{odd}} \sum_{i \in odd}
       \left(v_i - p_{even}(T_i)\right)^2}

    References
    ----------
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., Johns Hopkins
      University Press, 2013 (linear least squares).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(20.0, 60.0, 81)
    >>> v = 5.0 + 0.2 * t - 0.001 * t**2
    >>> round(holdout_rms(t, v, "°/h", "g0_x"), 6)
    0.0
    """
    even, odd = even_odd_split(t_med.size)
    held = _cubic(t_med[even], v_med[even], unit, name)
    run_odd = RunData(
        np.arange(odd.size, dtype=np.float64), t_med[odd].reshape(-1, 1), None, ("temperature",)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pred = held.predict(run_odd)
    return float(np.sqrt(np.mean((v_med[odd] - pred) ** 2)))


def judge_sensor(
    rec: Recording,
    where: str,
    kind: str,
    vals: FloatArray,
    overrides: tuple[str, ...],
    firmware: str,
) -> dict[str, Any]:
    """Judge one sensor instance's data before anything is fitted.

    :func:`thermocal.adequacy.judge` for a cubic (3 in the temperature, 4 bins; stillness of
    ``vals``), with ArduPilot's minimum sweep added when ``firmware="ardupilot"``.

    Parameters
    ----------
    rec : thermocal.recording.Recording
        The instance's recording (time [s], temperature [°C], axes x, y, z).
    where : str
        Name of the instance in messages (``TOPIC.N``).
    kind : str
        ``"gyro"`` or ``"accel"``.
    vals : numpy.ndarray
        Shape (n, 3): the three axes in the canonical unit [°/h or mg].
    overrides : tuple of str
        Names of the adequacy tests the user accepts anyway.
    firmware : str
        ``"px4"`` or ``"ardupilot"`` (the latter adds the 10 °C minimum sweep).

    Returns
    -------
    dict
        The adequacy record (:meth:`thermocal.adequacy.Adequacy.to_dict`).

    Raises
    ------
    ThermocalInputError
        When a test fails and is not in ``overrides`` (a sweep too short, a sensor moving).

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp`` (minimum
      learning range).
    """
    temp = rec.temperature_c("temperature")
    unit = rec.signal(AXES[0])[1]
    shown = units.shown_unit(unit, rec.units.get(AXES[0], unit))
    factor, given = shown.to_shown, shown.unit
    tname = f"{where} temperature"
    judged = adequacy.judge(
        adequacy.Needs({tname: 3}, 4),
        [rec.time_s],
        [temp.reshape(-1, 1)],
        [tname],
        signals=[vals],
        kind=kind,
        name=where,
        unit_factor=factor,
        unit=given,
        overrides=overrides,
    )
    if firmware == "ardupilot":
        span = float(np.max(temp)) - float(np.min(temp))
        judged = judged.merged(
            adequacy.Adequacy(
                (adequacy.firmware_test(span, "ArduPilot", adequacy.ARDUPILOT_MIN_SPAN_C),),
                overrides,
            )
        )
    return judged.enforce().to_dict()


def motion_floor(kind: str) -> float:
    """The smallest departure :func:`thermocal.adequacy.stillness` calls motion.

    Parameters
    ----------
    kind : str
        ``"gyro"`` or anything else (an accelerometer).

    Returns
    -------
    float
        The floor in the canonical unit of ``kind`` [°/h for a gyro, mg for an accelerometer].
    """
    if kind == "gyro":
        return adequacy.MOTION_FLOOR_DEG_S * adequacy.DEG_H_PER_DEG_S
    return adequacy.MOTION_FLOOR_MG


def still_mask(time_s: FloatArray, motion: adequacy.Motion) -> npt.NDArray[np.bool_]:
    """The samples outside every bump :func:`thermocal.adequacy.stillness` found.

    Each episode ``[start, end]`` is widened by :data:`thermocal.adequacy.STILL_BLOCK_S` on
    both sides (the block edges are where a bump begins and ends, not where it is over).

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times, ascending [s].
    motion : thermocal.adequacy.Motion
        The stillness result (its ``episodes``: start [s], end [s], peak).

    Returns
    -------
    numpy.ndarray of bool
        True for the samples kept (still), same length as ``time_s``.
    """
    keep = np.ones(time_s.size, dtype=bool)
    pad = adequacy.STILL_BLOCK_S
    for start, end, _peak in motion.episodes:
        a, b = np.searchsorted(time_s, [start - pad, end + pad])
        keep[a:b] = False
    return keep


def fit_sensor(
    rec: Recording,
    topic: str,
    kind: str,
    instance: int,
    *,
    overrides: tuple[str, ...] = (),
    firmware: str = "px4",
    motions: dict[str, adequacy.Motion] | None = None,
) -> SensorFit:
    """Judge, clean, bin and fit one sensor instance's three axes (a cubic in T per axis).

    Judge the log (:func:`judge_sensor`), leave out the bumps (the board handled, knocked:
    :func:`thermocal.adequacy.stillness`'s episodes, :func:`still_mask`; a bump fills whole
    temperature bins where the sweep is fast, and no statistic of the bin can tell it from the
    bias), bin (:func:`thermocal.firmware.binning.temperature_bins`), judge on held-out bins
    (:func:`holdout_rms`) and fit a cubic per axis to every bin.

    Parameters
    ----------
    rec : thermocal.recording.Recording
        The instance's recording: time [s], ``temperature`` [°C], axes x, y, z.
    topic : str
        Topic (PX4) or message (ArduPilot) name, used in channel and message names.
    kind : str
        ``"gyro"`` or ``"accel"``.
    instance : int
        Sensor instance number (0, 1, …).
    overrides : tuple of str, optional
        Adequacy tests the user accepts anyway (default none).
    firmware : str, optional
        ``"px4"`` (default) or ``"ardupilot"`` (adds its 10 °C minimum sweep).
    motions : dict, optional
        When given, receives the stillness result under ``TOPIC.N`` (for
        :func:`step_warnings`, not computed twice).

    Returns
    -------
    SensorFit
        Sweep [°C], sample and bin counts, hold-out rms per axis [°/h or mg] and the three
        fitted channels.

    Raises
    ------
    ThermocalInputError
        When the data are judged inadequate (not overridden), or the temperature covers fewer
        than :data:`thermocal.firmware.binning.MIN_BINS` bins.

    Notes
    -----
    Per axis, the least-squares cubic of the bin medians :math:`(T_k, v_k)`:

    .. math:: v(T) = c_0 + c_1 T + c_2 T^2 + c_3 T^3

    References
    ----------
    - PX4 ``Tools/process_sensor_caldata.py`` (cubic fit of bias against temperature).
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``.
    """
    temp = rec.temperature_c("temperature")
    lo, hi = float(np.min(temp)), float(np.max(temp))
    where = f"{topic}.{instance}"
    vals = np.column_stack([rec.signal(a)[0] for a in AXES])  # canonical unit (°/h or mg)
    unit = rec.signal(AXES[0])[1]
    with adequacy.stillness_remembered():  # the judgement's stillness, not computed twice
        record = judge_sensor(rec, where, kind, vals, overrides, firmware)
        motion = adequacy.stillness(rec.time_s, vals, motion_floor(kind))
    if motions is not None:
        motions[where] = motion
    keep = still_mask(rec.time_s, motion)
    if motion.episodes and np.count_nonzero(keep) < temp.size:
        _c, t_med, v_med = temperature_bins(temp[keep], vals[keep])
    else:
        _c, t_med, v_med = temperature_bins(temp, vals)
    if t_med.size < MIN_BINS:
        raise ThermocalInputError(
            f"{where}: the temperature covers {t_med.size} bins of {BIN_WIDTH_C:g} °C; a cubic "
            f"needs at least {MIN_BINS}: record a wider sweep"
        )
    sid = rec.meta.sensor_id
    fit = SensorFit(
        topic, kind, instance, int(sid) if sid and str(sid).isdigit() else 0, unit,
        (lo, hi), int(temp.size), int(t_med.size), adequacy=record,
    )  # fmt: skip
    short = "g" if kind == "gyro" else "a"
    for j, axis in enumerate(AXES):
        name = f"{short}{instance}_{axis}"
        fit.holdout_rms[axis] = holdout_rms(t_med, v_med[:, j], unit, name)
        model = _cubic(t_med, v_med[:, j], unit, name)
        model.signal_name, model.signal_unit = axis, unit
        model.adequacy_ = record
        model.inputs_ = {
            **model_inputs(rec, axis, ["temperature"]),
            "sensor_id": str(fit.device_id),
        }
        role = {"kind": kind, "axis": axis, "instance": instance}
        fit.channels.append(Channel(name, axis, rec.units.get(axis, unit), model, role))
    return fit


def calibration_of(fits: Sequence[SensorFit]) -> Calibration:
    """Every fitted channel of ``fits`` as one calibration.

    Parameters
    ----------
    fits : sequence of SensorFit
        The fitted sensor instances.

    Returns
    -------
    thermocal.models.calibration.Calibration
        Their channels, in order.
    """
    return Calibration([ch for f in fits for ch in f.channels])


def summary(fits: Sequence[SensorFit]) -> dict[str, Any]:
    """The JSON summary: per sensor the sweep, bins and hold-out rms per axis.

    Parameters
    ----------
    fits : sequence of SensorFit
        The fitted sensor instances.

    Returns
    -------
    dict
        ``TOPIC.N`` → the fields of :class:`SensorFit` without the channels, plus
        ``holdout_rms_unit`` (°/h or mg).
    """
    return {
        f"{f.topic}.{f.instance}": {
            **{k: v for k, v in dataclasses.asdict(f).items() if k != "channels"},
            "holdout_rms_unit": f.unit,
        }
        for f in fits
    }


def require_fields(df: Any, names: Sequence[str], log: Path, where: str) -> None:
    """Refuse a topic or message that lacks fields the calibration reads, naming them.

    Parameters
    ----------
    df : pandas.DataFrame
        The topic's or message's table.
    names : sequence of str
        Fields the calibration reads.
    log : pathlib.Path
        The log file (named in the error).
    where : str
        The topic or message (named in the error).

    Raises
    ------
    ThermocalInputError
        When a field is missing (a damaged format definition renames them).
    """
    missing = [n for n in names if n not in df.columns]
    if missing:
        raise ThermocalInputError(
            f"{log}: {where} lacks the field(s) {', '.join(missing)} (a damaged format "
            "definition?); it has: " + ", ".join(map(str, list(df.columns)[:20]))
        )


# --- the output set ------------------------------------------------------------------------


@dataclass(frozen=True)
class ReportRequest:
    """One sensor's report, as :class:`thermocal.report.calibration.CalibrationReportInputs`
    takes it (the presentation layer writes it: :data:`Reporter`).

    Attributes
    ----------
    calibration : Calibration
        The sensor's calibration.
    recording : Recording
        Its samples.
    recording_path, title, generated_by : str
        The log, the report's title and its maker.
    sensor : str or None
        The sensor's name.
    extra : mapping
        Extra per-channel columns of the summary table.
    notes : tuple of str
        Notes shown in the report.
    previous : CoefficientComparison or None
        The coefficients active in the log against the new ones.
    firmware_learning : CoefficientComparison or None
        The firmware's own learned coefficients against the new ones.
    emulated_learning : CoefficientComparison or None
        What the firmware's own learning, emulated on the log, would store against the new
        ones.
    allan : bool
        Draw each channel's Allan deviation before and after compensation with its noise
        terms (default False: left out; most of a report's cost on a long log).
    """

    calibration: Calibration
    recording: Recording
    recording_path: str
    title: str
    generated_by: str
    sensor: str | None = None
    extra: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    previous: CoefficientComparison | None = None
    """The coefficients active in the log against the new ones (a table and figure)."""
    firmware_learning: CoefficientComparison | None = None
    """The firmware's own learned coefficients (ArduPilot ``TCLR``) against the new ones."""
    allan: bool = False
    """Each channel's Allan deviation section drawn (False: left out, not computed)."""
    emulated_learning: CoefficientComparison | None = None
    """What the firmware's own learning, emulated on the log, would store against the new
    coefficients (:mod:`thermocal.tempcal.learning`)."""


AnyReportRequest = ReportRequest | OffsetReportRequest | ArdupilotBaroReportRequest
"""What a report is built from: a sensor's calibration, a PX4 barometer's or magnetometer's
``TC_B``/``TC_M``, ArduPilot's ``TCAL_BARO_EXP``."""
Reporter = Callable[[Path, AnyReportRequest], object]
"""Writes one report (HTML) to the path; given by the caller (the CLI), so that this file
layer does not import the presentation layer."""


PARALLEL_MIN_SAMPLES = 100_000
"""A sensor's report is built in a worker process, beside the fits of the next sensors,
when its recording has at least this many samples and the machine at least two cores
(:class:`OutputSet`); smaller ones are built here (starting a process costs more)."""


def _report_job(
    reporter: Reporter, path: Path, request: AnyReportRequest
) -> list[tuple[Warning, str, int]]:
    """In the worker: write one report; its warnings (message, file, line) are returned to
    be said again by the parent process, in whose warning filters they belong."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        reporter(path, request)
    return [
        (w.message if isinstance(w.message, Warning) else w.category(str(w.message)),
         w.filename, w.lineno)
        for w in caught
    ]  # fmt: skip


def _n_samples(request: AnyReportRequest) -> int:
    if isinstance(request, ReportRequest):
        return int(request.recording.time_s.size)
    return int(np.asarray(request.temp_c).size)


@dataclass
class OutputSet:
    """The files of one calibration set, built in ``stage`` beside ``output`` and moved into
    place whole by :meth:`commit` (:func:`thermocal.writers.commit_directory`).

    Reports of large recordings (:data:`PARALLEL_MIN_SAMPLES`) are built by one worker
    process while this one goes on with the next sensors (``workers`` 1; 0: all here).  At
    :meth:`commit` every report not yet begun there is taken back and built here, the others
    awaited; a report that failed in the worker (or could not be sent to it) is built again
    here, so that its error is raised as without the worker.  The reports are the same
    either way; the worker's warnings are said again here.

    Attributes
    ----------
    output : Path
        The set's final folder.
    stage : Path
        The folder it is built in.
    reporter : Reporter or None
        What writes the reports (None: no reports).
    reports : list of Path
        The reports written.
    workers : int
        Report worker processes (1, or 0: all here).
    """

    output: Path
    stage: Path
    reporter: Reporter | None
    reports: list[Path] = field(default_factory=list)
    workers: int = 0
    _pool: Any = None
    _pending: list[tuple[Any, Path, AnyReportRequest | None]] = field(default_factory=list)

    def report(self, name: str, request: AnyReportRequest) -> None:
        """Write the report ``name`` into the stage (when a reporter is given).

        Built here, or in the worker process for a large recording (the class docstring).

        Parameters
        ----------
        name : str
            File name of the report inside the output directory.
        request : AnyReportRequest
            What the report is built from.
        """
        path = self.output / name
        self.reports.append(path)
        if self.reporter is None:
            return
        if self.workers > 0 and _n_samples(request) >= PARALLEL_MIN_SAMPLES:
            if self._pool is None:
                self._pool = _report_pool()
            self._forget_written()
            fut = self._pool.submit(_report_job, self.reporter, self.stage / name, request)
            self._pending.append((fut, self.stage / name, request))
            return
        self.reporter(self.stage / name, request)

    def _forget_written(self) -> None:
        """The requests of reports the worker has written are not kept (their recordings'
        memory given back); a report not begun or failed keeps its request."""
        self._pending = [
            (fut, path, None if fut.done() and _succeeded(fut) else request)
            for fut, path, request in self._pending
        ]

    def finish_reports(self) -> None:
        """Every report of the set written: those not begun by the worker are built here,
        the last first (the worker goes on with the earlier ones), then the worker's
        awaited (the class docstring)."""
        from thermocal.writers import WRITTEN

        pending, self._pending = self._pending, []
        assert self.reporter is not None or not pending
        for fut, path, request in reversed(pending):  # the last first: the worker goes on
            if not fut.cancel():  # begun (or done) there, and so every one before it
                break
            assert request is not None  # kept: not done
            self.reporter(path, request)  # type: ignore[misc]
        for fut, path, request in pending:
            if fut.cancelled():
                continue
            try:
                said = fut.result()
            except Exception:  # failed there (or not sent): here, with its own error
                assert request is not None  # kept: failed
                self.reporter(path, request)  # type: ignore[misc]
                continue
            for message, filename, lineno in said:
                warnings.warn_explicit(message, type(message), filename, lineno)
            WRITTEN.append(path)
        self.close()

    def close(self) -> None:
        """Stop the worker (a report it is building is finished first)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def commit(self, calibration: Calibration, params_name: str, params_text: str) -> None:
        """Write the reports left, ``calibration.json`` and the parameter file, then move the set.

        Parameters
        ----------
        calibration : thermocal.models.calibration.Calibration
            The calibration written as ``calibration.json``.
        params_name : str
            File name of the firmware parameter file.
        params_text : str
            Its content.
        """
        from thermocal.pipeline.model_file import save_calibration
        from thermocal.writers import atomic_write, commit_directory

        self.finish_reports()
        save_calibration(calibration, self.stage / "calibration.json")
        with atomic_write(self.stage / params_name, "w") as fh:
            fh.write(params_text)
        commit_directory(self.stage, self.output)


def _succeeded(fut: Any) -> bool:
    """A finished future without an exception."""
    return not fut.cancelled() and fut.exception() is None


def _report_pool() -> Any:
    """One worker process for reports: forked where fork is safe (Linux: the worker
    starts with this process's modules and costs no import), else spawned."""
    import multiprocessing
    import sys
    from concurrent.futures import ProcessPoolExecutor

    method = "fork" if sys.platform.startswith("linux") else "spawn"
    return ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context(method))


PARALLEL_MIN_BYTES = 10_000_000
"""A log of at least this size [bytes] starts the report worker before it is read
(:func:`report_worker`)."""


def _warm_job(reporter: Reporter) -> None:
    """In the worker: the reporter's ``warm()`` when it has one (imports, fonts)."""
    warm = getattr(reporter, "warm", None)
    if callable(warm):
        warm()


@contextlib.contextmanager
def report_worker(reporter: Reporter | None, log: Path) -> Iterator[Any]:
    """Start the report worker of :class:`OutputSet` before a large log is read.

    For a log of at least :data:`PARALLEL_MIN_BYTES`, so that the worker's start and the
    reporter's ``warm()`` (imports, fonts: a second or so) overlap the reading.  Stopped at
    the end of the block.

    Parameters
    ----------
    reporter : Reporter or None
        Writes one report; None: no reports, no worker.
    log : pathlib.Path
        The log about to be read (its size decides).

    Yields
    ------
    concurrent.futures.ProcessPoolExecutor or None
        The worker, or None when the reports are built here (:func:`report_workers`, a small
        log).
    """
    pool = None
    try:
        big = log.stat().st_size >= PARALLEL_MIN_BYTES
    except OSError:  # said by the reader
        big = False
    if reporter is not None and big and report_workers() > 0:
        pool = _report_pool()
        pool.submit(_warm_job, reporter)
    try:
        yield pool
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)


def report_workers() -> int:
    """Worker processes for reports: 1 when the machine has a core to spare (two cores or
    more, the load average at least one below their number), else 0: on a busy machine a
    second process only competes for the same cores and costs its own start (imports,
    the recordings sent to it), so the reports are built here."""
    import os

    cores = os.cpu_count() or 1
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):  # no load average here (Windows)
        load = 0.0
    return 1 if cores - load >= 1.0 else 0


def check_output_dir(output: Path) -> None:
    """Refuse an output that exists and is not a directory.

    Parameters
    ----------
    output : pathlib.Path
        The output directory asked for.

    Raises
    ------
    ThermocalInputError
        When ``output`` exists and is not a directory.
    """
    if output.exists() and not output.is_dir():
        raise ThermocalInputError(f"{output}: exists and is not a directory")


@contextlib.contextmanager
def staged_set(output: Path, reporter: Reporter | None, pool: Any = None) -> Iterator[OutputSet]:
    """A new staging directory for ``output``, removed on any failure.

    :func:`thermocal.writers.staging_directory`; on any failure — a later sensor's error,
    Ctrl-C — it is removed (:func:`thermocal.writers.discard_staging`), so that no part of the
    set is left.

    Parameters
    ----------
    output : pathlib.Path
        The output directory the set is moved to by :meth:`OutputSet.commit`.
    reporter : Reporter or None
        Writes one report; None: none written.
    pool : concurrent.futures.ProcessPoolExecutor, optional
        The report worker already started (:func:`report_worker`); default none.

    Yields
    ------
    OutputSet
        The set being built.
    """
    from thermocal.writers import discard_staging, staging_directory

    workers = 1 if pool is not None else report_workers()  # the worker started: used
    out = OutputSet(output, staging_directory(output), reporter, workers=workers)
    out._pool = pool
    try:
        yield out
    except BaseException:
        out.close()  # the worker stops writing into the stage before it is removed
        discard_staging()
        raise
    out.close()


# --- gates: doubtful, named in a warning ---------------------------------------------------

STALL_S = 600.0
"""A sweep that does not rise by :data:`STALL_RISE_C` for this long has stopped rising
(ArduPilot's learning ends then: AP_InertialSensor_tempcal.cpp ``CAL_TIMEOUT_MS`` = 600 s)."""
STALL_RISE_C = 0.5
"""The rise ArduPilot's learning waits for before it takes the next sample [°C]."""
END_MARGIN_C = 2.0
"""A reference temperature closer than this to an end of the calibrated range [°C]."""


class GateWarning(ThermocalWarning):
    """A calibration log that is usable but doubtful: said, named, not refused."""


def warn_gates(gates: Sequence[str | None]) -> None:
    """Say each gate's sentence as a :class:`GateWarning`.

    Parameters
    ----------
    gates : sequence of str or None
        Each gate's sentence; None: the gate passed.
    """
    for msg in gates:
        if msg:
            warnings.warn(GateWarning(msg), stacklevel=2)


def sweep_stall(time_s: FloatArray, temp_c: FloatArray) -> tuple[float, float, float]:
    r"""The longest stretch without a :data:`STALL_RISE_C` rise of the temperature.

    A rise: the running maximum enters the next 0.5 °C step above the first temperature; the
    stretch after the last rise counts too (a sweep that ends on a plateau).

    Parameters
    ----------
    time_s : numpy.ndarray
        Sample times, ascending [s].
    temp_c : numpy.ndarray
        Temperatures, same length [°C].

    Returns
    -------
    tuple of float
        (longest time without a rise [s], the temperature it stalled at [°C], the time it
        began [s from the log's start]).

    Notes
    -----
    With :math:`\Delta = 0.5` °C, the level of sample :math:`i` is

    .. math:: \ell_i = \left\lfloor \frac{\max_{j \le i} T_j - T_0}{\Delta} \right\rfloor

    and a rise is a sample where :math:`\ell` increases.

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
      (``CAL_TIMEOUT_MS`` = 600 s without a 0.5 °C rise ends the learning).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 3000.0, 10.0)
    >>> temp = np.minimum(20.0 + t / 60.0, 40.0)  # 1 °C/min to 40 °C at 1200 s, then flat to 2990 s
    >>> [round(x, 1) for x in sweep_stall(t, temp)]
    [1790.0, 40.0, 1200.0]
    """
    t = np.asarray(time_s, dtype=np.float64)
    temp = np.asarray(temp_c, dtype=np.float64)
    if t.size < 2:
        return 0.0, float(temp[0]) if temp.size else float("nan"), 0.0
    level = np.floor((np.maximum.accumulate(temp) - temp[0]) / STALL_RISE_C)
    rises = [0, *(int(i) + 1 for i in np.flatnonzero(np.diff(level) > 0))]
    marks = np.array([*(t[r] for r in rises), t[-1]])
    gaps = np.diff(marks)
    k = int(np.argmax(gaps))
    return float(gaps[k]), float(temp[rises[k]]), float(marks[k] - t[0])


def stall_warning(where: str, time_s: FloatArray, temp_c: FloatArray) -> str | None:
    """The sentence of a sweep that stops rising for more than :data:`STALL_S`, or None.

    Parameters
    ----------
    where : str
        Name of the sensor in the sentence.
    time_s : numpy.ndarray
        Sample times [s].
    temp_c : numpy.ndarray
        Temperatures [°C].

    Returns
    -------
    str or None
        The warning sentence, or None when the sweep never stalls longer (:func:`sweep_stall`).

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
      (``CAL_TIMEOUT_MS``).
    """
    gap, at_c, start = sweep_stall(time_s, temp_c)
    if gap <= STALL_S:
        return None
    return (
        f"{where}: the temperature sweep stops rising: {gap:.0f} s from {start:.0f} s on "
        f"without a {STALL_RISE_C:g} °C rise (at {at_c:.1f} °C); ArduPilot's own learning "
        f"ends after {STALL_S:.0f} s without one — check the heating"
    )


def step_warnings(
    fits: Sequence[SensorFit],
    series: Mapping[str, tuple[FloatArray, FloatArray]],
    motions: Mapping[str, adequacy.Motion] | None = None,
) -> list[str]:
    """A step-like bias on one instance of a multi-IMU board.

    :func:`thermocal.adequacy.stillness` of every instance of a kind; a step on one instance
    not seen on another within the stillness window is a bias jump of that sensor, not the
    board moving (which every instance would see).

    Parameters
    ----------
    fits : sequence of SensorFit
        The fitted instances (grouped by kind; a kind with one instance is skipped).
    series : mapping
        ``TOPIC.N`` → (time [s], values (n, 3) in the canonical unit [°/h or mg]).
    motions : mapping, optional
        ``TOPIC.N`` → stillness result already computed (:func:`fit_sensor`'s ``motions``).

    Returns
    -------
    list of str
        One sentence per instance with a step of its own.
    """
    out: list[str] = []
    by_kind: dict[str, list[SensorFit]] = {}
    for f in fits:
        by_kind.setdefault(f.kind, []).append(f)
    for kind, group in by_kind.items():
        if len(group) < 2:
            continue
        floor = motion_floor(kind)
        steps = {}
        for f in group:
            key = f"{f.topic}.{f.instance}"
            if motions is not None and key in motions:
                steps[key] = motions[key].steps
            elif key in series:
                t, v = series[key]
                steps[key] = adequacy.stillness(t, v, floor).steps
        for key, mine in steps.items():
            others = [s for k, ss in steps.items() if k != key for s in ss]
            alone = [
                s for s in mine
                if not any(abs(s[0] - o[0]) <= adequacy.STILL_WINDOW_S for o in others)
            ]  # fmt: skip
            if alone:
                t0 = float(series[key][0][0])
                shown = ", ".join(f"{s[0] - t0:.0f} s" for s in alone[:5])
                out.append(
                    f"{key}: a step-like bias at {shown} that the other {kind} instance(s) do "
                    "not show — a bias jump of this sensor (not the board moving); its "
                    "calibration is doubtful"
                )
    return out


def end_warning(where: str, what: str, ref_c: float, lo: float, hi: float) -> str | None:
    """The sentence of a reference temperature near or beyond an end of the calibrated range.

    Within :data:`END_MARGIN_C` of, or outside, ``[lo, hi]``: the firmware clamps there and the
    cubic is least known.

    Parameters
    ----------
    where : str
        Name of the sensor in the sentence.
    what : str
        What the temperature is (e.g. ``"the reference temperature"``).
    ref_c : float
        The reference temperature [°C].
    lo, hi : float
        The calibrated range [°C].

    Returns
    -------
    str or None
        The sentence, or None when ``lo + 2 <= ref_c <= hi - 2``.

    Examples
    --------
    >>> end_warning("g0", "TREF", 25.0, 10.0, 60.0) is None
    True
    >>> end_warning("g0", "TREF", 59.0, 10.0, 60.0) is None
    False
    """
    if lo + END_MARGIN_C <= ref_c <= hi - END_MARGIN_C:
        return None
    return (
        f"{where}: {what} {ref_c:.1f} °C is too close to the calibration's end "
        f"({lo:.1f}…{hi:.1f} °C; within {END_MARGIN_C:g} °C or outside): the cubic is least "
        "determined there and the firmware clamps beyond it"
    )


GYRO_BIAS_MAX_RAD_S = 0.05
"""A still flight-controller gyro's rate beyond this [rad/s] is doubtful: PX4's ``ATT_BIAS_MAX``
(attitude_estimator_q, "Gyro bias limit", default 0.05 rad/s) — what PX4's estimator takes
for a gyro bias at most."""
GYRO_NOISE_MAX_RAD_S = 0.0175
"""A still flight-controller gyro's sample-to-sample noise beyond 1 °/s rms [rad/s] is
doubtful: MEMS gyros of flight controllers are specified at 0.004–0.01 °/s/√Hz (InvenSense
ICM-20602, ICM-42688-P, Bosch BMI088 datasheets), 0.1–0.3 °/s rms over their bandwidth."""


def gyro_unit_warning(where: str, vals: FloatArray) -> str | None:
    r"""The sentence of a still gyro whose rates look like deg/s logged in a rad/s field.

    Parameters
    ----------
    where : str
        Name of the sensor in the sentence.
    vals : numpy.ndarray
        Shape (n, 3): the still gyro in the canonical unit [°/h].

    Returns
    -------
    str or None
        The sentence when an axis's median rate exceeds :data:`GYRO_BIAS_MAX_RAD_S` or its
        white noise exceeds :data:`GYRO_NOISE_MAX_RAD_S`; None when plausible.

    Notes
    -----
    Per axis, in rad/s, the bias and the white noise from first differences:

    .. math:: b = |\operatorname{median}(v)|, \qquad
       \sigma = \frac{\operatorname{std}(v_{i+1} - v_i)}{\sqrt{2}}

    References
    ----------
    - PX4 ``ATT_BIAS_MAX`` (attitude_estimator_q, default 0.05 rad/s).
    """
    v = np.asarray(vals, dtype=np.float64) * units.DH_TO_RS  # rad/s
    bias = np.abs(np.median(v, axis=0))
    noise = np.std(np.diff(v, axis=0), axis=0) / np.sqrt(2.0) if v.shape[0] > 2 else bias * 0
    j, k = int(np.argmax(bias)), int(np.argmax(noise))
    if bias[j] <= GYRO_BIAS_MAX_RAD_S and noise[k] <= GYRO_NOISE_MAX_RAD_S:
        return None
    what = (
        f"a median rate of {bias[j]:.4g} rad/s on {AXES[j]} (PX4's ATT_BIAS_MAX: "
        f"{GYRO_BIAS_MAX_RAD_S:g})"
        if bias[j] > GYRO_BIAS_MAX_RAD_S
        else f"a noise of {noise[k]:.4g} rad/s rms on {AXES[k]} (a flight controller's gyro: "
        f"≤ {GYRO_NOISE_MAX_RAD_S:g})"
    )
    return (
        f"{where}: the still gyro reads {what}: more than a flight-controller gyro at rest — "
        "deg/s logged in the rad/s field (×57.3)? The parameters are in the log's unit; "
        "check the driver before using them"
    )
