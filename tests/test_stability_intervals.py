"""``allan --deviation`` says how each interval was found, and says "none" with the reason
where it gives none (MTIE, TIE rms, Theo1) instead of a bare null (issue 29 item 2)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main


def test_no_interval_is_stated(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rng = np.random.default_rng(4)
    y = rng.standard_normal(3000) * 0.02 + 0.5  # a gyro at rest, deg/s
    path = tmp_path / "gyro.csv"
    path.write_text(
        "time (s),gx [deg/s]\n"
        + "".join(f"{i * 0.01:.2f},{v!r}\n" for i, v in enumerate(y.tolist()))
    )
    code = main(["allan", str(path), "--signal", "gx [deg/s]", "--deviation",
                 "oadev,mtie,tierms,theo1", "--json"])  # fmt: skip
    cap = capsys.readouterr()
    assert code == 0, cap.err
    obj = json.loads(cap.out)
    assert obj["oadev_interval"].startswith("chi-square, 68.3 %")
    assert all(v is not None for v in obj["oadev_low"][:5])
    for name in ("mtie", "tierms", "theo1"):
        assert obj[f"{name}_interval"].startswith("none: "), name
        assert all(v is None for v in obj[f"{name}_low"]), name
    code = main(["allan", str(path), "--signal", "gx [deg/s]", "--deviation", "mtie"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert "mtie: interval none: MTIE is a maximum over windows" in cap.out.replace("\n", " ")
