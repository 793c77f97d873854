"""Writing mechanisms in screwkit's URDF convention (``docs/urdf-convention.md``).

:class:`UrdfWriter` builds one :class:`~screwkit.model.urdf_document.UrdfDocument`: links with primitive
visuals, tree joints, URDF+ ``<loop>`` joints closing the chains, ``<transmission>`` elements marking the
actuators, the optional ``<reference_configuration>`` and ``<named_pose>`` elements. The document gives
the description a file of it would be read as (:meth:`UrdfWriter.description`, no text written) and its
text (:meth:`UrdfWriter.text`), where numbers are the shortest text that reads back as the same float.
:func:`planar_rrr_document` builds a whole planar n-RRR (the bundled ``planar_5rrr`` and the designs of
``screwkit design-search``), :func:`planar_rrr_urdf` writes it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from screwkit.model.urdf_description import UrdfDescription
from screwkit.model.urdf_document import (
    ExtensionRecord,
    JointRecord,
    LinkRecord,
    LoopRecord,
    TransmissionRecord,
    UrdfDocument,
    written_number,
    written_triple,
)

__all__ = ["UrdfWriter", "planar_rrr_document", "planar_rrr_urdf", "elbow"]


def _pose(pose) -> tuple:
    xyz, rpy = pose
    return written_triple(xyz), written_triple(rpy)


class UrdfWriter:
    """Builds one mechanism document, element by element (:class:`~screwkit.model.urdf_document.UrdfDocument`)."""

    def __init__(self, name: str, comment: str):
        self.name, self.comment = name, comment
        self.records: list = []

    def link(self, name: str, shape: tuple | None = None, xyz=(0, 0, 0), rpy=(0, 0, 0)) -> None:
        """A link; ``shape`` is ("box", size3), ("cylinder", radius, length) or ("sphere", radius)."""
        self.records.append(LinkRecord(name, shape, written_triple(xyz), written_triple(rpy)))

    def rod(self, name: str, length: float, radius: float = 0.015) -> None:
        """A link drawn as a cylinder from its origin along its x axis."""
        self.link(name, ("cylinder", radius, length), xyz=(length / 2, 0, 0), rpy=(0, math.pi / 2, 0))

    def joint(self, name, joint_type, parent, child, xyz=(0, 0, 0), rpy=(0, 0, 0), axis=None, limit=None) -> None:
        self.records.append(JointRecord(
            name, joint_type, parent, child, written_triple(xyz), written_triple(rpy),
            None if axis is None else written_triple(axis),
            None if limit is None else tuple(written_number(value) for value in limit)))

    def loop(
        self, name, loop_type, chain, predecessor, predecessor_pose, successor, successor_pose, axis=None,
        second_axis=None
    ) -> None:
        """A URDF+ loop joint; poses are (xyz, rpy) of the loop frame in each link frame."""
        self.records.append(LoopRecord(name, loop_type, chain, predecessor, _pose(predecessor_pose), successor,
                                       _pose(successor_pose), None if axis is None else written_triple(axis),
                                       None if second_axis is None else written_triple(second_axis)))

    def transmission(self, joint: str) -> None:
        self.records.append(TransmissionRecord(joint))

    def task_coordinates(self, names) -> None:
        """``<task_coordinates names="z roll pitch"/>``: the independent coordinates of a lower-mobility mechanism."""
        self.records.append(ExtensionRecord("task_coordinates", tuple(names)))

    def output(self, output_type: str) -> None:
        """``<output type="point"/>``: the platform frame's origin is a point output (``"frame"``: the default)."""
        self.records.append(ExtensionRecord("output", output_type))

    def named_pose(self, name: str, values: dict[str, float]) -> None:
        """A ``<named_pose>``: task coordinate values (m, rad) by coordinate name."""
        self.records.append(ExtensionRecord("named_pose", {k: written_number(v) for k, v in values.items()}, name))

    def reference_configuration(self, values: dict[str, float]) -> None:
        self.records.append(ExtensionRecord("reference_configuration",
                                            {k: written_number(v) for k, v in values.items()}))

    def document(self) -> UrdfDocument:
        """The document written so far."""
        return UrdfDocument(self.name, self.comment, tuple(self.records))

    def description(self, source: str = "<string>") -> UrdfDescription:
        """What reading :meth:`text` gives, without writing it (see :meth:`UrdfDocument.description`)."""
        return self.document().description(source)

    def text(self) -> str:
        return self.document().text()


def _angle(vector: NDArray) -> float:
    return math.atan2(vector[1], vector[0])


def elbow(base: NDArray, end: NDArray, proximal: float, distal: float, side: float = 1.0) -> NDArray:
    """Elbow c of an R-R-R leg, on the ``side`` (+1: left, the +u_perp side) of the line base -> end."""
    delta = end - base
    distance = np.linalg.norm(delta)
    along = (proximal**2 - distal**2 + distance**2) / (2 * distance)
    height = side * math.sqrt(proximal**2 - along**2)
    unit = delta / distance
    return base + along * unit + height * np.array([-unit[1], unit[0]])


def rrr_leg(writer: UrdfWriter, chain: str, base: NDArray, end: NDArray, platform_point: NDArray, proximal: float,
            distal: float, side: float) -> None:
    """One actuated planar R-R-R leg ``chain``: base joint at ``base`` (base frame), elbow on the ``side`` of
    the line to ``end`` (the leg's end in the base frame, reference assembly), loop onto the platform at
    ``platform_point`` (platform frame); links, joints, the loop and the transmission."""
    c = elbow(base, end, proximal, distal, side=side)
    first_angle, second_angle = _angle(c - base), _angle(end - c)
    writer.rod(f"{chain}_link_a", proximal)
    writer.rod(f"{chain}_link_l", distal)
    writer.joint(f"{chain}_joint_b", "continuous", "base_link", f"{chain}_link_a",
                 xyz=(base[0], base[1], 0), rpy=(0, 0, first_angle), axis=(0, 0, 1))  # fmt: skip
    writer.joint(f"{chain}_joint_c", "continuous", f"{chain}_link_a", f"{chain}_link_l",
                 xyz=(proximal, 0, 0), rpy=(0, 0, second_angle - first_angle), axis=(0, 0, 1))  # fmt: skip
    writer.loop(f"{chain}_joint_d", "revolute", chain,
                f"{chain}_link_l", ((distal, 0, 0), (0, 0, -second_angle)),
                "platform", ((platform_point[0], platform_point[1], 0), (0, 0, 0)), axis=(0, 0, 1))  # fmt: skip
    writer.transmission(f"{chain}_joint_b")


def planar_rrr_urdf(name: str, base: NDArray, platform: NDArray, proximal, distal, working_mode=1.0,
                    comment: str = "", named_poses: dict[str, tuple[float, ...]] | None = None,
                    output: str = "frame") -> str:
    """The URDF text of :func:`planar_rrr_document`."""
    return planar_rrr_document(name, base, platform, proximal, distal, working_mode, comment, named_poses,
                               output).text()


def planar_rrr_document(name: str, base: NDArray, platform: NDArray, proximal, distal, working_mode=1.0,
                        comment: str = "", named_poses: dict[str, tuple[float, ...]] | None = None,
                        output: str = "frame") -> UrdfDocument:
    """A planar n-RRR: base joints ``base`` (n, 2), platform joints ``platform`` (n, 2) in the
    platform frame, arm lengths (scalars or (n,)), elbows on the ``working_mode`` side (+1: +u_perp)
    in the reference assembly (platform at x = y = phi = 0). Base joints are actuated."""
    base, platform = np.asarray(base, dtype=float), np.asarray(platform, dtype=float)
    count = base.shape[0]
    proximal = np.broadcast_to(np.asarray(proximal, dtype=float), (count,))
    distal = np.broadcast_to(np.asarray(distal, dtype=float), (count,))
    sides = np.broadcast_to(np.asarray(working_mode, dtype=float), (count,))
    reach = float(np.max(np.linalg.norm(base, axis=-1)))
    writer = UrdfWriter(name, comment)
    writer.link("base_link", ("cylinder", round(reach + 0.05, 6), 0.01), xyz=(0, 0, -0.02))
    writer.link("platform", ("cylinder", round(float(np.max(np.linalg.norm(platform, axis=-1))) + 0.02, 6), 0.02))
    writer.joint("platform_joint", "planar", "base_link", "platform", axis=(0, 0, 1))
    for i in range(count):
        rrr_leg(writer, f"chain_{i + 1}", base[i], platform[i], platform[i], float(proximal[i]), float(distal[i]),
                float(sides[i]))
    if output != "frame":
        writer.output(output)
    for pose_name, values in (named_poses or {}).items():
        writer.named_pose(pose_name, dict(zip(("x", "y", "phi") if output == "frame" else ("x", "y"), values)))
    return writer.document()

