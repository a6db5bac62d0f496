"""``allan --deviation`` says how each interval was found, and says "none" with the reason
where it gives none (MTIE, TIE rms) instead of a bare null (issue 29 item 2); Theo1's
interval comes from Howe's EDF."""

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
    for name in ("mtie", "tierms"):
        assert obj[f"{name}_interval"].startswith("none: "), name
        assert all(v is None for v in obj[f"{name}_low"]), name
    # Theo1: Howe's EDF for white FM (α = 0, identified), written out here from SP 1065
    # §5.2.16 / Riley's notes: ((4.1 N + 0.8)/t − (3.1 N + 6.5)/N) · t^1.5/(t^1.5 + 5.2),
    # N phase points, t = 0.75 m = τ/τ0
    assert obj["theo1_interval"].startswith("chi-square, 68.3 %, Howe's empirical Theo1")
    n = len(y) + 1
    for tau, edf, a, lo, hi, dev in zip(obj["theo1_tau_s"], obj["theo1_edf"], obj["theo1_alpha"],
                                        obj["theo1_low"], obj["theo1_high"], obj["theo1"],
                                        strict=True):  # fmt: skip
        if a != 0 or edf is None:
            continue
        t = tau / 0.01
        want = ((4.1 * n + 0.8) / t - (3.1 * n + 6.5) / n) * t**1.5 / (t**1.5 + 5.2)
        assert edf == pytest.approx(want, rel=1e-9), tau
        assert lo < dev < hi
    assert sum(a == 0 for a in obj["theo1_alpha"]) >= 5
    code = main(["allan", str(path), "--signal", "gx [deg/s]", "--deviation", "mtie"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert "mtie: interval none: MTIE is a maximum over windows" in cap.out.replace("\n", " ")
