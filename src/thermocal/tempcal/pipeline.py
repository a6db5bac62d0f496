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
    """One sensor instance: its topic, device id, sweep, per-axis hold-out rms [its unit]."""

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
    """The rms [unit] on the odd bins of a cubic fitted to the even bins only
    (:func:`.binning.even_odd_split`): ``sqrt(mean((v_odd − p_even(T_odd))²))``."""
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
    """Step 1: :func:`thermocal.adequacy.judge` of one instance (a cubic: 3 in the
    temperature, 4 bins; stillness of ``vals`` in the canonical unit), with ArduPilot's
    minimum sweep for ``firmware="ardupilot"``; refuses (exit 2) what is not overridden."""
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
    """The smallest departure :func:`thermocal.adequacy.stillness` calls motion, in the
    canonical unit of ``kind`` (°/h for a gyro, mg for an accelerometer)."""
    if kind == "gyro":
        return adequacy.MOTION_FLOOR_DEG_S * adequacy.DEG_H_PER_DEG_S
    return adequacy.MOTION_FLOOR_MG


def still_mask(time_s: FloatArray, motion: adequacy.Motion) -> npt.NDArray[np.bool_]:
    """The samples outside every bump :func:`thermocal.adequacy.stillness` found (each
    episode ``[start, end]`` [s] widened by :data:`adequacy.STILL_BLOCK_S` on both sides:
    the block edges are where a bump begins and ends, not where it is over)."""
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
    """Judge the log (:func:`judge_sensor`), leave out the bumps (the board handled,
    knocked: :func:`thermocal.adequacy.stillness`'s episodes, :func:`still_mask`; a bump
    fills whole temperature bins where the sweep is fast, and no statistic of the bin can
    tell it from the bias), then bin (:func:`.binning.temperature_bins`), judge on held-out
    bins (:func:`holdout_rms`) and fit one sensor instance's three axes (a cubic in T per
    axis, to every bin).  ``motions`` (when given) gets the stillness result under
    ``TOPIC.N`` (for :func:`step_warnings`, not computed twice)."""
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
    """Every fitted channel of ``fits`` as one calibration."""
    return Calibration([ch for f in fits for ch in f.channels])


def summary(fits: Sequence[SensorFit]) -> dict[str, Any]:
    """The JSON summary: per sensor the sweep, bins and hold-out rms per axis."""
    return {
        f"{f.topic}.{f.instance}": {
            **{k: v for k, v in dataclasses.asdict(f).items() if k != "channels"},
            "holdout_rms_unit": f.unit,
        }
        for f in fits
    }


def require_fields(df: Any, names: Sequence[str], log: Path, where: str) -> None:
    """Refuse (exit 2) a topic or message missing fields the calibration reads (a damaged
    format definition renames them), naming them."""
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
    takes it (the presentation layer writes it: :data:`Reporter`)."""

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
    either way; the worker's warnings are said again here."""

    output: Path
    stage: Path
    reporter: Reporter | None
    reports: list[Path] = field(default_factory=list)
    workers: int = 0
    _pool: Any = None
    _pending: list[tuple[Any, Path, AnyReportRequest]] = field(default_factory=list)

    def report(self, name: str, request: AnyReportRequest) -> None:
        """Write the report ``name`` into the stage (when a reporter is given): here, or
        in the worker process (the class docstring)."""
        path = self.output / name
        self.reports.append(path)
        if self.reporter is None:
            return
        if self.workers > 0 and _n_samples(request) >= PARALLEL_MIN_SAMPLES:
            if self._pool is None:
                self._pool = _report_pool()
            fut = self._pool.submit(_report_job, self.reporter, self.stage / name, request)
            self._pending.append((fut, self.stage / name, request))
            return
        self.reporter(self.stage / name, request)

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
            self.reporter(path, request)  # type: ignore[misc]
        for fut, path, request in pending:
            if fut.cancelled():
                continue
            try:
                said = fut.result()
            except Exception:  # failed there (or not sent): here, with its own error
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
        """Write the reports left (:meth:`finish_reports`), ``calibration.json`` and the
        parameter file, then move the set into place."""
        from thermocal.pipeline.model_file import save_calibration
        from thermocal.writers import atomic_write, commit_directory

        self.finish_reports()
        save_calibration(calibration, self.stage / "calibration.json")
        with atomic_write(self.stage / params_name, "w") as fh:
            fh.write(params_text)
        commit_directory(self.stage, self.output)


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
    """The report worker of :class:`OutputSet` started before a large log
    (:data:`PARALLEL_MIN_BYTES`) is read, so that its start and the reporter's ``warm()``
    (imports, fonts: a second or so) overlap the reading; None when the reports are built
    here (:func:`report_workers`, a small log).  Stopped at the end of the block."""
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
    """Worker processes for reports: 1 on a machine with two cores or more, else 0."""
    import os

    return 1 if (os.cpu_count() or 1) > 1 else 0


def check_output_dir(output: Path) -> None:
    """Refuse (exit 2) an output that exists and is not a directory."""
    if output.exists() and not output.is_dir():
        raise ThermocalInputError(f"{output}: exists and is not a directory")


@contextlib.contextmanager
def staged_set(output: Path, reporter: Reporter | None, pool: Any = None) -> Iterator[OutputSet]:
    """A new staging directory for ``output`` (:func:`thermocal.writers.staging_directory`);
    on any failure — a later sensor's error, Ctrl-C — it is removed
    (:func:`thermocal.writers.discard_staging`), so that no part of the set is left.
    ``pool``: the report worker already started (:func:`report_worker`)."""
    from thermocal.writers import discard_staging, staging_directory

    out = OutputSet(output, staging_directory(output), reporter, workers=report_workers())
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
    """Each gate's sentence as a :class:`GateWarning` (None: the gate passed)."""
    for msg in gates:
        if msg:
            warnings.warn(GateWarning(msg), stacklevel=2)


def sweep_stall(time_s: FloatArray, temp_c: FloatArray) -> tuple[float, float, float]:
    """(longest time without a :data:`STALL_RISE_C` rise of the running maximum [s], the
    temperature it stalled at [°C], the time it began [s from the log's start]).  A rise:
    the running maximum enters the next 0.5 °C step above the first temperature; the
    stretch after the last rise counts too (a sweep that ends on a plateau)."""
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
    """The sentence of a sweep that stops rising for more than :data:`STALL_S`, or None."""
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
    """A step-like bias on one instance of a multi-IMU board:
    :func:`thermocal.adequacy.stillness` of every instance of a kind (``series``: name →
    (time [s], values in the canonical unit), or its result already in ``motions``); a step
    on one instance not seen on another within the stillness window is a bias jump of that
    sensor, not the board moving (which every instance would see)."""
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
    """``what`` (a reference temperature) within :data:`END_MARGIN_C` of, or outside, the
    calibrated range [lo, hi] °C: the firmware clamps there, the cubic is least known."""
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
    """The sentence of a still gyro whose median rate on an axis exceeds
    :data:`GYRO_BIAS_MAX_RAD_S` or whose white noise (``std(diff(v))/√2`` per axis) exceeds
    :data:`GYRO_NOISE_MAX_RAD_S`: the deg/s of some drivers logged in a rad/s topic (×57.3);
    ``vals`` (n, 3) in the canonical unit (°/h); None when plausible."""
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
