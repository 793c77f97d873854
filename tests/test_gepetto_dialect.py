"""A Gepetto robot.yaml in example-parallel-robots' earlier dialect (2023), read as its tools read it.

That dialect wrote ``name_mot`` as a pattern of the motors' names (its ``getMotId_q``: ``re.search``) and
``rotule_name`` as one of the joints made ball joints (its ``jointTypeUpdate``), beside ``Lidmot`` / ``Lidvmot``
(the motors' coordinates). The robots it described were later rewritten with lists (``name_mot``, ``joint_name``,
``joint_type``), and the loader reads its keys by name and passes over any other. Such a file was refused (``unknown
key(s) Lidmot, Lidvmot, rotule_name``, naming three of the five keys read). Now it opens as written, the report
saying how each key was read: ``custom_1``'s files (three R-R-S legs, balls ``to_rotule_1..3``, six motors
``mot_1..6``) written in the earlier dialect read as written in the later one, index for index.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from test_universal_input import CUSTOM, HIPS

from helpers import screwkit, screwkit_json
from screwkit.io import graph_mechanism, read_closed_tree
from screwkit.io.closed_tree import ImportError_

EARLIER = {"closed_loop": [["fermeture1_B", "fermeture1_A"], ["fermeture2_B", "fermeture2_A"]], "type": ["6d", "6d"],
           "name_mot": "mot", "rotule_name": "to_rotule", "Lidmot": [0, 1, 2, 3, 4, 5], "Lidvmot": [0, 1, 2, 3, 4, 5],
           "comment": "a key no loader reads"}


def _written(tmp_path, spec: dict):
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "robot.urdf").write_text((CUSTOM / "robot.urdf").read_text())
    (tmp_path / "robot.yaml").write_text(yaml.safe_dump(spec))
    return tmp_path / "robot.urdf"


def _indices(path):
    tree = read_closed_tree(path, lock=HIPS)
    return tree, graph_mechanism(tree).indices()


def test_the_earlier_dialect_reads_as_the_later_one(tmp_path):
    later = yaml.safe_load((CUSTOM / "robot.yaml").read_text())
    assert sorted(later["joint_name"]) == ["to_rotule_1", "to_rotule_2", "to_rotule_3"]  # what the pattern must find
    tree, ours = _indices(_written(tmp_path / "earlier", EARLIER))
    _, theirs = _indices(_written(tmp_path / "later", later))
    assert sorted(ours.actuators) == sorted(theirs.actuators)
    for name in ("iti_actuators", "oti_actuators", "lmti", "cti"):
        np.testing.assert_allclose(getattr(ours, name), getattr(theirs, name), rtol=0, atol=1e-12, err_msg=name)
    said = "\n".join(tree.notes)
    assert "name_mot 'mot' read as a pattern of the motors' names" in said and "mot_1, mot_2, mot_3" in said
    assert "rotule_name 'to_rotule' read as a pattern of the ball joints' names" in said and "to_rotule_3" in said
    assert "key(s) Lidmot, Lidvmot, comment passed over" in said


def test_rotule_name_beside_joint_name_is_passed_over_and_said(tmp_path):
    later = yaml.safe_load((CUSTOM / "robot.yaml").read_text())
    tree, ours = _indices(_written(tmp_path / "both", {**later, "rotule_name": "libre"}))
    _, theirs = _indices(_written(tmp_path / "later", later))
    np.testing.assert_allclose(ours.lmti, theirs.lmti, rtol=0, atol=1e-12)
    assert any("rotule_name 'libre' passed over: joint_name and joint_type say the joints" in note
               for note in tree.notes)


@pytest.mark.parametrize("change, needle", [
    ({"name_mot": "("}, "name_mot '(' is not a pattern of joint names (missing )"),
    ({"rotule_name": "(["}, "rotule_name '([' is not a pattern of joint names"),
    ({"name_mot": ""}, "name_mot '' would take every joint"),
    ({"rotule_name": ""}, "rotule_name '' would take every joint"),
    ({"name_mot": "zzz"}, "name_mot 'zzz', read as a pattern of the motors' names, matches no joint; --actuate"),
])
def test_a_pattern_that_cannot_be_read_is_refused_naming_it(tmp_path, change, needle):
    """One line naming the key and the pattern (an invalid one raised Python's ``re.error`` from deep inside)."""
    with pytest.raises(ImportError_) as error:
        read_closed_tree(_written(tmp_path, {**EARLIER, **change}), lock=HIPS)
    assert needle in str(error.value) and "\n" not in str(error.value)


def test_keys_of_any_type_beside_the_earlier_ones_are_passed_over_and_said(tmp_path):
    """Keys that are numbers or null beside string keys (a sorted() of mixed types raised TypeError), and a
    ``rotule_name`` that is no string."""
    later = yaml.safe_load((CUSTOM / "robot.yaml").read_text())
    tree = read_closed_tree(_written(tmp_path, {**later, 1: "x", None: "y", "comment": "z", "rotule_name": [1, 2]}),
                            lock=HIPS)
    said = "\n".join(tree.notes)
    assert "key(s) 1, None, comment passed over" in said
    assert "rotule_name [1, 2] passed over: not a pattern of joint names" in said


@pytest.mark.cli
def test_the_command_opens_the_earlier_dialect_and_says_how_it_read_it(tmp_path):
    path = _written(tmp_path, EARLIER)
    completed = screwkit("info", path, *[item for hip in HIPS for item in ("--lock", hip)])
    assert completed.returncode == 0, completed.stderr
    assert "read as a pattern of the motors' names" in completed.stdout
    assert "passed over: example-parallel-robots' loader reads closed_loop, type, name_mot, joint_name, " \
           "joint_type" in completed.stdout


GALLERY = CUSTOM.parent


def _sine(u, v, normal) -> float:
    """|sin| of the angle between u and v, both projected on the plane of ``normal``."""
    u, v = (w - (w @ normal) * normal for w in (u, v))
    return float(abs(np.cross(u, v) @ normal) / (np.linalg.norm(u) * np.linalg.norm(v)))


@pytest.mark.cli
def test_a_published_five_bar_in_the_earlier_dialect_opens_as_written_with_its_pressure_angles():
    """``robot_simple`` (removed from the repository in 2024; its robot.yaml ``name_mot: mot``, ``rotule_name:
    to_rotule``, ``Lidmot``, ``Lidvmot``): the command reads it as written, and at the configuration it reports,
    put into Pinocchio's own model of the URDF, each ITI is |sin| between the crank and the rod and the LMTI |sin|
    between the two rods at the closure point (the paper's planar forms), to 1e-12."""
    import pinocchio as pin

    path = GALLERY / "robot_simple" / "robot.urdf"
    read = screwkit_json("analyze", path)
    model = pin.buildModelFromUrdf(str(path))
    data, q = model.createData(), pin.neutral(model)
    for key, value in read["configuration"].items():
        if model.existJointName(name := key.split(":")[1]):  # (not the chains' loop joints, screwkit's own)
            joint = model.joints[model.getJointId(name)]
            q[joint.idx_q] = np.radians(value["value"]) if value["unit"] == "deg" else value["value"]
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    at = {name: data.oMf[model.getFrameId(name)].translation for name in
          ("mot1", "libre1", "mot2", "libre2", "fermeture1_A", "fermeture1_B")}
    assert np.linalg.norm(at["fermeture1_A"] - at["fermeture1_B"]) < 1e-9  # the loop closed there
    normal, point = data.oMi[model.getJointId("mot1")].rotation[:, 2], at["fermeture1_A"]
    for motor, elbow in (("mot1", "libre1"), ("mot2", "libre2")):
        expected = _sine(at[elbow] - at[motor], point - at[elbow], normal)
        assert read["iti_actuators"][f"{motor}:{motor}"] == pytest.approx(expected, abs=1e-12)
    assert read["lmti"] == pytest.approx(_sine(point - at["libre1"], point - at["libre2"], normal), abs=1e-12)


@pytest.mark.cli
def test_a_graph_leg_on_the_platforms_own_path_says_so_where_its_loop_is_named():
    """``robot_marcheur_6`` (a 6-SPS leg read as a graph): the leg the foot hangs on has no closure of its own; ``info``
    printed an empty name there (``loop  (graph)``)."""
    completed = screwkit("info", GALLERY / "robot_marcheur_6" / "robot.urdf")
    assert completed.returncode == 0, completed.stderr
    assert "loop none, the platform body's own path (graph)" in completed.stdout
    assert "loop  (" not in completed.stdout
