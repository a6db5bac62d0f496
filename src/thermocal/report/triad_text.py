"""Calibrations of triads as text: the tables and lines of a multi-position or turntable
calibration, as blocks of :mod:`thermocal.report.text` (lines and
:class:`~thermocal.report.text.TextTable`), printed by the command line or read in a notebook.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal.report.text import Block, TextTable, fmt

if TYPE_CHECKING:
    from thermocal.pipeline.multipos import MultiposResult
    from thermocal.pipeline.turntable import SingleRunResult, ThermalRunsResult


def _triad_table(kind: str, d: dict[str, Any]) -> TextTable:
    """One triad's bias, scale factors and misalignments with their σ."""
    rows = [(f"bias {ax}", fmt(d["bias"][i], 5), fmt(d["bias_sigma"][i], 3), d["bias_unit"])
            for i, ax in enumerate("xyz")]  # fmt: skip
    rows += [
        (f"scale factor {ax}", fmt(d["scale_factor_ppm"][i], 5),
         fmt(d["scale_factor_ppm_sigma"][i], 3), "ppm")
        for i, ax in enumerate("xyz")
    ]  # fmt: skip
    for i, n in enumerate(d["misalignment_names"]):
        sig = d["misalignment_arcsec_sigma"][i]  # 0: an element the model holds at 0
        rows.append((f"misalignment {n}", fmt(d["misalignment_arcsec"][i], 5),
                     fmt(sig, 3) if sig else "held (not fitted)", "″"))  # fmt: skip
    k2 = d.get("k2")  # stored with the parameters above (fitted with them)
    if k2:
        rows += [(f"K2 {ax}", fmt(v, 4), fmt(e, 2), k2["unit"].replace("^2", "²"))
                 for ax, v, e in zip("xyz", k2["k2"], k2["k2_sigma"], strict=True)]  # fmt: skip
    columns = ("parameter", "value", "σ", "unit")
    return TextTable(f"{kind} triad ({d['method']})", columns, tuple(rows), ("left",) * 4)


def gyro_misfit_line(run: dict[str, Any]) -> str | None:
    """The line said when a run's gyro motions scatter beyond their noise
    (:func:`thermocal.multipos.gyro.scatter_beyond_noise`: the gyro's σ are scaled by the
    reduced χ²), else None.

    Parameters
    ----------
    run : dict
        One run of a multi-position result's ``runs`` (its ``gyro`` figures).

    Returns
    -------
    str or None

    References
    ----------
    Ferraris et al. (1995), *Sensors and Materials* 7(5) (gyro scale factors and
    misalignments from rotations between poses).
    """
    from thermocal.multipos.gyro import scatter_beyond_noise

    g = run.get("gyro")
    if not g or not g["dof"] > 0 or g["reduced_chi2"] is None:
        return None
    chi2, dof = float(g["reduced_chi2"]), int(g["dof"])
    if not scatter_beyond_noise(chi2, dof):
        return None
    return (
        f"{run['input']}: the gyro's {g['n_motions']} motions scatter beyond their noise "
        f"(reduced χ² {fmt(chi2, 3)} on {dof} degrees of freedom, {g['model']} model): "
        "its σ are scaled by it"
    )


def g_sensitivity_line(run: dict[str, Any], what: str = "poses") -> str | None:
    """The gyro's sensitivity to specific force found in a run's static poses: the elements
    beyond 3σ with their σ (or that none is), or why the poses cannot separate it; None
    without a gyro.

    Parameters
    ----------
    run : dict
        One run of a multi-position result's ``runs`` (its ``gyro`` figures), or of a
        turntable's (``gyro`` holding its ``g_sensitivity`` keys).
    what : str, optional
        What the still positions are called (``poses``, a turntable's ``dwells``).

    Returns
    -------
    str or None

    References
    ----------
    IEEE Std 952-1997, annex B (acceleration-sensitive drift).
    """
    g = run.get("gyro")
    if not g or "g_sensitivity" not in g:
        return None
    gs = g["g_sensitivity"]
    if gs is None:
        return f"{run['input']}: gyro g-sensitivity not estimated: {g['g_sensitivity_note']}"
    found = [
        f"{'xyz'[i]}/{'xyz'[j]} {fmt(gs['matrix'][i][j], 3)} ± {fmt(gs['matrix_sigma'][i][j], 2)}"
        for i in range(3)
        for j in range(3)
        if gs["significant"][i][j]
    ]
    head = (
        f"{run['input']}: gyro g-sensitivity from {gs['n_poses']} {what} "
        f"[{gs['unit']}, gyro/force axis]: "
    )
    if not found:
        worst = max(max(row) for row in gs["matrix_sigma"])
        return head + f"none beyond 3σ (σ ≤ {fmt(worst, 2)})"
    done = (
        "; taken off the rotations before the fit"
        if g.get("g_sensitivity_subtracted")
        else "; not compensated by this calibration"
    )
    why = f"; {g['g_sensitivity_note']}" if g.get("g_sensitivity_note") else ""
    return head + "; ".join(found) + f" (beyond 3σ{done}{why})"


def g_sensitivity_table(gs: dict[str, Any], title: str) -> TextTable:
    """A g-sensitivity ``A`` as a table: one row per gyro axis, one column per specific
    force axis, each cell ``value ± σ`` in ``gs["unit"]``, ``*`` marking an element beyond
    :data:`thermocal.multipos.gsens.SIGNIFICANT_SIGMA` σ.

    Parameters
    ----------
    gs : dict
        ``matrix`` and ``matrix_sigma`` (3×3) and ``unit``, as the results' JSON holds them.
    title : str
        The table's title.

    Returns
    -------
    TextTable

    References
    ----------
    IEEE Std 952-1997, annex B (acceleration-sensitive drift).
    """
    from thermocal.multipos.gsens import SIGNIFICANT_SIGMA

    def cell(v: float, s: float) -> str:
        star = " *" if s > 0 and abs(v) > SIGNIFICANT_SIGMA * s else ""
        return f"{fmt(v, 3)} ± {fmt(s, 2)}{star}"

    rows = tuple(
        (f"gyro {ax}", *(cell(gs["matrix"][i][j], gs["matrix_sigma"][i][j]) for j in range(3)))
        for i, ax in enumerate("xyz")
    )
    columns = (f"A [{gs['unit']}]", "force x", "force y", "force z")
    return TextTable(f"{title} (* beyond {SIGNIFICANT_SIGMA:g}σ)", columns, rows,
                     ("left",) * 4)  # fmt: skip


def g_sensitivity_stored_line(out: dict[str, Any]) -> str | None:
    """Whether the calibration holds the gyro's g-sensitivity (``compensate`` then takes
    ``A f`` off), and why; None without a gyro.

    Parameters
    ----------
    out : dict
        A multi-position result's JSON object (its ``gyro.g_sensitivity``).

    Returns
    -------
    str or None

    References
    ----------
    IEEE Std 952-1997, annex B (acceleration-sensitive drift).
    """
    gs = out.get("gyro", {}).get("g_sensitivity")
    if gs is None:
        return None
    if not gs["stored"]:
        return f"gyro g-sensitivity {gs['why']}: compensate leaves it in"
    worst = max(abs(v) for row in gs["matrix"] for v in row)
    return (
        f"gyro g-sensitivity {gs['why']} (largest |A| {fmt(worst, 3)} {gs['unit']}, over "
        f"{gs['n_sessions']} session(s)): compensate takes A·f off with the accelerometer's "
        "specific force; the gyro bias is that at zero specific force"
    )


def pose_detection_lines(out: dict[str, Any]) -> list[str]:
    """The pose detector's choice, per file: poses found, the still limit and what set it,
    the stretches rejected and why.

    Parameters
    ----------
    out : dict
        A multi-position result's dictionary (``pose_detection``, ``unit``).

    Returns
    -------
    list of str

    References
    ----------
    Tedaldi et al. (2014), ICRA (static detector on the accelerometer's variance).
    """
    lines = []
    for d in out.get("pose_detection", []):
        a = d["accel"]
        lines.append(
            f"{d['input']}: {d['n_poses']} poses (window {fmt(d['window_s'], 3)} s, still "
            f"for ≥ {fmt(d['static_s'], 3)} s below an accelerometer rms of "
            f"{fmt(a['still_limit_rms'], 3)} {out['unit']}, set by the "
            + ("noise" if a["limit_set_by"] == "noise" else "motions")
            + f": noise {', '.join(fmt(v, 3) for v in a['noise_sigma'])}, motions "
            f"{fmt(a['motion_rms'], 3)}); {len(d['rejected'])} rejected"
        )
        lines += [f"  rejected {r['start']}…{r['end']}: {r['reason']}" for r in d["rejected"]]
    return lines


def multipos_text(
    res: MultiposResult, output: Path | str, spell: Callable[[str], str] | None = None
) -> list[Block]:
    """A multi-position calibration as text (:func:`multipos_summary_text` of its
    dictionary).

    Parameters
    ----------
    res : thermocal.pipeline.multipos.MultiposResult
        The calibration (:func:`thermocal.pipeline.multipos.calibrate_files`).
    output : pathlib.Path or str
        The calibration file written, named in the summary line.
    spell : callable, optional
        How the pose detector's reasons write the parameters they name (default their own
        names; the command line: its options).

    Returns
    -------
    list of str or TextTable
    """
    return multipos_summary_text(res.to_dict(spell), res.accel_unit, output)


def _k2_line(run: dict[str, Any]) -> str:
    """A run's accelerometer K2 per axis (± 1σ) and the residual with it."""
    k = run["accel_k2"]
    terms = ", ".join(
        f"{ax} {fmt(v, 3)} ± {fmt(e, 2)}" for ax, v, e in zip("xyz", k["k2"], k["k2_sigma"],
                                                             strict=True)
    )  # fmt: skip
    return (
        f"{run['input']}: accelerometer K2 {terms} {k['unit'].replace('^2', '²')}; "
        f"gravity-magnitude residual rms with K2 {fmt(k['residual_rms_after'], 3)}; "
        "stored in the calibration with the bias, scale factors and misalignments fitted "
        "with it (compensate applies it)"
    )


def _misfit_line(run: dict[str, Any], a_unit: str) -> str | None:
    """The line said when a run's poses scatter beyond their noise in the accelerometer
    fit the calibration stores (the one with K2 when fitted), else None."""
    fit, what = (run["accel_k2"], " (the fit with K2)") if "accel_k2" in run else (run["accel"], "")
    if not fit.get("misfit"):
        return None
    return (
        f"{run['input']}: the poses scatter more than their noise{what} (reduced χ² "
        f"{fmt(fit['reduced_chi2'], 3)}): each pose's σ inflated by a misfit of "
        f"{fmt(fit['misfit'], 3)} {a_unit}, so that each counts as the misfit says"
    )


def multipos_summary_text(out: dict[str, Any], a_unit: str, output: Path | str) -> list[Block]:
    """A multi-position calibration's dictionary as text: each triad's table at TREF, the
    lean of the 360° turns, the poses and the gravity-magnitude residual before → after, the
    runs that scatter beyond their noise, and the pose detector's choice.

    Parameters
    ----------
    out : dict
        The calibration as :meth:`thermocal.pipeline.multipos.MultiposResult.to_dict`
        gives it.
    a_unit : str
        The accelerometer's unit.
    output : pathlib.Path or str
        The calibration file written, named in the summary line.

    Returns
    -------
    list of str or TextTable

    References
    ----------
    Tedaldi et al. (2014), ICRA; Ferraris et al. (1995), *Sensors and Materials* 7(5).
    """
    blocks: list[Block] = [_triad_table(k, out[k]) for k in ("accel", "gyro") if k in out]
    for run in out["runs"]:
        lean = run.get("gyro", {}).get("turn_axis_lean_deg", 0.0)
        if lean > 0:
            blocks.append(
                f"{run['input']}: the 360° turns lean {fmt(lean, 2)}° off their axes "
                "(per component, found in the data): counted in the σ, the misalignments "
                "rest on the motions between poses"
            )
    blocks += [_k2_line(run) for run in out["runs"] if "accel_k2" in run]
    with_k2 = " (the fit with K2, stored)" if out.get("accel", {}).get("k2") else ""
    blocks.append(
        f"{out['n_poses']} poses; gravity-magnitude residual rms "
        f"{fmt(out['gravity_residual_rms_before'], 3)} → "
        f"{fmt(out['gravity_residual_rms_after'], 3)} {a_unit}{with_k2}; written {output}"
    )
    stored = g_sensitivity_stored_line(out)
    blocks += [stored] if stored is not None else []
    gs = out.get("gyro", {}).get("g_sensitivity")
    if gs is not None and gs["matrix"] is not None:
        state = "stored" if gs["stored"] else "not stored"
        title = f"gyro g-sensitivity over {gs['n_sessions']} session(s), {state}"
        blocks.append(g_sensitivity_table(gs, title))
    for run in out["runs"]:
        line = gyro_misfit_line(run)
        blocks += [line] if line is not None else []
        line = g_sensitivity_line(run)
        blocks += [line] if line is not None else []
        line = _misfit_line(run, a_unit)
        blocks += [line] if line is not None else []
    return blocks + pose_detection_lines(out)


def turntable_text(res: SingleRunResult) -> list[Block]:
    """One turntable run's calibration: bias, scale factors and misalignments with the
    filter's σ, the Cramér-Rao bound and the least-squares value, then the inner axis's
    azimuth and the filter/least-squares agreement.

    Parameters
    ----------
    res : thermocal.pipeline.turntable.SingleRunResult
        The run's calibration.

    Returns
    -------
    list of str or TextTable

    References
    ----------
    IEEE Std 1431-2004 (rate-table calibration of a gyro triad).
    """
    from thermocal.turntable.model import MISALIGNMENT_NAMES

    out = res.to_dict()
    ls = out["least_squares"]
    groups = (
        ("bias", "bias_deg_h", "°/h", ("x", "y", "z")),
        ("scale factor", "scale_factor_ppm", "ppm", ("x", "y", "z")),
        ("misalignment", "misalignment_arcsec", "″", MISALIGNMENT_NAMES),
    )
    rows = tuple(
        (f"{label} {n}", fmt(out[key][i], 5), fmt(out[key + "_sigma"][i], 3),
         fmt(out["crb"][key][i], 3), fmt(ls[key][i], 5), unit)
        for label, key, unit, names in groups
        for i, n in enumerate(names)
    )  # fmt: skip
    columns = ("coefficient", "value", "σ", "CRB σ", "least squares", "unit")
    title = f"turntable calibration of {res.input} ({out['method']})"
    blocks: list[Block] = [
        TextTable(title, columns, rows, ("left",) * len(columns)),
        f"inner-axis azimuth (yx − xy)/2: {fmt(out['inner_axis_azimuth_arcsec'], 4)} ± "
        f"{fmt(out['inner_axis_azimuth_arcsec_sigma'], 3)} ″; "
        f"filter/LS agreement {fmt(out['agreement_max_sigma'], 2)} σ; written {res.output}",
    ]
    line = turntable_g_sensitivity_line(out, str(res.input))
    blocks += [line] if line is not None else []
    gs = out.get("g_sensitivity")
    if gs is not None:  # this run's estimate (°/h/g, as the result's JSON holds it)
        state = "taken off the moves" if out.get("g_sensitivity_subtracted") else "not taken off"
        blocks.append(g_sensitivity_table(gs, f"gyro g-sensitivity from the dwells, {state}"))
    return blocks


def turntable_g_sensitivity_line(out: dict[str, Any], name: str) -> str | None:
    """A turntable run's g-sensitivity line (:func:`g_sensitivity_line` on its dwells).

    Parameters
    ----------
    out : dict
        The run's result dictionary (``g_sensitivity``, ``g_sensitivity_note``,
        ``g_sensitivity_subtracted``).
    name : str
        The run's file, heading the line.

    Returns
    -------
    str or None
        None for a result without the keys.

    References
    ----------
    IEEE Std 1431-2004 (the acceleration-sensitive drift of the rate model).
    """
    if "g_sensitivity" not in out:
        return None
    keys = ("g_sensitivity", "g_sensitivity_note", "g_sensitivity_subtracted")
    return g_sensitivity_line({"input": name, "gyro": {k: out[k] for k in keys}}, "dwells")


def turntable_thermal_text(res: ThermalRunsResult) -> list[Block]:
    """Soak runs' calibration over temperature: per triad, each parameter's polynomial order,
    value and σ at TREF and its leave-one-temperature-out rms, then the file written.

    Parameters
    ----------
    res : thermocal.pipeline.turntable.ThermalRunsResult
        The calibration of several soaks.

    Returns
    -------
    list of str or TextTable

    References
    ----------
    IEEE Std 1431-2004 (rate-table calibration); PX4 ``TemperatureCompensation.cpp``
    (parameters as polynomials in T − TREF).
    """
    blocks: list[Block] = []
    for name, tri in (("gyro", res.gyro), ("accel", res.accel)):
        if tri is None:
            continue
        title = (
            f"{name} triad over temperature (TREF {tri.tref_c:g} °C, soaks "
            f"{', '.join(f'{t:g}' for t in tri.soak_temperatures_c)} °C)"
        )
        rows = tuple(
            (fit.name, fit.unit, str(len(fit.coef) - 1), fmt(fit.coef[0], 5),
             fmt(fit.sigma[0], 3), fmt(fit.loto_rms, 3))
            for fit in tri.fits
        )  # fmt: skip
        columns = ("parameter", "unit", "order", "at TREF", "σ", "LOTO rms")
        blocks.append(TextTable(title, columns, rows, ("left",) * len(columns)))
    for f, r in res.runs:
        line = turntable_g_sensitivity_line(r.to_dict(), str(f))
        blocks += [line] if line is not None else []
    gs = res.g_sensitivity
    if gs:
        blocks.append(f"gyro g-sensitivity over the soaks {gs['why']}"
                      + ("" if gs["stored"] else ": compensate leaves it in"))  # fmt: skip
        if gs["matrix"] is not None:
            state = "stored" if gs["stored"] else "not stored"
            blocks.append(g_sensitivity_table(gs, f"gyro g-sensitivity over the soaks, {state}"))
    blocks.append(f"calibration written: {res.output} (compensate applies it per sample)")
    return blocks


__all__ = [
    "g_sensitivity_line",
    "g_sensitivity_table",
    "gyro_misfit_line",
    "multipos_summary_text",
    "multipos_text",
    "pose_detection_lines",
    "turntable_g_sensitivity_line",
    "turntable_text",
    "turntable_thermal_text",
]
