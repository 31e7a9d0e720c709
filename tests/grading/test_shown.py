"""The one cleaner (grading/shown.py): what it keeps matters as much as what it removes; the
hostile strings through every sink are tests/grading/test_hostile.py's."""
import pytest

from grading import shown


def test_names_and_lines_are_kept():
    name = "Zoë Ñúñez, \u0645\u06cc\u200c\u0631\u0627 (0042)"  # a Persian name keeps its ZWNJ
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
