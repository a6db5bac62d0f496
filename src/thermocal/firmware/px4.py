"""PX4's thermal-compensation coefficients from arrays of temperature and sensor output.

:func:`px4_coefficients` is the fit of PX4's offboard calibration script
(``Tools/process_sensor_caldata.py``) as a pure function: per axis, a polynomial of the
firmware's order in ``T − TREF`` with ``TREF`` the middle of the recorded range, offsets
in the firmware's SI units (gyro rad/s, accelerometer m/s², barometer Pa, magnetometer
gauss).  :class:`Px4Fit` holds the result, evaluates the firmware's correction and names
the ``TC_*`` parameters.  No file is read or written here.

References
----------
* PX4-Autopilot, ``Tools/process_sensor_caldata.py``,
  https://github.com/PX4/PX4-Autopilot/blob/main/Tools/process_sensor_caldata.py
* PX4-Autopilot, ``src/modules/temperature_compensation/TemperatureCompensation.cpp``,
  https://github.com/PX4/PX4-Autopilot/tree/main/src/modules/temperature_compensation
* PX4 User Guide, "Thermal Compensation", https://docs.px4.io/main/en/advanced_config/sensor_thermal_calibration.html
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import ParameterError
from thermocal.firmware.binning import BIN_WIDTH_C, MIN_BINS, even_odd_split, temperature_bins
from thermocal.firmware.formats import FORMATS, SensorParams

FloatArray = npt.NDArray[np.float64]
PX4 = FORMATS["px4"]
AXIS_NAMES = ("x", "y", "z")


@dataclass(frozen=True)
class Px4Fit:
    """PX4's thermal compensation of one sensor instance.

    Parameters
    ----------
    kind : str
        ``"gyro"``, ``"accel"``, ``"baro"`` or ``"mag"``.
    tmin_c, tmax_c : float
        The calibrated range, ``TMIN`` and ``TMAX`` [°C].
    tref_c : float
        The reference temperature ``TREF`` [°C].
    coefficients : tuple of tuple of float
        ``coefficients[axis][k]`` = ``X_k`` of ``(T − TREF)^k``, k = 0…order [firmware
        unit: rad/s, m/s², Pa or gauss].
    holdout_rms : tuple of float
        Per axis, the rms of a polynomial fitted to the even temperature bins, evaluated on
        the odd ones [firmware unit]: how well the fit predicts data it was not fitted to.
    n_samples, n_bins : int
        Samples given, occupied temperature bins fitted.
    relative : bool
        The offsets are relative to the median of the data (accelerometer, barometer,
        magnetometer: gravity, the weather and the Earth's field are in the data).

    Notes
    -----
    The firmware subtracts, per axis ``i``,

    .. math::

        o_i(T) = \\sum_{k=0}^{n} X_{k,i}\\,\\Delta T^k, \\qquad
        \\Delta T = \\operatorname{clamp}(T, T_\\mathrm{min}, T_\\mathrm{max}) - T_\\mathrm{ref}

    (``TemperatureCompensation::apply``).

    References
    ----------
    - PX4 ``src/modules/sensors/temperature_compensation/TemperatureCompensation.cpp``.
    """

    kind: str
    tmin_c: float
    tmax_c: float
    tref_c: float
    coefficients: tuple[tuple[float, ...], ...]
    holdout_rms: tuple[float, ...]
    n_samples: int
    n_bins: int
    relative: bool

    def offset(self, temperature_c: npt.ArrayLike) -> FloatArray:
        r"""The offset the firmware subtracts at ``temperature_c``.

        Parameters
        ----------
        temperature_c : array_like
            Temperatures [°C], clamped to ``TMIN…TMAX`` as the firmware does.

        Returns
        -------
        numpy.ndarray
            Shape (n, axes) [firmware unit].

        Notes
        -----
        .. math:: o_i(T) = \sum_{k=0}^{n} X_{k,i}\,\Delta T^k, \qquad
           \Delta T = \operatorname{clamp}(T, T_{min}, T_{max}) - T_{ref}

        References
        ----------
        - PX4 ``src/modules/sensors/temperature_compensation/TemperatureCompensation.cpp``.
        """
        t = np.clip(np.asarray(temperature_c, dtype=np.float64).ravel(), self.tmin_c, self.tmax_c)
        c = np.asarray(self.coefficients, dtype=np.float64)  # (axes, order + 1)
        out = np.asarray(np.polynomial.polynomial.polyval(t - self.tref_c, c.T), np.float64)
        return out.T.reshape(t.size, -1)

    def params(self, instance: int = 0, device_id: int = 0) -> dict[str, float]:
        """The ``TC_*`` parameters of this sensor as instance ``instance``.

        Parameters
        ----------
        instance : int
            0…3: ``TC_G0`` … ``TC_G3`` (and A, B, M).
        device_id : int
            PX4's device id of the sensor (``TC_G<n>_ID``: the firmware applies the
            parameters to the sensor with this id).

        Returns
        -------
        dict
            Name → value: ``TC_<L>_ENABLE``, ``TC_<L><n>_ID``, ``_TMIN``, ``_TMAX``,
            ``_TREF`` and ``_X<k>_<axis>`` (``_X<k>`` for the barometer).

        Raises
        ------
        thermocal.errors.ParameterError
            ``instance`` outside 0…3.
        """
        if not 0 <= instance < PX4.max_instances:
            raise ParameterError(
                "instance", f"{{name}} {instance}: PX4 has instances 0…{PX4.max_instances - 1}"
            )
        letter = PX4.sensors[self.kind].tag
        p = f"TC_{letter}{instance}_"
        out: dict[str, float] = {f"TC_{letter}_ENABLE": 1, p + "ID": int(device_id)}
        out.update({p + "TMIN": self.tmin_c, p + "TMAX": self.tmax_c, p + "TREF": self.tref_c})
        for i, axis in enumerate(self.coefficients):
            for k, c in enumerate(axis):
                out[f"{p}X{k}" if len(self.coefficients) == 1 else f"{p}X{k}_{i}"] = c
        return out

    def to_dict(self) -> dict[str, Any]:
        """The fit as plain values (JSON)."""
        return asdict(self)


def _sensor(kind: str) -> SensorParams:
    """The PX4 sensor ``kind`` (``ParameterError`` for one PX4 does not compensate)."""
    if kind not in PX4.sensors:
        raise ParameterError(
            "kind", f"{{name}} must be one of {', '.join(PX4.sensors)}, got {kind!r}"
        )
    return PX4.sensors[kind]


def _checked(temperature_c: npt.ArrayLike, values: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Both arrays as float64, ``values`` as (n, axes); refused when empty, not finite or
    of different lengths."""
    temp = np.asarray(temperature_c, dtype=np.float64).ravel()
    vals = np.asarray(values, dtype=np.float64)
    vals = vals.reshape(-1, 1) if vals.ndim == 1 else vals
    if vals.ndim != 2 or vals.shape[0] != temp.size:
        raise ParameterError(
            "values", f"{{name}} must have one row per temperature ({temp.size}), got shape "
            f"{np.shape(values)}",
        )  # fmt: skip
    if temp.size == 0 or not np.all(np.isfinite(temp)):
        raise ParameterError("temperature_c", "{name} must be finite and not empty")
    if not np.all(np.isfinite(vals)):
        raise ParameterError("values", "{name} must be finite")
    return temp, vals


def binned_polynomial(
    temperature_c: npt.ArrayLike,
    values: npt.ArrayLike,
    order: int,
    tref_c: float,
    *,
    bin_width_c: float = BIN_WIDTH_C,
) -> tuple[FloatArray, FloatArray, int]:
    """A polynomial per column of ``values`` in ``T − tref_c``, fitted to the medians of the
    occupied temperature bins, and its hold-out rms.

    Parameters
    ----------
    temperature_c : array_like, shape (n,)
        Temperature of each sample [°C].
    values : array_like, shape (n,) or (n, axes)
        The sensor output [any unit].
    order : int
        Degree of the polynomial.
    tref_c : float
        Reference temperature [°C].
    bin_width_c : float
        Width of the temperature bins [°C].

    Returns
    -------
    coefficients : ndarray, shape (axes, order + 1)
        ``c[axis][k]`` of ``(T − tref_c)^k`` [unit of ``values``].
    holdout_rms : ndarray, shape (axes,)
        rms on the odd bins of the polynomial fitted to the even bins [unit of ``values``].
    n_bins : int
        Occupied bins.

    Raises
    ------
    thermocal.errors.ParameterError
        Fewer than ``max(8, 2·(order + 1))`` occupied bins (parameter ``temperature_c``).

    Notes
    -----
    Every bin weighs the same, whatever the time the sweep spent in it, and its median is
    not moved by a spike.  With bin medians :math:`(\\tilde T_b, \\tilde v_b)`, the
    coefficients minimise :math:`\\sum_b (\\tilde v_b - \\sum_k c_k (\\tilde T_b -
    T_\\mathrm{ref})^k)^2` (``numpy.polynomial.polynomial.polyfit``), as PX4's script fits
    its bin means with ``numpy.polyfit``.

    References
    ----------
    - PX4 ``Tools/process_sensor_caldata.py`` (binned polynomial fit).
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013 (least squares).
    """
    temp, vals = _checked(temperature_c, values)
    _c, t_med, v_med = temperature_bins(temp, vals, bin_width_c)
    need = max(MIN_BINS, 2 * (order + 1))
    if t_med.size < need:
        raise ParameterError(
            "temperature_c",
            f"{{name}} covers {t_med.size} bins of {bin_width_c:g} °C; a polynomial of order "
            f"{order} needs at least {need}: record a wider sweep",
        )
    x = t_med - tref_c
    even, odd = even_odd_split(x.size)
    poly = np.polynomial.polynomial
    held = poly.polyfit(x[even], v_med[even], order)  # (order + 1, axes)
    rms = np.sqrt(
        np.mean((v_med[odd] - poly.polyval(x[odd], held).T.reshape(odd.size, -1)) ** 2, axis=0)
    )
    coefs = np.asarray(poly.polyfit(x, v_med, order), np.float64).reshape(order + 1, -1)
    return coefs.T.copy(), np.asarray(rms, dtype=np.float64).ravel(), int(t_med.size)


def px4_coefficients(
    temperature_c: npt.ArrayLike,
    values: npt.ArrayLike,
    *,
    kind: str = "gyro",
    tref_c: float | None = None,
    bin_width_c: float = BIN_WIDTH_C,
) -> Px4Fit:
    """PX4's thermal-compensation polynomial of one sensor instance.

    Parameters
    ----------
    temperature_c : array_like, shape (n,)
        The sensor's temperature [°C] (``sensor_gyro.temperature`` …).
    values : array_like, shape (n, 3) or (n,)
        The sensor output at rest, in PX4's unit: gyro [rad/s], accelerometer [m/s²],
        barometer pressure [Pa], magnetometer [gauss].
    kind : {"gyro", "accel", "baro", "mag"}
        Which sensor: its polynomial order (3, 3, 5, 3) and whether the offsets are
        relative (all but the gyro: gravity, the weather and the Earth's field are in the
        data, so each axis is taken relative to its median, as PX4's script does).
    tref_c : float, optional
        ``TREF`` [°C]; default the middle of the recorded range, as PX4's script.
    bin_width_c : float
        Width of the temperature bins whose medians are fitted [°C].

    Returns
    -------
    Px4Fit
        ``TMIN``/``TMAX`` (the recorded extremes), ``TREF``, ``X_k`` per axis, hold-out rms.

    Raises
    ------
    thermocal.errors.ParameterError
        Arrays of different lengths, not finite, an unknown ``kind``, a non-finite
        ``tref_c``, or a sweep covering too few temperature bins.

    Notes
    -----
    PX4's script fits, per axis, ``numpy.polyfit(T − TREF, v, order)`` with
    ``TREF = (TMIN + TMAX)/2`` to the means of 2000 temperature bins after a running median
    of 31 samples; here the fit is made to the medians of ``bin_width_c`` bins
    (:func:`binned_polynomial`: equal weight across the range, robust to spikes).  The
    firmware then subtracts

    .. math::

        o(T) = \\sum_{k=0}^{n} X_k\\,(\\operatorname{clamp}(T, T_\\mathrm{min},
        T_\\mathrm{max}) - T_\\mathrm{ref})^k .

    ``thermocal px4-tempcal`` fits the same bins with the same cubic, but takes ``TMIN`` and
    ``TMAX`` at the median temperatures of the first and last bins (the fitted range, a
    fraction of a bin inside the recorded extremes) and writes accelerometer offsets that
    are zero at mid-range instead of relative to the median: with its ``TREF`` given as
    ``tref_c``, the coefficients here are its own, the accelerometer's ``X0`` aside.

    References
    ----------
    * PX4-Autopilot, ``Tools/process_sensor_caldata.py``.
    * PX4-Autopilot, ``src/modules/temperature_compensation/TemperatureCompensation.cpp``.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> temp = np.linspace(-10.0, 60.0, 20_000)
    >>> bias = 0.002 + 1e-4 * (temp - 25.0)              # rad/s
    >>> gyro = np.column_stack([bias, -bias, 0 * bias]) + 1e-4 * rng.standard_normal((20_000, 3))
    >>> fit = px4_coefficients(temp, gyro, kind="gyro")
    >>> fit.tref_c, round(fit.coefficients[0][0], 4), round(fit.coefficients[0][1], 6)
    (25.0, 0.002, 0.0001)
    >>> sorted(fit.params(0, device_id=2293768))[:3]
    ['TC_G0_ID', 'TC_G0_TMAX', 'TC_G0_TMIN']
    """
    sensor = _sensor(kind)
    temp, vals = _checked(temperature_c, values)
    if vals.shape[1] != sensor.n_axes:
        raise ParameterError(
            "values", f"{{name}}: a PX4 {kind} has {sensor.n_axes} axis/axes, got {vals.shape[1]}"
        )
    if tref_c is not None and not math.isfinite(tref_c):
        raise ParameterError("tref_c", f"{{name}} {tref_c}: not a finite temperature")
    lo, hi = float(np.min(temp)), float(np.max(temp))
    tref = 0.5 * (lo + hi) if tref_c is None else float(tref_c)
    relative = kind != "gyro"
    rel = vals - np.median(vals, axis=0) if relative else vals
    coefs, rms, n_bins = binned_polynomial(temp, rel, sensor.order, tref, bin_width_c=bin_width_c)
    return Px4Fit(
        kind, lo, hi, tref, tuple(tuple(float(c) for c in row) for row in coefs),
        tuple(float(r) for r in rms), int(temp.size), n_bins, relative,
    )  # fmt: skip


__all__ = ["Px4Fit", "binned_polynomial", "px4_coefficients"]
