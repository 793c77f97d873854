"""URDFs exported by onshape-to-robot: loops closed by ``closing_<name>_1`` / ``closing_<name>_2`` frame pairs.

onshape-to-robot writes each mate named ``closing_<name>`` of the CAD assembly as two dummy links
(``closing_<name>_1`` and ``closing_<name>_2``, each on a fixed joint) attached to the two parts it
mated, at the point the mate joins them. A URDF has no element for what the mate was (its MuJoCo export
writes a ball mate as one ``<connect>``, a revolute as two, a fastened one as a ``<weld>``), nor for
which joints are driven. So, without a ``robot.yaml`` beside the file (:mod:`screwkit.io.gepetto`, which
says both), this module reads:

* every ``closing_`` pair as a ball joint (``3d``: the two origins coincide), the least it can be; the
  conversion then makes two balls between the same two bodies the hinge through them, and a planar
  mechanism's balls pins about the plane's normal (:mod:`screwkit.io.star`);
* the actuated joints as the branches from the base suggest them: on each branch of the tree that
  leaves the base and reaches a closure, its prismatic joint on the way to the closures when it has
  exactly one (a Stewart platform's leg), else its first joint (a motor on the base).

Both guesses are said in the import report, with how to say otherwise (a ``robot.yaml`` with
``closed_loop``, ``type`` and ``name_mot``).
"""

from __future__ import annotations

import re
from pathlib import Path

from screwkit.common.xml_text import tolerant_xml
from screwkit.io.closed_tree import (
    ClosedTree,
    Closure,
    ImportError_,
    declared_task_coordinates,
    homogeneous,
    joint_kind,
    path_to,
)
from screwkit.io.urdf_tree import urdf_model
from screwkit.model.urdf_element_reader import passive_joint

__all__ = ["CLOSING", "closing_pairs", "read_onshape", "transmitted_tree", "transmitted_joints"]

CLOSING = re.compile(r"closing_(.+)_([12])")
"""The name of a closing frame: ``closing_<name>_1`` or ``closing_<name>_2``."""


def closing_pairs(names) -> dict[str, tuple[str, str]]:
    """``name -> (closing_<name>_1, closing_<name>_2)`` for every complete pair among ``names``."""
    sides: dict[str, dict[str, str]] = {}
    for name in names:
        match = CLOSING.fullmatch(name)
        if match:
            sides.setdefault(match.group(1), {})[match.group(2)] = name
    return {key: (pair["1"], pair["2"]) for key, pair in sorted(sides.items()) if set(pair) == {"1", "2"}}


def has_closing_frames(path: Path) -> bool:
    """Whether a URDF file names at least one complete ``closing_`` pair of links (read as text, quickly)."""
    with open(path, "rb") as handle:  # the head alone (a file over the size cap is refused unread)
        head = handle.read(4_000_000).decode("utf-8", errors="replace")
    return bool(closing_pairs(re.findall(r"<link\s+name\s*=\s*[\"']([^\"']+)[\"']", head)))


def transmitted_joints(urdf_text: bytes, passive: bool = False) -> list[str]:
    """The joints a URDF's ``<transmission>`` elements drive (``<joint name="...">`` or the joint's name as text),
    in file order, once each: the file's own word for which joints are actuated. A joint whose every
    ``<hardwareInterface>`` is a passive one (``PassiveJointInterface``: a closed-loop simulator's joints that the
    loop moves) is driven by none; with ``passive``, those joints instead."""
    import xml.etree.ElementTree as ElementTree

    try:
        root = ElementTree.fromstring(tolerant_xml(urdf_text))
    except ElementTree.ParseError:
        return []
    joints = [(joint.get("name") or (joint.text or "").strip(), passive_joint(joint))
              for transmission in root.findall("transmission") for joint in transmission.findall("joint")]
    return list(dict.fromkeys(name for name, idle in joints if name and idle == passive))


def read_onshape(urdf: Path, *, output: str | None = None, output_type: str | None = None) -> ClosedTree:
    """The closed tree of an onshape-to-robot URDF whose loops are ``closing_`` frame pairs."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = urdf_model(urdf)
    frames = {frame.name: frame for frame in model.frames if frame.type == pin.FrameType.BODY}
    pairs = closing_pairs(frames)
    unpaired = sorted(name for name in frames if CLOSING.fullmatch(name)
                      and not any(name in pair for pair in pairs.values()))
    if unpaired:
        raise ImportError_(f"{urdf}: closing frame(s) {', '.join(unpaired)} without their other half "
                           "(onshape-to-robot writes closing_<name>_1 and closing_<name>_2).")
    if not pairs:
        raise ImportError_(f"{urdf}: no closing_<name>_1 / closing_<name>_2 frame pair: no loop to close.")
    closures = []
    for key, (first, second) in pairs.items():
        a, b = frames[first], frames[second]
        closures.append(Closure(f"closing_{key}", int(a.parentJoint), homogeneous(a.placement),
                                int(b.parentJoint), homogeneous(b.placement), "3d"))
    written = urdf.read_bytes()
    transmitted = transmitted_joints(written)
    unknown = [name for name in transmitted if not model.existJointName(name)
               or model.joints[model.getJointId(name)].nv != 1]
    unactuated = (f"{urdf}: <transmission> names joint(s) {', '.join(unknown)}, not 1-DoF joints of the tree"
                  if unknown else "")  # refused unless --actuate names the actuators (read_closed_tree)
    motors = [] if unknown else transmitted or guessed_motors(model, closures)  # none: refused, idem
    tree = ClosedTree(str(urdf), model, closures, motors, pin.neutral(model), output, output_type,
                      "onshape-to-robot URDF (closing_ frame pairs)",
                      task_coordinates=declared_task_coordinates(urdf.read_bytes()), unactuated=unactuated)
    tree.notes.append(f"closing_ pairs read as ball joints (a URDF does not say the mate's type): "
                      f"{', '.join(c.name for c in closures)}; a robot.yaml beside the file (type: 3d or 6d) says "
                      "otherwise")
    if not transmitted:
        tree.notes.append(f"actuators guessed from the branches leaving the base (no <transmission>): "
                          f"{', '.join(motors)}; --actuate JOINT or a robot.yaml beside the file (name_mot) says "
                          "otherwise")
    passive_note(tree, written, transmitted)
    return tree


def guessed_motors(model, closures: list[Closure], hinges=()) -> list[str]:
    """On each branch leaving the base towards a closure: its one prismatic joint on the way, else its first joint
    that is not one of ``hinges`` (those a reader wrote for a ball or universal joint, which no motor drives)."""
    branches: dict[int, list[int]] = {}
    for closure in closures:
        for joint in (closure.joint_a, closure.joint_b):
            path = path_to(model, joint)
            if path:
                members = branches.setdefault(path[0], [])
                members += [j for j in path if j not in members]
    motors = []
    for _, members in sorted(branches.items()):
        kinds = {joint: joint_kind(model, joint)[0] for joint in members}
        prismatic = [joint for joint in members if kinds[joint] == "prismatic"]
        chosen = prismatic[0] if len(prismatic) == 1 else next(
            (joint for joint in members if str(model.names[joint]) not in hinges), None)
        if chosen is not None and kinds[chosen] in ("revolute", "prismatic"):
            motors.append(str(model.names[chosen]))
    return motors


def transmitted_tree(urdf: Path, data: bytes, model, closures: list[Closure], q, output: str | None,
                     output_type: str | None, file_format: str, driven: list[str] = ()) -> ClosedTree:
    """The closed tree of a URDF whose closures another tool's elements write (Gazebo's, Drake's): its actuators
    those of its ``<transmission>`` elements, else those its joint controllers drive (``driven``: Gazebo's
    plugins), else guessed from the branches leaving the base (said in its notes); a transmission naming no joint of
    the tree is refused unless --actuate names them (read_closed_tree). ``data``: the file's bytes, as read."""
    declared = transmitted_joints(data)
    transmitted = declared or list(driven)
    motors = transmitted or guessed_motors(model, closures)
    unknown = [motor for motor in motors if motor not in list(model.names)]
    naming = "<transmission> names" if declared else "its joint controller plugins name"
    unactuated = f"{urdf}: {naming} joint(s) {', '.join(unknown)}, not in the tree" if unknown else ""
    tree = ClosedTree(str(urdf), model, closures, [] if unknown else motors, q, output, output_type, file_format,
                      task_coordinates=declared_task_coordinates(data), unactuated=unactuated)
    passive = passive_note(tree, data, declared)
    if not transmitted:
        tree.notes.append(f"actuators guessed from the branches leaving the base (no <transmission>"
                          f"{' drives a joint' if passive else ''}): {', '.join(motors)}; --actuate JOINT says "
                          "otherwise")
    elif not declared:
        tree.notes.append(f"actuators: the joints the file's joint controller plugins drive, {', '.join(motors)} (no "
                          f"<transmission>{' drives a joint' if passive else ''})")
    return tree


def passive_note(tree: ClosedTree, data: bytes, driven: list[str]) -> list[str]:
    """The joints of the URDF ``data``'s transmissions whose hardware interfaces are all passive ones, but those
    another transmission drives (``driven``); the import report's line on them, if any."""
    passive = [joint for joint in transmitted_joints(data, passive=True) if joint not in driven]
    if passive:
        tree.notes.append(f"joints {', '.join(passive)}: their <transmission>s' hardware interfaces are passive "
                          "(PassiveJointInterface): moved by the loops, not actuators")
    return passive
