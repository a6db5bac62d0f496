"""``thermocal noise FILE --from-datasheet``: the file of data-sheet figures parsed into
:func:`thermocal.stability.datasheet.datasheet_noise`, the Kalibr file or JSON written."""

from __future__ import annotations

import json
import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from thermocal._lazy import LazyModule
from thermocal.cli.common import jsonable, show, stdout
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.identifiers import one_line

if TYPE_CHECKING:
    import thermocal.report.noise_text as _text
    import thermocal.stability.datasheet as _ds
    import thermocal.writers as _writers
else:
    _ds = LazyModule("thermocal.stability.datasheet")
    _writers = LazyModule("thermocal.writers")
    _text = LazyModule("thermocal.report.noise_text")

_FIGURE = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*?)\s*")
_MAX_BYTES = 64 * 1024


def read_sheet(path: Path) -> tuple[dict[str, tuple[float, str]], float]:
    """The figures (value, unit) and the update rate [Hz] of a TOML file of data-sheet
    figures; one-line errors naming the file and the key."""
    if path.is_dir():
        raise ThermocalInputError(f"{path}: is a directory, expected a TOML file of figures")
    raw = path.read_bytes()[: _MAX_BYTES + 1]
    if len(raw) > _MAX_BYTES:
        raise ThermocalInputError(f"{path}: larger than 64 KiB, not a file of data-sheet figures")
    try:
        doc = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ThermocalInputError(
            f"{path}: not a TOML file of data-sheet figures ({one_line(str(exc))[:120]}); "
            'write one per line: gyro_noise_density = "0.014 deg/s/sqrt(Hz)"'
        ) from None
    rate = doc.pop("update_rate_hz", None)
    if isinstance(rate, bool) or not isinstance(rate, int | float):
        raise ThermocalInputError(
            f"{path}: no update_rate_hz (the IMU's output rate in Hz, a number: "
            "update_rate_hz = 200)"
        )
    figures: dict[str, tuple[float, str]] = {}
    for key, text in doc.items():
        m = _FIGURE.fullmatch(text) if isinstance(text, str) else None
        if m is None:
            raise ThermocalInputError(
                f"{path}: {one_line(str(key))} = {one_line(repr(text))[:60]}: give a value and "
                'its unit as a string, e.g. "0.014 deg/s/sqrt(Hz)"'
            )
        figures[str(key)] = (float(m[1]), m[2])
    return figures, float(rate)


def refuse_recording_options(given: Mapping[str, object]) -> None:
    """Refuse the options of a recording given with ``--from-datasheet``."""
    extra = [k for k, v in given.items() if v is not None]
    if extra:
        raise ThermocalInputError(
            f"--from-datasheet reads figures, not a recording: drop {', '.join(extra)}"
        )


def from_datasheet(
    path: Path, output: Path, out_format: str, *, inflate: float, rostopic: str
) -> None:
    """Read the figures, build the model, write ``output`` atomically, print the table."""
    _writers.check_not_input(output, [path])
    if output.is_dir():
        raise ThermocalInputError(f"{output}: is a directory, expected a file name")
    figures, rate = read_sheet(path)
    try:
        model = _ds.datasheet_noise(figures, rate, inflate=inflate, rostopic=rostopic)
    except ParameterError as exc:
        where = {"figures": "the figures", "update_rate_hz": "update_rate_hz"}
        if exc.parameter in ("inflate", "rostopic"):
            raise  # the command's own options, named by the command line
        raise ThermocalInputError(
            f"{path}: {exc.named(where.get(exc.parameter, exc.parameter))}"
        ) from None
    if out_format == "kalibr":
        text = _ds.datasheet_yaml(model, path.name)
    else:
        text = json.dumps(jsonable(model.to_dict(path.name)), allow_nan=False, indent=1)
    with _writers.atomic_write(output, "w") as fh:
        fh.write(text + ("" if text.endswith("\n") else "\n"))
    show(_text.datasheet_noise_text(str(path), model))
    stdout.print(f"{out_format} noise model written to {output} (from the data sheet's figures)")
