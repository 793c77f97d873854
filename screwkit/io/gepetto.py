"""Gepetto's closed-loop robots: a URDF tree plus a ``robot.yaml`` beside it.

The format of Gepetto's example-parallel-robots and toolbox-parallel-robots: ``closed_loop`` lists
pairs of Pinocchio frame names (joint, body or fixed-joint frames) that must coincide, ``type``
says how for each pair (``3d``: the origins, a ball joint; ``6d``: the whole frames, a weld; the
case of the letter does not matter), and ``name_mot`` lists the actuated joints. ``joint_name`` /
``joint_type`` (joint types changed when loading) are refused with a message: write the joints
in the URDF instead. The tree is read by Pinocchio; everything else by
:func:`screwkit.io.star.convert_tree`.
"""

from __future__ import annotations

from pathlib import Path

from screwkit.io.closed_tree import ClosedTree, Closure, ImportError_, declared_task_coordinates, homogeneous

__all__ = ["read_gepetto", "yaml_beside"]


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
    unknown = sorted(set(spec) - {"closed_loop", "type", "name_mot", "joint_name", "joint_type"})
    if unknown:
        raise ImportError_(f"{yaml_path}: unknown key(s) {', '.join(unknown)} (expected closed_loop, type, name_mot).")
    if spec.get("joint_name") or spec.get("joint_type"):
        raise ImportError_(f"{yaml_path}: joint_name/joint_type (joint types changed at loading) are not supported: "
                           "write those joints in the URDF.")
    pairs, kinds, motors = spec.get("closed_loop") or [], spec.get("type") or [], spec.get("name_mot")
    unactuated = "" if isinstance(motors, list) and motors else f"{yaml_path}: name_mot must list the actuated joints"
    motors = motors if not unactuated else []  # refused unless --actuate names them (screwkit.io.read_closed_tree)
    if len(kinds) != len(pairs):
        raise ImportError_(f"{yaml_path}: {len(pairs)} closed_loop pair(s) but {len(kinds)} type(s).")
    try:
        model = pin.buildModelFromUrdf(str(urdf))
    except (RuntimeError, ValueError) as error:
        raise ImportError_(f"{urdf}: Pinocchio cannot read the tree ({error}).") from None
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
                      unactuated=unactuated)
