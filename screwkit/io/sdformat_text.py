"""SDFormat text: one ``<model>``'s links, joints and frames, and their poses resolved in the world.

What :mod:`screwkit.io.sdformat` builds a closed tree from, and what :mod:`screwkit.io.gazebo` reads a
``<gazebo><joint>`` with. SDFormat's pose semantics (1.7 and later):

* a ``<pose>`` holds ``x y z roll pitch yaw`` (radians, or degrees with ``degrees="true"``), or ``x y z qx qy qz
  qw`` with ``rotation_format="quat_xyzw"``; it is written in the frame its ``relative_to`` names, by default: the
  model frame ``__model__`` for a link, the child link for a joint, the ``attached_to`` frame for a ``<frame>``
  (itself ``__model__`` by default); the model's own ``<pose>`` places the model in the world;
* a joint's ``<axis><xyz>`` (and ``<axis2>``) is written in the joint frame, or in the frame its ``expressed_in``
  names (``__model__`` when a file of SDFormat 1.5 or 1.6 says ``<use_parent_model_frame>true``, and always in a
  file of SDFormat 1.4 or earlier, whose axes libsdformat reads in the model frame);
* a joint's ``<parent>`` may be ``world``; a link, joint or frame name is a frame, and ``__model__`` is attached
  to the canonical link (the model's ``canonical_link``, else its first link).

:func:`world_poses` gives every frame's pose in the world at zero joint values, as SDFormat's own semantic pose
resolution does. Constructs this reading does not follow are refused with the file and element named: nested
models, ``<include>`` (wherever it is), several models, a ``placement_frame``, unknown frames and cycles of
``relative_to``; so are an unnamed model, link, joint or frame and a ``degrees`` that is not a bool or is on a
quaternion (SDFormat refuses them), a zero quaternion (no rotation), an axis ``<limit>`` whose lower bound is above
the upper (no range) or equal to it (a joint Gazebo holds still: write it ``fixed``). A ``continuous`` joint's
limits are ignored, as SDFormat says ("omit if joint is continuous").
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import rotation_from_rpy
from screwkit.common.xml_text import tolerant_xml
from screwkit.io.closed_tree import ImportError_
from screwkit.io.drake import drake_elements

__all__ = ["SdfAxis", "SdfJoint", "SdfModel", "numbers", "parse_pose", "parse_joint", "in_parent_model_frame",
           "read_model", "world_poses", "attached_link", "controllers", "controlled_joints", "detachable_joints",
           "plugin_note", "WORLD", "MODEL_FRAME", "CONTROLLER"]

WORLD = "world"
MODEL_FRAME = "__model__"
UNLIMITED = 1e16
"""SDFormat's default joint limits (``-1e16``, ``1e16``): at or beyond it, a joint has no limit."""


def numbers(text: str | None, count: int, default: str, where: str, tag: str) -> NDArray[np.float64]:
    """``count`` finite numbers of an element's text (``default`` when it is empty); one line naming ``where``."""
    text = default if text is None or not text.strip() else text
    try:
        values = np.array([float(word) for word in text.split()])
    except ValueError:
        values = np.array([])
    if values.size != count or not np.all(np.isfinite(values)):
        raise ImportError_(f"{where}: <{tag}> must hold {count} finite numbers, got {text.strip()!r}.")
    return values


def _flag(node, attribute: str, where: str) -> bool:
    """An SDFormat bool attribute (``true``, ``false``, ``1``, ``0``, any case; absent: false)."""
    text = node.get(attribute, "false").strip().lower()
    if text not in ("true", "false", "1", "0"):
        raise ImportError_(f"{where}: <{node.tag} {attribute}={node.get(attribute)!r}>: expected true or false (or 1 "
                           "or 0).")
    return text in ("true", "1")


def parse_pose(node, where: str) -> tuple[NDArray[np.float64], str]:
    """A ``<pose>`` element (or None: the identity) as a 4x4 matrix, and its ``relative_to`` ("" if not given)."""
    matrix = np.eye(4)
    if node is None:
        return matrix, ""
    quaternion = node.get("rotation_format", "euler_rpy") == "quat_xyzw"
    if node.get("rotation_format", "euler_rpy") not in ("euler_rpy", "quat_xyzw"):
        raise ImportError_(f"{where}: <pose rotation_format={node.get('rotation_format')!r}> (expected euler_rpy or "
                           "quat_xyzw).")
    degrees = _flag(node, "degrees", where)
    if quaternion and degrees:
        raise ImportError_(f"{where}: <pose rotation_format='quat_xyzw' degrees={node.get('degrees')!r}>: degrees "
                           "apply to roll, pitch and yaw, not to a quaternion (SDFormat refuses it).")
    values = numbers(node.text, 7 if quaternion else 6, "0 0 0 0 0 0 1" if quaternion else "0 0 0 0 0 0", where,
                     "pose")
    matrix[:3, 3] = values[:3]
    if quaternion:
        norm = float(np.linalg.norm(values[3:]))
        if not 1e-12 < norm < np.inf:
            raise ImportError_(f"{where}: <pose rotation_format='quat_xyzw'> {node.text.strip()!r}: the quaternion "
                               "x y z w is " + ("zero" if norm <= 1e-12 else "too large") + ": no rotation.")
        x, y, z, w = values[3:] / norm
        matrix[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                          [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                          [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    else:
        matrix[:3, :3] = rotation_from_rpy(np.radians(values[3:]) if degrees else values[3:])
    return matrix, node.get("relative_to", "").strip()


@dataclass(frozen=True)
class SdfAxis:
    """A joint axis: its ``xyz`` (unit) in the frame ``expressed_in`` ("" = the joint frame), its limits or None."""

    xyz: NDArray[np.float64]
    expressed_in: str
    limits: tuple[float, float] | None


@dataclass(frozen=True)
class SdfJoint:
    """An SDFormat ``<joint>``: its pose (4x4) in the frame ``relative_to`` ("" = the child), its axes."""

    name: str
    kind: str
    parent: str
    child: str
    pose: NDArray[np.float64]
    relative_to: str
    axes: tuple[SdfAxis, ...]
    where: str
    held: bool = False
    """A revolute or prismatic joint whose limits are lower = upper = 0, read as the fixed joint it is (Gazebo holds
    it there: it cannot move)."""


def _axis(element, tag: str, where: str, version: tuple[int, ...], kind: str) -> SdfAxis:
    node = element.find(tag)
    xyz_node = node.find("xyz") if node is not None else None
    xyz = numbers(xyz_node.text if xyz_node is not None else None, 3, "0 0 1", where, f"{tag}><xyz")
    if np.linalg.norm(xyz) < 1e-12:
        raise ImportError_(f"{where}: <{tag}><xyz> is zero.")
    expressed = xyz_node.get("expressed_in", "").strip() if xyz_node is not None else ""
    if version < (1, 5) or (version < (1, 7) and in_parent_model_frame(node)):  # 1.4: always (its 1_4.convert)
        expressed = expressed or MODEL_FRAME
    for inner in node.iter() if node is not None else ():
        if "degrees" in inner.attrib:
            raise ImportError_(f"{where}: <{tag}>...<{inner.tag} degrees=...>: SDFormat has no degrees there (only "
                               "on <pose>): limits are in radians.")
    return SdfAxis(xyz / np.linalg.norm(xyz), expressed, _limits(element, tag, where, kind))


def in_parent_model_frame(axis) -> bool:
    """Whether an ``<axis>`` element (or None) says ``<use_parent_model_frame>true`` (SDFormat 1.5 and 1.6)."""
    return axis is not None and axis.findtext("use_parent_model_frame", "").strip().lower() in ("true", "1")


def _bounds(element, tag: str, where: str) -> NDArray[np.float64] | None:
    """An axis's ``<limit>`` bounds as written (SDFormat's defaults where one is left out), None without one."""
    node = element.find(f"{tag}/limit")
    if node is None:
        return None
    lower = node.findtext("lower", "").strip() or str(-UNLIMITED)
    upper = node.findtext("upper", "").strip() or str(UNLIMITED)
    return numbers(f"{lower} {upper}", 2, "", where, f"{tag}><limit")


def _limits(element, tag: str, where: str, kind: str) -> tuple[float, float] | None:
    """An axis's ``<limit>``: None when it has none, the joint (of type ``kind``) is continuous (SDFormat ignores a
    continuous joint's limits: "omit if joint is continuous") or ball or fixed, or its bounds are SDFormat's defaults
    (no limit); refused when the lower bound is not below the upper."""
    node = element.find(f"{tag}/limit")
    if node is None or kind in ("continuous", "ball", "fixed"):
        return None
    bounds = _bounds(element, tag, where)
    if bounds[0] > bounds[1]:
        raise ImportError_(f"{where}: <{tag}><limit> lower {bounds[0]:g} > upper {bounds[1]:g}: the lower limit must "
                           "be below the upper.")
    if bounds[0] == bounds[1]:
        raise ImportError_(f"{where}: <{tag}><limit> lower = upper = {bounds[0]:g}: the joint cannot move (Gazebo "
                           "holds it at that value, away from where the file draws it); write a fixed joint, or limits "
                           "with lower below upper.")
    if abs(bounds[0]) < UNLIMITED and abs(bounds[1]) < UNLIMITED:
        return float(bounds[0]), float(bounds[1])
    return None


SCENERY = ("ground_plane", "sun")
"""The models a Gazebo world includes that are none of a mechanism (``model://ground_plane``, Fuel's
``.../models/Ground Plane``, ``model://sun``): left out, said."""
CONTROLLER = re.compile(r"joint.*controller|apply.?joint.?force", re.IGNORECASE)
"""A joint-controller plugin's ``filename`` or ``name`` (its ``<joint_name>`` joints are driven), or one that applies a
force or torque at joints (Gazebo's ``ApplyJointForce``: an effort input)."""


def controllers(parents) -> list:
    """The joint-controller ``<plugin>`` elements among the children of ``parents`` (a model; a URDF's ``<gazebo>``)."""
    return [plugin for parent in parents for plugin in parent.findall("plugin")
            if CONTROLLER.search(plugin.get("filename", "")) or CONTROLLER.search(plugin.get("name", ""))]


def controlled_joints(parents) -> list[str]:
    """The joints that the joint-controller plugins among the children of ``parents`` drive (their ``<joint_name>``,
    in file order, once each)."""
    return list(dict.fromkeys((node.text or "").strip() for plugin in controllers(parents)
                              for node in plugin.iter("joint_name") if (node.text or "").strip()))


def detachable_joints(parents, links, model: str, taken=()) -> list[tuple[object, str]]:
    """The fixed joints that Gazebo's DetachableJoint plugins among the children of ``parents`` make when the
    simulation starts, between ``<parent_link>`` and ``<child_link>`` as the file places them: a loop where both are
    among the model's ``links``; each as an SDFormat ``<joint>`` element (named apart from the joints ``taken``) with
    how the file writes it, for messages, which says when the plugin's ``<child_model>`` is neither ``__model__`` nor
    the model's name ``model`` (the name it is spawned under, as a published five-bar's; else another model, whose
    link of that name it would attach: then no loop of this mechanism). A plugin attaching a link this model does not
    have is no loop."""
    found, names = [], set(taken)
    for parent in parents:
        for plugin in parent.findall("plugin"):
            if "DetachableJoint" not in plugin.get("name", "") and \
                    "detachable-joint" not in plugin.get("filename", "").lower():
                continue
            ends = [(plugin.findtext(tag) or "").strip() for tag in ("parent_link", "child_link")]
            if not all(end in links for end in ends):
                continue
            name = next(f"{ends[0]}_to_{ends[1]}{suffix}" for suffix in ("", *(f"_{k}" for k in range(2, 99)))
                        if f"{ends[0]}_to_{ends[1]}{suffix}" not in names)
            names.add(name)
            joint = ElementTree.Element("joint", name=name, type="fixed")
            ElementTree.SubElement(joint, "parent").text = ends[0]
            ElementTree.SubElement(joint, "child").text = ends[1]
            spawned = (plugin.findtext("child_model") or "").strip()
            other = f"; its <child_model> {spawned!r} read as this model spawned so" \
                if spawned not in ("", "__model__", model) else ""
            found.append((joint, f"<plugin name='{plugin.get('name', '')}'> ({ends[0]} to {ends[1]}{other})"))
    return found


def plugin_note(plugins: list[tuple[object, str]], what: str) -> str:
    """The import report's line on the fixed joints (``what``: joints, closures) that :func:`detachable_joints` made."""
    said = "; ".join(written.split("(", 1)[1].rstrip(")") for _, written in plugins)
    return (f"{what} {', '.join(joint.get('name') for joint, _ in plugins)}: the fixed joints Gazebo's DetachableJoint "
            f"plugins make at start, the links where the file places them ({said})")


def parse_joint(element, where: str, version: tuple[int, ...] = (1, 7)) -> SdfJoint:
    """An SDFormat ``<joint>`` element as written (``where``: the file and element, for messages; ``version``: the
    file's SDFormat version: 1.5 and 1.6 read ``<use_parent_model_frame>``, 1.4 and earlier write every axis in the
    model frame)."""
    name = element.get("name", "")
    ends = []
    for tag in ("parent", "child"):
        node = element.find(tag)
        end = (node.text or "").strip() if node is not None else ""
        if not end:
            raise ImportError_(f"{where}: no <{tag}>.")
        ends.append(end)
    pose, relative = parse_pose(element.find("pose"), where)
    kind = element.get("type", "")
    bounds = _bounds(element, "axis", where) if kind in ("revolute", "prismatic") else None
    held = bounds is not None and bounds[0] == bounds[1] == 0.0  # held where the file draws it: a fixed joint
    kind = "fixed" if held else kind
    axes = tuple(_axis(element, tag, where, version, kind) for tag in ("axis", "axis2"))
    return SdfJoint(name, kind, ends[0], ends[1], pose, relative, axes, where, held)


@dataclass
class SdfModel:
    """One ``<model>`` of an SDFormat file: where each frame's pose is written (``poses``: name -> (relative_to,
    4x4)), the links in file order, the joints, the ``<frame>`` elements (name -> attached_to), the canonical link,
    and the model element itself (for what :mod:`screwkit.io.sdformat` reads further: plugins, markers)."""

    source: str
    name: str
    element: object
    links: list[str]
    joints: list[SdfJoint]
    frames: dict[str, str]
    canonical: str
    poses: dict[str, tuple[str, NDArray[np.float64]]] = field(default_factory=dict)
    where: dict[str, str] = field(default_factory=dict)
    ball_constraints: list[tuple[str, NDArray[np.float64], str, NDArray[np.float64], str]] = field(
        default_factory=list)
    """Drake's ``<drake:ball_constraint>`` elements: (link A, P in A, link B, Q in B, where), P and Q coinciding."""
    renamed: list[str] = field(default_factory=list)
    """What reading renamed (an SDFormat 1.6 joint named as a link), for the import report."""


def _the_model(path: Path, root) -> tuple[object, str]:
    """The one model of an SDFormat file, and the world's other models, static and without joints (a ground plane),
    which it leaves out (their names, quoted, for the import report; "" if none)."""
    if root.tag != "sdf":
        raise ImportError_(f"{path}: the root element is <{root.tag}>, not <sdf>: not an SDFormat file.")
    parents = {child: parent for parent in root.iter() for child in parent}
    scenery_included = []
    for include in root.iter("include"):  # wherever it is: in <sdf>, a <world>, a <model>, a nested one
        scope = parents[include]
        uri = include.findtext("uri", "").strip()
        if scope.tag == "world" and uri.rstrip("/").rsplit("/", 1)[-1].lower().replace(" ", "_") in SCENERY:
            scenery_included.append(repr(uri))  # Gazebo's own ground plane and sun: none of the mechanism
            continue
        named = f" name='{scope.get('name')}'" if scope.get("name") is not None else ""
        raise ImportError_(f"{path}: <include> of {uri!r}: included models are "
                           f"not read (this one in <{scope.tag}{named}>); write the model in the file.")
    models = root.findall("model") + root.findall("world/model")
    scenery = [model for model in models if (model.findtext("static") or "").strip().lower() in ("true", "1")
               and model.find("joint") is None]  # a world's ground plane, its walls: none of the mechanism
    moving = [model for model in models if model not in scenery] or models
    if len(moving) != 1:
        names = ", ".join(repr(model.get("name")) for model in moving)
        aside = f", besides {len(scenery)} static without joints" if len(moving) < len(models) else ""
        raise ImportError_(f"{path}: {len(moving)} <model> elements ({names or 'none'}{aside}); screwkit reads one "
                           "model: write the mechanism's model alone in a file.")
    model = moving[0]
    left_out = ", ".join([repr(other.get("name")) for other in models if other is not model] + scenery_included)
    if not (model.get("name") or "").strip():
        raise ImportError_(f"{path}: <model> has no name (SDFormat requires one).")
    for nested in model.iter("model"):
        if nested is not model:
            raise ImportError_(f"{path}: <model name='{model.get('name')}'><model name='{nested.get('name')}'>: "
                               "nested models are not read; write their links and joints in the outer model.")
    if model.get("placement_frame"):
        raise ImportError_(f"{path}: <model name='{model.get('name')}' placement_frame=...>: not read; write the "
                           "model's <pose> in the world.")
    return model, left_out


def _check_poses(element, path: Path) -> None:
    """Every ``<pose>`` of the model, its links, joints and frames readable (:func:`parse_pose`), or one line naming
    each one that is not, so that one run lists them all."""
    refused = []
    for node in [element, *(child for tag in ("link", "joint", "frame") for child in element.findall(tag))]:
        try:
            parse_pose(node.find("pose"), f"<{node.tag} name='{node.get('name')}'>")
        except ImportError_ as error:
            refused.append(str(error).removesuffix("."))
    if refused:
        raise ImportError_(f"{path}: " + "; ".join(refused) + ".")


def read_model(path: Path) -> SdfModel:
    """The one model of an SDFormat file (in ``<sdf>`` or in its one ``<world>``), as written."""
    path = Path(path)
    try:
        root = ElementTree.fromstring(tolerant_xml(path.read_bytes()))
    except ElementTree.ParseError as error:
        raise ImportError_(f"{path}: not well-formed XML ({error}).") from None
    element, scenery = _the_model(path, root)
    version = tuple(int(part) for part in (root.get("version", "1.7").split(".") + ["0"])[:2] if part.isdigit())
    label = f"{path}: <model name='{element.get('name')}'>"
    _check_names(element, label)
    _check_poses(element, path)
    drake = sorted({name for name, _ in drake_elements(element)} - {"ball_constraint"})
    if drake:  # Drake's own joints and ties: left out, the model would be another mechanism
        raise ImportError_(f"{label}: <drake:{drake[0]}>, Drake's own, joins links in a way screwkit does not read (it "
                           "reads <drake:ball_constraint>); the model without it would be another mechanism.")
    links = [link.get("name", "") for link in element.findall("link")]
    if not links:
        raise ImportError_(f"{label}: no <link>.")
    model = SdfModel(str(path), element.get("name", ""), element, links, [], {}, element.get("canonical_link") or
                     links[0])
    if scenery:
        model.renamed.append(f"models {scenery} of the world left out: scenery (static without joints, or Gazebo's "
                             "ground plane and sun included)")
    model.ball_constraints = [_ball_constraint(node, f"{label}: <drake:ball_constraint> {number}")
                              for number, (_, node) in enumerate(drake_elements(element), start=1)]
    pose, relative = parse_pose(element.find("pose"), label)
    if relative not in ("", WORLD):
        raise ImportError_(f"{label}: <pose relative_to={relative!r}>: a model's pose is read in the world only.")
    model.poses[MODEL_FRAME] = (WORLD, pose)
    model.where[MODEL_FRAME] = label
    for link in element.findall("link"):
        where = f"{path}: <link name='{link.get('name')}'>"
        pose, relative = parse_pose(link.find("pose"), where)
        _declare(model, link.get("name", ""), relative or MODEL_FRAME, pose, where)
    if version < (1, 7):  # before 1.7 a joint could share a link's name: libsdformat renames the joint, and warns
        _rename_joints_named_as_links(model, element, version)
    written = [(joint, f"<joint name='{joint.get('name')}'>") for joint in element.findall("joint")]
    plugins = detachable_joints([element], links, model.name, [joint.get("name") for joint, _ in written])
    for joint, written_as in written + plugins:
        parsed = parse_joint(joint, f"{path}: {written_as}", version)
        model.joints.append(parsed)
        _declare(model, parsed.name, parsed.relative_to or parsed.child, parsed.pose, parsed.where)
    if plugins:
        model.renamed.append(plugin_note(plugins, "joints"))
    for frame in element.findall("frame"):
        where = f"{path}: <frame name='{frame.get('name')}'>"
        attached = frame.get("attached_to", "").strip() or MODEL_FRAME
        pose, relative = parse_pose(frame.find("pose"), where)
        _declare(model, frame.get("name", ""), relative or attached, pose, where)
        model.frames[frame.get("name", "")] = attached
    if model.canonical not in links:
        raise ImportError_(f"{label}: canonical_link {model.canonical!r} is not one of its links.")
    return model


def _ball_constraint(node, where: str) -> tuple[str, NDArray, str, NDArray, str]:
    """A ``<drake:ball_constraint>`` of an SDFormat model (its children's text: the links' names, P and Q in them)."""
    written = {child.tag.rsplit("}", 1)[-1]: (child.text or "").strip() for child in node if isinstance(child.tag, str)}
    read = []
    for tag in ("ball_constraint_body_A", "ball_constraint_p_AP", "ball_constraint_body_B", "ball_constraint_p_BQ"):
        if not written.get(tag):
            raise ImportError_(f"{where}: no <drake:{tag}>.")
        read.append(written[tag] if "body" in tag else numbers(written[tag], 3, "", where, f"drake:{tag}"))
    return (*read, where)


def _rename_joints_named_as_links(model: SdfModel, element, version: tuple[int, ...]) -> None:
    """A joint of a file before SDFormat 1.7 named as a link or as a joint before it gets the name ``<name>_joint``
    (``<name>_joint<k>`` while that is taken), as libsdformat gives it: in file order, against the links and the
    joints already named; said in ``model.renamed``."""
    taken = set(model.links)
    for joint in element.findall("joint"):
        name = new = joint.get("name", "")
        count = 0
        while new in taken:
            new, count = f"{name}_joint{count - 1 if count else ''}", count + 1
        if new != name:
            joint.set("name", new)
            what = "a link" if name in model.links else "a joint before it"
            model.renamed.append(f"joint {name!r} named {new!r}: {what} of this SDFormat "
                                 f"{'.'.join(map(str, version))} file has its name, and libsdformat renames the "
                                 "joint so (1.7 refuses the file)")
        taken.add(new)


def _check_names(element, label: str) -> None:
    """Every link, joint and frame of the model named (SDFormat requires the name), else refused by position."""
    for tag in ("link", "joint", "frame"):
        for number, child in enumerate(element.findall(tag), start=1):
            if not (child.get("name") or "").strip():
                suffix = "th" if 10 <= number % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(number % 10, "th")
                raise ImportError_(f"{label}: its {number}{suffix} <{tag}> has no name (SDFormat requires one: a "
                                   f"{tag} is a frame, named to be placed and joined).")


def _declare(model: SdfModel, name: str, relative_to: str, pose: NDArray, where: str) -> None:
    if not name or name in (WORLD, MODEL_FRAME) or name.startswith("__"):
        raise ImportError_(f"{where}: a frame needs a name other than world and those starting with __.")
    if name in model.poses:
        raise ImportError_(f"{where}: the name {name!r} is already {model.where[name].split(': ', 1)[1]} (links, "
                           "joints and frames share one namespace).")
    model.poses[name] = (relative_to, pose)
    model.where[name] = where


def world_poses(model: SdfModel) -> dict[str, NDArray[np.float64]]:
    """Every frame's pose (4x4) in the world at zero joint values: links, joints, frames, ``__model__``."""
    resolved: dict[str, NDArray] = {WORLD: np.eye(4)}
    children_of_world = {joint.name for joint in model.joints if joint.child == WORLD}  # refused later, and said why

    def resolve(name: str, seen: tuple[str, ...]) -> NDArray:
        if name in resolved:
            return resolved[name]
        relative, pose = model.poses[name]
        if relative == WORLD and name != MODEL_FRAME and name not in children_of_world:
            raise ImportError_(f"{model.where[name]}: its pose is relative_to 'world', a frame outside the model's "
                               "scope (SDFormat names only frames of the same scope: the model's '__model__', a link, "
                               "a joint or a <frame>; the model's own <pose> places it in the world).")
        if relative not in model.poses and relative != WORLD:
            raise ImportError_(f"{model.where[name]}: its pose is relative_to {relative!r}, not a frame of the model.")
        if relative in seen + (name,):
            raise ImportError_(f"{model.where[name]}: its pose's relative_to goes round a cycle ("
                               + " -> ".join(seen + (name, relative)) + ").")
        resolved[name] = resolve(relative, seen + (name,)) @ pose
        return resolved[name]

    for name in model.poses:
        resolve(name, ())
    return resolved


def attached_link(model: SdfModel, name: str) -> str:
    """The link a frame moves with (``world`` for the world): a link itself, a joint's child, a frame's
    ``attached_to``, ``__model__``'s canonical link."""
    seen = []
    joints = {joint.name: joint for joint in model.joints}
    while name not in model.links and name != WORLD:
        if name in seen:
            raise ImportError_(f"{model.where[name]}: attached_to goes round a cycle ({' -> '.join(seen + [name])}).")
        seen.append(name)
        if name == MODEL_FRAME:
            name = model.canonical
        elif name in joints:
            name = joints[name].child
        elif name in model.frames:
            name = model.frames[name]
        else:
            where = model.where.get(seen[-2], model.source) if len(seen) > 1 else model.source
            raise ImportError_(f"{where}: names {name!r}, not a link, joint or frame of the model.")
    return name
