"""The model file's content as a dict: its format tag and version, the canonical JSON and
its SHA-256 checksum (:func:`checksum`), the header check (:func:`check_model_header`) and
the dict of a fitted model (:func:`model_content`; with its checksum
:func:`model_file_dict`) and the fitted model rebuilt from one (:func:`restore_model`).  No
file is read or written here: the files are :mod:`thermocal.pipeline.model_file`'s.

A model file is a self-describing, versioned JSON object::

    {
      "format": "thermocal-model", "format_version": 3,
      "family": "poly", "thermocal_version": "0.1.0",
      "created_utc": "...",
      "signal": {"name": "gyro", "unit": "deg/h", "target": "bias"},
      "temperatures": ["T1", "T2", "T3", "T4"], "temperature_unit": "degC",
      "rate": {"method": "backward", "interval_s": 60.0},
      "params": {...constructor arguments...},
      "state": {...learned values, family specific...},
      "coefficients": [{"name": "T1", "value": ..., "stderr": ...}, ...],
      "range": {"temperature_c": {"T1": [lo, hi], ...}, "temperature_unit": "degC",
                "rate_c_per_min": {"T1": [lo, hi], ...}},
      "fit": {"rms_residual": ..., "condition_number": ..., "n_samples": ..., ...},
      "data": [{"file": "run1.csv", "sha256": "..."}],
      "inputs": {"time_unit": "ms", "units": {"gyro": "deg/s", "T1": "counts"},
                 "unit_sources": {"<time>": "metadata", "gyro": "option", ...},
                 "temperature_conversion": {"T1": [0.0625, -50.0, "int16"]},
                 "temperature_unit": "degC", "known_input": {...},
                 "temperature_rate": {...}, "scale_factor": {...}},
      "checksum": "sha256 of the canonical JSON of everything above"
    }

``signal.unit`` is the canonical unit the maths use ([°/h] or [mg]); ``inputs`` (format
version 2, completed in 3) is how the fitted data were written: the time unit, each
column's unit as given (e.g. ``deg/s``), raw-count temperature conversions, the known
input removed and the Ṫ definition.  ``temperature_unit`` is ``counts`` for a model fitted
on raw-count temperatures without a conversion: its ranges (``range.temperature_c``) and
coefficients are then in counts, and applying it needs raw-count data.  compensate,
validate, report and export-c use ``inputs`` where the command line and the data file are
silent (:meth:`TemperatureModel.input_units`).  Older files load; what they did not
record is unknown and falls to the resolver's stated default.

Loading checks the format tag, the version (a newer version is refused with a
clear error), the family (must be registered) and the checksum (a corrupted or
hand-edited file is refused).  The checksum guards against accidents (truncation, a
hand edit, a bit flip), not against tampering: anyone can recompute it.  So the content
is checked too, before anything uses it: the reader's bounds (:mod:`thermocal.models.
filecheck`: 64 MiB, nesting depth 32, finite numbers only, integers within ±2⁵³) and each
section's types and shapes (:func:`thermocal.models.schema.verify_model_dict`; triads:
:func:`thermocal.turntable.thermal.check_triad_dict`), every error naming the key path.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import math
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from thermocal.errors import (
    DesignError,
    ModelFileError,
)
from thermocal.models.results import FitStats
from thermocal.units import (
    LEGACY_TEMPERATURE_UNIT,
    normalize_signal_unit,
    normalize_temperature_unit,
)

if TYPE_CHECKING:
    from thermocal.models.base import TemperatureModel

M = TypeVar("M", bound="TemperatureModel")

MODEL_FORMAT = "thermocal-model"
MODEL_FORMAT_VERSION = 3


# --- file I/O ------------------------------------------------------------------------------


def _jsonify(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonify(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonify(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonify(obj.tolist())
    if isinstance(obj, np.generic):
        return _jsonify(obj.item())
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def _canonical(d: dict[str, Any]) -> bytes:
    return json.dumps(
        {k: v for k, v in d.items() if k != "checksum"},
        sort_keys=True,
        separators=(",", ":"),
        ensure_ascii=True,
        allow_nan=False,
    ).encode("ascii")


def checksum(d: dict[str, Any]) -> str:
    """SHA-256 of the canonical JSON of a model dict (``checksum`` key excluded).

    Parameters
    ----------
    d : dict
        A model (or calibration) file's content.

    Returns
    -------
    str
        64 hexadecimal digits.

    References
    ----------
    - FIPS PUB 180-4 (2015), Secure Hash Standard.
    """
    return hashlib.sha256(_canonical(d)).hexdigest()


def check_model_header(d: Any) -> None:
    """Refuse foreign, newer or unknown model dicts with a clear :class:`ModelFileError`.

    Parameters
    ----------
    d : object
        A parsed JSON document.

    Raises
    ------
    thermocal.errors.ModelFileError
        Not a thermocal model, a newer format version, or a missing section.
    """
    if not isinstance(d, dict) or d.get("format") != MODEL_FORMAT:
        raise ModelFileError("not a thermocal model file (missing 'format': 'thermocal-model')")
    ver = d.get("format_version")
    if not isinstance(ver, int):
        raise ModelFileError("model file has no integer format_version")
    if ver > MODEL_FORMAT_VERSION:
        raise ModelFileError(
            f"model file format version {ver} is newer than this thermocal supports "
            f"({MODEL_FORMAT_VERSION}); upgrade thermocal"
        )
    for key in ("family", "params", "state", "temperatures", "range", "fit"):
        if key not in d:
            raise ModelFileError(f"model file is missing the {key!r} section")


def _nonfinite_fields(obj: Any, path: str = "") -> list[str]:
    """Dotted paths of the NaN/inf floats inside a JSON-like structure."""
    if isinstance(obj, dict):
        return [p for k, v in obj.items() for p in _nonfinite_fields(v, f"{path}.{k}")]
    if isinstance(obj, (list, tuple)):
        return [p for i, v in enumerate(obj) for p in _nonfinite_fields(v, f"{path}[{i}]")]
    if isinstance(obj, float) and not math.isfinite(obj):
        return [path.lstrip(".")]
    return []


def model_file_dict(model: TemperatureModel) -> dict[str, Any]:
    """The model file's dict (:meth:`TemperatureModel.to_dict` with its checksum); a
    non-finite number anywhere is refused with :class:`DesignError` naming the field.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.

    Returns
    -------
    dict
        The content with its ``checksum``.

    Raises
    ------
    thermocal.errors.DesignError
        A non-finite number in the content.
    """
    d = model.to_dict()
    bad = _nonfinite_fields(d)
    if bad:
        raise DesignError(
            f"the fitted model holds non-finite numbers ({', '.join(bad[:5])}): the data do "
            "not determine it (too few samples or a degenerate design); nothing written"
        )
    d["checksum"] = checksum(d)
    return d


def model_content(model: TemperatureModel) -> dict[str, Any]:
    """The model file's content of a fitted model, without its checksum
    (:meth:`TemperatureModel.to_dict <thermocal.models.base.TemperatureModel.to_dict>`).

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.

    Returns
    -------
    dict
        JSON-ready content in the layout of this module's docstring.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        The model is not fitted.
    """
    from thermocal._version import __version__

    model.check_fitted()
    params = _jsonify(model.get_params())
    state = _jsonify(model._state())
    d: dict[str, Any] = {
        "format": MODEL_FORMAT,
        "format_version": MODEL_FORMAT_VERSION,
        "family": model.family,
        "thermocal_version": __version__,
        "created_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "signal": {"name": model.signal_name, "unit": model.signal_unit, "target": model.target},
        "temperatures": list(model.temp_names_),
        "temperature_unit": model.temperature_unit,
        "rate": (
            {
                "method": params.get("rate_method", "backward"),
                "interval_s": params.get("rate_interval_s", 60.0),
            }
            if model.uses_rate
            else None
        ),
        "params": params,
        "state": state,
        "coefficients": [c.to_dict() for c in model.coefficients()],
        "range": {
            "temperature_c": {
                n: [float(a), float(b)]
                for n, (a, b) in zip(model.temp_names_, model.temp_range_, strict=True)
            },
            "rate_c_per_min": (
                {
                    n: [float(a), float(b)]
                    for n, (a, b) in zip(model.temp_names_, model.rate_range_, strict=True)
                }
                if model.rate_range_ is not None
                else None
            ),
        },
        "fit": _jsonify(model.stats_.to_dict()),
        "data": _jsonify(model.data_),
        "inputs": _jsonify(_inputs_record(model, params, bool(state.get("uses_rate", True)))),
    }
    if model.adequacy_ is not None:
        d["adequacy"] = _jsonify(model.adequacy_)
    d["range"]["temperature_unit"] = model.temperature_unit
    return d


def _inputs_record(
    model: TemperatureModel, params: dict[str, Any], rate_used: bool
) -> dict[str, Any]:
    """The model file's ``inputs``: what the caller recorded
    (:func:`~thermocal.models.rundata.model_inputs`) with the temperature unit of the model
    and the Ṫ definition of rate models."""
    out = dict(getattr(model, "inputs_", {}) or {})
    out["temperature_unit"] = model.temperature_unit
    if model.uses_rate and rate_used:
        tu = model.temperature_unit
        method = params.get("rate_method", "backward")
        interval = params.get("rate_interval_s", 60.0)
        out["temperature_rate"] = {
            "method": method,
            "interval_s": interval,
            "unit": f"{tu}/min",
            "definition": (
                f"Ṫ = ΔT/Δt × 60 [{tu}/min] of the raw temperatures over {interval} s "
                f"({method} difference), within a contiguous (gap-free) segment"
            ),
        }
    return out


def restore_model(cls: type[M], d: dict[str, Any]) -> M:
    """A fitted model of family ``cls`` rebuilt from a model file's content
    (:meth:`TemperatureModel.from_dict <thermocal.models.base.TemperatureModel.from_dict>`).

    Parameters
    ----------
    cls : type
        The family's class.
    d : dict
        A model file's content.

    Returns
    -------
    TemperatureModel
        The fitted model.

    Raises
    ------
    thermocal.errors.ModelFileError
        Wrong format tag, a newer format version, or a dict of another family.
    """
    check_model_header(d)
    if not cls.family or str(d["family"]) != cls.family:
        raise ModelFileError(
            f"a model of family {d['family']!r} is not a {cls.family or cls.__name__!r} "
            "model (thermocal.models.registry.model_from_dict reads any family)"
        )
    model = cls(**d.get("params", {}))
    model._set_state(d["state"])
    model.temp_names_ = tuple(d["temperatures"])
    tr = d["range"]["temperature_c"]
    model.temp_range_ = np.array([tr[n] for n in model.temp_names_], dtype=np.float64)
    rr = d["range"].get("rate_c_per_min")
    model.rate_range_ = (
        np.array([rr[n] for n in model.temp_names_], dtype=np.float64) if rr else None
    )
    fit = dict(d["fit"])
    known = {
        "n_samples",
        "n_coefficients",
        "rms_residual",
        "condition_number",
        "r_squared",
        "dof",
    }
    model.stats_ = FitStats(
        n_samples=int(fit.get("n_samples", 0)),
        n_coefficients=int(fit.get("n_coefficients", 0)),
        rms_residual=float(fit.get("rms_residual", float("nan"))),
        condition_number=fit.get("condition_number"),
        r_squared=fit.get("r_squared"),
        dof=fit.get("dof"),
        extra={k: v for k, v in fit.items() if k not in known},
    )
    model.data_ = list(d.get("data", []))
    model.inputs_ = dict(d.get("inputs") or {})  # format version 1 files: unknown
    adequacy = d.get("adequacy")
    model.adequacy_ = dict(adequacy) if isinstance(adequacy, dict) else None
    sig = d.get("signal") or {}
    model.signal_name = sig.get("name", "signal")
    model.signal_unit = normalize_signal_unit(str(sig["unit"]))  # required by the schema
    model.target = sig.get("target", "bias")
    tu = d.get("temperature_unit")
    # files before format version 3 were always fitted in °C (and say so)
    model.temperature_unit = normalize_temperature_unit(str(tu or LEGACY_TEMPERATURE_UNIT))
    return model
