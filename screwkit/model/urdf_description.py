"""What the safe XML pass reads from a URDF file, as frozen records: :class:`UrdfDescription` and the
elements it holds (:class:`JointElement`, :class:`LoopElement`, :class:`TransmissionElement`, their
:class:`Origin`), with the joint types of the convention and :func:`file_error`, the form of every error.

They are read by :func:`screwkit.model.urdf_reader.parse_urdf`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.common.rotations import rotation_from_rpy

TREE_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
"""Joint types of the URDF specification."""
PLATFORM_JOINT_TYPES = ("floating", "planar")
"""Types of the joint that attaches the platform to the base."""
AXIS_JOINT_TYPES = ("revolute", "continuous", "prismatic", "planar")
"""Joint types whose ``<axis>`` means something (a zero axis is refused on them only)."""


@dataclass(frozen=True)
class Origin:
    """A URDF ``<origin>``: translation ``xyz`` (m) and fixed-axis ``rpy`` angles (rad)."""

    xyz: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    rpy: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))

    @property
    def rotation(self) -> NDArray[np.float64]:
        """Rotation matrix ``Rz(yaw) Ry(pitch) Rx(roll)``."""
        return rotation_from_rpy(self.rpy)

    @property
    def translation(self) -> NDArray[np.float64]:
        """Translation vector."""
        return np.asarray(self.xyz, dtype=float)


@dataclass(frozen=True)
class JointElement:
    """A tree ``<joint>`` as written in the file."""

    name: str
    type: str
    parent: str
    child: str
    origin: Origin
    axis: NDArray[np.float64]
    limits: tuple[float, float] = (-np.inf, np.inf)
    """Position limits (rad or m): ``<limit lower upper>`` of revolute and prismatic joints, else unlimited."""
    drive_limits: tuple[float, float] = (np.inf, np.inf)
    """``<limit effort velocity>`` (N or N m, m/s or rad/s), as Pinocchio reads them; unlimited when absent."""


@dataclass(frozen=True)
class LoopElement:
    """A URDF+ ``<loop>`` joint closing a chain.

    The loop-joint frame is ``predecessor_origin`` in the predecessor link frame and
    ``successor_origin`` in the successor link frame; at the reference configuration the two
    frames coincide up to the loop joint's own motion. ``axes`` are unit vectors in the loop
    frame (``axis`` and, for a universal joint, ``axis2``).
    """

    name: str
    type: str
    predecessor: str
    predecessor_origin: Origin
    successor: str
    successor_origin: Origin
    axes: tuple[NDArray[np.float64], ...]
    chain: str


@dataclass(frozen=True)
class TransmissionElement:
    """A ``<transmission>`` and the joints it drives."""

    name: str
    joints: tuple[str, ...]


@dataclass(frozen=True)
class UrdfDescription:
    """What the safe XML pass read from one URDF document.

    Attributes
    ----------
    source : str
        File path (or ``"<string>"``) used in error messages.
    robot_name : str
    links : tuple of str
    joints : dict of str to JointElement
        Tree joints by name.
    loops : tuple of LoopElement
        In file order (chains are then ordered by name, :func:`screwkit.model.builder.chain_order`).
    transmissions : tuple of TransmissionElement
    reference_configuration : dict of str to float
        Joint values of the reference assembly given in ``<reference_configuration>``.
    named_poses : dict of str to dict of str to float
        ``<named_pose name="..." x="..." ...>``: task coordinate values (m, rad) by pose name.
    length_unit : str
        The unit the file was written in (its lengths are converted to metres here).
    task_coordinates : tuple of str or None
        ``<task_coordinates names="z roll pitch"/>``: the independent coordinates a pose is
        given in, for a mechanism of lower mobility (None: inferred).
    output : str
        ``"frame"`` (the platform frame, the default) or ``"point"`` (``<output type="point"/>``:
        the platform frame's origin is a point output, rotations about it are idle).
    read_text : str
        The document as read (in metres), checked to contain no DTD; empty for a description built
        from a :class:`~screwkit.model.urdf_document.UrdfDocument`.
    document : UrdfDocument or None
        The records a writer built this description from (:meth:`UrdfDocument.description`), which
        write :attr:`text` when it is asked for; None for a description read from a text.
    converted_from : str
        The format of the file of another tool this text was converted from (``"MJCF"``, ...; empty for a
        file in screwkit's convention): its errors then name what the user wrote (a joint, a chain, an option),
        not the elements of the text converted in memory (:meth:`fail`).
    """

    source: str
    robot_name: str
    links: tuple[str, ...]
    joints: dict[str, JointElement]
    loops: tuple[LoopElement, ...]
    transmissions: tuple[TransmissionElement, ...]
    reference_configuration: dict[str, float]
    named_poses: dict[str, dict[str, float]] = field(default_factory=dict)
    length_unit: str = "m"
    task_coordinates: tuple[str, ...] | None = None
    output: str = "frame"
    read_text: str = field(default="", repr=False)
    document: Any = field(default=None, repr=False, compare=False)
    converted_from: str = ""

    @cached_property
    def text(self) -> str:
        """The URDF text in metres (for :func:`pinocchio.buildModelFromXML` and the viewer): the text read, or
        the one the document writes, on first use."""
        return self.document.text() if self.document is not None else self.read_text

    def fail(self, element: str, problem: str) -> ValueError:
        """A one-line error naming this file, an element and a problem (for a file of another tool, what the element
        of the converted text stands for in it: :func:`as_written`)."""
        return file_error(self.source, as_written(element) if self.converted_from else element, problem)


CONVERTED_ELEMENTS = (
    (re.compile(r"<robot name='[^']*'>"), lambda match: ""),
    (re.compile(r"<output type='point'>"), lambda match: ""),  # (each message says "the output point")
    (re.compile(r"<loop name='(.*)_loop'>"), lambda match: f"chain '{match.group(1)}'"),
    (re.compile(r"<loop name='(.*)'>"), lambda match: f"closure '{match.group(1)}'"),
    (re.compile(r"<transmission name='(.*)_transmission'>"), lambda match: f"actuated joint '{match.group(1)}'"),
)
"""The elements of a text converted from a file of another tool (:mod:`screwkit.io.star` writes them) and what they
stand for in that file; any other is named as it is (a ``<joint>``, and a URDF source's ``<task_coordinates>``, are
the file's own)."""


def initial_remedy(file_format: str) -> str:
    """How a file of another tool drawn at a dead centre is read away from it: ``--initial`` (and, for MJCF, a
    keyframe named 'home'), for the refusals of :mod:`screwkit.io.idle_joints` and :mod:`screwkit.closure.assembly`."""
    return ("give joint values away from it: --initial JOINT VALUE (an actuated joint away from its dead centre, held "
            "there while the loops close)" + (", or a keyframe named 'home'" if file_format == "MJCF" else ""))


def as_written(element: str) -> str:
    """``element`` of a converted text named as the file of another tool has it (:data:`CONVERTED_ELEMENTS`)."""
    for pattern, named in CONVERTED_ELEMENTS:
        match = pattern.fullmatch(element)
        if match:
            return named(match)
    return element


def file_error(source: str, element: str, problem: str) -> ValueError:
    """``ValueError("<file>: <element>: <problem>")``, the form of every URDF error (``<file>: <problem>`` when no
    element is named)."""
    return ValueError(f"{source}: {element}: {problem}" if element else f"{source}: {problem}")
