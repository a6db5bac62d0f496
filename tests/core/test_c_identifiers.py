"""The gate between names and generated C (issue 26, item 3): ``thermocal.identifiers``.

Identifiers: what a name becomes, written out here by hand (the expected hash suffixes with
hashlib); collisions after mapping refused naming both originals.  Comments and string
literals: checked by the C compiler itself, which must accept every hostile text inside a
comment under ``-std=c99 -Wall -Wextra -Werror -pedantic`` and give back the exact bytes
of every string literal."""

from __future__ import annotations

import hashlib
import re
import subprocess
from pathlib import Path

import pytest

from thermocal.errors import ThermocalInputError
from thermocal.export.c.harness import find_compiler
from thermocal.identifiers import (
    MAX_IDENTIFIER_LEN,
    c_comment,
    c_identifier,
    c_string,
    check_generated_c,
)

HOSTILE = [
    "T1 */\n#error INJECTED\n/*",
    "gyro \\",
    "gyro \\   ",
    "a ??/",
    "??=define X",
    "q\"uo'te",
    "\u03c9 [\u00b0/h] \U0001f600",
    "*/",
    "/*",
    "*",
    "/",
    "/*/",
    "\r\n#pragma once\r",
    "\x00\x07\x1b[31m\x7f",
    "\u2028#error LS",
    "int",
    "",
    "x" * 300,
    "__LINE__",
    "_Bool",
    "9lives",
]
SAFE = re.compile(r"[a-z][a-z0-9]*(_[a-z0-9]+)*")
CC_FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
needs_cc = pytest.mark.skipif(find_compiler() is None, reason="no C compiler on this machine")


def _sha8(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:8]


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("rlg poly-v2", "rlg_poly_v2"),
        ("gyro_x", "gyro_x"),
        ("GX [deg/s]", "gx_deg_s"),
        ("int", "c_int"),  # a C keyword
        ("class", "c_class"),  # a C++ keyword: the firmware may be C++
        ("stdin", "c_stdin"),  # a standard macro
        ("_Bool", "c_bool"),  # leading underscore stripped, then a C23 keyword
        ("__LINE__", "line"),
        ("9lives", "m_9lives"),  # a leading digit
        ("température", "temperature"),  # NFKD: the accent dropped
        ("ω", "u03c9"),  # other non-ASCII: its code point
        ("a  --  b", "a_b"),  # one underscore between parts
        ("T1 */\n#error INJECTED\n/*", "t1_error_injected"),
        ("", f"id_{_sha8('')}"),  # nothing left: a hash of the original
        ("*/", f"id_{_sha8('*/')}"),
    ],
)
def test_identifier_mapping(name: str, expected: str) -> None:
    assert c_identifier(name) == expected


def test_long_names_are_bounded_and_stay_distinct() -> None:
    a, b = "x" * 299 + "a", "x" * 299 + "b"
    ia, ib = c_identifier(a), c_identifier(b)
    assert len(ia) == MAX_IDENTIFIER_LEN == 63  # C99 §5.2.4.1: 63 significant characters
    assert ia == "x" * 54 + "_" + _sha8(a)
    assert ib == "x" * 54 + "_" + _sha8(b)
    assert ia != ib


@pytest.mark.parametrize("name", [*HOSTILE, "rlg poly-v2", "m_1", "c_int"])
def test_every_identifier_is_safe_and_maps_to_itself(name: str) -> None:
    s = c_identifier(name)
    assert SAFE.fullmatch(s), s
    assert len(s) <= 63
    assert s not in {"int", "for", "while", "class", "new", "bool", "stdin", "errno"}
    assert c_identifier(s) == s  # a safe identifier goes through unchanged


def test_collisions_after_mapping_are_refused_naming_both() -> None:
    used: dict[str, str] = {}
    assert c_identifier("a b", used, what="channel") == "a_b"
    assert c_identifier("a b", used, what="channel") == "a_b"  # the same name again: fine
    with pytest.raises(ThermocalInputError) as e:
        c_identifier("a-b", used, what="channel")
    assert "'a b'" in str(e.value) and "'a-b'" in str(e.value) and "'a_b'" in str(e.value)
    assert "channel" in str(e.value)
    with pytest.raises(ThermocalInputError, match=r"'GX'.*'gx'"):
        c_identifier("gx", {"gx": "GX"})  # lower case: GX and gx meet
    used = {}
    c_identifier("int", used)
    with pytest.raises(ThermocalInputError, match=r"'int'.*'c_int'"):
        c_identifier("c_int", used)
    used = {}
    c_identifier("", used)
    c_identifier(" ", used)  # both empty after mapping, but different originals: hashed apart
    assert len(used) == 2


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("a*/b", "a* /b"),
        ("a/*b", "a/ *b"),
        ("/*/", " / * / "),  # and no '/' or '*' at the ends to meet the text around it
        ("line1\nline2\r", "line1\\x0aline2\\x0d"),
        ("C:\\data\\", "C:\\data\\x5c"),  # a trailing backslash would splice the next line
        ("x\\  ", "x\\x5c  "),  # also before trailing spaces (gcc splices those too)
        ("a ??/", "a ? ?/ "),  # a trigraph (??/ is a backslash in C99); the end padded
        ("20 °C", "20 degC"),  # thermocal's own symbols in ASCII (issue 38)
        ("é ω", "\\u00e9 omega"),
        ("\U0001f600", "\\U0001f600"),
        ("plain text", "plain text"),
    ],
)
def test_comment_escapes(text: str, expected: str) -> None:
    assert c_comment(text) == expected


@pytest.mark.parametrize("text", HOSTILE)
def test_comment_text_is_inert(text: str) -> None:
    s = c_comment(text)
    assert all(" " <= ch <= "~" for ch in s)
    assert "*/" not in s and "/*" not in s and "??" not in s
    assert not re.search(r"\\\s*$", s)
    assert s[:1] not in ("*", "/") and s[-1:] not in ("*", "/")
    assert c_comment(s) == s  # idempotent: escaping twice changes nothing


@needs_cc
def test_hostile_comments_and_strings_compile_and_keep_their_bytes(tmp_path: Path) -> None:
    """Every hostile text in a comment (each next to '/', '*' and at the end of a line)
    and in a string literal: the compiler accepts the file with -Werror, and the program
    prints each literal's bytes, equal to the UTF-8 of the original."""
    lines = ["#include <stdio.h>"]
    for text in HOSTILE:
        c = c_comment(text)
        lines += [f"/* {c} */", f"/*{c}*/", f"/* [{c}/{c}] */", f"/* {c}", " */"]
    lits = ", ".join(c_string(t) for t in HOSTILE)
    lines += [
        f"static const char *const S[{len(HOSTILE)}] = {{{lits}}};",
        f"static const unsigned long N[{len(HOSTILE)}] = {{"
        + ", ".join(f"sizeof {c_string(t)} - 1" for t in HOSTILE)
        + "};",
        "int main(void)",
        "{",
        "    int i;",
        "    unsigned long j;",
        f"    for (i = 0; i < {len(HOSTILE)}; ++i) {{",
        '        for (j = 0; j < N[i]; ++j) printf("%02x", (unsigned char)S[i][j]);',
        '        printf("\\n");',
        "    }",
        "    return 0;",
        "}",
    ]
    src = tmp_path / "t.c"
    src.write_text("\n".join(lines) + "\n", encoding="ascii")
    exe = tmp_path / "t"
    proc = subprocess.run(
        [str(find_compiler()), *CC_FLAGS, "-o", str(exe), str(src)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == [t.encode("utf-8").hex() for t in HOSTILE]


def test_string_literal_escapes() -> None:
    assert c_string('a"b\\c') == '"a\\"b\\\\c"'
    assert c_string("??/") == '"\\?\\?/"'
    assert c_string("°\n") == '"\\302\\260\\012"'


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("#error INJECTED\n", "preprocessor line"),
        ("/* a */\n  #  pragma once\n", "preprocessor line"),
        ("#define X 1 /* a /* b */\n", "inside a comment"),
        ("/* a\n", "not closed"),
        ('#define X "a\n', "not closed"),
        ("int a; /* x ??/ */\n", "trigraph"),
        ("int a; /* x \\\n*/\n", "backslash"),
        ("int a; /* \u00b0 */\n", "outside printable ASCII"),
        ("int a; */\n", "outside a comment"),
        ('#include "../x.h"\n', "preprocessor line"),
    ],
)
def test_backstop_refuses_steered_text(text: str, words: str) -> None:
    with pytest.raises(ThermocalInputError, match=words):
        check_generated_c(text)


def test_backstop_accepts_what_the_generators_write() -> None:
    check_generated_c(
        '/*\n * a comment\n */\n#ifndef M_H\n#define M_H\n#define M_UNIT "deg/h" /* u */\n'
        '#include "m.h"\nint m_x(void);\n#endif /* M_H */\n'
    )
