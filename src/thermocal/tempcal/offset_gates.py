"""Gates of PX4's barometers and magnetometers before their ``TC_B``/``TC_M`` fit: what no
barometer on Earth and no still magnetometer reads is named and the sensor
left out (no ``TC_B<n>``/``TC_M<n>`` written, the IMU calibrations kept), or the odd samples
set aside with their count — never fitted.

Barometer (``sensor_baro.pressure`` [Pa], PX4 ``msg/SensorBaro.msg``):

* **plausible pressure**: :data:`BARO_RANGE_PA` (30 000…110 000 Pa: the US Standard
  Atmosphere 1976 gives 30 090 Pa at 9 km, above any flight-controller calibration bench,
  and the highest sea-level pressure recorded is 108 480 Pa, WMO archive).  A log whose
  median reads 300…1100 is in hPa (mbar), 30…110 in kPa: named and left out.  Fewer than
  :data:`MIN_PLAUSIBLE_SHARE` of the samples outside: set aside with their count.
* **altitude held**: a barometer's thermal drift is a smooth function of its temperature;
  the 1-s medians of the pressure must stay within :data:`BARO_STEP_PA` of a polynomial of
  order :data:`SMOOTH_ORDER` in the temperature (:func:`altitude_residual`): 100 Pa is about
  8 m near sea level (dp/dh = −ρg ≈ −12 Pa/m).  A departure is the board carried or flown
  (or weather faster than the sweep): named with its time span and left out.

Magnetometer (``sensor_mag.x/y/z`` [gauss], ``msg/SensorMag.msg``):

* **field magnitude**: Earth's field is 0.25…0.65 gauss (25…65 µT, IGRF); a board's hard
  iron adds some, so a median magnitude outside :data:`MAG_RANGE_GAUSS` (a factor 3 around
  Earth's) is another unit (µT ×100, mgauss ×1000, nT ×1e5, tesla ×1e-4): named and left
  out; single samples outside are set aside with their count.
* **heading held**: the direction of the 1-s mean field must stay within
  :data:`MAG_TURN_DEG` of its median direction (thermal offsets of a few mgauss turn a
  0.25-gauss field by about 1°); a turning vehicle is named with its time span and left out.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from thermocal.recording import FloatArray

BARO_RANGE_PA = (30_000.0, 110_000.0)
"""Pressures a barometer reads at the Earth's surface or in flight [Pa] (module docstring)."""
BARO_STEP_PA = 100.0
"""Largest departure of a still board's pressure from a smooth curve of its temperature [Pa]
(:func:`altitude_residual`; about 8 m near sea level)."""
CHANGE_WINDOW_S = 60.0
"""The window in which a departure from the smooth curve is located (said, not judged) [s]."""
SMOOTH_ORDER = 5
"""The order of the smooth curve of the temperature the pressure must follow (PX4's TC_B)."""
MAG_EARTH_GAUSS = (0.25, 0.65)
"""Earth's field magnitude [gauss] (IGRF: about 25 µT at the magnetic equator to 65 µT near
the poles)."""
MAG_RANGE_GAUSS = (MAG_EARTH_GAUSS[0] / 3.0, MAG_EARTH_GAUSS[1] * 3.0)
"""Magnitudes a board's magnetometer reads in gauss (Earth's, a factor 3 for hard iron)."""
MAG_TURN_DEG = 10.0
"""Largest angle of the 1-s mean field from its median direction on a still board [°]."""
MIN_PLAUSIBLE_SHARE = 0.5
"""Fewer plausible samples than this share: the sensor is left out, not its samples."""

_BARO_UNITS = (("hPa (mbar)", 100.0), ("kPa", 1000.0), ("psi", 6894.757))
_MAG_UNITS = (("µT", 0.01), ("milligauss", 0.001), ("nT", 1e-5), ("tesla", 1e4))


@dataclass(frozen=True)
class Screened:
    """The samples kept (``keep``, a boolean mask) or ``None`` (the sensor left out), and
    the sentences said (``left_out`` why it was left out, ``notes`` samples set aside).

    Attributes
    ----------
    keep : numpy.ndarray of bool or None
        The samples kept (None: the sensor left out).
    left_out : str or None
        Why it was left out.
    notes : tuple of str
        The samples set aside, said.
    """

    keep: npt.NDArray[np.bool_] | None
    left_out: str | None
    notes: tuple[str, ...]


def _unit_guess(median: float, units: tuple[tuple[str, float], ...], lo: float,
                hi: float) -> str:  # fmt: skip
    """The unit whose factor brings ``median`` into ``lo``…``hi``, said as a clause."""
    for name, factor in units:
        if lo <= abs(median) * factor <= hi:
            return f" — the values look like {name}"
    return ""


def _block_means(time_s: FloatArray, values: FloatArray, block_s: float = 1.0) -> tuple[
    FloatArray, FloatArray
]:  # fmt: skip
    """(block start times [s], per-block medians (k, m)) of 1-s blocks."""
    t = np.asarray(time_s, dtype=np.float64)
    idx = np.floor((t - t[0]) / block_s).astype(np.int64)
    starts = np.flatnonzero(np.r_[True, np.diff(idx) != 0])
    bounds = np.r_[starts, t.size]
    med = np.array([np.median(values[a:b], axis=0) for a, b in itertools.pairwise(bounds)])
    return t[starts], med.reshape(len(starts), -1)


def _set_aside(where: str, what: str, ok: npt.NDArray[np.bool_], raw: FloatArray) -> str | None:
    """The sentence of the samples set aside (not ``ok``), naming the first."""
    bad = np.flatnonzero(~ok)
    if bad.size == 0:
        return None
    first = bad[0]
    shown = np.asarray(raw[first]).ravel()
    value = ", ".join(f"{v:.6g}" for v in shown)
    return (
        f"{where}: {bad.size} of {ok.size} samples set aside ({what}; the first at row "
        f"{first}: {value}); the fit uses the other {ok.size - bad.size}"
    )


@dataclass(frozen=True)
class Dialect:
    """How a firmware names the pressure field, its unit's source and its parameters.

    Attributes
    ----------
    field : str
        The pressure field's name.
    unit_source : str
        Where its unit is stated.
    params : str
        What the firmware's parameters are called.
    """

    field: str = "pressure"
    unit_source: str = "PX4 logs Pa (SensorBaro.msg)"
    params: str = "TC_B parameters"


ARDUPILOT_BARO = Dialect("Press", "ArduPilot logs Pa (LogStructure.h BARO)", "TCAL_* parameters")


def altitude_residual(temp_c: FloatArray, pressure_pa: FloatArray) -> FloatArray:
    r"""The pressure minus its least-squares polynomial in the temperature: what the temperature
    does not explain (a climb, a descent, the board carried).

    Parameters
    ----------
    temp_c : numpy.ndarray
        Temperatures [°C].
    pressure_pa : numpy.ndarray
        Pressures, same length [Pa].

    Returns
    -------
    numpy.ndarray
        The residual [Pa], same length.

    Notes
    -----
    With :math:`x` the temperature normalised to −1…1 over the sweep and :math:`n` =
    :data:`SMOOTH_ORDER` (PX4's own order for ``TC_B``, fewer with fewer distinct
    temperatures):

    .. math:: r_i = p_i - \sum_{k=0}^{n} \hat a_k x_i^k, \qquad
       \hat a = \arg\min_a \sum_i \Big(p_i - \sum_k a_k x_i^k\Big)^2

    References
    ----------
    - PX4 ``Tools/process_sensor_caldata.py`` (the barometer's polynomial order).
    - G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013 (least squares).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(20.0, 60.0, 50)
    >>> float(np.max(np.abs(altitude_residual(t, 101325.0 + 3.0 * t)))) < 1e-6
    True
    """
    t = np.asarray(temp_c, dtype=np.float64)
    half = max(0.5 * float(np.ptp(t)), 1e-9)
    x = (t - 0.5 * (float(np.max(t)) + float(np.min(t)))) / half
    order = min(SMOOTH_ORDER, max(np.unique(t).size - 1, 0))
    v = np.vander(x, order + 1, increasing=True)
    coef, *_ = np.linalg.lstsq(v, np.asarray(pressure_pa, dtype=np.float64), rcond=None)
    out: FloatArray = np.asarray(pressure_pa, dtype=np.float64) - v @ coef
    return out


def _fastest_change(tb: FloatArray, resid: FloatArray) -> tuple[float, float, float]:
    """(start [s], end [s], change [Pa]) of the :data:`CHANGE_WINDOW_S` window over which
    the residual of :func:`altitude_residual` changes most: where the board moved."""
    j = np.searchsorted(tb, tb + CHANGE_WINDOW_S, side="right") - 1
    change = resid[j] - resid
    k = int(np.argmax(np.abs(change)))
    return float(tb[k]), float(tb[j[k]]), float(change[k])


def screen_baro(where: str, time_s: FloatArray, temp_c: FloatArray, pressure_pa: FloatArray,
                dialect: Dialect = Dialect()) -> Screened:  # fmt: skip
    """The barometer gates (module docstring) of one barometer's samples.

    Parameters
    ----------
    where : str
        Name of the barometer in messages.
    time_s : numpy.ndarray
        Sample times [s].
    temp_c : numpy.ndarray
        Temperatures [°C].
    pressure_pa : numpy.ndarray
        Pressures [Pa].
    dialect : Dialect, optional
        How the firmware names the field and its parameters (default PX4's).

    Returns
    -------
    Screened
        The samples kept (None: the barometer is left out), the sentence saying why it is
        left out, and notes on samples set aside.
    """
    field, params = dialect.field, dialect.params
    p = np.asarray(pressure_pa, dtype=np.float64).reshape(-1)
    finite = np.isfinite(p) & np.isfinite(np.asarray(temp_c, dtype=np.float64))
    if not finite.any():
        name = field if not np.isfinite(p).any() else "temperature (with a finite pressure)"
        return Screened(None, f"{where}: field {name!r} has no finite value (all NaN or "
                        f"infinite): the barometer is left out, no {params} written",
                        ())  # fmt: skip
    lo, hi = BARO_RANGE_PA
    ok = finite & (p >= lo) & (p <= hi)
    if np.count_nonzero(ok) < MIN_PLAUSIBLE_SHARE * p.size:
        med = float(np.median(p[finite]))
        guess = _unit_guess(med, _BARO_UNITS, lo, hi)
        return Screened(None, (
            f"{where}: field {field!r} reads {med:.6g} (median) where {dialect.unit_source}, "
            f"outside any pressure at the Earth's surface or in flight "
            f"({lo:.0f}…{hi:.0f} Pa){guess}: the barometer is left out, no {params} written"
        ), ())  # fmt: skip
    notes = [n for n in [_set_aside(where, f"{field} not finite or outside {lo:.0f}…{hi:.0f} Pa",
                                    ok, p)] if n]  # fmt: skip
    t = np.asarray(time_s, dtype=np.float64)[ok]
    tb, mb = _block_means(t, np.column_stack([p[ok], np.asarray(temp_c, dtype=np.float64)[ok]]))
    resid = altitude_residual(mb[:, 1], mb[:, 0])
    k = int(np.argmax(np.abs(resid)))
    if abs(resid[k]) > BARO_STEP_PA:
        a, b, change = _fastest_change(tb, resid)
        return Screened(None, (
            f"{where}: the pressure departs by {resid[k]:+.0f} Pa (about "
            f"{-resid[k] / 12.0:+.0f} m of altitude) from a smooth curve of the temperature "
            f"(a barometer's thermal drift follows its temperature within {BARO_STEP_PA:g} "
            f"Pa); it changes fastest between {a - t[0]:.0f} s and {b - t[0]:.0f} s of the log "
            f"({change:+.0f} Pa): the board was carried or flown; the barometer is left out, "
            f"no {params} written — record the sweep with the board at rest"
        ), tuple(notes))  # fmt: skip
    return Screened(ok, None, tuple(notes))


def screen_mag(where: str, time_s: FloatArray, temp_c: FloatArray, field_gauss: FloatArray
               ) -> Screened:  # fmt: skip
    """The magnetometer gates (module docstring) of one magnetometer's samples.

    Parameters
    ----------
    where : str
        Name of the magnetometer in messages.
    time_s : numpy.ndarray
        Sample times [s].
    temp_c : numpy.ndarray
        Temperatures [°C].
    field_gauss : numpy.ndarray
        Field (n, 3) [gauss].

    Returns
    -------
    Screened
        The samples kept (None: the magnetometer is left out), the sentence saying why, and
        notes on samples set aside.
    """
    b = np.asarray(field_gauss, dtype=np.float64).reshape(len(temp_c), -1)
    finite = np.all(np.isfinite(b), axis=1) & np.isfinite(np.asarray(temp_c, dtype=np.float64))
    if not finite.any():
        name = "x, y, z" if not np.all(np.isfinite(b), axis=1).any() else "temperature"
        return Screened(None, f"{where}: field(s) {name}: no finite row (NaN or infinite): "
                        "the magnetometer is left out, no TC_M parameters written", ())  # fmt: skip
    mag = np.full(b.shape[0], np.nan)
    mag[finite] = np.linalg.norm(b[finite], axis=1)
    lo, hi = MAG_RANGE_GAUSS
    ok = finite & (mag >= lo) & (mag <= hi)
    if np.count_nonzero(ok) < MIN_PLAUSIBLE_SHARE * b.shape[0]:
        med = float(np.median(mag[finite]))
        guess = _unit_guess(med, _MAG_UNITS, *MAG_EARTH_GAUSS)
        return Screened(None, (
            f"{where}: the field magnitude is {med:.6g} (median) where PX4 logs gauss "
            f"(SensorMag.msg) and Earth's field is {MAG_EARTH_GAUSS[0]:g}…{MAG_EARTH_GAUSS[1]:g} "
            f"gauss (beyond {lo:.3g}…{hi:.3g} with a board's hard iron){guess}: the "
            "magnetometer is left out, no TC_M parameters written"
        ), ())  # fmt: skip
    notes = [n for n in [_set_aside(where, f"field magnitude not finite or outside "
                                    f"{lo:.3g}…{hi:.3g} gauss", ok, b)] if n]  # fmt: skip
    t = np.asarray(time_s, dtype=np.float64)[ok]
    tb, mb = _block_means(t, b[ok])
    unit = mb / np.linalg.norm(mb, axis=1, keepdims=True)
    ref = np.median(unit, axis=0)
    ref /= np.linalg.norm(ref)
    angle = np.degrees(np.arccos(np.clip(unit @ ref, -1.0, 1.0)))
    off = np.flatnonzero(angle > MAG_TURN_DEG)
    if off.size:
        return Screened(None, (
            f"{where}: the field turns by up to {float(np.max(angle)):.0f}° from its median "
            f"direction between {tb[off[0]] - t[0]:.0f} s and {tb[off[-1]] - t[0]:.0f} s of the "
            f"log (a still board: within {MAG_TURN_DEG:g}°): the vehicle turned; the "
            "magnetometer is left out, no TC_M parameters written — record the sweep with "
            "the board at rest"
        ), tuple(notes))  # fmt: skip
    return Screened(ok, None, tuple(notes))


__all__ = [
    "ARDUPILOT_BARO",
    "BARO_RANGE_PA",
    "BARO_STEP_PA",
    "CHANGE_WINDOW_S",
    "MAG_EARTH_GAUSS",
    "MAG_RANGE_GAUSS",
    "MAG_TURN_DEG",
    "SMOOTH_ORDER",
    "Dialect",
    "Screened",
    "altitude_residual",
    "screen_baro",
    "screen_mag",
]
