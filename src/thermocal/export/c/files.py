"""``thermocal export-c``: a model or calibration file to its C module on disk
(:mod:`thermocal.export.c`), with the checks the command makes first."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from thermocal.errors import ThermocalWarning, UnitWarning
from thermocal.export.c.calibration import export_c, fitted_sample_interval, generate_c_calibration
from thermocal.export.c.core import CExport
from thermocal.export.c.harness import FloatError, find_compiler, measure_float_error
from thermocal.export.checks import check_firmware_adequacy
from thermocal.identifiers import c_identifier


@dataclass(frozen=True)
class ExportCResult:
    """What :func:`export_c_file` wrote.  ``kind``: ``"model"`` (one model file),
    ``"calibration"`` (channels; ``channels`` holds ``(name, unit, family)``) or
    ``"triads"`` (``triads`` holds ``(name, unit, columns)``).  ``float_error``: the float
    build's worst-case error against double (a model with ``use_float`` and a compiler).

    Attributes
    ----------
    kind : str
        ``"model"``, ``"calibration"`` or ``"triads"``.
    export : CExport
        The generated module.
    files : tuple of Path
        The files written.
    channels : tuple of (str, str, str)
        ``(name, unit, family)`` of each channel of a calibration.
    triads : tuple of (str, str, tuple of str)
        ``(name, unit, columns)`` of each triad.
    float_error : FloatError or None
        The float build's worst-case error against double.
    """

    kind: str
    export: CExport
    files: tuple[Path, ...]
    channels: tuple[tuple[str, str, str], ...] = ()
    triads: tuple[tuple[str, str, tuple[str, ...]], ...] = ()
    float_error: FloatError | None = None

    def to_dict(self) -> dict[str, Any]:
        """The result as a JSON object (what the ``export-c`` command prints as JSON)."""
        ex, files = self.export, [str(p) for p in self.files]
        if self.kind == "triads":
            return {
                "family": "triads",
                "prefix": ex.prefix,
                "real": ex.real,
                "triads": {n: {"unit": u, "columns": list(c)} for n, u, c in self.triads},
                "files": files,
            }
        if self.kind == "calibration":
            return {
                "family": "calibration",
                "prefix": ex.prefix,
                "real": ex.real,
                "channels": {n: {"unit": u, "family": f} for n, u, f in self.channels},
                "temperature_unit": ex.temperature_unit,
                "files": files,
            }
        out: dict[str, Any] = {
            "family": ex.family,
            "prefix": ex.prefix,
            "real": ex.real,
            "unit": ex.unit,
            "model_unit": ex.model_unit,
            "temperature_unit": ex.temperature_unit,
            "files": files,
            "float_max_abs_error": None,
            "float_max_rel_error": None,
        }
        if self.float_error is not None:
            out["float_max_abs_error"] = self.float_error.max_abs
            out["float_max_rel_error"] = self.float_error.max_rel
            out["float_error_samples"] = self.float_error.n_samples
        return out


def _read_json(path: Path) -> object:
    """The file's JSON, or None when it is not JSON within the model files' bounds (the
    model loader then says why)."""
    from thermocal.errors import ModelFileError
    from thermocal.pipeline.model_filecheck import read_json

    try:
        return read_json(path)
    except ModelFileError:
        return None


def export_c_file(
    model_file: str | Path,
    output: str | Path,
    *,
    use_float: bool = False,
    name: str | None = None,
    sample_interval_s: float | None = None,
    unit: str | tuple[str, ...] | None = None,
) -> ExportCResult:
    """``thermocal export-c``: write the C99 header and source of a model or calibration
    file into the directory ``output`` (:class:`CExport`, written as a pair).

    ``name``: the C prefix (default: the file stem).  A calibration of channels gives one
    module for all (:func:`generate_c_calibration`; ``unit`` one unit or one per channel),
    one of triads its triad module; a model file its module (:func:`export_c`), its rate
    buffer sized for ``sample_interval_s`` [s] (default: the fitted data's, else 1 s with a
    warning for rate models) and in ``unit`` (default: the fitted data's, with a warning
    for older files and raw counts).  ``use_float``: ``float`` arithmetic, and for a model
    file the float build's worst-case error against double measured
    (:func:`measure_float_error`) when a C compiler is found (a warning otherwise).
    Data that did not support the fit are refused (:func:`check_firmware_adequacy`).

    Parameters
    ----------
    model_file : str or Path
        A model or calibration file (JSON).
    output : str or Path
        Output directory.
    use_float, name, sample_interval_s, unit
        As above; ``sample_interval_s`` in [s], defaults ``False``/``None``; ``unit`` one
        unit, or for a calibration a tuple of one per channel.

    Returns
    -------
    ExportCResult
        The module(s) generated, the paths written and the float error when measured.

    Raises
    ------
    ThermocalInputError
        When the file cannot be read, an output is an input, or the data did not support
        the fit.
    ModelFileError
        When a family has no C generator or a coefficient cannot be written.
    """
    from thermocal.models.calibration import is_calibration
    from thermocal.outputs import check_outputs

    path, out_dir = Path(model_file), Path(output)
    real = "float" if use_float else "double"
    check_outputs([], [path], dirs=[out_dir])  # the files themselves: when named
    if is_calibration(_read_json(path)):
        return _export_calibration(path, out_dir, name, real, sample_interval_s, unit)
    if isinstance(unit, tuple):  # a model file has one signal
        from thermocal import units

        unit = units.per_signal_unit(unit, [str(path)], "unit")[str(path)]
    from thermocal.adequacy import check_for_firmware
    from thermocal.pipeline.model_file import load_model_dict

    d = load_model_dict(path)
    check_for_firmware(d.get("adequacy"), str(path))
    if sample_interval_s is None:
        sample_interval_s = _default_sample_interval(d, path)
    if unit is None:
        _warn_unstated_unit(d, path)
    ex, paths = export_c(
        path, out_dir, prefix=name, real=real, sample_interval_s=sample_interval_s, unit=unit
    )
    err = None
    if use_float:
        if find_compiler() is None:
            warnings.warn(
                "no C compiler found: the float build's error was not measured",
                ThermocalWarning,
                stacklevel=2,
            )
        else:
            err = measure_float_error(
                d, prefix=ex.prefix, sample_interval_s=sample_interval_s, unit=unit
            )
            if not math.isfinite(err.max_abs):  # inf − inf or inf − x: the float build overflowed
                warnings.warn(
                    ThermocalWarning.naming(
                        f"{path}: the float build's output is not finite where double's is (a "
                        "result beyond FLT_MAX 3.4028235e+38 over the calibrated range): these "
                        "float functions are wrong; export without {use_float} (in double)",
                        "use_float",
                    ),
                    stacklevel=2,
                )
    return ExportCResult("model", ex, tuple(paths), float_error=err)


def _default_sample_interval(d: dict[str, Any], path: Path) -> float:
    """The fitted data's sample interval [s]; else 1 s, with a warning for a rate model."""
    fitted = fitted_sample_interval(d)
    if fitted is not None:
        return fitted
    if d.get("rate"):
        warnings.warn(
            UnitWarning.naming(
                f"{path}: the model file does not record its data's sample "
                "interval (an older file); the C rate buffer is sized for 1 s samples "
                "— give {sample_interval_s}, or sampling faster shortens the rate "
                "interval in the firmware",
                "sample_interval_s",
            ),
            stacklevel=3,
        )
    return 1.0


def _warn_unstated_unit(d: dict[str, Any], path: Path) -> None:
    """Without ``unit``: warn when the model file does not record its data's unit (the C
    then works in the model's) or when the data were raw counts converted by a scale
    factor."""
    sig = d.get("signal") or {}
    given = ((d.get("inputs") or {}).get("units") or {}).get(sig.get("name"))
    if not given:
        warnings.warn(
            UnitWarning.naming(
                f"{path}: the model file does not record the unit its data were "
                f"in (an older file); the C works in the model's unit {sig.get('unit')} "
                "(give {unit} for another)",
                "unit",
            ),
            stacklevel=3,
        )
    elif given == "counts" and sig.get("unit") != "counts":
        warnings.warn(
            UnitWarning.naming(
                f"{path}: the model was fitted on raw counts converted with a scale "
                f"factor; the C works in {sig.get('unit')} (convert the counts first, or "
                "give {unit})",
                "unit",
            ),
            stacklevel=3,
        )


def _export_calibration(
    path: Path,
    output: Path,
    name: str | None,
    real: str,
    sample_interval_s: float | None,
    unit: str | tuple[str, ...] | None,
) -> ExportCResult:
    """A calibration's C: one header and one source for every channel, each channel in
    its data's unit (``unit`` applies one unit to every channel, or one per channel); or
    the module of its triads."""
    from thermocal import units
    from thermocal.models.format import model_file_dict
    from thermocal.pipeline.model_file import load_calibration

    cal = load_calibration(path)
    check_firmware_adequacy(cal, path, None)
    prefix = name or c_identifier(path.stem)
    if cal.triads and not cal.channels:  # a turntable calibration over temperature
        from thermocal.export.c.triad import generate_c_triads

        ex = generate_c_triads(cal.triads, prefix=prefix, real=real)
        paths = ex.write(output, inputs=[path])
        triads = tuple((t.name, t.unit, tuple(t.columns)) for t in cal.triads)
        return ExportCResult("triads", ex, tuple(paths), triads=triads)
    cal.require_channels("export-c")
    unit_of = units.per_signal_unit(unit, cal.names, "unit")
    channels = [(c.name, model_file_dict(c.model), unit_of[c.name] or c.unit) for c in cal.channels]
    ex = generate_c_calibration(
        channels, prefix=prefix, real=real, sample_interval_s=sample_interval_s
    )
    paths = ex.write(output, inputs=[path])
    rows = tuple(
        (c.name, u, c.model.family) for c, u in zip(cal.channels, ex.unit.split(","), strict=True)
    )
    return ExportCResult("calibration", ex, tuple(paths), channels=rows)
