"""A safe XML pass over a URDF file for what Pinocchio and yourdfpy do not read.

Pinocchio builds the kinematic tree; this module reads the rest of screwkit's URDF
convention (see ``docs/urdf-convention.md``):

* ``<loop>`` elements (URDF+ loop joints) that close each leg onto the platform,
* ``<transmission>`` elements that mark the actuated joints,
* the optional ``<reference_configuration>`` element (screwkit extension),
* the optional ``<named_pose>`` elements and ``<units length="mm"/>`` (screwkit extensions),
* the tree ``<joint>`` elements (names, types, links, origins, axes, limits; a ``<mimic>`` is refused) and the tree's
  shape: one root link, one parent per link, no cycle.

Lengths: a file written in another unit (``<units length="mm"/>`` or the ``length_unit``
argument) is converted to metres here, in the description *and* in the text handed to
Pinocchio, so everything downstream is in metres.

Size: files above :data:`MAX_FILE_BYTES` are refused before parsing, and trees of more than
:data:`MAX_LINKS` links or deeper than :data:`MAX_TREE_DEPTH` joints before Pinocchio sees them
(its URDF parser takes time growing with the square of the number of links, and recurses once
per level of the tree, so that a very deep tree overflows the stack and crashes the process);
reading is linear in the file size.

Security: a URDF is data from elsewhere. Any document type declaration (``<!DOCTYPE``)
or entity declaration (``<!ENTITY``) is refused *before* parsing, so entity bombs
("billion laughs") and external entities are never expanded or fetched. Without a DTD,
the parser knows no entities besides the five predefined ones.

Every error is a one-line :class:`ValueError` naming the file, the element and the problem.

This module checks and converts the document; the records it returns are in
:mod:`screwkit.model.urdf_description`, the element-by-element reading is in
:mod:`screwkit.model.urdf_element_reader`, and their public names are importable from here too.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ElementTree
from pathlib import Path

from screwkit.common.units import LENGTH_UNITS, metres_per
from screwkit.common.xml_text import tolerant_xml
from screwkit.model.urdf_description import AXIS_JOINT_TYPES as AXIS_JOINT_TYPES
from screwkit.model.urdf_description import PLATFORM_JOINT_TYPES as PLATFORM_JOINT_TYPES
from screwkit.model.urdf_description import TREE_JOINT_TYPES as TREE_JOINT_TYPES
from screwkit.model.urdf_description import JointElement as JointElement
from screwkit.model.urdf_description import LoopElement as LoopElement
from screwkit.model.urdf_description import Origin as Origin
from screwkit.model.urdf_description import TransmissionElement as TransmissionElement
from screwkit.model.urdf_description import UrdfDescription, file_error
from screwkit.model.urdf_element_reader import LARGEST_COORDINATE as LARGEST_COORDINATE
from screwkit.model.urdf_element_reader import MAX_LINKS as MAX_LINKS
from screwkit.model.urdf_element_reader import MAX_TREE_DEPTH as MAX_TREE_DEPTH
from screwkit.model.urdf_element_reader import ElementReader

_DECLARATION = re.compile(rb"<!\s*(DOCTYPE|ENTITY)", re.IGNORECASE)
MAX_FILE_BYTES = 16 * 2**20
"""Largest mechanism file read (16 MiB); larger files are refused before parsing."""


def read_urdf(path: str | os.PathLike, *, length_unit: str | None = None,
              max_bytes: int = MAX_FILE_BYTES) -> UrdfDescription:
    """Read and check a URDF file (see :func:`parse_urdf`); files above ``max_bytes`` are refused unread."""
    source = str(path)
    try:
        size = os.path.getsize(path)
        if size > max_bytes:
            raise ValueError(f"{source}: the file has {size:,} bytes, more than the {max_bytes:,} bytes screwkit reads "
                             "(screwkit.model.urdf_reader.MAX_FILE_BYTES).")
        data = Path(path).read_bytes()
    except OSError as error:
        raise ValueError(f"{source}: cannot read the file: {error.strerror or error}.") from None
    return parse_urdf(data, source, length_unit=length_unit, max_bytes=max_bytes)


def parse_urdf(document: str | bytes, source: str = "<string>", *, length_unit: str | None = None,
               max_bytes: int = MAX_FILE_BYTES) -> UrdfDescription:
    """Parse a URDF document, refusing DTDs and entity declarations before parsing.

    Parameters
    ----------
    document : str or bytes
        The XML text.
    source : str
        Name used in error messages (the file path).
    length_unit : str, optional
        The unit the document's lengths are written in (one of
        :data:`screwkit.common.units.LENGTH_UNITS`); overrides the file's ``<units length=...>``;
        default metres.
    max_bytes : int
        Largest document accepted.

    Raises
    ------
    ValueError
        On a DTD or entity declaration, malformed XML, or an element that breaks the
        convention (unknown link, unsupported loop type, missing axis, a cycle in the tree, ...).
    """
    data = document.encode("utf-8") if isinstance(document, str) else bytes(document)
    if len(data) > max_bytes:
        raise ValueError(f"{source}: the document has {len(data):,} bytes, more than the {max_bytes:,} bytes "
                         "screwkit reads (screwkit.model.urdf_reader.MAX_FILE_BYTES).")
    declaration = _DECLARATION.search(data)
    if declaration is not None:
        line = data.count(b"\n", 0, declaration.start()) + 1
        raise ValueError(
            f"{source}: <!{declaration.group(1).decode().upper()}> at line {line}: document type and entity "
            "declarations are refused (entity expansion is unsafe and URDF does not need them)."
        )
    try:
        root = ElementTree.fromstring(tolerant_xml(data))
    except ElementTree.ParseError as error:
        raise ValueError(f"{source}: malformed XML: {error}.") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ValueError(f"{source}: the file is not UTF-8 text: {error}.") from None
    if root.tag != "robot":
        raise file_error(source, f"<{root.tag}>", "expected the root element <robot>.")
    unit = _length_unit(root, source, length_unit)
    if unit != "m":
        scale_lengths(root, metres_per(unit))
        for element in root.findall("units"):
            element.set("length", "m")  # the text handed on is in metres
        text = '<?xml version="1.0"?>\n' + ElementTree.tostring(root, encoding="unicode") + "\n"
    return ElementReader(source).read(root, text, unit)


def _length_unit(root: ElementTree.Element, source: str, given: str | None) -> str:
    """The document's length unit: ``given``, else ``<units length=...>``, else metres (repeated ``<units>`` must
    agree)."""
    declared = None
    for element in root.findall("units"):
        length = (element.get("length") or "").strip()
        if length not in LENGTH_UNITS:
            raise file_error(source, f"<units length='{length}'>",
                             f"unknown length unit; expected one of {', '.join(LENGTH_UNITS)}.")
        if declared is not None and length != declared:
            raise file_error(source, f"<units length='{length}'>",
                             f"a second <units> element disagrees with <units length='{declared}'> before it; "
                             "keep one.")
        declared = length
    unit = given if given is not None else (declared or "m")
    if unit not in LENGTH_UNITS:
        raise ValueError(f"Unknown length unit {unit!r}; expected one of {', '.join(LENGTH_UNITS)}.")
    return unit


def _scale_attribute(element: ElementTree.Element | None, attribute: str, factor: float) -> None:
    if element is None or element.get(attribute) is None:
        return
    words = element.get(attribute).split()
    try:
        element.set(attribute, " ".join(repr(float(word) * factor) for word in words))
    except ValueError:
        pass  # left as written: the reader reports it with the element's name


def scale_lengths(root: ElementTree.Element, factor: float) -> None:
    """Multiply every length of a URDF tree by ``factor``, in place.

    Lengths are: ``xyz`` of every ``<origin>``; the limits of prismatic joints; primitive
    sizes (box size, cylinder radius and length, sphere radius) and mesh scales of visual and
    collision geometry; the position values of prismatic joints in ``<reference_configuration>``
    and the x, y, z values of ``<named_pose>``. Angles, masses and inertias are left alone
    (inertias are not used by screwkit).
    """
    for origin in root.iter("origin"):
        _scale_attribute(origin, "xyz", factor)
    prismatic = {joint.get("name") for joint in root.findall("joint") if joint.get("type") == "prismatic"}
    prismatic |= {loop.get("name") for loop in root.findall("loop") if loop.get("type") == "prismatic"}
    for joint in root.findall("joint"):
        if joint.get("name") in prismatic:
            for limit in joint.findall("limit"):
                _scale_attribute(limit, "lower", factor)
                _scale_attribute(limit, "upper", factor)
    for geometry in root.iter("geometry"):
        _scale_attribute(geometry.find("box"), "size", factor)
        _scale_attribute(geometry.find("cylinder"), "radius", factor)
        _scale_attribute(geometry.find("cylinder"), "length", factor)
        _scale_attribute(geometry.find("sphere"), "radius", factor)
        mesh = geometry.find("mesh")
        if mesh is not None:
            if mesh.get("scale") is None:
                mesh.set("scale", "1 1 1")
            _scale_attribute(mesh, "scale", factor)
    for configuration in root.findall("reference_configuration"):
        for joint in configuration.findall("joint"):
            if joint.get("name") in prismatic:
                _scale_attribute(joint, "value", factor)
    for pose in root.findall("named_pose"):
        for coordinate in ("x", "y", "z"):
            _scale_attribute(pose, coordinate, factor)
