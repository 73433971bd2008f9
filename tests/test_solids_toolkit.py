"""The solids toolkit against closed forms: areas, volumes, inertias, containment, round trips.

Every expected value comes from a formula or an independent library (shapely for
areas and containment, the format's own layout for file sizes), never from an
earlier output of the code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
import trimesh

from cadgen.solids import (
    ExportFormatError,
    SolidError,
    SolidInputError,
    circle,
    closed_shell,
    encloses,
    extrude,
    from_trimesh,
    hull_of_circles,
    mass_properties,
    offset_outline,
    segments_for,
    to_trimesh,
    validate_holes,
    validate_outline,
)
from cadgen.export.meshes import assembly_bytes, load_volume, stl_bytes
from kinematics.errors import DesignError

#: Extrusions are exact up to rounding: manifold3d's 2-D engine keeps coordinates
#: to 1e-8 mm, far below this for parts of a few mm and more.
EXACT_RTOL = 1e-9
#: Binary STL and GLB store float32 coordinates: each is rounded by at most
#: 2**-24 relative, and a volume (cubic in them) moves by a few times that.
FLOAT32_VOLUME_RTOL = 1e-6


# ----------------------------------------------------------------- independent formulas


def shoelace(points):
    x, y = np.asarray(points, dtype=float).T
    return 0.5 * abs(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def perimeter(points):
    points = np.asarray(points, dtype=float)
    return float(np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1).sum())


def regular_polygon_area(radius, n):
    return n / 2 * radius ** 2 * math.sin(2 * math.pi / n)


def assert_proper_volume(mesh):
    assert mesh.is_watertight
    assert mesh.is_winding_consistent
    assert mesh.volume > 0


def star(rng, points=23, centre=(0.0, 0.0)):
    """A random star-shaped (hence simple) polygon, counter-clockwise."""
    angles = np.sort(rng.uniform(0, 2 * np.pi, points))
    radii = rng.uniform(5.0, 20.0, points)
    return np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]) + centre


def problem_codes(error):
    return {(problem.path, problem.code) for problem in error.value.problems}


# --------------------------------------------------------------------- extrusion


L_SHAPE = np.array([[0, 0], [30, 0], [30, 8], [8, 8], [8, 25], [0, 25]], dtype=float)
OUTLINES = {
    "L shape": (L_SHAPE, 7.5),
    "L shape clockwise": (L_SHAPE[::-1], 3.0),
    "star": (star(np.random.default_rng(20261121)), 12.0),
    "star far from origin": (star(np.random.default_rng(7), centre=(250.0, -180.0)), 4.25),
}


@pytest.mark.parametrize("outline, height", OUTLINES.values(), ids=OUTLINES.keys())
def test_extruded_polygon_volume_and_area(outline, height):
    mesh = to_trimesh(extrude(outline, height, z0=-2.0), "prism")
    assert_proper_volume(mesh)
    area = shoelace(outline)
    assert mesh.volume == pytest.approx(area * height, rel=EXACT_RTOL)
    assert mesh.area == pytest.approx(2 * area + perimeter(outline) * height, rel=EXACT_RTOL)
    assert mesh.bounds[:, 2] == pytest.approx([-2.0, height - 2.0], abs=1e-12)
    assert mesh.vertices.dtype == np.float64


def test_extruded_polygon_with_holes():
    outer = np.array([[0, 0], [40, 0], [40, 30], [0, 30]], dtype=float)
    holes = [circle(5.0, 37, centre=(10.0, 10.0)),
             np.array([[25, 5], [35, 5], [30, 20]], dtype=float)[::-1],  # clockwise on purpose
             L_SHAPE * 0.2 + (22.0, 22.0)]
    height = 6.0
    plate = extrude(outer, height, holes=holes)
    mesh = to_trimesh(plate, "plate")
    assert_proper_volume(mesh)
    net_area = shoelace(outer) - sum(shoelace(hole) for hole in holes)
    assert mesh.volume == pytest.approx(net_area * height, rel=EXACT_RTOL)
    walls = perimeter(outer) + sum(perimeter(hole) for hole in holes)
    assert mesh.area == pytest.approx(2 * net_area + walls * height, rel=EXACT_RTOL)
    # Holes are through holes: a pin down a hole's axis, taller than the plate, misses it.
    pin = extrude(circle(1.0, 8, centre=(10.0, 10.0)), height + 2.0, z0=-1.0)
    assert (plate ^ pin).is_empty()
    assert not (plate ^ pin.translate((5.0, 0.0, 0.0))).is_empty()  # beside the hole it hits


@pytest.mark.parametrize("segments", [8, 64, 1000])
def test_extruded_regular_polygon_matches_closed_form(segments):
    radius, height = 17.5, 3.2
    mesh = to_trimesh(extrude(circle(radius, segments, centre=(3.0, -4.0)), height), "disc")
    assert_proper_volume(mesh)
    assert mesh.volume == pytest.approx(regular_polygon_area(radius, segments) * height, rel=EXACT_RTOL)


def test_closed_input_is_accepted_and_made_counter_clockwise():
    clockwise_closed = np.vstack([L_SHAPE[::-1], L_SHAPE[-1]])
    outline = validate_outline(clockwise_closed, "part.outline")
    assert len(outline) == len(L_SHAPE)
    assert shapely.LinearRing(outline).is_ccw
    assert set(map(tuple, outline)) == set(map(tuple, L_SHAPE))


# ------------------------------------------------------------------------ errors


BOWTIE = np.array([[0, 0], [10, 10], [10, 0], [0, 10]], dtype=float)


def test_bowtie_is_refused_and_the_crossing_located():
    with pytest.raises(DesignError) as error:
        extrude(BOWTIE, 5.0, path="solids.face_width")
    assert problem_codes(error) == {("solids.face_width", "self_intersecting_outline")}
    message = error.value.problems[0].message
    assert "(5, 5) mm" in message  # the diagonals of the bowtie cross at its centre
    assert "one lobe" in message


def test_zero_height_is_refused():
    with pytest.raises(DesignError) as error:
        extrude(L_SHAPE, 0.0, path="solids.face_width")
    assert problem_codes(error) == {("solids.face_width", "face_width_not_positive")}


def test_all_problems_are_reported_together():
    with pytest.raises(DesignError) as error:
        extrude(BOWTIE, float("nan"), path="solids.face_width", outline_path="gears.central.outline")
    assert problem_codes(error) == {("gears.central.outline", "self_intersecting_outline"),
                                    ("solids.face_width", "face_width_not_positive")}


def test_non_finite_point_is_refused():
    outline = L_SHAPE.copy()
    outline[3, 1] = np.nan
    with pytest.raises(DesignError) as error:
        validate_outline(outline, "part.outline")
    assert problem_codes(error) == {("part.outline", "not_finite")}
    assert "index 3" in error.value.problems[0].message


@pytest.mark.parametrize("points, code", [
    ([[0, 0], [1, 0]], "too_few_points"),
    ([[0, 0], [1, 1], [2, 2], [3, 3]], "degenerate_outline"),
    ([[0, 0], [4, 0], [4, 0], [0, 3]], "duplicate_points"),
    ([[0, 0], [4, 0], [4, 4], [2, 0], [0, 4]], "self_intersecting_outline"),  # touches itself at (2, 0)
], ids=["two points", "collinear", "repeated point", "touching itself"])
def test_bad_outlines_get_their_codes(points, code):
    with pytest.raises(DesignError) as error:
        validate_outline(points, "p")
    assert problem_codes(error) == {("p", code)}


def test_hole_outside_and_overlapping_holes_are_refused():
    outer = np.array([[0, 0], [20, 0], [20, 20], [0, 20]], dtype=float)
    outside = np.array([[18, 5], [25, 5], [25, 9], [18, 9]], dtype=float)
    touching = np.array([[0, 12], [3, 12], [3, 15]], dtype=float)  # on the outline's edge x = 0
    first = circle(3.0, 16, centre=(8.0, 8.0))
    second = circle(3.0, 16, centre=(11.0, 8.0))
    with pytest.raises(DesignError) as error:
        validate_holes(outer, [outside, touching, first, second], "plate.holes")
    assert problem_codes(error) == {("plate.holes[0]", "hole_outside_outline"),
                                    ("plate.holes[1]", "hole_outside_outline"),
                                    ("plate.holes[3]", "holes_overlap")}
    with pytest.raises(DesignError) as error:
        extrude(outer, 2.0, holes=[outside], path="plate.thickness", outline_path="plate.outline")
    assert problem_codes(error) == {("plate.outline.holes[0]", "hole_outside_outline")}


def test_empty_boolean_result_is_an_error():
    block = extrude(L_SHAPE, 2.0)
    with pytest.raises(SolidError) as error:
        to_trimesh(block - block, "nothing left")
    assert error.value.invariant == "not_empty"
    assert "nothing left" in str(error.value)


def test_open_mesh_is_refused():
    box = trimesh.creation.box((1.0, 2.0, 3.0))
    open_box = trimesh.Trimesh(box.vertices, box.faces[:-1], process=False)
    with pytest.raises(SolidError) as error:
        from_trimesh(open_box, "open box")
    assert error.value.invariant == "watertight"


def test_from_trimesh_keeps_the_volume():
    solid = from_trimesh(trimesh.creation.box((1.0, 2.0, 3.0)))
    assert solid.volume() == pytest.approx(6.0, rel=EXACT_RTOL)


# ------------------------------------------------------------------------ shapes


CIRCLES = np.array([[0.0, 0.0, 10.0], [30.0, 5.0, 6.0], [12.0, -20.0, 3.0], [2.0, 1.0, 2.0]])


def circle_samples(circles, count=720):
    # Includes the tangency angles 2 pi k / n of every tested segment count, where
    # a circumscribed polygon touches its circle.
    angles = 2 * np.pi * np.arange(count) / count
    rings = circles[:, None, :2] + circles[:, 2, None, None] * np.stack([np.cos(angles), np.sin(angles)], -1)
    return rings.reshape(-1, 2)


@pytest.mark.parametrize("segments", [6, 16, 200])
def test_hull_of_circles_contains_every_disc(segments):
    hull = hull_of_circles(CIRCLES, segments)
    polygon = shapely.Polygon(hull)
    assert polygon.is_valid and shapely.LinearRing(hull).is_ccw
    assert polygon.area == pytest.approx(polygon.convex_hull.area, rel=1e-12)  # convex
    assert shapely.covers(polygon, shapely.points(circle_samples(CIRCLES))).all()


@pytest.mark.parametrize("segments", [8, 16, 200, 4000])
def test_hull_of_two_equal_circles_is_a_polygonal_stadium(segments):
    # The hull of two copies of the circumscribed n-gon r G is the Minkowski sum of
    # the centre segment (length d) and r G, whose area is area(r G) + d * width:
    # for n a multiple of 4, G has edges tangent at 90 and 270 degrees, width 2 r.
    radius, distance = 5.0, 20.0
    hull = hull_of_circles([(0.0, 0.0, radius), (distance, 0.0, radius)], segments)
    area = shapely.Polygon(hull).area
    polygon_area = segments * radius ** 2 * math.tan(math.pi / segments)
    assert area == pytest.approx(polygon_area + 2 * radius * distance, rel=1e-12)
    stadium = math.pi * radius ** 2 + 2 * radius * distance
    # ... which tends to the stadium from above, with the circumscribed polygon's excess.
    excess = radius ** 2 * (segments * math.tan(math.pi / segments) - math.pi)
    assert 0 < area - stadium <= excess + 1e-12 * stadium  # slack: rounding of the areas


def test_offset_outline_contains_the_exact_offset():
    square = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], dtype=float)
    distance, segments = 2.0, 64
    grown = shapely.Polygon(offset_outline(square, distance, segments))
    # Exact offset boundary: the sides moved out by d, and quarter circles of radius d.
    t = np.linspace(0, 1, 101)
    sides = np.concatenate([np.column_stack([10 * t, np.full_like(t, -distance)]),
                            np.column_stack([10 * t, np.full_like(t, 10 + distance)]),
                            np.column_stack([np.full_like(t, -distance), 10 * t]),
                            np.column_stack([np.full_like(t, 10 + distance), 10 * t])])
    corners = circle_samples(np.array([[x, y, distance] for x in (0, 10) for y in (0, 10)]))
    assert shapely.covers(grown, shapely.points(np.concatenate([sides, corners]))).all()
    # Between the exact offset's area and that of the offset by d / cos(pi / n).
    enlarged = distance / math.cos(math.pi / segments)
    exact = 100 + 40 * distance + math.pi * distance ** 2
    assert exact < grown.area <= 100 + 40 * enlarged + math.pi * enlarged ** 2


@pytest.mark.parametrize("radius, tolerance", [(1.0, 0.01), (50.0, 0.01), (200.0, 0.001)])
def test_segments_for_is_the_fewest_within_tolerance(radius, tolerance):
    count = segments_for(radius, tolerance, minimum=3)
    assert radius * (1 / math.cos(math.pi / count) - 1) <= tolerance
    assert radius * (1 / math.cos(math.pi / (count - 1)) - 1) > tolerance


def test_shape_helpers_check_their_arguments():
    with pytest.raises(SolidInputError):
        circle(-1.0, 16)
    with pytest.raises(ValueError):  # SolidInputError is a ValueError too
        hull_of_circles([(0.0, 0.0, 1.0)], 2)


# ------------------------------------------------------------------------ housing


GEARS = np.array([[0.0, 0.0, 20.0], [45.0, 0.0, 25.0]])  # swept discs: centres and tip radii
CLEARANCE, WALL, HEIGHT, SEGMENTS = 1.0, 2.0, 10.0, 96


@pytest.fixture(scope="module")
def housing():
    return closed_shell(GEARS, height=HEIGHT, clearance=CLEARANCE, wall=WALL, segments=SEGMENTS,
                        path="gearbox_2.housing")


def gear(radius, height, z0, centre):
    return extrude(circle(radius, SEGMENTS), height, z0=z0).translate((centre[0], centre[1], 0.0))


def test_closed_shell_is_a_hollow_watertight_box(housing):
    mesh = to_trimesh(housing.solid, "gearbox 2 housing")
    assert_proper_volume(mesh)
    outer_area = shapely.Polygon(housing.outer_outline).area
    cavity_area = shapely.Polygon(housing.cavity_outline).area
    expected = outer_area * (HEIGHT + 2 * WALL) - cavity_area * HEIGHT
    assert mesh.volume == pytest.approx(expected, rel=EXACT_RTOL)
    assert mesh.bounds[:, 2] == pytest.approx([-WALL, HEIGHT + WALL], abs=1e-12)
    # One body with a void: two closed surfaces (outside, cavity), Euler characteristic 4.
    assert len(mesh.split(only_watertight=False)) == 2
    assert mesh.euler_number == 4


def test_closed_shell_wall_is_nowhere_thinner_than_asked(housing):
    cavity = shapely.Polygon(housing.cavity_outline)
    outer = shapely.Polygon(housing.outer_outline)
    assert outer.contains_properly(cavity)
    assert cavity.distance(outer.exterior) >= WALL * (1 - 1e-12)
    # and the cavity keeps the clearance round every swept disc
    grown = GEARS + [0.0, 0.0, CLEARANCE]
    assert shapely.covers(cavity, shapely.points(circle_samples(grown))).all()


def test_single_gear_shell_volume_closed_form():
    # One disc: both outlines are regular circumscribed n-gons about r + c and r + c + w.
    r, n = 12.0, 24
    housing = closed_shell([(5.0, 5.0, r)], height=HEIGHT, clearance=CLEARANCE, wall=WALL, segments=n,
                           z_cavity_bottom=3.0)

    def area(radius):
        return n * radius ** 2 * math.tan(math.pi / n)
    expected = area(r + CLEARANCE + WALL) * (HEIGHT + 2 * WALL) - area(r + CLEARANCE) * HEIGHT
    assert to_trimesh(housing.solid, "single").volume == pytest.approx(expected, rel=EXACT_RTOL)


def test_gears_at_their_discs_are_enclosed(housing):
    for cx, cy, r in GEARS:
        assert encloses(housing, gear(r, HEIGHT - 1.0, 0.5, (cx, cy))) == (True, 0.0)
    # Touching the floor and the ceiling (coplanar faces) still counts as inside.
    enclosed, outside = encloses(housing, gear(GEARS[1, 2], HEIGHT, 0.0, GEARS[1, :2]))
    assert enclosed and outside == pytest.approx(0.0, abs=1e-6)


def test_gear_cutting_into_the_side_wall_is_caught(housing):
    cx, cy, r = GEARS[1]
    radius = r + CLEARANCE + WALL / 2
    enclosed, outside = encloses(housing, gear(radius, HEIGHT - 1.0, 0.5, (cx, cy)))
    assert not enclosed
    disc = shapely.Polygon(circle(radius, SEGMENTS, centre=(cx, cy)))
    expected = disc.difference(shapely.Polygon(housing.cavity_outline)).area * (HEIGHT - 1.0)
    assert outside == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("height, z0, sticking", [
    (HEIGHT + 2.0, -1.0, 2.0),            # into the floor and the ceiling, not through
    (HEIGHT + 10.0, -5.0, 10.0),          # through the housing: out on both sides
], ids=["into the walls", "through the housing"])
def test_gear_taller_than_the_cavity_is_caught(housing, height, z0, sticking):
    cx, cy, r = GEARS[0]
    enclosed, outside = encloses(housing, gear(r, height, z0, (cx, cy)))
    assert not enclosed
    assert outside == pytest.approx(regular_polygon_area(r, SEGMENTS) * sticking, rel=EXACT_RTOL)


def test_closed_shell_rejects_thin_walls_and_negative_clearance():
    with pytest.raises(DesignError) as error:
        closed_shell(GEARS, height=HEIGHT, clearance=1.0, wall=0.5, segments=32, path="gearbox_2.housing",
                     min_wall=1.0)
    assert problem_codes(error) == {("gearbox_2.housing.wall", "wall_too_thin")}
    assert "0.5 mm" in str(error.value) and "minimum is 1 mm" in str(error.value)
    with pytest.raises(DesignError) as error:
        closed_shell(GEARS, height=HEIGHT, clearance=-0.2, wall=0.0, segments=32, path="h")
    assert problem_codes(error) == {("h.wall", "wall_too_thin"), ("h.clearance", "clearance_negative")}


# ----------------------------------------------------------------- mass properties


STEEL = 7850.0  # kg/m^3


@pytest.mark.parametrize("segments", [24, 720])
def test_cylinder_mass_properties(segments):
    radius, height = 20.0, 10.0
    offset = np.array([150.0, -80.0, 40.0])  # far from the origin on purpose
    solid = extrude(circle(radius, segments), height, z0=-height / 2).translate(tuple(offset))
    properties = mass_properties(to_trimesh(solid, "cylinder"), STEEL)

    # Exact for the prism of a regular n-gon (circumradius R, theta = 2 pi / n):
    # each centre triangle's polar moment is A_t R^2 (2 + cos theta) / 6, and a
    # regular polygon's second moment of area is isotropic (I_x = I_y = J / 2).
    theta = 2 * math.pi / segments
    volume = regular_polygon_area(radius, segments) * height
    mass = volume * STEEL * 1e-9  # mm^3 -> m^3
    axial = mass * radius ** 2 * (2 + math.cos(theta)) / 6
    transverse = axial / 2 + mass * height ** 2 / 12
    assert properties["volume_mm3"] == pytest.approx(volume, rel=EXACT_RTOL)
    assert properties["mass_kg"] == pytest.approx(mass, rel=EXACT_RTOL)
    assert properties["centre_of_mass_mm"] == pytest.approx(offset, abs=1e-9)
    inertia = properties["inertia_kg_mm2"]
    assert np.diag(inertia) == pytest.approx([transverse, transverse, axial], rel=EXACT_RTOL)
    assert np.abs(inertia - np.diag(np.diag(inertia))).max() <= 1e-9 * axial

    # Against the true cylinder (m r^2 / 2, m (3 r^2 + h^2) / 12): the n-gon's mass
    # falls short by the area ratio and its radius of gyration by (2 + cos theta) / 3,
    # so the relative gap is bounded by the sum of the two deficits.
    area_deficit = 1 - regular_polygon_area(radius, segments) / (math.pi * radius ** 2)
    tolerance = area_deficit + (1 - (2 + math.cos(theta)) / 3)
    cylinder_mass = math.pi * radius ** 2 * height * STEEL * 1e-9
    assert inertia[2, 2] == pytest.approx(cylinder_mass * radius ** 2 / 2, rel=tolerance)
    assert inertia[0, 0] == pytest.approx(cylinder_mass * (3 * radius ** 2 + height ** 2) / 12, rel=tolerance)


def test_box_mass_properties_and_rotated_tensor():
    a, b, c = 30.0, 12.0, 5.0
    density = 1240.0  # PLA
    box = extrude([[0, 0], [a, 0], [a, b], [0, b]], c)
    mass = a * b * c * density * 1e-9
    properties = mass_properties(to_trimesh(box, "box"), density)
    expected = np.diag([mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12, mass * (a * a + b * b) / 12])
    assert properties["mass_kg"] == pytest.approx(mass, rel=EXACT_RTOL)
    assert properties["area_mm2"] == pytest.approx(2 * (a * b + b * c + a * c), rel=EXACT_RTOL)
    assert properties["centre_of_mass_mm"] == pytest.approx([a / 2, b / 2, c / 2], abs=1e-12)
    assert properties["inertia_kg_mm2"] == pytest.approx(expected, abs=1e-12 * mass * a * a)

    # Rotating the body rotates the tensor: I' = R I R^T (off-diagonals included).
    rotation = trimesh.transformations.rotation_matrix(0.7, [1.0, 2.0, -0.5])
    turned = mass_properties(to_trimesh(box.transform(rotation[:3, :]), "turned box"), density)
    R = rotation[:3, :3]
    assert turned["inertia_kg_mm2"] == pytest.approx(R @ expected @ R.T, abs=1e-9 * mass * a * a)


def test_mass_needs_a_positive_density():
    mesh = to_trimesh(extrude(L_SHAPE, 1.0), "l")
    with pytest.raises(ValueError):
        mass_properties(mesh, 0.0)


# ------------------------------------------------------------------------ export


@pytest.fixture(scope="module")
def parts(housing):
    gear_a = to_trimesh(gear(20.0, 8.0, 1.0, (0.0, 0.0)), "gear a")
    gear_b = to_trimesh(extrude(circle(25.0, SEGMENTS), 8.0, holes=[circle(4.0, 32)], z0=1.0), "gear b")
    shell = to_trimesh(housing.solid, "housing")
    placed = trimesh.transformations.rotation_matrix(0.3, [0, 0, 1], point=[0, 0, 0])
    placed[:3, 3] = [45.0, 0.0, 0.0]
    return [("housing", shell, np.eye(4)), ("gear a", gear_a, np.eye(4)), ("gear b", gear_b, placed)]


def test_stl_round_trip_and_determinism(parts):
    _, mesh, _ = parts[0]
    data = stl_bytes(mesh)
    assert len(data) == 84 + 50 * len(mesh.faces)  # binary STL: header, count, 50 bytes per facet
    assert load_volume(data, "stl") == pytest.approx(mesh.volume, rel=FLOAT32_VOLUME_RTOL)
    rebuilt = to_trimesh(closed_shell(GEARS, height=HEIGHT, clearance=CLEARANCE, wall=WALL,
                                      segments=SEGMENTS).solid, "housing")
    assert stl_bytes(mesh) == data
    assert stl_bytes(rebuilt) == data


def test_glb_round_trip_and_determinism(parts):
    data = assembly_bytes(parts, "glb")
    total = sum(mesh.volume for _, mesh, _ in parts)  # rigid placements keep volumes
    assert load_volume(data, "glb") == pytest.approx(total, rel=FLOAT32_VOLUME_RTOL)
    copies = [(name, mesh.copy(), transform.copy()) for name, mesh, transform in parts]
    assert assembly_bytes(copies, "glb") == data
    scene = trimesh.load_scene(trimesh.util.wrap_as_stream(data), file_type="glb")
    assert sorted(scene.graph.nodes_geometry) == sorted(name for name, _, _ in parts)
    moved = scene.graph["gear b"][0]
    in_metres = parts[2][2].copy()
    in_metres[:3, 3] *= 1e-3          # glTF's unit is the metre: the placement is too
    assert moved == pytest.approx(in_metres, abs=1e-12)


def test_three_mf_is_deterministic_and_round_trips(parts):
    # lxml and networkx are core dependencies (pyproject.toml), so 3MF is always there
    data = assembly_bytes(parts, "3mf")
    assert assembly_bytes(parts, "3mf") == data
    assert load_volume(data, "3mf") == pytest.approx(sum(m.volume for _, m, _ in parts), rel=1e-9)


def test_assembly_checks_its_input(parts):
    with pytest.raises(ExportFormatError):
        assembly_bytes(parts, "step")
    with pytest.raises(SolidInputError, match="unique"):
        assembly_bytes([parts[1], parts[1]], "glb")
