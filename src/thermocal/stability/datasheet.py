"""An IMU noise model for estimators (Kalibr's ``imu.yaml``) from data-sheet figures.

Pure maths and text: no file I/O.  A data sheet states the white noise either as a noise
density (°/s/√Hz, mdps/√Hz, µg/√Hz) or as a random walk (ARW in °/√h, VRW in m/s/√h); the
two are the same coefficient N of the Allan variance ``σ²(τ) = N²/τ`` (IEEE Std 952-1997
Annex C): ``1 °/s/√Hz = 60 °/√h`` since ``√h = 60 √s``.  Kalibr's continuous-time white-noise
density is N in SI units (the Kalibr wiki "IMU Noise Model": "from the datasheet of the
IMU").  A data sheet rarely states the random walk of the bias; the Kalibr wiki suggests
reading it from the in-run bias stability (the Allan deviation's minimum) "assuming that the
noise is dominated by white noise and a random walk": the minimum of
``σ²(τ) = N²/τ + K²τ/3`` is ``σ_min² = 2NK/√3`` at ``τ = √3 N/K``, so
``K = √3 σ_min² / (2N)`` — an upper bound of K when flicker noise (the real bias
instability) makes part of the floor.

A data sheet's density is taken as N, as the Kalibr wiki reads it.  Where a data sheet
defines its density as the one-sided amplitude spectral density of the output, white noise
of coefficient N has the one-sided ASD √2·N (:mod:`thermocal.stability.psd`), and N is the
density over √2: the value written is then √2 too large, on the safe side.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, Final, Literal

from thermocal import units
from thermocal.errors import ParameterError
from thermocal.identifiers import one_line
from thermocal.stability.noise_model import (
    IMU_DENSITY,
    IMU_RATE_HZ,
    KALIBR_KEYS,
    ROS_NAME,
    check_kalibr_yaml,
)

Kind = Literal["density", "walk", "bias"]

_G: Final = units.STANDARD_GRAVITY_M_S2
_D: Final = units.DEG_TO_RAD
_H: Final = units.SECONDS_PER_HOUR
_SQRT_H: Final = math.sqrt(units.SECONDS_PER_HOUR)  # √h = 60 √s

# (sensor, kind) -> normalised unit -> factor to the SI unit of the Kalibr key
FACTORS: Final[dict[tuple[str, str], dict[str, float]]] = {
    ("gyro", "density"): {
        "rad/s/sqrt(hz)": 1.0,
        "rad/sqrt(s)": 1.0,
        "deg/s/sqrt(hz)": _D,
        "deg/sqrt(s)": _D,
        "mdps/sqrt(hz)": _D * 1e-3,
        "mdeg/s/sqrt(hz)": _D * 1e-3,
        "deg/h/sqrt(hz)": _D / _H,
        "deg/sqrt(h)": _D / _SQRT_H,
        "rad/sqrt(h)": 1.0 / _SQRT_H,
    },
    ("accel", "density"): {
        "m/s^2/sqrt(hz)": 1.0,
        "m/s/sqrt(s)": 1.0,
        "g/sqrt(hz)": _G,
        "mg/sqrt(hz)": _G * 1e-3,
        "ug/sqrt(hz)": _G * 1e-6,
        "m/s/sqrt(h)": 1.0 / _SQRT_H,
        "ft/s/sqrt(h)": 0.3048 / _SQRT_H,
    },
    ("gyro", "bias"): {
        "rad/s": 1.0,
        "deg/s": _D,
        "mdps": _D * 1e-3,
        "mdeg/s": _D * 1e-3,
        "deg/h": _D / _H,
    },
    ("accel", "bias"): {"m/s^2": 1.0, "g": _G, "mg": _G * 1e-3, "ug": _G * 1e-6},
    ("gyro", "walk"): {
        "rad/s^2/sqrt(hz)": 1.0,
        "rad/s/sqrt(s)": 1.0,
        "deg/s^2/sqrt(hz)": _D,
        "deg/s/sqrt(s)": _D,
        "deg/h/sqrt(h)": _D / _H / _SQRT_H,
        "deg/h^2/sqrt(hz)": _D / _H / _H,
    },
    ("accel", "walk"): {
        "m/s^3/sqrt(hz)": 1.0,
        "m/s^2/sqrt(s)": 1.0,
        "m/s^2/sqrt(h)": 1.0 / _SQRT_H,
        "mg/sqrt(s)": _G * 1e-3,
        "ug/sqrt(s)": _G * 1e-6,
        "mg/sqrt(h)": _G * 1e-3 / _SQRT_H,
        "ug/sqrt(h)": _G * 1e-6 / _SQRT_H,
        "m/s/h/sqrt(h)": 1.0 / _H / _SQRT_H,
    },
}
"""Per sensor and figure (``density`` the white noise, ``bias`` the in-run bias stability,
``walk`` the bias random walk), every unit accepted (normalised by :func:`normalize_unit`)
and its factor to SI (rad/s, m/s²; per √Hz for a density, per s per √Hz for a walk).
``g`` is standard gravity g0 = 9.80665 m/s² (CGPM 1901)."""

SI: Final[dict[tuple[str, str], str]] = {
    ("gyro", "density"): "rad/s/sqrt(Hz)",
    ("accel", "density"): "m/s^2/sqrt(Hz)",
    ("gyro", "bias"): "rad/s",
    ("accel", "bias"): "m/s^2",
    ("gyro", "walk"): "rad/s^2/sqrt(Hz)",
    ("accel", "walk"): "m/s^3/sqrt(Hz)",
}
"""The SI unit of each figure (Kalibr's units)."""

PLAUSIBLE: Final[dict[tuple[str, str], tuple[float, float]]] = {
    ("gyro", "density"): IMU_DENSITY["gyro"],
    ("accel", "density"): IMU_DENSITY["accel"],
    ("gyro", "bias"): (1.0e-10, 1.0e-2),
    ("accel", "bias"): (1.0e-9, 1.0e-1),
    ("gyro", "walk"): (1.0e-13, 1.0e-2),
    ("accel", "walk"): (1.0e-11, 1.0),
}
"""The SI range outside which a figure is no IMU's (a unit misread): densities as
:data:`thermocal.stability.noise_model.IMU_DENSITY`; a gyro's bias stability from
2·10⁻⁵ °/h (below a strategic-grade ring-laser gyro's 0.0005 °/h) to 2000 °/h (20× a
consumer MEMS part's); an accelerometer's from 0.1 ng to 10 mg; random walks over ten
decades either side of the MEMS parts' 10⁻⁶…10⁻⁴."""


def normalize_unit(unit: str) -> str:
    """A data-sheet unit in the spelling of :data:`FACTORS`: lower case, no spaces,
    ``°`` → ``deg``, ``µ``/``μ`` → ``u``, ``√x``/``rtx``/``x^0.5`` → ``sqrt(x)``,
    ``hr`` → ``h``, ``sec`` → ``s``, ``²``/``³`` → ``^2``/``^3``, ``dps`` → ``deg/s``.

    Parameters
    ----------
    unit : str
        The unit as the data sheet writes it (``"°/√hr"``, ``"µg/√Hz"``).

    Returns
    -------
    str
        The normalised spelling (``"deg/sqrt(h)"``, ``"ug/sqrt(hz)"``).

    Examples
    --------
    >>> normalize_unit("°/√hr"), normalize_unit("µg/√Hz"), normalize_unit("mdps/rtHz")
    ('deg/sqrt(h)', 'ug/sqrt(hz)', 'mdps/sqrt(hz)')
    """
    u = unit.strip().lower().replace(" ", "").replace("°", "deg").replace("º", "deg")
    u = u.replace("µ", "u").replace("μ", "u").replace("²", "^2").replace("³", "^3")
    u = u.replace("degrees", "deg").replace("degree", "deg").replace("/sec", "/s")
    u = re.sub(r"(?:√|rt|sqrt)\(?([a-z]+)\)?", r"sqrt(\1)", u)
    u = re.sub(r"\(?([a-z]+)\)?\^(?:0\.5|\(1/2\))", r"sqrt(\1)", u)
    u = re.sub(r"hrs?\b", "h", u)
    u = re.sub(r"(?<!m)dps", "deg/s", u)
    u = u.replace("m/s2", "m/s^2").replace("m/s3", "m/s^3").replace("/s²", "/s^2")
    return u


@dataclass(frozen=True)
class SheetFigure:
    """One data-sheet figure as stated and in SI.

    Attributes
    ----------
    sensor : {"gyro", "accel"}
        Which sensor.
    kind : {"density", "walk", "bias"}
        White-noise density (or ARW/VRW), bias random walk, in-run bias stability.
    value : float
        The figure as the data sheet states it [``unit``].
    unit : str
        Its unit as given.
    si : float
        The figure in SI [``si_unit``].
    si_unit : str
        The SI unit (Kalibr's).
    source : str
        ``datasheet`` (stated) or how it was derived.
    """

    sensor: str
    kind: str
    value: float
    unit: str
    si: float
    si_unit: str
    source: str = "datasheet"


def sheet_figure(
    sensor: str, kind: Kind, value: float, unit: str, *, parameter: str
) -> SheetFigure:
    """A data-sheet figure checked and converted to SI.

    Parameters
    ----------
    sensor : {"gyro", "accel"}
        Which sensor.
    kind : {"density", "walk", "bias"}
        The figure: white-noise density (a density per √Hz, or an ARW/VRW per √h), bias
        random walk, in-run bias stability.
    value : float
        The figure [``unit``].
    unit : str
        Its unit (:data:`FACTORS` lists those accepted, in any spelling
        :func:`normalize_unit` reads).
    parameter : str
        The parameter an error names.

    Returns
    -------
    SheetFigure
        The figure and its SI value.

    Raises
    ------
    thermocal.errors.ParameterError
        An unknown unit, a value not finite and positive, or an SI value outside
        :data:`PLAUSIBLE` (a unit misread).

    Notes
    -----
    .. math:: N\\,[\\mathrm{rad/s/\\sqrt{Hz}}] = N\\,[°/\\sqrt{h}]\\cdot\\frac{\\pi}{180}\\cdot
              \\frac{1}{60}, \\qquad \\sqrt{h} = 60\\sqrt{s}

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C (N in °/√h, K in °/h/√h, B in °/h).

    Examples
    --------
    >>> f = sheet_figure("gyro", "density", 0.66, "°/√hr", parameter="gyro_noise_density")
    >>> print(f"{f.si:.4e} {f.si_unit}")
    1.9199e-04 rad/s/sqrt(Hz)
    """
    table = FACTORS[(sensor, kind)]
    u = normalize_unit(unit)
    if u not in table:
        raise ParameterError(
            parameter,
            f"{{name}}: unit {one_line(repr(unit))} is not one for a {sensor} "
            f"{_WORDS[kind]}; use one of {', '.join(table)}",
        )
    if not (math.isfinite(value) and value > 0.0):
        raise ParameterError(parameter, f"{{name}} {value!r}: give a positive figure")
    si = value * table[u]
    lo, hi = PLAUSIBLE[(sensor, kind)]
    if not lo <= si <= hi:
        raise ParameterError(
            parameter,
            f"{{name}} {value:g} {unit}: {si:.3g} {SI[(sensor, kind)]} is outside any "
            f"{sensor}'s {_WORDS[kind]} ({lo:g} … {hi:g} {SI[(sensor, kind)]}); check the "
            "figure and its unit",
        )
    return SheetFigure(sensor, kind, float(value), unit, si, SI[(sensor, kind)])


_WORDS: Final = {
    "density": "white-noise density (or random walk ARW/VRW)",
    "walk": "bias random walk",
    "bias": "in-run bias stability",
}


def walk_from_bias(density: SheetFigure, bias: SheetFigure) -> SheetFigure:
    """The bias random walk K that, with the white noise N, makes the Allan deviation's
    minimum equal to the in-run bias stability (the Kalibr wiki's reading of a data
    sheet): an upper bound of K when flicker noise makes part of the floor.

    Parameters
    ----------
    density : SheetFigure
        The white-noise density N (SI).
    bias : SheetFigure
        The in-run bias stability σ_min, the Allan deviation's minimum (SI).

    Returns
    -------
    SheetFigure
        K [rad/s²/√Hz or m/s³/√Hz], its ``source`` saying how it was derived.

    Notes
    -----
    .. math:: \\sigma^2(\\tau) = \\frac{N^2}{\\tau} + \\frac{K^2\\tau}{3},\\quad
              \\sigma_{min}^2 = \\frac{2NK}{\\sqrt3}\\ \\text{at}\\ \\tau^* = \\frac{\\sqrt3 N}{K}
              \\ \\Rightarrow\\ K = \\frac{\\sqrt3\\,\\sigma_{min}^2}{2N}

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C (the terms' Allan variances).
    .. [2] The Kalibr wiki, "IMU Noise Model", section "From the datasheet of the IMU".

    Examples
    --------
    >>> n = sheet_figure("gyro", "density", 0.0135, "deg/s/sqrt(Hz)", parameter="n")
    >>> b = sheet_figure("gyro", "bias", 14.5, "deg/h", parameter="b")
    >>> print(f"{walk_from_bias(n, b).si:.3e}")
    1.816e-05
    """
    k = math.sqrt(3.0) * bias.si**2 / (2.0 * density.si)
    tau = math.sqrt(3.0) * density.si / k
    return SheetFigure(
        density.sensor,
        "walk",
        k,
        SI[(density.sensor, "walk")],
        k,
        SI[(density.sensor, "walk")],
        source=(
            f"derived: K = √3·σ_min²/(2N) from the bias stability {bias.value:g} {bias.unit} "
            f"taken as the Allan minimum of white noise and a random walk alone (at τ = "
            f"{tau:.3g} s); an upper bound when flicker makes part of the floor"
        ),
    )


@dataclass(frozen=True)
class DatasheetNoise:
    """A noise model from data-sheet figures (Kalibr's continuous-time values).

    Attributes
    ----------
    figures : dict of str to SheetFigure
        By Kalibr key (``gyroscope_noise_density`` …): the figure used.
    given : tuple of SheetFigure
        Every figure given, as stated.
    update_rate_hz : float
        The IMU's output rate [Hz].
    inflate : float
        Factor every Kalibr value is multiplied by (1: none).
    rostopic : str
        The IMU's ROS topic.
    notes : tuple of str
        What the user should know (disagreeing figures, derived values).
    """

    figures: dict[str, SheetFigure]
    given: tuple[SheetFigure, ...]
    update_rate_hz: float
    inflate: float
    rostopic: str
    notes: tuple[str, ...]

    def kalibr(self) -> dict[str, float | str]:
        """Kalibr's ``imu.yaml`` values by key (continuous time, SI, inflated)."""
        out: dict[str, float | str] = {k: f.si * self.inflate for k, f in self.figures.items()}
        out["update_rate"] = self.update_rate_hz
        out["rostopic"] = self.rostopic
        return {k: out[k] for k in KALIBR_KEYS}

    def to_dict(self, source: str) -> dict[str, Any]:
        """The model as plain values: ``source``, ``kalibr``, ``inflate``,
        ``update_rate_hz``, ``figures`` (per key: ``value``, ``unit``, ``si``,
        ``si_unit``, ``source``), ``given`` and ``notes``.

        Parameters
        ----------
        source : str
            The file the figures came from.

        Returns
        -------
        dict
            The keys above.
        """
        return {
            "source": source,
            "from": "datasheet",
            "kalibr": self.kalibr(),
            "inflate": self.inflate,
            "update_rate_hz": self.update_rate_hz,
            "figures": {k: _fig_dict(f) for k, f in self.figures.items()},
            "given": [_fig_dict(f) for f in self.given],
            "notes": list(self.notes),
            "discrete_time": "white noise σ_d = σ_c / √Δt; random walk σ_d = σ_c · √Δt",
        }


def _fig_dict(f: SheetFigure) -> dict[str, Any]:
    """One figure as plain values."""
    return {"sensor": f.sensor, "kind": f.kind, "value": f.value, "unit": f.unit,
            "si": f.si, "si_unit": f.si_unit, "source": f.source}  # fmt: skip


Figure = tuple[float, str]
"""A data-sheet figure: its value and its unit as written (``(0.66, "deg/sqrt(h)")``)."""


def datasheet_noise(
    figures: dict[str, Figure],
    update_rate_hz: float,
    *,
    inflate: float = 1.0,
    rostopic: str = "/imu0",
) -> DatasheetNoise:
    """Kalibr's noise model from data-sheet figures, units checked and converted to SI.

    Parameters
    ----------
    figures : dict of str to (float, str)
        Value and unit per figure: ``gyro_noise_density`` and ``accel_noise_density``
        (required; a density per √Hz or a random walk ARW/VRW per √h), ``gyro_random_walk``
        and ``accel_random_walk`` (the bias random walk, optional),
        ``gyro_bias_instability`` and ``accel_bias_instability`` (the in-run bias
        stability, the Allan deviation's minimum: K derived from it when the random walk
        is not given), ``gyro_arw``/``accel_vrw`` (a second white-noise figure: the larger
        of the two is used, their disagreement stated).
    update_rate_hz : float
        The IMU's output rate [Hz] (Kalibr's ``update_rate``).
    inflate : float, optional
        Factor ≥ 1 every Kalibr value is multiplied by (default 1: none).
    rostopic : str, optional
        The IMU's ROS topic (default ``/imu0``).

    Returns
    -------
    DatasheetNoise
        The figures used per Kalibr key and what the user should know.

    Raises
    ------
    thermocal.errors.ParameterError
        A figure unknown, missing, with a unit it cannot have, or outside any IMU's range;
        a rate outside 10 Hz … 100 kHz; ``inflate`` below 1; a topic not a ROS name.

    Notes
    -----
    ``N [rad/s/√Hz] = ARW [°/√h]·(π/180)/60``; ``N [m/s²/√Hz] = VRW [m/s/√h]/60
    = density [µg/√Hz]·g0·10⁻⁶``; ``K = √3 σ_min²/(2N)`` when only the bias stability is
    given (:func:`walk_from_bias`).

    References
    ----------
    .. [1] IEEE Std 952-1997, Annex C.
    .. [2] The Kalibr wiki, "IMU Noise Model" (continuous-time densities, "From the
       datasheet of the IMU").

    Examples
    --------
    ADIS16448 data-sheet figures (as quoted in the Kalibr thread "Obtaining IMU parameters
    from datasheet", https://github.com/ethz-asl/kalibr/issues/63):

    >>> m = datasheet_noise({"gyro_noise_density": (0.66, "deg/sqrt(h)"),
    ...                      "accel_noise_density": (0.11, "m/s/sqrt(h)"),
    ...                      "gyro_random_walk": (4e-6, "rad/s^2/sqrt(Hz)"),
    ...                      "accel_random_walk": (2e-4, "m/s^3/sqrt(Hz)")}, 200.0)
    >>> print(f"{m.kalibr()['gyroscope_noise_density']:.4e}")
    1.9199e-04
    """
    _check_common(figures, update_rate_hz, inflate, rostopic)
    given: list[SheetFigure] = []
    chosen: dict[str, SheetFigure] = {}
    notes: list[str] = []
    for sensor, prefix, second in (("gyro", "gyroscope", "gyro_arw"),
                                   ("accel", "accelerometer", "accel_vrw")):  # fmt: skip
        dens, more = _white(sensor, figures, second, notes)
        given += more
        walk = _walk(sensor, figures, dens, given, notes)
        chosen[f"{prefix}_noise_density"] = dens
        chosen[f"{prefix}_random_walk"] = walk
    return DatasheetNoise(chosen, tuple(given), float(update_rate_hz), float(inflate),
                          rostopic, tuple(notes))  # fmt: skip


KNOWN_FIGURES: Final = (
    "gyro_noise_density", "gyro_arw", "gyro_random_walk", "gyro_bias_instability",
    "accel_noise_density", "accel_vrw", "accel_random_walk", "accel_bias_instability",
)  # fmt: skip
"""The figures :func:`datasheet_noise` reads."""


def _check_common(
    figures: dict[str, Figure], rate_hz: float, inflate: float, rostopic: str
) -> None:
    """Refuse an unknown figure, a rate, inflation or topic no estimator takes."""
    for key in figures:
        if key not in KNOWN_FIGURES:
            raise ParameterError(
                "figures",
                f"{{name}}: unknown figure {one_line(repr(key))}; the figures are "
                f"{', '.join(KNOWN_FIGURES)}",
            )
    lo, hi = IMU_RATE_HZ
    if not (math.isfinite(rate_hz) and lo <= rate_hz <= hi):
        raise ParameterError(
            "update_rate_hz",
            f"{{name}} {rate_hz!r}: give the IMU's output rate, {lo:g} … {hi:g} Hz",
        )
    if not (math.isfinite(inflate) and inflate >= 1.0):
        raise ParameterError("inflate", f"{{name}} {inflate!r}: give a factor ≥ 1 (1: none)")
    if not ROS_NAME.fullmatch(rostopic):
        raise ParameterError(
            "rostopic", f"{{name}} {one_line(repr(rostopic))}: not a ROS topic name"
        )


def _white(
    sensor: str, figures: dict[str, Figure], second: str, notes: list[str]
) -> tuple[SheetFigure, list[SheetFigure]]:
    """The white-noise figure used (the larger of the density and the ARW/VRW given)."""
    key = f"{sensor}_noise_density"
    found = [
        sheet_figure(sensor, "density", figures[k][0], figures[k][1], parameter=k)
        for k in (key, second)
        if k in figures
    ]
    if not found:
        raise ParameterError(
            "figures",
            f"{{name}}: no {key} (the {sensor}'s white-noise density or its random walk "
            f"{'ARW' if sensor == 'gyro' else 'VRW'}, e.g. "
            f"{'0.014 deg/s/sqrt(Hz)' if sensor == 'gyro' else '175 ug/sqrt(Hz)'})",
        )
    use = max(found, key=lambda f: f.si)
    if len(found) == 2:
        a, b = found
        notes.append(
            f"{sensor}: the data sheet's two white-noise figures differ by "
            f"{abs(a.si / b.si - 1.0) * 100:.0f} % ({a.value:g} {a.unit} = {a.si:.4g}, "
            f"{b.value:g} {b.unit} = {b.si:.4g} {a.si_unit}; a density is often read at one "
            "frequency, the random walk from the Allan deviation): the larger is used"
        )
    return use, found


def _walk(
    sensor: str,
    figures: dict[str, Figure],
    dens: SheetFigure,
    given: list[SheetFigure],
    notes: list[str],
) -> SheetFigure:
    """The bias random walk: given, else derived from the bias stability, else refused."""
    key, bkey = f"{sensor}_random_walk", f"{sensor}_bias_instability"
    bias = None
    if bkey in figures:
        bias = sheet_figure(sensor, "bias", *figures[bkey], parameter=bkey)
        given.append(bias)
    if key in figures:
        walk = sheet_figure(sensor, "walk", *figures[key], parameter=key)
        given.append(walk)
        return walk
    if bias is None:
        raise ParameterError(
            "figures",
            f"{{name}}: no {key} and no {bkey}; Kalibr needs the bias random walk: give it, "
            "or the in-run bias stability it is derived from, or record the IMU at rest "
            "and read both from its Allan deviation",
        )
    walk = walk_from_bias(dens, bias)
    notes.append(f"{sensor}: random walk {walk.si:.4g} {walk.si_unit} {walk.source}")
    return walk


def datasheet_yaml(model: DatasheetNoise, source: str) -> str:
    """Kalibr's ``imu.yaml`` text of a data-sheet model, each key with the figure it came
    from, its conversion, the inflation, and its discrete-time value.

    Parameters
    ----------
    model : DatasheetNoise
        The model.
    source : str
        The file of figures, named in the header.

    Returns
    -------
    str
        The ``imu.yaml`` text (checked by
        :func:`thermocal.stability.noise_model.check_kalibr_yaml`).
    """
    dt = 1.0 / model.update_rate_hz
    lines = [
        f"# IMU noise model for Kalibr, written by thermocal noise from the data-sheet figures "
        f"in {one_line(source)}",
        "# Continuous-time values (Kalibr's convention), converted to SI from the data sheet's",
        "# units (IEEE 952-1997 Annex C: 1 deg/s/sqrt(Hz) = 60 deg/sqrt(h)).",
    ]
    if model.inflate != 1.0:
        lines.append(
            f"# Every noise value below is INFLATED x{model.inflate:g} over the data sheet's."
        )
    else:
        lines.append("# NOT inflated: the data sheet's typical figures as stated.")
    lines += [f"# note: {one_line(n)}" for n in model.notes]
    lines.append("")
    values = model.kalibr()
    for key, f in model.figures.items():
        v = float(values[key])
        how = f"{f.value:g} {one_line(f.unit)}" if f.source == "datasheet" else "derived"
        lines.append(f"# {key} [{f.si_unit}]: from {how} = {f.si:.6e}.")
        disc = v / math.sqrt(dt) if key.endswith("density") else v * math.sqrt(dt)
        op = "σ_c / √Δt" if key.endswith("density") else "σ_c · √Δt"
        lines.append(f"#   discrete time at Δt = {dt:.6g} s: σ_d = {op} = {disc:.6e}")
        lines.append(f"{key}: {v:.6e}")
        lines.append("")
    rate = repr(float(model.update_rate_hz))
    lines += ["# update_rate [Hz]: the data sheet's output rate given.", f"update_rate: {rate}", ""]
    lines += [f'rostopic: "{model.rostopic}"', ""]
    text = "\n".join(lines)
    check_kalibr_yaml(text)
    return text
