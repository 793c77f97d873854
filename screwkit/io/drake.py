"""URDFs whose loops are closed by Drake's ball constraints: ``<drake:ball_constraint>`` elements.

Drake (``drake::multibody``) closes a URDF's loops with elements of its own namespace, which every other URDF parser
(Pinocchio's included) skips::

    <drake:ball_constraint>
      <drake:ball_constraint_body_A name="rocker"/>
      <drake:ball_constraint_body_B name="coupler"/>
      <drake:ball_constraint_p_AP value="0.3 0 0"/>    <!-- P, in body A's frame -->
      <drake:ball_constraint_p_BQ value="0 0 0"/>      <!-- Q, in body B's frame: P and Q coincide -->
    </drake:ball_constraint>

(``MultibodyPlant::AddBallConstraint``). Each is a ``3d`` closure: the point both bodies keep, closed near the file's
joint values as every closure is (:func:`screwkit.io.closed_tree.assemble`). Drake's URDFs may leave the ``world``
link implicit (a joint whose parent is ``world`` with no such link): it is added. Drake's other elements that join
bodies (``drake:linear_bushing_rpy``, ``drake:tendon_constraint``, a ``drake:joint`` of its own, ...) are refused by
name rather than left out, which would analyse another mechanism. The actuated joints are those of the URDF's
``<transmission>`` elements, else guessed as for onshape-to-robot files (said in the import report).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

from screwkit.common.xml_text import UNDECLARED, tolerant_xml
from screwkit.io.closed_tree import ClosedTree, Closure, ImportError_, homogeneous
from screwkit.io.onshape import transmitted_tree

__all__ = ["has_drake_constraints", "read_drake", "drake_elements"]

NAMESPACES = ("http://drake.mit.edu", UNDECLARED + "drake")
"""Drake's namespace as its files declare it, and as an undeclared ``drake:`` prefix is read."""
CLOSURES = ("ball_constraint", "joint", "linear_bushing_rpy", "tendon_constraint", "weld_constraint")
"""Drake's elements that join bodies (or joints) of a model, as its parsers list them (``weld_constraint`` as its
development files write it): only ball constraints are read. (``linear_spring_damper`` and
``collision_filter_group`` join nothing: they are left to Drake.)"""


def drake_elements(root) -> list[tuple[str, object]]:
    """(name, element) of the children of a URDF's root in Drake's namespace that tie bodies together."""
    found = []
    for element in root:
        match = re.fullmatch(r"\{(.*)\}(.*)", element.tag) if isinstance(element.tag, str) else None
        if match and match.group(1) in NAMESPACES and match.group(2) in CLOSURES:
            found.append((match.group(2), element))
    return found


def has_drake_constraints(path: Path) -> bool:
    """Whether a URDF file has one of Drake's closures (read as text, quickly)."""
    with open(path, "rb") as handle:  # the head alone (a file over the size cap is refused unread)
        head = handle.read(4_000_000)
    if b"drake:" not in head:
        return False
    try:
        return bool(drake_elements(ElementTree.fromstring(tolerant_xml(head))))
    except ElementTree.ParseError:
        return False


def _child(element, name: str, attribute: str, where: str) -> str:
    for child in element:
        if isinstance(child.tag, str) and child.tag.endswith("}" + name) and child.get(attribute) is not None:
            return child.get(attribute).strip()
    raise ImportError_(f"{where}: no <drake:{name} {attribute}=...>.")


def _point(text: str, where: str, tag: str) -> np.ndarray:
    try:
        values = np.array([float(word) for word in text.split()], dtype=float)
    except ValueError:
        values = np.zeros(0)
    if values.shape != (3,) or not np.all(np.isfinite(values)):
        raise ImportError_(f"{where}: <drake:{tag} value={text!r}>: expected three finite numbers (m).")
    return values


def read_drake(urdf: Path, *, output: str | None = None, output_type: str | None = None) -> ClosedTree:
    """The closed tree of a URDF whose loops are Drake's ``<drake:ball_constraint>`` elements."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    data = urdf.read_bytes()
    root = ElementTree.fromstring(tolerant_xml(data))
    elements = drake_elements(root)
    other = sorted({name for name, _ in elements if name != "ball_constraint"})
    if other:
        raise ImportError_(f"{urdf}: <drake:{other[0]}>, Drake's own, joins bodies in a way screwkit does not read (it "
                           "reads <drake:ball_constraint>); the file without it would be another mechanism.")
    text = data.decode("utf-8", errors="replace")
    links = [link.get("name") for link in root.iter("link")]
    if "world" not in links and any(parent.get("link") == "world" for parent in root.iter("parent")):
        text = re.sub(r"(<robot\b[^>]*>)", r'\1<link name="world"/>', text, count=1)  # Drake's implicit world
        links.insert(0, "world")
    children = {child.get("link") for child in root.iter("child")}
    roots = [link for link in links if link not in children]
    if len(roots) > 1:  # (urdfdom would print its own lines and refuse the file)
        raise ImportError_(f"{urdf}: links {', '.join(map(repr, roots))} are no joint's child: Drake makes each but "
                           "the first a free body, screwkit reads a tree with one root; join each to the base (a fixed "
                           "joint) or to the mechanism.")
    try:
        model = pin.buildModelFromXML(text)
    except (RuntimeError, ValueError) as error:
        raise ImportError_(f"{urdf}: Pinocchio cannot read the tree ({error}).") from None
    bodies = {frame.name: index for index, frame in enumerate(model.frames) if frame.type == pin.FrameType.BODY}
    closures = []
    for number, (_, element) in enumerate(elements, start=1):
        name = f"ball_constraint_{number}"
        where = f"{urdf}: <drake:ball_constraint> {number}"
        sides = []
        for body_tag, point_tag in (("ball_constraint_body_A", "ball_constraint_p_AP"),
                                    ("ball_constraint_body_B", "ball_constraint_p_BQ")):
            body = _child(element, body_tag, "name", where)
            if body not in bodies:
                raise ImportError_(f"{where}: <drake:{body_tag} name={body!r}>: no link of that name.")
            frame = model.frames[bodies[body]]
            placement = np.eye(4)
            placement[:3, 3] = _point(_child(element, point_tag, "value", where), where, point_tag)
            sides.append((int(frame.parentJoint), homogeneous(frame.placement) @ placement))
        (joint_a, on_a), (joint_b, on_b) = sides
        closures.append(Closure(name, joint_a, on_a, joint_b, on_b, "3d"))
    return transmitted_tree(urdf, data, model, closures, pin.neutral(model), output, output_type,
                            "URDF + Drake ball constraints (<drake:ball_constraint>)")
