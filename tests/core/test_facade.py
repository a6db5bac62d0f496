"""The public facade: ``thermocal.__all__`` is the curated API, every name in it resolves to
the object its defining module holds, is documented in ``docs/api.rst``, and ``import
thermocal`` stays light."""

from __future__ import annotations

import importlib
import re
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

import thermocal

API_RST = Path(__file__).resolve().parents[2] / "docs" / "api.rst"

SUBPACKAGES = ("export", "metrics", "models", "multipos", "simulate", "stability", "turntable")
"""The documented subpackages the facade names (written here, not read from the facade)."""

DEFINED_IN = {
    "Metadata": "thermocal.recording",
    "Recording": "thermocal.recording",
    "read_recording": "thermocal.readers.dispatch",
    "write_recording": "thermocal.writers",
    "ReadOptions": "thermocal.readers.options",
    "load_model": "thermocal.pipeline.model_file",
    "save_model": "thermocal.pipeline.model_file",
    "load_calibration": "thermocal.pipeline.model_file",
    "ParameterError": "thermocal.errors",
    "ThermocalInputError": "thermocal.errors",
}


def test_all_is_the_curated_api() -> None:
    assert set(thermocal.__all__) == {*DEFINED_IN, *SUBPACKAGES, "__version__"}
    assert len(thermocal.__all__) == len(set(thermocal.__all__))
    assert dir(thermocal) == sorted(thermocal.__all__)


def test_every_name_resolves_to_its_defining_object() -> None:
    for name, module in DEFINED_IN.items():
        assert getattr(thermocal, name) is getattr(importlib.import_module(module), name), name
    for name in SUBPACKAGES:
        sub = getattr(thermocal, name)
        assert isinstance(sub, ModuleType) and sub.__name__ == f"thermocal.{name}", name
        assert sub.__doc__ and len(sub.__doc__.strip()) > 40, f"thermocal.{name} has no docstring"
    assert isinstance(thermocal.__version__, str)


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="load_recording"):
        thermocal.load_recording  # noqa: B018  (not public: read_recording is)


def test_every_public_name_is_in_the_api_reference() -> None:
    text = API_RST.read_text(encoding="utf-8")
    targets = set(re.findall(r"^\.\. auto\w+:: (thermocal[\w.]*)\s*$", text, re.MULTILINE))
    missing = [n for n in thermocal.__all__ if f"thermocal.{n}" not in targets]
    assert not missing, f"not in docs/api.rst: {missing}"


def test_import_and_the_light_names_load_no_heavy_library() -> None:
    code = (
        "import sys, thermocal\n"
        "thermocal.ParameterError, thermocal.ThermocalInputError, thermocal.metrics\n"
        "print(*[m for m in ('pandas', 'pyarrow', 'scipy', 'matplotlib') if m in sys.modules])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == []
