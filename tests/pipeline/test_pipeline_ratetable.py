"""The rate-table result read back from its JSON (thermocal.pipeline.ratetable.read_result):
the same object as the command computed, and a file that is not one refused."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal.errors import ThermocalInputError, UnitWarning
from thermocal.pipeline.ratetable import RateTableOptions, ratetable_files, read_result
from thermocal.ratetable.simulate import simulate_temperatures
from thermocal.writers import write_recording

LADDER = (-100.0, -10.0, -0.1, 0.0, 0.1, 10.0, 100.0)


@pytest.fixture(scope="module")
def result_file(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    d = tmp_path_factory.mktemp("rtres")
    runs = simulate_temperatures(
        np.random.default_rng(3), [0.0, 40.0], rates_dps=LADDER, dwell_s=8.0, rate_hz=50.0,
        up_down=True, tc_ppm_per_c=30.0, cubic_ppm=200.0,
    )  # fmt: skip
    files = []
    for k, (rec, _) in enumerate(runs):
        files.append(d / f"rt{k}.csv")
        write_recording(rec, files[-1])
    res = ratetable_files(files, RateTableOptions(rate_column="table_rate", temps="temp"))
    path = d / "res.json"
    path.write_text(json.dumps(res.to_dict()))
    return path, res.to_dict()


def test_result_read_back_is_the_result(result_file: tuple[Path, dict]) -> None:
    path, want = result_file
    res = read_result(path)
    assert json.loads(json.dumps(res.to_dict())) == want
    assert res.temperature_coefficient is not None
    assert res.temperature_coefficient.ppm_per_c == want["temperature_coefficient"]["ppm_per_c"]
    assert [ld.scale_factor for ld in res.ladders] == [ld["scale_factor"] for ld in want["ladders"]]


def test_not_a_result_refused(result_file: tuple[Path, dict], tmp_path: Path) -> None:
    _, want = result_file
    bad = tmp_path / "bad.json"
    for text in ("[1, 2]", "{", json.dumps({**want, "ladders": [{"scale_factor": 1.0}]})):
        bad.write_text(text)
        with pytest.raises(ThermocalInputError, match=r"bad\.json"):
            read_result(bad)
    with pytest.raises(ThermocalInputError, match="cannot read"):
        read_result(tmp_path / "missing.json")


def test_a_gyro_unit_against_the_file_names_gyro_unit(tmp_path: Path) -> None:
    rec, _ = simulate_temperatures(np.random.default_rng(1), [25.0], rates_dps=LADDER,
                                   dwell_s=8.0, rate_hz=50.0)[0]  # fmt: skip
    path = tmp_path / "deg_s.csv"  # the file says deg/s
    write_recording(rec, path)
    with warnings.catch_warnings(record=True) as caught:  # and the counts' plausibility
        warnings.simplefilter("always")
        ratetable_files([path], RateTableOptions(gyro_unit="counts", rate_column="table_rate"))
    said = [str(w.message) for w in caught
            if issubclass(w.category, UnitWarning) and "contradicts" in str(w.message)]  # fmt: skip
    assert len(said) == 1 and "gyro_unit counts contradicts the file's metadata" in said[0], said
