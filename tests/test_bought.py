"""Bought parts as solids: their shapes against the catalogue by hand, their places against the
features cut for them, the overlap check's fits, and the sweeps seeing them.

The counts against the bill of materials are in tests/test_bom.py (a real build of each
example, read back from bom.csv and the assembly file).
"""

import math
import re

import numpy as np
import pytest
import shapely

from cadgen.solids.bought import (BoughtItem, BoughtPart, bought_mesh, bought_parts,
                                  bought_solid, fits_part, item_frame, register_maker, registered_kinds)
from cadgen.solids.outline import signed_area

from helpers import REFERENCE

SEGMENTS = 96


def _polygon(radius, sides=SEGMENTS):
    """The area of the inscribed regular polygon of a circle (the solids' circles)."""
    return sides / 2 * radius**2 * math.sin(2 * math.pi / sides)


# ------------------------------------------------------------------ shapes, by hand
def test_an_iso_4762_m6_x_20_screw_is_its_tables_head_and_shank():
    from cadgen.machine.catalogue import socket_screw

    row = socket_screw("M6")
    dk, k, d, length = row["head_diameter"], row["head_height"], 6.0, 20.0
    assert (dk, k) == (10.0, 6.0)          # ISO 4762, M6: dk max 10, k max 6
    mesh = bought_mesh("socket head cap screw",
                       {"d": d, "length": length, "head_diameter": dk, "head_height": k},
                       SEGMENTS)
    assert mesh.is_watertight
    np.testing.assert_allclose(mesh.bounds, [[-dk / 2, -dk / 2 * math.sin(math.pi / 2), -length],
                                             [dk / 2, dk / 2, k]], atol=1e-9)
    # the hand calculation: two cylinders, pi/4 (dk^2 k + d^2 l); the mesh's polygons are
    # inscribed, so it is smaller by their area's ratio (0.07 % at 96 sides), exactly
    assert mesh.volume == pytest.approx(_polygon(dk / 2) * k + _polygon(d / 2) * length,
                                        rel=1e-7)
    assert mesh.volume == pytest.approx(math.pi / 4 * (dk**2 * k + d**2 * length), rel=1e-3)


def test_a_6202_bearing_is_a_ring_of_its_bore_outside_and_width():
    from cadgen.machine.catalogue import bearings

    row = next(b for b in bearings() if b.designation == "6202")
    assert (row.bore, row.outside, row.width) == (15.0, 35.0, 11.0)
    mesh = bought_mesh("bearing", {"bore": 15.0, "outside": 35.0, "width": 11.0}, SEGMENTS)
    assert mesh.volume == pytest.approx(math.pi / 4 * (35.0**2 - 15.0**2) * 11.0, rel=1e-3)
    assert mesh.volume == pytest.approx((_polygon(17.5) - _polygon(7.5)) * 11.0, rel=1e-7)
    np.testing.assert_allclose(mesh.extents, [35.0, 35.0 * math.cos(math.pi / SEGMENTS * 0), 11.0],
                               atol=1e-9)


@pytest.mark.parametrize("kind, size, volume", [
    # ISO 4032 M3: s 5.5, m 2.4; a regular hexagon across flats s is sqrt(3)/2 s^2
    ("hexagon nut", {"d": 3.0, "s": 5.5, "m": 2.4},
     (math.sqrt(3) / 2 * 5.5**2 - _polygon(1.5)) * 2.4),
    # ISO 7089 6: d1 6.4, d2 12, h 1.6
    ("plain washer", {"d1": 6.4, "d2": 12.0, "h": 1.6}, (_polygon(6.0) - _polygon(3.2)) * 1.6),
    # DIN 6885 A 5 x 5 x 25, a plain box
    ("key", {"width": 5.0, "height": 5.0, "length": 25.0}, 625.0),
    # ISO 8734 3 x 8 in its 48-sided reamed hole's polygon
    ("dowel pin", {"diameter": 3.0, "length": 8.0, "sides": 48}, _polygon(1.5, 48) * 8.0),
    # ISO 4027 M4 x 4: a cone point of 90 deg (height d/2) and the rest a cylinder
    ("set screw", {"d": 4.0, "length": 4.0}, _polygon(2.0) * (2.0 + 2.0 / 3.0)),
    # ISO 4029 M4 x 6, cup point: its envelope, a cylinder
    ("set screw", {"d": 4.0, "length": 6.0, "point": "cup"}, _polygon(2.0) * 6.0),
    ("retaining ring", {"inner": 14.0, "outer": 21.0, "thickness": 1.0},
     _polygon(10.5) - _polygon(7.0)),
    ("spring", {"outside": 10.0, "wire": 1.0, "length": 20.0},
     (_polygon(5.0) - _polygon(4.0)) * 20.0),
    ("roller", {"outside": 6.0, "width": 3.0, "bore": 2.0}, (_polygon(3.0) - _polygon(1.0)) * 3.0),
    # ISO 2341 B 5 x 24: head dk 8, k 1.6 on the 5 mm shank, 24 long from under the head
    ("clevis pin", {"d": 5.0, "length": 24.0, "head_diameter": 8.0, "head_height": 1.6},
     _polygon(4.0) * 1.6 + _polygon(2.5) * 24.0),
    # ISO 1234 1.2 x 10: legs d max 1.0 together, 10 long; the eye a block c max 2.0 square,
    # d thick
    ("split pin", {"d": 1.0, "c": 2.0, "length": 10.0}, 2.0 * 2.0 * 1.0 + _polygon(0.5) * 10.0),
    # ISO 8738 5: d1 5, d2 10, h 1
    ("washer", {"d1": 5.0, "d2": 10.0, "h": 1.0}, _polygon(5.0) - _polygon(2.5)),
    # ISO 2338 4 m6 x 12
    ("parallel pin", {"diameter": 4.0, "length": 12.0}, _polygon(2.0) * 12.0),
    # EN 13906-1 d 0.9, D 9.9: the coil's tube from D + d = 10.8 to D - d = 9.0
    ("compression spring", {"outside": 10.8, "wire": 0.9, "length": 11.6},
     (_polygon(5.4) - _polygon(4.5)) * 11.6),
], ids=lambda v: v if isinstance(v, str) else "")
def test_each_catalogue_kind_has_its_closed_form_volume(kind, size, volume):
    mesh = bought_mesh(kind, size, SEGMENTS)
    assert mesh.is_watertight and mesh.is_winding_consistent
    # manifold3d's sections lie on a 1e-8 mm grid: the volumes agree to about that
    assert mesh.volume == pytest.approx(volume, rel=1e-7)


def test_a_new_kind_is_one_registered_maker_and_a_wrong_one_is_named():
    from cadgen.solids.bought_makers import ring

    assert {"bearing", "key", "socket head cap screw", "hexagon nut", "plain washer",
            "dowel pin", "set screw", "retaining ring", "pin", "spring",
            "roller", "clevis pin", "split pin", "washer", "parallel pin",
            "compression spring"} <= set(registered_kinds())
    import cadgen.solids.bought as bought

    register_maker("test spacer ring", lambda size, segments: ring(
        size["inner"], size["outer"], size["width"], segments))
    try:
        solid = bought_solid("test spacer ring", {"inner": 10.0, "outer": 14.0, "width": 3.0},
                             64)
        assert solid.volume() == pytest.approx((_polygon(7.0, 64) - _polygon(5.0, 64)) * 3.0)
        with pytest.raises(ValueError, match="have a maker already"):
            register_maker("test spacer ring", lambda size, segments: None)
    finally:
        bought._MAKERS.pop("test spacer ring")
    with pytest.raises(ValueError, match="no maker for bought items of kind 'flux capacitor'"):
        bought_solid("flux capacitor", {}, 64)
    with pytest.raises(ValueError, match="length must be a finite length > 0"):
        bought_solid("pin", {"diameter": 3.0, "length": -1.0}, 64)


@pytest.mark.parametrize("axis", [(0, 0, 1), (0, 0, -1), (1, 0, 0), (0.3, -0.4, 0.5)])
def test_an_items_frame_puts_its_z_on_the_axis(axis):
    frame = item_frame((1.0, 2.0, 3.0), axis, turn=0.7)
    unit = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    np.testing.assert_allclose(frame[:3, 2], unit, atol=1e-12)
    np.testing.assert_allclose(frame[:3, :3] @ frame[:3, :3].T, np.eye(3), atol=1e-12)
    assert np.linalg.det(frame[:3, :3]) == pytest.approx(1.0)
    np.testing.assert_allclose(frame[:3, 3], [1.0, 2.0, 3.0])


def test_a_bolt_stack_sits_on_the_faces_it_clamps_by_hand():
    from cadgen.solids.bought_places import bolt_stack

    # an M4 bolt through 20 mm of flange: washers 0.8, nut 3.2, the screw the bill's length
    items = bolt_stack(item_frame((5.0, 6.0, 0.0)), 10.0, -10.0, "M4", 20.0)
    kinds = [item.kind for item in items]
    assert kinds == ["plain washer", "socket head cap screw", "plain washer", "hexagon nut"]
    z = {kind + str(k): float(item.at[2, 3]) for k, (kind, item) in enumerate(zip(kinds, items))}
    assert z["plain washer0"] == 10.0 and z["socket head cap screw1"] == 10.8
    assert z["plain washer2"] == -10.8 and z["hexagon nut3"] == -10.8 - 3.2
    screw = items[1]
    # ISO 4762 M4 x 30: 20 + 2 x 0.8 + 3.2 + 2 x 0.7 = 26.2 mm needed, 30 the next length
    assert screw.designation == "ISO 4762 M4 x 30 - 8.8" and screw.size["length"] == 30.0
    assert 10.8 - 30.0 < -10.8 - 3.2            # its end stands out of the nut
    assert len({item.stack for item in items}) == 1 and items[0].stack


# ------------------------------------------------------------------ places, against the cuts
@pytest.fixture(scope="module")
def planting():
    """The paper's design to its solids as a build makes them (the gears cut and bored, the
    cam screwed on)."""
    from cadgen.pipeline.build import STAGE_FUNCTIONS, _Build
    from cadgen.params import load_params

    params = load_params(REFERENCE)
    run = _Build(params, ["kinematics", "metrics", "cam", "drivetrain", "teeth", "parts"], None)
    run.effects, run.case = ["solids"], "field"
    run.run(STAGE_FUNCTIONS)
    return params, run.values


def _world_axis(pose):
    return pose[:3, 3], pose[:3, 2]


def _line_distance(point, direction, other_point, other_direction) -> float:
    """Distance between two parallel lines (their directions checked parallel)."""
    assert abs(abs(float(np.dot(direction, other_direction))) - 1.0) < 1e-12
    offset = np.asarray(other_point) - np.asarray(point)
    return float(np.linalg.norm(offset - np.dot(offset, direction) * direction))


@pytest.mark.parametrize("phi", [0.0, 1.9])
def test_each_bearing_is_coaxial_with_its_shaft(planting, phi):
    _, values = planting
    assembly = values["parts"].assembly
    world = {name: pose for name, _, pose in assembly.placements(phi, bought=True)}
    shafts = {part.name: part for part in assembly.parts if part.kind == "shaft"}
    # (the cam roller runs on its pin in the lever: tests/test_duckbill.py)
    bearings = [part for part in assembly.bought if part.kind == "bearing"
                and part.host != "lever"]
    assert len(bearings) >= 10
    for part in bearings:
        # its shaft's copies (a shaft with its own part for arm 2 fits both)
        copies = [copy for shaft in shafts.values() if fits_part(shaft.name, part.fitted)
                  for copy, _, _ in shaft.instances or ((shaft.name, None, None),)]
        assert copies, part.name
        for name, _, _ in part.instances:
            point, direction = _world_axis(world[name])
            nearest = min(_line_distance(point, direction, *_world_axis(world[copy]))
                          for copy in copies)
            assert nearest < 1e-6, (name, shaft.name, nearest)


def _hole_centres(solid, z: float, diameter: float) -> np.ndarray:
    """Centres of the round holes of ``diameter`` (within 2 % of its area) in a section."""
    polygons = [shapely.Polygon(loop) for loop in solid.slice(z).to_polygons()]
    area = math.pi * diameter**2 / 4
    return np.array([np.asarray(p.centroid.coords[0]) for p in polygons
                     if abs(abs(signed_area(np.asarray(p.exterior.coords)[:-1])) - area)
                     < 0.02 * area])


def _axis_through(centres, point, direction, z):
    """The screw's axis at height ``z`` (its host frame) and the nearest hole centre's gap."""
    at = point + (z - point[2]) / direction[2] * direction
    return float(np.min(np.linalg.norm(centres - at[:2], axis=1)))


def test_each_flange_screw_passes_through_its_holes_centre(planting):
    params, values = planting
    outcome = values["parts"]
    parts = {part.name: part for part in outcome.assembly.parts}
    from cadgen.machine.catalogue import clearance_hole
    from cadgen.machine.fits import process_fits

    fits = process_fits(params.manufacturing.process)
    checked = 0
    for name, housing in outcome.housings.items():
        base = parts[f"{name}-base"]
        screws = [part for part in outcome.assembly.bought
                  if part.host == base.name and part.kind == "socket head cap screw"]
        assert len(screws) == len(housing.bolt_positions) >= 4
        # the holes as cut: a section of each half through its flange
        low, high = housing.flange_z
        hole = clearance_hole(housing.bolt_size, fits.bolt_hole_series) + fits.bolt_hole_extra
        for half, z in (("base", 0.5 * (low + housing.parting_z)),
                        ("cover", 0.5 * (housing.parting_z + high))):
            centres = _hole_centres(parts[f"{name}-{half}"].solid, z, hole)
            assert len(centres) == len(housing.bolt_positions)
            for screw in screws:
                at = screw.local(0.0)          # in the housing's frame (its local is the eye)
                assert _axis_through(centres, at[:3, 3], at[:3, 2], z) < 1e-6
                checked += 1
    assert checked >= 2 * (4 + 4 + 4)


def test_the_tapped_screws_pass_through_their_tapped_holes(planting):
    """The cam's screws in the cover roof's tapped holes, the hollow shaft C's in gearbox 2's
    floor's: each screw's axis through a tapped hole's centre, in the world (arm 1's housing:
    the screws of its cam and of the shaft C that carries it; the others are arm 2's)."""
    from cadgen.machine.fixings import TAP_DRILL

    _, values = planting
    assembly = values["parts"].assembly
    world = {name: pose for name, _, pose in assembly.placements(0.0, bought=True)}
    parts = {part.name: part for part in assembly.parts}
    housing = values["parts"].housings["gearbox2"]
    cases = [("cam", "gearbox2-cover", housing.z_top - 1.0, 3),
             ("shaft-C", "gearbox2-base", housing.z_bottom + 1.0, 6)]
    for host, into, z, count in cases:
        screws = [part for part in assembly.bought
                  if part.host == host and part.kind == "socket head cap screw"]
        thread = re.search(r"(M\d+)", screws[0].designation).group(1)
        centres = _hole_centres(parts[into].solid, z, TAP_DRILL[thread])
        assert len(centres) == count
        into_pose = world[f"{into}-arm1"]
        gaps = []
        for screw in screws:
            for name, _, _ in screw.instances:
                local = np.linalg.solve(into_pose, world[name])   # in arm 1's housing
                gaps.append(_axis_through(centres, local[:3, 3], local[:3, 2], z))
        gaps = np.array(gaps)
        assert np.count_nonzero(gaps < 1e-6) == count, (host, np.sort(gaps)[:count + 1])
        assert np.all((gaps < 1e-6) | (gaps > 10.0))      # the others are far: arm 2's


def test_each_key_fills_its_keyseat_and_its_gears_keyway(planting):
    """A key in its keyseat shares no material with its shaft (their faces coincide), stands
    h - t1 out of it (DIN 6885), and shares none with its gear's hub either (first copies;
    the overlap check takes every copy): measured on the placed solids at two poses."""
    from cadgen.machine.catalogue import key_for_shaft
    from cadgen.solids.overlaps import VOLUME_FLOOR

    assembly = planting[1]["parts"].assembly
    parts = {part.name: part for part in assembly.parts}
    keys = [part for part in assembly.bought if part.kind == "key"]
    assert len(keys) >= 15           # every keyed gear's, the planter's, the input stub's
    for key in keys:
        shaft = parts[key.host]
        b, h, length = (float(v) for v in re.findall(r"[\d.]+", key.designation)[-3:])
        np.testing.assert_allclose(sorted(key.mesh.extents), sorted([b, h, length]), atol=1e-12)
        for phi in (0.0, 0.8):
            local = np.linalg.solve(shaft.local(phi), key.local(phi))   # in the shaft's frame
            assert (key.solid.transform(local[:3, :]) ^ shaft.solid).volume() <= VOLUME_FLOOR
            corners = key.mesh.vertices @ local[:3, :3].T + local[:3, 3]
            # the shaft's radius where the key sits (its polygon's corners are on the circle)
            span = (shaft.mesh.vertices[:, 2] >= corners[:, 2].min()) & (
                shaft.mesh.vertices[:, 2] <= corners[:, 2].max())
            radius = float(np.hypot(*shaft.mesh.vertices[span, :2].T).max())
            depth = key_for_shaft(round(2 * radius, 6)).shaft_depth
            assert np.hypot(corners[:, 0], corners[:, 1]).max() == pytest.approx(
                np.hypot(radius - depth + h, b / 2), abs=1e-8)
            gears = [parts[name] for name in key.fitted if name != key.host and name in parts]
            for gear in gears:
                world = {name: pose for name, _, pose in assembly.placements(phi, bought=True)}
                placed_key = key.solid.transform(world[key.instances[0][0]][:3, :])
                placed_gear = gear.solid.transform(world[gear.instances[0][0]][:3, :])
                assert (placed_key ^ placed_gear).volume() <= VOLUME_FLOOR, (key.name, gear.name)


def test_each_ring_sits_in_its_groove_on_its_shafts_axis(planting):
    """A DIN 471 ring rides with its shaft, coaxial, its bore on the groove's bottom: the
    shaft's least radius over the ring's height is d2 / 2 of the standard's table (d 15: d2
    14.3, s 1; d 20: 19, 1.2), and the ring is s thick; every shaft with a ring in its stack
    has it as a solid."""
    table = {12.0: (11.5, 1.0), 15.0: (14.3, 1.0), 17.0: (16.2, 1.0), 20.0: (19.0, 1.2),
             25.0: (23.9, 1.2), 30.0: (28.6, 1.5)}   # DIN 471: d1 -> (d2, s)
    assembly = planting[1]["parts"].assembly
    parts = {part.name: part for part in assembly.parts}
    rings = [part for part in assembly.bought if part.kind == "retaining ring"
             and parts[part.host].kind == "shaft"]   # (the lever's roller pin has one too)
    held = planting[1]["drivetrain"].retention
    # one ring solid per ring of each shaft part: a gearbox-2 shaft's two sides are one part,
    # C2's are two (side 2 has its own, shaft-C2-arm2)
    own = {(r.shaft + ("-arm2" if r.side == 2 and r.shaft == "C2" else ""), k)
           for r in held for k in range(len(r.rings))}
    assert len(rings) == len(own) > 5
    for ring in rings:
        shaft = parts[ring.host]
        d1 = float(re.search(r"DIN 471 (\d+)", ring.designation).group(1))
        d2, s = table[d1]
        local = np.linalg.solve(shaft.local(0.3), ring.local(0.3))   # in the shaft's frame
        np.testing.assert_allclose(local[:3, 2], [0.0, 0.0, 1.0], atol=1e-12)
        np.testing.assert_allclose(local[:2, 3], [0.0, 0.0], atol=1e-9)
        corners = ring.mesh.vertices @ local[:3, :3].T + local[:3, 3]
        low, high = corners[:, 2].min(), corners[:, 2].max()
        assert high - low == pytest.approx(s, abs=1e-9)
        # the shaft's section through the ring's middle: the groove's bottom, no larger
        section = np.vstack(shaft.solid.slice(0.5 * (low + high)).to_polygons())
        assert np.hypot(*section.T).max() == pytest.approx(d2 / 2, abs=1e-6), ring.name
        assert np.hypot(*corners[:, :2].T).min() == pytest.approx(d2 / 2, abs=1e-6)


def test_a_set_screw_is_drilled_on_its_keyways_line_and_bears_on_the_keys_back(planting):
    """A gear held by a set screw (ISO 4029, cup point): the screw's axis is radial along the
    keyway's centre line in the middle of the face, its point at the key's back (DIN 6885:
    d/2 - t1 + h from the axis: C 30 mm, key 8 x 7, t1 4: 18 mm), its thread in a tap-drilled
    hole of the gear (ISO 2306: M5 4.2 mm) whose axis has no material, and its far end inside
    the gear's outline."""
    from cadgen.machine.catalogue import key_for_shaft
    from cadgen.solids.extrude import manifold3d_engine

    m3d = manifold3d_engine()
    values = planting[1]
    assembly, drivetrain = values["parts"].assembly, values["drivetrain"]
    parts = {part.name: part for part in assembly.parts}
    screws = [part for part in assembly.bought if part.kind == "set screw"]
    assert {s.host for s in screws} == {"train-1-planet", "transmission-driven-gear"}
    drills = {"M5": 4.2, "M6": 5.0}
    names = {gear.replace(" ", "-"): gear for r in drivetrain.retention for gear, _ in r.set_screws}
    for screw in screws:
        gear = parts[screw.host]
        shaft, mount = drivetrain.shaft_of_gear(names[gear.name])
        key = key_for_shaft(shaft.diameter)
        thread, length = re.search(r"(M\d+) x (\d+)", screw.designation).groups()
        at = np.linalg.solve(gear.local(0.0), screw.local(0.0))   # in the gear's frame
        axis, point = at[:3, 2], at[:3, 3]
        assert axis[2] == pytest.approx(0.0, abs=1e-12)
        assert point[2] == pytest.approx(mount.face_width / 2, abs=1e-9)
        assert point[0] * axis[1] - point[1] * axis[0] == pytest.approx(0.0, abs=1e-9)  # radial
        assert np.hypot(*point[:2]) == pytest.approx(
            shaft.diameter / 2 - key.shaft_depth + key.height, abs=1e-9)
        # the gear's material along the screw: none within the tap drill's radius, all round
        # it just outside (the thread's), from the bore to the screw's far end
        far = point + axis * float(length)

        def rod(radius):
            return m3d.Manifold.cylinder(float(length), radius, radius, 48).transform(
                at[:3, :])

        drill = drills[thread] / 2
        assert (gear.solid ^ rod(drill - 0.02)).volume() < 1e-6, screw.name
        shell = (gear.solid ^ rod(drill + 0.3)).volume()
        assert shell == pytest.approx(math.pi * ((drill + 0.3) ** 2 - drill**2) * float(length),
                                      rel=0.05), screw.name
        outline = shapely.Polygon(gear.outline)
        assert outline.contains(shapely.Point(*far[:2])), screw.name


# ------------------------------------------------------------------ the overlap check's fits
def _plate_and_screw(head_face: float, *, tapped: bool = False, fitted=("plate",)):
    """A 10 mm plate with an M6 hole (clearance, or a 5.0 mm tap drill through), an ISO 4762
    M6 x 16 screw in it with its head's face at ``head_face``."""
    from cadgen.solids.bought_places import tapped_screws
    from cadgen.solids.extrude import manifold3d_engine
    from cadgen.solids.parts import Assembly, Part

    m3d = manifold3d_engine()
    hole = 2.5 if tapped else 3.3
    plate = (m3d.Manifold.cube((40.0, 40.0, 10.0)).translate((-20.0, -20.0, 0.0))
             - m3d.Manifold.cylinder(12.0, hole, hole, 48).translate((0.0, 0.0, -1.0)))
    host = Part("plate", "housing", "frame", plate,
                bought=tuple(tapped_screws("M6", 16.0, [(0.0, 0.0)], head_face, up=False,
                                           fitted=fitted[1:])))
    if not tapped:
        host.bought = tuple(BoughtItem(item.kind, item.designation, item.size, item.at,
                                       item.label, item.fitted, 0.0) for item in host.bought)
    parts = [host]
    assembly = Assembly(parts, lambda body, phi: np.eye(4), None,
                        bought=bought_parts(parts, SEGMENTS))
    return assembly


def test_a_screw_in_its_hole_passes_and_its_head_sunk_in_the_wall_fails():
    from cadgen.solids.overlaps import overlap_check

    seated = overlap_check(_plate_and_screw(10.0), segments=SEGMENTS)
    assert seated["passed"] and seated["overlaps"] == [] and seated["pairs_examined"] == 1
    sunk = overlap_check(_plate_and_screw(9.0), segments=SEGMENTS)
    [overlap] = sunk["overlaps"]
    assert not sunk["passed"] and overlap["b"] == "bought/screw-M6x16-1"
    # the head's last millimetre inside the plate, round the 6.6 mm hole
    assert overlap["volume_mm3"] == pytest.approx(_polygon(5.0) - _polygon(3.3, 48), rel=1e-9)
    assert "plate and bought/screw-M6x16-1 share" in sunk["failures"][0]


def test_a_screws_thread_in_a_tapped_hole_is_its_fit_and_no_deeper():
    from cadgen.solids.bought_places import thread_depth
    from cadgen.solids.overlaps import overlap_check

    assert thread_depth("M6") == pytest.approx(0.5)        # (6 - 5.0) / 2, ISO 2306's drill
    # the screw's shank (16 mm) in a 10 mm tapped plate from its top: 10 mm of thread shell,
    # its last 6 mm below the plate
    check = overlap_check(_plate_and_screw(10.0, tapped=True), segments=SEGMENTS)
    [overlap] = check["overlaps"]
    assert check["passed"] and overlap["joined"]
    assert overlap["volume_mm3"] == pytest.approx((_polygon(3.0) - _polygon(2.5, 48)) * 10.0,
                                                  rel=1e-6)
    # allowed: the thread's depth and the chord error of a circle as large as the overlap
    # (its box takes in the head's face on the plate: 5 mm)
    assert overlap["thickness_mm"] <= overlap["allowed_mm"] <= 0.5 + 5.0 * (
        1 - math.cos(math.pi / SEGMENTS)) + 1e-9


def test_a_screw_not_fitted_to_what_it_is_in_fails_however_thin():
    """The same thread shell, but the screw is not fitted to the plate (its host is another
    part): the plate and the screw share material no joint allows."""
    from cadgen.solids.extrude import manifold3d_engine
    from cadgen.solids.overlaps import overlap_check
    from cadgen.solids.parts import Assembly, Part

    tapped = _plate_and_screw(10.0, tapped=True)
    plate = tapped.parts[0]
    holder = Part("holder", "housing", "frame",
                  manifold3d_engine().Manifold.cube((1.0, 1.0, 1.0)).translate((50.0, 0, 0)),
                  bought=plate.bought)
    stranger = Part("plate", "housing", "frame", plate.solid)
    parts = [holder, stranger]
    assembly = Assembly(parts, lambda body, phi: np.eye(4), None,
                        bought=bought_parts([holder], SEGMENTS))
    for part in assembly.bought:   # fitted to the holder only
        part.fitted = frozenset({"holder"})
    check = overlap_check(assembly, segments=SEGMENTS)
    assert not check["passed"]
    assert check["overlaps"][0]["joined"] is False


def test_a_bought_solid_buried_whole_in_a_wall_is_found_though_no_surface_crosses():
    """A dowel sunk whole inside the plate (no face of it meets the plate's): the screen's
    parity ray finds it held, and the check fails with the dowel's whole volume."""
    from cadgen.solids.extrude import manifold3d_engine
    from cadgen.solids.overlaps import overlap_check
    from cadgen.solids.parts import Assembly, Part

    plate = manifold3d_engine().Manifold.cube((40.0, 40.0, 10.0)).translate((-20.0, -20.0, 0.0))
    pin = BoughtItem("dowel pin", "ISO 8734 3 x 8 - A - St", {"diameter": 3.0, "length": 8.0},
                     item_frame((5.0, 5.0, 1.0)), "dowel-3x8", ())
    parts = [Part("plate", "housing", "frame", plate, bought=(pin,))]
    assembly = Assembly(parts, lambda body, phi: np.eye(4), None,
                        bought=bought_parts(parts, SEGMENTS))
    check = overlap_check(assembly, segments=SEGMENTS)
    [overlap] = check["overlaps"]
    assert not check["passed"] and overlap["volume_mm3"] == pytest.approx(_polygon(1.5) * 8.0)


def test_the_contact_screen_hides_no_overlap_of_the_paper_design(planting, monkeypatch):
    """The screen only spares booleans: the check with every pair of a bought solid
    intersected (but a stack's own) finds the same overlaps, with the same volumes."""
    import cadgen.solids.contact as contact
    from cadgen.solids.overlaps import overlap_check

    assembly = planting[1]["parts"].assembly
    screened = overlap_check(assembly, segments=SEGMENTS)
    monkeypatch.setattr(contact, "may_overlap", lambda items, pairs, boxes: np.ones(
        len(pairs), dtype=bool))
    every = overlap_check(assembly, segments=SEGMENTS)
    assert screened["pairs_intersected"] < every["pairs_intersected"]

    def found(check):
        return {(o["a"], o["b"]): round(o["volume_mm3"], 6) for o in check["overlaps"]}

    assert found(screened) == found(every)
    assert screened["failures"] == every["failures"]


# ------------------------------------------------------------------ the sweeps
def test_the_arm_sweep_takes_the_bought_solids_of_each_arm(planting):
    from cadgen.pipeline.clearances import _arm_part_bounds, arm_groups

    params, values = planting
    assembly = values["parts"].assembly
    arm1, arm2 = arm_groups(assembly, bought=True)
    made1, _ = arm_groups(assembly)
    riding = [name for name in arm1 if name.startswith("bought/")]
    # gearbox 2's flange bolts (a screw, two washers and a nut each), its dowels and bearings,
    # the keys of D and E, the cam's screws: on each arm
    housing = values["parts"].housings["gearbox2"]
    assert len(riding) >= 4 * len(housing.bolt_positions) + 2 + 3
    assert arm1[:len(made1)] == made1 and len(arm1) == len(arm2)
    copies = {name: part for part in assembly.bought for name, _, _ in part.instances}
    for one, two in zip(arm1, arm2):
        if one in copies:
            assert copies[one] is copies[two]
    parts = {part.name: part for part in assembly.parts}
    bounds = _arm_part_bounds(values["kinematics"], parts, values["cam"], assembly.bought)
    assert {copies[name].name for name in riding} <= set(bounds)
    # a screw head on gearbox 2's flange moves no faster than the flange round it allows
    rc = values["kinematics"].carrier_radii["C"]
    for name in riding:
        speed, acceleration = bounds[copies[name].name]
        assert speed >= rc and acceleration >= rc


def test_a_bought_solid_hanging_under_a_housing_is_what_the_ground_sweep_sees(planting):
    """A pin (a bought item) fixed under gearbox 1's flange, reaching 30 mm further down than
    the housing: the ground clearance falls by about that and names the pin."""
    from types import SimpleNamespace

    from cadgen.pipeline.clearances import ground_clearance

    params, values = planting
    outcome = values["parts"]
    assembly = outcome.assembly
    before = ground_clearance(params, values["kinematics"], outcome, values["metrics"])
    host = next(part for part in assembly.parts if part.name == "gearbox1-base")
    low = host.mesh.bounds[0]
    item = BoughtItem("pin", "test pin", {"diameter": 8.0, "length": 400.0},
                      item_frame((0.0, float(low[1]) + 1.0, float(low[2]) + 4.0), (0, -1, 0)),
                      "pin-test")
    pinned = SimpleNamespace(name=host.name, body=host.body, local=host.local,
                             instances=host.instances, bought=(item,))
    extra = bought_parts([pinned], SEGMENTS)
    assembly.bought = list(assembly.bought) + extra
    try:
        after = ground_clearance(params, values["kinematics"], outcome, values["metrics"])
    finally:
        assembly.bought = assembly.bought[:-1]
    assert "bought/pin-test-1" in after["nearest"]
    assert after["minimum_mm"] < before["minimum_mm"] - 100.0
    assert after["certified"]


def test_every_made_parts_stl_read_back_in_float32_is_closed(planting):
    """The written STL (float32) of every made part, read back and welded as a slicer does, is
    watertight with consistent winding and the solid's volume (drilled set-screw holes and
    pins through curved walls leave slivers that float32 collapses)."""
    import io

    import trimesh

    from cadgen.export.meshes import stl_bytes

    outcome = planting[1]["parts"]
    for part in outcome.assembly.parts:
        if part.kind == "ground":
            continue
        mesh = outcome.printing_mesh(part)
        back = trimesh.load(io.BytesIO(stl_bytes(mesh)), file_type="stl")
        assert back.is_watertight and back.is_winding_consistent, part.name
        assert back.volume == pytest.approx(mesh.volume, rel=1e-5), part.name
