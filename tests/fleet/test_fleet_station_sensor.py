"""``thermocal fleet`` reads a station folder's sensor and asks for one when there are several."""

from __future__ import annotations

from pathlib import Path

from station_folders import run_cli as _run
from station_folders import station_folder as _station


def test_fleet_reads_a_station_sensor_and_asks_for_one(tmp_path: Path) -> None:
    _station(tmp_path)
    head = ('[fit]\nmodel = "poly"\norder = 1\nsignal = ["gx_deg_h"]\nsignal_unit = "deg/h"\n'
            'temps = "temp_c"\n')  # fmt: skip
    (tmp_path / "ok.toml").write_text(
        head + 'sensor = "b"\n\n[[unit]]\nid = "U1"\nmodeling = ["rec"]\n'
    )
    code, _o, err = _run(["fleet", str(tmp_path / "ok.toml"), "-o", str(tmp_path / "f1")])
    assert code == 0, err
    (tmp_path / "amb.toml").write_text(head + '\n[[unit]]\nid = "U1"\nmodeling = ["rec"]\n')
    code, _o, err = _run(["fleet", str(tmp_path / "amb.toml"), "-o", str(tmp_path / "f2")])
    assert code != 0 and "--sensor ID" in err and "Traceback" not in err, err
