"""The demos' results speak for themselves: ``to_dict`` is the JSON the command prints (its
keys, paths as strings) and ``text`` the summary table, its cells the figures given here."""

from __future__ import annotations

import json
from pathlib import Path

from thermocal.demo.chamber import DemoResult, ModelSummary
from thermocal.demo.imu import ChannelSummary, ImuDemoResult
from thermocal.report.text import TextTable


def _model(label: str, n: int, after: float) -> ModelSummary:
    return ModelSummary(
        label, Path(f"m/{label}.json"), Path(f"v/{label}.json"), (Path("c/a.h"),), n, 12.0,
        0.5, -0.01, True, 4, 0.02, after, 0.05, after / 2,
        {"bias_stability": 100 * (1 - after / 0.02), "bias_repeatability": None},
    )  # fmt: skip


def test_chamber_demo_result_json_and_table() -> None:
    res = DemoResult(
        Path("out"), Path("out/report.html"),
        (_model("selected", 10, 0.01), _model("s37", 37, 0.015)), {}, Path("out/c.csv"),
        (Path("out/a"), Path("out/b")), {"fit": 1.0}, 2.25, 7,
    )  # fmt: skip
    d = res.to_dict()
    assert list(d) == ["report", "out_dir", "elapsed_s", "timings_s", "seed", "models", "files"]
    assert d["models"][0]["model"] == "m/selected.json" and d["models"][1]["n_coefficients"] == 37
    assert d["files"] == ["out/a", "out/b"]
    json.dumps(d)  # JSON types only
    table, star, files = res.text()
    assert star == "* reported model; (…) improvement"
    assert isinstance(table, TextTable)
    assert table.columns == ("figure", "before", "after, selected *", "after, s37")
    assert table.rows[2] == ("bias stability", "0.02", "0.01 (+50.0 %)", "0.015 (+25.0 %)")
    assert table.rows[3] == ("bias repeatability", "0.05", "0.005 (—)", "0.0075 (—)")
    assert files == "2 files in out (2.2 s)"


def test_imu_demo_result_json_and_table() -> None:
    ch = ChannelSummary("gx", "deg/s", 4, 1.5, 6.0, (-10.0, 60.0), -0.25, 0.002, 0.001,
                        0.0243, 0.00110, 99.8654)  # fmt: skip
    res = ImuDemoResult(Path("o"), Path("o/r.html"), Path("o/c.json"), [ch], [Path("o/x")], 3.0, 5)
    d = res.to_dict()
    assert d["seed"] == 5 and d["calibration"] == "o/c.json"
    assert d["channels"]["gx"]["temp_range_c"] == [-10.0, 60.0]
    assert list(d["channels"]["gx"])[4] == "temp_range_c"
    table = res.text()[0]
    assert isinstance(table, TextTable)
    assert table.title == "thermocal demo --imu (seed 5): validation run"
    assert table.rows == (("gx", "deg/s", "-0.25", "0.0243", "0.0011", "99.9 %"),)
