"""ISO 286-1 limit deviations and the process fits, against the standard's tables."""

import pytest

from cadgen.machine.fits import FitError, deviation, mean_deviation, process_fits, tolerance_grade


@pytest.mark.parametrize("designation, nominal, expected", [
    ("H7", 35, (0.0, 0.025)),        # ISO 286-2: H7 over 30 up to 50 = 0 / +25 um
    ("k6", 20, (0.002, 0.015)),      # k6 over 18 up to 30 = +2 / +15 um
    ("k6", 10, (0.001, 0.010)),      # k6 over 6 up to 10 = +1 / +10 um
    ("k6", 100, (0.003, 0.025)),     # k6 over 80 up to 120 = +3 / +25 um
    ("g6", 20, (-0.020, -0.007)),    # g6 over 18 up to 30 = -7 / -20 um
    ("h7", 50, (-0.025, 0.0)),       # h7 over 30 up to 50 = -25 / 0 um
    ("H7", 18, (0.0, 0.018)),        # 18 belongs to the step over 10 up to 18
    ("js6", 20, (-0.0065, 0.0065)),  # IT6 = 13 um, symmetric
    ("JS9", 20, (-0.026, 0.026)),    # IT9 = 52 um (the hub keyway of DIN 6885 normal fit)
], ids=lambda v: str(v))
def test_limit_deviations_are_iso_286s(designation, nominal, expected):
    lower, upper = deviation(designation, nominal)
    assert lower == pytest.approx(expected[0], abs=1e-12)
    assert upper == pytest.approx(expected[1], abs=1e-12)


def test_h7_at_35_is_exact():
    assert deviation("H7", 35) == (0.0, 0.025)
    assert tolerance_grade(7, 35) == 0.025


@pytest.mark.parametrize("designation, nominal", [("H7", 0), ("H7", 121), ("F7", 20),
                                                  ("H5", 20), ("k", 20)])
def test_outside_the_subset_is_refused_with_the_value(designation, nominal):
    with pytest.raises(FitError, match="not|outside"):
        deviation(designation, nominal)


def test_printed_process_allowances():
    fits = process_fits("printed")
    assert fits.seat_allowance(47.0) == 0.10
    assert fits.hub_allowance(20.0) == 0.20
    assert fits.running_clearance == 1.2
    assert fits.key_slot_allowance == 0.20
    assert fits.backlash == 0.20
    assert fits.bolt_hole_series == "medium" and fits.bolt_hole_extra == 0.2
    assert fits.material("gear") == ("PETG", 1270.0, "printed")
    assert fits.material("shaft").name == "steel C45"


def test_machined_process_sits_in_the_middle_of_h7():
    fits = process_fits("machined")
    # H7 over 30 up to 50 is 0 / +25 um: its middle +12.5 um
    assert fits.seat_allowance(47.0) == pytest.approx(0.0125)
    assert fits.hub_allowance(20.0) == pytest.approx(mean_deviation("H7", 20.0)) == 0.0105
    assert fits.key_slot_allowance == 0.0 and fits.backlash == 0.05
    assert fits.material("housing") == ("aluminium EN AW-6082", 2700.0, "machined")
    assert fits.material("planter").name == "steel S235"


@pytest.mark.parametrize("process, hub, backlash, gear", [
    ("laser", 0.05, 0.10, "steel S355"), ("edm", 0.0105, 0.03, "steel C45")],
    ids=["laser", "edm"])
def test_cut_plate_processes(process, hub, backlash, gear):
    fits = process_fits(process)
    assert fits.hub_allowance(20.0) == pytest.approx(hub)
    assert fits.backlash == backlash
    assert fits.seat_allowance(47.0) == pytest.approx(0.0125)   # housings machined
    assert fits.material("gear").name == gear
    assert fits.material("housing").process == "machined"


def test_unknown_process_is_named():
    with pytest.raises(FitError, match="'cast'"):
        process_fits("cast")
