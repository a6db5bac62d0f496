"""The maths imports no I/O (issue 15, STYLE.md): importing a maths module loads neither
the file layer (:mod:`thermocal.io`, :mod:`thermocal.compensate.files`, model files) nor pandas
or pyarrow.  Checked in a fresh interpreter, so nothing imported by other tests hides it."""

from __future__ import annotations

import subprocess
import sys

import pytest

MATHS = [
    "thermocal.units",
    "thermocal.recording",
    "thermocal.preprocess",
    "thermocal.metrics",
    "thermocal.stability.allan",
    "thermocal.profiles",
    "thermocal.validation",
    "thermocal.compensate.kernels",
    "thermocal.models",
    "thermocal.models.base",
    "thermocal.models.poly",
    "thermocal.models.piecewise",
    "thermocal.models.warmup",
    "thermocal.models.bank",
    "thermocal.models.calibration",
    "thermocal.models.terms",
    "thermocal.models.fitting",
    "thermocal.models.lstsq",
    "thermocal.models.poly_fit",
    "thermocal.models.poly_eval",
    "thermocal.export.c",
    "thermocal.report.analysis",
]
FILE_LAYER = [
    "pandas",
    "pyarrow",
    "thermocal.io",
    "thermocal.compensate.files",
    "thermocal.models.files",
]


@pytest.mark.parametrize("module", MATHS)
def test_maths_module_loads_no_file_layer(module: str) -> None:
    code = f"import sys, {module}\nprint(','.join(m for m in {FILE_LAYER!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"{module} loads {out.stdout.strip()}"


def test_the_file_functions_are_still_reachable_from_the_packages() -> None:
    import thermocal
    import thermocal.models

    assert callable(thermocal.read_recording) and callable(thermocal.write_recording)
    assert callable(thermocal.models.load_model) and callable(thermocal.models.save_model)
    with pytest.raises(AttributeError):
        _ = thermocal.models.no_such_thing  # type: ignore[attr-defined]
