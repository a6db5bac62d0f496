"""``thermocal noise FILE --temps COL``: the noise per temperature bin
(:func:`thermocal.stability.noise_temperature.imu_noise_by_temperature`), the model at
``--at-temperature`` and the file it writes."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from thermocal._lazy import LazyModule
from thermocal.cli.common import jsonable, show, split_names, stdout
from thermocal.errors import ThermocalInputError
from thermocal.identifiers import one_line

if TYPE_CHECKING:
    import thermocal.report.noise_text as _text
    import thermocal.stability.noise_temperature as _nt
    import thermocal.writers as _writers
    from thermocal.recording import Recording
else:
    _nt = LazyModule("thermocal.stability.noise_temperature")
    _writers = LazyModule("thermocal.writers")
    _text = LazyModule("thermocal.report.noise_text")


def parse_bins(text: str | None) -> tuple[tuple[float, ...] | None, float]:
    """``--temp-bins``: one number is a width [°C], several are the edges [°C]."""
    if text is None:
        return None, 5.0
    parts = split_names(text) or []
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        vals = ()
    if not vals:
        raise ThermocalInputError(
            f"--temp-bins {one_line(repr(text))}: give a bin width in °C (5) or the edges "
            "(10,20,30,40)"
        )
    return (None, vals[0]) if len(vals) == 1 else (vals, 5.0)


def by_temperature(
    file: Path,
    rec: Recording,
    names: tuple[list[str], list[str]],
    temps: str,
    bins: str | None,
    opts: dict[str, Any],
    output: Path,
) -> None:
    """The noise per bin printed; the JSON, or the Kalibr file at ``--at-temperature``,
    written."""
    out_format, at_c = opts["out_format"], opts["temperature_c"]
    if out_format == "kalibr" and at_c is None:
        raise ThermocalInputError(
            "--format kalibr with --temps: give --at-temperature T (the estimator's "
            "temperature, interpolated between the bins) or --format json for every bin"
        )
    column = (split_names(temps) or [""])[0]
    edges, width = parse_bins(bins)
    res = _nt.imu_noise_by_temperature(
        rec, names[0], names[1], column, edges, width_c=width, confidence=opts["confidence"],
        where=str(file),
    )  # fmt: skip
    at = None
    if at_c is not None:
        at = _nt.noise_at_temperature(res, at_c, inflate=opts["inflate"])
    if out_format == "kalibr":
        assert at is not None
        text = _nt.at_temperature_yaml(at, res, file.name, opts["rostopic"])
    else:
        doc = {"source": file.name, "by_temperature": res.to_dict(),
               "at_temperature": None if at is None else at.to_dict()}  # fmt: skip
        text = json.dumps(jsonable(doc), allow_nan=False, indent=1)
    with _writers.atomic_write(output, "w") as fh:
        fh.write(text + ("" if text.endswith("\n") else "\n"))
    show(_text.noise_by_temperature_text(str(file), res, at))
    if opts.get("plot") is not None:
        from thermocal.report.noise_plots import plot_noise_by_temperature

        plot_noise_by_temperature(res, opts["plot"], title=f"{file.name}: noise per temperature")
        stdout.print(f"plot written to {opts['plot']}")
    stdout.print(f"{out_format} noise per temperature written to {output}")
