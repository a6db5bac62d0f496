"""The tutorials run as written: every ``console`` and ``python`` block of a tutorial page is
executed, in order, in a temporary folder that sees the repository's ``tests/`` as the root
does (outputs land there, never in the clone), and what it prints is compared, number by
number, with the ``text`` block that follows it on the page; the numbers are also checked
against the reference the page quotes: Stable32's printed tables (``tests/data/
stable32_phasedat``, from allantools' test data, LGPL-3.0) and imucal 2.6.0's calibration of
its own example session (``tests/data/imucal_ferraris``, MIT).
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from tutorial_pages import ROOT, TUTORIALS, _numbers, _run_in_scratch

STABLE32 = ROOT / "tests" / "data" / "stable32_phasedat"


def _stable32(name: str) -> np.ndarray:
    """Stable32's printed rows: AF, τ, terms, α, low, deviation, high."""
    lines = (STABLE32 / name).read_text(encoding="latin-1").splitlines()
    return np.array([[float(v) for v in ln.split()] for ln in lines if ln.strip() and ln[0] != "#"])


@pytest.fixture(scope="module")
def stability_page(tmp_path_factory: pytest.TempPathFactory) -> list[tuple[str, str]]:
    return _run_in_scratch(tmp_path_factory.mktemp("stability"), "stability-stable32.md")


@pytest.fixture(scope="module")
def multipos_page(tmp_path_factory: pytest.TempPathFactory) -> list[tuple[str, str]]:
    return _run_in_scratch(tmp_path_factory.mktemp("multipos"), "multipos-imucal.md")


def test_every_tutorial_is_executed_here() -> None:
    assert sorted(p.name for p in TUTORIALS.glob("*.md")) == [
        "chamber-log.md",  # tests/docs/test_tutorial_chamber_log.py
        "chamber-to-c.md",  # tests/docs/test_tutorials_a.py
        "fc-params.md",  # tests/docs/test_tutorials_b.py
        "firmware-learning.md",  # tests/docs/test_tutorial_firmware_learning.py
        "hysteresis.md",  # tests/docs/test_tutorial_hysteresis.py
        "multipos-imucal.md",
        "noise-for-estimator.md",  # tests/docs/test_tutorials_a.py
        "notebook-allan.md",  # tests/docs/test_tutorial_notebook_allan.py
        "notebook-multipos.md",  # tests/docs/test_tutorial_notebook_multipos.py
        "notebook-poly.md",  # tests/docs/test_tutorial_notebook_poly.py
        "notebook-px4.md",  # tests/docs/test_tutorial_notebook_px4.py
        "production-batch.md",  # tests/docs/test_tutorials_b.py
        "ratetable.md",  # tests/docs/test_tutorial_ratetable.py
        "ros-bags.md",  # tests/docs/test_tutorial_ros_bags.py
        "stability-stable32.md",
        "station.md",  # tests/docs/test_tutorial_station.py
        "tumble.md",  # tests/docs/test_tutorial_tumble.py
    ]


def test_stability_tutorial_prints_what_the_page_shows(
    stability_page: list[tuple[str, str]],
) -> None:
    assert len(stability_page) == 2
    for printed, shown in stability_page:
        assert _numbers(printed) == _numbers(shown)
        assert len(_numbers(printed)) >= 30


def test_stability_tutorial_numbers_are_stable32s(stability_page: list[tuple[str, str]]) -> None:
    """Values to Stable32's five printed digits, bounds to 2e-3 (its EDF rounding), terms and
    α exactly: the tolerances of tests/stability/test_stability_reference.py."""
    table = [_numbers(line) for line in stability_page[0][0].splitlines() if line.startswith("│")]
    got = np.array(table)  # τ, oadev, low, high, edf, α, terms
    ref = _stable32("phase_dat_oadev_octave.txt")
    np.testing.assert_array_equal(got[:, 0], ref[:, 1])
    np.testing.assert_allclose(got[:, 1], ref[:, 5], rtol=1e-4)
    np.testing.assert_allclose(got[:, 2], ref[:, 4], rtol=2e-3)
    np.testing.assert_allclose(got[:, 3], ref[:, 6], rtol=2e-3)
    np.testing.assert_array_equal(got[:, 5], ref[:, 3])
    np.testing.assert_array_equal(got[:, 6], ref[:, 2])
    # the Python block: oadev and mdev at τ = 1, 4, 16, 64 s against both of Stable32's tables
    rows = [_numbers(line) for line in stability_page[1][0].splitlines()]
    for k, name in enumerate(("oadev", "mdev")):
        ref = _stable32(f"phase_dat_{name}_octave.txt")
        ref = ref[np.isin(ref[:, 1], [1, 4, 16, 64])]
        mine = np.array(rows[4 * k : 4 * k + 4])  # τ, dev, low, high
        np.testing.assert_allclose(mine[:, 1], ref[:, 5], rtol=1e-4)
        np.testing.assert_allclose(mine[:, 2], ref[:, 4], rtol=2e-3)
        np.testing.assert_allclose(mine[:, 3], ref[:, 6], rtol=2e-3)


def test_multipos_tutorial_prints_what_the_page_shows(
    multipos_page: list[tuple[str, str]],
) -> None:
    assert len(multipos_page) == 4  # multipos; the time added, compensate, the faces
    printed, shown = multipos_page[0]
    assert _numbers(printed) == _numbers(shown)
    assert len(_numbers(printed)) >= 48  # 24 parameters, value and σ
    for printed, shown in multipos_page[1:]:
        assert [ln.strip() for ln in printed.strip().splitlines()] == [
            ln.strip() for ln in shown.strip().splitlines()
        ]


def test_multipos_tutorial_compensate_is_imucals_model(
    multipos_page: list[tuple[str, str]],
) -> None:
    """The compensated faces of the page: |a| of (K_a R_a)⁻¹ (f̄ − b) with imucal's K_a R_a
    and the bias the page prints, f̄ each face's raw mean; within 0.015 m/s² of the 9.81 the
    session was calibrated with, their rms the fit's gravity-magnitude residual."""
    printed = multipos_page[0][0]
    acc = _triad_rows(printed, "accel triad")
    bias = np.array([acc[f"bias {a}"][0] for a in "xyz"])
    data = ROOT / "tests" / "data" / "imucal_ferraris"
    raw = np.genfromtxt(data / "example_ferraris_session.csv", delimiter=",", names=True)
    f = np.column_stack([raw["acc_x"], raw["acc_y"], raw["acc_z"]])
    sections = json.loads((data / "example_ferraris_session_list.json").read_text())
    faces = re.findall(r"^(\w+): \|a\| ([\d.]+) -> ([\d.]+) m/s\^2$", multipos_page[3][0], re.M)
    assert [name for name, _, _ in faces] == ["x_p", "x_a", "y_p", "y_a", "z_p", "z_a"]
    for name, before, after in faces:
        mean = f[sections[name]["start"] : sections[name]["end"]].mean(axis=0)
        assert float(before) == pytest.approx(np.linalg.norm(mean), abs=6e-4)
        a = np.linalg.solve(IMUCAL_KA_RA, mean - bias)
        assert float(after) == pytest.approx(np.linalg.norm(a), abs=2e-4), name
        assert abs(float(after) - 9.81) < 0.015
    rms = math.sqrt(np.mean([(float(after) - 9.81) ** 2 for _, _, after in faces]))
    residual = re.search(r"gravity-magnitude residual rms [\d.]+ → ([\d.]+)", printed)
    assert residual is not None and rms == pytest.approx(float(residual[1]), abs=2e-4)


# imucal 2.6.0's FerrarisCalibration of the same session, K_g·R_g and K_a·R_a (computed in a
# scratch venv as tests/multipos/test_multipos_imucal.py's docstring says; imucal is no dependency)
IMUCAL_KG_RG = np.array([
    [1.0279030921108503, -0.00046689722733542574, -0.006590606955485163],
    [-0.00021830076271155843, 0.982423943314377, -0.0027347345695309115],
    [0.009697592565938506, 0.0076281835698891395, 0.9982342394732935],
])  # fmt: skip
IMUCAL_KA_RA = np.array([
    [0.9966083432390234, -0.014782310326065154, -0.007457416390046589],
    [0.008597647264494957, 1.002399044531187, 0.0018480118201669386],
    [0.01364307550082869, 0.0020504932882582476, 1.0233023499168432],
])  # fmt: skip
# thermocal's misalignment ab is the element (row, column) of I + E (turntable.model)
MISALIGNMENT_RC = {"yx": (0, 1), "zx": (0, 2), "xy": (1, 0), "zy": (1, 2), "xz": (2, 0),
                   "yz": (2, 1)}  # fmt: skip
ARCSEC = 180.0 / math.pi * 3600.0


def _triad_rows(printed: str, title: str) -> dict[str, tuple[float, float]]:
    """parameter → (value, σ) of one triad's table."""
    lines = printed.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.lstrip().startswith(title))
    rows: dict[str, tuple[float, float]] = {}
    for ln in lines[start + 4 :]:
        if not ln.startswith("│"):
            break
        name, value, sigma, _ = (c.strip() for c in ln.strip("│").split("│"))
        rows[name] = (float(value), float(sigma))
    return rows


def test_multipos_tutorial_numbers_are_imucals(multipos_page: list[tuple[str, str]]) -> None:
    """Accelerometer: scale factors and misalignments equal imucal's to the five digits
    printed; gyro scale factors within 1σ of imucal's (the page's claims)."""
    printed = multipos_page[0][0]
    acc = _triad_rows(printed, "accel triad")
    gyr = _triad_rows(printed, "gyro triad")
    for i, axis in enumerate("xyz"):
        ref_acc = (IMUCAL_KA_RA[i, i] - 1) * 1e6
        assert acc[f"scale factor {axis}"][0] == pytest.approx(ref_acc, rel=5e-5, abs=0.05)
        ref_gyr = (IMUCAL_KG_RG[i, i] - 1) * 1e6
        value, sigma = gyr[f"scale factor {axis}"]
        assert abs(value - ref_gyr) < sigma, axis
    for name, (r, c) in MISALIGNMENT_RC.items():
        ref = IMUCAL_KA_RA[r, c] * ARCSEC
        assert acc[f"misalignment {name}"][0] == pytest.approx(ref, rel=5e-5, abs=0.01)
