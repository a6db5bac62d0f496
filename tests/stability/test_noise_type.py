"""``allan --noise-type``: the noise the intervals and bias factors assume, set by hand as in
Stable32's noise-type setting.

Reference from outside thermocal: Stable32's Hadamard Total run of PHASE.DAT with the noise
set to white PM (tests/data/stable32_phasedat/phase_dat_htotdev_octave_nobias.txt, allantools'
test data, LGPL-3.0): α = 2 in every row where Stable32's own identification of the same
record reads white FM and then flicker PM (phase_dat_htotdev_octave.txt), and no bias factor
(Stable32 has none for phase noise)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stable32_phasedat import allan_refuses, phase_csv, rows, run_allan
from thermocal.cli.allan_cmd import parse_noise_type
from thermocal.stability.family import NOISE_TYPES


def test_white_pm_htotdev_equals_stable32s_forced_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """All nine rows, m = 1–256: values to 1e-4, bounds to 2e-3 (Stable32's phase-noise EDF
    of the total deviations, the simple white-PM EDF + 2; the overlapping-Hadamard EDF used
    before put them 2.5–8 ‰ off), with --bias-correct on: the factor is 1 at white PM."""
    r = rows("phase_dat_htotdev_octave_nobias.txt", commented=True)
    assert r.shape[0] == 9 and (r[:, 3] == 2).all()
    obj = run_allan(
        capsys, phase_csv(tmp_path), "htotdev", r[:, 1], "--noise-type", "wpm", "--bias-correct"
    )
    assert obj["htotdev_alpha"] == [2] * 9
    assert obj["htotdev_alpha_method"] == ["given"] * 9
    assert obj["htotdev_bias_factor"] == [1.0] * 9
    np.testing.assert_allclose(obj["htotdev"], r[:, 5], rtol=1e-4)
    np.testing.assert_allclose(obj["htotdev_low"], r[:, 4], rtol=2e-3)
    np.testing.assert_allclose(obj["htotdev_high"], r[:, 6], rtol=2e-3)


def test_identified_run_differs_from_the_forced_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without the option the same record reads white FM at m = 1 (Stable32's identified run),
    so the option is what changes the interval."""
    obj = run_allan(capsys, phase_csv(tmp_path), "htotdev", np.array([1.0]))
    forced = run_allan(capsys, phase_csv(tmp_path), "htotdev", np.array([1.0]), "--noise-type", "2")
    assert obj["htotdev_alpha"] == [0] and forced["htotdev_alpha"] == [2]
    assert forced["htotdev_edf"][0] < 0.8 * obj["htotdev_edf"][0]


def test_names_and_alpha_values() -> None:
    assert [NOISE_TYPES[k] for k in ("wpm", "fpm", "wfm", "ffm", "rwfm")] == [2, 1, 0, -1, -2]
    assert parse_noise_type("auto", ["oadev"]) is None
    assert parse_noise_type(None, ["oadev"]) is None
    assert parse_noise_type("FFM", ["oadev"]) == -1
    assert parse_noise_type("-4", ["hdev", "htotdev", "mtie"]) == -4


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--deviation", "oadev", "--noise-type", "pink"], "--noise-type 'pink'"),
        (["--deviation", "oadev", "--noise-type", "3"], "from -4 to 2"),
        (["--deviation", "oadev,hdev", "--noise-type", "rrfm"], "Hadamard"),
        (["--noise-type", "wfm"], "--deviation"),
    ],
)
def test_bad_noise_type_is_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], words: str
) -> None:
    assert words in allan_refuses(tmp_path, capsys, *extra)
