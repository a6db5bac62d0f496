"""A gyro triad's g-sensitivity in the calibration file (format version 3): written with its
σ and unit, read back equal, absent from older files (which still load), refused where it
cannot be what it says (a version-2 file, an accelerometer triad, a unit not the triad's per
g, a matrix not 3×3 of finite numbers)."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest

from thermocal.errors import ModelFileError
from thermocal.models.calibration import Calibration, Triad, calibration_from_dict
from thermocal.models.format import checksum
from thermocal.turntable.thermal import constant_triad

A = np.array([[0.01, -0.002, 0.03], [0.0, 0.004, -0.005], [0.02, 0.0, -0.001]])  # deg/s/g
S = np.full((3, 3), 1e-4)


def _cal(g_sens: bool) -> Calibration:
    theta = np.array([36.0, -18.0, 7.2, 100.0, -50.0, 20.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    acc = constant_triad("accel", 25.0, theta, np.eye(12), method="multipos")
    gyr = constant_triad("gyro", 25.0, theta, np.eye(12), method="multipos")
    return Calibration(
        [],
        [
            Triad("accel", ("ax", "ay", "az"), "g", "", acc),
            Triad("gyro", ("gx", "gy", "gz"), "deg/s", "", gyr,
                  g_sensitivity=A if g_sens else None, g_sensitivity_sigma=S if g_sens else None),
        ],
    )  # fmt: skip


def _resummed(d: dict[str, Any]) -> dict[str, Any]:
    d = json.loads(json.dumps(d))
    d.pop("checksum", None)
    d["checksum"] = checksum(d)
    return d


def test_written_with_its_unit_and_read_back() -> None:
    d = json.loads(json.dumps(_cal(True).to_dict()))
    assert d["format_version"] == 3
    g = d["triads"][1]
    assert g["g_sensitivity"] == A.tolist() and g["g_sensitivity_sigma"] == S.tolist()
    assert g["g_sensitivity_unit"] == "deg/s/g"
    assert "g_sensitivity" not in d["triads"][0]
    back = calibration_from_dict(d, "c.json").triads[1]
    assert back.g_sensitivity is not None and back.g_sensitivity_sigma is not None
    np.testing.assert_array_equal(back.g_sensitivity, A)
    np.testing.assert_array_equal(back.g_sensitivity_sigma, S)


def test_a_file_without_it_is_what_it_was() -> None:
    d = json.loads(json.dumps(_cal(False).to_dict()))
    assert d["format_version"] == 1
    assert not any(k.startswith("g_sensitivity") for t in d["triads"] for k in t)
    back = calibration_from_dict(d, "c.json")
    assert all(t.g_sensitivity is None and t.g_sensitivity_sigma is None for t in back.triads)


def _gyro(**kw: Any) -> Any:
    return lambda d: d["triads"][1].update(**kw)


def _on_accel(d: dict[str, Any]) -> None:
    d["triads"][0].update(
        g_sensitivity=A.tolist(), g_sensitivity_sigma=S.tolist(), g_sensitivity_unit="g/g"
    )


@pytest.mark.parametrize(
    ("change", "words"),
    [
        # an older thermocal would have dropped it without a word
        (lambda d: d.update(format_version=2), ("g_sensitivity", "format_version 3")),
        (_on_accel, ("gyro triad",)),
        (_gyro(g_sensitivity_unit="deg/h/g"), ("g_sensitivity_unit", "'deg/s/g'")),
        (_gyro(g_sensitivity_unit=None), ("g_sensitivity_unit",)),
        (_gyro(g_sensitivity=[[0.0, 0.0], [0.0, 0.0]]), ("g_sensitivity", "3×3")),
        (_gyro(g_sensitivity=[[0.0, 0.0, "1"], [0.0] * 3, [0.0] * 3]), ("3×3",)),
        (_gyro(g_sensitivity=[[0.0, 0.0, True], [0.0] * 3, [0.0] * 3]), ("3×3",)),
        (_gyro(g_sensitivity_sigma=[[-1.0, 0.0, 0.0], [0.0] * 3, [0.0] * 3]), ("non-negative",)),
        (lambda d: d["triads"][1].pop("g_sensitivity"), ("without g_sensitivity",)),
    ],
)
def test_a_doubtful_one_is_refused(change: Any, words: tuple[str, ...]) -> None:
    d = json.loads(json.dumps(_cal(True).to_dict()))
    change(d)
    with pytest.raises(ModelFileError) as err:
        calibration_from_dict(_resummed(d), "c.json")
    for w in words:
        assert w in str(err.value), (w, str(err.value))


def test_the_term_in_the_columns_units() -> None:
    """``A f`` of a triad in deg/s with the force in m/s² and the columns in rad/s:
    (f / 9.80665) A^T π/180, written here; zeros without a g-sensitivity."""
    tri = _cal(True).triads[1]
    f = np.array([[0.0, 0.0, 9.80665], [4.0, -3.0, 8.5], [-9.0, 1.0, 0.2]])
    want = (f / 9.80665) @ A.T * np.pi / 180.0
    np.testing.assert_allclose(tri.g_sensitivity_term(f, "m/s^2", "rad/s"), want, rtol=1e-12)
    np.testing.assert_allclose(tri.g_sensitivity_term(f * 1e3 / 9.80665, "mg", "deg/s"),
                               want * 180.0 / np.pi, rtol=1e-12)  # fmt: skip
    np.testing.assert_array_equal(_cal(False).triads[1].g_sensitivity_term(f, "g", "deg/s"), 0.0)
