"""One value a line: Stable32's own data files (PHASE.DAT, distributed with Stable32; a copy
in tests/data/stable32_phasedat, allantools' test data, LGPL-3.0), read as they are."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from stable32_phasedat import DATA, rows
from thermocal.cli import main
from thermocal.readers.text import sniff_text

PHASE_DAT = DATA / "PHASE.DAT"


def test_sniffed_as_one_column_after_its_comment_lines() -> None:
    head = PHASE_DAT.read_text().splitlines()[:50]
    lay = sniff_text(head)
    assert (lay.n_fields, lay.header, lay.skip, lay.banner) == (1, False, 2, ())


def test_allan_on_stable32s_file_equals_its_output(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """--names gives the column (the signal of a one-column log), --rate the time; OADEV's
    values and bounds equal Stable32's printed ones."""
    r = rows("phase_dat_oadev_octave.txt")
    taus = ",".join(f"{t:g}" for t in r[:, 1])
    code = main(["allan", str(PHASE_DAT), "--names", "phase", "--rate", "1", "--data-type",
                 "phase", "--deviation", "oadev", "--taus", taus, "--noise-id", "stable32",
                 "--json"])  # fmt: skip
    cap = capsys.readouterr()
    assert code == 0, cap.err
    obj = json.loads(cap.out)
    assert obj["oadev_tau_s"] == r[:, 1].tolist()
    np.testing.assert_allclose(obj["oadev"], r[:, 5], rtol=1e-4)
    np.testing.assert_allclose(obj["oadev_low"], r[:, 4], rtol=2e-3)
    np.testing.assert_allclose(obj["oadev_high"], r[:, 6], rtol=2e-3)
    assert "banner" not in cap.err  # '#' comment lines are no banner


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ([], "--names NAME"),
        (["--names", "phase"], "--rate HZ"),
        (["--names", "phase,x", "--rate", "1"], "2 names for 1 columns"),
    ],
)
def test_what_is_missing_is_named(
    capsys: pytest.CaptureFixture[str], extra: list[str], words: str
) -> None:
    code = main(["allan", str(PHASE_DAT), "--data-type", "phase", *extra])
    err = capsys.readouterr().err
    assert code == 2, err
    assert words in err


def test_a_text_file_of_words_is_still_refused(tmp_path: Path) -> None:
    path = tmp_path / "notes.txt"
    path.write_text("hello\nworld\nagain\n")
    from thermocal.errors import FileFormatError

    with pytest.raises(FileFormatError, match="two or more fields"):
        sniff_text(path.read_text().splitlines())


def test_signal_message_lists_the_files_columns(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """allan reads only the columns it uses; when none is named the message still lists the
    file's columns (it listed nothing before)."""
    path = tmp_path / "one.txt"
    path.write_text("phase [s]\n" + "".join(f"{0.1 * k + 0.01 * (k % 3)!r}\n" for k in range(40)))
    code = main(["allan", str(path), "--rate", "1", "--data-type", "phase"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "--signal; available: 'phase [s]'" in err
