"""Housings cut into bolted segments so every printed piece fits the printer (issue 14)."""

import math
from collections import Counter

import numpy as np
import pytest

from cadgen.design import build_mechanism
from cadgen.machine.drivetrain import drivetrain
from cadgen.params import validate_text
from cadgen.solids.errors import SolidInputError
from cadgen.solids.outcome import enclosure_checks, fits_build_volume, printing_pose
from cadgen.solids.planting import planting_assembly
from cadgen.solids.segments import (long_axis, lug_thickness, segment_cuts, segment_extents,
                                    segment_housing, segment_problems)
from kinematics.errors import DesignError
from tests.helpers import reference_text, with_keys

#: Relative volume tolerance of the pieces against their half (manifold3d's booleans are exact
#: but for float rounding).
VOLUME_RTOL = 1e-6


def _planting(**manufacturing):
    params = validate_text(with_keys(reference_text(), "manufacturing", **manufacturing))
    mechanism = build_mechanism(params)
    train = drivetrain(params, mechanism)
    assembly, housings, _ = planting_assembly(params, mechanism, None, None, 0.0, drivetrain=train)
    return params, assembly, housings


@pytest.fixture(scope="module")
def printed():
    return _planting(process='"printed"')


def _housing_parts(assembly, stem):
    return [p for p in assembly.parts if p.kind == "housing" and p.name.startswith(stem)]


def test_gearbox1_is_cut_and_gearbox2_is_whole(printed):
    _, assembly, (box1, box2, *_) = printed
    names = [p.name for p in assembly.parts if p.kind == "housing"]
    assert [n for n in names if n.startswith("gearbox1")] == [
        "gearbox1-base-1", "gearbox1-base-2", "gearbox1-base-3",
        "gearbox1-cover-1", "gearbox1-cover-2", "gearbox1-cover-3"]
    assert [n for n in names if n.startswith("gearbox2")] == ["gearbox2-base", "gearbox2-cover"]
    assert len(box1.joints) == 2 and box2.joints == ()
    # gearbox 2's segments ride on both arms like the whole halves
    arms = {p.name: p.instances for p in assembly.parts if p.name.startswith("gearbox2")}
    assert [i[0] for i in arms["gearbox2-base"]] == ["gearbox2-base-arm1", "gearbox2-base-arm2"]


def test_every_housing_part_fits_the_build_volume_and_is_watertight(printed):
    params, assembly, _ = printed
    volume = params.manufacturing.build_volume
    for part in _housing_parts(assembly, "gearbox"):
        mesh = part.mesh
        assert mesh.is_watertight and mesh.is_winding_consistent, part.name
        extents = np.ptp(mesh.copy().apply_transform(printing_pose(mesh)).vertices, axis=0)
        assert fits_build_volume(extents, volume), (part.name, extents)


@pytest.mark.parametrize("half", ["base", "cover"])
def test_the_pieces_make_up_the_half_without_overlapping(printed, half):
    import manifold3d as m3d

    _, assembly, (box1, *_) = printed
    pieces = [p.solid for p in _housing_parts(assembly, f"gearbox1-{half}-")]
    whole = getattr(box1, half)
    # the lugs lie outside the housing's envelope but where they thicken the flange (the same
    # material, its bolt holes drilled again): inside it the pieces are the half exactly
    union = m3d.Manifold.batch_boolean(pieces, m3d.OpType.Add)
    assert math.isclose((union ^ box1.outer).volume(), whole.volume(), rel_tol=VOLUME_RTOL)
    assert math.isclose(sum(p.volume() for p in pieces), union.volume(), rel_tol=VOLUME_RTOL)
    for i, a in enumerate(pieces):
        for b in pieces[i + 1:]:
            overlap = a ^ b
            assert overlap.is_empty() or overlap.volume() < VOLUME_RTOL * whole.volume()
    # nothing of the lugs is in the cavity the gears turn in
    assert (union ^ box1.cavity).is_empty() or (union ^ box1.cavity).volume() < 1e-6


def test_each_splice_bolt_passes_through_both_lugs(printed):
    import manifold3d as m3d

    _, assembly, (box1, *_) = printed
    parts = {p.name: p.solid for p in assembly.parts}
    for index, joint in enumerate(box1.joints):
        assert joint.bolts.shape == (4, 3)          # two bolts per half, one each side
        assert joint.grip == pytest.approx(2 * lug_thickness(box1))
        angle = math.degrees(math.atan2(joint.axis[1], joint.axis[0]))
        for bolt in joint.bolts:
            half = "base" if bolt[2] < box1.parting_z else "cover"
            before = parts[f"gearbox1-{half}-{index + 1}"]
            after = parts[f"gearbox1-{half}-{index + 2}"]

            def rod(radius, length=joint.grip):
                return (m3d.Manifold.cylinder(length, radius, radius, 32, True)
                        .rotate((0.0, 90.0, 0.0)).rotate((0.0, 0.0, angle))
                        .translate(tuple(bolt)))

            inside = rod(0.45 * joint.bolt_hole_diameter)
            around = rod(1.2 * joint.bolt_hole_diameter / 2) - rod(0.55 * joint.bolt_hole_diameter,
                                                                 joint.grip + 2)
            for piece in (before, after):
                assert (piece ^ inside).is_empty()            # the hole is clear ...
                assert (piece ^ around).volume() > 0.1        # ... in a lug round it


def test_the_cuts_avoid_the_seats_and_are_fewest(printed):
    params, _, (box1, *_) = printed
    volume = params.manufacturing.build_volume
    cuts = segment_cuts(box1, volume, margin=1.0)
    assert len(cuts) == 2
    assert segment_problems(box1, cuts, volume, margin=1.0, name="gearbox1") == []
    _, axis = long_axis(box1.flange_outline)
    assert abs(axis[1]) == pytest.approx(1.0)        # gearbox 1 is long along y
    # one cut fewer cannot fit: the housing is over twice the bed's length
    length = np.ptp(box1.flange_outline @ axis)
    assert length > 2 * (max(volume) - 1.0)
    for along, across, height in segment_extents(box1, cuts):
        assert fits_build_volume((along + 1, across + 1, height + 1), volume)


def test_the_machined_process_gives_the_two_halves(printed):
    _, assembly, (box1, box2, *_) = _planting(process='"machined"')
    names = [p.name for p in assembly.parts if p.kind == "housing"]
    assert names == ["gearbox1-base", "gearbox1-cover", "gearbox2-base", "gearbox2-cover",
                     "frame-base", "frame-cover"]
    assert box1.joints == () and box2.joints == ()


def test_a_build_volume_too_small_for_any_split_is_named():
    with pytest.raises(DesignError) as caught:
        _planting(process='"printed"', build_volume="[60.0, 60.0, 60.0]")
    problems = caught.value.problems
    assert problems and all(p.path == "manufacturing.build_volume" for p in problems)
    assert "cannot split gearbox1 between its bearing seats to fit the build volume" in \
        problems[0].message
    # the best piece's size is listed: its height is gearbox 1's base, floor wall plus cavity
    # (the cover is a lid), from the drivetrain's stack
    params = validate_text(with_keys(reference_text(), "manufacturing", process='"printed"'))
    stack = drivetrain(params, build_mechanism(params)).stacks["gearbox1"]
    assert f" x {stack.floor_wall + stack.cavity_height:.1f} mm" in problems[0].message


def test_a_cut_through_a_seat_is_a_design_error(printed):
    _, _, (box1, *_) = printed
    seat = box1.seats[0]
    with pytest.raises(DesignError) as caught:
        segment_housing(box1, [(seat.xy, (1.0, 0.0))], segments=32, name="gearbox1")
    assert caught.value.problems[0].code == "cut_through_seat"
    assert caught.value.problems[0].path == "manufacturing.build_volume"


@pytest.mark.parametrize("cuts, segments", [
    ([((0.0, 120.0), (1.0, 0.0)), ((0.0, -120.0), (1.0, 0.2))], 32),   # not parallel
    ([((0.0, 2000.0), (1.0, 0.0))], 32),                                  # misses the housing
    ([((0.0, 120.0), (0.0, 0.0))], 32),                                   # no direction
    ([((0.0, 120.0), (1.0, 0.0))], 2),                                    # too few sides
], ids=["not-parallel", "misses", "no-direction", "segments"])
def test_bad_cuts_are_refused(printed, cuts, segments):
    _, _, (box1, *_) = printed
    with pytest.raises(SolidInputError):
        segment_housing(box1, cuts, segments=segments)


@pytest.mark.parametrize("volume, margin", [((256, 256), 1.0), ((256, 256, -1), 1.0),
                                            ((256, 256, 256), -1.0)],
                         ids=["two-sizes", "negative", "negative-margin"])
def test_bad_build_volumes_are_refused(printed, volume, margin):
    _, _, (box1, *_) = printed
    with pytest.raises(SolidInputError):
        segment_cuts(box1, volume, margin=margin)


def test_the_rest_of_the_pipeline_sees_the_segments(printed):
    from cadgen.export.meshes import material_key
    from cadgen.pipeline.clearances import _present
    from cadgen.report.bom import _bought_rows

    params, assembly, (box1, box2, *rest) = printed
    housings = {"gearbox1": box1, "gearbox2": box2}
    assert [r["housing"] for r in enclosure_checks(assembly, housings)] == ["gearbox1", "gearbox2"]
    # the assembly model places each segment as often as its housing: gearbox 2 once per arm
    copies = {p.name: len(p.instances) for p in assembly.parts if p.kind == "housing"}
    assert {copies[f"gearbox1-base-{k}"] for k in (1, 2, 3)} == {1}
    assert copies["gearbox2-base"] == copies["gearbox2-cover"] == 2
    assert material_key("gearbox1-cover-2", "housing") == "housing-cover"
    assert material_key("gearbox1-base-2", "housing") == "housing"
    parts = {p.name: p for p in assembly.parts}
    assert _present(("gearbox1-base", "gearbox2-cover"), parts) == [
        "gearbox1-base-1", "gearbox1-base-2", "gearbox1-base-3", "gearbox2-cover"]

    def screws(model):
        return sum(r["quantity"] for r in _bought_rows(model, None)
                   if r["part"] == "socket head cap screw")

    # each splice's bolts are bought once per placed copy of its housing
    spliced = sum(len(j.bolts) for j in box1.joints) + 2 * sum(len(j.bolts) for j in box2.joints)
    spliced += sum(len(j.bolts) for housing in rest for j in getattr(housing, "joints", ()))
    model = assembly.model
    assert screws(model) - screws(model.without(lambda j: j.detail.startswith("splice"))) == spliced
    assert Counter(len(j.bolts) for j in box1.joints) == {4: 2}
