"""thermocal: test and calibrate inertial sensors.

The public API is what this package exports (:data:`__all__`) and the documented
subpackages it names; everything else is private by convention, even without a leading
underscore, and may change without notice.

* **Recordings**: :class:`Recording` and :class:`Metadata`; :func:`read_recording` (with one
  :class:`ReadOptions` saying how a file is read) and :func:`write_recording`.
* **Model files**: :func:`load_model`, :func:`save_model`, :func:`load_calibration`.
* **Errors**: :class:`ThermocalInputError` (bad input a user can correct; the command line
  turns it into exit status 2 and one ``error:`` line) and :class:`ParameterError` (a bad
  value of one parameter of a library call, named as the signature spells it).
* **Subpackages**: :mod:`thermocal.metrics` (figures of merit), :mod:`thermocal.stability`
  (Allan deviation and its family, noise terms, noise model), :mod:`thermocal.models`
  (temperature-compensation model families), :mod:`thermocal.multipos` (multi-position
  calibration), :mod:`thermocal.turntable` (dual-axis turntable calibration),
  :mod:`thermocal.simulate` (sensors and chambers with a known truth) and
  :mod:`thermocal.export` (C code and flight-controller parameters).

The workflows :mod:`thermocal.station`, :mod:`thermocal.fleet` and :mod:`thermocal.report`
are documented too (see the API reference); the command line (:mod:`thermocal.cli`) is
not an API.

Units and frames, declared once for the whole package:

* time [s]; temperatures [°C] (raw ADC ``counts`` accepted on input);
  temperature rate Ṫ [°C/min];
* gyro signals are reported in [°/h], accelerometer signals in [mg];
  angle random walk [°/√h], rate random walk [°/h/√h];
* local frame East-North-Up (ENU); earth rate Ω = 7.292115e-5 rad/s
  (:data:`thermocal.units.EARTH_RATE_RAD_S`);
* turntable frames as :mod:`thermocal.turntable.kinematics` defines them (``mat_nb``
  takes body vectors to the base frame).

``import thermocal`` is light: every name above is imported on first use, so that
``import thermocal`` loads neither pandas, pyarrow, scipy nor matplotlib.

Examples
--------
>>> import thermocal
>>> "read_recording" in thermocal.__all__ and "stability" in thermocal.__all__
True
>>> thermocal.ParameterError("rate_hz", "{name} must be positive, got -1").parameter
'rate_hz'
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import TYPE_CHECKING, Any

from thermocal._version import __version__

if TYPE_CHECKING:
    from thermocal import export, metrics, models, multipos, simulate, stability, turntable
    from thermocal.errors import ParameterError, ThermocalInputError
    from thermocal.pipeline.model_file import load_calibration, load_model, save_model
    from thermocal.readers.dispatch import read_recording
    from thermocal.readers.options import ReadOptions
    from thermocal.recording import Metadata, Recording
    from thermocal.writers import write_recording

_RECORDING = ("Metadata", "Recording")
_MODEL_FILES = ("load_model", "save_model", "load_calibration")
_ERRORS = ("ParameterError", "ThermocalInputError")
_SUBPACKAGES = ("export", "metrics", "models", "multipos", "simulate", "stability", "turntable")
"""The documented subpackages, imported on first attribute access."""


def _home(name: str) -> ModuleType:
    """The module that defines the public ``name``, imported now (each import written out,
    so that ``scripts/import_graph.py`` sees the facade's arrows)."""
    if name in _RECORDING:
        from thermocal import recording

        return recording
    if name == "read_recording":
        from thermocal.readers import dispatch

        return dispatch
    if name == "ReadOptions":
        from thermocal.readers import options

        return options
    if name == "write_recording":
        from thermocal import writers

        return writers
    if name in _MODEL_FILES:
        from thermocal.pipeline import model_file

        return model_file
    if name in _ERRORS:
        from thermocal import errors

        return errors
    raise AttributeError(f"module 'thermocal' has no attribute {name!r}")


def __getattr__(name: str) -> Any:
    """Import a public name or subpackage on first use (``import thermocal`` stays light)."""
    if name in _SUBPACKAGES:
        return importlib.import_module(f"thermocal.{name}")
    return getattr(_home(name), name)


def __dir__() -> list[str]:
    """The public names, for completion in a notebook."""
    return sorted(__all__)


__all__ = [
    "Metadata",
    "ParameterError",
    "ReadOptions",
    "Recording",
    "ThermocalInputError",
    "__version__",
    "export",
    "load_calibration",
    "load_model",
    "metrics",
    "models",
    "multipos",
    "read_recording",
    "save_model",
    "simulate",
    "stability",
    "turntable",
    "write_recording",
]
