"""export-c writes a header and a source that only make sense together (issue 27): both
are written whole to temporaries before either is renamed, so that a failure writing the
second leaves neither new file, and an older pair exactly as it was."""

from __future__ import annotations

import errno
from pathlib import Path

import pytest

import thermocal.export.c.core as core
from thermocal.errors import ThermocalInputError
from thermocal.export.c import CExport


def _module(version: int) -> CExport:
    return CExport(
        prefix="pair",
        real="double",
        header=f"/* pair header, version {version} */\n#define PAIR_VERSION {version}\n",
        source=f'/* pair source, version {version} */\n#include "pair.h"\n',
        family="poly",
        n_temps=1,
    )


def _fail_on_second(monkeypatch: pytest.MonkeyPatch) -> list[Path]:
    """Make the second file written fail with a full disk; returns the paths tried."""
    tried: list[Path] = []
    real = core._write_text

    def write_text(path: Path, text: str) -> None:
        tried.append(path)
        if len(tried) == 2:
            real(path, text[: len(text) // 2])  # part-written, then the disk is full
            raise OSError(errno.ENOSPC, "No space left on device")
        real(path, text)

    monkeypatch.setattr(core, "_write_text", write_text)
    return tried


def test_pair_written_together(tmp_path: Path) -> None:
    paths = _module(1).write(tmp_path / "out")
    assert [p.name for p in paths] == ["pair.h", "pair.c"]
    assert paths[0].read_text() == _module(1).header
    assert paths[1].read_text() == _module(1).source
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["pair.c", "pair.h"]


def test_failure_on_the_second_file_leaves_neither(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    tried = _fail_on_second(monkeypatch)
    out = tmp_path / "out"
    with pytest.raises(ThermocalInputError, match="nothing was written"):
        _module(1).write(out)
    assert len(tried) == 2
    assert list(out.iterdir()) == []  # no header, no source, no temporary


def test_failure_on_the_second_file_keeps_the_old_pair(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "out"
    _module(1).write(out)
    old = {p.name: p.read_bytes() for p in out.iterdir()}
    _fail_on_second(monkeypatch)
    with pytest.raises(ThermocalInputError, match="nothing was written"):
        _module(2).write(out)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == old  # old pair, no temporary
