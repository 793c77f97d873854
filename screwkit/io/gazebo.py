"""URDFs whose loops are closed by Gazebo joints: ``<gazebo><joint>`` elements (SDFormat joints) closing the tree.

URDF cannot write a loop; Gazebo users write the joints that close one as SDFormat joints inside a
``<gazebo>`` element of the URDF, which Gazebo adds to the model and every URDF parser (Pinocchio's
included) skips::

    <gazebo>
      <joint name="loop_2" type="revolute">
        <parent>distal_2</parent>
        <child>distal_1</child>
        <pose>0.3 0 0 0 0 0</pose>              <!-- in the child link's frame (SDFormat) -->
        <axis><xyz>0 0 1</xyz></axis>           <!-- in the joint's frame (the model's with
                                                     <use_parent_model_frame>1</use_parent_model_frame>) -->
      </joint>
    </gazebo>

Each such joint is a closure at the file's configuration (the tree's joints at 0, as Gazebo spawns
it): a ``ball`` one point that both links keep (``3d``), a ``fixed`` one the whole frame (``6d``), a
``revolute`` (or ``continuous``) one two points on its axis, which :mod:`screwkit.io.star` makes the
hinge through them (a pin about the normal in a planar mechanism). Other types are refused by name.
The actuated joints are those of the URDF's ``<transmission>`` elements, else guessed as for
onshape-to-robot files (:func:`screwkit.io.onshape.guessed_motors`, said in the import report).
The joint elements are read as :mod:`screwkit.io.sdformat_text` reads an SDFormat file's (from which
:mod:`screwkit.io.sdformat` builds whole models, loops written as native joints).
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

from screwkit.common.xml_text import tolerant_xml
from screwkit.io.closed_tree import (
    ClosedTree,
    Closure,
    ImportError_,
    homogeneous,
    inverse,
)
from screwkit.io.onshape import transmitted_tree
from screwkit.io.sdformat_text import (
    MODEL_FRAME,
    controlled_joints,
    detachable_joints,
    in_parent_model_frame,
    parse_joint,
    plugin_note,
)
from screwkit.io.urdf_tree import urdf_model

__all__ = ["has_gazebo_joints", "read_gazebo"]

HINGE_TYPES = ("revolute", "continuous")
TYPES = (*HINGE_TYPES, "ball", "fixed")


def has_gazebo_joints(path: Path) -> bool:
    """Whether a URDF file has a ``<joint>`` or a DetachableJoint ``<plugin>`` inside a ``<gazebo>`` element (read as
    text, quickly)."""
    with open(path, "rb") as handle:  # the head alone (a file over the size cap is refused unread)
        head = handle.read(4_000_000)
    return b"<gazebo" in head and _gazebo_joints(head) != []


def _gazebo_joints(text: bytes) -> list[tuple[object, str]]:
    """:func:`_joints_of` the URDF's text (none if it is not well-formed)."""
    try:
        return _joints_of(ElementTree.fromstring(tolerant_xml(text)))
    except ElementTree.ParseError:
        return []


def _joints_of(root) -> list[tuple[object, str]]:
    """The ``<gazebo><joint>`` elements of a URDF (its ``root`` element), and for each DetachableJoint plugin joining
    two of its own links the fixed joint it makes (:func:`~screwkit.io.sdformat_text.detachable_joints`); each with
    how it is written, for messages."""
    joints = [(joint, f"<gazebo><joint name='{joint.get('name')}'>") for gazebo in root.findall("gazebo")
              for joint in gazebo.findall("joint")]
    links = {link.get("name") for link in root.findall("link")}
    taken = [joint.get("name") for joint in root.iter("joint")]
    return joints + detachable_joints(root.findall("gazebo"), links, root.get("name", ""), taken)


def read_gazebo(urdf: Path, *, output: str | None = None, output_type: str | None = None) -> ClosedTree:
    """The closed tree of a URDF whose loops are ``<gazebo><joint>`` elements."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    model = urdf_model(urdf)
    data = model.createData()
    q = pin.neutral(model)
    pin.framesForwardKinematics(model, data, q)
    bodies = {frame.name: index for index, frame in enumerate(model.frames) if frame.type == pin.FrameType.BODY}
    scale = max(float(np.max(np.abs([np.asarray(frame.translation) for frame in data.oMf]))), 1e-3)
    closures, notes = [], []
    written = urdf.read_bytes()
    root = ElementTree.fromstring(tolerant_xml(written))  # (well-formed: Pinocchio has read it)
    found = _joints_of(root)
    for element, written_as in found:
        name = element.get("name") or f"gazebo_joint_{len(closures) + 1}"
        where = f"{urdf}: {written_as}"
        kind = element.get("type", "")
        if kind not in TYPES:
            raise ImportError_(f"{where}: type {kind!r} cannot close a loop here (expected one of {', '.join(TYPES)}).")
        joint = parse_joint(element, where, (1, 6))  # (<use_parent_model_frame>, where written, read as 1.5-1.6 do)
        links = []
        for tag, link in (("parent", joint.parent), ("child", joint.child)):
            if link not in bodies:
                raise ImportError_(f"{where}: <{tag}> names {link!r}, not a link of the tree.")
            links.append(bodies[link])
        if joint.relative_to not in ("", joint.child) or joint.axes[0].expressed_in not in ("", name, MODEL_FRAME):
            raise ImportError_(f"{where}: a pose relative_to or an axis expressed_in another frame is not read: write "
                               "the pose in the child link's frame and the axis in the joint's (SDFormat's defaults).")
        in_child = joint.pose
        parent, child = (model.frames[index] for index in links)
        world_child = homogeneous(data.oMf[links[1]])
        parent_from_world = inverse(homogeneous(data.oMf[links[0]]))
        points = [in_child]
        if kind in HINGE_TYPES:  # a hinge: two points on its axis, made the hinge through them by the conversion
            axis = joint.axes[0].xyz
            if joint.axes[0].expressed_in == MODEL_FRAME:  # the model's frame: the root link's, the world's here
                axis = (world_child @ in_child)[:3, :3].T @ axis
                if in_parent_model_frame(element.find("axis")) and 1.0 - abs(float(axis @ joint.axes[0].xyz)) > 1e-12:
                    # (by the element, not expressed_in: another line in the 1.7 reading)
                    notes.append(f"{written_as}: its axis read in the model's frame, as <use_parent_model_frame> asks "
                                 "(SDFormat 1.5 and 1.6; Gazebo's URDF conversion to SDFormat 1.7, libsdformat 9 "
                                 "and later, drops that element and reads the axis in the joint's frame: another "
                                 "axis here)")
            second = in_child.copy()
            second[:3, 3] = in_child[:3, 3] + scale * in_child[:3, :3] @ axis
            points.append(second)
        for number, placement in enumerate(points):  # each side in its joint's frame, coinciding at q
            on_parent = homogeneous(parent.placement) @ parent_from_world @ world_child @ placement
            on_child = homogeneous(child.placement) @ placement
            closures.append(Closure(name if len(points) == 1 else f"{name}_{'ab'[number]}", int(parent.parentJoint),
                                    on_parent, int(child.parentJoint), on_child, "6d" if kind == "fixed" else "3d",
                                    axis_point=number == 1))
    plugins = [(joint, written_as) for joint, written_as in found if written_as.startswith("<plugin")]
    written_with = ["<gazebo><joint>"] * (len(plugins) < len(found)) + ["DetachableJoint plugins"] * bool(plugins)
    tree = transmitted_tree(urdf, written, model, closures, q, output, output_type,
                            f"URDF + Gazebo joints ({', '.join(written_with)})",
                            controlled_joints(root.findall("gazebo")))
    if plugins:
        tree.notes.append(plugin_note(plugins, "closures"))
    tree.notes.extend(notes)
    return tree

