"""ArduPilot's IMU temperature calibration from arrays of temperature and sensor output.

:func:`ardupilot_coefficients` fits the polynomial ArduPilot's IMU temperature
calibration applies (``AP_InertialSensor_tempcal.cpp``): per axis a cubic in
``T − 35 °C`` whose constant is dropped (the correction is relative to the temperature of
the sensor calibration), stored ×1e6 as ``INS_TCAL<n>_GYR<k>_<X|Y|Z>`` and
``_ACC<k>_<X|Y|Z>``.  Beside it, the firmware's own pieces restated as pure functions: the
correction curve (:func:`ardupilot_poly_curve`), the firmware's learning fit
(:func:`tclr_learned`) and the board rotations ``AHRS_ORIENTATION`` takes
(:func:`ardupilot_rotation`).  No file is read or written here.

References
----------
* ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``,
  https://github.com/ArduPilot/ardupilot/blob/master/libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp
* ArduPilot, ``libraries/AP_Math/polyfit.h`` and ``libraries/AP_Math/rotations.h``,
  https://github.com/ArduPilot/ardupilot/tree/master/libraries/AP_Math
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.firmware.binning import BIN_WIDTH_C
from thermocal.firmware.formats import AP_TREF_C, FORMATS
from thermocal.firmware.px4 import binned_polynomial

FloatArray = npt.NDArray[np.float64]
ARDUPILOT = FORMATS["ardupilot"]

AP_ROTATIONS: dict[int, str] = {
    0: "NONE", 1: "YAW_45", 2: "YAW_90", 3: "YAW_135", 4: "YAW_180", 5: "YAW_225",
    6: "YAW_270", 7: "YAW_315", 8: "ROLL_180", 9: "ROLL_180_YAW_45", 10: "ROLL_180_YAW_90",
    11: "ROLL_180_YAW_135", 12: "PITCH_180", 13: "ROLL_180_YAW_225", 14: "ROLL_180_YAW_270",
    15: "ROLL_180_YAW_315", 16: "ROLL_90", 17: "ROLL_90_YAW_45", 18: "ROLL_90_YAW_90",
    19: "ROLL_90_YAW_135", 20: "ROLL_270", 21: "ROLL_270_YAW_45", 22: "ROLL_270_YAW_90",
    23: "ROLL_270_YAW_135", 24: "PITCH_90", 25: "PITCH_270", 26: "PITCH_180_YAW_90",
    27: "PITCH_180_YAW_270", 28: "ROLL_90_PITCH_90", 29: "ROLL_180_PITCH_90",
    30: "ROLL_270_PITCH_90", 31: "ROLL_90_PITCH_180", 32: "ROLL_270_PITCH_180",
    33: "ROLL_90_PITCH_270", 34: "ROLL_180_PITCH_270", 35: "ROLL_270_PITCH_270",
    36: "ROLL_90_PITCH_180_YAW_90", 37: "ROLL_90_YAW_270", 39: "PITCH_315",
    40: "ROLL_90_PITCH_315", 41: "PITCH_7", 42: "ROLL_45", 43: "ROLL_315",
}  # fmt: skip
"""ArduPilot's ``enum Rotation`` (``libraries/AP_Math/rotations.h``), the board orientations
``AHRS_ORIENTATION`` takes, by value; 38 (``ROLL_90_PITCH_68_YAW_293``) and 100 (custom) are
not implemented and refused by name."""
AP_REFUSED_ROTATIONS = {38: "ROLL_90_PITCH_68_YAW_293", 100: "CUSTOM"}


def ardupilot_rotation(code: int) -> FloatArray:
    r"""The matrix of ArduPilot board rotation ``code`` (``AHRS_ORIENTATION``).

    Parameters
    ----------
    code : int
        A value of ArduPilot's ``enum Rotation`` (:data:`AP_ROTATIONS`).

    Returns
    -------
    numpy.ndarray
        The 3×3 matrix :math:`R` with ``Vector3::rotate`` giving :math:`R v`.

    Raises
    ------
    ThermocalInputError
        When ``code`` is not implemented (38, 100 custom, or unknown).

    Notes
    -----
    For ``ROTATION_ROLL_r_PITCH_p_YAW_y``:

    .. math:: R = R_z(y)\,R_y(p)\,R_x(r)

    checked against ``rotations.cpp``: YAW_90 is (x, y) → (−y, x), ROLL_90 is (y, z) → (−z, y),
    PITCH_90 is (x, z) → (z, −x).

    References
    ----------
    - ArduPilot ``libraries/AP_Math/rotations.h`` and ``libraries/AP_Math/vector3.cpp``
      (``Vector3::rotate``).

    Examples
    --------
    >>> import numpy as np
    >>> (ardupilot_rotation(2) @ np.array([1.0, 0.0, 0.0])).round(3).tolist()
    [0.0, 1.0, 0.0]
    """
    if code not in AP_ROTATIONS:
        name = AP_REFUSED_ROTATIONS.get(code, "unknown")
        raise ThermocalInputError(
            f"AHRS_ORIENTATION {code} ({name}) is not implemented: the data cannot be rotated "
            "back to the sensor frame; calibrate from a log recorded with AHRS_ORIENTATION 0"
        )
    angles = {"ROLL": 0.0, "PITCH": 0.0, "YAW": 0.0}
    parts = AP_ROTATIONS[code].split("_")
    for axis, deg in zip(parts[::2], parts[1::2], strict=True):
        angles[axis] = math.radians(float(deg))
    cr, sr = math.cos(angles["ROLL"]), math.sin(angles["ROLL"])
    cp, sp = math.cos(angles["PITCH"]), math.sin(angles["PITCH"])
    cy, sy = math.cos(angles["YAW"]), math.sin(angles["YAW"])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    r: FloatArray = np.round(rz @ ry @ rx, 12).astype(np.float64)
    return r


AP_CURVE_FORMULA = (
    "poly(clamp(T, TMIN, TMAX) − 35 °C), poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6 "
    "(AP_InertialSensor_tempcal.cpp correct_sensor, without its constant CALTEMP term)"
)


def ardupilot_poly_curve(
    coef: Sequence[Sequence[float]], tmin_c: float, tmax_c: float
) -> Callable[[FloatArray], FloatArray]:
    r"""The temperature-dependent part of ArduPilot's correction for stored coefficients.

    Parameters
    ----------
    coef : sequence of sequence of float
        ``coef[k - 1][axis]`` = :math:`c_k` as stored (×1e6), k = 1…3, axes x, y, z.
    tmin_c, tmax_c : float
        The calibrated range ``INS_TCAL<n>_TMIN``/``_TMAX`` [°C].

    Returns
    -------
    callable
        ``curve(temp_c)``: temperatures (n,) [°C] → correction (n, 3) [rad/s or m/s²].

    Notes
    -----
    :data:`AP_CURVE_FORMULA`:

    .. math:: p(t) = (c_1 + (c_2 + c_3 t)\,t)\,t \cdot 10^{-6}, \qquad
       t = \operatorname{clamp}(T, T_{min}, T_{max}) - 35

    References
    ----------
    - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
      (``correct_sensor``).

    Examples
    --------
    >>> import numpy as np
    >>> curve = ardupilot_poly_curve([[100.0, 0, 0], [0, 0, 0], [0, 0, 0]], 20.0, 50.0)
    >>> [round(float(x), 6) for x in curve(np.array([45.0, 60.0]))[:, 0]]
    [0.001, 0.0015]
    """
    c = np.asarray(coef, dtype=np.float64)

    def curve(temp_c: FloatArray) -> FloatArray:
        t = (np.clip(np.asarray(temp_c, dtype=np.float64), tmin_c, tmax_c) - AP_TREF_C)[:, None]
        out: FloatArray = (c[0] + (c[1] + c[2] * t) * t) * t * 1e-6
        return out

    return curve


def tclr_learned(temp_c: FloatArray, xyz: FloatArray) -> list[list[float]]:
    r"""The coefficients the firmware learns from its ``TCLR`` points.

    Parameters
    ----------
    temp_c : numpy.ndarray
        The points' temperatures (n,) [°C], at least 4 distinct.
    xyz : numpy.ndarray
        The points' X, Y, Z (n, 3) [rad/s or m/s²].

    Returns
    -------
    list of list of float
        ``c[k - 1][axis]`` as stored (×1e6), k = 1…3 (the constant dropped).

    Notes
    -----
    The firmware's ``PolyFit<4>`` is the least-squares cubic with constant, per axis, in
    :math:`t = T - 35`:

    .. math:: \min_p \sum_i \left(v_i - \sum_{k=0}^{3} p_k t_i^k\right)^2, \qquad
       c_k = 10^6\,p_k,\; k = 1 \ldots 3

    References
    ----------
    - ArduPilot ``libraries/AP_Math/polyfit.h`` and
      ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp`` (``save_calibration``).
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013 (least squares).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(20.0, 60.0, 9)
    >>> v = np.column_stack([2e-6 * (t - 35.0), 0 * t, 0 * t])
    >>> [round(x, 6) for x in tclr_learned(t, v)[0]]
    [2.0, 0.0, 0.0]
    """
    v = np.vander(np.asarray(temp_c, dtype=np.float64) - AP_TREF_C, 4, increasing=True)
    p, *_ = np.linalg.lstsq(v, np.asarray(xyz, dtype=np.float64), rcond=None)
    return [[float(x) * 1e6 for x in p[k]] for k in (1, 2, 3)]


@dataclass(frozen=True)
class ArdupilotFit:
    """ArduPilot's temperature calibration of one IMU sensor (gyro or accelerometer).

    Parameters
    ----------
    kind : str
        ``"gyro"`` or ``"accel"``.
    tmin_c, tmax_c : float
        The calibrated range, ``INS_TCAL<n>_TMIN``/``_TMAX`` [°C].
    coefficients : tuple of tuple of float
        ``coefficients[k - 1][axis]`` = ``c_k`` as stored (×1e6), k = 1…3, axes x, y, z.
    holdout_rms : tuple of float
        Per axis, the rms of a cubic fitted to the even temperature bins, evaluated on the
        odd ones [rad/s or m/s²].
    n_samples, n_bins : int
        Samples given, occupied temperature bins fitted.

    Notes
    -----
    The firmware (``AP_InertialSensor_tempcal.cpp``, ``correct_sensor``) subtracts

    .. math::

        p(\\operatorname{clamp}(T) - 35) - p(T_\\mathrm{cal} - 35), \\qquad
        p(t) = (c_1 + (c_2 + c_3 t)\\,t)\\,t \\cdot 10^{-6}

    with :math:`T_\\mathrm{cal}` the temperature of the accelerometer or gyro calibration
    (``INS_ACC<n>_CALTEMP``, ``INS_GYR<n>_CALTEMP``).
    """

    kind: str
    tmin_c: float
    tmax_c: float
    coefficients: tuple[tuple[float, ...], ...]
    holdout_rms: tuple[float, ...]
    n_samples: int
    n_bins: int

    def correction(self, temperature_c: npt.ArrayLike, caltemp_c: float = AP_TREF_C) -> FloatArray:
        r"""What the firmware subtracts at ``temperature_c``, calibrated at ``caltemp_c``.

        Parameters
        ----------
        temperature_c : array_like
            Temperatures [°C] (clamped to ``tmin_c…tmax_c``).
        caltemp_c : float, optional
            ``INS_ACC<n>_CALTEMP``/``INS_GYR<n>_CALTEMP`` [°C]; default 35.

        Returns
        -------
        numpy.ndarray
            Shape (n, 3) [rad/s or m/s²].

        Notes
        -----
        .. math:: \Delta(T) = p(\operatorname{clamp}(T) - 35)
           - p(\operatorname{clamp}(T_{cal}) - 35)

        with :math:`p` of :func:`ardupilot_poly_curve`.

        References
        ----------
        - ArduPilot ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
          (``correct_sensor``).
        """
        curve = ardupilot_poly_curve(self.coefficients, self.tmin_c, self.tmax_c)
        t = np.asarray(temperature_c, dtype=np.float64).ravel()
        return curve(t) - curve(np.array([float(caltemp_c)]))

    def params(self, instance: int = 0) -> dict[str, float]:
        """The ``INS_TCAL<instance + 1>_*`` parameters of this sensor.

        Parameters
        ----------
        instance : int
            The IMU, 0…2 (``INS_TCAL1`` … ``INS_TCAL3``).

        Returns
        -------
        dict
            Name → value: ``_ENABLE`` (1), ``_TMIN``, ``_TMAX`` and
            ``_GYR<k>_<X|Y|Z>`` or ``_ACC<k>_<X|Y|Z>``.

        Raises
        ------
        thermocal.errors.ParameterError
            ``instance`` outside 0…2.
        """
        if not 0 <= instance < ARDUPILOT.max_instances:
            raise ParameterError(
                "instance",
                f"{{name}} {instance}: ArduPilot has instances 0…{ARDUPILOT.max_instances - 1}",
            )
        p = f"INS_TCAL{instance + 1}_"
        tag = ARDUPILOT.sensors[self.kind].tag
        out: dict[str, float] = {p + "ENABLE": 1, p + "TMIN": self.tmin_c, p + "TMAX": self.tmax_c}
        for k, row in enumerate(self.coefficients, start=1):
            for axis, c in zip("XYZ", row, strict=True):
                out[f"{p}{tag}{k}_{axis}"] = c
        return out

    def to_dict(self) -> dict[str, Any]:
        """The fit as plain values (JSON)."""
        return asdict(self)


def ardupilot_coefficients(
    temperature_c: npt.ArrayLike,
    values: npt.ArrayLike,
    *,
    kind: str = "gyro",
    bin_width_c: float = BIN_WIDTH_C,
) -> ArdupilotFit:
    """ArduPilot's IMU temperature-calibration coefficients of one gyro or accelerometer.

    Parameters
    ----------
    temperature_c : array_like, shape (n,)
        The IMU's temperature [°C].
    values : array_like, shape (n, 3)
        The sensor output at rest in the sensor frame: gyro [rad/s], accelerometer [m/s²].
    kind : {"gyro", "accel"}
        Which sensor (the parameter names ``GYR``/``ACC``).
    bin_width_c : float
        Width of the temperature bins whose medians are fitted [°C].

    Returns
    -------
    ArdupilotFit
        ``TMIN``/``TMAX`` (the recorded extremes), ``c_k`` per axis as stored (×1e6),
        hold-out rms.

    Raises
    ------
    thermocal.errors.ParameterError
        Arrays of different lengths or not finite, an unknown ``kind``, a sweep covering too
        few temperature bins.

    Notes
    -----
    A least-squares cubic with constant in ``T − 35`` is fitted to the medians of the
    temperature bins (:func:`thermocal.firmware.px4.binned_polynomial`),
    :math:`v \\approx p_0 + p_1 t + p_2 t^2 + p_3 t^3`, :math:`t = T - 35`; the firmware
    stores :math:`c_k = p_k \\cdot 10^{6}`, k = 1…3, the constant dropped (the learning of
    ``AP_InertialSensor_tempcal.cpp`` does the same with its ``PolyFit<4>``).

    References
    ----------
    * ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``
      (``Learn::save_calibration``, ``correct_sensor``).

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> temp = np.linspace(-10.0, 60.0, 20_000)
    >>> bias = 1e-4 * (temp - 35.0) + 2e-6 * (temp - 35.0) ** 2   # rad/s
    >>> gyro = np.column_stack([bias, bias, bias]) + 1e-4 * rng.standard_normal((20_000, 3))
    >>> fit = ardupilot_coefficients(temp, gyro, kind="gyro")
    >>> [round(c) for c in (fit.coefficients[0][0], fit.coefficients[1][0])]
    [100, 2]
    >>> fit.params(0)["INS_TCAL1_TMAX"]
    60.0
    """
    if kind not in ARDUPILOT.sensors:
        raise ParameterError(
            "kind", f"{{name}} must be one of {', '.join(ARDUPILOT.sensors)}, got {kind!r}"
        )
    temp = np.asarray(temperature_c, dtype=np.float64).ravel()
    vals = np.asarray(values, dtype=np.float64)
    if vals.ndim != 2 or vals.shape[1] != 3:
        raise ParameterError("values", f"{{name}} must have shape (n, 3), got {vals.shape}")
    coefs, rms, n_bins = binned_polynomial(temp, vals, 3, AP_TREF_C, bin_width_c=bin_width_c)
    scale = ARDUPILOT.scale
    stored = tuple(tuple(float(coefs[j, k]) / scale for j in range(3)) for k in (1, 2, 3))
    return ArdupilotFit(
        kind, float(np.min(temp)), float(np.max(temp)), stored, tuple(float(r) for r in rms),
        int(temp.size), n_bins,
    )  # fmt: skip


__all__ = [
    "AP_CURVE_FORMULA",
    "AP_REFUSED_ROTATIONS",
    "AP_ROTATIONS",
    "ArdupilotFit",
    "ardupilot_coefficients",
    "ardupilot_poly_curve",
    "ardupilot_rotation",
    "tclr_learned",
]
