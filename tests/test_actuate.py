"""``--actuate JOINT``: the actuators of a file of another tool named by the user, instead of those the file marks
or that screwkit guesses (SDFormat without markers, URDF exports without transmissions, MJCF actuators through
tendons).

What is checked against what:

* a file whose actuators are guessed, read with ``--actuate`` naming two of its three motors, has the textbook
  pressure angles of the five-bar with those two legs (:func:`test_io.assert_textbook`, closed forms), and the same
  indices as the file with those two joints marked in it;
* other joints driven (the elbows): the same indices as the file that marks the elbows, through the file's own
  reading path;
* a rod-level Delta read as a graph, its motors named in another order: the textbook pressure angles
  (:func:`test_graph_legs.textbook`), and a map's task rebuilds it with the same actuators;
* MJCF whose actuator drives a tendon: refused as written, opened with ``--actuate``;
* every mistake (unknown joint, a locked, fixed or ball joint, a name twice, a file in screwkit's convention) is one
  line naming the option and the joint; the command line as a subprocess.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from delta_rods import delta_rods_mjcf
from sdformat_models import delta_sdf, five_bar_sdf
from test_gallery_published import GEPETTO
from test_gazebo import five_bar_gazebo
from test_graph_legs import POSES, assert_delta_textbook, textbook
from test_io import assert_textbook, five_bar_gepetto, five_bar_mjcf, poses_near_home
from test_onshape import five_bar_onshape

from helpers import one_line_error, screwkit
from screwkit.io import ImportError_, graph_mechanism, read_closed_tree, read_mechanism_file
from screwkit.io.loader import load
from screwkit.studies.graph_source import cached_graph, graph_source
from screwkit.studies.poses import indices_at_poses

MARKER = "<screwkit:actuated/>"


def write(tmp_path, text: str, name: str = "robot.sdf"):
    path = tmp_path / name
    path.write_text(text)
    return path


def marked_only(text: str, joints) -> str:
    """A five-bar SDFormat text (unmarked) with ``<screwkit:actuated/>`` on ``joints`` alone."""
    for joint in joints:
        head = f'<joint name="{joint}" type='
        assert text.count(head) == 1
        start = text.index(head)
        end = text.index("</joint>", start)
        text = text[:end] + MARKER + text[end:]
    return text


def assert_same_indices(first, second, points) -> None:
    a, b = (indices_at_poses(m, points, detail=True) for m in (first, second))
    assert first.actuator_names == second.actuator_names
    for name in ("iti_actuators", "lmti", "oti_submechanisms"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=0, atol=1e-12, err_msg=name)
    for j in a.f_o:
        np.testing.assert_allclose(a.f_o[j], b.f_o[j], rtol=0, atol=1e-12)


@pytest.mark.parametrize("named", [("mot3", "mot1"), ("mot1", "mot3")])
def test_two_motors_of_a_guessed_five_bar_named_give_the_textbook_angles_of_those_two_legs(tmp_path, named):
    guessed = write(tmp_path, five_bar_sdf(marker=""))
    converted, report = read_mechanism_file(guessed, actuate=named)
    assert report.motors == list(named)
    assert not any(note.startswith("actuators guessed") for note in report.notes)
    assert f"actuators as given (--actuate): {', '.join(named)}; the file's were guessed: mot1, mot2, mot3" \
        in report.notes
    mechanism = load(guessed, actuate=named)
    assert mechanism.dof == 2 and mechanism.actuator_names == ("mot1:mot1", "mot3:mot3")  # the legs' own order
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points, legs=(0, 2))
    marked = load(write(tmp_path, marked_only(five_bar_sdf(marker=""), ("mot1", "mot3")), "marked.sdf"))
    assert_same_indices(mechanism, marked, points)


def test_the_elbows_driven_instead_give_what_the_file_marking_the_elbows_gives(tmp_path):
    guessed = write(tmp_path, five_bar_sdf(marker=""))
    elbows = ("free1", "free2", "free3")
    mechanism = load(guessed, actuate=elbows)
    marked = load(write(tmp_path, marked_only(five_bar_sdf(marker=""), elbows), "elbows.sdf"))
    points = poses_near_home()
    assert_same_indices(mechanism, marked, points)
    motors = indices_at_poses(load(guessed), points, detail=True)  # another mechanism: other numbers
    assert np.abs(indices_at_poses(mechanism, points, detail=True).iti_actuators - motors.iti_actuators).max() > 0.01


def test_a_file_that_marks_its_motors_is_overridden_and_says_which_it_had(tmp_path):
    path = write(tmp_path, five_bar_sdf(marker="screwkit"))
    _, report = read_mechanism_file(path, actuate=("mot2", "mot3"))
    assert report.motors == ["mot2", "mot3"]
    assert "actuators as given (--actuate): mot2, mot3; the file's are: mot1, mot2, mot3" in report.notes


def test_a_rod_level_delta_with_its_motors_named_in_another_order_through_the_graph(tmp_path):
    path = write(tmp_path, delta_sdf(POSES[0], plugin=False).replace(MARKER, ""), "delta.sdf")
    named = ("motor_4", "motor_2", "motor_1", "motor_3")
    tree = read_closed_tree(path, actuate=named)
    assert tree.motors == list(named) and tree.actuated == named
    graph = graph_mechanism(tree)
    assert_delta_textbook(graph.indices(), textbook(POSES[0]))
    rebuilt = cached_graph(graph_source(graph))  # what a map's task reads where it runs
    assert rebuilt.tree.motors == list(named)
    np.testing.assert_array_equal(rebuilt.indices().lmti, graph.indices().lmti)


def test_an_mjcf_actuator_through_a_tendon_is_refused_unless_the_actuators_are_named(tmp_path):
    text = five_bar_mjcf().replace('<motor name="m_3" joint="a_3"/>', '<motor name="m_3" tendon="t"/>')
    text = text.replace("</mujoco>", '<tendon><fixed name="t"><joint joint="a_3" coef="1"/></fixed></tendon>'
                                     "</mujoco>")
    path = write(tmp_path, text, "five_bar.xml")
    with pytest.raises(ImportError_, match=r"five_bar\.xml: <actuator><motor name='m_3'> drives no joint \(tendon "
                                           r"and site transmissions are not supported\); --actuate JOINT names"):
        read_closed_tree(path)
    mechanism = load(path, actuate=("a_1", "a_2", "a_3"))
    points = poses_near_home()
    assert_textbook(indices_at_poses(mechanism, points, detail=True), points)
    _, report = read_mechanism_file(path, actuate=("a_1", "a_2", "a_3"))
    assert any("the file's could not be taken (<actuator><motor name='m_3'> drives no joint" in note
               for note in report.notes), report.notes


DRIVABLE = r"; the joints that can be driven \(revolute or prismatic\) are table, mot1, mot2, mot3, free1, free2, " \
    r"free3, loop_1\.$"

MISTAKES = [
    (("nope",), r"--actuate nope: no joint of that name" + DRIVABLE),
    (("loop_2",), r"--actuate loop_2: it closes a loop, which screwkit cuts there \(a joint of the tree can be "
                  r"driven\)" + DRIVABLE),
    (("anchor",), r"--actuate anchor: a fixed joint, which cannot drive anything" + DRIVABLE),
    (("mot1", "mot1"), r"robot\.sdf: --actuate mot1: given twice"),
    (("",), r"robot\.sdf: --actuate: expected joint names, got ''"),
]


@pytest.mark.parametrize("names, message", MISTAKES)
def test_a_joint_that_cannot_be_actuated_is_refused_naming_it(tmp_path, names, message):
    path = write(tmp_path, five_bar_sdf(marker="", stage=True))
    with pytest.raises(ImportError_, match=message):
        read_closed_tree(path, actuate=names)


def test_a_locked_joint_and_a_ball_joint_are_refused(tmp_path):
    path = write(tmp_path, five_bar_sdf(marker="", stage=True))
    with pytest.raises(ImportError_, match=r"robot\.sdf: --actuate table: the joint is held by --lock table; the "
                                           r"joints that can be driven \(revolute or prismatic\) are mot1, "):
        read_closed_tree(path, lock=("table",), actuate=("table", "mot1"))
    delta = write(tmp_path, delta_sdf(POSES[0]), "delta.sdf")
    with pytest.raises(ImportError_, match=r"delta\.sdf: --actuate ball_2a: a ball joint \(3 DoF\), not a 1-DoF joint; "
                                           r"the joints that can be driven \(revolute or prismatic\) are motor_1"):
        read_closed_tree(delta, actuate=("ball_2a",))
    with pytest.raises(ImportError_, match=r"delta\.sdf: --actuate ball_2a_y: one hinge of ball joint 'ball_2a', not a "
                                           r"1-DoF joint"):
        read_closed_tree(delta, actuate=("motor_1", "ball_2a_y"))
    with pytest.raises(ImportError_, match=r"delta\.sdf: --actuate nope: no joint of that name; the joints that can "
                                           r"be driven \(revolute or prismatic\) are motor_1, motor_2, motor_3, "
                                           r"motor_4\.$"):
        read_closed_tree(delta, actuate=("nope",))
    mjcf = write(tmp_path, delta_rods_mjcf(POSES[0]), "delta.xml")  # MJCF: Pinocchio's own spherical joint
    with pytest.raises(ImportError_, match=r"delta\.xml: --actuate ball_2a: a joint of 3 DoF \(JointModelSpherical"
                                           r"\), not a 1-DoF joint; the joints that can be driven"):
        read_closed_tree(mjcf, actuate=("ball_2a",))


def test_a_string_is_one_name_and_a_file_in_screwkits_convention_refuses_the_option(tmp_path):
    path = write(tmp_path, five_bar_sdf(marker=""))
    assert read_closed_tree(path, actuate="mot2").motors == ["mot2"]
    for wrong, shown in ((5, "int 5"), (b"mot1", "bytes b'mot1'")):
        with pytest.raises(ImportError_, match=rf"robot\.sdf: --actuate: expected joint names \(strings\), got "
                                               rf"{shown}"):
            read_closed_tree(path, actuate=wrong)
    with pytest.raises(ValueError, match=r"five_bar_3\.urdf: an output frame or type, locked, actuated or initial "
                                         r"joints named apart from the file apply to files of other tools"):
        load("five_bar_3", actuate=("motor_1",))


def test_the_command_line_drives_the_joints_named(tmp_path):
    """``analyze``, ``info`` and ``convert`` with ``--actuate``, as subprocesses: the same figures as the file that
    marks those joints, the converted file's transmissions, and a mistake in one line."""
    guessed = write(tmp_path, five_bar_sdf(marker=""))
    marked = write(tmp_path, marked_only(five_bar_sdf(marker=""), ("mot1", "mot3")), "marked.sdf")
    given = screwkit("analyze", guessed, "--actuate", "mot3", "--actuate", "mot1", "--json")
    assert given.returncode == 0, given.stderr
    own = screwkit("analyze", marked, "--json")
    assert own.returncode == 0, own.stderr
    given, own = json.loads(given.stdout), json.loads(own.stdout)
    assert given["actuators"] == own["actuators"] == ["mot1:mot1", "mot3:mot3"] and given["f_o"] == {"1": 0.0}
    for key in ("iti", "lmti", "iti_actuators", "f_o", "f_io"):
        assert given[key] == pytest.approx(own[key], abs=1e-12), key
    info = screwkit("info", guessed, "--actuate", "mot3", "--actuate", "mot1")
    assert info.returncode == 0, info.stderr
    assert "actuators as given (--actuate): mot3, mot1" in info.stdout
    out = tmp_path / "converted.urdf"
    converted = screwkit("convert", guessed, out, "--actuate", "mot3", "--actuate", "mot1")
    assert converted.returncode == 0, converted.stderr
    assert load(out).actuator_names == load(marked).actuator_names
    one_line_error(screwkit("analyze", guessed, "--actuate", "nope"), "robot.sdf: --actuate nope: no joint of that "
                   "name")
    one_line_error(screwkit("analyze", "five_bar_3", "--actuate", "motor_1"), "five_bar_3.urdf: an output frame or "
                   "type, locked, actuated or initial joints")


def _gepetto_without_name_mot(tmp_path):
    urdf, yaml = five_bar_gepetto()
    (tmp_path / "robot.urdf").write_text(urdf)
    (tmp_path / "robot.yaml").write_text("\n".join(line for line in yaml.splitlines() if "name_mot" not in line))
    return tmp_path / "robot.urdf", ("mot1", "mot2", "mot3")


def _onshape_naming_no_joint(tmp_path):
    bad = ('<transmission name="t"><type>transmission_interface/SimpleTransmission</type><joint name="gripper"/>'
           "</transmission>")
    path = write(tmp_path, five_bar_onshape().replace("</robot>", bad + "</robot>"), "robot.urdf")
    return path, ("motor1", "motor2", "motor3")


def _gazebo_naming_a_loop_joint(tmp_path):
    bad = ('<transmission name="t"><type>transmission_interface/SimpleTransmission</type><joint name="loop_2"/>'
           "</transmission>")
    path = write(tmp_path, five_bar_gazebo(transmissions=False).replace("</robot>", bad + "</robot>"), "robot.urdf")
    return path, ("mot1", "mot2", "mot3")


def _sdformat_marking_a_ball(tmp_path):
    text = delta_sdf(POSES[0], plugin=False).replace('type="ball"><parent>arm_2</parent>',
                                                     f'type="ball">{MARKER}<parent>arm_2</parent>', 1)
    return write(tmp_path, text, "delta.sdf"), ("motor_1", "motor_2", "motor_3", "motor_4")


@pytest.mark.parametrize("make, message", [
    (_gepetto_without_name_mot, r"robot\.yaml: name_mot must list the actuated joints"),
    (_onshape_naming_no_joint, r"<transmission> names joint\(s\) gripper, not 1-DoF joints of the tree"),
    (_gazebo_naming_a_loop_joint, r"<transmission> names joint\(s\) loop_2, not in the tree"),
    (_sdformat_marking_a_ball, r"joint 'ball_2a' is marked actuated but is a ball joint, not a 1-DoF one"),
])
def test_a_file_whose_own_marking_is_wrong_is_refused_as_written_and_opens_with_its_actuators_named(tmp_path, make,
                                                                                                      message):
    """Each reader refused the file's wrong or missing marking before --actuate could replace it, listing the joints
    that can be driven (those that open it among them)."""
    path, named = make(tmp_path)
    with pytest.raises(ImportError_, match=message + r"; --actuate JOINT names the actuated joints \(those that can "
                                                     r"be driven, revolute or prismatic: .*\)\.$") as refused:
        read_closed_tree(path)
    listed = str(refused.value).rsplit("revolute or prismatic: ", 1)[1].removesuffix(").").split(", ")
    assert set(named) <= set(listed), listed
    tree = read_closed_tree(path, actuate=named)
    assert tree.motors == list(named)
    assert any(note.startswith("actuators as given (--actuate)") and "the file's could not be taken" in note
               for note in tree.notes), tree.notes
    if path.suffix == ".sdf":  # the rod-level Delta: a graph, its textbook
        assert_delta_textbook(graph_mechanism(tree).indices(), textbook(POSES[0]))
    else:
        points = poses_near_home()
        assert_textbook(indices_at_poses(load(path, actuate=named), points, detail=True), points)


def test_a_refusal_after_reading_names_the_option_that_named_the_joint():
    """A joint named that is on no leg (the published five-bar's closing frame): the message said "actuated joint",
    as if the file had marked it."""
    published = Path(__file__).parent / "data/gallery/published/example_parallel_robots/5bar_linkage/robot.urdf"
    with pytest.raises(ImportError_, match=r"robot\.yaml: --actuate closedloop1_B is on no leg"):
        read_mechanism_file(published, actuate=("closedloop1_B", "mot1"))


def test_analyze_says_in_its_first_line_when_the_actuators_are_guessed(tmp_path):
    """A file that names no actuator is analysed with the ones guessed from the branches leaving the base, and every
    fault-tolerance figure is about that guess: `analyze` says so in its first line and in its JSON
    (``actuators_guessed``), not only in the import report on stderr; not when the file or ``--actuate`` names them.
    A passive Gazebo four-bar had read "2 actuators, 1 DOF (1 redundant)", F_O1 = 1, with nothing beside it."""
    guessed, marked = write(tmp_path, five_bar_sdf(marker="")), write(tmp_path, five_bar_sdf(), "marked.sdf")
    runs = {"guessed": screwkit("analyze", guessed), "marked": screwkit("analyze", marked),
            "named": screwkit("analyze", guessed, "--actuate", "mot1", "--actuate", "mot2")}
    for label, run in runs.items():
        assert run.returncode == 0, (label, run.stderr)
        assert ("(guessed: the file names none" in run.stdout.splitlines()[0]) == (label == "guessed"), label
    delta = write(tmp_path, re.sub(r"<plugin .*?</plugin>", "", delta_sdf()), "delta.sdf")  # through the graph
    for label, path in (("guessed", guessed), ("marked", marked), ("guessed", delta)):
        run = screwkit("analyze", path, "--json")
        assert json.loads(run.stdout)["actuators_guessed"] == (label == "guessed"), label
    assert "4 actuators (guessed: the file names none" in screwkit("analyze", delta).stdout.splitlines()[0]


def test_a_fixed_joint_named_as_its_link_is_refused_as_fixed(tmp_path):
    """A link with its joint's name (allowed in URDF; MuJoCo's custom) makes two frames of one name; the fixed joint's
    was looked up by name alone, and Pinocchio refused with its own "Several frames match the filter"."""
    source = GEPETTO / "5bar_linkage"
    text = re.sub(r'(link|name)="effector"', r'\1="effector_frame"', (source / "robot.urdf").read_text())
    assert '<link name="effector_frame"' in text and '<child link="effector_frame"' in text
    (tmp_path / "robot.urdf").write_text(text)
    shutil.copy(source / "robot.yaml", tmp_path / "robot.yaml")
    with pytest.raises(ImportError_, match=r"robot\.urdf \+ robot\.yaml: --actuate effector_frame: a fixed joint, "
                                           r"which cannot drive anything; the joints that can be driven \(revolute or "
                                           r"prismatic\) are "):
        read_closed_tree(tmp_path / "robot.urdf", actuate=("effector_frame",))
