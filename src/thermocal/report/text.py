"""Results as text: the tables and lines a person reads in a terminal or a notebook.

Each function turns a result object into a list of blocks, each a line of text (``str``) or
a :class:`TextTable` (a title, column names and rows of cells already formatted), in the
order they are read.  Nothing is printed here: the command line draws the tables with rich
(the same cells, the same order), a notebook user may print :meth:`TextTable.to_text` or
build a data frame from :attr:`TextTable.rows`.  Numbers are shown with :func:`fmt`
(significant digits, ``—`` for a missing value), in the result's own unit.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeAlias

if TYPE_CHECKING:
    from thermocal.inspection import Inspection
    from thermocal.metrics import MetricsResult, PowerOnMetrics
    from thermocal.stability.allan import NoiseTerm
    from thermocal.stability.analysis import AllanAnalysis, AllanChannel, ImuNoise
    from thermocal.stability.family import StabilityResult


def fmt(x: float | None, digits: int = 4) -> str:
    """A number for a table cell: ``digits`` significant digits, ``—`` for None or NaN.

    Parameters
    ----------
    x : float or None
        The number.
    digits : int
        Significant digits (default 4).

    Returns
    -------
    str
        ``f"{x:.{digits}g}"``, or ``"—"`` for None, NaN and infinities.

    Examples
    --------
    >>> fmt(1234.5678), fmt(0.000123456, 3), fmt(None), fmt(float("nan"))
    ('1235', '0.000123', '—', '—')
    """
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    return f"{x:.{digits}g}"


@dataclass(frozen=True)
class TextTable:
    """A table of formatted cells.

    Attributes
    ----------
    title : str or None
        The table's title.
    columns : tuple of str
        The column names.
    rows : tuple of tuple of str
        The cells, row by row (each row as long as ``columns``).
    justify : tuple of str
        ``"left"`` or ``"right"`` per column.
    """

    title: str | None
    columns: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    justify: tuple[str, ...]

    def to_text(self) -> str:
        """The table as plain text: the title, then one line per row, cells padded.

        Returns
        -------
        str
            Lines separated by ``"\\n"``; right-justified columns padded on the left.

        Examples
        --------
        >>> t = TextTable("τ", ("τ [s]", "ADEV"), (("1", "0.5"), ("10", "0.17")),
        ...               ("right", "right"))
        >>> print(t.to_text())
        τ
        τ [s] ADEV
            1  0.5
           10 0.17
        """
        grid = [self.columns, *self.rows]
        widths = [max(len(r[i]) for r in grid) for i in range(len(self.columns))]
        lines = [self.title] if self.title else []
        for r in grid:
            cells = [
                c.rjust(w) if j == "right" else c.ljust(w)
                for c, w, j in zip(r, widths, self.justify, strict=True)
            ]
            lines.append(" ".join(cells).rstrip())
        return "\n".join(lines)


Block: TypeAlias = "str | TextTable"
"""One block of a text rendering: a line or a table."""


class _Rows:
    """A table under construction (the rows appended one by one)."""

    def __init__(self, title: str | None, columns: Sequence[str], justify: str) -> None:
        self.title, self.columns, self.justify = title, tuple(columns), justify
        self.rows: list[tuple[str, ...]] = []

    def add(self, *cells: str) -> None:
        self.rows.append(tuple(cells))

    def table(self, justify: Sequence[str] | None = None) -> TextTable:
        just = tuple(justify) if justify else (self.justify,) * len(self.columns)
        return TextTable(self.title, self.columns, tuple(self.rows), just)


# --- stability ---------------------------------------------------------------------------


def family_text(where: str, res: StabilityResult) -> list[Block]:
    """One channel's deviations of the NIST SP 1065 family: a table per deviation (τ, the
    deviation, its interval, edf, the noise type α and the number of terms; τ where the
    deviation is undefined left out) and why a deviation has no interval.

    Parameters
    ----------
    where : str
        The file the titles name.
    res : thermocal.stability.family.StabilityResult
        The deviations of one channel.

    Returns
    -------
    list of str or TextTable

    References
    ----------
    Riley, W. J. (2008). *Handbook of Frequency Stability Analysis*, NIST SP 1065.
    """
    from thermocal.stability.family import no_interval

    out: list[Block] = []
    for name, c in res.curves.items():
        corrected = ", bias-corrected as Stable32" if c.bias is not None else ""
        t = _Rows(
            f"{where} — {name} [{c.unit}] ({res.data_type} data{corrected})",
            ("τ [s]", name, "low", "high", "edf", "α", "terms"),
            "right",
        )
        for i in range(c.tau_s.size):
            if not math.isfinite(float(c.dev[i])):
                continue
            t.add(
                fmt(float(c.tau_s[i])),
                fmt(float(c.dev[i]), 5),
                fmt(float(c.low[i]), 5),
                fmt(float(c.high[i]), 5),
                fmt(float(c.edf[i]), 4),
                str(int(c.alpha[i])),
                str(int(c.n_terms[i])),
            )
        out.append(t.table())
        why = no_interval(name)
        if why is not None:
            out.append(f"{name}: interval {why}")
    return out


def minimum_cell(t: NoiseTerm | None) -> str:
    """The bias instability at the Allan curve's minimum in one cell: value, unit, τ,
    quality (``—`` without one).

    Parameters
    ----------
    t : thermocal.stability.allan.NoiseTerm or None
        The term read at the minimum.

    Returns
    -------
    str

    References
    ----------
    IEEE Std 952-1997, Annex C.3 (bias instability at the flat of the curve).
    """
    if t is None or t.value is None:
        return "—"
    return f"{fmt(t.value)} {t.unit} (τ {fmt(t.tau_s)} s, {t.quality})"


def minimum_line(t: NoiseTerm | None) -> str | None:
    """The bias instability at the curve's minimum and its interval, as one line (None
    without one).

    Parameters
    ----------
    t : thermocal.stability.allan.NoiseTerm or None
        The term read at the minimum.

    Returns
    -------
    str or None

    References
    ----------
    IEEE Std 952-1997, Annex C.3.
    """
    if t is None or t.value is None:
        return None
    return (
        f"bias instability at the curve's minimum: {fmt(t.value)} {t.unit} "
        f"({fmt(t.low)} … {fmt(t.high)}), quality {t.quality}: {t.reason}"
    )


def stretch_cell(t: NoiseTerm) -> str:
    """The angle random walk read on the −½ stretch in one cell: value, unit, τ range.

    Parameters
    ----------
    t : thermocal.stability.allan.NoiseTerm
        The slope-line term.

    Returns
    -------
    str

    References
    ----------
    IEEE Std 952-1997, Annex C (slope −½: angle random walk N = σ(1 s)).
    """
    if t.value is None:
        return "—"
    rng = f" (τ {fmt(t.tau_range_s[0])}…{fmt(t.tau_range_s[1])} s)" if t.tau_range_s else ""
    return f"{fmt(t.value)} {t.unit}{rng}"


def allan_channels_text(where: str, analysis: AllanAnalysis) -> list[Block]:
    """Several channels' noise terms side by side: one table with a column per channel
    (least-squares fit, the −½ stretch, the curve's minimum, fit quality), then each
    channel's quantization and periodic terms.

    Parameters
    ----------
    where : str
        The file the title names.
    analysis : thermocal.stability.analysis.AllanAnalysis
        The analysis of several channels.

    Returns
    -------
    list of str or TextTable

    References
    ----------
    IEEE Std 952-1997, Annex C (noise terms of the Allan variance).
    """
    chans = analysis.channels
    t = _Rows(f"{where} — noise terms (least-squares fit), per channel", ("term", *chans), "right")
    first = next(iter(chans.values())).noise
    for key, term in first.fit.terms().items():
        t.add(term.label, *[_fit_cell(c.noise, key) for c in chans.values()])
        if key == "angle_random_walk":
            t.add(
                "  on the −½ stretch",
                *[stretch_cell(c.noise.slope.angle_random_walk) for c in chans.values()],
            )
        elif key == "bias_instability":
            t.add(
                "  at the curve's minimum",
                *[minimum_cell(c.noise.bias_minimum) for c in chans.values()],
            )
    t.add(
        "fit quality",
        *[
            f"{q.quality} (χ²/ν {q.reduced_chi2:.3g})" if (q := c.noise.quality) else "—"
            for c in chans.values()
        ],
    )
    out: list[Block] = [t.table(("left", *("right",) * len(chans)))]
    out += [f"{n}: {c.quantization.line()}" for n, c in chans.items() if c.quantization is not None]
    out += [f"{n}: periodic term: {p.words()}" for n, c in chans.items() for p in c.noise.periodic]
    return out


def _fit_cell(noise: Any, key: str) -> str:
    """One channel's least-squares value of the noise term ``key`` (the minimum's bias
    instability when the fit has none)."""
    tt = noise.fit.terms()[key]
    bm = noise.bias_minimum
    if tt.value is not None:
        return f"{fmt(tt.value)} {tt.unit}"
    if key == "bias_instability" and bm is not None and bm.value is not None:
        return f"{fmt(bm.value)} {bm.unit} (minimum; fit: —)"
    return "—"


def allan_text(where: str, ch: AllanChannel) -> list[Block]:
    """One channel's overlapping Allan deviation and noise terms: the ADEV table (τ, ADEV,
    interval, terms, edf), the noise terms by least squares and by slope lines, then the
    lines on the curve's minimum, periodic terms, the filtered short τ, the fit's χ², the
    quantization and the dynamic ADEV.

    Parameters
    ----------
    where : str
        The file the title names.
    ch : thermocal.stability.analysis.AllanChannel
        One channel of :func:`thermocal.stability.analysis.allan_analysis`.

    Returns
    -------
    list of str or TextTable

    References
    ----------
    IEEE Std 952-1997, Annex C; Riley, W. J. (2008), NIST SP 1065 (intervals, edf).
    """
    res, noise = ch.adev, ch.noise
    t1 = _Rows(
        f"{where} — overlapping Allan deviation [{res.unit}]",
        ("τ [s]", "ADEV", "low", "high", "terms", "edf"),
        "right",
    )
    for i in range(res.tau_s.size):
        t1.add(
            fmt(float(res.tau_s[i])),
            fmt(float(res.adev[i])),
            fmt(float(res.adev_low[i])),
            fmt(float(res.adev_high[i])),
            str(int(res.n_terms[i])),
            fmt(float(res.edf[i]), 3),
        )
    out: list[Block] = [t1.table(), _noise_table(noise)]
    line = minimum_line(noise.bias_minimum)
    out += [line] if line is not None else []
    out += [
        f"periodic term: {p.words()}; {100 * (p.share or 0):.3g} % of σ² there"
        for p in noise.periodic
    ]
    if noise.shaped_below_s is not None:
        out.append(
            f"τ < {fmt(noise.shaped_below_s)} s lies below the −½ line (the sensor's own "
            "filter): left out of the noise terms"
        )
    if noise.quality is not None:
        out.append(
            f"noise-model fit: reduced χ² {noise.quality.reduced_chi2:.3g} on "
            f"{noise.quality.dof} degrees of freedom — {noise.quality.quality}"
        )
    out += [ch.quantization.line()] if ch.quantization is not None else []
    dyn = ch.dynamic
    if dyn is not None:
        out.append(
            f"dynamic ADEV: {dyn.t_s.size} windows of {dyn.window_s:g} s, "
            + ("stationary" if dyn.stationary else f"{len(dyn.changes)} changes (warning)")
        )
    return out


def _noise_table(noise: Any) -> TextTable:
    """The noise terms of one channel by least squares and by slope lines."""
    t2 = _Rows("noise terms", ("term", "fit", "slope lines", "unit", "note"), "left")
    fit, slope = noise.fit.terms(), noise.slope.terms()
    poor = noise.quality is not None and noise.quality.quality == "poor"
    for name in fit:
        f, s = fit[name], slope[name]
        note = "poor fit (see the warning)" if poor else (f.reason or s.reason or "")
        mark = " ?" if poor else ""
        if name == "angle_random_walk" and s.tau_range_s is not None:
            note = f"−½ stretch τ {fmt(s.tau_range_s[0])}…{fmt(s.tau_range_s[1])} s; " + note
        t2.add(
            f.label,
            fmt(f.value) + (mark if f.value is not None else ""),
            fmt(s.value) + (mark if s.value is not None else ""),
            f.unit,
            note,
        )
        bm = noise.bias_minimum
        if name == "bias_instability" and bm is not None and bm.value is not None:
            t2.add(
                "  at the curve's minimum",
                "",
                fmt(bm.value),
                bm.unit,
                f"τ = {fmt(bm.tau_s)} s, {bm.quality} (IEEE 952 C.3)",
            )
    return t2.table()


def imu_noise_text(where: str, res: ImuNoise) -> list[Block]:
    """An IMU's noise model in continuous time, one row per axis: the white-noise density
    and how it was read, the random walk, and the bias instability at the Allan curve's
    minimum; then each axis's quantization.

    Parameters
    ----------
    where : str
        The file the title names.
    res : thermocal.stability.analysis.ImuNoise
        The noise model (:func:`thermocal.stability.analysis.imu_noise`).

    Returns
    -------
    list of str or TextTable

    References
    ----------
    IEEE Std 952-1997, Annex C (−½ line at τ = 1 s, +½ line at τ = 3 s).
    """
    columns = ("axis", "noise density", "random walk", "unit (density; walk)", "from",
               "bias instability (minimum)")  # fmt: skip
    rows = []
    for ax in res.axes:
        d = ax.density
        rng = d.tau_range_s
        how = d.method + (f" τ {fmt(rng[0])}…{fmt(rng[1])} s" if rng else "")
        rows.append((ax.name, fmt(d.value), fmt(ax.walk.value), f"{d.unit}; {ax.walk.unit}",
                     f"{how}; {ax.walk.method}", minimum_cell(ax.terms.bias_minimum)))  # fmt: skip
    title = f"{where} — IMU noise model (continuous time)"
    out: list[Block] = [TextTable(title, columns, tuple(rows), ("left",) * len(columns))]
    return out + [
        f"{ax.name}: {ax.quantization.line()}" for ax in res.axes if ax.quantization is not None
    ]


# --- inspection ----------------------------------------------------------------------------


def inspection_text(r: Inspection) -> list[Block]:
    """What a recording holds: samples, duration, sample rate, gaps and segments (or why
    they are not computed), a table of each column's role, unit, range, mean, NaN and
    spikes, a quantised or slow thermometer, each temperature's heating and cooling legs
    when it has any (the first ten), and the first ten gaps.

    Parameters
    ----------
    r : thermocal.inspection.Inspection
        The inspection (:func:`thermocal.inspection.inspect_recording`).

    Returns
    -------
    list of str or TextTable
    """
    if r.time_ok and r.duration_s is not None:
        head = (
            f"{r.n_samples} samples over {fmt(r.duration_s, 6)} s, "
            f"sample rate {fmt(r.sample_rate_hz, 6)} Hz, {len(r.gaps)} gaps, "
            f"{r.n_segments} contiguous segments"
        )
    elif r.time_ok:
        head = f"{r.n_samples} samples: too few for a duration or a sample rate"
    else:
        head = (
            f"{r.n_samples} samples; time is not finite and strictly increasing (see the "
            "errors below), so duration, sample rate, gaps and segments are not computed"
        )
    columns = ("column", "role", "unit", "min", "max", "mean", "NaN", "spikes")
    rows = tuple((c.name, c.role, c.unit, fmt(c.min, 6), fmt(c.max, 6), fmt(c.mean, 6),
                  str(c.n_nan), str(c.n_spikes)) for c in r.columns.values())  # fmt: skip
    out: list[Block] = [head, TextTable(None, columns, rows, ("left",) * len(columns))]
    for name, th in r.thermometers.items():
        if th is not None and (th["quantised"] or th["slow"]):
            out.append(
                f"temperature {name!r}: the thermometer is {th['kind']}; fit, px4-tempcal "
                "and ardupilot-tempcal fit on the temperature reconstructed at each sample"
            )
    for name, lg in r.legs.items():  # a record without a leg: said in the JSON only
        if lg is not None and lg["legs"]:
            shown = ", ".join(
                f"{g['direction']} {g['start_s']:.6g}…{g['stop_s']:.6g} s "
                f"({g['temp_start_c']:.4g}→{g['temp_stop_c']:.4g} °C)"
                for g in lg["legs"][:10]
            )
            more = f" … {len(lg['legs']) - 10} more" if len(lg["legs"]) > 10 else ""
            out.append(
                f"temperature {name!r}: {lg['summary']}" + (f": {shown}{more}" if shown else "")
            )
    if r.gaps:
        out.append(
            "gaps (start s, length s): "
            + ", ".join(f"({g['start_s']:.6g}, {g['length_s']:.6g})" for g in r.gaps[:10])
            + (f" … {len(r.gaps) - 10} more" if len(r.gaps) > 10 else "")
        )
    return out


# --- figures of merit ----------------------------------------------------------------------


def metrics_text(where: str, results: Mapping[str, MetricsResult]) -> list[Block]:
    """The figures of merit of one file, one column per channel (one channel: a value and
    a unit column): bias, earth rate removed, bias stability and peak-to-peak at the
    averaging time, drift angle, bias repeatability and temperature sensitivity over the
    hold stages, samples.  Rows no channel has are left out.

    Parameters
    ----------
    where : str
        The file the title names.
    results : mapping of str to thermocal.metrics.MetricsResult
        The figures per channel (:func:`thermocal.metrics.channel_metrics`).

    Returns
    -------
    list of TextTable
        One table.

    References
    ----------
    IEEE Std 952-1997 and IEEE Std 1431-2004 (bias, bias stability, drift).
    """
    many = len(results) > 1
    first = next(iter(results.values()))
    t = _Rows(
        f"{where} — {', '.join(results)}",
        ("figure", *(list(results) if many else ["value"]), *([] if many else ["unit"])),
        "right",
    )
    if many:  # each channel in its own unit: a row of units, no unit column
        t.add("unit", *[r.unit for r in results.values()])

    def row(
        label: str,
        get: Callable[[MetricsResult], float | None],
        digits: int = 4,
        unit: Callable[[MetricsResult], str] = lambda r: r.unit,
    ) -> None:
        values = [get(r) for r in results.values()]
        if all(v is None for v in values):
            return
        cells = [fmt(v, digits) for v in values]
        if not many:
            t.add(label, *cells, unit(first))
            return
        rate_unit = {unit(r) for r in results.values()} - {r.unit for r in results.values()}
        rate_unit.discard("")
        t.add(label + (f" [{', '.join(sorted(rate_unit))}]" if rate_unit else ""), *cells)

    def sens(r: MetricsResult) -> str:
        return r.temperature_sensitivity.unit if r.temperature_sensitivity else ""

    def angle(r: MetricsResult) -> str:
        return r.drift_angle_unit or ""

    row("bias", lambda r: r.bias, 6)
    row("  earth rate removed", lambda r: r.earth_rate_removed or None, 6)
    row(f"bias stability ({first.averaging_s:g} s)", lambda r: r.bias_stability)
    row(f"peak-to-peak ({first.averaging_s:g} s)", lambda r: r.peak_to_peak)
    row("drift angle, largest |θ|", lambda r: r.drift_angle_max, unit=angle)
    row("  reached at [s]", lambda r: r.drift_angle_max_time_s, unit=lambda r: "")
    row("drift angle (end)", lambda r: r.drift_angle, unit=angle)
    row("  bias b0 removed", lambda r: r.drift_reference.bias if r.drift_reference else None, 6)
    row(f"bias repeatability ({len(first.stages)} stages)", lambda r: r.bias_repeatability)
    s = "temperature_sensitivity"
    row(
        "temp. sensitivity, mean |ΔB/ΔT|",
        lambda r: getattr(r, s).mean_abs_adjacent if getattr(r, s) else None,
        unit=sens,
    )
    row(
        "temp. sensitivity, LS slope",
        lambda r: getattr(r, s).ls_slope if getattr(r, s) else None,
        unit=sens,
    )
    t.add("samples", *[str(r.n_samples) for r in results.values()], *([] if many else [""]))
    return [t.table(("left", *("right",) * len(results), *([] if many else ["left"])))]


def power_on_text(res: PowerOnMetrics) -> list[Block]:
    """Turn-on to turn-on figures: per channel a table of each run's bias and in-run bias
    stability, and the line of the bias repeatability (the sample standard deviation of
    the run biases) with its 68.3 % interval and the mean bias.

    Parameters
    ----------
    res : thermocal.metrics.PowerOnMetrics
        The figures of several power-ons (:func:`thermocal.metrics.power_on_metrics`).

    Returns
    -------
    list of str or TextTable

    References
    ----------
    IEEE Std 952-1997 (turn-on to turn-on bias repeatability).
    """
    out: list[Block] = []
    for name, rep in res.repeatability.items():
        t = _Rows(
            f"{name} — {len(rep.runs)} power-ons [{rep.unit}]",
            ("run", "bias", f"bias stability ({rep.runs[0].averaging_s:g} s)"),
            "right",
        )
        for f, r in zip(rep.files, rep.runs, strict=True):
            t.add(f, fmt(r.bias, 6), fmt(r.bias_stability))
        out.append(t.table())
        out.append(
            f"turn-on to turn-on bias repeatability: {fmt(rep.bias_repeatability)} "
            f"{rep.unit} (68.3 % interval {fmt(rep.bias_repeatability_low)} … "
            f"{fmt(rep.bias_repeatability_high)}); mean bias {fmt(rep.bias_mean, 6)} "
            f"{rep.unit}"
        )
    return out


__all__ = [
    "Block",
    "TextTable",
    "allan_channels_text",
    "allan_text",
    "family_text",
    "fmt",
    "imu_noise_text",
    "inspection_text",
    "metrics_text",
    "minimum_cell",
    "minimum_line",
    "power_on_text",
    "stretch_cell",
]
