"""Loading a mechanism: file -> description -> Pinocchio tree -> model -> reference assembly.

:func:`load` takes a bundled name (:func:`bundled_names`) or a file path and returns the
immutable :class:`~screwkit.model.Mechanism`. It is the one place where the model layer
(reading the file, :mod:`screwkit.model`) and the closure layer (the reference assembly,
:mod:`screwkit.closure`) meet; everything downstream takes the mechanism it returns. A file in screwkit's
convention that was loaded before (the same bytes, read the same way, by the same code) is read back from the
cache of loaded mechanisms (:mod:`screwkit.io.model_cache`) instead.
"""

from __future__ import annotations

import functools
import os
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np

from screwkit.closure.assembly import assemble, task_space
from screwkit.closure.canonical import canonical_geometry
from screwkit.closure.point_turns import DrivenIdleTurns
from screwkit.io import is_foreign, read_mechanism_file
from screwkit.io.drawn_loops import drawn_loops
from screwkit.io.model_cache import load_cached
from screwkit.model.builder import read_chains, read_platform
from screwkit.model.mechanism import Mechanism
from screwkit.model.pinocchio_bridge import build_model
from screwkit.model.urdf_description import UrdfDescription
from screwkit.model.urdf_reader import MAX_FILE_BYTES, parse_urdf, read_urdf

__all__ = ["load", "load_text", "converted_mechanism", "mechanism_from_description", "bundled_names", "bundled_path"]


@functools.cache
def bundled_names() -> tuple[str, ...]:
    """Names of the mechanisms shipped in :mod:`screwkit.robots`."""
    folder = resources.files("screwkit.robots")
    return tuple(sorted(item.name[: -len(".urdf")] for item in folder.iterdir() if item.name.endswith(".urdf")))


def bundled_graph_names() -> tuple[str, ...]:
    """Names of the closed-loop graphs shipped in :mod:`screwkit.robots` (MJCF files whose legs have loops inside
    them, opened by :func:`screwkit.io.graph_mechanism`: ``delta_rods_4``)."""
    folder = resources.files("screwkit.robots")
    return tuple(sorted(item.name[: -len(".xml")] for item in folder.iterdir() if item.name.endswith(".xml")))


def bundled_path(name: str) -> Path:
    """Path of a bundled URDF (or MJCF graph); a ValueError lists the bundled names if ``name`` is not one."""
    if name in bundled_graph_names():
        return Path(str(resources.files("screwkit.robots").joinpath(f"{name}.xml")))
    if name not in bundled_names():
        raise ValueError(f"Unknown bundled mechanism {name!r}; bundled are: "
                         f"{', '.join(bundled_names() + bundled_graph_names())}.")
    return Path(str(resources.files("screwkit.robots").joinpath(f"{name}.urdf")))


def _named_poses(description: UrdfDescription, mechanism: Mechanism) -> dict[str, np.ndarray]:
    """The reference assembly as ``home``, and the file's named poses, in task coordinates."""
    poses = {"home": mechanism.task_poses(mechanism.home_full_pose)}
    for name, values in description.named_poses.items():
        tag = f"<named_pose name='{name}'>"
        missing = [c for c in mechanism.task_coordinates if c not in values]
        unknown = [c for c in values if c not in mechanism.pose_coordinates]
        if missing or unknown:
            raise description.fail(tag, f"expected the task coordinates {', '.join(mechanism.task_coordinates)} "
                                        f"(m, rad), got {', '.join(values) or 'none'}.")
        if name == "home":
            raise description.fail(tag, "'home' is the reference assembly's pose; name this pose otherwise.")
        poses[name] = np.array([values[c] for c in mechanism.task_coordinates])
    return poses


def mechanism_from_description(description: UrdfDescription, *, limits: bool = True, model=None) -> Mechanism:
    """The mechanism of a file's description (see :func:`load`); ``model``: its Pinocchio model when it is
    already built (:func:`~screwkit.model.pinocchio_bridge.model_from_description`), else built from its text."""
    name = description.robot_name or Path(description.source).stem
    if model is None:
        model = build_model(description.text, lambda problem: description.fail(f"<robot name='{name}'>", problem))
    platform = read_platform(description, model, name)
    draft = Mechanism(
        name=name, path=description.source, description=description, pinocchio_model=model,
        is_planar=platform.is_planar, pose_coordinates=platform.pose_coordinates, base_link=platform.base_link,
        platform_link=platform.platform_link, platform_joint=platform.platform_joint,
        platform_joint_id=platform.platform_joint_id, platform_frame_placement=platform.platform_frame_placement,
        rotation_world_base=platform.rotation_world_base, translation_world_base=platform.translation_world_base,
        home_rotation=platform.home_rotation, home_translation=platform.home_translation,
        chains=read_chains(description, model, platform), dof=0, length_scale=1.0, named_poses={},
        length_unit=description.length_unit, output_point=np.zeros(3) if description.output == "point" else None)
    draft = drawn_loops(draft)  # axes and loop frames written rounded read as drawn (screwkit.io.drawn_loops)
    # every revolute drawn where the chain's geometry puts it, not where the file does (screwkit.closure.canonical)
    draft = replace(draft, named_poses={"home": draft.home_full_pose},  # the reference assembly, for assembling
                    chains=tuple(replace(chain, geometry=canonical_geometry(chain.geometry)) for chain in draft.chains))
    mechanism = task_space(assemble(draft, limits), getattr(description, "task_coordinates", None))
    return replace(mechanism, named_poses=_named_poses(description, mechanism))


def load(name_or_path: str | os.PathLike, *, length_unit: str | None = None,
         max_bytes: int = MAX_FILE_BYTES, limits: bool = True, output: str | None = None,
         output_type: str | None = None, lock: tuple[str, ...] = (), actuate: tuple[str, ...] = (),
         initial=()) -> Mechanism:
    """Load a mechanism by bundled name (see :func:`bundled_names`) or file path.

    Parameters
    ----------
    name_or_path : str or path
        A bundled name, the path of a URDF following ``docs/urdf-convention.md``, of an MJCF file
        (``.xml``, ``.mjcf``), of an SDFormat file (``.sdf``) or of a URDF tree with a Gepetto ``robot.yaml``
        beside it (all
        converted by :mod:`screwkit.io`; ``screwkit convert`` writes the conversion).
    length_unit : str, optional
        The unit the file's lengths are written in (``"mm"``, ...; see
        :data:`screwkit.common.units.LENGTH_UNITS`); overrides the file's ``<units length=...>``.
        Everything in screwkit is then in metres.
    max_bytes : int
        Largest file read (:data:`~screwkit.model.urdf_reader.MAX_FILE_BYTES`).
    limits : bool
        False: a reference assembly that puts a joint outside its limits (a CAD export rounded by a
        millimetre) is read all the same, and said in ``assembly_notes``; the limits still apply to the
        poses analysed unless those are asked without them too.
    output, output_type : str, optional
        For a file of another tool: the frame whose body is the platform and ``"point"`` or ``"frame"``
        (as :func:`screwkit.io.read_mechanism_file`); a file in screwkit's convention names its own platform,
        so they are refused there.
    lock : tuple of str
        For a file of another tool: joints held at their values in the file (``--lock``; a serial stage before the
        parallel part, :func:`screwkit.io.locking.lock_joints`).
    actuate : tuple of str
        For a file of another tool: the actuated joints, in this order, instead of those the file marks or that
        are guessed (``--actuate``; :func:`screwkit.io.locking.actuate_joints`).
    initial : sequence of (str, float) pairs
        For a file of another tool: joint values (deg for a revolute joint, m for a prismatic one) the reference
        assembly starts from and holds instead of the file's (``--initial``; a file written at a dead centre or with a
        joint outside its limits, :func:`screwkit.io.locking.set_initial`).

    Raises
    ------
    ValueError
        Unknown name, a missing file or a folder, or a file that breaks the convention (the
        message names the file, the element and the problem).
    TypeError
        ``name_or_path`` is neither a string nor a path.
    """
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise TypeError(f"Expected the name of a bundled mechanism ({', '.join(bundled_names())}) or a file path, "
                        f"got {type(name_or_path).__name__} {name_or_path!r}.")
    text = os.fspath(name_or_path)
    looks_like_path = (isinstance(name_or_path, os.PathLike) or text.endswith((".urdf", ".xml", ".mjcf", ".sdf"))
                       or os.sep in text or "/" in text)
    if not looks_like_path and (text in bundled_names() or not os.path.isdir(text)):
        path = bundled_path(text)
        if path.suffix == ".xml":  # a bundled graph: as its file (refused with LegWithLoops, for graph_mechanism)
            read_mechanism_file(path, output=output, output_type=output_type, lock=lock, actuate=actuate,
                                initial=initial)
    else:
        path = Path(text)
        if path.is_dir():
            raise ValueError(f"{text}: is a folder; expected a mechanism file (.urdf, .xml/.mjcf for MJCF, .sdf for "
                             "SDFormat) or "
                             f"a bundled name ({', '.join(bundled_names())}).")
        if not path.is_file():
            raise ValueError(f"{text}: no such file (bundled mechanisms are: {', '.join(bundled_names())}).")
        if is_foreign(path):  # MJCF, SDFormat, or a URDF of another tool (robot.yaml, closing_ frames, Gazebo joints)
            if path.stat().st_size > max_bytes:
                raise ValueError(f"{path}: {path.stat().st_size} bytes, more than the {max_bytes} read.")
            _, report, mechanism = converted_mechanism(path, output=output, output_type=output_type, lock=lock,
                                                       actuate=actuate, length_unit=length_unit, initial=initial,
                                                       limits=limits)
            return replace(mechanism, import_report=tuple(report.lines()))
    if output is not None or output_type is not None or lock or actuate or initial:
        raise ValueError(f"{path}: an output frame or type, locked, actuated or initial joints named apart from the "
                         "file apply to files of other tools (MJCF, SDFormat, URDF + robot.yaml, onshape-to-robot "
                         "URDFs); this file is in screwkit's convention (its output is its platform, its "
                         "<transmission>s name its actuators).")
    return load_cached(_content(path, max_bytes), ("file", str(path), length_unit, limits, max_bytes),
                       lambda: mechanism_from_description(read_urdf(path, length_unit=length_unit, max_bytes=max_bytes),
                                                          limits=limits))


def converted_mechanism(path: Path, *, output=None, output_type=None, lock=(), actuate=(), length_unit=None,
                        initial=(), limits: bool = True):
    """A file of another tool in screwkit's convention: its URDF text, the :class:`~screwkit.io.ImportReport` and
    the mechanism loaded from that text (:func:`load` and ``screwkit convert``). Where the output type is left to
    screwkit and the point where the legs meet is turned about by an actuator, the platform's frame is read
    instead, and the report says so."""
    converted, report = read_mechanism_file(path, output=output, output_type=output_type, lock=lock,
                                            actuate=actuate, length_unit=length_unit, initial=initial)
    try:
        mechanism = load_text(converted, str(path), length_unit=length_unit, limits=limits,
                              converted_from=report.file_format)
    except DrivenIdleTurns:
        if output_type is not None:
            raise
        # the point where the legs meet, taken by default: an actuator turns the platform about it, so the
        # frame instead (the one --output names, else the platform body's)
        body = report.platform_body
        converted, report = read_mechanism_file(path, output=output or body, output_type="frame", lock=lock,
                                                actuate=actuate, length_unit=length_unit, initial=initial)
        report.notes.append(f"output the frame {output or body!r}, not the point where the legs meet on body "
                            f"{body!r}: an actuator turns it about that point (--output-type point is "
                            "refused so)")
        mechanism = load_text(converted, str(path), length_unit=length_unit, limits=limits,
                              converted_from=report.file_format)
    return converted, report, mechanism


def _content(path: Path, max_bytes: int) -> bytes | None:
    """The file's bytes, for the cache's key; None when it is not to be read (too large, unreadable: the reader
    says why)."""
    try:
        return path.read_bytes() if path.stat().st_size <= max_bytes else None
    except OSError:
        return None


def load_text(text: str, source: str = "<string>", *, length_unit: str | None = None, limits: bool = True,
              converted_from: str = "") -> Mechanism:
    """Load a mechanism from the text of a URDF (``source`` names it in messages; ``limits``: as :func:`load`;
    ``converted_from``: the format of the file of another tool ``source`` is, whose conversion ``text`` is, so that
    messages name what that file has, :attr:`~screwkit.model.urdf_description.UrdfDescription.converted_from`)."""
    if not isinstance(text, (str, bytes, bytearray, memoryview)):
        hint = ": a file or a bundled name is opened by screwkit.load(path)" if isinstance(text, os.PathLike) else ""
        raise TypeError(f"load_text expects the text of a URDF (str or bytes), got {type(text).__name__}{hint}.")
    description = parse_urdf(text, source, length_unit=length_unit)
    if converted_from:
        description = replace(description, converted_from=converted_from)
    return mechanism_from_description(description, limits=limits)


@functools.lru_cache(maxsize=8)
def cached_mechanism(digest: str, text: str, source: str, limits: bool = True) -> Mechanism:
    """:func:`load_text`, remembered by the text's digest in this process and kept in the cache of loaded
    mechanisms (:mod:`screwkit.io.model_cache`), for tasks that rebuild a mechanism from its text."""
    return load_cached(text.encode(), ("text", source, limits), lambda: load_text(text, source, limits=limits))
