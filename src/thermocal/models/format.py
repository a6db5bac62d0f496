"""The model file's content as a dict: its format tag and version, the canonical JSON and
its SHA-256 checksum (:func:`checksum`), the header check (:func:`check_model_header`) and
the dict of a fitted model (:func:`model_file_dict`).  No file is read or written here: the
files are :mod:`thermocal.pipeline.model_file`'s.
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal.errors import (
    DesignError,
    ModelFileError,
)

if TYPE_CHECKING:
    from thermocal.models.base import TemperatureModel

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
