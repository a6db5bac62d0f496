"""Compensation with a triad calibration in chunks (issue 26, item 8): the file is streamed
through the per-sample correction ``(I + E(T))⁻¹ (x − b(T))`` chunk by chunk and written
incrementally, like the single channels, instead of read whole (1.9 GB at 10⁷ rows).

A simulated turntable-thermal campaign (six soaks and a held-out run at +10 °C, 23 761
rows) is calibrated with ``thermocal turntable``; the held-out run is compensated through
the CLI with small chunks and compared with the whole-file correction computed here from
the calibration file and the recording read whole."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import thermocal.pipeline.compensate as compensate_mod
import thermocal.readers.dispatch as io_mod
from thermocal.cli import main
from thermocal.pipeline.model_file import load_calibration
from thermocal.readers.dispatch import read_recording
from thermocal.turntable import thermal
from thermocal.turntable.simulate import simulate_turntable_thermal
from thermocal.writers import write_recording

G_COLS = ["gyro_x", "gyro_y", "gyro_z"]
A_COLS = ["accel_x", "accel_y", "accel_z"]
DEG_S_PER_DEG_H = 1.0 / 3600.0
M_S2_PER_MG = 9.80665e-3


@pytest.fixture(scope="module")
def campaign(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    d = tmp_path_factory.mktemp("triad_chunks")
    soaks, held = [], None
    for rec, truth in simulate_turntable_thermal(seed=7):
        f = d / f"{truth['label']}.parquet"
        write_recording(rec, f)
        if truth["held_out"]:
            held = f
        else:
            soaks.append(str(f))
    assert held is not None
    cal = d / "cal.json"
    assert main(["turntable", *soaks, "--temps", "T_imu", "--accel", ",".join(A_COLS),
                 "-o", str(cal), "--json"]) == 0  # fmt: skip
    return {"dir": d, "held": held, "cal": cal}


def _whole_file(cal: Path, held: Path) -> dict[str, np.ndarray]:
    """The whole-file correction: every row at once, bias unit → data unit by hand
    (gyro bias in °/h, data in °/s; accelerometer bias in mg, data in m/s²)."""
    rec = read_recording(held)
    temp = rec.column("T_imu")
    out: dict[str, np.ndarray] = {}
    for tri in load_calibration(cal).triads:
        cols = list(tri.columns)
        to_data = DEG_S_PER_DEG_H if tri.model.kind == "gyro" else M_S2_PER_MG
        x = np.column_stack([rec.column(c) for c in cols])
        xc = thermal.correct(tri.model, x, temp, to_data)
        out.update({f"{c}_comp": xc[:, k] for k, c in enumerate(cols)})
    return out


def _columns(path: Path) -> dict[str, np.ndarray]:
    if path.suffix == ".csv":
        df = pd.read_csv(path)
        return {str(c): df[c].to_numpy(dtype=float) for c in df.columns}
    tab = pq.read_table(path)
    return {c: tab.column(c).to_numpy() for c in tab.column_names}


@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
def test_chunked_triad_compensation_equals_the_whole_file(
    campaign: dict[str, Any],
    suffix: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    held, cal = campaign["held"], campaign["cal"]
    expected = _whole_file(cal, held)
    given = _columns(held)
    n = next(iter(given.values())).size
    chunk = 1000
    # the file is never read whole: the recording reader fails the test
    calls: list[int] = []
    real_correct = thermal.correct

    def counting(tri: Any, x: Any, temp: Any, to_data: float) -> np.ndarray:
        calls.append(len(x))
        return real_correct(tri, x, temp, to_data)

    def refuse(*_a: object, **_k: object) -> None:
        raise AssertionError("the triad path read the whole file")

    monkeypatch.setattr(compensate_mod, "read_recording", refuse)
    monkeypatch.setattr(io_mod, "read_recording", refuse)
    monkeypatch.setattr(thermal, "correct", counting)
    out = campaign["dir"] / f"comp_{chunk}{suffix}"
    capsys.readouterr()
    code = main(["compensate", str(cal), str(held), "-o", str(out), "--chunk-rows", str(chunk),
                 "--json"])  # fmt: skip
    res = capsys.readouterr()
    assert code == 0, res.err
    assert [t["triad"] for t in json.loads(res.out)["triads"]] == ["gyro", "accel"]
    # two triads per chunk, every chunk at most `chunk` rows
    assert len(calls) == 2 * math.ceil(n / chunk) and max(calls) == chunk
    got = _columns(out)
    for c, v in given.items():  # every input column kept as it was
        if suffix == ".parquet":
            np.testing.assert_array_equal(got[c], v, err_msg=c)
        else:  # CSV text: pandas < 2.2 writes some values with fewer digits (floor check)
            np.testing.assert_allclose(got[c], v, rtol=1e-12, atol=0.0, err_msg=c)
    for c, v in expected.items():
        np.testing.assert_allclose(got[c], v, rtol=1e-12, atol=0.0, err_msg=c)
        if suffix == ".parquet":
            np.testing.assert_array_equal(got[c], v, err_msg=c)  # bit for bit
    # the compensation does something: the corrected gyro differs from the raw one by the
    # bias (≈ 1e-3 °/s here)
    assert float(np.max(np.abs(got["gyro_x_comp"] - given["gyro_x"]))) > 1e-5


def test_chunk_size_does_not_change_the_triad_output(
    campaign: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    held, cal, d = campaign["held"], campaign["cal"], campaign["dir"]
    outs = []
    for chunk in (7, 100_000):
        out = d / f"cmp_{chunk}.parquet"
        assert main(["compensate", str(cal), str(held), "-o", str(out),
                     "--chunk-rows", str(chunk)]) == 0  # fmt: skip
        outs.append(pq.read_table(out))
    assert outs[0].equals(outs[1])
    assert outs[0].schema.metadata == outs[1].schema.metadata
