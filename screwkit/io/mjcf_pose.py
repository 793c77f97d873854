"""Orientations and ``<frame>`` elements of an MJCF file, resolved as MuJoCo resolves them.

Used by :func:`screwkit.io.mjcf_text.prepared_mjcf`, before Pinocchio reads the file:

* :func:`orientations_as_quaternions` writes every ``euler``, ``axisangle``, ``xyaxes`` and ``zaxis`` as the
  ``quat`` MuJoCo computes from it: in degrees or radians (``<compiler angle>``), Euler angles in the order
  of ``<compiler eulerseq>`` (a lowercase letter turns about the moving axis, an uppercase one about the
  fixed axis, mixed as MuJoCo mixes them), axes normalised. What MuJoCo refuses is refused, naming the
  element: two orientations on one element, a zero quaternion, an axis of (nearly) zero length;
* :func:`frames_flattened` lifts the children of every ``<frame>`` (MuJoCo 3) to the frame's parent, the
  frame's pose composed into theirs (nested frames too) and the frame's ``childclass`` kept on them.

Only the standard library and numpy.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

__all__ = ["MjcfError", "MIN_AXIS", "describe", "class_attributes", "euler_sequence", "quaternion_product",
           "rotation_matrix", "orientations_as_quaternions", "local_pose", "site_pose", "defaults_written",
           "frames_flattened", "joints_one_per_body", "unused_name"]

MIN_AXIS = 1e-7
"""Length of an axis (a hinge's, an ``axisangle``'s, a ``zaxis``, an ``xyaxes``'s) up to which MuJoCo refuses it."""
ALTERNATIVES = ("axisangle", "euler", "xyaxes", "zaxis")
"""The ways MJCF gives an orientation other than ``quat``."""
BUILT_IN = {("joint", "type"): "hinge", ("joint", "axis"): "0 0 1", ("joint", "pos"): "0 0 0",
            ("joint", "ref"): "0", ("joint", "springref"): "0", ("joint", "range"): "0 0",
            ("joint", "limited"): "auto", ("site", "pos"): "0 0 0", ("site", "quat"): "1 0 0 0",
            ("site", "type"): "sphere", ("equality", "active"): "true"}
"""MuJoCo's own defaults of the attributes screwkit reads."""
ORIENTED = ("body", "geom", "site", "frame", "camera", "light", "inertial")
"""The elements that have a pose of their own (in ``<worldbody>`` or as class defaults)."""
CLASSED = ("joint", "site", "geom", "camera", "light")
"""The elements of a frame that take their defaults from a class (bodies and frames pass ``childclass`` on)."""


class MjcfError(ValueError):
    """An MJCF file that cannot be prepared (the message names the file and the element)."""


def describe(element: ElementTree.Element) -> str:
    """``<tag name='...'>``, how a message names an element."""
    name = element.get("name")
    return f"<{element.tag} name='{name}'>" if name else f"<{element.tag}>"


def class_attributes(root: ElementTree.Element, tag: str, base: dict[str, str] | None = None) -> dict[str, dict]:
    """The attributes each default class gives a ``tag`` element (inherited from enclosing classes, starting
    from ``base``); the top class is ``main``."""
    classes: dict[str, dict[str, str]] = {}

    def visit(default: ElementTree.Element, inherited: dict[str, str]) -> None:
        own = default.find(tag)
        attributes = {**inherited, **(own.attrib if own is not None else {})}
        classes[default.get("class", "main")] = attributes
        for child in default.findall("default"):
            visit(child, attributes)

    for top in root.findall("default"):
        visit(top, dict(base or {}))
    return classes


def euler_sequence(compiler: ElementTree.Element, path: Path) -> str:
    """``<compiler eulerseq>``: three of x, y, z (moving axes) and X, Y, Z (fixed axes), as MuJoCo accepts."""
    sequence = compiler.get("eulerseq", "xyz")
    if len(sequence) != 3 or any(letter not in "xyzXYZ" for letter in sequence):
        raise MjcfError(f"{path}: <compiler eulerseq='{sequence}'>: expected three of the letters x, y, z "
                        "(moving axes) and X, Y, Z (fixed axes).")
    return sequence


def quaternion_product(a: NDArray, b: NDArray) -> NDArray:
    """The product ``a b`` of two quaternions (w, x, y, z): the rotation ``b`` then ``a`` in fixed axes."""
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def rotation_matrix(quaternion: NDArray) -> NDArray:
    """The rotation matrix of a quaternion (w, x, y, z), normalised first (MJCF's ``quat`` need not be unit)."""
    w, x, y, z = np.asarray(quaternion, dtype=float) / np.linalg.norm(quaternion)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _matrix_quaternion(columns: NDArray) -> NDArray:
    """The quaternion of a rotation matrix (MuJoCo's ``frame2quat``: the largest component first)."""
    m = columns
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        w = 0.5 * math.sqrt(1 + trace)
        return np.array([4 * w * w, m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]]) / (4 * w)
    if m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        x = 0.5 * math.sqrt(1 + m[0, 0] - m[1, 1] - m[2, 2])
        return np.array([m[2, 1] - m[1, 2], 4 * x * x, m[0, 1] + m[1, 0], m[0, 2] + m[2, 0]]) / (4 * x)
    if m[1, 1] > m[2, 2]:
        y = 0.5 * math.sqrt(1 - m[0, 0] + m[1, 1] - m[2, 2])
        return np.array([m[0, 2] - m[2, 0], m[0, 1] + m[1, 0], 4 * y * y, m[1, 2] + m[2, 1]]) / (4 * y)
    z = 0.5 * math.sqrt(1 - m[0, 0] - m[1, 1] + m[2, 2])
    return np.array([m[1, 0] - m[0, 1], m[0, 2] + m[2, 0], m[1, 2] + m[2, 1], 4 * z * z]) / (4 * z)


def _unit(vector: NDArray, what: str, where: str) -> NDArray:
    length = float(np.linalg.norm(vector))
    if length <= MIN_AXIS:
        raise MjcfError(f"{where}: the {what} is the zero vector (MuJoCo refuses lengths up to {MIN_AXIS:g}).")
    return vector / length


def _alternative_quaternion(attribute: str, values: NDArray, degree: bool, sequence: str, where: str) -> NDArray:
    """The quaternion MuJoCo computes from an ``axisangle``, ``euler``, ``xyaxes`` or ``zaxis`` (user_util)."""
    scale = math.pi / 180.0 if degree else 1.0
    if attribute == "axisangle":
        axis, half = _unit(values[:3], "axisangle's axis", where), values[3] * scale / 2
        return np.array([math.cos(half), *(math.sin(half) * axis)])
    if attribute == "euler":
        quaternion = np.array([1.0, 0.0, 0.0, 0.0])
        for letter, angle in zip(sequence, values * scale):
            turn = np.array([math.cos(angle / 2), 0.0, 0.0, 0.0])
            turn[1 + "xyz".index(letter.lower())] = math.sin(angle / 2)
            moving = letter.islower()  # moving axes: post-multiply; fixed axes: pre-multiply
            quaternion = quaternion_product(quaternion, turn) if moving else quaternion_product(turn, quaternion)
        return quaternion / np.linalg.norm(quaternion)
    if attribute == "xyaxes":
        x = _unit(values[:3], "xyaxes's x axis", where)
        y = _unit(values[3:] - x * float(x @ values[3:]), "xyaxes's y axis orthogonal to its x axis", where)
        return _matrix_quaternion(np.column_stack([x, y, np.cross(x, y)]))
    z = _unit(values, "zaxis", where)  # zaxis: the smallest rotation taking (0, 0, 1) to it (MuJoCo's z2quat)
    axis = np.array([-z[1], z[0], 0.0])
    sine = float(np.linalg.norm(axis))
    if sine <= MIN_AXIS:
        return np.array([1.0, 0.0, 0.0, 0.0]) if z[2] > 0 else np.array([0.0, 1.0, 0.0, 0.0])
    half = math.atan2(sine, z[2]) / 2
    return np.array([math.cos(half), *(math.sin(half) * axis / sine)])


def orientations_as_quaternions(root: ElementTree.Element, degree: bool, sequence: str, path: Path) -> int:
    """Every ``axisangle``, ``euler``, ``xyaxes`` and ``zaxis`` (class defaults included) replaced by the
    ``quat`` MuJoCo computes from it; returns how many of them held angles in degrees."""
    in_degrees = 0
    for element in root.iter():
        if element.tag not in ORIENTED:
            continue
        given = [attribute for attribute in ("quat", *ALTERNATIVES) if element.get(attribute) is not None]
        where = f"{path}: {describe(element)}"
        if len(given) > 1:
            raise MjcfError(f"{where}: {' and '.join(given)}: one orientation only (MuJoCo refuses several).")
        if given == ["quat"] and not any(float(word) for word in element.get("quat").split()):
            raise MjcfError(f"{where}: quat='{element.get('quat')}': the zero quaternion is no orientation.")
        if not given or given == ["quat"]:
            continue
        attribute = given[0]
        values = np.array([float(word) for word in element.attrib.pop(attribute).split()])
        quaternion = _alternative_quaternion(attribute, values, degree, sequence, where)
        element.set("quat", " ".join(repr(float(v)) for v in quaternion))
        in_degrees += degree and attribute in ("axisangle", "euler")
    return in_degrees


def local_pose(element: ElementTree.Element) -> tuple[NDArray, NDArray]:
    """An element's ``pos`` and ``quat`` (w, x, y, z) in its parent's frame, MuJoCo's defaults where absent (once
    :func:`orientations_as_quaternions` has written every orientation as a quaternion)."""

    def numbers(attribute: str, default: tuple) -> NDArray:
        text = element.get(attribute)
        return np.array([float(word) for word in text.split()] if text else default, dtype=float)

    return numbers("pos", (0.0, 0.0, 0.0)), numbers("quat", (1.0, 0.0, 0.0, 0.0))


def site_pose(site: ElementTree.Element) -> tuple[NDArray, NDArray]:
    """A site's ``pos`` and ``quat`` in its body, as MuJoCo places it: for a ``fromto``, the segment's midpoint and
    the smallest turn taking z from the segment's end to its start (as a ``zaxis``); else :func:`local_pose`."""
    if site.get("fromto") is None:
        return local_pose(site)
    ends = np.array([float(word) for word in site.get("fromto").split()]).reshape(2, 3)
    along = _unit(ends[0] - ends[1], "fromto segment", describe(site))
    return ends.mean(axis=0), _alternative_quaternion("zaxis", along, False, "xyz", describe(site))


def unused_name(name: str, taken: set) -> str:
    """``name``, with underscores added until it is not in ``taken``, which it joins."""
    while name in taken:
        name += "_"
    taken.add(name)
    return name


def _text(values: NDArray) -> str:
    return " ".join(repr(float(v)) for v in values)


def defaults_written(root: ElementTree.Element, path: Path | str = "") -> None:
    """Every site's pose (``pos`` and ``quat``, or its ``fromto``) and every joint's ``type``, ``pos``, ``axis``,
    ``ref``, ``springref`` and ``range`` written on it, from its class or MuJoCo's own defaults (Pinocchio reads no
    site's class, and takes an attribute a joint's class leaves unset from the body's ``childclass``; a frame's children
    are then composed from them; a joint's angles are converted from degrees by its own type, a slide's ``ref``
    from a class being a length whatever the class's joint type). A site with a ``fromto``, its own or its class's,
    is placed by it alone, as MuJoCo places it (its orientation left out); MuJoCo refuses one that also has a
    ``pos`` from anywhere, or that is not a capsule, cylinder, box or ellipsoid, and so does this."""
    defaults = {tag: class_attributes(root, tag) for tag in ("site", "joint")}
    wanted = {"site": ("pos", "quat"), "joint": ("type", "pos", "axis", "ref", "springref", "range")}

    def visit(element: ElementTree.Element, childclass: str) -> None:
        for child in element:
            if child.tag in wanted:
                given = defaults[child.tag].get(child.get("class") or childclass, {})
                if child.tag == "site" and (child.get("fromto") or given.get("fromto")) is not None:
                    _fromto_site(child, given, path)
                else:
                    for attribute in wanted[child.tag]:  # every one written: Pinocchio would take a childclass's
                        default = None if attribute == "range" else BUILT_IN.get((child.tag, attribute))
                        if "ref" in attribute and child.get("type", "hinge") not in ("hinge", "slide"):
                            continue  # a ref on a 1-DoF joint only (Pinocchio refuses one on a ball)
                        if child.get(attribute) is None and given.get(attribute, default) is not None:
                            child.set(attribute, given.get(attribute, default))  # no range: Pinocchio's infinite
            visit(child, child.get("childclass", childclass) if child.tag in ("body", "frame") else childclass)

    for world in root.findall("worldbody"):
        visit(world, "main")


def _fromto_site(site: ElementTree.Element, given: dict[str, str], path: Path | str) -> None:
    """A site placed by a ``fromto`` (its own, else its class's), written on it alone, or refused as MuJoCo refuses
    it."""
    where = f"{path}: {describe(site)}" if path else describe(site)
    if (site.get("pos") or given.get("pos")) is not None:
        raise MjcfError(f"{where}: both pos and fromto, from the site or its class (MuJoCo refuses it).")
    kind = site.get("type") or given.get("type", "sphere")
    if kind not in ("capsule", "cylinder", "box", "ellipsoid"):
        raise MjcfError(f"{where}: a fromto on a site of type '{kind}': MuJoCo takes one on a capsule, cylinder, box "
                        "or ellipsoid only (and refuses the file).")
    site.set("fromto", site.get("fromto") or given["fromto"])
    site.attrib.pop("quat", None)  # MuJoCo places such a site by its segment alone


def frames_flattened(root: ElementTree.Element) -> int:
    """Every ``<frame>`` of ``<worldbody>`` replaced by its children, the frame's pose composed into theirs
    (a joint's position and axis included) and its ``childclass`` written on them; returns how many frames.
    Their class defaults must be written on them first (:func:`defaults_written`)."""
    count = 0

    def lift(frame: ElementTree.Element, outer_class: str) -> None:
        """The children of ``frame`` (frames inside it already lifted) placed in the frame's parent's frame."""
        nonlocal count
        inner_class = frame.get("childclass", outer_class)
        position, quaternion = local_pose(frame)
        rotation = rotation_matrix(quaternion)
        for child in frame:
            if child.tag == "joint":
                axis = np.array([float(word) for word in child.get("axis", "0 0 1").split()])
                child.set("axis", _text(rotation @ axis))
            if child.tag == "site" and child.get("fromto") is not None:  # its pose in the frame, then composed
                pos, quat = site_pose(child)
                del child.attrib["fromto"]
                child.set("pos", _text(pos))
                child.set("quat", _text(quat))
            if child.tag in ORIENTED or child.tag == "joint":
                pos, quat = local_pose(child)
                child.set("pos", _text(position + rotation @ pos))
                if child.tag != "joint":
                    child.set("quat", _text(quaternion_product(quaternion, quat)))
            if inner_class != outer_class:
                if child.tag in ("body", "frame"):
                    child.set("childclass", child.get("childclass", inner_class))
                elif child.tag in CLASSED and child.get("class") is None:
                    child.set("class", inner_class)
        count += 1

    def visit(element: ElementTree.Element, childclass: str) -> None:
        for child in list(element):
            inner = child.get("childclass", childclass) if child.tag in ("body", "frame") else childclass
            visit(child, inner)
            if child.tag == "frame":
                lift(child, childclass)
                position = list(element).index(child)
                element.remove(child)
                for offset, grandchild in enumerate(list(child)):
                    element.insert(position + offset, grandchild)

    for world in root.findall("worldbody"):
        visit(world, "main")
    return count


def joints_one_per_body(root: ElementTree.Element) -> list[str]:
    """Every body with several joints written as nested bodies with one joint each, at its frame, the last one keeping
    the body's name and everything else it holds; returns those bodies' names. MuJoCo turns a body by its joints in
    the order written, each about its own axis through its own ``pos`` in the body's frame as turned by the joints
    before it, which is the motion of these nested bodies; Pinocchio 4.1 makes one composite joint of them, which
    moves the body otherwise and no longer has the joints' names. Run after :func:`frames_flattened`, every body
    named (:func:`screwkit.io.mjcf_classes.bodies_named`)."""
    taken = {element.get("name") for element in root.iter("body")}
    split = []
    for body in list(root.iter("body")):
        joints = [child for child in body if child.tag in ("joint", "freejoint")]
        if len(joints) < 2:
            continue
        attributes = dict(body.attrib)
        split.append(attributes["name"])
        kept = [child for child in body if child.tag not in ("joint", "freejoint")]
        for child in list(body):
            body.remove(child)
        outer = body
        for index, joint in enumerate(joints):
            if index == len(joints) - 1:  # the body itself, at the frame the joints before it turned
                inner = ElementTree.SubElement(outer, "body", {key: value for key, value in attributes.items()
                                                               if key not in ("pos", "quat", "mocap")})
                inner.append(joint)
                inner.extend(kept)
                break
            inner = outer if index == 0 else ElementTree.SubElement(outer, "body")
            inner.set("name", unused_name(f"{attributes['name']}__{joint.get('name') or index}", taken))
            if attributes.get("childclass") is not None:
                inner.set("childclass", attributes["childclass"])
            # an inertia of its own: Pinocchio asks one of every body when <compiler inertiafromgeom="false">
            ElementTree.SubElement(inner, "inertial", pos="0 0 0", mass="1", diaginertia="1 1 1")
            inner.append(joint)
            outer = inner
    return split
