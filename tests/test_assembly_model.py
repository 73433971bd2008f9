"""The assembly model as the backbone: the solids' copies, the bill's bought items and the
report's animation are read from it, and each is checked here by a second route (the drivetrain's
records counted by hand, the kinematics' own joint positions), not by the model again."""

import math
import re
from collections import Counter

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cadgen.assembly import AssemblyModel, Item, Joint, Placement
from cadgen.design import build_mechanism
from cadgen.params import load_params

BEARING = Item("bearing", "deep-groove ball bearing 6002-2Z (15 x 32 x 9 mm)", "6002", 1)
KEY = Item("key", "parallel key DIN 6885 A 5 x 5 x 20", "parallel key DIN 6885 A 5 x 5 x 20")


def small_machine():
    """A frame, a shaft on two bearings (one joint: coaxial), a keyed gear, a gear the user
    supplies the coupling for."""
    joints = (Joint("revolute", "shaft", "frame", "2 bearings", (BEARING, BEARING)),
              Joint("fixed", "gear", "shaft", "key", (KEY,)),
              Joint("fixed", "coupling", "shaft", "the user's hub", (KEY,)))
    placements = (Placement("frame", "frame", "frame"), Placement("shaft", "shaft", "frame"),
                  Placement("gear", "gear", "frame"))
    return AssemblyModel(("frame", "shaft", "gear", "coupling"), joints, "frame", placements,
                         made=("frame", "shaft", "gear"))


def totals(model, present=None):
    return {item.kind: total for item, total in model.bought(present)}


def test_bought_items_are_summed_over_the_joints_whose_parts_were_made():
    machine = small_machine()
    # by hand: two bearings on the shaft's joint, a key for the gear, a key for the coupling
    assert totals(machine) == {"bearing": 2, "key": 2}
    # the gear was not cut: its key is not bought; the user's coupling is not the machine's
    # part, so its key still is
    assert totals(machine, present={"frame", "shaft"}) == {"bearing": 2, "key": 1}
    # a joint removed takes its items with it, and keeps the placements and the made parts
    keyless = machine.without(lambda j: j.a == "gear")
    assert totals(keyless) == {"bearing": 2, "key": 1}
    assert keyless.placements == machine.placements and keyless.made == machine.made
    assert machine.instances_of("shaft") == (("shaft", "frame", 0.0),)


def test_bad_items_and_placements_are_refused():
    with pytest.raises(ValueError, match="whole positive"):
        Item("key", "k", "k", 0)
    with pytest.raises(TypeError, match="an item is an Item"):
        Joint("fixed", "a", "b", "", ("screw",))
    with pytest.raises(ValueError, match="placed twice"):
        AssemblyModel(("frame",), (), "frame", (Placement("frame", "frame", "frame"),) * 2)
    with pytest.raises(ValueError, match="not a part"):
        AssemblyModel(("frame",), (), "frame", (Placement("ghost", "ghost", "frame"),))
    with pytest.raises(ValueError, match="not parts"):
        AssemblyModel(("frame",), (), "frame", made=("ghost",))


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 5), st.integers(1, 9)), min_size=1, max_size=12),
       st.randoms(use_true_random=False))
def test_bought_totals_are_the_sum_of_the_items_in_any_joint_order(chain, random):
    # a chain of parts, each fixed to the one before with `count` screws of one of six sizes
    sizes = [Item("socket head cap screw", f"ISO 4762 M{s} x 20 - 8.8", f"M{s}") for s in range(6)]
    joints = [Joint("fixed", f"p{k + 1}", f"p{k}", "", (Item(
        sizes[size].kind, sizes[size].description, sizes[size].designation, count),))
        for k, (size, count) in enumerate(chain)]
    parts = tuple(f"p{k}" for k in range(len(chain) + 1))
    expected = Counter()
    for size, count in chain:
        expected[sizes[size].description] += count
    random.shuffle(joints)
    got = {item.description: total for item, total in AssemblyModel(parts, joints, "p0").bought()}
    assert got == dict(expected)


# ------------------------------------------------------------------ the paper's machine
@pytest.fixture(scope="module")
def paper_assembly():
    from cadgen.gears.trains import planting_train
    from cadgen.machine.drivetrain import drivetrain
    from cadgen.solids.planting import planting_assembly

    params = load_params("params/xin2024-planter.toml")
    mechanism = build_mechanism(params)
    machine = drivetrain(params, mechanism)
    train = planting_train(params, mechanism, drive=machine.drive)
    assembly, housings, _ = planting_assembly(params, mechanism, train, None, None,
                                              drivetrain=machine)
    return params, mechanism, machine, assembly, housings


def test_every_placed_solid_is_a_placement_of_the_model(paper_assembly):
    _, _, _, assembly, _ = paper_assembly
    model = assembly.model
    placed = [name for name, _, _ in assembly.placements(0.3)]
    assert sorted(placed) == sorted(p.instance for p in model.placements)
    assert set(model.placed_parts()) == {part.name for part in assembly.parts}
    # both arms: every gearbox-2 part twice, half a turn apart
    for part in assembly.parts:
        if part.body == "gearbox2":
            assert [(b, round(phase, 12)) for _, b, phase in part.instances] == [
                ("gearbox2", 0.0), ("gearbox2", round(math.pi, 12))]


def _record(machine, instance):
    """The drivetrain's shaft record of a placed shaft instance (by its name and copy)."""
    match = re.fullmatch(r"shaft-(.+?)(?:-(side|arm)(\d))?", instance)
    name, copy, number = match.groups()
    records = [s for s in machine.shafts if s.name == name]
    if copy == "side":
        return next(s for s in records if s.side == int(number))
    return records[0]


def test_the_bills_bearings_and_keys_by_hand_from_the_placed_solids(paper_assembly):
    from cadgen.report.bom import _bought_rows

    _, _, machine, assembly, _ = paper_assembly
    instances = [name for part in assembly.parts for name, _, _ in part.instances]
    bearings = keys = 0
    for name in instances:
        if name.startswith("shaft-"):
            record = _record(machine, name)
            bearings += sum(seat.count for seat in record.seats)
            for mount in record.mounts:   # a gear on this copy: free on two bearings, or keyed
                if getattr(mount, "bearing", None) is not None:
                    bearings += 2
                elif mount.key is not None:
                    keys += 1
            keys += record.coupling_key is not None   # the input's stub
    # the planter's keyed hub on each arm's shaft E
    keys += sum(name.startswith("planter-shell") for name in instances)
    assert machine.fixings["planter"]["key"] is not None
    rows = _bought_rows(assembly.model, set(instances))
    assert sum(r["quantity"] for r in rows if r["part"] == "bearing") == bearings
    assert sum(r["quantity"] for r in rows if r["part"] == "key") == keys
    # set I's planet key taken out of the model: one key fewer in the bill
    model = assembly.model.without(lambda j: j.kind == "fixed" and j.a == "planet-I-side1")
    assert sum(r["quantity"] for r in _bought_rows(model, set(instances))
               if r["part"] == "key") == keys - 1


def test_the_housings_bolts_by_hand(paper_assembly):
    from cadgen.report.bom import _bought_rows

    _, _, _, assembly, (box1, box2, frame) = paper_assembly
    rows = _bought_rows(assembly.model, None)
    nuts = sum(r["quantity"] for r in rows if r["part"] == "hexagon nut")
    washers = sum(r["quantity"] for r in rows if r["part"] == "plain washer")
    # one nut per flange bolt: gearbox 1 and the frame once, gearbox 2 on each arm
    flange = len(box1.bolt_positions) + 2 * len(box2.bolt_positions) + len(frame.bolt_positions)
    assert nuts == flange and washers == 2 * flange


def test_the_animation_places_gearbox2_where_the_kinematics_puts_c(paper_assembly):
    from cadgen.report.animation import parts_layer

    _, mechanism, _, assembly, _ = paper_assembly
    phi = np.linspace(0.0, 2 * np.pi, 12, endpoint=False)
    layer = parts_layer(assembly, phi)
    frames, seen = {}, Counter()   # "<part><k>": the part's k-th copy's (x, y, deg) per pose
    for instance in layer["instances"]:
        frames[f"{instance['part']}{seen[instance['part']]}"] = np.reshape(instance["frames"],
                                                                          (-1, 3))
        seen[instance["part"]] += 1
    for arm in (0, 1):
        placed = frames[f"gearbox2-base{arm}"]
        c = mechanism.positions(phi, arm=arm, points=("C",))["C"]
        # SVG's y points down: the frames hold (x, -y, -deg)
        assert np.allclose(placed[:, 0], c[:, 0], atol=0.051)
        assert np.allclose(-placed[:, 1], c[:, 1], atol=0.051)
    # gearbox 1 turns with carrier 1, backwards at the carrier angle
    turn = -frames["gearbox1-base0"][:, 2]
    assert np.allclose((turn + np.degrees(phi) + 180) % 360 - 180, 0.0, atol=0.006)
    # the covers are not drawn (their bases' outlines), every gear is
    drawn = {i["part"] for i in layer["instances"]}
    assert not any("-cover" in name for name in drawn)
    assert {p.name for p in assembly.parts if p.kind == "gear"} <= drawn


def test_a_made_part_the_model_cannot_place_is_refused(paper_assembly):
    from cadgen.assembly.machine import planting_model

    _, _, machine, _, _ = paper_assembly
    with pytest.raises(ValueError, match="mystery-bracket"):
        planting_model(machine, bodies={"mystery-bracket": "frame", "frame-base": "frame"})


def test_the_arms_swept_against_each_other_are_the_models_arm_copies(paper_assembly):
    from cadgen.pipeline.clearances import _arm_bounds_of, arm_groups
    from cadgen.solids.errors import SolidInputError

    _, _, _, assembly, _ = paper_assembly
    arm1, arm2 = arm_groups(assembly)
    # by hand, one arm outside its gears: gearbox 2's halves, its shafts D and E (they leave
    # the housing), the planter and its two blades (this assembly was built without a cam)
    expected = ["gearbox2-base", "gearbox2-cover", "shaft-D", "shaft-E", "planter-shell",
                "blade-right", "blade-left"]
    assert sorted(arm1) == sorted(f"{name}-arm1" for name in expected)
    assert [name.replace("-arm1", "-arm2") for name in arm1] == arm2
    part_of = {name: part.name for part in assembly.parts for name, _, _ in part.instances}
    bounds = {name: (1.0, 1.0) for name in expected if name != "shaft-E"}
    with pytest.raises(SolidInputError, match=r"\['shaft-E'\]"):
        _arm_bounds_of(arm1 + arm2, part_of, bounds)


def test_the_reports_joint_table_says_each_item_once_with_its_count():
    from cadgen.assembly.machine import model_report
    from cadgen.report.html_machine import _joint_graph_html

    html = _joint_graph_html(model_report(small_machine()))
    html = html.split("assembly order")[0]   # the joints' table (the order repeats the items)
    # the shaft's two seats' bearings are one line of two; the keys one each
    assert "2 x deep-groove ball bearing 6002-2Z (15 x 32 x 9 mm)" in html
    assert html.count("1 x parallel key DIN 6885 A 5 x 5 x 20") == 2


def test_the_assembly_order_puts_every_joint_once_and_in_a_workshops_order(paper_assembly):
    from cadgen.assembly.sequence import TIGHTENING_TORQUE_NM, assembly_sequence

    _, _, _, assembly, _ = paper_assembly
    model = assembly.model
    steps = assembly_sequence(model)
    holding = [j for j in model.joints if j.kind in ("fixed", "revolute")]
    assert [s["step"] for s in steps] == list(range(1, len(holding) + 1))
    assert Counter((tuple(sorted((s["part"], s["onto"]))), s["how"]) for s in steps) == Counter(
        (tuple(sorted((j.a, j.b))), j.detail) for j in holding)   # every holding joint, once
    when = {(s["part"], s["onto"]): s["step"] for s in steps}
    into = {s["part"]: s["step"] for s in steps if s["onto"].startswith(("gearbox", "frame"))
            and s["part"].startswith("shaft-") and s["joint"] == "revolute"}
    gears = {name for p in assembly.parts if p.kind == "gear" for name, _, _ in p.instances}
    for (part, onto), step in when.items():
        if onto in into and part in gears:
            assert step < into[onto], (part, onto)   # a gear onto its shaft before the shaft goes in
    for (part, onto), step in when.items():
        if "-cover" in part and onto.endswith(("base", "arm1", "arm2")):
            shafts = [s["step"] for s in steps if s["onto"] == onto and s["joint"] == "revolute"]
            assert shafts and max(shafts) < step, onto   # closed after its shafts are in
    # the flange bolts' torque, 8.8 at mu 0.14: gearbox 2's M4 at 3 N m
    cover = next(s for s in steps if s["part"] == "gearbox2-cover-arm1")
    assert any("M4" in b and f"{TIGHTENING_TORQUE_NM['M4']:g} N m" in b for b in cover["bought"])
    assert TIGHTENING_TORQUE_NM["M4"] == 3.0 and TIGHTENING_TORQUE_NM["M6"] == 10.1
