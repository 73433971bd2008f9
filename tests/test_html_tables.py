"""The report page's number rule (cadgen.report.html_tables), case by case.

Each expectation is worked by hand from the rule docs/report.md states: lengths to
0.001 mm, angles to 0.01 deg, other quantities to 4 significant digits, a stated accuracy's
leading digit as the last one shown, and never more than 6 significant digits.
"""

from __future__ import annotations

import pytest

from cadgen.report.html_tables import _number, _prose, _quantity, _to_accuracy


@pytest.mark.parametrize("value, unit, shown", [
    (57.848864106474366, "mm", "57.849 mm"),          # a length: 0.001 mm
    (17.602244394936363, "deg", "17.60 deg"),         # an angle: 0.01 deg
    (0.7608862134784933, "", "0.7609"),               # a ratio: 4 significant digits
    (1.0060518093946527, "", "1.006"),
    (1.0, "", "1"),                                   # a whole number reads as one
    (3600, "", "3600"),                               # an integer as it is
    (1.5197e-4, "mm", "0.000152 mm"),                 # rounds to 0 at 0.001: 3 digits
    (7.105427357601002e-15, "mm", "7.11e-15 mm"),
    (1e-13, "rad", "1e-13 rad"),
    (12345.6789, "mm", "12345.7 mm"),                 # 0.001 mm would be 8 digits: 6
], ids=["length", "angle", "ratio", "coefficient", "whole", "integer", "small", "tiny",
        "tolerance", "long"])
def test_a_quantity_by_its_unit(value, unit, shown):
    assert _quantity(value, unit) == shown


def test_significant_digits_and_the_cap():
    # a rating life of 21,534,745 h to 3 significant digits: 21,500,000
    assert _number(21534745.3, significant=3) == "21500000"
    assert _number(123456789.0, 0) == "123457000"     # never more than 6 significant digits
    assert _number(-541.0021374980898, 9) == "-541.002"
    assert _number(True) == "yes" and _number(None) == "—"


@pytest.mark.parametrize("value, error, unit, shown", [
    (191772.6, 0.00071 * 191772.6, "mm³", "191800"),  # error 136 mm³: hundreds
    (1.5054, 0.00071 * 1.5054, "kg", "1.505"),        # error 0.0011 kg: grams
    (2.5, 5e-6, "mm", "2.500"),                       # finer than 0.001 mm: the unit's rule
    (191772.6, None, "mm³", "191773"),                # no stated accuracy: the unit's rule
], ids=["volume", "mass", "finer", "none"])
def test_a_value_to_its_stated_accuracy(value, error, unit, shown):
    assert _to_accuracy(value, error, unit) == shown


@pytest.mark.parametrize("text, shown", [
    ("true minimum in [57.848863, 57.848864] mm", "true minimum in 57.849 ± 5.0e-07 mm"),
    ("true minimum in [-1.2345678e-05, 1.23456789]", "true minimum in [-1.23e-05, 1.23457]"),
    ("a radius of 0.91 mm (module 2.000), 1234.56789 mm", "a radius of 0.91 mm (module 2.000), "
                                                          "1234.57 mm"),
    ("three.js 0.187.0, bearing 6002, hash 123456789abcdef", "three.js 0.187.0, bearing 6002, "
                                                             "hash 123456789abcdef"),
], ids=["interval", "wide-interval", "long-number", "not-numbers"])
def test_free_text_keeps_to_six_significant_digits(text, shown):
    assert _prose(text) == shown
