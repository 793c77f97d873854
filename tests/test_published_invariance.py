"""Invariance of reading, on the files users bring.

* Every published URDF of the gallery (Gepetto's example-parallel-robots, a ROS 2 closed-loop workspace) written
  otherwise -- every length times 1000 and read in millimetres, hung from a new root link moved and turned in the
  world, its links and joints listed backwards and, where a ``robot.yaml`` names its closures, those listed
  backwards with each pair's frames swapped -- reads the same mechanism: the same actuators, and at the file's
  configuration the same ITI of each actuator, LMTI, every F_Oj and F_IOj, CTI and F_Cj (to 1e-11; the times 1000
  rounds each number in its last bit at most). A file refused as published is refused in the same words after its
  name. Files that open only with the locks their own refusals advise are taken with those locks.
* Every published MJCF file with its bodies, equalities and actuators listed backwards (which renumbers its joints
  in Pinocchio, unlike a URDF's order) and, where no free joint must stay at the top, hung in a moved, turned world.
* The published SDFormat files in millimetres, listed backwards, placed elsewhere in the world.

The bundled mechanisms have their own invariance tests (``tests/test_invariance.py``, ``tests/test_relabelling.py``);
these are the files no generator of ours wrote.
"""
from __future__ import annotations

import re
import shutil
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
import pytest
import yaml

from screwkit.io import ImportError_, LegWithLoops, graph_mechanism, read_closed_tree
from screwkit.io.loader import load
from screwkit.studies import indices_at_pose

PUBLISHED = Path(__file__).resolve().parent / "data" / "gallery" / "published"
GEPETTO = PUBLISHED / "example_parallel_robots"
TOLERANCE = 1e-11
OPENING = {  # the file, and the locks its own refusals advise (none: it opens as written)
    "5bar_linkage": (), "custom_1": (), "robot_delta": (), "robot_marcheur_6": (), "robot_simple": (),
    "wl16_like": (),
    "digit_like": ("motor_hip_x", "motor_hip_y", "motor_hip_z", "motor_knee", "free_knee"),
    "cassie_like": ("motor_hip1", "motor_hip2", "motor_tigh", "motor_knee", "free_knee"),
}
OPENING_FILES = [GEPETTO / name / "robot.urdf" for name in OPENING] + [
    PUBLISHED / "ros2_closed_loop_ws" / "3dof_delta.urdf", PUBLISHED / "ros2_closed_loop_ws" / "fivebar_linkage.urdf"]
REFUSED = ["battobot_6d", "digit_like_2legs", "digit_like_2legs_6D", "robot_ludo", "robot_marcheur_2"]
SDF_FILES = [PUBLISHED / "ros2_closed_loop_demo" / "model.sdf",
             PUBLISHED / "example_robot_data_cassie" / "cassie_v2.sdf"]
MJCF_FILES = [PUBLISHED / "lab_robots_iitk" / "5bar.xml", PUBLISHED / "reachy_mini" / "reachy_mini.xml",
              PUBLISHED / "agility_cassie" / "cassie.xml", PUBLISHED / "pinocchio_closed_chain" / "closed_chain.xml",
              PUBLISHED / "golf_modeling_suite" / "delta_robot.xml", PUBLISHED / "kayra" / "kayraCircle.xml"]


def _numbers(text: str | None, factor: float) -> str | None:
    return None if text is None else " ".join(repr(float(value) * factor) for value in text.split())


def rewritten(source: Path, folder: Path) -> Path:
    """``source``'s folder copied into ``folder``, the URDF in millimetres (origins, prismatic limits and shapes
    times 1000), under a new root link placed at (0.3, -0.2, 0.5) m turned by rpy (0.4, -0.7, 1.1), its links and
    joints listed backwards; a ``robot.yaml`` beside it with its closures listed backwards, each pair swapped."""
    target = folder / source.parent.name
    shutil.copytree(source.parent, target)
    robot = ElementTree.fromstring(source.read_text())
    for origin in robot.iter("origin"):
        if "xyz" in origin.attrib:
            origin.set("xyz", _numbers(origin.get("xyz"), 1000.0))
    for joint in robot.iter("joint"):
        for limit in joint.iter("limit") if joint.get("type") == "prismatic" else ():
            for bound in ("lower", "upper"):
                if bound in limit.attrib:
                    limit.set(bound, _numbers(limit.get(bound), 1000.0))
    for tag, sizes in (("box", ("size",)), ("cylinder", ("radius", "length")), ("sphere", ("radius",)),
                       ("mesh", ("scale",))):
        for shape in robot.iter(tag):
            for size in (size for size in sizes if size in shape.attrib or size == "scale"):
                shape.set(size, _numbers(shape.get(size, "1 1 1"), 1000.0))
    children = {joint.find("child").get("link") for joint in robot.iter("joint")}
    (root,) = [link.get("name") for link in robot.findall("link") if link.get("name") not in children]
    parts = [element for element in robot if element.tag in ("link", "joint")]
    for element in parts:
        robot.remove(element)
    world = ElementTree.SubElement(robot, "joint", name="moved_world_joint", type="fixed")
    ElementTree.SubElement(world, "parent", link="moved_world")
    ElementTree.SubElement(world, "child", link=root)
    ElementTree.SubElement(world, "origin", xyz="300.0 -200.0 500.0", rpy="0.4 -0.7 1.1")
    robot.extend(reversed(parts))
    ElementTree.SubElement(robot, "link", name="moved_world")
    (target / source.name).write_text(ElementTree.tostring(robot, encoding="unicode"))
    companion = target / "robot.yaml"
    if companion.is_file():
        settings = yaml.safe_load(companion.read_text())
        settings["closed_loop"] = [list(reversed(pair)) for pair in reversed(settings["closed_loop"])]
        companion.write_text(yaml.safe_dump(settings))
    return target / source.name


def mjcf_rewritten(source: Path, folder: Path) -> Path:
    """``source`` (MJCF) with the bodies of every body, the equality constraints and the actuators listed
    backwards (each body's joints kept in their order, which composes them), and its world's bodies hung from a new
    body moved to (0.3, -0.2, 0.5) and turned, unless a free joint must stay at the top (MuJoCo's rule)."""
    model = ElementTree.fromstring(source.read_text())
    for parent in [*model.iter("worldbody"), *model.iter("body"), *model.iter("equality"), *model.iter("actuator")]:
        kept = [child for child in parent if parent.tag in ("equality", "actuator") or child.tag == "body"]
        places = [index for index, child in enumerate(parent) if child in kept]
        for index, child in zip(places, reversed(kept)):
            parent[index] = child
    world = model.find("worldbody")
    if not any(joint.get("type") == "free" for joint in model.iter("joint")) and model.find(".//freejoint") is None:
        moved = ElementTree.Element("body", name="moved_world", pos="0.3 -0.2 0.5", quat="0.8 0.3 -0.4 0.2")
        moved.extend(list(world))
        for child in list(world):
            world.remove(child)
        world.append(moved)
    target = folder / source.name
    target.write_text(ElementTree.tostring(model, encoding="unicode"))
    return target


def sdf_rewritten(source: Path, folder: Path) -> Path:
    """``source`` (SDFormat, one model) in millimetres (every pose's position and prismatic limit times 1000), its
    links and joints listed backwards, the model placed at (0.3, -0.2, 0.5) m turned by rpy (0.4, -0.7, 1.1)."""
    root = ElementTree.fromstring(source.read_text())
    for pose in root.iter("pose"):
        values = (pose.text or "").split()
        if len(values) == 6:
            pose.text = " ".join([*_numbers(" ".join(values[:3]), 1000.0).split(), *values[3:]])
    for joint in root.iter("joint"):
        for bound in joint.iter("lower") if joint.get("type") == "prismatic" else ():
            bound.text = _numbers(bound.text, 1000.0)
        for bound in joint.iter("upper") if joint.get("type") == "prismatic" else ():
            bound.text = _numbers(bound.text, 1000.0)
    (model,) = root.iter("model")
    parts = [element for element in model if element.tag in ("link", "joint")]
    for element in parts:
        model.remove(element)
    model.extend(reversed(parts))
    assert model.find("pose") is None
    ElementTree.SubElement(model, "pose").text = "300.0 -200.0 500.0 0.4 -0.7 1.1"
    target = folder / source.name
    target.write_text(ElementTree.tostring(root, encoding="unicode"))
    return target


def read(path: Path, **options):
    """The mechanism as the command line opens it: serial legs, else the closed-loop graph."""
    try:
        return load(path, **options)
    except LegWithLoops:
        return graph_mechanism(read_closed_tree(path, **options))


def indices(mechanism):
    return mechanism.indices() if hasattr(mechanism, "tree") else indices_at_pose(mechanism, mechanism.home_pose)


def same(value, expected) -> bool:
    """Equal to :data:`TOLERANCE`, or both NaN (an index that does not apply: the CTI of a point output)."""
    return bool(np.isnan(value) and np.isnan(expected) or abs(value - expected) < TOLERANCE)


def words(refusal) -> list[str]:
    """A refusal's words after the file's name, in sorted order."""
    return sorted(re.split(r"[\s,().]+", str(refusal).split(": ", 1)[1]))


def by_actuator(result) -> dict[str, float]:
    return dict(zip(result.actuators, np.atleast_1d(result.iti_actuators).tolist()))


def assert_same_indices(other, published) -> None:
    """The same actuators, and by actuator name the same ITI, the same LMTI, F_Oj, F_IOj, CTI and F_Cj."""
    assert sorted(other.actuators) == sorted(published.actuators)
    first, second = by_actuator(published), by_actuator(other)
    assert all(same(second[name], value) for name, value in first.items()), (first, second)
    assert same(other.lmti, published.lmti)
    for faults in ("f_o", "f_io", "f_c"):
        mine, theirs = getattr(published, faults), getattr(other, faults)
        assert mine.keys() == theirs.keys() and all(same(theirs[j], mine[j]) for j in mine), faults
    assert (published.cti is None) == (other.cti is None)
    assert published.cti is None or same(other.cti, published.cti)


@pytest.mark.parametrize("source", OPENING_FILES, ids=lambda path: path.parent.name + "/" + path.stem)
def test_a_published_file_in_millimetres_in_a_moved_world_and_listed_backwards_has_the_same_indices(source,
                                                                                                     tmp_path):
    lock = OPENING.get(source.parent.name, ())
    published = indices(read(source, lock=lock))
    other = indices(read(rewritten(source, tmp_path), lock=lock, length_unit="mm"))
    assert_same_indices(other, published)


@pytest.mark.parametrize("name", REFUSED)
def test_a_published_file_refused_as_written_is_refused_for_the_same_reason_rewritten(name, tmp_path):
    source = GEPETTO / name / "robot.urdf"
    with pytest.raises(ImportError_) as published:
        read(source)
    with pytest.raises(ImportError_) as other:
        read(rewritten(source, tmp_path), length_unit="mm")
    assert str(other.value).split(": ", 1)[1] == str(published.value).split(": ", 1)[1]


@pytest.mark.parametrize("source", MJCF_FILES, ids=lambda path: path.parent.name)
def test_a_published_mjcf_file_listed_backwards_in_a_moved_world_reads_the_same(source, tmp_path):
    """MuJoCo files are read in their order (Pinocchio numbers the joints so): listed backwards, the same indices by
    actuator name, or the same refusal in the same words (a list of joints it names in the file's order)."""
    try:
        published = indices(read(source))
    except ImportError_ as refusal:
        with pytest.raises(ImportError_) as other:
            read(mjcf_rewritten(source, tmp_path))
        # (the joints it names listed in the file's order, which is the reader's: the same words, in any order)
        assert words(other.value) == words(refusal)
        return
    other = indices(read(mjcf_rewritten(source, tmp_path)))
    assert_same_indices(other, published)


@pytest.mark.parametrize("source", SDF_FILES, ids=lambda path: path.parent.name)
def test_a_published_sdformat_file_in_millimetres_listed_backwards_in_a_moved_world_reads_the_same(source, tmp_path):
    """SDFormat closes its loops with joints of the model, and the reader cuts each loop at a joint the file's order
    picks: listed backwards, the same indices by actuator name, or the same refusal up to the bodies it names as
    joined by the cut joints (Cassie's: which body is the platform?)."""
    try:
        published = indices(read(source))
    except ImportError_ as refusal:
        with pytest.raises(ImportError_) as other:
            read(sdf_rewritten(source, tmp_path), length_unit="mm")
        cut = " (the closures join"
        assert words(str(other.value).split(cut)[0]) == words(str(refusal).split(cut)[0])
        return
    other = indices(read(sdf_rewritten(source, tmp_path), length_unit="mm"))
    assert_same_indices(other, published)
