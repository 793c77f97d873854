"""Gepetto's closed-loop robots: a URDF tree plus a ``robot.yaml`` beside it.

The format of Gepetto's example-parallel-robots and toolbox-parallel-robots: ``closed_loop`` lists
pairs of Pinocchio frame names (joint, body or fixed-joint frames) that must coincide, ``type``
says how for each pair (``3d``: the origins, a ball joint; ``6d``: the whole frames, a weld; the
case of the letter does not matter), and ``name_mot`` lists the actuated joints. ``joint_name`` /
``joint_type`` replace joints of the URDF when loading, as Gepetto's own loader
(``example_parallel_robots.loader_tools.completeRobotLoader``) does: ``SPHERICAL`` puts a ball joint
where the joint was (its axis dropped), ``UJOINT_AB`` (A, B two of X, Y, Z) two revolute joints about
the joint frame's axes A then B, named ``<joint>_A`` and ``<joint>_B``, the joint's link and frames
carried by the second, and ``FIXED`` holds the joint at 0 (:func:`replaced_joints`). The tree is read
by Pinocchio; everything else by :func:`screwkit.io.star.convert_tree`.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from screwkit.io.closed_tree import ClosedTree, Closure, ImportError_, declared_task_coordinates, homogeneous
from screwkit.io.urdf_tree import urdf_model

__all__ = ["read_gepetto", "yaml_beside", "replaced_joints"]


def yaml_beside(urdf: Path) -> Path | None:
    """The ``robot.yaml`` (or ``<stem>.yaml``) next to a URDF, if there is one."""
    for candidate in (urdf.with_suffix(".yaml"), urdf.parent / "robot.yaml"):
        if candidate.is_file():
            return candidate
    return None


def read_gepetto(urdf: Path, yaml_path: Path, *, output: str | None = None,
                 output_type: str | None = None) -> ClosedTree:
    """The closed tree of a URDF and its Gepetto ``robot.yaml``."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read
    import yaml

    source = f"{urdf} + {yaml_path.name}"
    try:
        spec = yaml.safe_load(yaml_path.read_text(encoding="utf-8"))
    except yaml.YAMLError as error:
        raise ImportError_(f"{yaml_path}: not valid YAML ({str(error).splitlines()[0]}).") from None
    if not isinstance(spec, dict):
        raise ImportError_(f"{yaml_path}: expected a mapping with closed_loop, type and name_mot.")
    pairs, kinds, motors = spec.get("closed_loop") or [], spec.get("type") or [], spec.get("name_mot")
    for key, value in (("closed_loop", pairs), ("type", kinds)):
        if not isinstance(value, list):
            raise ImportError_(f"{yaml_path}: {key} must be a list, got {value!r}.")
    if len(kinds) != len(pairs):
        raise ImportError_(f"{yaml_path}: {len(pairs)} closed_loop pair(s) but {len(kinds)} type(s).")
    model = urdf_model(urdf)
    written = spec.get("name_mot")
    spec, notes = _earlier_dialect(spec, model, f"{yaml_path}")
    motors = spec.get("name_mot")
    unactuated = "" if isinstance(motors, list) and motors else f"{yaml_path}: " + (
        f"name_mot {written!r}, read as a pattern of the motors' names, matches no joint" if isinstance(written, str)
        else "name_mot must list the actuated joints")
    motors = motors if not unactuated else []  # refused unless --actuate names them (screwkit.io.read_closed_tree)
    if spec.get("joint_name") is not None or spec.get("joint_type") is not None:
        model, replaced = replaced_joints(model, spec.get("joint_name"), spec.get("joint_type"), f"{yaml_path}")
        notes += replaced
    names = [frame.name for frame in model.frames]
    closures = []
    for index, (pair, kind) in enumerate(zip(pairs, kinds)):
        if not (isinstance(pair, list) and len(pair) == 2):
            raise ImportError_(f"{yaml_path}: closed_loop[{index}] must be a pair of frame names, got {pair!r}.")
        if str(kind).lower() not in ("3d", "6d"):
            raise ImportError_(f"{yaml_path}: type[{index}] must be 3d or 6d, got {kind!r}.")
        sides = []
        for name in pair:
            if name not in names:
                raise ImportError_(f"{yaml_path}: closed_loop[{index}] names frame {name!r}, not in {urdf.name}.")
            frame = model.frames[names.index(name)]
            sides.append((int(frame.parentJoint), homogeneous(frame.placement)))
        closures.append(Closure(f"{pair[0]}-{pair[1]}", sides[0][0], sides[0][1], sides[1][0], sides[1][1],
                                str(kind).lower()))
    return ClosedTree(source, model, closures, [str(m) for m in motors], pin.neutral(model), output, output_type,
                      "URDF + Gepetto robot.yaml", task_coordinates=declared_task_coordinates(urdf.read_bytes()),
                      unactuated=unactuated, notes=notes)


KEYS = ("closed_loop", "type", "name_mot", "joint_name", "joint_type")
"""The keys of a robot.yaml that example-parallel-robots' loader reads (by key: it passes over any other)."""


def _earlier_dialect(spec: dict, model, source: str) -> tuple[dict, list[str]]:
    """``spec`` with the keys of example-parallel-robots' earlier robot.yaml (2023) read as its tools read them:
    ``name_mot`` a pattern of the motors' names (``re.search``, ``getMotId_q``), ``rotule_name`` one of the joints
    made ball joints (``jointTypeUpdate``), when ``joint_name`` does not list them; the other keys passed over
    (``Lidmot``/``Lidvmot``, the motors' coordinates, follow from the names), each said in a note. A pattern that is
    no regular expression, or is empty (it would take every joint), is refused naming it (``source``: the file)."""
    spec, notes, names = dict(spec), [], list(model.names)[1:]

    def matching(key: str) -> list[str]:
        pattern = spec[key]
        try:
            found = [name for name in names if pattern and re.search(pattern, name)]
        except re.error as error:
            raise ImportError_(f"{source}: {key} {pattern!r} is not a pattern of joint names ({error}).") from None
        if not pattern:
            raise ImportError_(f"{source}: {key} '' would take every joint: write the joints' names, or a pattern.")
        return found

    if isinstance(spec.get("name_mot"), str):
        pattern, spec["name_mot"] = spec["name_mot"], matching("name_mot")
        notes.append(f"robot.yaml's name_mot {pattern!r} read as a pattern of the motors' names, as the earlier "
                     f"dialect of example-parallel-robots did: {', '.join(spec['name_mot']) or 'none'}")
    balls = spec.get("rotule_name")
    if isinstance(balls, str) and spec.get("joint_name") is None and spec.get("joint_type") is None:
        spec["joint_name"] = matching("rotule_name")
        spec["joint_type"] = ["SPHERICAL"] * len(spec["joint_name"])
        notes.append(f"robot.yaml's rotule_name {balls!r} read as a pattern of the ball joints' names, as the earlier "
                     f"dialect of example-parallel-robots did: {', '.join(spec['joint_name']) or 'none'}")
    elif balls is not None:
        notes.append(f"robot.yaml's rotule_name {balls!r} passed over: " + (
            "joint_name and joint_type say the joints" if isinstance(balls, str) else "not a pattern of joint names"))
    spec.pop("rotule_name", None)
    other = sorted(map(str, set(spec) - set(KEYS)))
    if other:
        notes.append(f"robot.yaml's key(s) {', '.join(other)} passed over: example-parallel-robots' loader reads "
                     f"{', '.join(KEYS)}")
    return spec, notes


def replaced_joints(model, names, kinds, source: str):
    """``model`` with the joints ``names`` replaced by the ``kinds`` of a robot.yaml's ``joint_name`` / ``joint_type``
    (see the module's docstring), as example-parallel-robots' loader replaces them; every other joint, link and frame
    kept, with its limits (the loader drops every joint's limits), and what was replaced, for the import report. A
    name that is no joint of the URDF is passed over, as the loader passes it over, and said in the report.
    ``source`` names the file in errors."""
    import pinocchio as pin

    replace, missing = _replacements(model, names, kinds, source)
    rebuilt = pin.Model()
    rebuilt.name = model.name
    carrier = {0: 0}  # each joint of ``model``: the joint of ``rebuilt`` that carries its link
    for joint in range(1, model.njoints):
        name, kind, joint_model = model.names[joint], replace.get(model.names[joint], ""), model.joints[joint]
        parent, placement = carrier[model.parents[joint]], model.jointPlacements[joint]
        if kind == "SPHERICAL":
            joint_model = pin.JointModelSpherical()
        elif kind.startswith("UJOINT"):
            first, second = (getattr(pin, f"JointModelR{axis}")() for axis in kind[-2:])
            parent = rebuilt.addJoint(parent, first, placement, f"{name}_{kind[-2]}")
            joint_model, placement, name = second, pin.SE3.Identity(), f"{name}_{kind[-1]}"
        carrier[joint] = rebuilt.addJoint(parent, joint_model, placement, name)
        rebuilt.appendBodyToJoint(carrier[joint], model.inertias[joint], pin.SE3.Identity())
    for frame in list(model.frames)[1:]:  # the universe's frame is the rebuilt model's own
        name, joint = model.names[frame.parentJoint], carrier[frame.parentJoint]
        if frame.type == pin.FrameType.JOINT and frame.name == name and replace.get(name, "").startswith("UJOINT"):
            for axis, hinge in zip(replace[name][-2:], (joint - 1, joint)):  # the universal joint's two hinges
                rebuilt.addFrame(pin.Frame(f"{name}_{axis}", hinge, pin.SE3.Identity(), pin.FrameType.JOINT), False)
        else:
            rebuilt.addFrame(pin.Frame(frame.name, joint, frame.placement, frame.type), False)
    _copy_limits(model, rebuilt, [(joint, carrier[joint]) for joint in range(1, model.njoints)
                                  if replace.get(model.names[joint], "FIXED") == "FIXED"])
    fixed = [rebuilt.getJointId(name) for name, kind in replace.items() if kind == "FIXED"]
    notes = ["robot.yaml's joint_type " + (f"holds {name} at 0 (FIXED)" if kind == "FIXED" else
             f"replaces {name} by a ball joint" if kind == "SPHERICAL" else f"replaces {name} by revolute joints "
             f"{name}_{kind[-2]} and {name}_{kind[-1]} (a universal joint)") for name, kind in replace.items()]
    if missing:
        notes.append(f"robot.yaml's joint_name lists {', '.join(missing)}, not joints of the URDF: passed over, as "
                     "example-parallel-robots' loader passes them over")
    return (pin.buildReducedModel(rebuilt, fixed, pin.neutral(rebuilt)) if fixed else rebuilt), notes


def _replacements(model, names, kinds, source: str) -> tuple[dict[str, str], list[str]]:
    """The joints to replace, each with its type, and the names that are no joints of ``model``; an entry that
    cannot be read is refused naming it."""
    if not (isinstance(names, list) and isinstance(kinds, list)) or len(names) != len(kinds):
        raise ImportError_(f"{source}: joint_name and joint_type must be two lists of the same length, got "
                           f"{names!r} and {kinds!r}.")
    replace: dict[str, str] = {}
    missing = []
    for index, (name, kind) in enumerate(zip(map(str, names), map(str, kinds))):
        if not model.existJointName(name) or name == "universe":
            missing.append(name)
            continue
        if name in replace:
            raise ImportError_(f"{source}: joint_name[{index}] names {name!r} a second time.")
        if kind not in ("SPHERICAL", "FIXED") and not (re.fullmatch("UJOINT_[XYZ]{2}", kind) and kind[-1] != kind[-2]):
            raise ImportError_(f"{source}: joint_type[{index}] ({name!r}) must be SPHERICAL, FIXED or UJOINT_AB with A "
                               f"and B two of X, Y, Z, got {kind!r}.")
        dofs = model.joints[model.getJointId(name)].nv
        if dofs != 1:
            raise ImportError_(f"{source}: joint_name[{index}] names {name!r}, a joint of {dofs} DoFs: only a 1-DoF "
                               "joint is replaced.")
        replace[name] = kind
    return replace, missing


def _copy_limits(model, rebuilt, kept: list[tuple[int, int]]) -> None:
    """The limits of the joints ``kept`` (pairs of a joint of ``model`` and the same joint of ``rebuilt``) copied
    into ``rebuilt``; a universal joint's hinges unlimited (Pinocchio's default for a joint added without limits is
    the largest float, which is no limit either but overflows in arithmetic)."""
    lower, upper = rebuilt.lowerPositionLimit.copy(), rebuilt.upperPositionLimit.copy()
    for joint in range(1, rebuilt.njoints):
        if rebuilt.joints[joint].nq == 1:
            lower[rebuilt.joints[joint].idx_q], upper[rebuilt.joints[joint].idx_q] = -np.inf, np.inf
    for old, new in kept:
        source = slice(model.joints[old].idx_q, model.joints[old].idx_q + model.joints[old].nq)
        target = slice(rebuilt.joints[new].idx_q, rebuilt.joints[new].idx_q + rebuilt.joints[new].nq)
        lower[target], upper[target] = model.lowerPositionLimit[source], model.upperPositionLimit[source]
    rebuilt.lowerPositionLimit, rebuilt.upperPositionLimit = lower, upper
