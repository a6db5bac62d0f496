"""The firmware parameter dialects thermocal writes: one table, :data:`FORMATS`.

Each entry says what a flight controller's thermal compensation takes: the sensors it
compensates (parameter prefix, polynomial order, axes, unit), how many instances of each,
the reference temperature of the polynomial, the scale its coefficients are stored with
and the file a ground station loads.  ``thermocal export-params``, ``px4-tempcal`` and
``ardupilot-tempcal`` read their dialect here; a new firmware is one more entry.

References
----------
* PX4-Autopilot, ``src/modules/temperature_compensation/TemperatureCompensation.cpp``
  and ``TemperatureCompensation.h``, https://github.com/PX4/PX4-Autopilot
* PX4-Autopilot, ``Tools/process_sensor_caldata.py``,
  https://github.com/PX4/PX4-Autopilot/blob/main/Tools/process_sensor_caldata.py
* ArduPilot, ``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``,
  https://github.com/ArduPilot/ardupilot
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

AP_TREF_C = 35.0
"""ArduPilot's fixed reference of the temperature polynomial [°C]
(``AP_InertialSensor_tempcal.cpp``: ``TEMP_REFERENCE``)."""
ARDUPILOT_SCALE = 1.0e-6
"""ArduPilot stores its coefficients ``c_k`` scaled: the firmware multiplies them by 1e-6."""
INT32_RANGE = (-(2**31), 2**31 - 1)
"""The values of a firmware's int32 parameter (MAVLink type 6)."""


@dataclass(frozen=True)
class Documented:
    """What a firmware documents of a parameter.

    Parameters
    ----------
    pattern : str
        A regular expression of the parameter names.
    type : int
        The MAVLink type written (6 int32, 9 float).
    lo, hi : float
        The values it takes [the parameter's unit].
    hard : bool
        A value outside is refused (the firmware cannot store or use it); else warned (a
        ground station's @Range, which the firmware itself does not enforce).
    source : str
        Where the firmware documents it.
    """

    pattern: str
    type: int
    lo: float
    hi: float
    hard: bool
    source: str


@dataclass(frozen=True)
class SensorParams:
    """One compensated sensor of a firmware.

    Parameters
    ----------
    kind : str
        ``"gyro"``, ``"accel"``, ``"baro"`` or ``"mag"``.
    tag : str
        The letter or word of its parameter names (PX4 ``G`` in ``TC_G0_X0_0``,
        ArduPilot ``GYR`` in ``INS_TCAL1_GYR1_X``).
    order : int
        Degree of the firmware's polynomial in the temperature.
    n_axes : int
        Axes per instance (3 for a triad, 1 for a barometer's pressure).
    unit : str
        Unit of the offsets the firmware subtracts (``rad/s``, ``m/s^2``, ``Pa``, ``gauss``).
    """

    kind: str
    tag: str
    order: int
    n_axes: int
    unit: str


@dataclass(frozen=True)
class ParamsFileLayout:
    """How a dialect's parameter file is written: the lines its ground station expects
    around thermocal's comment lines, then one line per parameter.

    Parameters
    ----------
    row : str
        One parameter's line, with ``{name}``, ``{value}`` and ``{type}`` (the MAVLink
        type: 6 int32, written as an integer; 9 float, written as Python's shortest repr).
    opening, closing : tuple of str
        The lines before and after the comment lines.
    thermal : str
        What a thermal-compensation file of the dialect holds, for its provenance line.

    References
    ----------
    - QGroundControl Developer Guide, *Parameter File Format*
      (``Vehicle-Id Component-Id Name Value Type``, tab separated), as PX4-Autopilot
      ``Tools/process_sensor_caldata.py`` writes it.
    - ArduPilot, ``Tools/scripts/tempcal_IMU.py``: the ``.parm`` file of ``NAME VALUE``
      lines Mission Planner loads.
    """

    row: str = "{name} {value}"
    opening: tuple[str, ...] = ()
    closing: tuple[str, ...] = ()
    thermal: str = ""

    def text(
        self, params: Mapping[str, float], types: Mapping[str, int], comments: Iterable[str] = ()
    ) -> str:
        """The file's text: :attr:`opening`, ``comments``, :attr:`closing`, one :attr:`row`
        per parameter, newline-terminated.

        Parameters
        ----------
        params : Mapping[str, float]
            Name → value [the parameter's unit], in the order written.
        types : Mapping[str, int]
            Name → MAVLink type (6 int32, 9 float; 9 when absent).
        comments : iterable of str
            Whole comment lines (``# …``) between the opening and the closing.

        Returns
        -------
        str

        Examples
        --------
        >>> ap = FORMATS["ardupilot"].layout
        >>> ap.text({"INS_TCAL1_ENABLE": 1, "INS_TCAL1_TMIN": 10}, {"INS_TCAL1_ENABLE": 6})
        'INS_TCAL1_ENABLE 1\\nINS_TCAL1_TMIN 10.0\\n'
        >>> FORMATS["px4"].layout.text({"TC_G0_X0_0": 0.25}, {}).splitlines()[-1]
        '1\\t1\\tTC_G0_X0_0\\t0.25\\t9'
        """
        rows = []
        for name, value in params.items():
            typ = types.get(name, 9)
            shown = str(int(value)) if typ == 6 else repr(float(value))
            rows.append(self.row.format(name=name, value=shown, type=typ))
        return "\n".join([*self.opening, *comments, *self.closing, *rows]) + "\n"


@dataclass(frozen=True)
class FirmwareFormat:
    """One firmware dialect of thermal-compensation parameters.

    Parameters
    ----------
    name : str
        The dialect's name (``"px4"``, ``"ardupilot"``).
    title : str
        What the parameter file is, for messages.
    params_file : str
        The parameter file of a calibration set (``px4.params``, ``ardupilot.parm``).
    max_instances : int
        Sensor instances of one kind the firmware has parameters for.
    instances : str
        The parameter groups those instances are, for messages.
    tref_c : float or None
        The fixed reference temperature of the polynomial [°C]; None: the middle of the
        calibrated range, written as a parameter (PX4 ``TREF``).
    scale : float
        The factor the firmware multiplies a stored coefficient by (1 for PX4, 1e-6 for
        ArduPilot).
    sensors : Mapping[str, SensorParams]
        The sensors it compensates, by kind.
    source : str
        The firmware source file that applies the parameters.
    documented : tuple of Documented
        The parameters whose type and values the firmware documents (checked before a
        parameter file is written).
    layout : ParamsFileLayout
        How its parameter file is written.
    """

    name: str
    title: str
    params_file: str
    max_instances: int
    instances: str
    tref_c: float | None
    scale: float
    sensors: Mapping[str, SensorParams] = field(default_factory=dict)
    source: str = ""
    documented: tuple[Documented, ...] = ()
    layout: ParamsFileLayout = ParamsFileLayout()


FORMATS: dict[str, FirmwareFormat] = {
    "px4": FirmwareFormat(
        "px4", "QGroundControl parameter file (TC_*)", "px4.params", 4,
        "TC_G0…TC_G3 and TC_A0…TC_A3", None, 1.0,
        {
            "gyro": SensorParams("gyro", "G", 3, 3, "rad/s"),
            "accel": SensorParams("accel", "A", 3, 3, "m/s^2"),
            "baro": SensorParams("baro", "B", 5, 1, "Pa"),
            "mag": SensorParams("mag", "M", 3, 3, "gauss"),
        },
        "src/modules/temperature_compensation/TemperatureCompensation.cpp",
        (
            Documented(r"TC_[GABM]_ENABLE", 6, 0, 1, True,
                       "PX4 TC_G_ENABLE/TC_A_ENABLE/TC_B_ENABLE/TC_M_ENABLE: boolean int32 "
                       "(src/modules/temperature_compensation parameters)"),
            Documented(r"TC_[GABM][0-3]_ID", 6, INT32_RANGE[0], INT32_RANGE[1], True,
                       "PX4 TC_*<n>_ID: int32 (same parameters)"),
        ),
        ParamsFileLayout(
            "1\t1\t{name}\t{value}\t{type}",
            ("# Onboard parameters for Vehicle 1", "#"),
            ("#", "# Vehicle-Id Component-Id Name Value Type"),
            "thermal compensation, TC_*",
        ),
    ),
    "ardupilot": FirmwareFormat(
        "ardupilot", "Mission Planner parameter file (INS_TCAL*)", "ardupilot.parm", 3,
        "INS_TCAL1…INS_TCAL3", AP_TREF_C, ARDUPILOT_SCALE,
        {
            "gyro": SensorParams("gyro", "GYR", 3, 3, "rad/s"),
            "accel": SensorParams("accel", "ACC", 3, 3, "m/s^2"),
        },
        "libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp",
        (
            Documented(r"INS_TCAL[1-3]_ENABLE", 6, 0, 2, True,
                       "ArduPilot INS_TCALn_ENABLE @Values 0:Disabled,1:Enabled,2:LearnCalibration "
                       "(AP_InertialSensor_tempcal.cpp)"),
            Documented(r"INS_TCAL[1-3]_T(MIN|MAX)", 9, -70, 80, False,
                       "ArduPilot INS_TCALn_TMIN/TMAX @Range: -70 80 degC "
                       "(AP_InertialSensor_tempcal.cpp; the firmware clamps T to the values "
                       "written)"),
            Documented(r"TCAL_ENABLED", 6, 0, 2, True,
                       "ArduPilot TCAL_ENABLED @Values 0:Disabled,1:Enabled,2:EnableAndLearn "
                       "(AP_TempCalibration.cpp)"),
            Documented(r"TCAL_TEMP_(MIN|MAX)", 6, -128, 127, True,
                       "ArduPilot TCAL_TEMP_MIN/MAX: AP_Int8 (AP_TempCalibration.h)"),
            Documented(r"TCAL_BARO_EXP", 9, 0, 2, True,
                       "ArduPilot TCAL_BARO_EXP: exp_limit_min 0 … exp_limit_max 2 "
                       "(AP_TempCalibration.h)"),
        ),
        ParamsFileLayout("{name} {value}", thermal="INS_TCAL*"),
    ),
}  # fmt: skip
"""The firmware dialects by name.  PX4: ``GYRO_COUNT_MAX = ACCEL_COUNT_MAX = 4`` with
``static_assert``\\ s that the ``TC_G0…TC_G3``/``TC_A0…TC_A3`` parameters match
(``TemperatureCompensation.h``); ``TC_B<n>_X0…X5`` (order 5, Pa) and ``TC_M<n>_X<k>_<axis>``
(order 3, gauss) for n = 0…3 (PX4 v1.15 and later).  ArduPilot: ``INS_TCAL1_…INS_TCAL3_``
(``AP_SUBGROUPINFO(tcal_old_param[0..2], "_TCAL1_"…"_TCAL3_")`` in
``AP_InertialSensor.cpp``, the first three IMUs), a cubic without constant about
:data:`AP_TREF_C` stored ×1e6."""


def firmware_format(name: str) -> FirmwareFormat:
    """The dialect called ``name``.

    Parameters
    ----------
    name : str
        A key of :data:`FORMATS`.

    Returns
    -------
    FirmwareFormat
        Its entry.

    Raises
    ------
    thermocal.errors.ParameterError
        ``name`` is not a dialect (parameter ``format``).

    Examples
    --------
    >>> firmware_format("ardupilot").tref_c
    35.0
    >>> firmware_format("px4").sensors["baro"].order
    5
    """
    from thermocal.errors import ParameterError

    if name not in FORMATS:
        raise ParameterError(
            "format", f"{{name}} must be one of {', '.join(FORMATS)}, got {name!r}"
        )
    return FORMATS[name]


__all__ = [
    "AP_TREF_C",
    "ARDUPILOT_SCALE",
    "FORMATS",
    "INT32_RANGE",
    "Documented",
    "FirmwareFormat",
    "ParamsFileLayout",
    "SensorParams",
    "firmware_format",
]
