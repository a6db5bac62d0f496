"""The package version, in a module of its own: what writes it into files (model files,
reports, generated C) imports it from here, not from the :mod:`thermocal` package, whose
lazy attributes reach the file layer (``thermocal.read_recording``)."""

from __future__ import annotations

__version__ = "0.1.0"
