"""A family's model built directly from its parameter values is the model its written file reads back as.

:meth:`Family.mechanism` builds the model from the writer's document (its description and a Pinocchio
model made from it) without writing or parsing a URDF; :meth:`Family.urdf` writes the same document when a
design is kept. For every bundled family at its defaults and at random values within the bounds, the two
models are checked equal: Pinocchio trees, every chain's geometry, joint names, limits, actuators, solver
and working mode, the reference assembly, the task coordinates and the indices at random poses.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import assert_indices_close, random_reachable_poses
from screwkit.io.loader import load, load_text
from screwkit.model.urdf_reader import parse_urdf
from screwkit.studies import indices_at_poses
from screwkit.studies.design.families import FAMILIES, family

TOLERANCE = 1e-12


def design_values(name: str, count: int, seed: int) -> list[dict[str, float]]:
    """The defaults and ``count`` candidates that assemble, drawn within the bounds of every parameter."""
    chosen, rng = family(name), np.random.default_rng(seed)
    found = [{}]
    while len(found) < count + 1:
        values = {}
        for parameter in chosen.parameters:
            value = rng.uniform(parameter.lower, parameter.upper)
            values[parameter.name] = float(round(value)) if parameter.integer else float(value)
        try:
            chosen.mechanism(values)
        except ValueError:  # an arm that cannot reach its platform joint: no candidate
            continue
        found.append(values)
    return found


def pinocchio_trees_equal(direct, read) -> None:
    assert (direct.name, direct.njoints, direct.nq, direct.nv, direct.nframes) == (
        read.name, read.njoints, read.nq, read.nv, read.nframes)
    assert list(direct.names) == list(read.names) and list(direct.parents) == list(read.parents)
    for one, other in zip(direct.joints, read.joints):
        assert (one.shortname(), one.idx_q, one.idx_v) == (other.shortname(), other.idx_q, other.idx_v)
    for one, other in zip(direct.jointPlacements, read.jointPlacements):
        np.testing.assert_allclose(one.homogeneous, other.homogeneous, rtol=0, atol=TOLERANCE)
    for one, other in zip(direct.frames, read.frames):
        assert (one.name, one.type, one.parentJoint, one.parentFrame) == (
            other.name, other.type, other.parentJoint, other.parentFrame)
        np.testing.assert_allclose(one.placement.homogeneous, other.placement.homogeneous, rtol=0, atol=TOLERANCE)
    for limits in ("lowerPositionLimit", "upperPositionLimit", "effortLimit", "velocityLimit"):
        np.testing.assert_array_equal(getattr(direct, limits), getattr(read, limits), err_msg=limits)


GEOMETRY = ("joint_rotations", "joint_translations", "joint_axes", "leg_loop_rotation", "leg_loop_translation",
            "loop_axes", "platform_loop_rotation", "platform_loop_translation")


def mechanisms_equal(direct, read) -> None:
    """The same model to :data:`TOLERANCE`, every name, flag and choice exactly."""
    pinocchio_trees_equal(direct.pinocchio_model, read.pinocchio_model)
    for name in ("name", "is_planar", "pose_coordinates", "base_link", "platform_link", "platform_joint",
                 "platform_joint_id", "dof", "instantaneous_dof", "task_axes", "task_source", "task_coordinates",
                 "actuators", "assembly_notes", "length_unit"):
        assert getattr(direct, name) == getattr(read, name), name
    for name in ("rotation_world_base", "translation_world_base", "home_rotation", "home_translation", "home_pose"):
        np.testing.assert_allclose(getattr(direct, name), getattr(read, name), rtol=0, atol=TOLERANCE, err_msg=name)
    np.testing.assert_allclose(direct.platform_frame_placement.homogeneous, read.platform_frame_placement.homogeneous,
                               rtol=0, atol=TOLERANCE)
    assert direct.length_scale == pytest.approx(read.length_scale, rel=0, abs=TOLERANCE)
    assert direct.named_poses.keys() == read.named_poses.keys()
    for pose in direct.named_poses:
        np.testing.assert_allclose(direct.named_poses[pose], read.named_poses[pose], rtol=0, atol=TOLERANCE)
    description, read_description = direct.description, read.description
    assert description.reference_configuration == read_description.reference_configuration
    assert description.task_coordinates == read_description.task_coordinates
    assert description.output == read_description.output
    assert [t.joints for t in description.transmissions] == [t.joints for t in read_description.transmissions]
    assert len(direct.chains) == len(read.chains)
    for one, other in zip(direct.chains, read.chains):
        for name in ("name", "joint_names", "actuated", "prismatic", "loop_name", "loop_type", "tree_joint_ids",
                     "solver", "solver_reason", "branch", "reference_sign"):
            assert getattr(one, name) == getattr(other, name), (one.name, name)
        assert (one.closed_form is None) == (other.closed_form is None)
        np.testing.assert_array_equal(one.joint_limits, other.joint_limits)
        np.testing.assert_allclose(one.reference_values, other.reference_values, rtol=0, atol=TOLERANCE)
        assert one.geometry.joint_prismatic == other.geometry.joint_prismatic
        assert one.geometry.loop_type == other.geometry.loop_type
        for name in GEOMETRY:
            np.testing.assert_allclose(getattr(one.geometry, name), getattr(other.geometry, name), rtol=0,
                                       atol=TOLERANCE, err_msg=f"{one.name}: {name}")


@pytest.mark.parametrize("name", list(FAMILIES))
def test_the_model_built_directly_is_the_one_its_file_reads_back_as(name, tmp_path):
    chosen = family(name)
    for number, values in enumerate(design_values(name, 3, seed=sorted(FAMILIES).index(name))):
        direct = chosen.mechanism(values)
        assert direct.description.read_text == ""  # no text was written to build it
        text = chosen.urdf(values)
        read = load_text(text, source=direct.path)
        mechanisms_equal(direct, read)
        path = tmp_path / f"{name}_{number}.urdf"  # the kept design, as design-search writes it
        path.write_text(text)
        mechanisms_equal(direct, load(path))
        assert direct.description.text == text  # written from the same records, on demand
        poses = random_reachable_poses(read, np.random.default_rng(number), 12)
        assert_indices_close(indices_at_poses(read, poses, detail=True), indices_at_poses(direct, poses, detail=True),
                             atol=TOLERANCE)


@pytest.mark.parametrize("name", list(FAMILIES))
def test_the_description_built_directly_is_the_one_the_reader_reads(name):
    """Field by field, bit for bit: the document's numbers are those its text reads back as."""
    chosen = family(name)
    for values in design_values(name, 2, seed=7):
        document = chosen.document(values)
        direct, read = document.description("same"), parse_urdf(document.text(), "same")
        for field in ("robot_name", "links", "reference_configuration", "named_poses", "length_unit",
                      "task_coordinates", "output"):
            assert getattr(direct, field) == getattr(read, field), field
        assert direct.joints.keys() == read.joints.keys()
        for joint, other in zip(direct.joints.values(), read.joints.values()):
            assert (joint.type, joint.parent, joint.child, joint.limits, joint.drive_limits) == (
                other.type, other.parent, other.child, other.limits, other.drive_limits)
            for one, two in ((joint.origin.xyz, other.origin.xyz), (joint.origin.rpy, other.origin.rpy),
                             (joint.axis, other.axis)):
                np.testing.assert_array_equal(one, two, err_msg=joint.name)
        for loop, other in zip(direct.loops, read.loops, strict=True):
            assert (loop.name, loop.type, loop.chain, loop.predecessor, loop.successor) == (
                other.name, other.type, other.chain, other.predecessor, other.successor)
            for one, two in ((loop.predecessor_origin, other.predecessor_origin),
                             (loop.successor_origin, other.successor_origin)):
                np.testing.assert_array_equal(one.xyz, two.xyz)
                np.testing.assert_array_equal(one.rpy, two.rpy)
            np.testing.assert_array_equal(np.array(loop.axes), np.array(other.axes))
        assert direct.transmissions == read.transmissions


def test_a_writer_that_returns_text_is_still_loaded_from_it():
    """A family declared with a writer ``values -> URDF text`` (docs/design.md, earlier releases) still works."""
    bundled = family("planar_rrr")
    texts = bundled.__class__(**{**{f: getattr(bundled, f) for f in bundled.__dataclass_fields__},
                                 "writer": lambda legs, values, name: bundled.writer(legs, values, name).text()})
    from_text, direct = texts.mechanism({"upper": 0.9}), bundled.mechanism({"upper": 0.9})
    assert from_text.description.read_text != ""
    mechanisms_equal(direct, from_text)
