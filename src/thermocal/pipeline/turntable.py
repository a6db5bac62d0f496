"""The turntable at the file layer's edge: ``thermocal turntable FILE...`` as one library call.

One run (:func:`turntable_calibration` with one file): the gyro triad's bias, scale factor
and misalignment (:func:`thermocal.turntable.calibration.calibrate`), written as the
result JSON.  Several runs at soak temperatures: each run calibrated alone, then
every parameter of each triad as a polynomial in temperature
(:func:`thermocal.turntable.thermal.fit_triad`), judged first
(:mod:`thermocal.adequacy`) and written as a calibration of triads that ``compensate``
applies.  Every run is read by :func:`thermocal.readers.read_recording` with the same
options as every other command (text logs, ULog/DataFlash topics).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from thermocal import adequacy, units
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.readers.options import ReadOptions
from thermocal.recording import Recording
from thermocal.turntable import thermal as _thermal
from thermocal.turntable.calibration import TurntableResult, calibrate

MIN_POSITIONS_OF_A_SOAK = 12
"""A soak run missing a few of the sixteen positions is still used (with a warning): twelve
distinct attitudes still separate the twelve parameters of each triad."""


@dataclass(frozen=True)
class TurntableOptions:
    """What every turntable run is read and calibrated with.

    Attributes
    ----------
    gyro, accel : tuple of str
        The gyro's (and accelerometer's, or None) x, y, z columns.
    temps : str or None
        The temperature column [°C].
    latitude, gravity : float or None
        Site latitude [°] and local gravity [m/s²] (None: the file's, normal gravity).
    time, time_unit : str or None
        The time column and its unit.
    gyro_unit, accel_unit, encoder_unit : str or None
        The columns' units (None: the file's, :func:`thermocal.units.resolve_unit`).
    alpha, beta : str
        The inner- and outer-axis encoder columns.
    arw, encoder_noise : float or None
        Angle random walk [°/√h] and encoder noise [″] (None: from the dwells).
    min_dwell : float
        Shortest dwell [s].
    channels : int
        2 (Δα, Δβ) or 3 (Δα, Δβ, Δγ).
    read : ReadOptions or None
        A text log's layout.
    topic : str or None
        A flight log's topic.
    alpha_offset : float
        The α encoder's reading at the geometry's α = 0 [°].
    """

    gyro: tuple[str, str, str]
    accel: tuple[str, str, str] | None = None
    temps: str | None = None
    latitude: float | None = None
    time: str | None = "time"
    time_unit: str | None = None
    gyro_unit: str | None = None
    accel_unit: str | None = None
    gravity: float | None = None
    alpha: str = "alpha_deg"
    beta: str = "beta_deg"
    encoder_unit: str | None = None
    arw: float | None = None
    encoder_noise: float | None = None
    min_dwell: float = 60.0
    channels: int = 3
    read: ReadOptions | None = None
    """A text log's layout (``names``, ``rate_hz``, …); the columns are those named above."""
    topic: str | None = None
    alpha_offset: float = 0.0
    """The α encoder's reading at the geometry's α = 0 [°] (subtracted from the α column)."""


def check_order(order: int) -> None:
    """Refuse an ``order`` outside 0 … :data:`thermocal.turntable.thermal.MAX_ORDER`
    (3: a cubic in temperature per parameter, the most a few soaks can support; the number of
    soaks limits it further once the runs are read) before any file is read: typer parses an
    order of 10²⁰ as a Python int.

    Parameters
    ----------
    order : int
        Polynomial order in temperature of each calibration parameter [-].

    Returns
    -------
    None

    Raises
    ------
    ThermocalInputError
        When ``order`` is below 0 or above ``MAX_ORDER`` (a huge order is shown shortened).
    """
    if not 0 <= order <= _thermal.MAX_ORDER:
        shown = (
            str(order)
            if len(str(order)) <= 24
            else f"{str(order)[:20]}… ({len(str(order))} digits)"
        )
        raise ParameterError(
            "order", f"{{name}} must be between 0 and {_thermal.MAX_ORDER}, got {shown}"
        )


def read_run(path: Path, o: TurntableOptions) -> Recording:
    """Read one run (:func:`thermocal.readers.read_recording`).  The gyro columns' unit goes
    through the shared resolver: ``o.gyro_unit`` > file metadata > unit in the column name > °/s
    (gyro_z in °/s), the last stated in a warning.

    Parameters
    ----------
    path : Path
        The run's file (any registered format).
    o : TurntableOptions
        Columns, units and read options of the run.

    Returns
    -------
    Recording
        The run with its gyro columns [°/s unless stated], encoder and temperature columns.

    Raises
    ------
    ThermocalInputError
        When the file cannot be read or a named column is missing.
    """
    from thermocal.readers.dispatch import read_recording

    read = (o.read or ReadOptions()).replace(
        time=o.time,
        time_unit=o.time_unit,
        signals=tuple(o.gyro),
        signal_unit=o.gyro_unit,
        temperatures=(o.temps,) if o.temps else None,
        topic=o.topic,
    )
    return read_recording(path, read, model=units.StatedUnits(signal_default="deg/s"))


def calibrate_run(
    path: Path, o: TurntableOptions, *, min_positions: int
) -> tuple[Recording, TurntableResult]:
    """Read one run and calibrate it (:func:`thermocal.turntable.calibration.calibrate`).

    Parameters
    ----------
    path : Path
        The run's file.
    o : TurntableOptions
        Columns, units, site latitude [°], noise priors and dwell of the run.
    min_positions : int
        Fewest dwell positions accepted [-] (16 for a lone run).

    Returns
    -------
    rec : Recording
        The run as read.
    result : TurntableResult
        The estimated scale factors, misalignments and biases with their σ.

    Raises
    ------
    ThermocalInputError
        When the file cannot be read or too few positions are found.

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    """
    rec = read_run(path, o)
    res = calibrate(
        rec,
        o.latitude,
        gyro_columns=o.gyro,
        alpha_column=o.alpha,
        beta_column=o.beta,
        gyro_unit=o.gyro_unit,
        encoder_unit=o.encoder_unit,
        arw_deg_sqrt_h=o.arw,
        encoder_noise_arcsec=o.encoder_noise,
        min_dwell_s=o.min_dwell,
        channels=o.channels,
        accel_columns=o.accel,
        accel_unit=o.accel_unit,
        gravity_m_s2=o.gravity,
        temperature_column=o.temps,
        min_positions=min_positions,
        alpha_offset_deg=o.alpha_offset,
    )
    return rec, res


@dataclass(frozen=True)
class SingleRunResult:
    """One run's calibration (:class:`~thermocal.turntable.calibration.TurntableResult`), the
    file it came from and the result JSON written.

    Attributes
    ----------
    input : Path
        The run.
    output : Path
        The result JSON written.
    result : TurntableResult
        The calibration.
    """

    input: Path
    output: Path
    result: TurntableResult

    def to_dict(self, spell: Callable[[str], str] | None = None) -> dict[str, Any]:
        """The result JSON, with ``input``.

        Parameters
        ----------
        spell : callable, optional
            How the warnings name a parameter (:meth:`TurntableResult.to_dict`).

        Returns
        -------
        dict
        """
        out: dict[str, Any] = self.result.to_dict(spell)
        out["input"] = str(self.input)
        return out


def triad_summary(tri: _thermal.TriadThermal) -> dict[str, object]:
    r"""The JSON of one triad's temperature model (tref_c, order, coefficients
    with _sigma, loto_rms).

    Parameters
    ----------
    tri : TriadThermal
        The triad's fitted temperature model.

    Returns
    -------
    dict
        ``tref_c`` [°C], ``order``, ``temperature_range_c`` [°C] and per parameter its
        unit, coefficients (ascending powers of :math:`T - T_\mathrm{ref}`), their σ and
        the leave-one-temperature-out RMS.
    """
    return {
        "tref_c": tri.tref_c,
        "order": tri.order,
        "temperature_range_c": [tri.t_lo_c, tri.t_hi_c],
        "parameters": {
            f.name: {
                "unit": f.unit,
                "coefficients": f.coef.tolist(),
                "coefficients_sigma": f.sigma.tolist(),
                "loto_rms": f.loto_rms,
            }
            for f in tri.fits
        },
    }


@dataclass(frozen=True)
class ThermalRunsResult:
    """Several soak runs' calibration: each run's result, the triads' temperature models
    (``accel`` None without accelerometer columns), the adequacy record of the soaks and the
    calibration file written.

    Attributes
    ----------
    output : Path
        The calibration file written.
    runs : tuple of (Path, TurntableResult)
        Each soak run.
    gyro, accel : TriadThermal
        The triads' temperature models (accel None without its columns).
    adequacy : dict
        The adequacy record of the soaks.
    g_sensitivity : dict
        What the calibration holds of the gyro's g-sensitivity (:func:`stored_g_sensitivity`).
    """

    output: Path
    runs: tuple[tuple[Path, TurntableResult], ...]
    gyro: _thermal.TriadThermal
    accel: _thermal.TriadThermal | None
    adequacy: dict[str, Any]
    g_sensitivity: dict[str, Any] = field(default_factory=dict)
    """``matrix``, ``matrix_sigma`` (the runs' pooled ``A`` in ``unit``, None when no run
    estimated it), ``unit``, ``stored`` and ``why`` (:func:`stored_g_sensitivity`)."""

    def to_dict(self, spell: Callable[[str], str] | None = None) -> dict[str, Any]:
        """The result as JSON types (what the ``turntable`` command prints for several runs).

        Parameters
        ----------
        spell : callable, optional
            How the runs' warnings name a parameter (:meth:`TurntableResult.to_dict`).

        Returns
        -------
        dict
            ``output``, ``format``, each run's figures, each triad's temperature model and
            the adequacy record.
        """
        out: dict[str, Any] = {
            "output": str(self.output),
            "format": "thermocal-calibration",
            "runs": [{"input": str(f), **r.to_dict(spell)} for f, r in self.runs],
            "gyro": triad_summary(self.gyro),
            "adequacy": self.adequacy,
        }
        if self.accel is not None:
            out["accel"] = triad_summary(self.accel)
        return out


def check_as_read(cal: Any, output: Path, hint: str, *parameters: str) -> None:
    """The checks the calibration file's reader applies
    (:func:`thermocal.models.calibration.calibration_from_dict`: each triad's TREF within
    its range, a well-conditioned ``I + E(T)`` over it, finite numbers …) applied to ``cal``
    before it is written to ``output``: a calibration that its own reader would refuse is
    refused now (:class:`~thermocal.errors.DesignError` naming what failed, ``hint`` the
    parameters that get the user further), and nothing is written.

    Parameters
    ----------
    cal : Calibration
        The calibration about to be written.
    output : Path
        Where it would be written (named in the message).
    hint : str
        What gets the user further, appended to the message, with ``{parameter}`` for each
        of ``parameters``.
    *parameters : str
        The parameters ``hint`` names.

    Returns
    -------
    None

    Raises
    ------
    DesignError
        When the calibration's own reader would refuse it.
    """
    import json

    from thermocal.errors import DesignError, ModelFileError
    from thermocal.models.calibration import calibration_from_dict

    try:
        calibration_from_dict(json.loads(json.dumps(cal.to_dict())), str(output))
    except (ModelFileError, ValueError) as exc:
        raise DesignError.around(exc, "", "; not written: " + hint, *parameters) from None


def turntable_calibration(
    files: Sequence[Path],
    output: Path,
    opts: TurntableOptions,
    *,
    order: int | None = None,
    tref_c: float | None = None,
    overrides: tuple[str, ...] = (),
) -> SingleRunResult | ThermalRunsResult:
    """``thermocal turntable``: one run → :class:`SingleRunResult` (the result JSON written
    to ``output``); several runs, or one with ``opts.temps`` and ``order``/``tref_c`` →
    :class:`ThermalRunsResult` (the calibration written to ``output``, :func:`thermal_runs`).
    Refuses (exit 2) an output that is an input, an order outside 0…3, several runs without
    a temperature column, and ``order``/``tref_c`` for one run.

    Parameters
    ----------
    files : sequence of Path
        The runs, one per soak temperature when several.
    output : Path
        The result (one run) or calibration (several runs) JSON file to write.
    opts : TurntableOptions
        Columns, units and rig settings shared by the runs.
    order : int or None, optional
        Polynomial order in temperature (0…3); default ``None``: chosen per parameter.
    tref_c : float or None, optional
        Reference temperature of the polynomials [°C]; default ``None``: mid-range.
    overrides : tuple of str, optional
        Adequacy tests to accept although failed (default none).

    Returns
    -------
    SingleRunResult or ThermalRunsResult
        The result; its ``to_dict()`` is the command's JSON.

    Raises
    ------
    ThermocalInputError
        On the refusals listed above.

    References
    ----------
    - *A method for separating the combined error coefficients of a ring-laser gyro triad
      based on dual-axis rotation*, Chinese invention patent CN104880182.
    """
    from thermocal.writers import check_not_input, write_json

    if order is not None:
        check_order(order)
    check_not_input(output, list(files))
    if len(files) > 1 or (opts.temps is not None and (order is not None or tref_c is not None)):
        if opts.temps is None:
            raise ThermocalInputError.naming(
                "several runs: name their temperature column with {temps} (one run per soak)",
                "temps",
            )
        return thermal_runs(files, output, opts, order, tref_c, overrides)
    if order is not None or tref_c is not None:
        raise ThermocalInputError.naming(
            "{order} and {tref_c} need several runs and {temps}", "order", "tref_c", "temps"
        )
    _rec, result = calibrate_run(files[0], opts, min_positions=16)
    single = SingleRunResult(files[0], output, result)
    write_json(output, single.to_dict())
    return single


def thermal_runs(
    files: Sequence[Path],
    output: Path,
    opts: TurntableOptions,
    order: int | None,
    tref_c: float | None,
    overrides: tuple[str, ...] = (),
) -> ThermalRunsResult:
    r"""Each run calibrated alone (at least :data:`MIN_POSITIONS_OF_A_SOAK` positions), then
    every parameter of each triad as a polynomial in temperature about ``tref_c`` [°C]
    (:func:`thermocal.turntable.thermal.fit_triad`); writes a calibration of triads.  The
    soak temperatures are judged first (:func:`thermocal.adequacy.temperature_tests`: span
    and distinct soaks for the order asked, 1 when the order is chosen per parameter).

    Parameters
    ----------
    files : sequence of Path
        The runs, one per soak.
    output : Path
        The calibration file to write (``.json``).
    opts : TurntableOptions
        Columns, units and rig settings shared by the runs.
    order : int or None
        Polynomial order in temperature; ``None`` chooses it per parameter.
    tref_c : float or None
        Reference temperature [°C]; ``None``: mid-range of the soaks.
    overrides : tuple of str, optional
        Adequacy tests to accept although failed (default none).

    Returns
    -------
    ThermalRunsResult
        The runs, the triads' temperature models and the adequacy record.

    Raises
    ------
    ThermocalInputError
        When ``output`` is not ``.json``, a run cannot be read, or the soaks cannot
        support the order (adequacy tests not overridden).
    DesignError
        When the calibration would be refused on reading.

    Notes
    -----
    Each parameter :math:`p` (scale factor, misalignment, bias) is fitted as

    .. math:: p(T) = \sum_{k=0}^{n} c_k (T - T_\mathrm{ref})^k

    by weighted least squares on the runs' estimates and their σ.
    """
    from thermocal.models.calibration import Calibration, Triad
    from thermocal.pipeline.model_file import save_calibration

    if output.suffix.lower() != ".json":
        raise ThermocalInputError(f"{output}: the calibration is JSON; use a .json name")
    runs, gyro_unit, accel_unit = _soak_runs(files, opts)
    temps_c = [float(r.temperature_c) for _f, r in runs]  # type: ignore[arg-type]
    judged = adequacy.Adequacy(
        tuple(
            adequacy.temperature_tests(
                np.asarray(temps_c, dtype=np.float64), "the soak temperatures", order or 1
            )
        ),
        overrides,
    )
    record = judged.enforce().to_dict()
    rig, temps = (opts.alpha, opts.beta), str(opts.temps)
    latitude = runs[0][1].latitude_deg  # as used (the option or the files' metadata)
    gyro_model = _thermal.fit_triad(
        "gyro", temps_c, [r.kalman.theta for _f, r in runs], [r.kalman.sigma for _f, r in runs],
        tref_c=tref_c, order=order,
    )  # fmt: skip
    triads = [Triad("gyro", opts.gyro, gyro_unit, temps, gyro_model, rig, latitude, record)]
    g_sens = stored_g_sensitivity([r for _f, r in runs], gyro_unit)
    if g_sens["stored"]:
        triads[0] = replace(triads[0], g_sensitivity=np.asarray(g_sens["matrix"]),
                            g_sensitivity_sigma=np.asarray(g_sens["matrix_sigma"]))  # fmt: skip
    accel_model = None
    if opts.accel is not None:
        accel_model = _thermal.fit_triad(
            "accel", temps_c,
            [r.accel.theta for _f, r in runs if r.accel is not None],
            [r.accel.sigma for _f, r in runs if r.accel is not None],
            tref_c=gyro_model.tref_c, order=order,
        )  # fmt: skip
        triads.append(
            Triad("accel", opts.accel, str(accel_unit), temps, accel_model, rig, latitude, record)
        )
    cal = Calibration([], triads)
    check_as_read(cal, output, "check the columns' units ({gyro_unit}, {accel_unit}) and "
                  "the runs, or fit a lower {order}", "gyro_unit", "accel_unit",
                  "order")  # fmt: skip
    save_calibration(cal, output)
    return ThermalRunsResult(output, tuple(runs), gyro_model, accel_model, record, g_sens)


def stored_g_sensitivity(runs: Sequence[TurntableResult], gyro_unit: str) -> dict[str, Any]:
    """The runs' pooled g-sensitivity and whether the calibration stores it: it does when
    every run took its ``A f`` off before its fit (its bias is then the bias at zero
    specific force, as ``compensate`` expects); otherwise ``A`` is reported, not stored.

    Parameters
    ----------
    runs : sequence of TurntableResult
        The soak runs.
    gyro_unit : str
        The gyro's unit (``A`` in it per g).

    Returns
    -------
    dict
        ``matrix``, ``matrix_sigma`` (3×3 lists, None when no run estimated ``A``),
        ``unit`` (the gyro's unit per g), ``stored`` and ``why``.

    Notes
    -----
    Each element is the runs' inverse-variance mean
    (:func:`thermocal.turntable.gsens.pooled_g_sensitivity`).

    References
    ----------
    - IEEE Std 1431-2004 (the acceleration-sensitive drift of the rate model).
    """
    from thermocal.turntable.gsens import pooled_g_sensitivity

    pooled = pooled_g_sensitivity([r.g_sensitivity for r in runs])
    out: dict[str, Any] = {"matrix": None, "matrix_sigma": None, "unit": f"{gyro_unit}/g"}
    if pooled is None:
        return {**out, "stored": False, "why": "not estimated: no run's dwells separate it"}
    to_unit = float(units.convert(np.array([1.0]), "deg/h", gyro_unit)[0])
    out.update(matrix=(pooled[0] * to_unit).tolist(), matrix_sigma=(pooled[1] * to_unit).tolist())
    taken = sum(bool(r.g_sensitivity_subtracted) for r in runs)
    if runs and taken == len(runs):
        return {**out, "stored": True, "why": "stored: every run took it off before its fit"}
    why = (f"not stored: {len(runs) - taken} of {len(runs)} runs did not take it off (none "
           "beyond 3σ, or c·I alone: their notes say which)")  # fmt: skip
    return {**out, "stored": False, "why": why}


def _soak_runs(
    files: Sequence[Path], opts: TurntableOptions
) -> tuple[list[tuple[Path, TurntableResult]], str, str | None]:
    """Every soak run calibrated alone; (runs, the gyro unit, the accelerometer unit or
    None), refusing runs whose columns differ in unit."""
    runs = []
    gyro_units: set[str] = set()
    accel_units: set[str] = set()
    for f in files:
        rec, res = calibrate_run(f, opts, min_positions=MIN_POSITIONS_OF_A_SOAK)
        gyro_units |= {rec.units[c] for c in opts.gyro}  # resolved by read_recording
        if opts.accel is not None:
            accel_units |= (
                {opts.accel_unit} if opts.accel_unit else {rec.units[c] for c in opts.accel}
            )
        runs.append((f, res))
    for what, found in (("gyro", gyro_units), ("accelerometer", accel_units)):
        if len(found) > 1:
            raise ThermocalInputError(f"the runs' {what} columns differ in unit: {sorted(found)}")
    return runs, gyro_units.pop(), (accel_units.pop() if accel_units else None)
