"""One C module for a whole calibration, and the file-level entry point
(:mod:`thermocal.export.c`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from thermocal.errors import ThermocalInputError
from thermocal.export.c.core import (
    CExport,
    _comment,
    generate_c,
)
from thermocal.identifiers import c_comment, c_identifier, c_names


def check_distinct_names(
    modules: Sequence[tuple[str, CExport]], top: Sequence[str], what: str
) -> None:
    """Refuse (:class:`ThermocalInputError`) modules of one file that declare the same C
    name: each ``(original name, module)`` declares the identifiers under its own prefix
    (:func:`thermocal.identifiers.c_names`), the file itself ``top``.  Distinct identifiers
    can still meet once suffixed (channels ``a`` and ``a_t0``: ``A_T0_ORDER``).

    Parameters
    ----------
    modules : sequence of (str, CExport)
        Each channel's (or triad's) original name and its generated module.
    top : sequence of str
        The C names the combined file itself declares.
    what : str
        What a module is (``"channel"``, ``"triad"``), for the message.

    Returns
    -------
    None

    Raises
    ------
    ThermocalInputError
        When two modules (or a module and the file) give the same C name.
    """
    seen = {n: f"the {what}s' common code" for n in top}
    for name, ex in modules:
        for n in sorted(c_names(ex.header + "\n" + ex.source, ex.prefix)):
            if n in seen and seen[n] != f"{what} {name!r}":
                raise ThermocalInputError(
                    f"{what} {name!r} and {seen[n]} both give the C name {n}; rename one of them"
                )
            seen[n] = f"{what} {name!r}"


def generate_c_calibration(
    channels: Sequence[tuple[str, dict[str, Any], str | None]],
    *,
    prefix: str = "thermocal_cal",
    real: str = "double",
    sample_interval_s: float | None = None,
) -> CExport:
    """One C99 header and source for a whole calibration.

    ``channels``: ``(name, model dict, unit)`` per channel (unit None: the channel's data
    unit as fitted, :func:`c_signal_unit`). Each channel is the same code as its own
    :func:`generate_c` module under the prefix ``<prefix>_<name>``; on top, one state
    struct holding every channel's, one ``<prefix>_init`` and one
    ``<prefix>_compensate(s, time_s, temps_c[<P>_N_TEMPS], raw[<P>_N_CHANNELS],
    out[<P>_N_CHANNELS])`` taking the union of the channels' temperature inputs (in the
    order of ``<P>_TEMPERATURE_NAMES``) and the N raw values, each in its channel's unit,
    and writing the N compensated values. No allocation; the per-channel functions stay
    callable (``<prefix>_<name>_compensate``). ``sample_interval_s`` sizes the Ṫ buffers
    (None: each channel's fitted interval, :func:`fitted_sample_interval`).

    Parameters
    ----------
    channels : sequence of (str, dict, str or None)
        Channel name, model dict and signal unit of the C functions per channel.
    prefix : str, optional
        Prefix of the C identifiers and files (default ``"thermocal_cal"``).
    real : {"double", "float"}, optional
        C real type (default ``"double"``).
    sample_interval_s : float or None, optional
        Expected sample interval [s]; default ``None``: each channel's fitted one.

    Returns
    -------
    CExport
        The combined header and source.

    Raises
    ------
    ThermocalInputError
        When there is no channel, a real type is unknown, or two channels give one C name.
    ModelFileError
        When a channel's family has no C generator.
    UnitError
        When a channel's unit does not fit its model.
    """
    if not channels:
        raise ThermocalInputError("a calibration with no channel has no C")
    p = c_identifier(prefix)
    P = p.upper()
    used: dict[str, str] = {}
    ident = {name: c_identifier(name, used, what="channel") for name, _md, _u in channels}
    mods, temps, tu = _channel_modules(channels, p, ident, real, sample_interval_s)
    top = [f"{p}_{s}" for s in ("init", "compensate", "state", "real")]
    top += [f"{P}_{s}" for s in ("N_CHANNELS", "N_TEMPS", "CAL_H")]
    check_distinct_names([(name, ex) for name, ex, _t in mods], top, "channel")
    cm = _CalModules(p=p, real=real, ident=ident, mods=mods, temps=temps, tu=tu)
    return CExport(
        prefix=p,
        real=real,
        header=_cal_header(cm),
        source=_cal_source(cm),
        family="calibration",
        n_temps=len(temps),
        unit=",".join(ex.unit for _n, ex, _t in mods),
        model_unit=",".join(ex.model_unit for _n, ex, _t in mods),
        temperature_unit=tu,
    )


def _channel_modules(
    channels: Sequence[tuple[str, dict[str, Any], str | None]],
    p: str,
    ident: dict[str, str],
    real: str,
    sample_interval_s: float | None,
) -> tuple[list[tuple[str, CExport, list[str]]], list[str], str]:
    """Every channel's own module ``(name, module, its temperatures)``, the union of the
    temperatures in first-seen order and their one unit (different units refused)."""
    mods: list[tuple[str, CExport, list[str]]] = []
    temps: list[str] = []
    for _name, md, _unit in channels:
        for t in md["temperatures"]:
            if t not in temps:
                temps.append(str(t))
    tus = set()
    for name, md, unit in channels:
        ex = generate_c(
            md,
            prefix=f"{p}_{ident[name]}",
            real=real,
            sample_interval_s=(
                sample_interval_s
                if sample_interval_s is not None
                else fitted_sample_interval(md) or 1.0
            ),
            unit=unit,
        )
        mods.append((name, ex, [str(t) for t in md["temperatures"]]))
        tus.add(ex.temperature_unit)
    if len(tus) > 1:
        raise ThermocalInputError(
            "the channels' models take temperatures in different units "
            f"({', '.join(sorted(tus))}); one calibration's C takes one kind"
        )
    return mods, temps, next(iter(tus))


@dataclass(frozen=True)
class _CalModules:
    """The channels' modules of one calibration and what its common code needs."""

    p: str
    real: str
    ident: dict[str, str]
    mods: list[tuple[str, CExport, list[str]]]
    temps: list[str]
    tu: str

    @property
    def P(self) -> str:
        return self.p.upper()

    @property
    def chan_list(self) -> str:
        return c_comment(
            ", ".join(f"{i}={name} [{ex.unit}]" for i, (name, ex, _t) in enumerate(self.mods))
        )

    @property
    def temp_list(self) -> str:
        return c_comment(", ".join(f"{i}={t}" for i, t in enumerate(self.temps)))


def _cal_header(cm: _CalModules) -> str:
    """The calibration's header: every channel's header, then the common declarations."""
    p, P, tu, real = cm.p, cm.P, cm.tu, cm.real
    chan_list, temp_list = cm.chan_list, cm.temp_list
    return "\n".join(
        [
            _comment(
                [
                    f"thermocal calibration of {len(cm.mods)} channels: {chan_list}",
                    f"temps_c[] order: {temp_list} [{tu}]",
                    "Each channel's own functions are below; the calibration's functions at the "
                    "end take every channel at once.",
                ]
            ),
            f"#ifndef {P}_CAL_H",
            f"#define {P}_CAL_H",
            "",
            *[ex.header for _n, ex, _t in cm.mods],
            f"typedef {real} {p}_real;",
            f"#define {P}_N_CHANNELS {len(cm.mods)}",
            f"#define {P}_N_TEMPS {len(cm.temps)}",
            f"/* channels: {chan_list} */",
            f"/* temperatures: {temp_list} */",
            "",
            "typedef struct {",
            *[f"    {ex.prefix}_state {cm.ident[name]};" for name, ex, _t in cm.mods],
            f"}} {p}_state;",
            "",
            "/* Power-on: forget every channel's state; sample_interval_s: nominal [s]. */",
            f"void {p}_init({p}_state *s, double sample_interval_s);",
            f"/* One sample of every channel: time_s [s], temps_c [{tu}] in the order above,",
            "   raw[i] in channel i's unit; out[i] = raw[i] - model value, same unit. */",
            f"void {p}_compensate({p}_state *s, double time_s, const {p}_real "
            f"temps_c[{P}_N_TEMPS], const {p}_real raw[{P}_N_CHANNELS], "
            f"{p}_real out[{P}_N_CHANNELS]);",
            "",
            f"#endif /* {P}_CAL_H */",
            "",
        ]
    )


def _cal_source(cm: _CalModules) -> str:
    """The calibration's source: every channel's source (without its own include), then
    ``<p>_init`` and ``<p>_compensate`` calling each channel's."""
    p, P = cm.p, cm.P
    bodies = []
    for _name, ex, _t in cm.mods:
        lines = [ln for ln in ex.source.split("\n") if ln != f'#include "{ex.prefix}.h"']
        bodies.append("\n".join(lines))
    calls = []
    for i, (name, ex, ts) in enumerate(cm.mods):
        cid = cm.ident[name]
        idx = ", ".join(f"temps_c[{cm.temps.index(t)}]" for t in ts)
        calls += [
            "    {",
            f"        const {p}_real t_{cid}[{len(ts)}] = {{{idx}}};",
            f"        out[{i}] = {ex.prefix}_compensate(&s->{cid}, time_s, t_{cid}, raw[{i}]);",
            "    }",
        ]
    return "\n".join(
        [
            _comment([f"thermocal calibration of {len(cm.mods)} channels: {cm.chan_list}"]),
            f'#include "{p}.h"',
            "",
            *bodies,
            f"void {p}_init({p}_state *s, double sample_interval_s)",
            "{",
            *[
                f"    {ex.prefix}_init(&s->{cm.ident[name]}, sample_interval_s);"
                for name, ex, _t in cm.mods
            ],
            "}",
            "",
            f"void {p}_compensate({p}_state *s, double time_s, const {p}_real "
            f"temps_c[{P}_N_TEMPS], const {p}_real raw[{P}_N_CHANNELS], "
            f"{p}_real out[{P}_N_CHANNELS])",
            "{",
            *calls,
            "}",
            "",
        ]
    )


def fitted_sample_interval(model: dict[str, Any]) -> float | None:
    """The sample interval [s] of the data a model was fitted on (model file
    ``inputs.sample_interval_s``), or None for files that do not record it.

    Parameters
    ----------
    model : dict
        A model dict.

    Returns
    -------
    float or None
        The interval [s], or ``None`` when absent or not positive.
    """
    v = (model.get("inputs") or {}).get("sample_interval_s")
    return float(v) if isinstance(v, int | float) and v > 0 else None


def export_c(
    model_path: str | Path,
    out_dir: str | Path,
    *,
    prefix: str | None = None,
    real: str = "double",
    sample_interval_s: float = 1.0,
    unit: str | None = None,
) -> tuple[CExport, list[Path]]:
    """Read and verify a model file, generate its C module and write it into ``out_dir``
    (``unit``: the functions' signal unit, :func:`c_signal_unit`).

    Parameters
    ----------
    model_path : str or Path
        The model file (JSON).
    out_dir : str or Path
        Output directory of ``<prefix>.h`` and ``<prefix>.c``.
    prefix : str or None, optional
        C prefix; default ``None``: the model file's stem made a C identifier.
    real : {"double", "float"}, optional
        C real type (default ``"double"``).
    sample_interval_s : float, optional
        Expected sample interval [s] (default 1.0), sizing the rate ring buffer.
    unit : str or None, optional
        Signal unit of the functions (default: the unit fitted on).

    Returns
    -------
    export : CExport
        The generated module.
    paths : list of Path
        Header and source written.

    Raises
    ------
    ModelFileError
        When the model file cannot be verified or its family has no C generator.
    ThermocalInputError
        When an output is the model file or cannot be written.
    """
    from thermocal.pipeline.model_file import load_model_dict

    d = load_model_dict(model_path)
    ex = generate_c(
        d,
        prefix=c_identifier(prefix or Path(model_path).stem),
        real=real,
        sample_interval_s=sample_interval_s,
        unit=unit,
    )
    return ex, ex.write(out_dir, inputs=[model_path])
