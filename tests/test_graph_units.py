"""A file of another tool whose legs have loops inside them, written in millimetres, read with ``--length-unit mm``
(:mod:`screwkit.io.tree_units`): it used to be refused, and read without the option its poses, threshold and
reports were in millimetres labelled metres.

The rod-level Delta (tests/delta_rods.py) written in metres and the same robot written x1000: read in mm, every
index, the length scale and the poses solved at positions given in metres are those of the metre file; a map's
task rebuilds the graph in metres; every length of the tree (joint and frame placements, closures, the values
and limits of a slide) is the metre file's, and a joint whose lengths are not known is refused.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from delta_rods import delta_rods_mjcf
from sdformat_models import ups_sdf
from test_graph_legs import POSES

from helpers import screwkit
from screwkit.io import ImportError_, graph_mechanism, read_closed_tree
from screwkit.io.tree_units import in_metres
from screwkit.studies.graph_source import cached_graph, graph_source
from screwkit.studies.poses import graph_indices_at_poses

THOUSAND = (1000.0, np.eye(3), np.zeros(3))


def files(tmp_path):
    metres, millimetres = tmp_path / "delta.xml", tmp_path / "delta_mm.xml"
    metres.write_text(delta_rods_mjcf(POSES[0]))
    millimetres.write_text(delta_rods_mjcf(POSES[0], transform=THOUSAND))
    return metres, millimetres


def test_a_graph_written_in_millimetres_is_the_metre_file_once_read_in_mm(tmp_path):
    metres, millimetres = files(tmp_path)
    own = graph_mechanism(read_closed_tree(metres))
    read = graph_mechanism(read_closed_tree(millimetres, length_unit="mm"))
    assert read.length_scale == pytest.approx(own.length_scale, rel=1e-12)
    assert graph_mechanism(read_closed_tree(millimetres)).length_scale == pytest.approx(1000 * own.length_scale)
    first, second = own.indices(), read.indices()
    np.testing.assert_allclose(second.iti_actuators, first.iti_actuators, atol=1e-12)
    np.testing.assert_allclose([second.lmti, second.f_o[1]], [first.lmti, first.f_o[1]], atol=1e-12)
    targets = np.array(POSES[0]) + np.array([[0.0, 0.0, 0.0], [0.02, -0.01, 0.01], [-0.03, 0.02, -0.02]])
    at_metres, at_read = (graph_indices_at_poses(graph, targets) for graph in (own, read))
    assert at_read.reachable.all()
    np.testing.assert_allclose(at_read.lmti, at_metres.lmti, atol=1e-9)
    rebuilt = cached_graph(graph_source(read))  # a map's task, where it runs
    assert rebuilt.tree.length_unit == "mm" and rebuilt.length_scale == pytest.approx(own.length_scale, rel=1e-12)


def test_every_length_of_the_tree_is_brought_to_metres(tmp_path):
    """The 8-UPS written in SDFormat in metres and in millimetres (its slides, whose limits and values are lengths):
    read in mm, every joint placement, frame placement, closure and slide limit is the metre file's."""
    metres, millimetres = tmp_path / "ups.sdf", tmp_path / "ups_mm.sdf"
    metres.write_text(ups_sdf(limits=0.3))
    millimetres.write_text(ups_sdf(scale=1000.0, limits=0.3))
    own, read = read_closed_tree(metres), read_closed_tree(millimetres, length_unit="mm")
    for k in range(1, own.model.njoints):
        np.testing.assert_allclose(read.model.jointPlacements[k].translation, own.model.jointPlacements[k].translation,
                                   atol=1e-12)
    for mine, theirs in zip(read.model.frames, own.model.frames):
        np.testing.assert_allclose(mine.placement.translation, theirs.placement.translation, atol=1e-12)
    for mine, theirs in zip(read.closures, own.closures):
        np.testing.assert_allclose(mine.placement_a, theirs.placement_a, atol=1e-12)
        np.testing.assert_allclose(mine.placement_b, theirs.placement_b, atol=1e-12)
    np.testing.assert_allclose(read.model.upperPositionLimit, own.model.upperPositionLimit, atol=1e-12)
    np.testing.assert_allclose(read.model.lowerPositionLimit, own.model.lowerPositionLimit, atol=1e-12)
    slides = [k for k in range(1, own.model.njoints) if "slider" in own.model.names[k]]
    assert len(slides) == 8 and all(own.model.upperPositionLimit[own.model.joints[k].idx_q] == 0.3 for k in slides)
    moved = read_closed_tree(metres)
    moved.q_reference = moved.q_reference + 0.25  # a reference configuration with the slides out by 0.25 m
    back = in_metres(in_metres(moved, "mm"), "km")  # lengths x 1e-3 then x 1e3: the same tree
    np.testing.assert_allclose(back.q_reference, moved.q_reference, atol=1e-15)
    assert in_metres(moved, "m") is moved and in_metres(moved, None) is moved


def test_a_joint_whose_lengths_are_not_known_is_refused(tmp_path):
    import pinocchio as pin

    metres, _ = files(tmp_path)
    tree = read_closed_tree(metres)
    model = pin.Model(tree.model)
    model.addJoint(0, pin.JointModelHelicalUnaligned(np.array([0.0, 0.0, 1.0]), 0.1), pin.SE3.Identity(), "screw")
    tree.model = model
    with pytest.raises(ImportError_, match=r"delta\.xml: --length-unit mm: joint 'screw' is a "
                                           r"JointModelHelicalUnaligned, whose lengths are not known to screwkit"):
        in_metres(tree, "mm")


def test_the_command_line_reads_a_graph_in_millimetres(tmp_path):
    metres, millimetres = files(tmp_path)
    pose = ["--pose", "0.06 0.02 -0.45", "--json"]
    read = screwkit("analyze", millimetres, "--length-unit", "mm", *pose)
    assert read.returncode == 0, read.stderr
    own = screwkit("analyze", metres, *pose)
    assert own.returncode == 0, own.stderr
    read, own = json.loads(read.stdout), json.loads(own.stdout)
    assert read["pose"] == own["pose"] == {"x": 0.06, "y": 0.02, "z": -0.45}
    for key in ("iti", "lmti"):
        assert read[key] == pytest.approx(own[key], abs=1e-9), key
    info = screwkit("info", millimetres, "--length-unit", "mm")
    assert info.returncode == 0 and "delta_mm.xml, lengths in mm in the file" in info.stdout, info.stderr
