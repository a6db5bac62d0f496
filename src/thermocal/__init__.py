"""thermocal: test and calibrate inertial sensors.

Units and frames, declared once (STYLE rule 2):

* time [s]; temperatures [°C] (raw ADC ``counts`` accepted on input);
  temperature rate Ṫ [°C/min];
* gyro signals are reported in [°/h], accelerometer signals in [mg];
  angle random walk [°/√h], rate random walk [°/h/√h];
* local frame East-North-Up (ENU); earth rate Ω = 7.292115e-5 rad/s
  (:data:`thermocal.units.EARTH_RATE_RAD_S`);
* turntable frames as INTERFACE.md "Turntable geometry" (``mat_nb`` body→base).

See :mod:`thermocal.units` for the constants and conversions, and ``SPEC.md``
for the methods each module implements.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from thermocal._version import __version__

if TYPE_CHECKING:
    from thermocal.pipeline.model_file import load_calibration, load_model, save_model
    from thermocal.readers.dispatch import read_recording
    from thermocal.recording import Metadata, Recording
    from thermocal.writers import write_recording


def __getattr__(name: str) -> Any:
    """``read_recording``, ``write_recording`` and the model-file functions are imported on
    first use, so that the
    maths modules (``import thermocal.metrics`` …) do not load the file layer (pandas,
    pyarrow) with the package."""
    if name == "read_recording":
        from thermocal.readers import dispatch

        return dispatch.read_recording
    if name == "write_recording":
        from thermocal import writers

        return writers.write_recording
    if name in ("load_model", "save_model", "load_calibration"):
        from thermocal.pipeline import model_file

        return getattr(model_file, name)
    if name in ("Metadata", "Recording"):  # numpy: imported on first use too
        from thermocal import recording

        return getattr(recording, name)
    raise AttributeError(f"module 'thermocal' has no attribute {name!r}")


__all__ = [
    "Metadata",
    "Recording",
    "__version__",
    "load_calibration",
    "load_model",
    "read_recording",
    "save_model",
    "write_recording",
]
