"""The one cleaner of every string a hand-in or an export controls, before any screen shows it.

A compiler's message quotes the hand-in's code, a test's output quotes its stderr, a batch
names students by their folders and Gradescope's export by what they typed: any of them can
hold a terminal escape that repaints the screen (a fake `100/100` line), a cell a spreadsheet
runs as a formula, or markup. So everything on its way to results.json, a terminal, the HTML
pages, grades.csv or a Slurm script passes `clean` here; the sinks differ only in what they
add on top: `line` for one line, `cell` for a spreadsheet, `html` for a page.
"""
from __future__ import annotations

import html as _html
import unicodedata

# Characters that show nothing yet are not format characters: the variation selectors, the
# combining grapheme joiner, Mongolian free variation selectors, Khmer's inherent vowels and
# the Hangul fillers (Unicode's Default_Ignorable_Code_Point, less the Cf ones). Two names
# differing only by them look alike.
INVISIBLE = {*map(chr, (0x034F, 0x115F, 0x1160, 0x17B4, 0x17B5, 0x180B, 0x180C, 0x180D,
                        0x180F, 0x3164, 0xFFA0)),
             *map(chr, range(0xFE00, 0xFE10)), *map(chr, range(0xE0100, 0xE01F0))}
# Categories shown escaped: controls (Cc), format characters (Cf: zero-width spaces and
# joiners, bidi overrides that show one text and hold another, the BOM, soft hyphens,
# invisible operators, tags), surrogates (Cs), private use
# (Co), unassigned code points (Cn: the tag block's unassigned ones, and whatever this
# Python's Unicode tables do not know yet), line and paragraph separators (Zl, Zp).
ESCAPED_CATEGORIES = ("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp")
# Cells a spreadsheet reads as a formula (or, tab and CR, as the start of another cell).
FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def _escaped(ch: str) -> str:
    code = ord(ch)
    return (f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000
            else f"\\U{code:08x}")


def clean(text: object) -> str:
    """`text` as plain visible characters and newlines: every other control character
    (escapes, carriage returns, backspaces, bells), every format, private-use, unassigned or
    otherwise invisible character (bidi overrides, zero-width spaces and joiners), surrogates
    and line separators shown escaped (`\\x1b`, `\\u200b`), a tab as a space, CR LF as LF."""
    out = []
    for ch in str(text).replace("\r\n", "\n"):
        if ch == "\n":
            out.append(ch)
        elif ch == "\t":
            out.append(" ")
        elif ch in INVISIBLE or unicodedata.category(ch) in ESCAPED_CATEGORIES:
            out.append(_escaped(ch))
        else:
            out.append(ch)
    return "".join(out)


def line(text: object) -> str:
    """`clean`, on one line: a terminal's progress line, a cause, a Slurm directive."""
    return " ".join(clean(text).split("\n")).strip()


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return text.strip() == text


def cell(value: object) -> object:
    """A CSV cell: numbers as they are; text on one line, and text a spreadsheet would start
    a formula with led by an apostrophe, which it shows as text."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return value
    text = line(value)
    if text.startswith(FORMULA_START) and not _is_number(text):
        return "'" + text
    return text


def html(text: object) -> str:
    """`clean`, then HTML-escaped (quotes too: attribute values take it)."""
    return _html.escape(clean(text), quote=True)
