"""The one cleaner (grading/shown.py): what it keeps matters as much as what it removes; the
hostile strings through every sink are tests/grading/test_hostile.py's."""
import pytest

from grading import shown


def test_names_and_lines_are_kept():
    name = "Zoë Ñúñez, \u0645\u06cc\u0631\u0627, 李小龍, Ελένη 👩 (0042)"
    assert shown.clean(name) == name
    assert shown.clean("render.cpp:3:1: error\n  3 | x") == "render.cpp:3:1: error\n  3 | x"


@pytest.mark.parametrize("text,expected", [
    ("\x1b[2Kfake", "\\x1b[2Kfake"), ("a\r\nb", "a\nb"), ("a\rb", "a\\x0db"),
    ("a\tb", "a b"), ("x\u202ey", "x\\u202ey"), ("x\ud800y", "x\\ud800y")])
def test_controls_are_shown_escaped(text, expected):
    assert shown.clean(text) == expected


@pytest.mark.parametrize("value,expected", [
    (3, 3), ("1.91", "1.91"), ("-0.5", "-0.5"), ("=1+1", "'=1+1"), ("-2+3", "'-2+3"),
    ("@SUM(A1)", "'@SUM(A1)"), ("\t=1", "'=1"), ("a\nb", "a b"), ("", "")])
def test_cells_never_start_a_formula(value, expected):
    assert shown.cell(value) == expected


# Each shows nothing, so two names differing by one look alike on the class page: zero-width
# space, non-joiner and joiner, word joiner, BOM, soft hyphen, Mongolian vowel separator,
# invisible times, the deprecated format characters, tags (assigned and not), private use,
# a variation selector and a Hangul filler.
INVISIBLE = ["\u200b", "\u200c", "\u200d", "\u2060", "\ufeff", "\u00ad", "\u180e", "\u2062",
             "\u206a", "\u206f", "\U000e0000", "\U000e0001", "\U000e0041", "\U000e007f",
             "\ue000", "\U000f0000", "\ufe0f", "\u3164"]


@pytest.mark.parametrize("ch", INVISIBLE, ids=[f"U+{ord(c):04X}" for c in INVISIBLE])
def test_invisible_characters_are_shown_escaped(ch):
    cleaned = shown.clean(f"Ada{ch}Lovelace")
    assert ch not in cleaned and cleaned.isascii(), repr(cleaned)
    assert shown.line(f"Ada{ch}") != shown.line("Ada") and ch not in shown.html(ch)
