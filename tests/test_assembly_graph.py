"""The joint graph: rigid bodies, Kutzbach–Grübler mobility, loose parts.

The expected mobilities are the textbook ones (Grübler's count for the four-bar, five-bar,
triangle, slider-crank, Watt six-bar, cam-follower; Norton, Design of Machinery, ch. 2;
the planetary train's one freedom with the ring held and two as a differential), not
values read back from the code.
"""

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cadgen.assembly import AssemblyModel, Joint


def revolute(a, b, detail=""):
    return Joint("revolute", a, b, detail)


def fixed(a, b, detail="parallel key DIN 6885 A 6 x 6 x 25"):
    return Joint("fixed", a, b, detail)


def model(joints, frame="frame"):
    """A model of the parts the joints name, the frame first."""
    parts = [frame]
    for joint in joints:
        parts += [p for p in (joint.a, joint.b) if p not in parts]
    return AssemblyModel(tuple(parts), tuple(joints), frame)


FOUR_BAR = [revolute("frame", "crank"), revolute("crank", "coupler"),
            revolute("coupler", "rocker"), revolute("rocker", "frame")]


def planetary():
    return model([revolute("sun", "frame"), revolute("carrier", "frame"),
                  revolute("planet", "carrier"), Joint("gear", "sun", "planet"),
                  fixed("ring", "frame", "bolted"), Joint("gear", "ring", "planet")])


# --- classic counts -------------------------------------------------------------------------

def test_a_four_bar_has_one_freedom():
    four_bar = model(FOUR_BAR)
    assert four_bar.mobility() == 1
    assert four_bar.mobility_report() == {"formula": "M = 3 (N - 1) - 2 J1 - J2", "bodies": 4,
                                          "lower_pairs": 4, "higher_pairs": 0, "mobility": 1}
    assert four_bar.degrees_of_freedom_check() == []


def test_a_five_bar_has_two_and_a_triangle_none():
    five_bar = model([revolute("frame", "l1"), revolute("l1", "l2"), revolute("l2", "l3"),
                      revolute("l3", "l4"), revolute("l4", "frame")])
    triangle = model([revolute("frame", "l1"), revolute("l1", "l2"), revolute("l2", "frame")])
    assert five_bar.mobility() == 2
    assert triangle.mobility() == 0


def test_a_slider_crank_and_a_watt_six_bar_have_one_freedom():
    slider_crank = model([revolute("frame", "crank"), revolute("crank", "rod"),
                          revolute("rod", "slider"), Joint("prismatic", "slider", "frame")])
    # Watt I: two ternary links (frame and t) joined by binary links, 6 links, 7 revolutes
    watt = model([revolute("frame", "a"), revolute("a", "t"), revolute("t", "b"),
                  revolute("b", "frame"), revolute("t", "c"), revolute("c", "d"),
                  revolute("d", "frame")])
    assert slider_crank.mobility() == 1
    assert watt.mobility_report()["bodies"] == 6 and watt.mobility() == 1


def test_a_cam_counts_as_a_higher_pair_and_a_roller_adds_its_idle_spin():
    flat_follower = model([revolute("cam", "frame"), Joint("prismatic", "follower", "frame"),
                           Joint("cam", "cam", "follower")])
    roller_follower = model([revolute("cam", "frame"), Joint("prismatic", "follower", "frame"),
                             revolute("roller", "follower"), Joint("cam", "cam", "roller")])
    assert flat_follower.mobility() == 1
    assert roller_follower.mobility() == 2   # the roller's spin: Norton's redundant freedom


def test_a_planetary_train_has_one_freedom_and_two_as_a_differential():
    train = planetary()
    assert train.body_of("ring") == frozenset({"frame", "ring"})
    assert train.mobility_report()["higher_pairs"] == 2 and train.mobility() == 1
    ring_key = next(j for j in train.joints if j.kind == "fixed")
    differential = train.without(ring_key).with_joints(revolute("ring", "frame", "6010 bearing"))
    assert differential.mobility() == 2
    assert differential.degrees_of_freedom_check(expected=2) == []
    assert differential.degrees_of_freedom_check()[0].startswith("mobility 2, expected 1: ")


# --- rigid bodies ---------------------------------------------------------------------------

def test_a_gear_keyed_to_a_shaft_on_a_bearing_is_one_body_with_one_freedom():
    shaft = model([fixed("gear", "shaft"), revolute("shaft", "frame", "6004 bearing")])
    assert shaft.bodies() == (frozenset({"frame"}), frozenset({"gear", "shaft"}))
    assert shaft.body_of("gear") == shaft.body_of("shaft")
    assert shaft.mobility_report()["bodies"] == 2 and shaft.mobility() == 1


def test_a_shafts_two_bearings_are_one_revolute_pair():
    shaft = model([fixed("gear", "shaft"), revolute("shaft", "frame", "6004 bearing A"),
                   revolute("frame", "shaft", "6004 bearing B")])
    assert shaft.mobility_report()["lower_pairs"] == 1 and shaft.mobility() == 1


def test_a_bearing_inside_one_body_is_redundant_and_locks():
    locked = model([fixed("gear", "shaft"), revolute("shaft", "frame"),
                    revolute("gear", "shaft", "6004 bearing")])
    assert locked.redundant_joints() == (revolute("gear", "shaft", "6004 bearing"),)
    assert locked.mobility() == -1
    problem, = locked.degrees_of_freedom_check()
    assert "revolute joint gear–shaft (6004 bearing)" in problem


# --- parts nothing holds --------------------------------------------------------------------

def gearbox():
    """Input shaft, pinion, wheel on the output shaft, a crank and a sprocket keyed to it."""
    return model([revolute("input_shaft", "frame"), fixed("pinion", "input_shaft"),
                  Joint("gear", "pinion", "wheel"), fixed("wheel", "output_shaft"),
                  revolute("output_shaft", "frame", "6004 bearing"),
                  fixed("sprocket", "output_shaft"), fixed("crank", "output_shaft")])


def test_a_gearbox_holds_every_part():
    box = gearbox()
    assert box.unconnected() == []
    # one freedom: the two shafts turn together, 3 (3 - 1) - 2 * 2 - 1
    assert box.mobility() == 1


def test_removing_a_gears_key_leaves_exactly_that_gear_loose():
    loose = gearbox().without(fixed("sprocket", "output_shaft"))
    assert loose.unconnected() == ["sprocket"]
    assert loose.degrees_of_freedom_check()[0] == (
        "the part sprocket is tied to the frame by no chain of joints")


def test_removing_a_bearing_leaves_the_shaft_and_all_keyed_to_it_loose():
    box = gearbox().without(lambda j: j.kind == "gear")
    loose = box.without(revolute("output_shaft", "frame", "6004 bearing"))
    assert loose.unconnected() == ["wheel", "output_shaft", "sprocket", "crank"]
    assert loose.degrees_of_freedom_check()[0] == ("the parts wheel, output_shaft, sprocket, "
                                                   "crank are tied to the frame by no chain of joints")


def test_a_gear_mesh_alone_holds_nothing():
    # a shaft whose bearing is missing still meshes, but nothing holds it: loose, with all
    # keyed to it, exactly as with the meshes taken out first
    meshed = gearbox().without(revolute("output_shaft", "frame", "6004 bearing"))
    assert meshed.unconnected() == ["wheel", "output_shaft", "sprocket", "crank"]


# --- validation, editing, report ------------------------------------------------------------

def test_bad_joints_and_models_are_value_errors():
    with pytest.raises(ValueError, match="weld"):
        Joint("weld", "a", "b")
    with pytest.raises(ValueError, match="itself"):
        Joint("revolute", "shaft", "shaft")
    with pytest.raises(ValueError, match=r"revolute joint frame–crank.*unknown part 'crank'"):
        AssemblyModel(("frame",), (revolute("frame", "crank"),), "frame")
    with pytest.raises(ValueError, match="frame 'ground'"):
        AssemblyModel(("frame",), (), "ground")
    with pytest.raises(ValueError, match="twice"):
        AssemblyModel(("frame", "a", "a"), (), "frame")
    with pytest.raises(ValueError, match="no fixed joint"):
        gearbox().without(fixed("frame", "crank"))


def test_joints_of_and_the_report_are_plain_data():
    box = gearbox()
    assert box.joints_of("wheel") == (Joint("gear", "pinion", "wheel"), fixed("wheel", "output_shaft"))
    report = json.loads(json.dumps(box.as_report()))
    assert report["frame"] == "frame" and report["mobility"] == 1 and report["unconnected"] == []
    assert report["mobility_rule"]["bodies"] == 3
    assert report["bodies"] == [["frame"], ["input_shaft", "pinion"],
                                ["wheel", "output_shaft", "sprocket", "crank"]]
    assert report["joints"][0] == {"kind": "revolute", "a": "input_shaft", "b": "frame",
                                   "detail": ""}


# --- properties -----------------------------------------------------------------------------

@st.composite
def revolute_trees(draw, max_parts=10):
    """A random tree of k parts hung from the frame, one revolute joint per part."""
    k = draw(st.integers(1, max_parts))
    parents = [draw(st.integers(0, i)) for i in range(k)]
    names = ["frame"] + [f"p{i}" for i in range(1, k + 1)]
    joints = [revolute(names[i + 1], names[parent]) for i, parent in enumerate(parents)]
    return k, AssemblyModel(tuple(names), tuple(joints), "frame")


@settings(max_examples=60, deadline=None)
@given(revolute_trees())
def test_a_tree_of_k_parts_on_revolutes_has_k_freedoms(tree):
    k, hung = tree
    assert hung.mobility() == k
    assert hung.unconnected() == [] and hung.degrees_of_freedom_check(expected=k) == []


@settings(max_examples=60, deadline=None)
@given(revolute_trees(), st.data())
def test_new_parts_fixed_to_existing_ones_never_change_the_mobility(tree, data):
    k, hung = tree
    parts, joints = list(hung.parts), list(hung.joints)
    for n in range(data.draw(st.integers(1, 6))):
        host = data.draw(st.sampled_from(parts))
        new = f"n{n}"
        parts.append(new)
        joints += [fixed(new, host, f"bolt {i}") for i in range(data.draw(st.integers(1, 3)))]
    grown = AssemblyModel(tuple(parts), tuple(joints), "frame")
    assert grown.mobility() == k
    assert len(grown.bodies()) == len(hung.bodies()) and grown.unconnected() == []


@st.composite
def random_mechanisms(draw):
    """Any joints of any kinds among a handful of parts: loose parts, locks and all."""
    names = ["frame"] + [f"p{i}" for i in range(draw(st.integers(1, 7)))]
    pairs = st.tuples(st.sampled_from(names), st.sampled_from(names)).filter(lambda p: p[0] != p[1])
    joints = [Joint(kind, a, b) for kind, (a, b) in
              draw(st.lists(st.tuples(st.sampled_from(["fixed", "revolute", "prismatic", "gear",
                                                       "cam"]), pairs), max_size=12))]
    return AssemblyModel(tuple(names), tuple(joints), "frame")


@settings(max_examples=100, deadline=None)
@given(random_mechanisms(), st.data())
def test_the_order_of_parts_and_joints_never_changes_the_answers(machine, data):
    shuffled = AssemblyModel(tuple(data.draw(st.permutations(machine.parts))),
                             tuple(data.draw(st.permutations(machine.joints))), machine.frame)
    assert shuffled.mobility() == machine.mobility()
    assert set(shuffled.unconnected()) == set(machine.unconnected())
    assert set(shuffled.bodies()) == set(machine.bodies())
    assert set(shuffled.redundant_joints()) == set(machine.redundant_joints())
