"""Model and calibration files: the file edge of :mod:`thermocal.models`, in the workflow layer.

The maths modules (:mod:`thermocal.models.base`, the families, :mod:`thermocal.models.
calibration`) build and check plain dicts (:func:`~thermocal.models.format.model_file_dict`,
:func:`~thermocal.models.schema.verify_model_dict`, :meth:`Calibration.to_dict`,
:func:`~thermocal.models.calibration.calibration_from_dict`) and import no I/O; reading and
writing the files (atomically, :func:`thermocal.writers.write_json`) happens here.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from thermocal.errors import ModelFileError, ThermocalInputError
from thermocal.models import registry
from thermocal.models.base import TemperatureModel
from thermocal.models.calibration import (
    Calibration,
    Channel,
    calibration_from_dict,
    guess_role,
    is_calibration,
)
from thermocal.models.format import MODEL_FORMAT, model_file_dict
from thermocal.models.schema import verify_model_dict
from thermocal.pipeline.model_filecheck import read_json
from thermocal.writers import write_json


def file_sha256(path: str | Path, chunk: int = 1 << 20) -> str:
    """SHA-256 of a data file (provenance in model files).

    Parameters
    ----------
    path : str or Path
        A data file, a station's recording folder (its closed parts hashed in order) or
        another folder read as one recording (a ROS 2 bag: its files, by name).
    chunk : int, optional
        Bytes read at a time [B] (default 1 MiB).

    Returns
    -------
    str
        The hexadecimal digest (64 characters).

    References
    ----------
    - FIPS PUB 180-4, Secure Hash Standard (SHS), NIST, 2015.
    """
    from thermocal.readers.common import sha256_of
    from thermocal.readers.station import is_station_path, station_files

    p = Path(path)
    if p.is_file():  # a plain file: its digest taken once per process while it is unchanged
        digest = sha256_of(p)
        if digest is not None:
            return digest
    h = hashlib.sha256()
    # a station's recording folder (DIR or DIR/SENSOR): its closed parts, in order; another
    # folder a format reads (a ROS 2 bag): its files by name
    files = [p] if not p.is_dir() else sorted(f for f in p.iterdir() if f.is_file())
    for f in station_files(p) if is_station_path(p) else files:
        with open(f, "rb") as fh:
            while block := fh.read(chunk):
                h.update(block)
    return h.hexdigest()


def save_model(model: TemperatureModel, path: str | Path) -> dict[str, Any]:
    """Write a fitted model as JSON (atomically), with its checksum; returns the dict.

    A model holding a non-finite number (NaN or infinity in a coefficient, range or
    statistic) is refused with :class:`DesignError` naming the field: JSON cannot hold it
    and firmware must never load it.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.
    path : str or Path
        The JSON file to write.

    Returns
    -------
    dict
        The model file's content as written.

    Raises
    ------
    DesignError
        When the model holds a non-finite number.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.poly import PolyModel
    >>> t = np.arange(0.0, 3600.0, 10.0)
    >>> temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / 3600.0)
    >>> run = RunData(t, temp[:, None], 0.5 + 0.02 * temp, ("T1",))
    >>> model = PolyModel(order=1).fit([run])
    >>> with tempfile.TemporaryDirectory() as d:
    ...     written = save_model(model, Path(d) / "model.json")
    ...     back = load_model(Path(d) / "model.json")
    >>> written["family"], [(c.name, round(c.value, 4)) for c in back.coefficients()]
    ('poly', [('const', 0.5), ('T1', 0.02)])
    """
    d = model_file_dict(model)
    write_json(path, d)
    return d


def load_model_dict(path: str | Path) -> dict[str, Any]:
    """Read and verify a model file (format, version, checksum) without building it.

    Parameters
    ----------
    path : str or Path
        The model file (JSON).

    Returns
    -------
    dict
        The verified model dict.

    Raises
    ------
    ModelFileError
        When the file is not JSON, not a model file, of an unknown version, or its
        checksum does not match.
    """
    p = Path(path)
    d = read_json(p, "model file")
    return verify_model_dict(d, str(p))


def load_model(path: str | Path) -> TemperatureModel:
    """Load and verify a model file; returns the fitted model.

    Parameters
    ----------
    path : str or Path
        The model file (JSON) written by :func:`save_model`.

    Returns
    -------
    TemperatureModel
        The fitted model of its family.

    Raises
    ------
    ModelFileError
        When the file cannot be verified or is malformed (the message names ``path``).
    """
    return model_from_dict(load_model_dict(path), path)


def model_from_dict(d: dict[str, Any], path: str | Path) -> TemperatureModel:
    """The fitted model of a verified model dict (:func:`verify_model_dict`).

    Parameters
    ----------
    d : dict
        A verified model dict.
    path : str or Path
        The file it came from, named in errors.

    Returns
    -------
    TemperatureModel
        The fitted model.

    Raises
    ------
    ModelFileError
        When the family is unknown or a field is malformed.
    """
    try:
        return registry.model_from_dict(d)
    except ModelFileError as exc:
        raise ModelFileError(f"{path}: {exc}") from None
    except (KeyError, TypeError, ValueError) as exc:
        raise ModelFileError(
            f"{path}: malformed model file ({type(exc).__name__}: {exc})"
        ) from None


def save_calibration(cal: Calibration, path: str | Path) -> dict[str, Any]:
    """Write a calibration file (atomically); returns its dict.  The file's own reader
    (:func:`~thermocal.models.calibration.calibration_from_dict`) judges it first: a
    calibration that reader would refuse is refused here and not written.

    Parameters
    ----------
    cal : Calibration
        Channels and triads to write.
    path : str or Path
        The JSON file to write.

    Returns
    -------
    dict
        The calibration file's content as written.

    Raises
    ------
    ThermocalInputError
        When the calibration has no channel and no triad.
    DesignError
        When the file's own reader would refuse it.
    """
    import json

    from thermocal.errors import DesignError

    if not cal.channels and not cal.triads:
        raise ThermocalInputError("calibration: no channels to write")
    d = cal.to_dict()
    try:
        calibration_from_dict(json.loads(json.dumps(d)), str(path))
    except ThermocalInputError as exc:
        raise DesignError(f"{exc}; the calibration is not written") from None
    write_json(path, d)
    return d


def load_calibration(path: str | Path) -> Calibration:
    """A calibration file, or a single-model file as a calibration of one channel (named
    after the model's signal, in the unit its inputs record).

    Parameters
    ----------
    path : str or Path
        A calibration file or a model file (JSON).

    Returns
    -------
    Calibration
        Its channels and triads.

    Raises
    ------
    ModelFileError
        When the file is neither a model nor a calibration file, or fails verification.
    """
    p = Path(path)
    d = read_json(p, "model or calibration file")
    if is_calibration(d):
        return calibration_from_dict(d, str(p))
    if isinstance(d, dict) and d.get("format") == MODEL_FORMAT:
        model = model_from_dict(verify_model_dict(d, str(p)), p)
        sig = model.signal_name or "signal"
        unit = str((model.inputs_ or {}).get("units", {}).get(sig) or model.signal_unit)
        return Calibration([Channel(sig, sig, unit, model, guess_role(sig, unit))])
    raise ModelFileError(f"{p}: not a thermocal model or calibration file (missing 'format')")


__all__ = [
    "file_sha256",
    "load_calibration",
    "load_model",
    "load_model_dict",
    "save_calibration",
    "save_model",
]
