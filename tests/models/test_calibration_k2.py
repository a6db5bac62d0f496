"""An accelerometer triad's K2 in the calibration file (format version 4): written with its
σ and unit, read back equal, absent from older files (which load as before), refused where it
cannot be what it says (a version-3 file, a gyro triad, a unit not the triad's per g², not
three finite numbers, a σ without K2)."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest

from thermocal.errors import ModelFileError
from thermocal.models.calibration import Calibration, Triad, calibration_from_dict
from thermocal.models.format import checksum
from thermocal.turntable.thermal import constant_triad

K2 = np.array([0.05, -0.04, 0.03])  # m/s² per g²
S = np.array([0.002, 0.003, 0.001])


def _cal(k2: bool) -> Calibration:
    theta = np.array([36.0, -18.0, 7.2, 100.0, -50.0, 20.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    acc = constant_triad("accel", 25.0, theta, np.eye(12), method="multipos")
    gyr = constant_triad("gyro", 25.0, theta, np.eye(12), method="multipos")
    return Calibration(
        [],
        [
            Triad("accel", ("ax", "ay", "az"), "m/s^2", "", acc,
                  k2=K2 if k2 else None, k2_sigma=S if k2 else None),
            Triad("gyro", ("gx", "gy", "gz"), "deg/s", "", gyr),
        ],
    )  # fmt: skip


def _resummed(d: dict[str, Any]) -> dict[str, Any]:
    d = json.loads(json.dumps(d))
    d.pop("checksum", None)
    d["checksum"] = checksum(d)
    return d


def test_written_with_its_unit_and_read_back() -> None:
    d = json.loads(json.dumps(_cal(True).to_dict()))
    assert d["format_version"] == 4
    a = d["triads"][0]
    assert a["k2"] == K2.tolist() and a["k2_sigma"] == S.tolist()
    assert a["k2_unit"] == "m/s^2/g^2"
    assert "k2" not in d["triads"][1]
    back = calibration_from_dict(d, "c.json").triads[0]
    assert back.k2 is not None and back.k2_sigma is not None
    np.testing.assert_array_equal(back.k2, K2)
    np.testing.assert_array_equal(back.k2_sigma, S)


def test_a_file_without_it_is_what_it_was() -> None:
    d = json.loads(json.dumps(_cal(False).to_dict()))
    assert d["format_version"] == 1
    assert not any(k.startswith("k2") for t in d["triads"] for k in t)
    back = calibration_from_dict(d, "c.json")
    assert all(t.k2 is None and t.k2_sigma is None for t in back.triads)


def _acc(**kw: Any) -> Any:
    return lambda d: d["triads"][0].update(**kw)


def _on_gyro(d: dict[str, Any]) -> None:
    d["triads"][1].update(k2=K2.tolist(), k2_sigma=S.tolist(), k2_unit="deg/s/g^2")


@pytest.mark.parametrize(
    ("change", "words"),
    [
        # an older thermocal would have left it out without a word
        (lambda d: d.update(format_version=3), ("k2", "format_version 4")),
        (_on_gyro, ("accelerometer triad", "not a gyro")),
        (_acc(k2_unit="mg/g^2"), ("k2_unit", "'m/s^2/g^2'")),
        (_acc(k2_unit=None), ("k2_unit",)),
        (_acc(k2=[0.0, 0.0]), ("k2", "three finite")),
        (_acc(k2=[0.0, 0.0, "1"]), ("three finite",)),
        (_acc(k2=[0.0, 0.0, True]), ("three finite",)),
        (_acc(k2_sigma=[-1.0, 0.0, 0.0]), ("non-negative",)),
        (lambda d: d["triads"][0].pop("k2"), ("without k2",)),
    ],
)
def test_a_doubtful_one_is_refused(change: Any, words: tuple[str, ...]) -> None:
    d = json.loads(json.dumps(_cal(True).to_dict()))
    change(d)
    with pytest.raises(ModelFileError) as err:
        calibration_from_dict(_resummed(d), "c.json")
    for w in words:
        assert w in str(err.value), (w, str(err.value))
