"""An MJCF file made ready for Pinocchio's parser, as MuJoCo reads it, and MuJoCo's closure geometry.

Pinocchio's ``buildModelAndConstraintsFromMJCF`` reads the kinematic tree, but not everything a published
MJCF file holds the way MuJoCo does. :func:`prepared_mjcf` rewrites the XML first, saying what it did:

* ``<include file=...>`` elements are replaced by the included file's content (paths relative to the main
  file's folder, a nested include's too, as MuJoCo resolves them);
* several bodies under ``<worldbody>`` (a robot beside a camera rig, two halves of a mechanism) are wrapped in
  one body at the origin (Pinocchio reads only the first);
* unnamed ``<connect>``/``<weld>`` elements are named (Pinocchio merges unnamed ones);
* angles in degrees (``<compiler angle="degree">``, MuJoCo's default) become radians: hinge and ball joints'
  ``range``, ``ref`` and ``springref``;
* every ``euler``, ``axisangle``, ``xyaxes`` and ``zaxis`` becomes the ``quat`` MuJoCo computes from it
  (``<compiler angle>`` and ``eulerseq`` honoured, axes normalised), and every ``<frame>``'s children are
  lifted to its parent, the frame's pose composed into theirs (:mod:`screwkit.io.mjcf_pose`); a site's
  ``fromto`` from its class is written on it; a body with several joints becomes nested bodies with one joint
  each (:func:`~screwkit.io.mjcf_pose.joints_one_per_body`; Pinocchio would make one composite joint of them);
* default sections, classes, unnamed bodies and the joints of one body as MuJoCo reads them
  (:mod:`screwkit.io.mjcf_classes`);
* several ``<compiler>`` elements are read as one (MuJoCo applies them all);
* several top-level ``<default>``, ``<equality>``, ``<actuator>`` sections are merged (MuJoCo merges them;
  Pinocchio reads the first): the top class's element defaults take every section's attributes, a later one's
  winning;
* what kinematics does not need and Pinocchio cannot always read is left out: geoms, assets, plugins,
  cameras, lights, sensors, tendons, contacts (a mechanism's bodies, joints, sites, inertias and closures are
  all that is read).

What MuJoCo refuses of what is read is refused, naming the element: numbers that are not (or not as many as the
attribute holds), a name twice in one namespace, a hinge or slide axis of zero length, a limited joint's range
that is no interval, a keyframe's ``qpos`` that is not numbers. A range MuJoCo does not apply
(``limited="false"``...) is dropped: Pinocchio would apply it. An equality that is not a closure (a ``joint``,
``tendon`` or ``flex`` coupling) changes the mobility, which screwkit does not model: refused, unless it is
inactive (then left out, and said).

:func:`closure_placements` then gives each equality the frames MuJoCo constrains, from the bodies and sites
of the tree Pinocchio built: a ``weld`` with a ``relpose`` holds body2 at that pose in body1's frame (without
one, the pose they have at ``qpos0``); a ``connect`` holds body1's ``anchor`` on body2 at the point where it
is at ``qpos0``; site-based ones hold the two sites together. Only the standard library and numpy.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.common.xml_text import tolerant_xml
from screwkit.io.mjcf_classes import bodies_named, bodies_weighed, check_body_joints, defaults_merged, top_class_renamed
from screwkit.io.mjcf_pose import (
    MIN_AXIS,
    MjcfError,
    class_attributes,
    defaults_written,
    describe,
    euler_sequence,
    frames_flattened,
    joints_one_per_body,
    orientations_as_quaternions,
    rotation_matrix,
)

__all__ = ["prepared_mjcf", "closure_placements", "joint_ranges", "MAX_INCLUDE_DEPTH", "MjcfError",
           "CLOSURE_ATTRIBUTES"]

MAX_INCLUDE_DEPTH = 20
"""Deepest chain of ``<include>``s followed (a file including itself is refused before that)."""
ANGLE_ATTRIBUTES = ("range", "ref", "springref")
NOT_KINEMATICS = ("geom", "asset", "plugin", "extension", "camera", "light", "sensor", "tendon", "contact", "visual")
PLACEMENT_ATTRIBUTES = ("pos", "quat", "axisangle", "euler", "xyaxes", "zaxis")
"""How a body is placed in its parent (MJCF): on the one body under ``<worldbody>``, they move the whole robot."""
NUMBER_COUNTS = {"pos": (3,), "quat": (4,), "axis": (3,), "euler": (3,), "axisangle": (4,), "xyaxes": (6,),
                 "zaxis": (3,), "fromto": (6,), "anchor": (3,), "relpose": (7,), "range": (2,), "ref": (1,),
                 "springref": (1,), "gear": (1, 2, 3, 4, 5, 6)}
"""How many numbers each attribute that places a body, a joint or a closure holds (MuJoCo refuses the file
otherwise; a reader that took the numbers it could would place the mechanism somewhere else)."""
NAMESPACES = {"body": "body", "joint": "joint", "freejoint": "joint", "site": "site"}
SECTION_NAMESPACES = {"equality": "equality", "actuator": "actuator", "keyframe": "key"}
"""MuJoCo's namespaces that screwkit reads: a name twice in one is refused (by MuJoCo too)."""
COUPLINGS = {"joint": "a joint coupling", "tendon": "a tendon coupling", "flex": "a flex's edge lengths",
             "flexstrain": "a flex's strain"}
"""Equalities that are not closures: each constrains the mechanism's joints (changes its mobility)."""
IDENTIFYING = ("joint1", "joint2", "tendon1", "tendon2", "flex")
"""The attributes that say what a coupling couples, in messages."""
_COMMON = ("name", "class", "active", "solref", "solimp")
CLOSURE_ATTRIBUTES = {"connect": {*_COMMON, "body1", "body2", "anchor", "site1", "site2"},
                      "weld": {*_COMMON, "body1", "body2", "relpose", "anchor", "site1", "site2", "torquescale"}}
"""The attributes MuJoCo's schema allows on the closures screwkit reads; it refuses a file with any other (a
``relpose`` on a ``<connect>``, which only a ``<weld>`` has), and so does screwkit rather than ignore it."""


def _parse(path: Path) -> ElementTree.Element:
    try:
        return ElementTree.fromstring(tolerant_xml(path.read_bytes()))
    except ElementTree.ParseError as error:
        raise MjcfError(f"{path}: not well-formed XML ({error}).") from None
    except OSError as error:
        raise MjcfError(f"{path}: cannot be read ({error.strerror or error}).") from None


def _resolve_includes(element: ElementTree.Element, folder: Path, stack: tuple[Path, ...]) -> None:
    for position, child in enumerate(list(element)):
        if child.tag != "include":
            _resolve_includes(child, folder, stack)
            continue
        name = child.get("file")
        if not name:
            raise MjcfError(f"{stack[-1]}: <include> without a file attribute.")
        path = (folder / name).resolve()
        if path in stack or len(stack) > MAX_INCLUDE_DEPTH:
            raise MjcfError(f"{stack[-1]}: <include file='{name}'> includes itself (or nests deeper than "
                            f"{MAX_INCLUDE_DEPTH}).")
        included = _parse(path)
        if included.tag != "mujoco":
            raise MjcfError(f"{path}: an included file's root must be <mujoco>, got <{included.tag}>.")
        _resolve_includes(included, folder, stack + (path,))  # nested ones too: the main file's folder
        element.remove(child)
        for offset, grandchild in enumerate(list(included)):
            element.insert(position + offset, grandchild)


def _merged(root: ElementTree.Element, tag: str) -> ElementTree.Element | None:
    """The first ``tag`` child, with the children of its later duplicates moved into it (MuJoCo merges them)."""
    found = root.findall(tag)
    for extra in found[1:]:
        for child in list(extra):
            found[0].append(child)
        root.remove(extra)
    return found[0] if found else None


def _class_joints(root: ElementTree.Element) -> dict[str, dict[str, str]]:
    """The joint attributes each default class gives (inherited from enclosing classes; MuJoCo's default: hinge)."""
    return class_attributes(root, "joint", {"type": "hinge"})


def _joints(root: ElementTree.Element):
    """Every ``<joint>`` of the tree and its attributes, class defaults (``class``, ``childclass``) included."""
    classes = _class_joints(root)

    def visit(element: ElementTree.Element, childclass: str):
        childclass = element.get("childclass", childclass)
        for child in element:
            if child.tag == "joint":
                yield child, {**classes.get(child.get("class") or childclass, {"type": "hinge"}), **child.attrib}
            yield from visit(child, childclass)

    for world in root.findall("worldbody"):
        yield from visit(world, "main")


def joint_ranges(root: ElementTree.Element) -> dict[str, tuple[float, float] | None]:
    """Each named hinge's and slide's limits as MuJoCo applies them, once the file is prepared (radians; None: not
    limited). Pinocchio 4.1 shifts a joint's limits by its ``ref`` (and by a class's instead of its own), although
    its joint values are MuJoCo's: :func:`screwkit.io.mjcf.read_mjcf` writes these instead."""
    ranges: dict[str, tuple[float, float] | None] = {}
    for joint, attributes in _joints(root):
        if joint.get("name") and attributes.get("type", "hinge") in ("hinge", "slide"):
            low, high = (float(word) for word in attributes.get("range", "0 0").split())
            ranges[joint.get("name")] = (low, high) if low < high else None
    return ranges


def _to_radians(root: ElementTree.Element) -> int:
    """Every joint angle of a file in degrees, in radians; returns how many attributes changed (orientations
    are quaternions by then)."""
    classes = {name: attributes["type"] for name, attributes in _class_joints(root).items()}
    changed = 0

    def scale(element: ElementTree.Element, attribute: str) -> None:
        nonlocal changed
        words = (element.get(attribute) or "").split()
        if not words:
            return
        try:
            values = [float(word) for word in words]
        except ValueError:
            return
        element.set(attribute, " ".join(repr(math.radians(v)) for v in values))
        changed += 1

    def joint_type(element: ElementTree.Element, childclass: str) -> str:
        return element.get("type") or classes.get(element.get("class") or childclass, "hinge")

    def visit(element: ElementTree.Element, childclass: str, in_default: bool) -> None:
        childclass = element.get("childclass", childclass)
        if element.tag == "default":
            childclass = element.get("class", childclass)
        for child in element:
            if child.tag == "joint" and joint_type(child, childclass) in ("hinge", "ball"):
                for attribute in ANGLE_ATTRIBUTES:
                    scale(child, attribute)
            visit(child, childclass, in_default or child.tag == "default")

    visit(root, "main", False)
    return changed


def _check_numbers(root: ElementTree.Element, path: Path) -> None:
    """Every attribute of NUMBER_COUNTS holds that many numbers, or the file is refused naming the element."""
    for element in root.iter():
        for attribute, counts in NUMBER_COUNTS.items():
            text = element.get(attribute)
            if text is None or element.tag in ("compiler", "option", "size", "flag"):
                continue
            words = text.split()
            try:
                finite = all(math.isfinite(float(word)) for word in words)
            except ValueError:
                finite = False
            if not finite or len(words) not in counts:
                expected = " to ".join(str(c) for c in (counts[0], counts[-1]) if c) if len(counts) > 1 else counts[0]
                name = f" name='{element.get('name')}'" if element.get("name") else ""
                raise MjcfError(f"{path}: <{element.tag}{name}> {attribute}={text!r}: expected {expected} finite "
                                "number(s).")


def _check_keys(root: ElementTree.Element, path: Path) -> None:
    """Every keyframe's ``qpos`` is finite numbers (MuJoCo refuses a word, Pinocchio misreads a NaN)."""
    for keyframe in root.findall("keyframe"):
        for key in keyframe.findall("key"):
            for word in (key.get("qpos") or "").split():
                try:
                    finite = math.isfinite(float(word))
                except ValueError:
                    finite = False
                if not finite:
                    raise MjcfError(f"{path}: <keyframe>{describe(key)} qpos={key.get('qpos')!r}: {word!r} is not a "
                                    "finite number.")


def _check_equalities(root: ElementTree.Element, equality: ElementTree.Element | None,
                      path: Path) -> tuple[list[str], list[tuple[str, str | None, float, str]]]:
    """The equalities, as MuJoCo reads them: ``active`` from the element or its class; an active coupling of
    tendons or flexes is refused (screwkit does not model it), an inactive one left out. Returns what was left out,
    and the active couplings of two joints (or one held), taken out of the text too: ``(joint1, joint2 or None,
    slope, where)``, which refuse the mechanism only where they constrain it (a gripper's two fingers, one analysed:
    :func:`~screwkit.io.couplings.check_couplings`)."""
    classes = class_attributes(root, "equality")
    ignored, couplings = [], []
    for element in ([] if equality is None else list(equality)):
        named = " ".join(f"{key}='{element.get(key)}'" for key in ("name", *IDENTIFYING) if element.get(key))
        where = f"{path}: <equality><{element.tag}{' ' + named if named else ''}>"
        if element.tag not in ("connect", "weld", *COUPLINGS):
            removed = " (MuJoCo 2's distance constraint, since removed)" if element.tag == "distance" else ""
            raise MjcfError(f"{where}: not an equality MuJoCo reads{removed}: MuJoCo refuses the file.")
        unknown = sorted(set(element.attrib) - CLOSURE_ATTRIBUTES.get(element.tag, set(element.attrib)))
        if unknown:
            raise MjcfError(f"{where}: {unknown[0]}={element.get(unknown[0])!r}: not an attribute of <{element.tag}> "
                            f"(it has {', '.join(sorted(CLOSURE_ATTRIBUTES[element.tag]))}): MuJoCo refuses the file.")
        active = element.get("active", classes.get(element.get("class") or "main", {}).get("active", "true"))
        if active not in ("true", "false"):
            raise MjcfError(f"{where}: active='{active}': expected true or false.")
        element.set("active", active)
        if element.tag == "joint" and active == "true" and element.get("joint1"):
            words = (element.get("polycoef") or "0 1 0 0 0").split()  # joint1 - its ref = polynomial of joint2's
            try:
                slope = float(words[1]) if len(words) > 1 else 0.0  # (the slope at joint2's reference)
            except ValueError:
                raise MjcfError(f"{where}: polycoef={element.get('polycoef')!r}: expected numbers.") from None
            couplings.append((element.get("joint1"), element.get("joint2"), slope, where))
            equality.remove(element)
            continue
        if element.tag in COUPLINGS and active == "true":
            raise MjcfError(f"{where}: {COUPLINGS[element.tag]} changes the mechanism's mobility and screwkit "
                            "does not model it; remove the element (or set active='false') to analyse the joints "
                            "as independent.")
        if element.tag in COUPLINGS:
            ignored.append(f"<{element.tag}{' ' + repr(element.get('name')) if element.get('name') else ''}>")
            equality.remove(element)
    return ignored, couplings


DEFORMABLE = {"flexcomp": "a deformable body", "flex": "a deformable body"}
"""Elements that make bodies MuJoCo generates or deforms: screwkit analyses rigid links only."""


def _check_deformable(root: ElementTree.Element, path: Path) -> None:
    """A deformable or generated body is refused naming its element (Pinocchio would name the body it did not find:
    ``rod_0_0_0``, which MuJoCo generates from ``<flexcomp name='rod'>`` and the file's connects attach to)."""
    for tag, what in DEFORMABLE.items():
        found = root.find(f".//{tag}")
        if found is not None:
            named = f" name='{found.get('name')}'" if found.get("name") else ""
            raise MjcfError(f"{path}: <{tag}{named}> is {what}, which screwkit does not model (it analyses rigid "
                            "links joined by joints and closures); a rigid mechanism inside the file can be written "
                            "without it.")


def _without_replicates(root: ElementTree.Element, path: Path) -> list[str]:
    """MuJoCo's ``<replicate>`` (copies of a subtree, each named with its index) is not expanded: one that nothing the
    mechanism is read by names (closures, actuators, tendons; the obstacles of a test scene) is left out, and said;
    any other is refused, naming what refers into it and how to write the copies out."""
    dropped = []
    for parent, replicate in list(_outermost(root, "replicate")):
        inside = {element.get("name") for element in replicate.iter() if element.get("name")}
        referring = next((f"<{element.tag} {key}='{value}'>" for section in ("equality", "actuator", "tendon")
                          for block in root.findall(section) for element in block.iter()
                          for key, value in element.attrib.items()
                          if _copy_of(value, inside, replicate.get("sep", ""))), None)
        if referring is None and root.find("keyframe") is not None:
            referring = "<keyframe> (its qpos counts every copy's joints)"
        if referring is not None:
            raise MjcfError(f"{path}: <replicate count='{replicate.get('count')}'> holds elements {referring} refers "
                            "to: screwkit does not expand MuJoCo's <replicate>; write the copies out (MuJoCo writes "
                            "a model expanded with mj_saveLastXML).")
        parent.remove(replicate)
        names = f" ({', '.join(sorted(inside)[:3])}{', ...' if len(inside) > 3 else ''})" if inside else ""
        dropped.append(f"count {replicate.get('count')}{names}")
    return [f"<replicate> block(s) nothing the mechanism is read by refers to, left out: {'; '.join(dropped)}"] \
        if dropped else []


def _copy_of(value: str, inside: set, sep: str) -> bool:
    """Whether ``value`` names an element of a ``<replicate>`` (its names ``inside``): one of them, or a copy's, which
    MuJoCo numbers (ball0, ball1, ..., after ``sep``)."""
    return value in inside or any(value.startswith(name + sep) and value[len(name + sep):].isdigit() for name in inside)


def _outermost(element: ElementTree.Element, tag: str):
    """(parent, element) of each ``tag`` element under ``element`` that no other such holds."""
    for child in element:
        if child.tag == tag:
            yield element, child
        else:
            yield from _outermost(child, tag)


def _check_names(root: ElementTree.Element, path: Path) -> None:
    """No name twice in one of MuJoCo's namespaces that screwkit reads (MuJoCo refuses the file; Pinocchio would
    merge two joints into one, or take either of two bodies, sites, closures or keyframes)."""
    seen: dict[str, set[str]] = {"body": {"world"}}  # MuJoCo's world body

    def claim(element: ElementTree.Element, space: str) -> None:
        name = element.get("name")
        if not name:
            return
        if name in seen.setdefault(space, set()):
            world = " (MuJoCo's world body is named 'world')" if (space, name) == ("body", "world") else ""
            raise MjcfError(f"{path}: <{element.tag} name='{name}'>: the {space} name is used twice{world}.")
        seen[space].add(name)

    for world in root.findall("worldbody"):
        for element in world.iter():
            if element.tag in NAMESPACES:
                claim(element, NAMESPACES[element.tag])
    for section, space in SECTION_NAMESPACES.items():
        for parent in root.findall(section):
            for element in parent:
                claim(element, space)


def _check_joints(root: ElementTree.Element, path: Path, autolimits: bool) -> list[str]:
    """The joints' axes and ranges, refused where MuJoCo refuses them; a range MuJoCo does not apply
    (``limited="false"``; with autolimits, one that is no interval) is dropped, since Pinocchio would apply it.
    Returns the joints whose range was dropped."""
    dropped = []
    for joint, attributes in _joints(root):
        tag = f"<joint name='{joint.get('name')}'>" if (name := joint.get("name")) else "<joint>"
        kind = attributes.get("type", "hinge")
        if kind not in ("hinge", "slide", "ball"):
            continue
        axis = attributes.get("axis", "0 0 1")
        length = math.hypot(*(float(word) for word in axis.split()))
        if kind != "ball" and (length <= MIN_AXIS or length * length == math.inf):  # (squared: MuJoCo reads 0)
            small = "" if length == 0.0 else f"; MuJoCo refuses lengths up to {MIN_AXIS:g}" if length <= MIN_AXIS \
                else "; its length overflows once squared, and MuJoCo reads it as zero"
            raise MjcfError(f"{path}: {tag}: the axis is the zero vector (axis='{axis}'{small}).")
        limited, text = attributes.get("limited", "auto"), attributes.get("range", "0 0")
        low, high = (float(word) for word in text.split())
        if limited not in ("true", "false", "auto"):
            raise MjcfError(f"{path}: {tag}: limited='{limited}': expected true, false or auto.")
        if limited == "auto" and not autolimits and (low, high) != (0.0, 0.0):
            raise MjcfError(f"{path}: {tag}: range='{text}' without limited='true' or 'false', under <compiler "
                            "autolimits='false'>: limited or not?")
        applied = limited == "true" or (limited == "auto" and autolimits and low < high)
        if applied and kind == "ball" and low != 0.0:
            raise MjcfError(f"{path}: {tag}: range='{text}' on a limited ball joint: the first number must be 0 "
                            "(the second is the largest angle).")
        if applied and kind != "ball" and low >= high:
            raise MjcfError(f"{path}: {tag}: range='{text}' on a limited joint: the lower limit must be below the "
                            "upper.")
        if not applied and (low, high) != (0.0, 0.0):
            joint.set("range", "0 0")  # Pinocchio reads lower == upper: no limits (screwkit.io.star)
            dropped.append(name or "?")
    return dropped


def prepared_mjcf(path: Path) -> tuple[str, list[str], ElementTree.Element, list]:
    """The text of an MJCF file as Pinocchio should read it, what was changed, its element tree, and its active
    joint couplings (taken out of the text: :func:`_check_equalities`)."""
    path = Path(path)
    root = _parse(path)
    if root.tag != "mujoco":
        hint = " (a URDF: give it the suffix .urdf)" if root.tag == "robot" else ""
        raise MjcfError(f"{path}: the root element is <{root.tag}>, not <mujoco>{hint}.")
    _resolve_includes(root, path.parent, (path.resolve(),))
    _check_deformable(root, path)
    notes = _without_replicates(root, path)
    compilers = root.findall("compiler")
    compiler = _merged(root, "compiler")
    if compiler is None:
        compiler = ElementTree.Element("compiler")
        root.insert(0, compiler)
    for later in compilers[1:]:  # MuJoCo applies every <compiler>'s attributes
        compiler.attrib.update(later.attrib)
    for attribute in ("meshdir", "texturedir", "assetdir"):
        compiler.attrib.pop(attribute, None)  # no mesh is read
    angle = compiler.get("angle", "degree")
    if angle not in ("degree", "radian"):
        raise MjcfError(f"{path}: <compiler angle='{angle}'>: expected degree or radian.")
    sequence = euler_sequence(compiler, path)
    if compiler.get("coordinate", "local") != "local":
        raise MjcfError(f"{path}: <compiler coordinate='{compiler.get('coordinate')}'>: global coordinates are no "
                        "longer read by MuJoCo (since 2.3.3; it refuses the file): write it in local coordinates.")
    defaults_merged(root, path)
    equality = _merged(root, "equality")
    ignored, couplings = _check_equalities(root, equality, path)  # before the tendons go: <equality><tendon> is one
    if ignored:
        notes.append(f"inactive equality coupling(s) left out, as MuJoCo leaves them out: {', '.join(ignored)}")
    for parent in list(root.iter()):
        for child in list(parent):
            if child.tag in NOT_KINEMATICS:
                parent.remove(child)
    _check_numbers(root, path)
    _check_keys(root, path)
    _check_names(root, path)
    in_degrees = orientations_as_quaternions(root, angle == "degree", sequence, path)
    defaults_written(root, path)
    frames = frames_flattened(root)
    if frames:
        notes.append(f"{frames} <frame> element(s) read as MuJoCo reads them: their children placed in the frame")
    check_body_joints(root, path, {id(joint): attributes for joint, attributes in _joints(root)})
    bodies_named(root)  # Pinocchio merges unnamed bodies inside others, and drops their joints
    bodies_weighed(root, path, compiler)  # Pinocchio asks an inertia of every body
    split = joints_one_per_body(root)
    if split:
        notes.append(f"bodies with several joints ({', '.join(split)}) read as MuJoCo composes them: nested bodies "
                     "with one joint each, the body's name on the last")
    dropped = _check_joints(root, path, compiler.get("autolimits", "true") == "true")
    if dropped:
        notes.append(f"range not applied, as MuJoCo does not (limited='false', or not an interval): "
                     f"{', '.join(dropped)}")
    if angle == "degree":
        count = _to_radians(root) + in_degrees
        if count:
            notes.append(f"angles in degrees (MuJoCo's default unit) read as such: {count} attribute(s) converted")
    compiler.set("angle", "radian")
    compiler.set("eulerseq", "xyz")  # no euler is left
    world = _merged(root, "worldbody")
    bodies = [] if world is None else world.findall("body")
    if not bodies:
        raise MjcfError(f"{path}: <worldbody> holds no body: nothing to analyse.")
    placed = any(bodies[0].get(key) is not None for key in PLACEMENT_ATTRIBUTES if key != "pos") or any(
        float(word) != 0.0 for word in (bodies[0].get("pos") or "0").split())
    if len(bodies) > 1 or placed:  # Pinocchio drops the placement of the one body under <worldbody>: hold it in one
        wrapper = ElementTree.Element("body", name="screwkit_world", pos="0 0 0")
        # an inertia of its own: Pinocchio asks one of every body when <compiler inertiafromgeom="false">
        ElementTree.SubElement(wrapper, "inertial", pos="0 0 0", mass="1", diaginertia="1 1 1")
        for body in bodies:
            world.remove(body)
            wrapper.append(body)
        world.append(wrapper)
        if len(bodies) > 1:
            notes.append(f"{len(bodies)} bodies under <worldbody> ({', '.join(b.get('name', '?') for b in bodies)}) "
                         "held in one, 'screwkit_world', at the origin")
    named, taken = [], {element.get("name") for element in ([] if equality is None else equality)}
    for element in ([] if equality is None else list(equality)):
        if element.tag in ("connect", "weld") and element.get("body2") == "world":
            element.attrib.pop("body2")  # MuJoCo's world body, as body2 left out means (Pinocchio knows no 'world')
        if element.tag in ("connect", "weld") and not element.get("name"):
            name = f"{element.tag}_{len(named) + 1}"
            while name in taken:  # a closure of the file has that name
                name = f"{name}_"
            element.set("name", name)
            named.append(name)
    if named:
        notes.append(f"{len(named)} unnamed closure(s) named in file order: {', '.join(named[:4])}"
                     + (", ..." if len(named) > 4 else ""))
    _merged(root, "actuator")
    top_class_renamed(root)
    # no <equality> in the text Pinocchio reads: screwkit places closures itself (closure_placements), and Pinocchio
    # 4.1's parser of connects on sites crashes the process now and then (read over and over on one file)
    kept = [(index, element) for index, element in enumerate(root) if element.tag == "equality"]
    for _, element in kept:
        root.remove(element)
    text = ElementTree.tostring(root, encoding="unicode")
    for index, element in kept:
        root.insert(index, element)
    return text, notes, root, couplings


# -- MuJoCo's closure geometry -------------------------------------------------------------------------


def _numbers(element: ElementTree.Element, attribute: str, count: int, default) -> list[float]:
    words = (element.get(attribute) or "").split()
    if not words and default is not None:  # (None: MuJoCo asks it)
        return list(default)
    try:
        values = [float(word) for word in words]
    except ValueError:
        values = []
    if len(values) != count:
        raise MjcfError(f"<{element.tag} name='{element.get('name')}'>: expected {count} numbers in '{attribute}', "
                        "got " + (repr(element.get(attribute)) if attribute in element.attrib else "none") + ".")
    return values


def closure_placements(element: ElementTree.Element, model, data, frame_of) -> tuple[int, NDArray, int, NDArray]:
    """The two frames (joint id, 4x4 placement in that joint's frame) a ``connect`` or ``weld`` holds together, as
    MuJoCo does. ``data`` holds the forward kinematics at ``qpos0``; ``frame_of(name, kind)`` the Pinocchio frame
    (``kind`` "body" or "site")."""
    if element.get("site1") or element.get("site2"):
        placements = []
        for attribute in ("site1", "site2"):
            frame = frame_of(element.get(attribute), "site")
            placements.append((frame.parentJoint, frame.placement.homogeneous.copy()))
        (joint_a, place_a), (joint_b, place_b) = placements
        return joint_a, place_a, joint_b, place_b
    body1 = frame_of(element.get("body1"), "body")
    body2 = frame_of(element.get("body2") or "world", "body")
    world_1 = data.oMi[body1.parentJoint].homogeneous @ body1.placement.homogeneous
    world_2 = data.oMi[body2.parentJoint].homogeneous @ body2.placement.homogeneous
    if element.tag == "connect":
        anchor = np.eye(4)
        anchor[:3, 3] = _numbers(element, "anchor", 3, None)  # (MuJoCo refuses a connect of bodies without it)
        place_a = body1.placement.homogeneous @ anchor
        on_body2 = np.linalg.inv(world_2) @ world_1 @ anchor  # where the anchor is on body2 at qpos0
        return body1.parentJoint, place_a, body2.parentJoint, body2.placement.homogeneous @ on_body2
    relpose = _numbers(element, "relpose", 7, ())
    if relpose and any(relpose[3:]):  # body2's pose in body1's frame
        relative = np.eye(4)
        relative[:3, :3] = rotation_matrix(relpose[3:])
        relative[:3, 3] = relpose[:3]
    else:  # the pose they have at qpos0
        relative = np.linalg.inv(world_1) @ world_2
    return body1.parentJoint, body1.placement.homogeneous @ relative, body2.parentJoint, body2.placement.homogeneous
