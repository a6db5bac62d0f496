"""What the flight controllers' own temperature learning would store, emulated from a log.

Two learners, restated from their published sources (their rules and their arithmetic, in
the firmware's precision: ``float`` as float32, ``double`` as float64) and run on the samples
of a log:

* ArduPilot's in-flight learning (``INS_TCAL<n>_ENABLE`` = 2,
  ``AP_InertialSensor_tempcal.cpp`` ``TCal::Learn``): a low-passed temperature, averaging
  windows of at least 100 samples closed at every 0.5 °C rise (one ``TCLR`` point each), a
  running least-squares cubic (``PolyFit<4, double, Vector3f>``), partial saves every 15 s
  once the temperature has risen 10 °C, the end at ``INS_TCAL<n>_TMAX`` or after 600 s
  without a new point (:func:`ardupilot_learning`).
* PX4's on-board calibration (``sensors temperature_calibrate``,
  ``temperature_calibration/task.cpp``, ``common.h``, ``gyro.cpp``, ``accel.cpp``,
  ``polyfit.hpp``): the start between ``SYS_CAL_TMIN`` and ``SYS_CAL_TMAX`` after 10 s, every
  sample at a new highest temperature accumulated into a cubic about
  ``TREF = T_start + SYS_CAL_TDEL / 2``, done when the temperature has risen more than
  ``SYS_CAL_TDEL`` (:func:`px4_oncal`).

Each returns a frozen result: would it have completed, the rule that stopped it with its
numbers, and the parameters it would have stored.  No file is read here.

References
----------
* ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp`` (commit
  025810d325bad2593ff100bc50a2bc7e9d300755), ``libraries/AP_Math/polyfit.cpp``,
  ``libraries/Filter/LowPassFilter2p.cpp``, https://github.com/ArduPilot/ardupilot
  (GPL-3.0: restated, not copied).
* PX4-Autopilot, ``src/modules/temperature_compensation/temperature_calibration/``
  (``task.cpp``, ``common.h``, ``gyro.cpp``, ``accel.cpp``, ``polyfit.hpp``; BSD-3-Clause),
  https://github.com/PX4/PX4-Autopilot
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError
from thermocal.firmware.formats import AP_TREF_C

FloatArray = npt.NDArray[np.float64]
F32 = np.float32

AP_STEP_C = 0.5
"""A learning window closes when the filtered temperature has risen this much [°C]."""
AP_MIN_SAMPLES = 100
"""…and holds at least this many samples (``Learn::add_sample``)."""
AP_RANGE_MIN_C = 10.0
"""``TEMP_RANGE_MIN``: the rise above the start before saving or finishing [°C]."""
AP_TIMEOUT_S = 600.0
"""``CAL_TIMEOUT_MS``: the learning finishes after this long without a new point [s]."""
AP_SAVE_S = 15.0
"""A partial calibration is saved at most this often once the rise is reached [s]."""
AP_FILTER_HZ = (1000.0, 0.5)
"""The temperature filter: ``LowPassFilter2p`` set for 1000 Hz sampling, 0.5 Hz cutoff."""
AP_TMAX_DEFAULT_C = 70.0
"""``INS_TCAL<n>_TMAX``'s default [°C]."""
FLT_EPSILON = float(np.finfo(np.float32).eps)

PX4_TDEL_C = 24.0
"""``SYS_CAL_TDEL``'s default: the rise that ends the calibration [°C]."""
PX4_TMIN_C = 5.0
"""``SYS_CAL_TMIN``'s default: samples below are ignored, the start waits for it [°C]."""
PX4_TMAX_C = 10.0
"""``SYS_CAL_TMAX``'s default: a start above it is an error [°C]."""
PX4_SETTLE_S = 10.0
"""The start waits until this long after boot (``hrt_absolute_time() > 10E6``) [s]."""


# --- ArduPilot ---------------------------------------------------------------------------


def ardupilot_temperature_filter(
    temp_c: npt.ArrayLike, sample_hz: float = AP_FILTER_HZ[0], cutoff_hz: float = AP_FILTER_HZ[1]
) -> npt.NDArray[np.float32]:
    r"""ArduPilot's two-pole low-pass of the learner's temperature, in float32.

    Parameters
    ----------
    temp_c : array_like
        The temperature fed to the learner, one value per sample [°C].
    sample_hz, cutoff_hz : float
        The filter's design rate and cutoff [Hz] (the firmware: 1000 and 0.5, whatever the
        real rate).

    Returns
    -------
    numpy.ndarray
        The filtered temperature (float32) [°C], started at the first value.

    Notes
    -----
    Butterworth biquad in direct form II, :math:`\Omega = \tan(\pi f_c / f_s)`,
    :math:`c = 1 + 2\cos(\pi/4)\Omega + \Omega^2`, :math:`b_0 = \Omega^2 / c`,
    :math:`b_1 = 2 b_0`, :math:`b_2 = b_0`, :math:`a_1 = 2(\Omega^2 - 1)/c`,
    :math:`a_2 = (1 - 2\cos(\pi/4)\Omega + \Omega^2)/c`:

    .. math:: d_0 = x - a_1 d_1 - a_2 d_2, \qquad y = b_0 d_0 + b_1 d_1 + b_2 d_2

    with both delays reset to :math:`x_0 / (1 + a_1 + a_2)`.  With the coefficients
    rounded to float32 (as the firmware stores them), :math:`1 + a_1 + a_2 \approx 10^{-5}`
    keeps about two significant digits: the DC gain
    :math:`(b_0 + b_1 + b_2)/(1 + a_1 + a_2)` of the 1000 Hz / 0.5 Hz design is 1.0074, so
    the filtered temperature (and the ``TCLR`` temperatures and the ``TMAX`` test) reads
    0.74 % high.

    References
    ----------
    - ArduPilot ``libraries/Filter/LowPassFilter2p.cpp`` (``DigitalBiquadFilter``).

    Examples
    --------
    >>> import numpy as np
    >>> y = ardupilot_temperature_filter(np.full(3000, 30.0))
    >>> round(float(y[-1]), 2)                       # the float32 design's DC gain
    30.22
    """
    pi = F32(math.pi)
    ohm = F32(np.tan(pi / (F32(sample_hz) / F32(cutoff_hz))))
    cos45 = F32(np.cos(pi / F32(4.0)))
    c = F32(F32(1.0) + F32(2.0) * cos45 * ohm + ohm * ohm)
    b0 = F32(ohm * ohm / c)
    b1 = F32(2.0) * b0
    a1 = F32(F32(2.0) * (ohm * ohm - F32(1.0)) / c)
    a2 = F32((F32(1.0) - F32(2.0) * cos45 * ohm + ohm * ohm) / c)
    x = np.asarray(temp_c, dtype=np.float64).astype(np.float32)
    out = np.empty(x.size, dtype=np.float32)
    if x.size == 0:
        return out
    gain = 1.0 / float(F32(F32(1.0) + a1 + a2))
    d1 = d2 = F32(float(x[0]) * gain)
    # a scalar loop: the recursion in float32 exactly as the firmware runs it
    for i, xi in enumerate(x.tolist()):
        d0 = F32(F32(F32(xi) - d1 * a1) - d2 * a2)
        out[i] = F32(F32(d0 * b0 + d1 * b1) + d2 * b0)
        d2, d1 = d1, d0
    return out


@dataclass
class _ApPolyFit:
    """``PolyFit<4, double, Vector3f>``: the sums in double, the right-hand side in float."""

    mat: FloatArray = field(default_factory=lambda: np.zeros((4, 4)))
    vec: npt.NDArray[np.float32] = field(default_factory=lambda: np.zeros((4, 3), np.float32))
    n: int = 0

    def update(self, x: float, y: npt.NDArray[np.float32]) -> None:
        """One point: ``mat[j][l] += x^(6-j-l)``, ``vec[j] += y·x^(3-j)`` (highest first)."""
        p = 1.0
        for i in range(6, -1, -1):
            k = 0 if i < 4 else i - 3
            for j in range(i - k, k - 1, -1):
                self.mat[j, i - j] += p
            p *= x
        p = 1.0
        for i in range(3, -1, -1):
            self.vec[i] = (self.vec[i] + y * F32(p)).astype(np.float32)
            p *= x
        self.n += 1

    def polynomial(self) -> npt.NDArray[np.float32] | None:
        """(cubic, square, linear, constant) × (x, y, z) as float, None when singular."""
        det = float(np.linalg.det(self.mat)) if self.n else 0.0
        if not math.isfinite(det) or abs(det) < FLT_EPSILON:
            return None
        inv = np.linalg.inv(self.mat)
        res = np.zeros((4, 3))
        for i in range(4):
            for j in range(4):
                res[i] += self.vec[j].astype(np.float64) * inv[i, j]
        return res.astype(np.float32)


@dataclass(frozen=True)
class LearnPoint:
    """One ``TCLR`` point: a closed averaging window.

    Attributes
    ----------
    time_s : float
        When it closed [s].
    temp_c : float
        ``Temp``: the mid temperature of the window [°C].
    xyz : tuple of float
        ``X, Y, Z``: the window's mean (accelerometer: less the first window's) [rad/s, m/s²].
    n : int
        ``NSamp``: the samples averaged.
    """

    time_s: float
    temp_c: float
    xyz: tuple[float, float, float]
    n: int


@dataclass(frozen=True)
class ArdupilotLearning:
    """What ArduPilot's in-flight learning of one IMU would have done with a log.

    Attributes
    ----------
    instance : int
        The IMU (``INS_TCAL<instance + 1>``).
    outcome : str
        ``"completed"`` (``INS_TCAL<n>_TMAX`` reached), ``"timed out"`` (finished after
        600 s without a 0.5 °C rise, coefficients saved), ``"failed fit"`` (singular fit:
        the firmware disables the calibration) or ``"not completed"``.
    reason : str
        Why, with the numbers (the rise against the 10 °C required, the temperature against
        ``TMAX``, the time since the last point against the 600 s time-out).
    start_c, tmax_target_c, highest_c : float
        The learning's start temperature (the first accelerometer window's), its target
        ``INS_TCAL<n>_TMAX`` and the highest filtered temperature reached [°C].
    stored : dict of str to float
        The ``INS_TCAL<n>_*`` the firmware would hold at the end of the log (a partial
        save's when not completed; empty when nothing was saved).
    partial : bool
        ``stored`` is a partial save (every 15 s once 10 °C were reached).
    accel_points, gyro_points : tuple of LearnPoint
        The ``TCLR`` points the firmware would have logged (SType 0 and 1).
    end_time_s : float
        When the learning ended (the log's end when it did not) [s].
    """

    instance: int
    outcome: str
    reason: str
    start_c: float
    tmax_target_c: float
    highest_c: float
    stored: dict[str, float]
    partial: bool
    accel_points: tuple[LearnPoint, ...]
    gyro_points: tuple[LearnPoint, ...]
    end_time_s: float

    @property
    def completed(self) -> bool:
        """The firmware would have saved a finished calibration (``ENABLE`` back to 1)."""
        return self.outcome in ("completed", "timed out")

    def to_dict(self) -> dict[str, Any]:
        """The emulation as plain values (JSON); the points as lists."""
        return {
            "instance": self.instance,
            "completed": self.completed,
            "outcome": self.outcome,
            "reason": self.reason,
            "start_c": self.start_c,
            "tmax_target_c": self.tmax_target_c,
            "highest_c": self.highest_c,
            "stored": dict(self.stored),
            "partial": self.partial,
            "points": {"accel": len(self.accel_points), "gyro": len(self.gyro_points)},
            "end_time_s": self.end_time_s,
        }


@dataclass
class _ApState:
    """The learner's shared state across its accelerometer and gyro windows."""

    instance: int
    start_tmax: F32
    start_temp: F32
    fits: tuple[_ApPolyFit, _ApPolyFit]
    points: tuple[list[LearnPoint], list[LearnPoint]]
    accel_start: npt.NDArray[np.float32] | None = None
    last_save_ms: int = 0
    stored: dict[str, float] = field(default_factory=dict)
    outcome: str = ""
    reason: str = ""
    end_s: float = math.nan

    def save(self, temperature: F32) -> bool:
        """``Learn::save_calibration``: both fits' coefficients ×1e6 in float, TMIN/TMAX."""
        p = [f.polynomial() for f in self.fits]
        if p[0] is None:
            return False
        n = self.instance + 1
        out = dict(self.stored)
        for tag, poly in zip(("ACC", "GYR"), p, strict=True):
            if poly is None:
                self.stored = out
                return False
            for k in range(3):
                c = poly[2 - k] * F32(1.0e6)
                for axis, v in zip("XYZ", c.tolist(), strict=True):
                    out[f"INS_TCAL{n}_{tag}{k + 1}_{axis}"] = float(v)
        out[f"INS_TCAL{n}_TMIN"] = float(self.start_temp)
        out[f"INS_TCAL{n}_TMAX"] = float(temperature)
        self.stored = out
        return True


def _ap_window_sum(v: npt.NDArray[np.float32], lo: int, hi: int) -> npt.NDArray[np.float32]:
    """``sum += sample`` over samples lo…hi in float32, in order, divided by the count."""
    s = np.add.accumulate(v[lo : hi + 1], axis=0, dtype=np.float32)[-1]
    out: npt.NDArray[np.float32] = (s / F32(hi + 1 - lo)).astype(np.float32)
    return out


def _ap_next_event(
    ft: npt.NDArray[np.float32], now_ms: npt.NDArray[np.int64], i0: int, last_temp: F32,
    last_ms: int, start_temp: F32, min_count: int,
) -> tuple[int, bool]:  # fmt: skip
    """The next sample that closes a window (False) or times the learning out (True);
    ``(-1, False)`` when the log ends first."""
    rise = ft[i0:] - last_temp
    ok = rise >= F32(AP_STEP_C)
    ok[: max(min_count - 1, 0)] = False
    j = int(np.argmax(ok)) + i0 if ok.any() else -1
    if last_ms:
        stop = ft.size if j < 0 else j
        late = (ft[i0:stop] - start_temp >= F32(AP_RANGE_MIN_C)) & (
            now_ms[i0:stop] - last_ms > int(AP_TIMEOUT_S * 1000)
        )
        if late.any():
            return int(np.argmax(late)) + i0, True
    return j, False


def ardupilot_learning(
    time_s: npt.ArrayLike,
    temp_c: npt.ArrayLike,
    accel: npt.ArrayLike,
    gyro: npt.ArrayLike,
    *,
    tmax_c: float = AP_TMAX_DEFAULT_C,
    instance: int = 0,
    samples_per_sample: float = 1.0,
) -> ArdupilotLearning:
    r"""Emulate ArduPilot's in-flight temperature learning of one IMU on a log's samples.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Time since boot of each sample [s] (the firmware's ``millis()``).
    temp_c : array_like, shape (n,)
        The IMU's temperature [°C].
    accel, gyro : array_like, shape (n, 3)
        The accelerometer [m/s²] and gyro [rad/s] samples in the board frame, before the
        temperature correction (the learner is fed before it, with ``ENABLE`` = 2).
    tmax_c : float
        ``INS_TCAL<n>_TMAX`` when the learning started: its target [°C] (default 70).
    instance : int
        The IMU, 0…2.
    samples_per_sample : float
        How many of the driver's samples each given sample stands for (the driver's rate
        over the log's, 1 ≤ it < 1000; default 1: the log holds every sample).  The temperature
        filter's cutoff and the 100-sample minimum are scaled by it.

    Returns
    -------
    ArdupilotLearning
        Completed or not and why, the parameters it would hold, the ``TCLR`` points.

    Raises
    ------
    thermocal.errors.ParameterError
        Arrays of different lengths or shapes, non-finite values, time going backwards,
        ``instance`` outside 0…2, ``samples_per_sample`` below 1.

    Notes
    -----
    Per sample the temperature is low-passed (:func:`ardupilot_temperature_filter`) and
    the sample summed.  A window closes at the first sample where it holds ≥ 100 samples
    and the filtered temperature :math:`T_f` has risen ≥ 0.5 °C since the last one; its
    point is :math:`T = (T_f + T_{last})/2` and the mean (the accelerometer's less its first
    window's, whose :math:`T` becomes the start).  Each point updates a least-squares cubic
    in :math:`t = T - 35`:

    .. math:: M \mathrel{+}= [t^{6-j-l}]_{j,l}, \quad v \mathrel{+}= y\,[t^{3-j}]_j, \qquad
       p = M^{-1} v, \qquad c_k = 10^6 p_{3-k}

    (``p`` highest power first; :math:`v` and :math:`p` in float32).  Once
    :math:`T_f - T_{start} \ge 10`: at :math:`T_f \ge T_{max}` the learning finishes
    (``TMAX`` = :math:`T_f`), else a partial save every 15 s; 600 s without a point after
    that rise also finishes it.  Accelerometer before gyro at each sample.

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
      (``Learn::add_sample``, ``save_calibration``, ``finish_calibration``, ``reset``) and
      ``libraries/AP_Math/polyfit.cpp`` (``PolyFit::update``, ``get_polynomial``).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 3000.0, 0.1)
    >>> temp = 20.0 + 0.01 * t                      # 30 °C in 50 min
    >>> gyro = np.column_stack([1e-4 * (temp - 35.0), 0 * t, 0 * t])
    >>> acc = np.zeros((t.size, 3))
    >>> r = ardupilot_learning(t, temp, acc, gyro, tmax_c=45.0, samples_per_sample=100)
    >>> r.outcome, round(r.stored["INS_TCAL1_GYR1_X"], 1)
    ('completed', 100.0)
    """
    t, temp, vals, min_count, spc = _ap_inputs(
        time_s, temp_c, accel, gyro, instance, samples_per_sample
    )
    ft = ardupilot_temperature_filter(temp, AP_FILTER_HZ[0], AP_FILTER_HZ[1] * spc)
    now_ms = np.floor(t * 1000.0).astype(np.int64)
    st = _ApState(instance, F32(tmax_c), F32(temp[0]), (_ApPolyFit(), _ApPolyFit()), ([], []))
    i0, last_temp, last_ms = 0, F32(temp[0]), 0
    while not st.outcome:
        j, late = _ap_next_event(ft, now_ms, i0, last_temp, last_ms, st.start_temp, min_count)
        if j < 0:
            break
        if late:
            _ap_finish(st, last_temp, "timed out", float(t[j]))
            break
        for s in (0, 1):
            _ap_point(st, s, _ap_window_sum(vals[s], i0, j), last_temp, ft[j], t[j], j - i0 + 1)
            _ap_after_point(st, ft[j], int(now_ms[j]), float(t[j]))
            if st.outcome:
                break
        i0, last_temp, last_ms = j + 1, ft[j], int(now_ms[j])
    return _ap_result(st, ft, t, last_ms)


def _ap_inputs(
    time_s: npt.ArrayLike, temp_c: npt.ArrayLike, accel: npt.ArrayLike, gyro: npt.ArrayLike,
    instance: int, samples_per_sample: float,
) -> tuple[FloatArray, FloatArray, tuple[npt.NDArray[np.float32], ...], int, float]:  # fmt: skip
    """The learner's inputs checked: times, temperatures (float), samples (float32)."""
    t = np.asarray(time_s, dtype=np.float64).ravel()
    temp = np.asarray(temp_c, dtype=np.float64).ravel()
    if not 0 <= instance <= 2:
        raise ParameterError("instance", f"{{name}} must be 0, 1 or 2, got {instance}")
    if not 1.0 <= samples_per_sample < AP_FILTER_HZ[0] / AP_FILTER_HZ[1] / 2:
        raise ParameterError(
            "samples_per_sample",
            f"{{name}} must be at least 1 and below {AP_FILTER_HZ[0] / AP_FILTER_HZ[1] / 2:.0f} "
            f"(the filter's cutoff stays below its Nyquist frequency), got {samples_per_sample}",
        )
    vals = []
    for name, v in (("accel", accel), ("gyro", gyro)):
        a = np.asarray(v, dtype=np.float64)
        if a.shape != (t.size, 3):
            raise ParameterError(name, f"{{name}} must have shape ({t.size}, 3), got {a.shape}")
        if not np.isfinite(a).all():
            raise ParameterError(name, "{name} holds values that are not finite")
        vals.append(a.astype(np.float32))
    if temp.size != t.size or t.size == 0:
        raise ParameterError("temp_c", f"{{name}} has {temp.size} values for {t.size} times")
    if not (np.isfinite(t).all() and np.isfinite(temp).all()):
        raise ParameterError("temp_c", "{name} or the times hold values that are not finite")
    if np.any(np.diff(t) < 0):
        raise ParameterError("time_s", "{name} goes backwards: sort the samples by time")
    min_count = max(1, math.ceil(AP_MIN_SAMPLES / samples_per_sample))
    return t, temp, tuple(vals), min_count, float(samples_per_sample)


def _ap_point(
    st: _ApState, s: int, mean: npt.NDArray[np.float32], last_temp: F32, temp: F32,
    time_s: float, n: int,
) -> None:  # fmt: skip
    """One window of sensor ``s`` (0 accelerometer, 1 gyro) closed: its point and fit."""
    mid = F32(F32(temp + last_temp) * F32(0.5))
    if s == 0:
        if st.accel_start is None:
            st.accel_start, st.start_temp = mean.copy(), mid
        mean = (mean - st.accel_start).astype(np.float32)
    tdiff = F32(float(mid) - AP_TREF_C)
    st.fits[s].update(float(tdiff), mean)
    st.points[s].append(LearnPoint(float(time_s), float(mid), tuple(map(float, mean)), n))  # type: ignore[arg-type]


def _ap_after_point(st: _ApState, temp: F32, now_ms: int, time_s: float) -> None:
    """After a point: finish at ``TMAX``, or a partial save every 15 s, once 10 °C risen."""
    if F32(temp - st.start_temp) < F32(AP_RANGE_MIN_C):
        return
    if temp >= st.start_tmax:
        _ap_finish(st, temp, "completed", time_s)
    elif now_ms - st.last_save_ms > int(AP_SAVE_S * 1000):
        st.last_save_ms = now_ms
        st.save(temp)


def _ap_finish(st: _ApState, temp: F32, outcome: str, time_s: float) -> None:
    """``Learn::finish_calibration``: saved, or a failed fit (the calibration disabled)."""
    st.outcome = outcome if st.save(temp) else "failed fit"
    st.end_s = time_s


def _ap_result(
    st: _ApState, ft: npt.NDArray[np.float32], t: FloatArray, last_ms: int
) -> ArdupilotLearning:
    """The emulation's result, with the rule that stopped it and its numbers."""
    n = st.instance + 1
    highest = float(np.max(ft)) if ft.size else math.nan
    start = float(st.start_temp)
    rise = float(np.max(ft) - st.start_temp) if ft.size else 0.0
    pts = (len(st.points[0]), len(st.points[1]))
    if st.outcome == "completed":
        reason = (
            f"completed: the temperature reached INS_TCAL{n}_TMAX {float(st.start_tmax):.1f} °C "
            f"after a rise of {st.stored[f'INS_TCAL{n}_TMAX'] - start:.1f} °C from {start:.1f} °C "
            f"({pts[0]} points)"
        )
    elif st.outcome == "timed out":
        reason = (
            f"timed out: no 0.5 °C rise for {AP_TIMEOUT_S:.0f} s after reaching "
            f"{st.stored[f'INS_TCAL{n}_TMAX']:.1f} °C (below INS_TCAL{n}_TMAX "
            f"{float(st.start_tmax):.1f} °C); saved over {start:.1f}…"
            f"{st.stored[f'INS_TCAL{n}_TMAX']:.1f} °C"
        )
    elif st.outcome == "failed fit":
        reason = f"failed fit: the cubic of {pts[0]} points is singular; calibration disabled"
    else:
        reason = _ap_not_completed(st, rise, highest, float(t[-1]), last_ms, pts[0])
    return ArdupilotLearning(
        st.instance, st.outcome or "not completed", reason, start, float(st.start_tmax),
        highest, dict(st.stored), bool(st.stored) and not st.outcome,
        tuple(st.points[0]), tuple(st.points[1]),
        st.end_s if st.outcome else float(t[-1]),
    )  # fmt: skip


def _ap_not_completed(
    st: _ApState, rise: float, highest: float, end_s: float, last_ms: int, n_points: int
) -> str:
    """The rule that kept an unfinished learning from completing, with its numbers."""
    n = st.instance + 1
    if rise < AP_RANGE_MIN_C:
        return (
            f"not completed: the temperature rose {rise:.1f} °C of the {AP_RANGE_MIN_C:.0f} °C "
            f"required (from {float(st.start_temp):.1f} to {highest:.1f} °C; target "
            f"INS_TCAL{n}_TMAX {float(st.start_tmax):.1f} °C)"
        )
    since = end_s - last_ms / 1000.0
    saved = (
        f"; the last partial save covers {st.stored[f'INS_TCAL{n}_TMIN']:.1f}…"
        f"{st.stored[f'INS_TCAL{n}_TMAX']:.1f} °C"
        if st.stored
        else ""
    )
    return (
        f"not completed: the temperature reached {highest:.1f} °C, below INS_TCAL{n}_TMAX "
        f"{float(st.start_tmax):.1f} °C, and the log ended {since:.0f} s after the last "
        f"0.5 °C step, before the {AP_TIMEOUT_S:.0f} s time-out ({n_points} points){saved}"
    )


# --- PX4 ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Px4Oncal:
    """What PX4's on-board temperature calibration would have done with one sensor instance.

    Attributes
    ----------
    kind : str
        ``"gyro"`` or ``"accel"``.
    instance : int
        The uORB instance (``TC_G<i>``/``TC_A<i>``).
    outcome : str
        ``"completed"`` (risen more than ``SYS_CAL_TDEL``), ``"too hot"`` (the start above
        ``SYS_CAL_TMAX``: the whole calibration aborts), ``"not started"`` or
        ``"not completed"``.
    reason : str
        Why, with the numbers.
    progress : int
        The progress the firmware reports, 0…100 (the rise over ``SYS_CAL_TDEL``).
    low_c, high_c, ref_c : float
        ``TMIN`` (the start), ``TMAX`` (the highest reached) and ``TREF`` (start +
        ``SYS_CAL_TDEL``/2) [°C]; NaN when not started.
    n_fitted : int
        The samples accumulated (each at a new highest temperature).
    stored : dict of str to float
        The ``TC_G<i>_*``/``TC_A<i>_*`` written when the calibration completes (empty
        otherwise: PX4 writes nothing until every sensor is done).
    start_time_s : float
        When it started [s] (NaN when not started).
    """

    kind: str
    instance: int
    outcome: str
    reason: str
    progress: int
    low_c: float
    high_c: float
    ref_c: float
    n_fitted: int
    stored: dict[str, float]
    start_time_s: float

    @property
    def completed(self) -> bool:
        """The sensor reached the rise (its part of the calibration is done)."""
        return self.outcome == "completed"

    def to_dict(self) -> dict[str, Any]:
        """The emulation as plain values (JSON)."""
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        d["completed"] = self.completed
        return d


def _px4_fit(x: FloatArray, y: FloatArray) -> FloatArray:
    """``polyfitter<4>``: sums of powers in double in sample order, ``VTV⁻¹·VTY``;
    (cubic, square, linear, constant) per column of ``y``."""
    powers = [np.ones_like(x)]
    for _ in range(6):
        powers.append(powers[-1] * x)  # temp *= x, as the firmware forms the powers
    sums = [float(np.add.accumulate(p)[-1]) for p in powers]
    vtv = np.array([[sums[6 - r - c] for c in range(4)] for r in range(4)])
    vty = np.array([np.add.accumulate(y * powers[3 - r][:, None], axis=0)[-1] for r in range(4)])
    inv = np.linalg.inv(vtv)
    res = np.zeros((4, y.shape[1]))
    for i in range(4):
        for j in range(4):
            res[i] += inv[i, j] * vty[j]
    return res


def px4_oncal(
    time_s: npt.ArrayLike,
    temp_c: npt.ArrayLike,
    values: npt.ArrayLike,
    *,
    kind: str = "gyro",
    instance: int = 0,
    tdel_c: float = PX4_TDEL_C,
    tmin_c: float = PX4_TMIN_C,
    tmax_c: float = PX4_TMAX_C,
    device_id: int = 0,
) -> Px4Oncal:
    r"""Emulate PX4's on-board temperature calibration of one gyro or accelerometer.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Time since boot of each sample [s].
    temp_c : array_like, shape (n,)
        The sensor's temperature [°C].
    values : array_like, shape (n, 3)
        The sensor's output (``sensor_gyro`` [rad/s], ``sensor_accel`` [m/s²]).
    kind : {"gyro", "accel"}
        Which calibrator (``TC_G`` or ``TC_A``; the accelerometer's constant is zeroed).
    instance : int
        The instance, 0…2.
    tdel_c, tmin_c, tmax_c : float
        ``SYS_CAL_TDEL`` (rise required), ``SYS_CAL_TMIN`` (lowest start),
        ``SYS_CAL_TMAX`` (highest start) [°C]; PX4's defaults 24, 5, 10.
    device_id : int
        ``TC_*_ID`` written.

    Returns
    -------
    Px4Oncal
        Completed or not and why, the progress, the parameters it would write.

    Raises
    ------
    thermocal.errors.ParameterError
        Arrays of different lengths or shapes, an unknown ``kind``, ``instance`` outside
        0…2, ``tdel_c`` not positive.

    Notes
    -----
    Samples below ``SYS_CAL_TMIN`` are skipped.  The first sample after 10 s from boot
    starts the calibration (an error above ``SYS_CAL_TMAX``): :math:`T_{low} = T_{high} = T`,
    :math:`T_{ref} = T + \Delta/2`.  Every later sample with :math:`T > T_{high}` raises
    :math:`T_{high}` and enters the least-squares cubic in :math:`t = T - T_{ref}` (double):

    .. math:: V^T V \mathrel{+}= [t^{6-r-c}]_{r,c}, \quad V^T y \mathrel{+}= y\,[t^{3-r}]_r,
       \qquad p = (V^T V)^{-1} V^T y

    until :math:`T_{high} - T_{low} > \Delta` (that sample included).  ``TC_*_X<3-k>`` =
    :math:`p_k` as float.

    References
    ----------
    - PX4-Autopilot ``src/modules/temperature_compensation/temperature_calibration/``
      ``gyro.cpp``, ``accel.cpp`` (``update_sensor_instance``, ``finish_sensor_instance``),
      ``common.h``, ``polyfit.hpp``, ``task.cpp``.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(0.0, 3000.0, 0.5)
    >>> temp = 8.0 + 0.01 * t
    >>> gyro = np.column_stack([1e-4 * (temp - 20.0), 0 * t, 0 * t])
    >>> r = px4_oncal(t, temp, gyro, kind="gyro")
    >>> r.outcome, round(r.stored["TC_G0_X1_0"], 6), round(r.ref_c, 2)
    ('completed', 0.0001, 20.1)
    """
    t, temp, vals = _px4_inputs(time_s, temp_c, values, kind, instance, tdel_c)
    f_temp = temp.astype(np.float32)
    usable = (f_temp >= F32(tmin_c)) & (t > PX4_SETTLE_S)
    if not usable.any():
        return _px4_not_started(kind, instance, f_temp, t, tmin_c)
    s = int(np.argmax(usable))
    low = f_temp[s]
    if low > F32(tmax_c):
        reason = (
            f"too hot: the calibration started at {float(low):.1f} °C, above SYS_CAL_TMAX "
            f"{tmax_c:g} °C (PX4 aborts every sensor: cool the board below it first)"
        )
        return Px4Oncal(kind, instance, "too hot", reason, 0, float(low), float(low),
                        math.nan, 0, {}, float(t[s]))  # fmt: skip
    return _px4_accumulate(kind, instance, t, f_temp, vals, s, (tdel_c, tmin_c), device_id)


def _px4_accumulate(
    kind: str, instance: int, t: FloatArray, f_temp: npt.NDArray[np.float32], vals: FloatArray,
    s: int, limits: tuple[float, float], device_id: int,
) -> Px4Oncal:  # fmt: skip
    """From the start at sample ``s``: the samples at a new highest temperature up to the
    one that completes the rise, their fit and the parameters."""
    tdel_c, tmin_c = limits
    low = f_temp[s]
    ref = F32(low + F32(0.5) * F32(tdel_c))
    rest = np.arange(s + 1, t.size)
    rest = rest[f_temp[rest] >= F32(tmin_c)]
    prior = np.maximum.accumulate(np.r_[low, f_temp[rest]])[:-1]
    rest = rest[f_temp[rest] > prior]  # each a new highest temperature
    done = np.flatnonzero(f_temp[rest] - low > F32(tdel_c))
    if done.size:
        rest = rest[: done[0] + 1]
    high = F32(f_temp[rest[-1]]) if rest.size else low
    progress = min(100, int(float(high - low) / float(F32(tdel_c)) * 100.0))
    stored: dict[str, float] = {}
    if done.size:
        x = f_temp[rest].astype(np.float64) - float(ref)
        res = _px4_fit(x, vals[rest].astype(np.float32).astype(np.float64))
        stored = _px4_params(kind, instance, res, float(low), float(high), float(ref),
                             device_id)  # fmt: skip
        reason = (
            f"completed: the temperature rose {float(high - low):.2f} °C (more than SYS_CAL_TDEL "
            f"{tdel_c:g} °C) from {float(low):.1f} °C; {rest.size} samples fitted"
        )
    else:
        reason = (
            f"not completed: the temperature rose {float(high - low):.1f} °C of the "
            f"{tdel_c:g} °C required (SYS_CAL_TDEL; from {float(low):.1f} to "
            f"{float(high):.1f} °C), progress {progress} %"
        )
    return Px4Oncal(
        kind, instance, "completed" if done.size else "not completed", reason, progress,
        float(low), float(high), float(ref), int(rest.size), stored, float(t[s]),
    )  # fmt: skip


def _px4_inputs(
    time_s: npt.ArrayLike, temp_c: npt.ArrayLike, values: npt.ArrayLike, kind: str,
    instance: int, tdel_c: float,
) -> tuple[FloatArray, FloatArray, FloatArray]:  # fmt: skip
    """The calibrator's inputs checked; samples with a temperature that is not finite are
    dropped (the firmware skips them)."""
    if kind not in ("gyro", "accel"):
        raise ParameterError("kind", f"{{name}} must be gyro or accel, got {kind!r}")
    if not 0 <= instance <= 2:
        raise ParameterError("instance", f"{{name}} must be 0, 1 or 2, got {instance}")
    if not tdel_c > 0:
        raise ParameterError("tdel_c", f"{{name}} must be positive, got {tdel_c}")
    t = np.asarray(time_s, dtype=np.float64).ravel()
    temp = np.asarray(temp_c, dtype=np.float64).ravel()
    v = np.asarray(values, dtype=np.float64)
    if temp.size != t.size or v.shape != (t.size, 3):
        raise ParameterError(
            "values", f"{{name}} must have shape ({t.size}, 3) with {t.size} temperatures, "
            f"got {v.shape} and {temp.size}",
        )  # fmt: skip
    keep = np.isfinite(temp) & np.isfinite(t) & np.isfinite(v).all(axis=1)
    return t[keep], temp[keep], v[keep]


def _px4_not_started(
    kind: str, instance: int, temp: npt.NDArray[np.float32], t: FloatArray, tmin_c: float
) -> Px4Oncal:
    """A calibration that never started: too cold, or the log too short."""
    if temp.size == 0:
        reason = "not started: no sample with a finite temperature"
    elif not np.any(temp >= F32(tmin_c)):
        reason = (
            f"not started: the temperature stayed below SYS_CAL_TMIN {tmin_c:g} °C "
            f"(highest {float(np.max(temp)):.1f} °C)"
        )
    else:
        reason = f"not started: no sample at or above SYS_CAL_TMIN {tmin_c:g} °C after "
        reason += f"{PX4_SETTLE_S:.0f} s from boot"
    return Px4Oncal(kind, instance, "not started", reason, 0, math.nan, math.nan, math.nan,
                    0, {}, math.nan)  # fmt: skip


def _px4_params(
    kind: str, instance: int, res: FloatArray, low: float, high: float, ref: float,
    device_id: int,
) -> dict[str, float]:  # fmt: skip
    """``finish_sensor_instance``: ``TC_<G|A><i>_X<3-k>_<axis>`` = float(p_k), the range."""
    tag = "G" if kind == "gyro" else "A"
    p = f"TC_{tag}{instance}_"
    out: dict[str, float] = {p + "ID": float(device_id)}
    for axis in range(3):
        for k in range(4):
            v = 0.0 if (kind == "accel" and k == 3) else res[k, axis]
            out[f"{p}X{3 - k}_{axis}"] = float(F32(v))
    out.update({p + "TMAX": high, p + "TMIN": low, p + "TREF": ref})
    return out


__all__ = [
    "AP_MIN_SAMPLES",
    "AP_RANGE_MIN_C",
    "AP_SAVE_S",
    "AP_STEP_C",
    "AP_TIMEOUT_S",
    "PX4_TDEL_C",
    "PX4_TMAX_C",
    "PX4_TMIN_C",
    "ArdupilotLearning",
    "LearnPoint",
    "Px4Oncal",
    "ardupilot_learning",
    "ardupilot_temperature_filter",
    "px4_oncal",
]
