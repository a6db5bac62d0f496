"""``thermocal noise FILE --psd PSD.csv``: every axis's PSD beside its Allan deviation
(:func:`thermocal.stability.psd.imu_psd`), the spectra written, the comparison printed."""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from thermocal._lazy import LazyModule
from thermocal.cli.common import show
from thermocal.errors import ThermocalInputError

if TYPE_CHECKING:
    import thermocal.report.noise_text as _text
    import thermocal.stability.psd as _psd
    import thermocal.writers as _writers
    from thermocal.recording import Recording
    from thermocal.stability.noise_model import AxisNoise
else:
    _psd = LazyModule("thermocal.stability.psd")
    _writers = LazyModule("thermocal.writers")
    _text = LazyModule("thermocal.report.noise_text")


def check(path: Path, file: Path, output: Path) -> None:
    """Refuse a ``--psd`` file over the input, the other output or a directory."""
    _writers.check_not_input(path, [file])
    if path.resolve() == output.resolve():
        raise ThermocalInputError(f"--psd {path}: the same file as -o; give another name")
    if path.is_dir():
        raise ThermocalInputError(f"--psd {path}: is a directory, expected a file name")


def write(rec: Recording, axes: Sequence[AxisNoise], path: Path) -> None:
    """The spectra to ``path`` (frequency_hz, then one ASD column per axis), atomically;
    the comparison printed."""
    import numpy as np

    res = _psd.imu_psd(rec, axes)
    f = res[0].freq_hz
    head = ["frequency_hz"] + [f"asd {p.name} [{p.unit}/sqrt(Hz)]" for p in res]
    table = np.column_stack([f] + [p.asd for p in res])
    with _writers.atomic_write(path, "w") as fh:
        csv.writer(fh, lineterminator="\n").writerow(head)
        np.savetxt(fh, table, delimiter=",", fmt="%.9g")
    show(_text.psd_text(res))
    show([f"PSD (Welch, one-sided) written to {path}"])
