"""The bill of materials against the files a build wrote, and the parts against each other.

One real build of the paper's design (teeth, solids, STL, DXF); every count of bom.csv is
checked against what the written files hold, read back independently: the STL files, the
assembly's nodes (GLB), the bolt holes cut in each housing's flange (a section of its STL),
and the shafts' and gears' axes in the assembly.
"""

import csv
import io
import math
import re
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

import cadgen
from cadgen.params import load_params

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    params = load_params(REPO / "params" / "xin2024-planter.toml")
    root = tmp_path_factory.mktemp("bom")
    result = cadgen.build(params, root, effects=["teeth", "solids", "stl", "dxf"])
    folder = root / params.name
    rows = list(csv.DictReader(io.StringIO((folder / "bom.csv").read_text(encoding="utf-8"))))
    scene = trimesh.load(folder / "solids" / "assembly.glb", force="scene")
    return params, result, folder, rows, scene


@pytest.fixture(scope="module")
def built_pricking(tmp_path_factory):
    params = load_params(REPO / "params" / "kernel-b.toml")
    root = tmp_path_factory.mktemp("bom-pricking")
    cadgen.build(params, root, effects=["teeth", "solids", "stl"])
    folder = root / params.name
    rows = list(csv.DictReader(io.StringIO((folder / "bom.csv").read_text(encoding="utf-8"))))
    return rows, trimesh.load(folder / "solids" / "assembly.glb", force="scene")


#: How a bill row names its item (its standard's words) -> the stem of the assembly's nodes
#: that place it as a solid (``bought/<stem>-<n>``), read here from the designation alone.
_NODE_STEMS = (
    ("bearing", r"(\d+)$", "bearing-{0}-2Z"),
    ("key", r"DIN 6885 A (\d+) x (\d+) x (\d+)$", "key-{0}x{1}x{2}"),
    ("socket head cap screw", r"ISO 4762 (M\d+) x (\d+) - 8\.8$", "screw-{0}x{1}"),
    ("hexagon nut", r"ISO 4032 (M\d+) - 8$", "nut-{0}"),
    ("plain washer", r"ISO 7089 (\d+) - 200 HV$", "washer-M{0}"),
    ("dowel pin", r"ISO 8734 (\d+) x (\d+) - A - St$", "dowel-{0}x{1}"),
    ("set screw", r"ISO 402[79] (M\d+) x (\d+) - 45H$", "set-screw-{0}x{1}"),
    ("retaining ring", r"DIN 471 (\d+) x [\d.]+$", "ring-471-{0}"),
    ("clevis pin", r"ISO 2341 B (\d+) x (\d+) - St$", "clevis-pin-{0}x{1}"),
    ("washer", r"ISO 8738 (\d+) - 160 HV$", "washer-8738-{0}"),
    ("split pin", r"ISO 1234 ([\d.]+) x (\d+) - St$", "split-pin-{0}x{1}"),
    ("parallel pin", r"ISO 2338 (\d+) m6 x (\d+) - St$", "parallel-pin-{0}x{1}"),
    ("compression spring", r"EN 13906-1 ([\d.]+) x ([\d.]+) x [\d.]+ n[\d.]+$",
     "spring-{0}x{1}"),
)


def _placed_solids(scene, row) -> int:
    """The assembly file's nodes placing the bought item of a bill row as a solid."""
    names = list(scene.graph.nodes_geometry)
    if row["part"] == "sprocket":    # bought whole, placed as its envelope under the case
        return sum(1 for n in names if n == "case-sprocket")
    kind, pattern, stem = next(entry for entry in _NODE_STEMS if entry[0] == row["part"])
    found = re.search(pattern, row["designation"])
    assert found, row
    node = re.compile(rf"bought/{re.escape(stem.format(*found.groups()))}-\d+")
    return sum(1 for n in names if node.fullmatch(n))


@pytest.mark.parametrize("which", ["planting", "pricking"])
def test_every_bought_row_is_placed_as_often_as_the_bill_says(which, request):
    """Each bought row of bom.csv (from the assembly model's joints) is as many solids in the
    written assembly file (from the parts that hold them), counted by the designation."""
    if which == "planting":
        _, _, _, rows, scene = request.getfixturevalue("built")
    else:
        rows, scene = request.getfixturevalue("built_pricking")
    bought = [r for r in rows if r["source"] == "buy"]
    kinds = {r["part"] for r in bought}
    assert {"bearing", "key", "socket head cap screw", "dowel pin"} <= kinds
    for row in bought:
        assert _placed_solids(scene, row) == int(row["quantity"]) > 0, row["designation"]
    nodes = [n for n in scene.graph.nodes_geometry if n.startswith("bought/")]
    assert len(nodes) == sum(int(r["quantity"]) for r in bought if r["part"] != "sprocket")


def _instances(scene, part: str) -> int:
    """Nodes of the assembly file placing ``part`` (instance names are ``<part>`` or
    ``<part>-<arm or side>``; a part of its own for arm 2, ``shaft-C2-arm2``, is placed once
    under its own name, and is not a copy of ``shaft-C2``)."""
    names = list(scene.graph.nodes_geometry)
    own = {n for n in names if re.fullmatch(r"shaft-\w+-arm2", n)
           and f"{n[:-len('-arm2')]}-side1" in names}
    return sum(1 for n in names if n == part or (n.startswith(part + "-") and n not in own
                                                  and n[len(part) + 1:].startswith(("arm", "side"))))


def test_every_made_part_is_a_written_file_placed_as_often_as_the_bom_says(built):
    _, _, folder, rows, scene = built
    made = [r for r in rows if r["source"] == "make"]
    stls = sorted(p.name for p in (folder / "solids").glob("*.stl") if p.name != "ground.stl")
    assert sorted(Path(r["file"]).name for r in made) == stls
    for row in made:
        assert int(row["quantity"]) == _instances(scene, row["part"]) > 0, row["part"]
        assert float(row["mass_each_kg"]) > 0


def test_two_bearings_per_shaft_and_their_bores_are_the_shafts(built):
    _, result, _, rows, scene = built
    shafts = [r for r in rows if r["source"] == "make" and r["part"].startswith("shaft-")]
    placed_shafts = sum(_instances(scene, r["part"]) for r in shafts)
    bearings = [r for r in rows if r["part"] == "bearing"]
    machine = result.report["machine"]
    # and two in the hub of each gear that runs free on its shaft (an idler on A and on B),
    # per copy
    free = [h["gear"].replace(" ", "-") for s in machine["shafts"] if s["side"] == 1
            for h in s["hubs"] if h.get("runs_free_on")]
    assert len(free) == 2
    placed_free = sum(_instances(scene, gear) for gear in free)
    # and the duckbill's cam roller, a bearing on each lever's pin
    rollers = _instances(scene, "lever")
    assert rollers == 2
    assert sum(int(r["quantity"]) for r in bearings) == (2 * placed_shafts + 2 * placed_free
                                                         + rollers)
    diameters = {(s["name"], s["side"]): s["diameter_mm"] for s in machine["shafts"]}
    for bearing in machine["bearings"]:
        assert bearing["d_mm"] == diameters[bearing["shaft"], bearing["side"]]


def _bolt_holes(path: Path, z: float, diameter: float) -> int:
    """Round holes of ``diameter`` in the STL's section at height ``z`` of its printing pose."""
    mesh = trimesh.load(path)
    section = mesh.section(plane_origin=[0.0, 0.0, z], plane_normal=[0.0, 0.0, 1.0])
    planar, _ = section.to_2D()
    circle = math.pi * diameter**2 / 4
    # every closed loop of the section whose area is a hole's (a polygon of the hole's circle:
    # within 1 % of its area); the flange's outline and the cavity are far larger
    return sum(1 for loop in planar.discrete
               if abs(shapely.Polygon(loop).area - circle) < 0.01 * circle)


def test_bolts_nuts_and_washers_match_the_holes_in_the_flanges(built):
    params, result, folder, rows, scene = built
    from cadgen.machine.catalogue import clearance_hole
    from cadgen.machine.fits import process_fits

    fits = process_fits(params.manufacturing.process)
    screws, holes = Counter(), Counter()
    for r in rows:
        if r["part"] == "socket head cap screw":
            screws[r["designation"].split()[2]] += int(r["quantity"])   # "ISO 4762 M3 x 16 - 8.8"
    for housing, thread in (("gearbox1", "M3"), ("gearbox2", "M4"), ("frame", "M3")):
        path = folder / "solids" / f"{housing}-base.stl"
        # the base lies on its floor in its printing pose: its flange is at the top, below the
        # parting plane; cut it half a flange below its top face
        mesh = trimesh.load(path)
        top = float(mesh.bounds[1, 2])
        diameter = clearance_hole(thread, fits.bolt_hole_series) + fits.bolt_hole_extra
        found = _bolt_holes(path, top - 0.5, diameter)
        assert found >= 4
        holes[thread] += found * _instances(scene, f"{housing}-base")
    flange_holes = Counter(holes)
    # the flanges that carry gearbox 1 (the sleeve S) and gearbox 2 (the hollow shaft C) are
    # screwed into tapped holes (M6: a 5.0 mm drill, ISO 2306) of their floors; cut 1 mm up
    for housing in ("gearbox1", "gearbox2"):
        path = folder / "solids" / f"{housing}-base.stl"
        bottom = float(trimesh.load(path).bounds[0, 2])
        holes["M6"] += _bolt_holes(path, bottom + 1.0, 5.0) * _instances(scene, f"{housing}-base")
    assert holes["M6"] == 6 + 2 * 6      # 6 screws on S, 6 on each arm's C
    # the cam's screws, tapped into gearbox 2's cover roof (an M3 tap drill, 2.5 mm, ISO 2306):
    # the cover lies on its roof (its largest flat face); cut 1 mm above the bottom
    path = folder / "solids" / "gearbox2-cover.stl"
    bottom = float(trimesh.load(path).bounds[0, 2])
    holes["M3"] += _bolt_holes(path, bottom + 1.0, 2.5) * _instances(scene, "gearbox2-cover")
    assert screws == holes
    nuts = Counter(r["designation"].split()[2] for r in rows if r["part"] == "hexagon nut"
                   for _ in range(int(r["quantity"])))
    washers = sum(int(r["quantity"]) for r in rows if r["part"] == "plain washer")
    assert nuts == flange_holes and washers == 2 * sum(flange_holes.values())


def test_keys_one_per_keyed_gear_placed(built):
    _, result, _, rows, scene = built
    keyed = [h["gear"].replace(" ", "-") for s in result.report["machine"]["shafts"]
             if s["side"] == 1 for h in s["hubs"] if h.get("key")]
    expected = sum(_instances(scene, gear) for gear in keyed)
    # and the input shaft's stub, keyed for the sprocket or coupling
    couplings = [s for s in result.report["machine"]["shafts"] if s["coupling_key"]]
    assert [s["name"] for s in couplings] == ["input"]
    # and the planter's hub on shaft E, on each arm
    assert result.report["machine"]["fixings"]["planter"]["key"] is not None
    hubs = _instances(scene, "planter-shell")
    assert sum(int(r["quantity"]) for r in rows if r["part"] == "key") == expected + 1 + hubs > 3


def test_each_gear_sits_on_its_shaft_axis(built):
    """The gears are placed from the gear trains' kinematics, the shafts from the drivetrain's
    axis formulas: at the catching pose each gear's axis is its shaft's, in its body's frame."""
    params = built[0]
    from cadgen.design import build_mechanism
    from cadgen.gears.trains import planting_train
    from cadgen.machine.drivetrain import drivetrain
    from cadgen.solids.planting import planting_assembly

    mechanism = build_mechanism(params)
    shafts = drivetrain(params, mechanism)
    assembly, _, _ = planting_assembly(params, mechanism,
                                       planting_train(params, mechanism, drive=shafts.drive), None,
                                       0.0, drivetrain=shafts)
    parts = {p.name: p for p in assembly.parts}
    checked = 0
    for phi in (0.0, 1.3):
        world = {name: pose for name, _, pose in assembly.placements(phi)}
        for shaft in shafts.shafts:
            if shaft.side != 1:
                continue
            axis = world[_first(parts[f"shaft-{shaft.name}"])][:2, 3]
            for mount in shaft.mounts:
                # a gear may turn in another housing than its shaft's (the central gear on C2
                # in gearbox 2): compared in the world
                gear = world[_first(parts[mount.gear.replace(" ", "-")])]
                np.testing.assert_allclose(gear[:2, 3], axis, atol=1e-9)
                checked += 1
    assert checked == 2 * 16


def _first(part) -> str:
    """The first placed copy's instance name of a part (side 1, arm 1, or its own name)."""
    return part.instances[0][0] if part.instances else part.name


def test_each_shaft_stl_is_as_long_as_its_stack_says(built):
    """The sizing gives each shaft's length from its stack (walls, bearing seats, extensions
    beyond the housing); the solids build the shaft from the housing's geometry: the two agree."""
    _, result, folder, _, _ = built
    for shaft in result.report["machine"]["shafts"]:
        mesh = trimesh.load(folder / "solids" / f"shaft-{shaft['name']}.stl")
        # as long as its stack says, as wide as its diameter or (a hollow shaft carrying a
        # housing) its flange, whichever extent is the larger
        width = 2 * shaft["flange"]["radius"] if shaft["flange"] else shaft["diameter_mm"]
        assert sorted(mesh.extents) == pytest.approx(sorted([shaft["length_mm"], width, width]),
                                                     abs=1e-4)       # float32 STL


def _direction(points) -> float:
    """Direction (rad) of the mean of some (n, 2) points about the origin."""
    mean = np.asarray(points, dtype=float).mean(axis=0)
    return math.atan2(mean[1], mean[0])


def test_each_keyseat_lies_under_its_gears_keyway_at_every_pose(built):
    """The keyseats cut into a shaft fix the gears' phasing on it: measured on the meshes, each
    keyseat (the shaft's vertices at its bottom, t1 deep) points where its gear's keyway (the
    bore's vertices at the keyway's bottom) points, in their body, at three carrier angles."""
    params = built[0]
    from cadgen.design import build_mechanism
    from cadgen.gears.trains import planting_train
    from cadgen.machine.drivetrain import drivetrain
    from cadgen.machine.hubs import hub_train
    from cadgen.solids.planting import planting_assembly

    mechanism = build_mechanism(params)
    shafts = drivetrain(params, mechanism)
    train, _ = hub_train(planting_train(params, mechanism, drive=shafts.drive), shafts)
    assembly, _, _ = planting_assembly(params, mechanism, train, None, 0.0, drivetrain=shafts)
    parts = {p.name: p for p in assembly.parts}
    holes = {profile.name: profile.hole for profile, *_ in train.gears}
    checked = 0
    for shaft in shafts.shafts:
        if shaft.side != 1:
            continue
        part = parts[f"shaft-{shaft.name}"]
        vertices = part.mesh.vertices
        radius = np.linalg.norm(vertices[:, :2], axis=1)
        inner = shaft.bore / 2 + 1e-6   # a hollow shaft's bore is not its keyseat
        for mount in shaft.mounts:
            key = mount.key
            if key is None:   # a gear running free on its bearings: no keyseat
                continue
            gear = parts[mount.gear.replace(" ", "-")]
            world0 = {name: pose for name, _, pose in assembly.placements(0.0)}
            # the gear's face from the shaft's own frame: world heights less the shaft's
            z0 = world0[_first(gear)][2, 3] - world0[_first(part)][2, 3]
            inside = (vertices[:, 2] > z0 - 1e-6) & (vertices[:, 2] < z0 + mount.face_width + 1e-6)
            seat = vertices[inside & (radius < shaft.diameter / 2 - key.shaft_depth / 2)
                            & (radius > inner), :2]
            hole = holes[mount.gear]
            keyway = hole[np.linalg.norm(hole, axis=1) > mount.hub_bore / 2 + key.hub_depth / 2]
            assert len(seat) and len(keyway)
            for phi in (0.0, 1.3, 4.0):
                world = {name: pose for name, _, pose in assembly.placements(phi)}
                shaft_pose, gear_pose = world[_first(part)], world[_first(gear)]
                turn_shaft = math.atan2(shaft_pose[1, 0], shaft_pose[0, 0])
                turn_gear = math.atan2(gear_pose[1, 0], gear_pose[0, 0])
                gap = (turn_shaft + _direction(seat)) - (turn_gear + _direction(keyway))
                assert abs(math.remainder(gap, 2 * math.pi)) < 1e-9, (shaft.name, mount.gear, phi)
            checked += 1
    assert checked == 16 - 2     # every keyed gear (one idler on each of A and B runs free)
