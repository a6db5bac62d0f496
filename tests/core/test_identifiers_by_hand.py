"""C identifiers and strings (:mod:`thermocal.identifiers`) against what a name must become,
written out here (kills a mutant of ``benchmarks/mutation_check.py``)."""

from __future__ import annotations


def test_c_identifiers_and_strings_by_hand() -> None:
    """A 100-character name becomes an identifier of at most 63 characters (C99's
    significant initial characters; mutant identifiers-length-hash lets 64…71 through), and DEL
    (0x7F) is written as the octal escape \\177 (mutant identifiers-printable-range writes
    it raw)."""
    from thermocal.identifiers import c_identifier, c_string

    for n in (64, 68, 100):
        ident = c_identifier("x" * n)
        assert len(ident) <= 63 and ident.startswith("x"), n
    assert c_identifier("y" * 63) == "y" * 63
    assert c_string("a\x7fb~") == '"a\\177b~"'
