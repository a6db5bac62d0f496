"""``outputs.check_outputs``: a folder the run replaces or deletes may hold no input, at any
depth; a folder whose name merely starts like the input's folder is no container (``u1``
and ``u10``); an input reached through a symbolic link is found by where it really is."""

from __future__ import annotations

from pathlib import Path

import pytest

from thermocal.errors import ThermocalInputError
from thermocal.outputs import check_outputs


def _input(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("time,x\n0,1\n", encoding="utf-8")
    return path


def test_a_replaced_folder_holding_an_input_is_refused(tmp_path: Path) -> None:
    deep = _input(tmp_path / "units" / "u1" / "raw" / "run.csv")
    others = [_input(tmp_path / f"in{i}.csv") for i in range(50)]
    replaced = [tmp_path / "units" / f"u{i}" for i in range(40)]
    with pytest.raises(ThermocalInputError) as err:
        check_outputs([], [*others, deep], replaced=replaced)
    assert str(err.value) == (
        f"{tmp_path / 'units' / 'u1'}: refusing to write the output there: it contains the "
        f"input file {deep}, which would be deleted"
    )


def test_a_folder_named_like_the_inputs_folder_is_no_container(tmp_path: Path) -> None:
    near = _input(tmp_path / "units" / "u10" / "run.csv")
    check_outputs([], [near], replaced=[tmp_path / "units" / "u1"])  # passes


def test_an_input_through_a_link_is_found_where_it_is(tmp_path: Path) -> None:
    real = _input(tmp_path / "data" / "u2" / "run.csv")
    (tmp_path / "link").symlink_to(tmp_path / "data")
    with pytest.raises(ThermocalInputError, match="which would be deleted"):
        check_outputs([], [tmp_path / "link" / "u2" / "run.csv"], replaced=[real.parent])
