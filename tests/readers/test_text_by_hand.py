"""Text logs (:mod:`thermocal.readers.text`): banners, headers, the decimal mark, what is a
number and a bad line, against the lines written here.  Each kills a mutant of
``benchmarks/mutation_check.py`` (``text-*``)."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from thermocal.errors import FileFormatError
from thermocal.readers.options import ReadOptions
from thermocal.readers.text import parse_number, read_text, sniff_text


def test_a_row_with_an_empty_field_is_data_not_a_banner() -> None:
    """A headerless log whose first row has a missing value starts at that row
    (mutant text-empty-field-not-number)."""
    lay = sniff_text(["0,,1", "1,2,3", "2,3,4"])
    assert (lay.skip, lay.header, lay.banner) == (0, False, ())


def test_a_line_with_an_empty_name_is_no_header() -> None:
    """``t,,b`` has an empty name: a banner line, not the header (mutant
    text-header-empty-name)."""
    lay = sniff_text(["t,,b", "0,1,2", "1,2,3"])
    assert (lay.skip, lay.header, lay.banner) == (1, False, ("t,,b",))


def test_the_decimal_mark_tie_goes_to_the_point() -> None:
    """``1;2`` reads the same with either decimal mark: a point (mutant
    text-decimal-tie-comma)."""
    assert sniff_text(["1;2", "3;4", "5;6"]).decimal == "."
    assert sniff_text(["1,5;2", "3,25;4", "5;6"]).decimal == ","


def test_underscores_and_foreign_digits_are_not_numbers() -> None:
    """``0_5`` is 5.0 to Python's float, a malformed number here (mutant
    text-underscore-number)."""
    with pytest.raises(ValueError, match="malformed"):
        parse_number("0_5")
    assert parse_number(" -1.5e3 ") == -1500.0


def test_a_row_with_too_many_fields_is_a_bad_line(tmp_path: Path) -> None:
    """A row with four fields in a three-field log: named as bad, or dropped with skip
    (mutant text-wrong-field-count-kept)."""
    f = tmp_path / "log.txt"
    f.write_text("logger v1\nt;a;b\n0;1;2\n1;2;3;4\n2;3;4\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the layout and the skipped line are stated
        with pytest.raises(FileFormatError, match="line 4"):
            read_text(f, "utf-8", ReadOptions())
        df, _info = read_text(f, "utf-8", ReadOptions(on_bad_lines="skip"))
    assert df.shape == (2, 3)
    assert list(df["t"]) == [0.0, 2.0]
