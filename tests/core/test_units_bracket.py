"""A unit written in brackets at the end of a column name, found in linear time.

``thermocal.units._NAME_BRACKET`` (the regular expression) is quadratic on a name of many
``(``: a 10 MB header name took minutes (issue 38's 'did you mean' hint read every name
with it; the text attacks' 10 MB line timed out).  ``_bracket_unit`` must find exactly what
the expression finds, on every short name drawn here; the expression is the reference."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from thermocal.units import _NAME_BRACKET, _bracket_unit, strip_unit_from_name


@given(st.text(alphabet="ab ([])m\ts_", max_size=12))
def test_bracket_unit_finds_what_the_expression_finds(name: str) -> None:
    m = _NAME_BRACKET.search(name)
    assert _bracket_unit(name) == (None if m is None else (m.start(), m.group(1)))


def test_a_name_of_a_million_brackets_is_read() -> None:
    """The expression's answer written out: the first ``(`` opens, the rest is the unit."""
    name = "T1" + "(" * 1_000_000 + "x)"
    assert _bracket_unit(name) == (2, "(" * 999_999 + "x")
    assert strip_unit_from_name(name) == "T1"
    assert strip_unit_from_name("gyro (deg/h)") == "gyro"
