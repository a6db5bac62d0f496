"""A calibration: several named channels, each with its own fitted model.

A real IMU has three gyros and three accelerometers; a calibration keeps one model per
channel (any family), with the channel's signal column, its unit as given and an optional
role, in one versioned file::

    {
      "format": "thermocal-calibration", "format_version": 1 | 2 | 3 | 4,
      "created_utc": "...", "thermocal_version": "...",
      "channels": [
        {"name": "gx", "signal": "gx", "unit": "deg/s",
         "role": {"kind": "gyro", "axis": "x"} | null,
         "model": { …a complete model file, with its own checksum… }},
        …
      ],
      "triads": [   (only when there are triads: multipos, turntable)
        {"name": "gyro", "columns": ["gx", "gy", "gz"], "unit": "deg/s",
         "temperature": "temp", "encoders": [...], "latitude_deg": 45.0,
         "model": { …TriadThermal: bias, scale factors, misalignments in T… },
         "count_scale": {"value": K, "unit": "deg/s"},          (raw counts; version ≥ 2)
         "g_sensitivity": [[A_xx, A_xy, A_xz], …],  (gyro only, version 3: row the gyro
         "g_sensitivity_sigma": [[…], …],             axis, column the specific force's
         "g_sensitivity_unit": "deg/s/g",             axis; the triad's unit per g)
         "k2": [K2_x, K2_y, K2_z],          (accel only, version 4: each axis's
         "k2_sigma": […],                     second-order coefficient, the triad's
         "k2_unit": "m/s^2/g^2"},             unit per g², g = 9.80665 m/s²)
        …
      ],
      "checksum": "<sha256 of the canonical JSON without this key>"
    }

Every channel's model is verified as a model file is (header, checksum, schema); the
calibration's checksum covers the channel list. A single-model file loads as a
calibration of one channel (:func:`load_calibration`), so every command that takes a
calibration also takes the model files written before.
"""

from __future__ import annotations

import datetime as _dt
import math
from collections.abc import Callable, Collection
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from thermocal.errors import ModelFileError, ThermocalInputError
from thermocal.models.base import TemperatureModel
from thermocal.models.format import checksum, model_file_dict
from thermocal.models.registry import model_from_dict
from thermocal.models.schema import verify_model_dict
from thermocal.recording import FloatArray

CALIBRATION_FORMAT = "thermocal-calibration"
CALIBRATION_FORMAT_VERSION = 4
"""The newest version this thermocal reads.  Version 2 added a triad's ``count_scale``,
version 3 a gyro triad's ``g_sensitivity``, version 4 an accelerometer triad's ``k2``; a
file is written with the lowest version that holds what it carries (1 without any), so a
file without them is what it was, and an older thermocal refuses a file whose counts it
could not convert, or whose g-sensitivity or K2 it would silently leave out, rather than
apply it wrongly."""
COUNT_SCALE_FORMAT_VERSION = 2
G_SENSITIVITY_FORMAT_VERSION = 3
K2_FORMAT_VERSION = 4

ROLE_KINDS = ("gyro", "accel")
"""Roles a channel may declare."""


def guess_role(name: str, unit: str) -> dict[str, Any] | None:
    """A channel's role from its unit kind and a trailing axis letter of its name
    (``gx`` → gyro x, ``acc_z`` → accel z); None when the unit is raw counts.

    Parameters
    ----------
    name : str
        The column name.
    unit : str
        Its unit as given (e.g. ``deg/s``, ``g``, ``counts``).

    Returns
    -------
    dict or None
        ``{"kind": "gyro"|"accel", "axis": "x"|"y"|"z"}`` (axis when the name ends in one).

    Examples
    --------
    >>> guess_role("gx", "deg/s"), guess_role("acc_z", "g"), guess_role("t", "counts")
    ({'kind': 'gyro', 'axis': 'x'}, {'kind': 'accel', 'axis': 'z'}, None)
    """
    from thermocal import units
    from thermocal.errors import UnitError

    try:
        kind = units.signal_kind(unit)
    except UnitError:  # an unknown unit: no role
        return None
    if kind == "raw":
        return None
    role: dict[str, Any] = {"kind": "gyro" if kind == "rate" else "accel"}
    last = name.strip().lower()[-1:]
    if last in ("x", "y", "z"):
        role["axis"] = last
    return role


@dataclass
class Channel:
    """One channel: ``name`` (unique in the calibration), the ``signal`` column it reads,
    the ``unit`` of that column as given, an optional ``role`` and its fitted ``model``.

    Attributes
    ----------
    name : str
        Channel name, unique in the calibration.
    signal : str
        The signal column it reads.
    unit : str
        That column's unit as given (e.g. ``deg/s``).
    model : TemperatureModel
        The fitted model.
    role : dict or None
        ``{"kind": ..., "axis": ...}`` (:func:`guess_role`), default None.
    """

    name: str
    signal: str
    unit: str
    model: TemperatureModel
    role: dict[str, Any] | None = None


@dataclass
class Triad:
    """A sensor triad whose error model couples its three axes: ``name``
    (``gyro``/``accel``), the three ``columns`` (x, y, z) it reads, their ``unit`` as given,
    the ``temperature`` column whose value indexes the model (``""`` for a model calibrated
    at one temperature and read without one), and the ``model`` itself
    (:class:`thermocal.turntable.thermal.TriadThermal`: bias, scale factors and
    misalignments as polynomials in temperature).  Applied as
    ``x_c = (I + E(T))⁻¹ (x − b(T))`` per sample (``<col>_comp``).  ``encoders`` (α, β
    columns) and ``latitude_deg`` are those of the calibration runs: a later command on a run
    of the same rig (validate, report) needs none of them repeated.

    Attributes
    ----------
    name : str
        ``gyro`` or ``accel``.
    columns : tuple of str
        The x, y, z columns.
    unit : str
        Their unit as given (physical unit of the parameters).
    temperature : str
        The temperature column ([°C]), ``""`` for a single-temperature model.
    model : thermocal.turntable.thermal.TriadThermal
        Bias, scale factors and misalignments as polynomials in temperature.
    encoders : tuple of str
        The α, β encoder columns [°] (default ``("alpha_deg", "beta_deg")``).
    latitude_deg : float or None
        Latitude of the calibration runs [°].
    g_sensitivity, g_sensitivity_sigma : numpy.ndarray, shape (3, 3), or None
        A gyro triad's sensitivity to specific force ``A`` and its σ [``unit`` per g].
    k2, k2_sigma : numpy.ndarray, shape (3,), or None
        An accelerometer triad's second-order coefficients and their σ [``unit`` per g²].

    Notes
    -----
    .. math:: x_c = (I + E(T))^{-1} (x - b(T) - A f)

    with ``A f`` only for a gyro triad with a ``g_sensitivity`` (``f`` the accelerometer
    triad's compensated output in g).  An accelerometer triad with ``k2`` is inverted from
    ``x = (I + E(T)) x_c + b(T) + K_2 ⊙ (x_c / g)^2`` (:func:`thermocal.multipos.
    accel_k2.invert_k2`).

    References
    ----------
    - IEEE Std 1554-2005, IEEE Recommended Practice for Inertial Sensor Test Equipment,
      Instrumentation, Data Acquisition, and Analysis.
    - Tedaldi, D., Pretto, A. & Menegatti, E. (2014). A robust and easy to implement method
      for IMU calibration without external equipments. ICRA 2014, 3042–3049.
    """

    name: str
    columns: tuple[str, str, str]
    unit: str
    temperature: str
    model: Any  # TriadThermal (imported lazily: the turntable package needs scipy)
    encoders: tuple[str, str] = ("alpha_deg", "beta_deg")
    latitude_deg: float | None = None
    adequacy: dict[str, Any] | None = None
    """The adequacy record of the soaks it was fitted on (:mod:`thermocal.adequacy`)."""
    data: tuple[dict[str, str], ...] = ()
    """The session files it was calibrated on, ``{"file": name, "sha256": hash}`` each (as a
    model file's ``data``): ``validate`` and ``report`` know them when given again."""
    count_scale: float | None = None
    """A triad calibrated on raw counts (``thermocal multipos`` given the count scales):
    one count is ``count_scale`` ``unit`` (the datasheet's sensitivity), and ``unit`` is the
    physical unit the parameters and the compensated columns are in.  Compensation converts
    raw-count columns first, ``x [unit] = count_scale · N``; None: the triad was calibrated on
    data in ``unit`` (files of format version 1 have no such key)."""
    g_sensitivity: FloatArray | None = field(default=None, compare=False)
    """A gyro triad's sensitivity to specific force, the 3×3 matrix ``A`` [``unit`` per g,
    g = 9.80665 m/s²] (row i the gyro axis, column j the specific force's axis; IEEE Std
    952-1997 annex B, IEEE Std 1431-2004): the gyro reads ``b + A f`` more at rest under the
    specific force ``f`` [g].  Compensation takes it off with the accelerometer triad's
    compensated output, ``x_c = (I + E(T))⁻¹ (x − b(T) − A f)``; None: not applied (files
    before format version 3 have no such key)."""
    g_sensitivity_sigma: FloatArray | None = field(default=None, compare=False)
    """The standard uncertainties of ``g_sensitivity`` (3×3) [``unit`` per g]."""
    k2: FloatArray | None = field(default=None, compare=False)
    """An accelerometer triad's second-order coefficient per axis, ``K2`` [``unit`` per g²,
    g = 9.80665 m/s²] (IEEE Std 1293-1998's ``K2 a²``, one per axis): the axis reads
    ``K2_i (a_i/g)²`` more under the true specific force ``a``.  Compensation inverts
    ``x = (I + E(T)) a + b(T) + K2 ⊙ (a/g)²`` per sample; None: not applied (files before
    format version 4 have no such key)."""
    k2_sigma: FloatArray | None = field(default=None, compare=False)
    """The standard uncertainties of ``k2`` (3,) [``unit`` per g²]."""

    @property
    def k2_unit(self) -> str:
        """The unit of ``k2`` as the file states it: the triad's unit per g² (``mg/g^2``)."""
        return f"{self.unit}/g^2"

    @property
    def g_sensitivity_unit(self) -> str:
        """The unit of ``g_sensitivity`` as the file states it: the triad's unit per g
        (``deg/s/g``)."""
        return f"{self.unit}/g"

    def g_sensitivity_term(self, force: Any, force_unit: str, unit: str) -> FloatArray:
        """``A f`` per sample in ``unit``: the rate a gyro triad with a g-sensitivity reads
        more under the specific force ``force`` (the accelerometer triad's compensated
        output, in ``force_unit``), the one formula of ``compensate`` and ``validate``.

        Parameters
        ----------
        force : array_like, shape (n, 3)
            The specific force [``force_unit``: g, mg or m/s²].
        force_unit : str
            Its unit (converted to g = 9.80665 m/s²).
        unit : str
            The rate unit of the result (the gyro columns' physical unit).

        Returns
        -------
        numpy.ndarray, shape (n, 3)
            ``A f`` [``unit``]; zeros for a triad without a g-sensitivity.

        Notes
        -----
        .. math:: (A f)_i = \\sum_j A_{ij} f_j, \\qquad f_j \\text{ in g}

        References
        ----------
        - IEEE Std 952-1997, annex B (acceleration-sensitive drift).
        """
        from thermocal import units

        f = np.asarray(force, dtype=np.float64)
        if self.g_sensitivity is None:
            return np.zeros_like(f)
        to_g = float(units.convert(np.array([1.0]), force_unit, "g")[0])
        to_unit = float(units.convert(np.array([1.0]), self.unit, unit)[0])
        a = np.asarray(self.g_sensitivity, dtype=np.float64) * to_unit
        out: FloatArray = (f * to_g) @ a.T
        return out

    def correct(self, x: Any, temp_c: Any, to_data: float, unit: str) -> FloatArray:
        """The compensated samples: ``(I + E(T))⁻¹ (x − b(T))``
        (:func:`thermocal.turntable.thermal.correct`), or for an accelerometer triad with
        ``k2`` the ``a`` of ``x = (I + E(T)) a + b(T) + K2 ⊙ (a/g)²`` by Newton's method
        (:func:`thermocal.multipos.accel_k2.invert_k2`), in blocks; the one formula of
        ``compensate`` and ``validate`` (``A f`` of a gyro's g-sensitivity taken off ``x``
        before).

        Parameters
        ----------
        x : array_like, shape (n, 3)
            Samples [``unit``].
        temp_c : array_like, shape (n,)
            Their temperatures [°C].
        to_data : float
            The factor from the model's bias unit (°/h or mg) to ``unit``.
        unit : str
            The samples' unit (of the triad's kind).

        Returns
        -------
        numpy.ndarray, shape (n, 3)
            Compensated samples [``unit``].

        Notes
        -----
        .. math:: x = (I + E(T))\\, a + b(T) + K_2 \\odot (a / g)^2

        References
        ----------
        - IEEE Std 1293-1998, *IEEE Standard Specification Format Guide and Test Procedure
          for Linear, Single-Axis, Nongyroscopic Accelerometers* (the K2 term).
        """
        from thermocal.turntable import thermal

        if self.k2 is None:
            return thermal.correct(self.model, x, temp_c, to_data)
        from thermocal import units
        from thermocal.multipos.accel_k2 import invert_k2

        xs = np.asarray(x, dtype=np.float64)
        tc = np.broadcast_to(np.asarray(temp_c, dtype=np.float64), xs.shape[:1])
        to_out = float(units.convert(np.array([1.0]), self.unit, unit)[0])
        g = float(units.convert(np.array([1.0]), "g", unit)[0])
        k2 = np.asarray(self.k2, dtype=np.float64) * to_out
        out = np.empty_like(xs)
        for a0 in range(0, xs.shape[0], thermal.CORRECT_BLOCK):
            sl = slice(a0, min(xs.shape[0], a0 + thermal.CORRECT_BLOCK))
            b, e = thermal.error_terms(self.model, tc[sl])
            out[sl] = invert_k2(xs[sl] - b * to_data, e + np.eye(3), k2, g)
        return out

    def calibrated_unit(self) -> str:
        """The unit of the columns the triad was calibrated on: raw counts for a triad with
        a count scale, else its unit (the unit of a column that states none).

        Returns
        -------
        str
        """
        return "counts" if self.count_scale is not None else self.unit

    def input_in(self, data_units: Collection[str], where: str) -> TriadInput:
        """How this triad's columns, read in ``data_units`` (one unit for the three), enter
        its model: raw counts of a triad with a count scale become ``count_scale · N`` in
        ``unit``; data in ``unit``'s kind are taken as they are.  The one path shared by
        ``compensate`` and ``validate`` (and the report).

        Parameters
        ----------
        data_units : collection of str
            The units the three columns were read in.
        where : str
            The data's name, for messages.

        Returns
        -------
        TriadInput

        Raises
        ------
        UnitError
            The columns differ in unit, are raw counts the triad has no count scale for,
            or are of another kind than the triad's unit (exit status 2).
        """
        from thermocal import units
        from thermocal.errors import UnitError

        found = set(data_units)
        if len(found) != 1:
            raise UnitError(f"{where}: the {self.name} triad's columns differ in unit")
        data_unit = found.pop()
        out_unit, scale = data_unit, None
        if data_unit == "counts" and self.count_scale is not None:
            out_unit, scale = self.unit, float(self.count_scale)
        elif data_unit == "counts":
            scale_of = f"{self.model.kind}_scale"  # multipos's parameter of the count scale
            raise UnitError.naming(
                f"{where}: the {self.name} triad's columns are raw counts, and the calibration "
                f"states no count scale (it was calibrated on {self.unit} data): convert the "
                f"columns to {self.unit}, or calibrate the counts with multipos "
                f"{{{scale_of}}} VALUE,UNIT",
                scale_of,
            )
        elif units.canonical_unit(data_unit) != units.canonical_unit(self.unit):
            raise UnitError.naming(
                f"{where}: the {self.name} triad was calibrated on "
                f"{'raw counts of ' if self.count_scale is not None else ''}{self.unit} data; "
                f"its columns {', '.join(map(repr, self.columns))} are read in {data_unit} "
                "(give {signal_unit} one unit per triad column, in the calibration's order, "
                "or leave it out to take the file's or the calibration's)",
                "signal_unit",
            )
        bias_unit = "deg/h" if self.model.kind == "gyro" else "mg"
        to_data = float(units.convert(np.array([1.0]), bias_unit, out_unit)[0])
        return TriadInput(data_unit, out_unit, scale, to_data)


@dataclass(frozen=True)
class TriadInput:
    """A triad's columns as its model takes them (:meth:`Triad.input_in`): the unit they were
    read in (``data_unit``), the physical ``unit`` of their values and of the compensated
    output, the ``count_scale`` applied to raw counts (one count is ``count_scale`` ``unit``;
    None for columns already in a physical unit) and ``to_data``, the factor from the
    model's bias unit (°/h for a gyro, mg for an accelerometer) to ``unit``.

    Attributes
    ----------
    data_unit : str
        The unit the columns were read in.
    unit : str
        Physical unit of the values and of the compensated output.
    count_scale : float or None
        [unit per count] for raw counts; None for physical columns.
    to_data : float
        Factor from the model's bias unit ([°/h] or [mg]) to ``unit``.
    """

    data_unit: str
    unit: str
    count_scale: float | None
    to_data: float

    def physical(self, x: Any) -> Any:
        """The values ``x`` (raw counts or already physical) in ``unit``:
        ``x_phys = count_scale · N`` for raw counts, else ``x`` unchanged.

        Parameters
        ----------
        x : float or numpy.ndarray
            Values in ``data_unit``.

        Returns
        -------
        float or numpy.ndarray
            Values in ``unit``.
        """
        if self.count_scale is None:
            return x
        with np.errstate(over="ignore"):  # an overflow is refused by the caller
            return x * self.count_scale


@dataclass
class Calibration:
    """Several channels, each with its model, and triads (module docstring).

    Attributes
    ----------
    channels : list of Channel
        Default empty.
    triads : list of Triad
        Default empty.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Two channels or triads share a name.
    """

    channels: list[Channel] = field(default_factory=list)
    triads: list[Triad] = field(default_factory=list)

    def __post_init__(self) -> None:
        names = [c.name for c in self.channels] + [t.name for t in self.triads]
        if len(set(names)) != len(names):
            raise ThermocalInputError(f"calibration: channel names must be unique, got {names}")

    def require_channels(self, what: str) -> None:
        """Refuse a calibration of triads only for a command that handles channels only.

        Parameters
        ----------
        what : str
            The command, for the message.

        Raises
        ------
        thermocal.errors.ThermocalInputError
            The calibration has no channel.
        """
        if not self.channels:
            raise ThermocalInputError(
                f"this calibration holds triads ({', '.join(t.name for t in self.triads)}) and no "
                f"single-channel model: {what} does not handle triads yet (compensate does)"
            )

    @property
    def names(self) -> list[str]:
        """Names of the channels, in order."""
        return [c.name for c in self.channels]

    def channel(self, name: str) -> Channel:
        """The channel called ``name``.

        Parameters
        ----------
        name : str
            The channel name.

        Returns
        -------
        Channel

        Raises
        ------
        thermocal.errors.ThermocalInputError
            No such channel (the message lists the names).
        """
        for c in self.channels:
            if c.name == name:
                return c
        raise ThermocalInputError(f"calibration: no channel {name!r}; it has {self.names}")

    def to_dict(self) -> dict[str, Any]:
        """The file's dict, with every model's own checksum and the calibration's."""
        from thermocal._version import __version__

        d: dict[str, Any] = {
            "format": CALIBRATION_FORMAT,
            "format_version": _format_version(self.triads),
            "created_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
            "thermocal_version": __version__,
            "channels": [
                {
                    "name": c.name,
                    "signal": c.signal,
                    "unit": c.unit,
                    "role": c.role,
                    "model": model_file_dict(c.model),
                }
                for c in self.channels
            ],
        }
        if self.triads:  # the key only when there are triads: older files are unchanged
            d["triads"] = [
                {
                    "name": t.name,
                    "columns": list(t.columns),
                    "unit": t.unit,
                    "temperature": t.temperature,
                    "encoders": list(t.encoders),
                    "latitude_deg": t.latitude_deg,
                    "model": t.model.to_dict(),
                    **({"adequacy": t.adequacy} if t.adequacy is not None else {}),
                    **({"data": [dict(x) for x in t.data]} if t.data else {}),
                    **(
                        {"count_scale": {"value": t.count_scale, "unit": t.unit}}
                        if t.count_scale is not None
                        else {}
                    ),
                    **_g_sensitivity_dict(t),
                    **_k2_dict(t),
                }
                for t in self.triads
            ]
        d["checksum"] = checksum(d)
        return d


def _format_version(triads: list[Triad]) -> int:
    """The lowest format version that holds what the triads carry."""
    if any(t.k2 is not None for t in triads):
        return K2_FORMAT_VERSION
    if any(t.g_sensitivity is not None for t in triads):
        return G_SENSITIVITY_FORMAT_VERSION
    if any(t.count_scale is not None for t in triads):
        return COUNT_SCALE_FORMAT_VERSION
    return 1


def _g_sensitivity_dict(t: Triad) -> dict[str, Any]:
    """A triad's g-sensitivity keys in the file (none without one)."""
    if t.g_sensitivity is None:
        return {}
    sigma = t.g_sensitivity_sigma
    return {
        "g_sensitivity": np.asarray(t.g_sensitivity, dtype=np.float64).tolist(),
        "g_sensitivity_sigma": (
            None if sigma is None else np.asarray(sigma, dtype=np.float64).tolist()
        ),
        "g_sensitivity_unit": t.g_sensitivity_unit,
    }


def _k2_dict(t: Triad) -> dict[str, Any]:
    """An accelerometer triad's K2 keys in the file (none without one)."""
    if t.k2 is None:
        return {}
    sigma = t.k2_sigma
    return {
        "k2": np.asarray(t.k2, dtype=np.float64).tolist(),
        "k2_sigma": None if sigma is None else np.asarray(sigma, dtype=np.float64).tolist(),
        "k2_unit": t.k2_unit,
    }


def is_calibration(d: Any) -> bool:
    """True when ``d`` is a calibration file's dict (its ``format`` tag), not a model file.

    Parameters
    ----------
    d : object
        A parsed JSON document.

    Returns
    -------
    bool
    """
    return isinstance(d, dict) and d.get("format") == CALIBRATION_FORMAT


def calibration_from_dict(d: dict[str, Any], where: str) -> Calibration:
    """Verify (format, version, checksums, each model's schema) and build.

    Parameters
    ----------
    d : dict
        The calibration file's content.
    where : str
        The file's name, for messages.

    Returns
    -------
    Calibration

    Raises
    ------
    thermocal.errors.ModelFileError
        Wrong format or version, a checksum mismatch, or a model that fails its schema.
    """
    ver = d.get("format_version")
    if not isinstance(ver, int):
        raise ModelFileError(f"{where}: calibration file has no integer format_version")
    if ver > CALIBRATION_FORMAT_VERSION:
        raise ModelFileError(
            f"{where}: calibration format version {ver} is newer than this thermocal supports "
            f"({CALIBRATION_FORMAT_VERSION}); upgrade thermocal"
        )
    if d.get("checksum") != checksum(d):
        raise ModelFileError(
            f"{where}: checksum mismatch: the calibration file was corrupted or edited by hand"
        )
    raw = d.get("channels")
    raw_triads = d.get("triads", [])
    if not isinstance(raw_triads, list):
        raise ModelFileError(f"{where}.triads: expected a list")
    if not isinstance(raw, list) or not (raw or raw_triads):
        raise ModelFileError(f"{where}.channels: expected a non-empty list of channels")
    channels = []
    for i, ch in enumerate(raw):
        at = f"{where}: channels[{i}]"
        if not isinstance(ch, dict):
            raise ModelFileError(f"{at}: expected an object")
        for key in ("name", "signal", "unit", "model"):
            if key not in ch:
                raise ModelFileError(f"{at}: the field {key!r} is missing")
        if not all(isinstance(ch[k], str) and ch[k] for k in ("name", "signal", "unit")):
            raise ModelFileError(f"{at}: name, signal and unit must be non-empty strings")
        role = ch.get("role")
        if role is not None and (not isinstance(role, dict) or role.get("kind") not in ROLE_KINDS):
            raise ModelFileError(f"{at}.role: expected null or {{'kind': gyro|accel, ...}}")
        md = verify_model_dict(ch["model"], where, f"channels[{i}].model")
        try:
            model = model_from_dict(md)
        except (KeyError, TypeError, ValueError) as exc:
            raise ModelFileError(f"{at}.model: malformed ({type(exc).__name__}: {exc})") from None
        channels.append(Channel(ch["name"], ch["signal"], ch["unit"], model, role))
    triads = [_triad_from_dict(t, f"{where}: triads[{i}]") for i, t in enumerate(raw_triads)]
    scaled = next((t.name for t in triads if t.count_scale is not None), None)
    if scaled is not None and ver < COUNT_SCALE_FORMAT_VERSION:
        # a thermocal of version 1 would ignore the count scale and apply the triad to counts
        raise ModelFileError(
            f"{where}: triad {scaled!r} has a count_scale, which needs format_version "
            f"{COUNT_SCALE_FORMAT_VERSION}; the file says {ver}"
        )
    sensed = next((t.name for t in triads if t.g_sensitivity is not None), None)
    if sensed is not None and ver < G_SENSITIVITY_FORMAT_VERSION:
        # an older thermocal would leave the g-sensitivity out without a word
        raise ModelFileError(
            f"{where}: triad {sensed!r} has a g_sensitivity, which needs format_version "
            f"{G_SENSITIVITY_FORMAT_VERSION}; the file says {ver}"
        )
    squared = next((t.name for t in triads if t.k2 is not None), None)
    if squared is not None and ver < K2_FORMAT_VERSION:
        raise ModelFileError(
            f"{where}: triad {squared!r} has a k2, which needs format_version "
            f"{K2_FORMAT_VERSION}; the file says {ver}"
        )
    try:
        return Calibration(channels, triads)
    except ThermocalInputError as exc:
        raise ModelFileError(f"{where}: {exc}") from None


def _triad_from_dict(t: Any, at: str) -> Triad:
    from thermocal.turntable.thermal import TriadThermal

    if not isinstance(t, dict):
        raise ModelFileError(f"{at}: expected an object")
    cols = t.get("columns")
    if not (isinstance(cols, list) and len(cols) == 3 and all(isinstance(c, str) for c in cols)):
        raise ModelFileError(f"{at}.columns: expected three column names")
    for key in ("name", "unit", "temperature"):
        if not isinstance(t.get(key), str) or not (t[key] or key == "temperature"):
            raise ModelFileError(f"{at}: {key} must be a non-empty string")
    if "model" not in t:
        raise ModelFileError(f"{at}: the field 'model' is missing")
    model = TriadThermal.from_dict(t["model"], f"{at}.model")
    if not t["temperature"] and model.order != 0:
        raise ModelFileError(f"{at}: a triad over temperature must name its temperature column")
    enc = t.get("encoders", ["alpha_deg", "beta_deg"])
    lat = t.get("latitude_deg")
    if not (isinstance(enc, list) and len(enc) == 2 and all(isinstance(c, str) for c in enc)):
        raise ModelFileError(f"{at}.encoders: expected the two encoder column names")
    if lat is not None and (
        isinstance(lat, bool) or not isinstance(lat, int | float) or not -90 <= lat <= 90
    ):
        raise ModelFileError(f"{at}.latitude_deg: expected a latitude [°] or null, got {lat!r}")
    return Triad(
        t["name"],
        (cols[0], cols[1], cols[2]),
        t["unit"],
        t["temperature"],
        model,
        (enc[0], enc[1]),
        None if lat is None else float(lat),
        t["adequacy"] if isinstance(t.get("adequacy"), dict) else None,
        tuple(
            {"file": str(x.get("file", "")), "sha256": str(x.get("sha256", ""))}
            for x in (t.get("data") or [])
            if isinstance(x, dict)
        ),
        _count_scale_from_dict(t.get("count_scale"), t["unit"], at),
        *_g_sensitivity_from_dict(t, model.kind, at),
        *_k2_from_dict(t, model.kind, at),
    )


def _matrix3(v: Any, at: str, what: str, nonnegative: bool) -> FloatArray:
    """A 3×3 nested list of finite numbers (non-negative ones for a σ) as an array."""
    ok = (
        isinstance(v, list)
        and len(v) == 3
        and all(isinstance(r, list) and len(r) == 3 for r in v)
        and all(
            not isinstance(x, bool) and isinstance(x, int | float) and math.isfinite(x)
            for r in v
            for x in r
        )
    )
    if not ok or (nonnegative and any(x < 0 for r in v for x in r)):
        sign = "non-negative " if nonnegative else ""
        raise ModelFileError(
            f"{at}.{what}: expected a 3×3 nested list of finite {sign}numbers (rows the gyro "
            "axes x, y, z; columns the specific force's axes)"
        )
    return np.array(v, dtype=np.float64)


def _vector3(v: Any, at: str, what: str, nonnegative: bool) -> FloatArray:
    """Three finite numbers (non-negative ones for a σ) as an array."""
    ok = isinstance(v, list) and len(v) == 3 and all(
        not isinstance(x, bool) and isinstance(x, int | float) and math.isfinite(x)
        and not (nonnegative and x < 0)
        for x in v
    )  # fmt: skip
    if not ok:
        sign = "non-negative " if nonnegative else ""
        raise ModelFileError(f"{at}.{what}: expected three finite {sign}numbers (x, y, z)")
    return np.array(v, dtype=np.float64)


def _term_from_dict(
    t: dict[str, Any],
    kind: str,
    at: str,
    key: str,
    owner: tuple[str, str],
    per: tuple[str, str],
    read: Callable[[Any, str, str, bool], FloatArray],
) -> tuple[FloatArray | None, FloatArray | None]:
    """A triad's optional term ``key`` and its σ (``key_sigma``): only on the triad kind
    ``owner[0]`` (named ``owner[1]`` in the message), in the triad's unit per ``per[0]``
    as ``key_unit`` states (``per[1]`` in the message), its values checked by ``read``;
    (None, None) when absent."""
    if t.get(key) is None:
        for k in (f"{key}_sigma", f"{key}_unit"):
            if t.get(k) is not None:
                raise ModelFileError(f"{at}: {k} without {key}")
        return None, None
    if kind != owner[0]:
        raise ModelFileError(f"{at}: a {key} belongs to {owner[1]}, not a {kind}")
    want = f"{t['unit']}/{per[0]}"
    if t.get(f"{key}_unit") != want:
        raise ModelFileError(
            f"{at}.{key}_unit: expected {want!r} (the triad's unit per {per[1]}), "
            f"got {t.get(f'{key}_unit')!r}"
        )
    value = read(t[key], at, key, False)
    raw_sigma = t.get(f"{key}_sigma")
    return value, None if raw_sigma is None else read(raw_sigma, at, f"{key}_sigma", True)


def _g_sensitivity_from_dict(
    t: dict[str, Any], kind: str, at: str
) -> tuple[FloatArray | None, FloatArray | None]:
    """A triad's ``g_sensitivity`` and its σ (format version 3): only on a gyro triad, 3×3,
    in the triad's unit per g as ``g_sensitivity_unit`` states; (None, None) when absent."""
    return _term_from_dict(
        t, kind, at, "g_sensitivity", ("gyro", "a gyro triad"), ("g", "g"), _matrix3
    )


def _k2_from_dict(
    t: dict[str, Any], kind: str, at: str
) -> tuple[FloatArray | None, FloatArray | None]:
    """An accelerometer triad's ``k2`` and its σ (format version 4): three finite numbers
    in the triad's unit per g² as ``k2_unit`` states; (None, None) when absent."""
    return _term_from_dict(
        t, kind, at, "k2", ("accel", "an accelerometer triad"), ("g^2", "g²"), _vector3
    )


def _count_scale_from_dict(cs: Any, unit: str, at: str) -> float | None:
    """A triad's ``count_scale`` object ``{"value": K, "unit": U}`` (format version 2): K a
    positive finite number, U the triad's own unit; None when absent."""
    if cs is None:
        return None
    value = cs.get("value") if isinstance(cs, dict) else None
    if (
        not isinstance(cs, dict)
        or isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or value <= 0
        or cs.get("unit") != unit
    ):
        raise ModelFileError(
            f"{at}.count_scale: expected {{'value': a positive number, 'unit': {unit!r}}}, "
            f"got {cs!r}"
        )
    return float(value)


__all__ = [
    "CALIBRATION_FORMAT",
    "CALIBRATION_FORMAT_VERSION",
    "G_SENSITIVITY_FORMAT_VERSION",
    "K2_FORMAT_VERSION",
    "Calibration",
    "Channel",
    "calibration_from_dict",
    "guess_role",
    "is_calibration",
]
