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


def test_correct_inverts_k2_in_the_samples_unit() -> None:
    """A triad in mg with K2 in mg/g², samples in m/s²: ``Triad.correct`` returns the ``a``
    of ``x = (I + E) a + b + K2 ⊙ (a/g)²`` written here in m/s² (g = 9.80665 m/s²)."""
    theta = np.array([36.0, -18.0, 7.2, 100.0, -50.0, 20.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    model = constant_triad("accel", 25.0, theta, np.eye(12), method="multipos")
    k2_mg = np.array([5.0, -4.0, 3.0])  # mg/g²
    tri = Triad("accel", ("ax", "ay", "az"), "mg", "", model, k2=k2_mg)
    ms2 = 9.80665e-3  # m/s² per mg
    arc = np.pi / 648000.0
    e = np.diag(theta[3:6] * 1e-6)
    # misalignments yx, zx, xy, zy, xz, yz at E[0,1], E[0,2], E[1,0], E[1,2], E[2,0], E[2,1]
    for (i, j), v in zip([(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)], theta[6:], strict=True):
        e[i, j] = v * arc
    rng = np.random.default_rng(5)
    a = rng.normal(0.0, 9.80665, (200, 3))
    x = a @ (np.eye(3) + e).T + theta[0:3] * ms2 + k2_mg * ms2 * (a / 9.80665) ** 2
    got = tri.correct(x, np.full(200, 25.0), ms2, "m/s^2")
    np.testing.assert_allclose(got, a, rtol=0, atol=1e-12)
