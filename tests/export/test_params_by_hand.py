"""Firmware parameters (:mod:`thermocal.export.params`): PX4's cubic, and the export of a fit
let through by one override only.  Each kills a mutant of
``benchmarks/mutation_check.py`` (``fw-*``)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from thermocal.errors import ThermocalInputError


def _channels(order: int) -> object:
    """Three gyro channels (°/h): a polynomial of ``order`` in T fitted to a quartic drift."""
    from thermocal.models.calibration import Calibration, Channel
    from thermocal.models.poly import PolyModel
    from thermocal.models.rundata import RunData

    temp = np.linspace(-10.0, 60.0, 400)
    u = (temp - 25.0) / 35.0
    chans = []
    for j, axis in enumerate("xyz"):
        y = 50.0 * u + 20.0 * u**3 + (j + 1) * 30.0 * u**4
        run = RunData(np.arange(temp.size, dtype=np.float64), temp.reshape(-1, 1), y,
                      ("temperature",), name=f"g{axis}", signal_unit="deg/h")  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = PolyModel(order=order, per_run_offset=False).fit([run])
        model.signal_name, model.signal_unit = axis, "deg/h"
        chans.append(Channel(f"g{axis}", axis, "deg/h", model,
                             {"kind": "gyro", "axis": axis, "instance": 0}))  # fmt: skip
    return Calibration(chans)


def test_px4_takes_a_cubic_not_a_quartic() -> None:
    """PX4's TC_G<n> holds X0…X3 (parameter reference: ``TC_G0_X3_0`` "Gyro rate offset
    temperature ^3 polynomial coefficient" is the highest): a quartic is refused."""
    from thermocal.export.params import export_params

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ok = export_params(_channels(3), "px4", device_id={"gyro": 1})  # type: ignore[arg-type]
        assert "TC_G0_X3_2" in ok.params and "TC_G0_X4_2" not in ok.params
        with pytest.raises(ThermocalInputError, match=r"T\^4"):
            export_params(_channels(4), "px4", device_id={"gyro": 1})  # type: ignore[arg-type]


def test_firmware_export_takes_only_the_override_of_the_failed_test() -> None:
    """A fit whose stillness failed and that was let through with --allow-narrow only (an
    override of another test) gives no firmware parameters."""
    from thermocal.adequacy import check_for_firmware

    record = {
        "tests": [
            {"name": "stillness", "verdict": "fail", "override": "--allow-motion",
             "message": "moving 40 % of the time"},
            {"name": "span", "verdict": "pass", "override": "--allow-narrow", "message": ""},
        ],
        "overrides": ["--allow-narrow"],
    }  # fmt: skip
    with pytest.raises(ThermocalInputError, match="stillness"):
        check_for_firmware(record, "cal.json")
    record["overrides"] = ["--allow-motion"]
    with pytest.warns(Warning, match="--allow-motion"):
        check_for_firmware(record, "cal.json")
