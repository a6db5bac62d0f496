"""The tumble test as text: the coefficients with their uncertainties, in the output's unit
and normalised by the scale factor (IEEE Std 1293's form), then the fit's residual
(:func:`tumble_text`)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from thermocal.report.text import Block, TextTable, fmt

if TYPE_CHECKING:
    from thermocal.pipeline.tumble import TumbleResult

_LABELS = {
    "k0": "K0 bias",
    "k1": "K1 scale factor",
    "delta_o": "δo misalignment (IA to PA)",
    "k2": "K2 second order",
    "k_ip": "Kip cross-coupling",
    "k3": "K3 third order",
}
_NORMALISED = {"k0": ("k0_g", "µg"), "k2": ("k2_g_per_g2", "µg/g²"),
               "k_ip": ("k_ip_g_per_g2", "µg/g²"), "k3": ("k3_g_per_g3", "µg/g³")}  # fmt: skip


def _pm(value: float, sigma: float) -> str:
    """``value ± sigma``, the value to the decimal of the σ's second significant digit."""
    if not (math.isfinite(sigma) and sigma > 0):
        return f"{fmt(value, 6)} ± {fmt(sigma, 2)}"
    decimals = max(0, 1 - math.floor(math.log10(sigma)))
    return f"{value:.{decimals}f} ± {fmt(sigma, 2)}"


def tumble_text(res: TumbleResult) -> list[Block]:
    """The tumble test as text: what was fitted, the coefficients table (1σ), the fit's
    residual and what one tumble about the output axis cannot separate.

    Parameters
    ----------
    res : TumbleResult
        The test (:func:`thermocal.pipeline.tumble.tumble_file`).

    Returns
    -------
    list of str or TextTable
    """
    fit, c = res.fit, res.coefficients
    if res.mode == "stations":
        head = (
            f"{res.file}: {len(res.stations)} stations of the head, the first "
            f"{res.settle_s:g} s of each left out (settling)"
        )
    else:
        head = f"{res.file}: a continuous tumble, {fit.n_points} samples"
    out: list[Block] = [head]
    if res.temperature is not None:
        tt = res.temperature
        out.append(f"  temperature ({tt.column}): {tt.mean_c:.2f} °C mean, {tt.min_c:.2f} to "
                   f"{tt.max_c:.2f} °C")  # fmt: skip
    if res.dropped:
        spans = ", ".join(f"{a:.0f}-{b:.0f} s" for a, b in res.dropped[:8])
        out.append(f"  {len(res.dropped)} steady stretch(es) too short, left out: {spans}")
    units = res.coefficient_units()
    norm = c.normalised()
    rows = []
    for name, v, s in zip(c.names, c.values, c.sigmas, strict=True):
        if name == "delta_o":
            cell, unit = _pm(v * 1e6, s * 1e6), "µrad"
        else:
            cell, unit = _pm(float(v), float(s)), units[name].replace("^2", "²").replace("^3", "³")
        per_k1 = "—"
        if name in _NORMALISED:
            key, nunit = _NORMALISED[name]
            nv, ns = norm[key]
            per_k1 = f"{_pm(nv * 1e6, ns * 1e6)} {nunit}"
        rows.append((_LABELS[name], cell, unit, per_k1))
    out.append(
        TextTable(
            f"tumble test ({fit.n_points} points, {fit.harmonics} harmonics; ± 1σ)",
            ("coefficient", "value", "unit", "/ K1"),
            tuple(rows),
            ("left", "right", "left", "right"),
        )
    )
    chi = f", reduced χ² {fit.reduced_chi2:.2f}" if fit.reduced_chi2 is not None else ""
    out.append(
        f"residual rms {fmt(fit.residual_rms, 3)} {res.output_unit} ({fit.dof} degrees of "
        f"freedom{chi})"
    )
    out.append(
        "K_pp taken as negligible: one tumble about the output axis gives K2 − K_pp and K0 + K_pp"
    )
    return out
