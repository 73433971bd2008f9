"""Gear hubs: the bore with its keyway or D-flat, the rim it leaves, and its way into DXF and STL.

Independent sources: closed-form areas (circle, circle segments, the keyway's rectangle beyond
the circle); the keyway's width and depth and the flat's chord measured on the polygon with
shapely; a brute-force point-to-segment distance (numpy) for the rim; the DXF read back with
ezdxf; the STL's volume against shapely's areas times the face width.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

ezdxf = pytest.importorskip("ezdxf")
shapely = pytest.importorskip("shapely")
import shapely.affinity  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from cadgen.export.dxf import CUTTING_LAYERS, write_gear_dxf  # noqa: E402
from cadgen.export.train_sheet import write_train_sheet  # noqa: E402
from cadgen.gears.pairs import circle_pair, generate_pair  # noqa: E402
from cadgen.gears.teeth import GearProfile, ToothSystem  # noqa: E402
from cadgen.gears.trains import GearStage, GearTrain  # noqa: E402
from cadgen.machine.hubs import (KEYWAY_TIE_TOLERANCE, MIN_RIM_MODULES,  # noqa: E402
                                 WARN_RIM_MODULES, best_keyway_angle, hub_hole, hub_train,
                                 rim_check, rim_thickness)
from cadgen.machine.model import Drivetrain, GearMount, KeySize, Shaft  # noqa: E402
from cadgen.solids.extrude import to_trimesh  # noqa: E402
from cadgen.solids.parts import gear_solid  # noqa: E402

#: DIN 6885-1 parallel keys: (shaft over, up to) -> (b, h, t1, t2, l), mm.
DIN_KEYS = [((6, 8), KeySize(2, 2, 1.2, 1.0, 6)), ((8, 10), KeySize(3, 3, 1.8, 1.4, 8)),
            ((10, 12), KeySize(4, 4, 2.5, 1.8, 10)), ((12, 17), KeySize(5, 5, 3.0, 2.3, 10)),
            ((17, 22), KeySize(6, 6, 3.5, 2.8, 14)), ((22, 30), KeySize(8, 7, 4.0, 3.3, 18)),
            ((30, 38), KeySize(10, 8, 5.0, 3.3, 22)), ((38, 44), KeySize(12, 8, 5.0, 3.3, 28)),
            ((44, 50), KeySize(14, 9, 5.5, 3.8, 36)), ((50, 58), KeySize(16, 10, 6.0, 4.3, 45))]
KEY_20 = KeySize(6, 6, 3.5, 2.8, 10)


def key_for(diameter):
    return next(key for (low, high), key in DIN_KEYS if low < diameter <= high)


def segment_area(radius, distance):
    """Area of the circle's part beyond a chord ``distance`` from its centre."""
    return radius**2 * math.acos(distance / radius) - distance * math.sqrt(radius**2 - distance**2)


def along(points, angle):
    """Coordinates along the direction ``angle`` and across it."""
    u = np.array([math.cos(angle), math.sin(angle)])
    v = np.array([-u[1], u[0]])
    return points @ u, points @ v


# --------------------------------------------------------------------------- the hole


KEY_CASES = {"20 mm, 6x6": (20.0, KEY_20, 0.0, 0.0, 0.3),
             "20 mm, allowances": (20.0, KEY_20, 0.05, 0.04, 2.0),
             "40 mm, 12x8": (40.0, key_for(40.0), 0.02, 0.1, -1.2)}


@pytest.mark.parametrize("diameter, key, bore, slot, angle", KEY_CASES.values(), ids=KEY_CASES)
def test_keyway_hole_area_width_and_depth(diameter, key, bore, slot, angle):
    hole = hub_hole(diameter, key=key, bore_allowance=bore, key_slot_allowance=slot, angle=angle,
                    segments=4096)
    radius, half = (diameter + bore) / 2, (key.width + slot) / 2
    bottom = diameter / 2 + key.hub_depth + slot / 2
    corner = math.sqrt(radius**2 - half**2)
    area = math.pi * radius**2 - segment_area(radius, corner) + 2 * half * (bottom - corner)
    polygon = shapely.Polygon(hole)
    assert polygon.area == pytest.approx(area, rel=1e-6)   # inscribed 4096-gon arcs: ~4e-7
    # depth on the centre line, width across it beyond the circle: shapely line cuts
    u = np.array([math.cos(angle), math.sin(angle)])
    v = np.array([-u[1], u[0]])
    centre_line = polygon.intersection(shapely.LineString([-2 * bottom * u, 2 * bottom * u]))
    assert along(np.asarray(centre_line.coords), angle)[0].max() == pytest.approx(bottom, abs=1e-12)
    middle = (corner + bottom) / 2 * u
    across = polygon.intersection(shapely.LineString([middle - radius * v, middle + radius * v]))
    assert across.length == pytest.approx(key.width + slot, abs=1e-12)
    # the corners are exact: on the circle and on the keyway's sides
    x, y = along(hole, angle)
    sides = np.isclose(np.abs(y), half, atol=1e-12) & (x < bottom - 1e-9)
    assert sides.sum() == 2 and np.allclose(np.hypot(x[sides], y[sides]), radius, atol=1e-12)


FLAT_CASES = {"8 mm, 0.5 flat": (8.0, 0.5, 0.0, 0.0), "12 mm, 1.0 flat": (12.0, 1.0, 0.03, 2.5)}


@pytest.mark.parametrize("diameter, flat, bore, angle", FLAT_CASES.values(), ids=FLAT_CASES)
def test_d_flat_hole_area_and_chord(diameter, flat, bore, angle):
    hole = hub_hole(diameter, flat_depth=flat, bore_allowance=bore, angle=angle, segments=4096)
    radius, chord = (diameter + bore) / 2, diameter / 2 - flat + bore / 2
    assert shapely.Polygon(hole).area == pytest.approx(
        math.pi * radius**2 - segment_area(radius, chord), rel=1e-6)
    x, y = along(hole, angle)
    assert x.max() == pytest.approx(chord, abs=1e-12)
    on_flat = np.isclose(x, chord, atol=1e-12)
    assert np.ptp(y[on_flat]) == pytest.approx(2 * math.sqrt(radius**2 - chord**2), abs=1e-12)
    assert np.allclose(np.hypot(x, y), radius, atol=1e-12)   # every point on the circle


def test_plain_bore_is_a_circle():
    hole = hub_hole(10.0, bore_allowance=0.1, segments=64)
    assert len(hole) == 64 and np.allclose(np.hypot(*hole.T), 5.05, atol=1e-12)
    assert best_keyway_angle(eccentric_outline(), lambda a: hub_hole(10.0, angle=a)) == 0.0


BAD = {"diameter": (dict(diameter=-1.0), "diameter"),
       "diameter nan": (dict(diameter=math.nan), "diameter"),
       "bore_allowance": (dict(bore_allowance=math.inf), "bore_allowance"),
       "angle": (dict(angle=math.nan), "angle"),
       "segments": (dict(segments=3), "segments"),
       "flat too deep": (dict(key=None, flat_depth=10.0), "flat_depth"),
       "flat negative": (dict(key=None, flat_depth=-0.1), "flat_depth"),
       "key too wide": (dict(key=KeySize(21, 6, 3.5, 2.8, 10)), "key"),
       "hub depth": (dict(key=KeySize(6, 6, 3.5, -1.0, 10)), r"key\.hub_depth"),
       "key and flat": (dict(flat_depth=1.0), "key or a D-flat")}


@pytest.mark.parametrize("changes, message", BAD.values(), ids=BAD)
def test_bad_hole_arguments_are_named(changes, message):
    arguments = dict(diameter=20.0, key=KEY_20) | changes
    with pytest.raises(ValueError, match=message):
        hub_hole(arguments.pop("diameter"), **arguments)


@settings(max_examples=60, deadline=None, derandomize=True, database=None)
@given(diameter=st.floats(6.5, 58.0), angle=st.floats(-7.0, 7.0), bore=st.floats(0.0, 0.3),
       slot=st.floats(0.0, 0.2), flat=st.one_of(st.none(), st.floats(0.05, 0.3)),
       segments=st.sampled_from([32, 96, 200]))
def test_hole_is_simple_ccw_and_the_shaft_fits(diameter, angle, bore, slot, flat, segments):
    if flat is None:
        key = key_for(diameter)
        hole = hub_hole(diameter, key=key, bore_allowance=bore, key_slot_allowance=slot,
                        angle=angle, segments=segments)
        # the shaft with its key sitting in its keyseat (t1 deep, h high)
        base = diameter / 2 - key.shaft_depth
        extra = shapely.box(base, -key.width / 2, base + key.height, key.width / 2)
    else:
        depth = flat * diameter / 2
        hole = hub_hole(diameter, flat_depth=depth, bore_allowance=bore, angle=angle,
                        segments=segments)
        extra = None
    ring = shapely.LinearRing(hole)
    polygon = shapely.Polygon(hole)
    assert polygon.is_valid and ring.is_simple and ring.is_ccw
    # the arcs are inscribed segments-gons: the shaft's circle as the inscribed polygon's
    # inradius (what a round bore of the same segments holds too)
    shaft = shapely.Point(0.0, 0.0).buffer(diameter / 2 * math.cos(math.pi / segments) - 1e-9,
                                           quad_segs=64)
    if extra is not None:
        shaft = shaft.union(extra)
    else:
        shaft = shaft.intersection(shapely.box(-diameter, -diameter, diameter / 2 - depth, diameter))
    shaft = shapely.affinity.rotate(shaft, angle, origin=(0, 0), use_radians=True)
    assert polygon.buffer(1e-9).contains(shaft)


# --------------------------------------------------------------------------- the rim


@pytest.fixture(scope="module")
def pair():
    system = ToothSystem(2.0)
    return generate_pair(circle_pair(("pinion", "wheel"), 24.0, 30.0), (24, 30), system=system)


def brute_distance(first, second):
    """Least distance between two closed polylines: every vertex of each against every segment
    of the other (the least distance of two disjoint polylines is at a vertex of one)."""
    def vertex_to_segments(points, ring):
        start, end = ring, np.roll(ring, -1, axis=0)
        edge = end - start
        offset = points[:, None, :] - start[None, :, :]
        t = np.clip(np.einsum("pij,ij->pi", offset, edge) / np.einsum("ij,ij->i", edge, edge), 0, 1)
        return np.linalg.norm(offset - t[..., None] * edge[None], axis=-1).min()
    return min(vertex_to_segments(first, second), vertex_to_segments(second, first))


@pytest.mark.parametrize("angle", [0.0, 0.13, 1.9])
def test_rim_thickness_against_brute_force(pair, angle):
    outline = pair.profiles[0].outline
    hole = hub_hole(20.0, key=KEY_20, angle=angle, segments=96)
    thickness, on_outline, on_hole = rim_thickness(outline, hole)
    assert thickness == pytest.approx(brute_distance(hole, outline), abs=1e-9)
    assert np.linalg.norm(on_outline - on_hole) == pytest.approx(thickness, abs=1e-12)
    # the ends lie on their rings
    assert shapely.LinearRing(outline).distance(shapely.Point(on_outline)) < 1e-9
    assert shapely.LinearRing(hole).distance(shapely.Point(on_hole)) < 1e-9


def test_a_hole_outside_the_outline_is_refused(pair):
    with pytest.raises(ValueError, match="not inside"):
        rim_thickness(pair.profiles[0].outline, hub_hole(44.0, key=key_for(44.0)))


def eccentric_outline(offset=6.0, radius=30.0, teeth=36):
    """A toothed ring about (offset, 0): its root is farthest from the origin towards +x."""
    t = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    r = radius + 1.5 * np.cos(teeth * t)
    return np.column_stack([offset + r * np.cos(t), r * np.sin(t)])


def test_best_keyway_angle_points_to_the_thickest_rim():
    outline = eccentric_outline()
    options = dict(key=KEY_20, segments=96)
    best = best_keyway_angle(outline, lambda a: hub_hole(20.0, angle=a, **options))
    assert abs(np.angle(np.exp(1j * best))) < np.radians(6)   # towards +x, up to a tooth
    rims = [rim_thickness(outline, hub_hole(20.0, angle=a, **options))[0]
            for a in np.linspace(0, 2 * np.pi, 72, endpoint=False)]
    chosen = rim_thickness(outline, hub_hole(20.0, angle=best, **options))[0]
    assert chosen >= max(rims) - 0.05 and chosen > min(rims) + 3.0


def test_a_d_flat_faces_the_nearest_root():
    # the flat leaves more rim than the round part would there: it goes where the rim is least
    best = best_keyway_angle(eccentric_outline(), lambda a: hub_hole(12.0, flat_depth=1.0, angle=a))
    assert abs(np.angle(np.exp(1j * (best - np.pi)))) < np.radians(6)


def _rim_by_direction(outline, hole_fn, steps=720):
    """The radial rim of every scanned direction, as the full (direction x bin) table: the
    hole's radial profile turned bin by bin against the outline's (the scan's definition)."""
    from cadgen.machine.hubs import _polar_bins, _resampled

    hole = np.asarray(hole_fn(0.0))
    outer_bin, outer_radius = _polar_bins(_resampled(np.asarray(outline), steps * 8), steps)
    inner_bin, inner_radius = _polar_bins(_resampled(hole, steps * 8), steps)
    outer = np.full(steps, np.inf)
    np.minimum.at(outer, outer_bin, outer_radius)
    inner = np.zeros(steps)
    np.maximum.at(inner, inner_bin, inner_radius)
    circle = np.median(np.hypot(*hole.T))
    beyond = inner > circle * (1 + 1e-9)
    rim = np.empty(steps)
    for k in range(steps):          # turned by k bins: bin b of the hole lands on b + k
        landed = (np.arange(steps) + k) % steps
        rim[k] = np.min(np.where(beyond, outer[landed] - inner, np.inf))
    return rim


@settings(max_examples=20, deadline=None, derandomize=True, database=None)
@given(offset=st.floats(0.0, 8.0), teeth=st.integers(8, 60), diameter=st.floats(10.0, 24.0))
def test_best_keyway_angle_is_the_first_best_of_every_direction(offset, teeth, diameter):
    outline = eccentric_outline(offset=offset, teeth=teeth)
    def hole(a):
        return hub_hole(diameter, key=key_for(diameter), angle=a)
    rim = _rim_by_direction(outline, hole)
    chosen = best_keyway_angle(outline, hole)
    index = int(round(chosen / (2 * np.pi / 720)))
    assert rim[index] >= rim.max() - KEYWAY_TIE_TOLERANCE
    assert not (rim[:index] >= rim.max() - KEYWAY_TIE_TOLERANCE).any()


def test_a_circular_gears_keyway_takes_the_first_of_its_equal_directions(pair):
    # z teeth: z directions leave the same rim but for rounding; the first one is taken
    for profile in pair.profiles:
        def hole(a):
            return hub_hole(20.0, key=KEY_20, angle=a)
        chosen = best_keyway_angle(profile.outline, hole)
        assert chosen < 2 * np.pi / profile.teeth + 2 * np.pi / 720
        rims = [rim_thickness(profile.outline, hole(chosen + 2 * np.pi * k / profile.teeth))[0]
                for k in range(profile.teeth)]
        assert np.ptp(rims) < 1e-6


def test_the_cutting_outline_is_thinned_once_as_the_contour_thins_it(holed):
    from cadgen.geometry.contour import thin_ring, thinned_contour
    from cadgen.machine.hubs import cutting_outline

    cut = cutting_outline(holed, 0.005)
    expected = thinned_contour(holed.outline, 0.005, centre=holed.centre,
                               bore_radius=holed.hole_reach)
    np.testing.assert_array_equal(cut.outline, expected)
    np.testing.assert_array_equal(cut.pitch, thin_ring(holed.pitch_curve, 0.005)[0])
    assert cut.tolerance_used == 0.005 and not cut.outline.flags.writeable
    assert cutting_outline(holed, 0.005) is cut                # remembered on the profile
    assert cutting_outline(holed, 0.002) is not cut            # per tolerance
    turned = dataclasses.replace(holed, hole=holed.hole.copy())
    assert cutting_outline(turned, 0.005) is not cut           # a changed profile: again


def test_rim_check_levels(pair):
    profile = pair.profiles[1]        # 30 teeth of module 2: root radius 27.5
    cases = {20.0: "", 40.0: "rim_thin", 44.0: "rim_too_thin"}
    for diameter, code in cases.items():
        check = rim_check(profile, hub_hole(diameter, key=key_for(diameter)), path="x")
        assert check.limit == MIN_RIM_MODULES * 2.0 and check.warning_limit == WARN_RIM_MODULES * 2.0
        assert [p.code for p in check.problems] == ([code] if code else [])
        assert check.passed == (code != "rim_too_thin")
        if code:
            assert "wheel" in check.problems[0].message and f"{check.thickness:.2f}" in \
                check.problems[0].message


# --------------------------------------------------------------------------- the train


def mount(gear, diameter, key=None, flat=0.0, allowance=0.0):
    return GearMount(gear, 0.0, 10.0, 1.0, 1.0, diameter, key, flat, allowance)


def test_hub_train_bores_every_carried_gear_once(pair):
    first = GearStage("first", pair, None, (0.0, (0.0, 0.0)))
    second = GearStage("second", pair, None, (0.0, (60.0, 0.0)))   # the same gears again
    train = GearTrain((first, second))
    shaft = Shaft("C2", "gearbox 2", 1, (0, 0), 20.0, 18.0, False, 1.0, 1.0, 1.0,
                  (mount("pinion", 20.0, KEY_20, allowance=0.02),), (), 0.0, 0.0)
    bored, checks = hub_train(train, Drivetrain("planting", (shaft,), {}, "machined"),
                              key_slot_allowance=0.04, segments=96)
    pinions = [stage.generated.profiles[0] for stage in bored.stages]
    assert pinions[0] is pinions[1] and pinions[0].hole is not None
    assert pinions[0].hole_reach == pytest.approx(math.hypot(10 + 2.8 + 0.02, 3.02), abs=1e-9)
    assert [stage.generated.profiles[1].hole for stage in bored.stages] == [None, None]
    assert [c.gear for c in checks] == ["pinion", "wheel"]
    assert checks[0].passed and checks[0].thickness == pytest.approx(
        rim_thickness(pinions[0].outline, pinions[0].hole)[0])
    assert checks[0].problems == ()
    assert [p.code for p in checks[1].problems] == ["hub_not_mounted"]
    assert pair.profiles[0].hole is None          # the input train is left as it was


@pytest.mark.parametrize("length, fails", [(6, False), (16, True)])
def test_a_set_screw_standing_proud_of_its_gear_fails_the_hub_check(pair, length, fails):
    """The pinion (24 teeth of module 2: root radius 21.5, tips 26) on a 20 mm shaft with a
    6 x 6 key (t1 3.5): the key's back 10 - 3.5 + 6 = 12.5 mm out; an M5 x 6 screw ends at
    18.5, inside the roots; an M5 x 16 at 28.5, past the tips."""
    from cadgen.machine.retention import ShaftRetention

    stage = GearStage("first", pair, None, (0.0, (0.0, 0.0)))
    shaft = Shaft("C2", "gearbox 2", 1, (0, 0), 20.0, 18.0, False, 1.0, 1.0, 1.0,
                  (mount("pinion", 20.0, KEY_20),), (), 0.0, 0.0)
    screw = f"set screw ISO 4029 M5 x {length} - 45H"
    held = ShaftRetention("C2", 1, (), (("pinion", screw),))
    _, checks = hub_train(GearTrain((stage,)), Drivetrain("planting", (shaft,), {}, "machined",
                                                          retention=(held,)))
    codes = [p.code for p in checks[0].problems]
    assert ("set_screw_proud" in codes) == fails and checks[0].passed == (not fails)
    if fails:
        assert screw in checks[0].problems[-1].message


# --------------------------------------------------------------------------- files


@pytest.fixture(scope="module")
def holed(pair):
    profile = pair.profiles[0]
    angle = best_keyway_angle(profile.outline, lambda a: hub_hole(20.0, key=KEY_20, angle=a))
    return dataclasses.replace(profile, hole=hub_hole(20.0, key=KEY_20, angle=angle),
                               bore_radius=10.0)


def closed_paths(doc, layer):
    paths = []
    for entity in doc.modelspace().query(f'*[layer=="{layer}"]'):
        assert entity.dxftype() == "LWPOLYLINE" and entity.closed, entity.dxftype()
        paths.append(np.array([point[:2] for point in entity.get_points("xy")]))
    return paths


def test_gear_dxf_holds_outline_and_hole(holed, tmp_path):
    path = tmp_path / "pinion.dxf"
    write_gear_dxf(path, holed)
    doc = ezdxf.readfile(path)
    auditor = doc.audit()
    assert not auditor.has_errors and not auditor.has_fixes
    cutting = [e for e in doc.modelspace() if e.dxf.layer in CUTTING_LAYERS]
    assert len(cutting) == 2
    (outline,), (hole,) = closed_paths(doc, "OUTLINE"), closed_paths(doc, "BORE")
    assert np.allclose(hole, holed.hole, atol=1e-12)
    body = shapely.Polygon(outline)
    assert body.contains(shapely.Polygon(hole))
    assert shapely.LinearRing(outline).distance(shapely.LinearRing(hole)) > MIN_RIM_MODULES * 2.0


def test_train_sheet_turns_the_hole_with_its_gear(holed, tmp_path):
    path = tmp_path / "train.dxf"
    write_train_sheet(path, [(holed, 0.4, (5.0, -3.0))])
    (hole,) = closed_paths(ezdxf.readfile(path), "BORE")
    turned = shapely.affinity.rotate(shapely.Polygon(holed.hole), 0.4, origin=(0, 0),
                                     use_radians=True)
    expected = shapely.affinity.translate(turned, 5.0, -3.0)
    assert shapely.Polygon(hole).symmetric_difference(expected).area < 1e-9


def test_a_hole_crossing_the_outline_is_refused(holed, tmp_path):
    from cadgen.export.dxf import DxfInputError

    broken = dataclasses.replace(holed, hole=hub_hole(46.0, key=key_for(46.0)))
    with pytest.raises(DxfInputError, match="hole"):
        write_gear_dxf(tmp_path / "broken.dxf", broken)
    assert not (tmp_path / "broken.dxf").exists()


def test_gear_stl_with_hole_is_watertight_with_the_right_volume(holed):
    solid, outline = gear_solid(holed, 8.0, 64, "gears.face_width", 0.005)
    mesh = to_trimesh(solid, "pinion")
    assert mesh.is_watertight
    area = shapely.Polygon(outline).area - shapely.Polygon(holed.hole).area
    assert mesh.volume == pytest.approx(8.0 * area, rel=1e-6)


def test_profile_without_hole_keeps_its_bore():
    profile = GearProfile("plain", np.array([[0, 0], [1, 0], [0, 1.0]]), np.zeros((3, 2)), 3, 1.0,
                          bore_radius=0.1)
    assert profile.hole is None and profile.hole_reach == 0.1
