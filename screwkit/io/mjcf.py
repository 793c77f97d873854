"""MuJoCo MJCF files: prepared as MuJoCo reads them, the tree read by Pinocchio's own parser.

:func:`screwkit.io.mjcf_text.prepared_mjcf` resolves ``<include>``s, wraps several world bodies in one,
names unnamed closures, converts degrees (MuJoCo's default unit) to radians, writes every orientation as a
quaternion and lifts the children of ``<frame>`` elements, saying what it did, and refuses an active joint,
tendon or flex coupling (``<equality><joint>``...: screwkit does not model couplings);
``buildModelAndConstraintsFromMJCF`` then builds the tree. Every ``<equality><connect>`` is a ``3d`` closure
(a ball joint) and every ``<weld>`` a ``6d`` one, their frames placed as MuJoCo places them
(:func:`~screwkit.io.mjcf_text.closure_placements`: a weld's ``relpose``, a connect's ``anchor``, or sites).
The joints driven by ``<actuator>`` elements (``motor``, ``position``, ``velocity``, ``general``..., by their
``joint`` or ``jointinparent`` attribute) are the actuated joints. A free body's joint is placed at the world's
origin, its coordinates being its pose in the world (MuJoCo's reading; Pinocchio 4.1 offsets a turned free body).
Reference joint values are ``qpos0`` (the joints' ``ref``), or the keyframe named ``home`` when there is one.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from screwkit.io.closed_tree import ClosedTree, Closure, ImportError_
from screwkit.io.mjcf_pose import rotation_matrix, site_pose
from screwkit.io.mjcf_text import MjcfError, closure_placements, joint_ranges, prepared_mjcf

__all__ = ["read_mjcf", "sites_placed"]


def read_mjcf(path: Path, *, output: str | None = None, output_type: str | None = None) -> ClosedTree:
    """The closed tree of an MJCF file (prepared as :mod:`screwkit.io.mjcf_text` says, read by Pinocchio)."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    source = str(path)
    try:
        text, notes, root, couplings = prepared_mjcf(Path(path))
    except MjcfError as error:
        raise ImportError_(str(error)) from None
    motors, unactuated = [], ""
    for actuators in root.findall("actuator"):
        for element in actuators:
            joint = _driven_joint(element)
            if joint is None:
                unactuated = unactuated or (f"{source}: <actuator><{element.tag} name={element.get('name')!r}> drives "
                                            "no joint (tendon and site transmissions are not supported)")
                continue
            if joint in motors:
                notes.append(f"joint {joint!r} is driven by more than one <actuator> (a servo's position and velocity "
                             "terms, say): one actuated joint")
            else:
                motors.append(joint)
    if not motors:
        unactuated = unactuated or f"{source}: no <actuator> drives a joint: nothing is actuated"
    with tempfile.TemporaryDirectory(prefix="screwkit-mjcf-") as folder:
        prepared = Path(folder) / Path(path).name
        prepared.write_text(text, encoding="utf-8")
        try:
            model, _, _ = pin.buildModelAndConstraintsFromMJCF(str(prepared))
        except Exception as error:  # noqa: BLE001 - Pinocchio's parser raises anything (IndexError, ...): one line
            if "Keyframe size" in str(error):  # MuJoCo pads a short qpos with qpos0, Pinocchio refuses it
                keys = ", ".join(f"'{key.get('name', '?')}' {len((key.get('qpos') or '').split())}"
                                 for keyframe in root.findall("keyframe") for key in keyframe.findall("key"))
                raise ImportError_(f"{source}: <keyframe><key> qpos: one number per joint coordinate expected "
                                   f"(MuJoCo fills a short one from qpos0, Pinocchio does not); numbers given: {keys}."
                                   ) from None
            raise ImportError_(f"{source}: Pinocchio cannot read it ({type(error).__name__}: {error}).") from None
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    for name, limits in joint_ranges(root).items():  # MuJoCo's: Pinocchio shifts them by a ref
        joint = model.joints[model.getJointId(name)] if model.existJointName(name) else None
        if joint is not None and joint.nq == 1:
            lower[joint.idx_q], upper[joint.idx_q] = limits or (-np.inf, np.inf)
    model.lowerPositionLimit, model.upperPositionLimit = lower, upper
    for joint in range(1, model.njoints):  # a free body's coordinates are its pose in the world (MuJoCo's)
        if model.joints[joint].shortname() == "JointModelFreeFlyer" and model.parents[joint] == 0:
            model.jointPlacements[joint] = pin.SE3.Identity()  # Pinocchio 4.1 offsets a turned one by (I - R) p
    try:
        sites_placed(model, root)
    except MjcfError as error:
        raise ImportError_(f"{source}: {error}") from None
    references = {item.key(): np.array(item.data()) for item in model.referenceConfigurations}
    qpos0 = np.asarray(references.get("qpos0", pin.neutral(model)), dtype=float)
    data = model.createData()
    pin.forwardKinematics(model, data, qpos0)

    def frame_of(name: str | None, kind: str):
        wanted = "universe" if name in (None, "world") else name
        types = (pin.FrameType.BODY, pin.FrameType.FIXED_JOINT) if kind == "body" else (pin.FrameType.OP_FRAME,)
        for frame in model.frames:
            if frame.name == wanted and (frame.type in types or wanted == "universe"):
                return frame
        raise ImportError_(f"{source}: no {kind} named {name!r} for a closure.")

    closures = []
    for equalities in root.findall("equality"):
        for element in equalities:
            if element.tag not in ("connect", "weld"):
                continue
            if element.get("active", "true") == "false":
                notes.append(f"closure {element.get('name')!r} is inactive in the file: left out")
                continue
            for first, second in (("body1", "body2"), ("site1", "site2")):
                if element.get(first) is not None and element.get(first) == element.get(second):
                    raise ImportError_(f"{source}: <{element.tag} name='{element.get('name')}'>: {first} and {second} "
                                       f"are both {element.get(first)!r}: a closure of a frame to itself (MuJoCo "
                                       "refuses it).")
            try:
                joint_a, place_a, joint_b, place_b = closure_placements(element, model, data, frame_of)
            except MjcfError as error:
                raise ImportError_(f"{source}: {error}") from None
            closures.append(Closure(element.get("name"), int(joint_a), place_a, int(joint_b), place_b,
                                    "3d" if element.tag == "connect" else "6d"))
    q = references.get("home", qpos0)
    return ClosedTree(source, model, closures, motors, np.asarray(q, dtype=float), output, output_type, "MJCF",
                      notes, unactuated=unactuated, couplings=tuple(couplings))


def _driven_joint(element) -> str | None:
    """The joint an ``<actuator>`` element drives, or None when its transmission is no joint's. Of the targets
    written, MuJoCo takes the one latest in the order ``joint``, ``jointinparent``, ``tendon``, ``cranksite``,
    ``site``, ``body`` (whatever the attributes' order in the element); ``jointinparent`` differs from ``joint``
    only in the frame of a ball's or free joint's gear."""
    if any(element.get(other) is not None for other in ("tendon", "cranksite", "site", "body")):
        return None
    return element.get("jointinparent", element.get("joint"))


def sites_placed(model, root) -> None:
    """Each named site's frame placed on its body's frame by the site's own ``pos`` and ``quat`` (or ``fromto``), as
    MuJoCo places it. Pinocchio 4.1's parser leaves out the offset of a body's joint (its ``pos``) for the sites of
    a body without a joint of its own under it, so such a site would sit off by that offset (a platform's output
    site, or a closure's, under a hinge drawn away from its body's origin), reads no ``fromto``, and makes no frame
    of a site of ``<worldbody>`` itself (a closure's anchor on the ground), which is added on the world's frame, nor
    of a site of a body without a joint at the world's origin (a fixed base's ground pivot), added on that body's."""
    import pinocchio as pin

    def placed(site):  # the site's pose on its body
        position, quaternion = site_pose(site)
        return pin.SE3(rotation_matrix(quaternion), position)

    def added(site, owner: int) -> None:  # a frame for the site on frame ``owner`` (0: the world's)
        model.addFrame(pin.Frame(site.get("name"), model.frames[owner].parentJoint, owner,
                                 model.frames[owner].placement * placed(site), pin.FrameType.OP_FRAME))

    for world in root.findall("worldbody"):
        for site in world.findall("site"):
            if site.get("name") is not None and not model.existFrame(site.get("name"), pin.FrameType.OP_FRAME):
                added(site, 0)

    for body in root.iter("body"):
        for site in body.findall("site"):
            name = site.get("name")
            if name is None:
                continue
            if not model.existFrame(name, pin.FrameType.OP_FRAME):
                # a site of a body with no joint that the parser makes a frame without its sites (the ground
                # pivot on a fixed base body at the world's origin): added on the body's frame
                if body.get("name") is not None and model.existFrame(body.get("name"), pin.FrameType.BODY):
                    added(site, model.getFrameId(body.get("name"), pin.FrameType.BODY))
                continue
            index = model.getFrameId(name, pin.FrameType.OP_FRAME)
            frame = model.frames[index]
            parent = model.frames[frame.parentFrame]
            if parent.type != pin.FrameType.BODY or body.get("name") not in (None, parent.name):
                continue  # not the frame of the site's body (Pinocchio names an unnamed body itself)
            frame.placement = parent.placement * placed(site)
            model.frames[index] = frame
