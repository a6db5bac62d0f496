"""The one registry of model families (STYLE rule 8, issue 27): every list of families is
derived from :data:`thermocal.models.registry.MODEL_REGISTRY`."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from thermocal.errors import ModelFileError
from thermocal.families import BUILTIN_FAMILIES, MODEL_FAMILIES, POLY
from thermocal.models import registry
from thermocal.models.bank import BankModel
from thermocal.models.format import checksum, model_file_dict
from thermocal.models.hyst import HystModel
from thermocal.models.piecewise import PiecewiseModel
from thermocal.models.poly import PolyModel
from thermocal.models.rundata import RunData
from thermocal.models.schema import verify_model_dict
from thermocal.models.warmup import WarmupModel


def _line_run() -> RunData:
    """y = 2 + 0.5·T [°/h] over 0…40 °C, exactly: a line every family fits."""
    t = np.arange(0.0, 4000.0, 1.0)
    temp = 20.0 + 20.0 * np.sin(2 * np.pi * t / 4000.0)
    return RunData(t, temp[:, None], 2.0 + 0.5 * temp, ("T1",), name="line")


def test_the_registry_lists_the_families_once_in_the_help_order() -> None:
    assert (
        tuple(registry.MODEL_REGISTRY)
        == MODEL_FAMILIES
        == ("poly", "piecewise", "warmup", "bank", "hyst")
    )
    assert {
        "poly": PolyModel,
        "piecewise": PiecewiseModel,
        "warmup": WarmupModel,
        "bank": BankModel,
        "hyst": HystModel,
    } == registry.MODEL_REGISTRY


def test_a_family_record_is_what_its_class_declares() -> None:
    poly = registry.family("poly")
    assert poly.model_class is PolyModel and poly.c_generator == "thermocal.export.c.poly"
    # the fit options are the constructor's parameters, in its order
    assert [o.name for o in poly.declaration.options] == [
        "terms", "order", "rate_interval_s", "rate_method", "select", "ridge", "rcond",
        "per_run_offset", "solver", "noise_threshold",
    ]  # fmt: skip
    assert poly.declaration is POLY is PolyModel.declaration
    assert [f.name for f in registry.families()] == list(MODEL_FAMILIES)
    with pytest.raises(
        ModelFileError, match="unknown model family 'nope'; known: bank, hyst, piecewise"
    ):
        registry.family("nope")


def test_names_and_classes_cannot_drift_apart() -> None:
    assert registry._registry(BUILTIN_FAMILIES) == registry.MODEL_REGISTRY
    # a declaration whose class carries another one stops the import
    moved = dataclasses.replace(POLY, model_class="thermocal.models.piecewise:PiecewiseModel")
    with pytest.raises(ImportError, match="does not carry the declaration of family 'poly'"):
        registry._registry((moved, *BUILTIN_FAMILIES[1:]))


def test_model_from_dict_dispatches_by_family_and_refuses_unknown_ones() -> None:
    model = registry.make_model("poly", order=1).fit([_line_run()])
    d = verify_model_dict(model_file_dict(model), "poly.json")
    back = registry.model_from_dict(d)
    assert isinstance(back, PolyModel)
    t = np.array([[0.0], [10.0], [40.0]])
    run = RunData(np.array([0.0, 60.0, 120.0]), t, np.zeros(3), ("T1",))
    np.testing.assert_allclose(back.predict(run), 2.0 + 0.5 * t[:, 0], atol=1e-9)
    # one family's class reads only its own files
    with pytest.raises(ModelFileError, match="'poly' is not a 'piecewise' model"):
        PiecewiseModel.from_dict(d)
    with pytest.raises(ModelFileError, match="unknown model family 'cubic'; known: bank,"):
        registry.model_from_dict({**d, "family": "cubic"})


def test_the_schema_calls_the_familys_state_check() -> None:
    model = registry.make_model("warmup", order=1, t0_order=0).fit([_line_run()])
    d = model_file_dict(model)
    d["params"]["sensor"] = 3  # one temperature input

    d["checksum"] = checksum(d)
    with pytest.raises(ModelFileError, match=r"params\.sensor: 3 is not one of the 1 temperature"):
        verify_model_dict(d, "w.json")
