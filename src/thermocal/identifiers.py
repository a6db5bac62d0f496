"""The one gate between names from files or options and generated code.

A column, channel, temperature or triad name, a module prefix (``name``) or a string field of a
model file can hold anything: ``*/``, a newline followed by ``#error``, a backslash that
splices the next line, a trigraph ``??/``, quotes, non-ASCII text, a C keyword, 300
characters.  Everything thermocal writes into C passes through one of these functions:

* :func:`c_identifier` — any string → a safe C identifier (ASCII letters, digits and single
  underscores, lower case, not starting with a digit, not a C/C++ keyword or reserved
  name, at most :data:`MAX_IDENTIFIER_LEN` characters); with ``used`` it refuses two
  originals that map to the same identifier;
* :func:`c_comment` — any string → text that can sit inside a ``/* … */`` comment without
  ending it, opening another, splicing lines or leaving the ASCII range;
* :func:`c_string` — any string → a C string literal (quotes included) with the same bytes;
* :func:`check_generated_c` — the backstop run on every generated file: printable ASCII
  only, no trigraph, no line splice, comments and strings closed, no ``/*`` inside a
  comment, and only the directives the generators write (``#ifndef``, ``#define``,
  ``#endif``, ``#include "x.h"``).  A file failing it is refused, never written.

Rules: ISO/IEC 9899:1999 §5.2.4.1 (63 significant initial characters of an internal
identifier), §6.4.1 (keywords), §7.1.3 (reserved identifiers: a leading underscore), §5.2.1.1
(trigraphs), §5.1.1.2 (line splicing in translation phase 2, before comments are removed).
"""

from __future__ import annotations

import hashlib
import re
import unicodedata
from collections.abc import MutableMapping

from thermocal.errors import ThermocalInputError

MAX_IDENTIFIER_LEN = 63
"""Longest identifier the gate returns: C99's guaranteed significant initial characters of
an internal identifier (§5.2.4.1).  Longer names keep their first characters and end in a
hash of the whole original, so two long names that differ only at the end stay distinct."""

MAX_PREFIX_LEN = 2 * MAX_IDENTIFIER_LEN + 1
"""Longest prefix of a generated module: a calibration's ``<prefix>_<channel>``, two
identifiers of the gate joined by ``_`` (a longer ``name`` is shortened as above)."""

_HASH_LEN = 8


def _words(text: str) -> frozenset[str]:
    return frozenset(text.split())


C_KEYWORDS = _words(
    # C89, C99, C11 (the underscore forms are excluded by the gate's stripping), C23
    "auto break case char const continue default do double else enum extern float for "
    "goto if inline int long register restrict return short signed sizeof static struct "
    "switch typedef union unsigned void volatile while bool true false nullptr alignas "
    "alignof constexpr static_assert thread_local typeof typeof_unqual"
)
CPP_KEYWORDS = _words(
    # the firmware that includes the header is often C++ (PX4, ArduPilot)
    "and and_eq asm bitand bitor catch char8_t char16_t char32_t class compl concept "
    "consteval constinit const_cast co_await co_return co_yield decltype delete "
    "dynamic_cast explicit export friend mutable namespace new noexcept not not_eq "
    "operator or or_eq private protected public reinterpret_cast requires static_cast "
    "template this throw try typeid typename using virtual wchar_t xor xor_eq final "
    "override"
)
STANDARD_NAMES = _words(
    # lower-case macros and identifiers of the standard headers a firmware includes
    # (a struct member or local of these names breaks where the header defines a macro)
    "main stdin stdout stderr errno assert offsetof va_arg va_start va_end va_copy "
    "setjmp longjmp complex imaginary noreturn isnan isinf isfinite isnormal signbit "
    "fpclassify isgreater isless isunordered math_errhandling ptrdiff_t size_t wchar_t "
    "int8_t int16_t int32_t int64_t uint8_t uint16_t uint32_t uint64_t intptr_t uintptr_t "
    "intmax_t uintmax_t"
)
RESERVED = C_KEYWORDS | CPP_KEYWORDS | STANDARD_NAMES

_RESERVED_PREFIX = "c_"
"""Put before a name that is a keyword or reserved (``int`` → ``c_int``)."""
_DIGIT_PREFIX = "m_"
"""Put before a name that starts with a digit (``1st`` → ``m_1st``)."""


def _short_hash(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:_HASH_LEN]


def c_identifier(
    name: str,
    used: MutableMapping[str, str] | None = None,
    *,
    what: str = "name",
    max_len: int = MAX_IDENTIFIER_LEN,
) -> str:
    """A safe C identifier from any string (``rlg poly-v2`` → ``rlg_poly_v2``).

    Steps: Unicode NFKD (``é`` → ``e`` + accent, the accent dropped); any other non-ASCII
    character → ``u`` and its code point in hex (``ω`` → ``u03c9``); everything that is not
    an ASCII letter or digit → ``_``; lower case; runs of ``_`` → one, none at either end;
    nothing left → ``id_<hash>``; a leading digit → ``m_`` before it; a C/C++ keyword or a
    reserved standard name (:data:`RESERVED`) → ``c_`` before
    it; longer than ``max_len`` (:data:`MAX_IDENTIFIER_LEN`) → the first characters, ``_``
    and 8 hex digits of the original's SHA-256.  A safe identifier maps to itself.

    ``used`` maps the identifiers given out so far to their originals (updated): a second
    original mapping to an identifier already taken is a :class:`ThermocalInputError`
    naming both (``what`` says what they are: channel, triad, …).

    Parameters
    ----------
    name : str
        Any string: a column, channel, triad or model name, a prefix.
    used : MutableMapping[str, str], optional
        The identifiers given out so far, mapped to their originals; updated.
    what : str
        What the names are, for the message (``"channel"``, ``"triad"``).
    max_len : int
        Longest identifier returned [characters].

    Returns
    -------
    str
        The identifier.

    Raises
    ------
    ThermocalInputError
        With ``used``: another original already maps to the same identifier (the message names
        both and says how to rename).

    References
    ----------
    ISO/IEC 9899:1999, *Programming languages — C*, §5.2.4.1 (63 significant initial
    characters), §6.4.1 (keywords), §7.1.3
    (reserved identifiers).

    Examples
    --------
    >>> c_identifier("rlg poly-v2"), c_identifier("2nd axis"), c_identifier("int")
    ('rlg_poly_v2', 'm_2nd_axis', 'c_int')
    >>> used = {}
    >>> c_identifier("T-1", used, what="channel")
    't_1'
    >>> c_identifier("T 1", used, what="channel")
    Traceback (most recent call last):
    ...
    thermocal.errors.ThermocalInputError: channels 'T-1' and 'T 1' both become ...
    """
    text = unicodedata.normalize("NFKD", str(name))
    parts: list[str] = []
    for ch in text:
        if ch.isascii():
            parts.append(ch if ch.isalnum() else "_")
        elif unicodedata.combining(ch):
            continue
        else:
            parts.append(f"_u{ord(ch):04x}_")
    s = re.sub(r"_+", "_", "".join(parts).lower()).strip("_")
    if not s:
        s = f"id_{_short_hash(str(name))}"
    if s[0].isdigit():
        s = _DIGIT_PREFIX + s
    if s in RESERVED:
        s = _RESERVED_PREFIX + s
    if len(s) > max_len:
        s = s[: max_len - _HASH_LEN - 1].rstrip("_") + "_" + _short_hash(str(name))
    if used is not None:
        other = used.get(s)
        if other is not None and other != name:
            raise ThermocalInputError(
                f"{what}s {other!r} and {name!r} both become the C identifier {s!r}; "
                f"rename one of them (C names keep ASCII letters, digits and '_', lower case)"
            )
        used[s] = str(name)
    return s


_TRIGRAPH = re.compile(r"\?\?(?=[=/'()!<>\-])")


C_COMMENT_ASCII = {
    "°": "deg", "″": "arcsec", "′": "arcmin", "µ": "u", "μ": "u", "²": "^2", "³": "^3",
    "⁻¹": "^-1", "·": "*", "×": "x", "−": "-", "–": "-", "—": "-", "…": "...", "±": "+/-",
    "≤": "<=", "≥": ">=", "→": "->", "Ṫ": "dT/dt", "τ": "tau", "σ": "sigma", "θ": "theta",
    "ω": "omega", "Ω": "Omega", "√": "sqrt", "Δ": "d",
}  # fmt: skip
"""The symbols of thermocal's own text (units, formulas) spelled in ASCII in generated C
comments (``48.1\u00b0`` would reach a header as a non-ASCII byte); other non-ASCII is escaped."""


def c_comment(text: object) -> str:
    """``text`` made safe inside a ``/* … */`` comment, on one line.

    The symbols of :data:`C_COMMENT_ASCII` → their ASCII spelling (``°`` → ``deg``);
    control characters (newline, carriage return, tab, NUL, DEL, …) → ``\\xNN``; other non-ASCII
    → ``\\uXXXX`` (``\\UXXXXXXXX`` beyond the BMP); ``??`` → ``? ?`` (no trigraph, §5.2.1.1);
    ``*/`` → ``* /`` and ``/*`` → ``/ *`` until neither is left; a backslash followed only
    by spaces up to the end → ``\\x5c`` (no line splice); a ``*``, ``/`` or ``?`` at either
    end gets a space on that side (so the surrounding text cannot complete one).  Idempotent.

    Parameters
    ----------
    text : object
        Any value; ``str(text)`` is made safe.

    Returns
    -------
    str
        Printable ASCII that cannot end, open or splice a comment.

    References
    ----------
    ISO/IEC 9899:1999, *Programming languages — C*, §5.1.1.2 (line splicing), §5.2.1.1
    (trigraphs), §6.4.9 (comments).

    Examples
    --------
    >>> c_comment("48.1 °C */ #error")
    '48.1 degC * / #error'
    """
    out: list[str] = []
    text = str(text)
    for sym, plain in C_COMMENT_ASCII.items():
        text = text.replace(sym, plain)
    for ch in text:
        o = ord(ch)
        if o < 0x20 or o == 0x7F:
            out.append(f"\\x{o:02x}")
        elif o > 0x7F:
            out.append(f"\\u{o:04x}" if o <= 0xFFFF else f"\\U{o:08x}")
        else:
            out.append(ch)
    s = "".join(out)
    while "??" in s:
        s = s.replace("??", "? ?")
    while "*/" in s or "/*" in s:
        s = s.replace("*/", "* /").replace("/*", "/ *")
    s = re.sub(r"\\(?=[ ]*$)", r"\\x5c", s)
    # the text around it may hold '/', '*' or '?': none may join one at either end
    if s[:1] in ("*", "/", "?"):
        s = " " + s
    if s[-1:] in ("*", "/", "?"):
        s += " "
    return s


_LINE_UNSAFE_CATEGORIES = frozenset(("Cc", "Cf", "Zl", "Zp", "Cs", "Co", "Cn"))
"""Unicode categories :func:`one_line` escapes: controls (newline, CR, NUL, NEL U+0085, the
file/group/record separators Python's ``splitlines`` breaks at), format characters (BOM,
bidirectional overrides), the line and paragraph separators U+2028/U+2029 (YAML 1.1 §5.4
line breaks), surrogates, private-use and unassigned code points (PyYAML refuses a file
holding a character outside YAML's printable set, even in a comment)."""


def one_line(text: object) -> str:
    """``text`` as ONE line of printable text, for a comment or a label in a generated
    file that is not C (Kalibr's YAML, parameter files, Markdown, logs): every character of
    :data:`_LINE_UNSAFE_CATEGORIES` → ``\\xNN`` (below U+0100), ``\\uXXXX`` or
    ``\\UXXXXXXXX``; everything else kept (``°``, ``σ`` are printable).  No reader can then
    find a line break, so no name can end a comment and start a key (YAML 1.2 §5.4, §6.6:
    a comment ends at the line break).  Idempotent.

    Parameters
    ----------
    text : object
        Any value; ``str(text)`` is escaped.

    Returns
    -------
    str
        One line of printable text.

    References
    ----------
    *YAML Ain't Markup Language (YAML) Version 1.2*, §5.4 (line break characters), §6.6
    (comments).

    Examples
    --------
    >>> print(one_line("gyro x" + chr(10) + "#error"))
    gyro x\\x0a#error
    """
    out: list[str] = []
    for ch in str(text):
        if unicodedata.category(ch) in _LINE_UNSAFE_CATEGORIES:
            o = ord(ch)
            if o < 0x100:
                out.append(f"\\x{o:02x}")
            else:
                out.append(f"\\u{o:04x}" if o <= 0xFFFF else f"\\U{o:08x}")
        else:
            out.append(ch)
    return "".join(out)


def c_string(text: object) -> str:
    """A C string literal (with its quotes) holding the UTF-8 bytes of ``text``:
    ``\\`` ``"`` and ``?`` escaped (``\\?``: no trigraph), every byte outside printable ASCII
    as a three-digit octal escape (``°`` → ``\\302\\260``).

    Parameters
    ----------
    text : object
        Any value; the UTF-8 bytes of ``str(text)`` are written.

    Returns
    -------
    str
        The literal, quotes included.

    References
    ----------
    ISO/IEC 9899:1999, *Programming languages — C*, §6.4.5 (string literals), §6.4.4.4 (octal
    escape sequences).

    Examples
    --------
    >>> print(c_string('say "hi"??'))
    "say \\"hi\\"\\?\\?"
    """
    out = ['"']
    for b in str(text).encode("utf-8", "surrogatepass"):
        ch = chr(b)
        if ch in '\\"?':
            out.append("\\" + ch)
        elif 0x20 <= b < 0x7F:
            out.append(ch)
        else:
            out.append(f"\\{b:03o}")
    out.append('"')
    return "".join(out)


_DIRECTIVES = (
    re.compile(r"#ifndef [A-Za-z][A-Za-z0-9_]*"),
    re.compile(r"#define [A-Za-z][A-Za-z0-9_]*( .*)?"),
    re.compile(r"#endif"),
    re.compile(r'#include "[A-Za-z0-9_]+\.h"'),
    re.compile(r"#include <[a-z0-9_]+\.h>"),
)


def c_code_only(text: str, *, keep_literals: bool = False) -> str:
    """``text`` with every comment replaced by one space and every string or character
    literal by ``""`` (kept as written with ``keep_literals``; newlines kept), for checks on
    the code itself; a
    :class:`ThermocalInputError` when a comment or literal is not closed or a comment holds
    ``/*``.

    Parameters
    ----------
    text : str
        C source text.
    keep_literals : bool
        Keep string and character literals as written instead of ``""``.

    Returns
    -------
    str
        The code with comments blanked.

    Raises
    ------
    ThermocalInputError
        A comment or literal is not closed, or a comment holds ``/*``.
    """
    out: list[str] = []
    i, n = 0, len(text)
    while i < n:
        ch = text[i]
        if text.startswith("/*", i):
            end = text.find("*/", i + 2)
            if end < 0:
                raise ThermocalInputError("generated C: a comment is not closed")
            body = text[i + 2 : end]
            if "/*" in body:
                raise ThermocalInputError("generated C: '/*' inside a comment")
            out.append(" " + "\n" * body.count("\n"))
            i = end + 2
        elif text.startswith("//", i):
            end = text.find("\n", i)
            i = n if end < 0 else end
            out.append(" ")
        elif ch in "\"'":
            j = i + 1
            while j < n and text[j] != ch:
                if text[j] == "\n":
                    raise ThermocalInputError("generated C: a string literal is not closed")
                j += 2 if text[j] == "\\" else 1
            if j >= n:
                raise ThermocalInputError("generated C: a string literal is not closed")
            out.append(text[i : j + 1] if keep_literals else '""')
            i = j + 1
        else:
            out.append(ch)
            i += 1
    return "".join(out)


def check_generated_c(text: str, what: str = "generated C") -> None:
    """Refuse (:class:`ThermocalInputError`) C text that a name could have steered: a
    character outside printable ASCII and newline, a trigraph, a line splice (backslash
    before a newline, §5.1.1.2), an open comment or literal, ``/*`` inside a comment, or a
    preprocessor line other than those the generators write (``#ifndef NAME``, ``#define
    NAME …``, ``#endif``, ``#include "name.h"``).

    Parameters
    ----------
    text : str
        The whole generated file.
    what : str
        How the message names it (the file's name).

    Raises
    ------
    ThermocalInputError
        The text breaks one of the rules above; the message says which.

    References
    ----------
    ISO/IEC 9899:1999, *Programming languages — C*, §5.1.1.2, §5.2.1.1, §6.4.9, §6.10.

    Examples
    --------
    >>> check_generated_c("int x = 1; /* fine */")
    >>> check_generated_c("int x = 1; /* a */ */", what="gyro.c")
    Traceback (most recent call last):
    ...
    thermocal.errors.ThermocalInputError: gyro.c: '*/' outside a comment
    """
    bad = next((c for c in text if not (" " <= c <= "~" or c == "\n")), None)
    if bad is not None:
        raise ThermocalInputError(f"{what}: character {bad!r} outside printable ASCII")
    if _TRIGRAPH.search(text):
        raise ThermocalInputError(f"{what}: a trigraph ('??' + one of =/'()!<>-)")
    if re.search(r"\\[ \t]*(\n|$)", text):
        raise ThermocalInputError(f"{what}: a backslash at the end of a line")
    code = c_code_only(text, keep_literals=True)
    if "*/" in c_code_only(text):
        raise ThermocalInputError(f"{what}: '*/' outside a comment")
    for ln in code.split("\n"):
        s = ln.strip()
        if s.startswith("#") and not any(d.fullmatch(s) for d in _DIRECTIVES):
            raise ThermocalInputError(f"{what}: unexpected preprocessor line {s[:80]!r}")


def c_names(text: str, prefix: str) -> set[str]:
    """Identifiers of C ``text`` (outside comments and literals) that begin with
    ``prefix + '_'`` in either case: the names a generated module declares under its
    prefix.

    Parameters
    ----------
    text : str
        C source text.
    prefix : str
        The module's prefix, without the trailing ``_``.

    Returns
    -------
    set of str
        The identifiers found, as written.

    Examples
    --------
    >>> sorted(c_names("float gyro_x(float t); /* gyro_y */ int other;", "GYRO"))
    ['gyro_x']
    """
    lo = prefix.lower() + "_"
    return {
        w
        for w in re.findall(r"[A-Za-z_][A-Za-z0-9_]*", c_code_only(text))
        if w.lower().startswith(lo)
    }


__all__ = [
    "CPP_KEYWORDS",
    "C_KEYWORDS",
    "MAX_IDENTIFIER_LEN",
    "MAX_PREFIX_LEN",
    "RESERVED",
    "c_code_only",
    "c_comment",
    "c_identifier",
    "c_names",
    "c_string",
    "check_generated_c",
    "one_line",
]
