"""Closed-loop mechanisms written by other tools, read into screwkit's model.

* :func:`read_mechanism_file`: MJCF (``.xml``/``.mjcf``, through Pinocchio's own parser), a URDF
  tree with a Gepetto ``robot.yaml`` beside it, or an onshape-to-robot URDF whose loops are
  ``closing_`` frame pairs (:mod:`screwkit.io.onshape`) or a URDF whose loops are ``<gazebo><joint>``
  elements (:mod:`screwkit.io.gazebo`) or Drake's ``<drake:ball_constraint>`` elements (:mod:`screwkit.io.drake`),
  or an SDFormat model (``.sdf``) whose loops are native joints
  (:mod:`screwkit.io.sdformat`), as the text of a URDF in screwkit's convention
  and an :class:`~screwkit.io.closed_tree.ImportReport`;
* :func:`is_foreign`: whether a path is such a file (the loader then imports it).

The conversion itself (assembly, platform, legs, loop joints, idle joints, output) is
:func:`screwkit.io.star.convert_tree`; legs joined to each other (compound legs) are
:mod:`screwkit.io.compound`'s; legs with loops inside them (parallelograms of ball-jointed rods) are analysed
as a graph at the file's configuration by :func:`graph_mechanism` (:mod:`screwkit.io.graph`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from screwkit.common.lazy import lazy_attributes
from screwkit.common.units import metres_per
from screwkit.common.xml_text import tolerant_xml

if TYPE_CHECKING:  # imported on first use (__getattr__), so that loading a file in screwkit's convention reads none
    from screwkit.io.closed_tree import ClosedTree, Closure, ImportError_, ImportReport, LegWithLoops
    from screwkit.io.drake import read_drake
    from screwkit.io.gazebo import read_gazebo
    from screwkit.io.gepetto import read_gepetto
    from screwkit.io.graph import GraphMechanism, graph_mechanism
    from screwkit.io.locking import actuate_joints, lock_joints
    from screwkit.io.mjcf import read_mjcf
    from screwkit.io.onshape import read_onshape
    from screwkit.io.sdformat import read_sdformat
    from screwkit.io.star import convert_tree

__all__ = ["read_mechanism_file", "read_closed_tree", "is_foreign", "convert_tree", "ClosedTree", "Closure",
           "ImportReport", "ImportError_", "LegWithLoops", "GraphMechanism", "graph_mechanism", "read_gepetto",
           "read_onshape", "read_gazebo", "read_drake", "read_mjcf", "read_sdformat", "lock_joints", "actuate_joints",
           "with_reference_configuration"]

_READERS = {
    **dict.fromkeys(("ClosedTree", "Closure", "ImportError_", "ImportReport", "LegWithLoops"),
                    "screwkit.io.closed_tree"),
    **dict.fromkeys(("GraphMechanism", "graph_mechanism"), "screwkit.io.graph"),
    "read_gazebo": "screwkit.io.gazebo", "read_drake": "screwkit.io.drake",
    "read_gepetto": "screwkit.io.gepetto", "read_mjcf": "screwkit.io.mjcf",
    "read_onshape": "screwkit.io.onshape", "convert_tree": "screwkit.io.star", "lock_joints": "screwkit.io.locking",
    "actuate_joints": "screwkit.io.locking", "read_sdformat": "screwkit.io.sdformat",
}
"""Where each name of the readers of other tools lives: imported when first used (PEP 562), since loading a file
in screwkit's convention (and every bundled mechanism) needs none of them (about 20 ms, YAML and XML readers)."""


__getattr__, __dir__ = lazy_attributes("screwkit.io", _READERS, globals())

MJCF_SUFFIXES = (".xml", ".mjcf")


def is_foreign(path: Path) -> bool:
    """An MJCF or SDFormat file, or a URDF with no ``<loop>`` of its own and a Gepetto ``robot.yaml`` beside it or
    onshape-to-robot ``closing_`` frame pairs or ``<gazebo><joint>`` or ``<drake:ball_constraint>`` elements."""
    from screwkit.io.drake import has_drake_constraints  # the readers: only for a file given by its path
    from screwkit.io.gazebo import has_gazebo_joints  # (idem)
    from screwkit.io.gepetto import yaml_beside  # (idem)
    from screwkit.io.onshape import has_closing_frames  # (idem)
    from screwkit.io.sdformat import SDFORMAT_SUFFIXES  # (idem)

    path = Path(path)
    if path.suffix.lower() in MJCF_SUFFIXES + SDFORMAT_SUFFIXES:
        return True
    if path.suffix.lower() == ".urdf" and (yaml_beside(path) is not None or has_closing_frames(path)
                                           or has_gazebo_joints(path) or has_drake_constraints(path)):
        with open(path, "rb") as handle:  # the head alone
            head = handle.read(4_000_000)
        return b"<loop" not in head
    return False


def read_closed_tree(path: Path, *, output: str | None = None, output_type: str | None = None,
                     lock: tuple[str, ...] = (), actuate: tuple[str, ...] = (),
                     length_unit: str | None = None, unit: str | None = None, initial=()) -> ClosedTree:
    """The closed tree of an MJCF file, an SDFormat file or a URDF of another tool (``output``, ``output_type``,
    ``lock``, ``actuate``, ``initial``: as :func:`read_mechanism_file`; ``length_unit``: the unit the file is written
    in, its lengths then brought to metres, :func:`screwkit.io.tree_units.in_metres`; a file read through
    :func:`read_mechanism_file` is scaled as its converted text is loaded instead, and its lengths are said in
    ``unit``, the unit its numbers are kept in)."""
    from dataclasses import replace

    from screwkit.io.closed_tree import ImportError_  # the readers: only for a file of another tool
    from screwkit.io.couplings import mimicked_joints  # (idem)
    from screwkit.io.locking import actuate_joints, drivable_joints, lock_joints, set_initial  # (idem)
    from screwkit.io.sdformat import SDFORMAT_SUFFIXES  # (idem)
    from screwkit.io.tree_units import in_metres  # (idem)

    tree = in_metres(_read_tree(Path(path), output, output_type), length_unit)
    if unit:
        tree = replace(tree, unit=unit)
    if Path(path).suffix.lower() not in (*MJCF_SUFFIXES, *SDFORMAT_SUFFIXES):  # a URDF read through Pinocchio
        tree = replace(tree, couplings=tree.couplings + mimicked_joints(Path(path).read_bytes(), str(path)))
    if not tree.closures:  # before its actuators are looked for: a tree has none to guess
        raise ImportError_(f"{tree.source}: no closure: nothing closes the tree into a parallel mechanism.")
    if tree.unactuated and not actuate:
        raise ImportError_(f"{tree.unactuated}; --actuate JOINT names the actuated joints (those that can be driven, "
                           f"revolute or prismatic: {drivable_joints(tree)}).")
    for name in (name for name in tree.motors if not tree.model.existJointName(name)):  # (MuJoCo refuses the file)
        raise ImportError_(f"{tree.source}: {tree.motor_label(name)} is not a joint of the tree.")
    tree = actuate_joints(lock_joints(set_initial(tree, initial), lock), actuate)
    if not tree.motors:
        raise ImportError_(f"{tree.source}: nothing to actuate: the file names no actuated joint and no 1-DoF joint "
                           "leaves the base on the way to a closure (--actuate JOINT names them).")
    return tree


def _read_tree(path: Path, output: str | None, output_type: str | None) -> ClosedTree:
    from screwkit.io.closed_tree import ImportError_  # the readers: only for a file of another tool
    from screwkit.io.drake import has_drake_constraints, read_drake  # (idem)
    from screwkit.io.gazebo import has_gazebo_joints, read_gazebo  # (idem)
    from screwkit.io.gepetto import read_gepetto, yaml_beside  # (idem)
    from screwkit.io.mjcf import read_mjcf  # (idem)
    from screwkit.io.onshape import has_closing_frames, read_onshape  # (idem)
    from screwkit.io.sdformat import SDFORMAT_SUFFIXES, read_sdformat  # (idem)

    if output_type not in (None, "point", "frame"):
        raise ValueError(f"Expected output type 'point' or 'frame', got {output_type!r}.")
    if path.suffix.lower() in MJCF_SUFFIXES:
        return read_mjcf(path, output=output, output_type=output_type)
    if path.suffix.lower() in SDFORMAT_SUFFIXES:
        return read_sdformat(path, output=output, output_type=output_type)
    yaml_path = yaml_beside(path)
    if yaml_path is not None:
        return read_gepetto(path, yaml_path, output=output, output_type=output_type)
    if has_closing_frames(path):
        return read_onshape(path, output=output, output_type=output_type)
    if has_gazebo_joints(path):
        return read_gazebo(path, output=output, output_type=output_type)
    if has_drake_constraints(path):
        return read_drake(path, output=output, output_type=output_type)
    raise ImportError_(f"{path}: no robot.yaml beside it, no closing_ frame pairs, no <gazebo><joint> and no "
                       "<drake:ball_constraint>: not a closed-loop tree screwkit reads.")


def read_mechanism_file(path: Path, *, output: str | None = None, output_type: str | None = None,
                        lock: tuple[str, ...] = (), actuate: tuple[str, ...] = (),
                        length_unit: str | None = None, initial=()) -> tuple[str, ImportReport]:
    """The URDF text (screwkit's convention) of an MJCF file or a URDF + robot.yaml, and the import report.

    ``output``: the frame (MJCF: a site or body) whose body is the platform; ``output_type``:
    ``"point"`` or ``"frame"`` (default: decided as :mod:`screwkit.io.star` says); ``lock``: joints held at their
    values in the file (:func:`screwkit.io.locking.lock_joints`: a serial stage before the parallel part);
    ``actuate``: the actuated joints, instead of the file's or the guessed ones
    (:func:`screwkit.io.locking.actuate_joints`); ``initial``: pairs of a joint name and its value (deg for a revolute
    joint, m for a prismatic one) that the assembly starts from and holds instead of the file's
    (:func:`screwkit.io.locking.set_initial`: a file written at a dead centre); ``length_unit``: the unit the file
    is written in, which the text keeps (its loader scales it) and the report's lengths are given in. A leg
    with loops inside it raises :class:`~screwkit.io.closed_tree.LegWithLoops` (:func:`graph_mechanism` analyses
    it).
    """
    from screwkit.io.star import convert_tree  # the conversion: only for a file of another tool

    return convert_tree(read_closed_tree(path, output=output, output_type=output_type, lock=lock, actuate=actuate,
                                         unit=length_unit, initial=initial))


def with_reference_configuration(text: str, mechanism) -> str:
    """A URDF text of screwkit's convention with its ``<reference_configuration>`` replaced by the
    mechanism's reference assembly (every tree joint, prismatic values in the file's length unit):
    a file whose loops were closed at loading (:attr:`~screwkit.model.mechanism.Mechanism.assembly_notes`)
    then closes as written. Comments are kept."""
    import xml.etree.ElementTree as ElementTree

    root = ElementTree.fromstring(tolerant_xml(text).decode(), parser=ElementTree.XMLParser(
        target=ElementTree.TreeBuilder(insert_comments=True)))
    for old in root.findall("reference_configuration"):
        root.remove(old)
    element = ElementTree.SubElement(root, "reference_configuration")
    factor = metres_per(mechanism.length_unit)
    for chain in mechanism.chains:
        for name, value, prismatic in zip(chain.joint_names, chain.reference_values, chain.prismatic):
            if name in chain.joint_names[:chain.geometry.n_tree_joints]:
                ElementTree.SubElement(element, "joint", name=name,
                                       value=repr(float(value / factor if prismatic else value)))
    ElementTree.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ElementTree.tostring(root, encoding="unicode") + "\n"
