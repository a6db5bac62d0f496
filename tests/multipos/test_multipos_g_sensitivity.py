"""``multipos --g-sensitivity`` where the poses cannot separate the gyro's g-sensitivity
(the fit refuses, as on poses whose gravity directions lie in one plane): ``apply`` is
refused in one ``error:`` line that says why and names the option; ``auto`` calibrates and
says it was not estimated; a session without a gyro refuses ``apply`` naming ``--gyro``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from gsens_session import MULTIPOS, READ, run, write_session
from thermocal.errors import DesignError
from thermocal.multipos import calibrate as _calibrate

NOTE = "the gyro's g-sensitivity is not separable from these poses (test)"


@pytest.fixture
def unseparable(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    write_session(tmp_path, seed=5)

    def refuse(*_a: Any, **_k: Any) -> Any:
        raise DesignError(NOTE)

    monkeypatch.setattr(_calibrate._gsens, "fit_g_sensitivity", refuse)
    return tmp_path


def test_apply_is_refused_in_one_line(unseparable: Path) -> None:
    d = unseparable
    code, _o, err = run(["multipos", str(d / "s.csv"), *MULTIPOS, "-o", str(d / "a.json"),
                         "--g-sensitivity", "apply"])  # fmt: skip
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2 and len(errors) == 1 and "Traceback" not in err, err
    assert "--g-sensitivity apply" in errors[0] and NOTE in errors[0], errors[0]
    assert not (d / "a.json").exists()


def test_auto_says_it_was_not_estimated(unseparable: Path) -> None:
    d = unseparable
    code, out, err = run(["multipos", str(d / "s.csv"), *MULTIPOS, "-o", str(d / "b.json"),
                          "--json"])  # fmt: skip
    assert code == 0, err
    gs = json.loads(out)["gyro"]["g_sensitivity"]
    assert gs["matrix"] is None and not gs["stored"] and gs["n_sessions"] == 0
    assert gs["why"] == f"not estimated: {NOTE}"
    assert json.loads((d / "b.json").read_text())["format_version"] == 1


def test_apply_without_a_gyro_names_it(tmp_path: Path) -> None:
    write_session(tmp_path, seed=5)
    code, _o, err = run(["multipos", str(tmp_path / "s.csv"), *READ, "--accel", "ax,ay,az",
                         "--accel-unit", "mg", "--latitude", "45", "-o", str(tmp_path / "c.json"),
                         "--g-sensitivity", "apply"])  # fmt: skip
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2 and len(errors) == 1, err
    assert "--gyro" in errors[0] and "--g-sensitivity" in errors[0], errors[0]
