"""The rate-table test as text: the spec-sheet table a customer receives, then the figures
per rate (:func:`ratetable_text`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from thermocal.report.text import Block, TextTable, fmt

if TYPE_CHECKING:
    from thermocal.pipeline.ratetable import RateTableResult
    from thermocal.ratetable.analysis import Figure, LadderResult


def _pm(value: float | None, sigma: float | None, digits: int = 4) -> str:
    """``value ± sigma`` (``—`` when refused)."""
    if value is None:
        return "—"
    return fmt(value, digits) + (f" ± {fmt(sigma, 2)}" if sigma is not None else "")


def _bound(f: Figure) -> str:
    """A threshold or resolution: ``≤ x`` (upper bound only) or ``a < · ≤ x``."""
    if f.value is None:
        return "—"
    d = f.detail or {}
    above = d.get("above_dps")
    return (f"{fmt(above, 3)} < · ≤ " if above is not None else "≤ ") + fmt(f.value, 3)


def _spec(ld: LadderResult, k_unit: str) -> TextTable:
    """The spec-sheet rows of one ladder (1σ uncertainties)."""
    t = f" at {ld.temperature_c:.1f} °C" if ld.temperature_c is not None else ""
    rows = [
        ("scale factor", _pm(ld.scale_factor, ld.scale_factor_sigma, 8), k_unit),
        (
            "bias (zero rate, from the line)",
            _pm(ld.zero_rate_bias_dps * 3600, ld.zero_rate_bias_sigma_dps * 3600),
            "°/h",
        ),
        (
            "scale-factor nonlinearity (max)",
            _pm(ld.nonlinearity.value, ld.nonlinearity.sigma),
            "ppm FS",
        ),
        ("scale-factor asymmetry", _pm(ld.asymmetry.value, ld.asymmetry.sigma), "ppm"),
        (
            "scale-factor repeatability (1σ)",
            _pm(ld.repeatability.value, ld.repeatability.sigma),
            "ppm",
        ),
        ("input threshold", _bound(ld.threshold), "°/s"),
        ("resolution", _bound(ld.resolution), "°/s"),
        ("full scale", fmt(ld.full_scale_dps), "°/s"),
    ]
    return TextTable(
        f"rate-table test{t} ({ld.n_plateaus} plateaus; ± 1σ)",
        ("figure", "value", "unit"),
        tuple(rows),
        ("left", "right", "left"),
    )


def _per_rate(ld: LadderResult) -> TextTable:
    """Bias and nonlinearity per rate."""
    rows = tuple(
        (
            fmt(r.rate_dps),
            str(r.n_plateaus),
            _pm(r.bias_dps * 3600, r.bias_sigma_dps * 3600),
            _pm(r.nonlinearity_ppm_fs, r.nonlinearity_sigma_ppm_fs),
            fmt(r.nonlinearity_ppm_rate),
        )
        for r in ld.rows
    )
    return TextTable(
        "per rate",
        ("rate [°/s]", "plateaus", "bias [°/h]", "nonlinearity [ppm FS]", "[ppm of rate]"),
        rows,
        ("right",) * 5,
    )


def ratetable_text(res: RateTableResult) -> list[Block]:
    """The rate-table test as text: each ladder's spec-sheet table and its figures per rate,
    the temperature coefficient, and every figure not computed with its reason.

    Parameters
    ----------
    res : RateTableResult
        The test (:func:`thermocal.pipeline.ratetable.ratetable_files`).

    Returns
    -------
    list of str or TextTable
    """
    out: list[Block] = []
    timings = res.timings or (None,) * len(res.files)
    for f, d, tm in zip(res.files, res.detections, timings, strict=True):
        source = "rates and their dwell" if d.source == "dwell" else d.source
        out.append(
            f"{f}: {len(d.plateaus)} plateaus from the {source}, the first "
            f"{d.settle_s:g} s of each left out (settling)"
        )
        if tm is not None:
            left = f"; {1 - tm.r2:.2g} of the output's variance off the profile's line"
            out.append(
                f"  the ladder starts at {tm.start_s:.3f} s"
                f" ({'found' if 'start' in tm.found else 'given'}), the table accelerating at "
                f"{tm.accel_dps2:.4g} °/s² ({'found' if 'accel' in tm.found else 'given'})"
                + (left if tm.r2 == tm.r2 else "")  # NaN: read back from a result file
            )
        if d.dropped:
            spans = ", ".join(f"{a:.0f}-{b:.0f} s" for a, b in d.dropped[:8])
            out.append(f"  {len(d.dropped)} steady stretch(es) too short, left out: {spans}")
    for ld in res.ladders:
        out.append(_spec(ld, res.scale_factor_unit))
        for name, fig in (
            ("asymmetry", ld.asymmetry),
            ("threshold", ld.threshold),
            ("resolution", ld.resolution),
            ("repeatability", ld.repeatability),
        ):
            if fig.reason:
                out.append(f"  {name}: not computed: {fig.reason}")
        out.append(_per_rate(ld))
    tc = res.temperature_coefficient
    if tc is not None:
        birge = f"; Birge ratio {tc.birge_ratio:.2f}" if tc.birge_ratio is not None else ""
        out.append(
            f"scale-factor temperature coefficient: {_pm(tc.ppm_per_c, tc.sigma_ppm_per_c)}"
            f" ppm/°C about {tc.tref_c:.1f} °C ({len(tc.temperatures_c)} ladders{birge})"
        )
    return out
