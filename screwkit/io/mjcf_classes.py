"""MJCF default classes, bodies and their joints, as MuJoCo reads them, before Pinocchio reads the file.

Used by :func:`screwkit.io.mjcf_text.prepared_mjcf`:

* :func:`defaults_merged` reads several top-level ``<default>`` sections as MuJoCo does: each reopens the top class
  ``main``, a later one's attributes winning, and a class keeps ``main`` as it stood when its section was read;
* :func:`bodies_named` names every unnamed body (Pinocchio 4.1 merges unnamed bodies inside others and drops their
  joints);
* :func:`check_body_joints` refuses the joints of one body MuJoCo refuses (a free joint or mocap body inside another
  body, a free joint with others, a ball followed by a rotation), and places a free joint at its body's origin,
  where MuJoCo has it whatever its ``pos``;
* :func:`top_class_renamed` gives the top class a name of its own in the text Pinocchio reads (Pinocchio applies a
  body's ``childclass`` to an element of ``class="main"``), and leaves the classes' joint ``ref`` out.

Only the standard library.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from pathlib import Path

from screwkit.io.mjcf_pose import ALTERNATIVES, BUILT_IN, MjcfError, describe, unused_name

__all__ = ["defaults_merged", "bodies_named", "bodies_weighed", "check_body_joints", "top_class_renamed", "TOP_CLASS",
           "MUJOCO_MINIMUM"]

TOP_CLASS = "screwkit_main"
"""The top class's name in the text Pinocchio reads."""
ORIENTATIONS = ("quat", *ALTERNATIVES)


def _frozen(first: ElementTree.Element, tag: str, changed: dict[str, str]) -> None:
    """The classes of ``first`` keep the top class's ``tag`` attributes as they stand, before ``changed`` changes
    them (MuJoCo copies the top class into a class when it reads the class)."""
    own = first.find(tag)
    standing = dict(own.attrib) if own is not None else {}
    for cls in first.findall("default"):
        element = cls.find(tag)
        if element is None:
            element = ElementTree.Element(tag)
            cls.insert(0, element)
        for key in changed:
            if key in ORIENTATIONS:
                if not any(element.get(other) is not None for other in ORIENTATIONS):
                    given = [other for other in ORIENTATIONS if other in standing]
                    element.set(given[0] if given else "quat", standing[given[0]] if given else "1 0 0 0")
            elif element.get(key) is None and (key in standing or (tag, key) in BUILT_IN):
                element.set(key, standing.get(key, BUILT_IN.get((tag, key), "")))
        if not element.attrib and not len(element):
            cls.remove(element)


def defaults_merged(root: ElementTree.Element, path: Path) -> None:
    """Several top-level ``<default>`` sections read as MuJoCo reads them: one top class, ``main``, whose element
    defaults take every section's attributes (a later one's winning) and which holds every section's classes, each
    class keeping ``main`` as it stood when its section was read; refused as MuJoCo refuses them: a top section of
    another class, a class name twice, an element twice in one class, a class or childclass no class is called."""
    tops = root.findall("default")
    for top in tops:
        if top.get("class", "main") != "main":
            raise MjcfError(f"{path}: top-level <default class='{top.get('class')}'>: the top class is 'main' and "
                            "cannot be renamed (MuJoCo refuses it); nest the class in a <default>.")
    seen: set[str] = set()
    for default in (nested for top in tops for nested in top.iter("default")):
        name = default.get("class", "main")
        if name in seen and default not in tops:
            raise MjcfError(f"{path}: <default class='{name}'>: a class name given twice (MuJoCo refuses it).")
        seen.add(name)
        tags = [child.tag for child in default if child.tag != "default"]
        for tag in {tag for tag in tags if tags.count(tag) > 1}:
            raise MjcfError(f"{path}: <default class='{name}'> holds more than one <{tag}> (MuJoCo refuses it).")
    for element in root.iter():
        for attribute in ("class", "childclass") if element.tag != "default" else ():
            if element.get(attribute) not in (None, *seen, "main"):
                raise MjcfError(f"{path}: {describe(element)}: {attribute}='{element.get(attribute)}' names no default "
                                "class of the file (MuJoCo refuses it).")
    if not tops:
        if any("main" in (element.get("class"), element.get("childclass")) for element in root.iter()):
            root.insert(1, ElementTree.Element("default", {"class": "main"}))
        return
    first = tops[0]
    for later in tops[1:]:  # its own element defaults first, as MuJoCo reads a section, then its classes
        for child in sorted(later, key=lambda element: element.tag == "default"):
            own = first.find(child.tag) if child.tag != "default" else None
            if child.tag != "default":
                _frozen(first, child.tag, child.attrib)
            if own is None:
                first.append(child)
            else:
                own.attrib.update(child.attrib)
        root.remove(later)
    first.set("class", "main")


def bodies_named(root: ElementTree.Element) -> int:
    """Every unnamed body given a name of its own, one a reader finds in the file: after its first named joint
    (``fl_ja_body`` for the body of joint ``fl_ja``), else ``body_1``, ...; returns how many."""
    taken = {body.get("name") for body in root.iter("body")}
    count = 0
    for body in root.iter("body"):
        if body.get("name") is None:
            count += 1
            joint = next((child.get("name") for child in body if child.tag in ("joint", "freejoint")
                          and child.get("name")), None)
            body.set("name", unused_name(f"{joint}_body" if joint else f"body_{count}", taken))
    return count


MUJOCO_MINIMUM = 1e-15
"""MuJoCo's ``mjMINVAL``: the least mass and inertia it takes of a moving body."""


def bodies_weighed(root: ElementTree.Element, path: Path, compiler: ElementTree.Element) -> int:
    """Under ``<compiler inertiafromgeom="false">`` (each body's inertia from its ``<inertial>`` alone), every body
    without one given a unit inertia, which Pinocchio asks of every body (the kinematics do not depend on it); returns
    how many. MuJoCo loads a file where each body with joints has, with the bodies welded to it (its children without
    joints, theirs, ...), a mass and an inertia above :data:`MUJOCO_MINIMUM`, each body's at least the compiler's
    ``boundmass`` and ``boundinertia``; a body with joints that has not is refused, as MuJoCo refuses it. Run once the
    frames are flattened and the bodies' joints read (:func:`check_body_joints`)."""
    if compiler.get("inertiafromgeom") != "false":
        return 0
    least = [float(compiler.get(name) or 0.0) for name in ("boundmass", "boundinertia")]

    def jointed(body) -> bool:
        return any(child.tag in ("joint", "freejoint") for child in body)

    def weight(body) -> list[float]:  # (its mass and inertia, with the bodies welded to it)
        inertial = body.find("inertial")
        words = [] if inertial is None else (inertial.get("diaginertia") or inertial.get("fullinertia") or "").split()
        own = [0.0 if inertial is None else float(inertial.get("mass") or 0.0), sum(float(word) for word in words[:3])]
        welded = [weight(child) for child in body.findall("body") if not jointed(child)]
        return [max(value, bound) + sum(part[k] for part in welded) for k, (value, bound) in enumerate(zip(own, least))]

    count = 0
    for body in (body for world in root.findall("worldbody") for body in world.iter("body")):
        if jointed(body) and min(weight(body)) <= MUJOCO_MINIMUM:
            raise MjcfError(f"{path}: {describe(body)}: a moving body without mass or inertia (with the bodies welded "
                            "to it; <compiler inertiafromgeom='false'>: each from its <inertial>): MuJoCo refuses the "
                            "file.")
        if body.find("inertial") is None:
            ElementTree.SubElement(body, "inertial", pos="0 0 0", mass="1", diaginertia="1 1 1")
            count += 1
    return count


def check_body_joints(root: ElementTree.Element, path: Path, resolved: dict[int, dict[str, str]]) -> None:
    """The joints of each body, refused where MuJoCo refuses them: a type MuJoCo does not know, a free joint or a
    mocap body inside another body (MuJoCo takes them on a body of ``<worldbody>`` only), a free joint with others
    (more than six DoFs), a ball joint followed by a hinge or a ball (a rotation after a rotation of every axis); a
    free joint's ``pos`` dropped (MuJoCo places a free body by its coordinates alone). ``resolved``: each joint's
    attributes, its class's included, by ``id``. Run once the frames are flattened
    (:func:`~screwkit.io.mjcf_pose.frames_flattened`: every joint is then its body's child, every body of the world
    the world's)."""
    top = {body for world in root.findall("worldbody") for body in world.findall("body")}
    for body in (body for world in root.findall("worldbody") for body in world.iter("body")):
        joints = [child for child in body if child.tag in ("joint", "freejoint")]
        kinds = ["free" if joint.tag == "freejoint" else resolved.get(id(joint), {}).get("type", "hinge")
                 for joint in joints]
        nested = (("a free joint", "free" in kinds), ("a mocap body", body.get("mocap") == "true"))
        for what in (what for what, present in nested if present and body not in top):
            raise MjcfError(f"{path}: {describe(body)}: {what} inside another body; MuJoCo takes it only on a body "
                            "of <worldbody> (and refuses the file).")
        for joint, kind in zip(joints, kinds):
            if kind not in ("free", "ball", "slide", "hinge"):
                raise MjcfError(f"{path}: {describe(joint)}: type='{kind}' is no joint type of MuJoCo's (free, ball, "
                                "slide, hinge; MuJoCo refuses the file).")
            if kind == "free":
                joint.attrib.pop("pos", None)
        if "free" in kinds and len(joints) > 1:
            raise MjcfError(f"{path}: {describe(body)}: a free joint and other joints in one body (more than six "
                            "DoFs; MuJoCo refuses it).")
        if "ball" in kinds[:-1] and any(kind in ("hinge", "ball") for kind in kinds[kinds.index("ball") + 1:]):
            raise MjcfError(f"{path}: {describe(body)}: a ball joint followed by a rotation in one body (MuJoCo "
                            "refuses it).")


def top_class_renamed(root: ElementTree.Element) -> None:
    """The top class named :data:`TOP_CLASS` in the text, and every ``class`` or ``childclass`` naming it; the classes'
    joint ``ref`` and ``springref`` left out (written on every hinge and slide by then, and refused by Pinocchio on a
    ball joint of such a class, which MuJoCo reads)."""
    for joint in (element for default in root.iter("default") for element in default.findall("joint")):
        for attribute in ("ref", "springref"):
            joint.attrib.pop(attribute, None)
    for element in root.iter():
        if element.tag == "default" and element in root.findall("default"):
            element.set("class", TOP_CLASS)
        for attribute in ("class", "childclass"):
            if element.tag != "default" and element.get(attribute) == "main":
                element.set(attribute, TOP_CLASS)
