"""MuJoCo MJCF files, read by Pinocchio's own parser (``buildModelAndConstraintsFromMJCF``).

``<equality><connect>`` gives a ``3d`` closure (a ball joint at the anchor), ``<weld>`` a ``6d``
one; the joints driven by ``<actuator>`` elements (``motor``, ``position``, ``velocity``,
``general``..., by their ``joint`` attribute) are the actuated joints, read from the XML (Pinocchio
does not keep them). What Pinocchio requires is checked first, with the element named: one body
directly under ``<worldbody>`` (Pinocchio drops its siblings), every equality named (unnamed ones
collapse into one), ``<compiler angle="radian">`` when slide joints have ranges (Pinocchio scales
their ranges as angles otherwise). Reference joint values are ``qpos0`` (``ref``/``qpos0`` of the
file), or the keyframe named ``home`` when there is one.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

from screwkit.io.closed_tree import ClosedTree, Closure, ImportError_, homogeneous

__all__ = ["read_mjcf"]


def read_mjcf(path: Path, *, output: str | None = None, output_type: str | None = None) -> ClosedTree:
    """The closed tree of an MJCF file."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    source = str(path)
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as error:
        raise ImportError_(f"{source}: not well-formed XML ({error}).") from None
    if root.tag != "mujoco":
        hint = " (a URDF: give it the suffix .urdf)" if root.tag == "robot" else ""
        raise ImportError_(f"{source}: the root element is <{root.tag}>, not <mujoco>{hint}.")
    world = root.find("worldbody")
    bodies = [] if world is None else world.findall("body")
    if len(bodies) != 1:
        raise ImportError_(f"{source}: <worldbody> holds {len(bodies)} bodies; Pinocchio reads only the first: wrap "
                           "the mechanism in one body at the origin.")
    equalities = [e for e in (root.find("equality") if root.find("equality") is not None else []) if e.tag in (
        "connect", "weld")]
    if any(not e.get("name") for e in equalities):
        raise ImportError_(f"{source}: every <connect>/<weld> must have a name (Pinocchio merges unnamed ones).")
    compiler = root.find("compiler")
    radian = compiler is not None and compiler.get("angle") == "radian"
    if not radian and any(j.get("type") == "slide" and j.get("range") for j in root.iter("joint")):
        raise ImportError_(f"{source}: slide joints with a range need <compiler angle=\"radian\"/> (Pinocchio "
                           "converts their ranges as angles otherwise).")
    motors = []
    actuators = root.find("actuator")
    for element in (actuators if actuators is not None else []):
        joint = element.get("joint")
        if joint is None:
            raise ImportError_(f"{source}: <actuator><{element.tag} name={element.get('name')!r}> drives no joint "
                               "(tendon and site transmissions are not supported).")
        if joint not in motors:
            motors.append(joint)
    if not motors:
        raise ImportError_(f"{source}: no <actuator> drives a joint: nothing is actuated.")
    try:
        model, points, frames = pin.buildModelAndConstraintsFromMJCF(str(path))
    except (RuntimeError, ValueError) as error:
        raise ImportError_(f"{source}: Pinocchio cannot read it ({error}).") from None
    constraints = sorted(equalities, key=lambda e: e.get("name"))  # Pinocchio returns them sorted by name
    connects = [e.get("name") for e in constraints if e.tag == "connect"]
    welds = [e.get("name") for e in constraints if e.tag == "weld"]
    closures = [Closure(name, int(c.joint1_id), homogeneous(c.joint1_placement), int(c.joint2_id),
                        homogeneous(c.joint2_placement), "3d") for name, c in zip(connects, points)]
    closures += [Closure(name, int(c.joint1_id), homogeneous(c.joint1_placement), int(c.joint2_id),
                         homogeneous(c.joint2_placement), "6d") for name, c in zip(welds, frames)]
    references = {item.key(): np.array(item.data()) for item in model.referenceConfigurations}
    q = references.get("home", references.get("qpos0", pin.neutral(model)))
    return ClosedTree(source, model, closures, motors, np.asarray(q, dtype=float), output, output_type, "MJCF")
