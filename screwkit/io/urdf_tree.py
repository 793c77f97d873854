"""Pinocchio's reading of the tree of a URDF of another tool, and what its parser says of a file it refuses, in one
line.

Pinocchio reads a URDF through urdfdom, which writes what is wrong with a file on the process's standard error (two
lines each: ``Error:   Malformed axis element for joint [j3]: Unable to parse component [1zzz] to a double ...`` and
where in urdfdom's sources), and then raises that the file "does not contain a valid URDF model". Its standard error
is held while the tree is read: a file it reads gives back what urdfdom wrote (its warnings), a file it refuses is
refused in one line with urdfdom's first complaint, which names the element.
"""

from __future__ import annotations

import math
import os
import re
import sys
import tempfile
from pathlib import Path
from xml.etree import ElementTree

from screwkit.common.xml_text import tolerant_xml
from screwkit.io.closed_tree import ImportError_
from screwkit.model.urdf_element_reader import LARGEST_COORDINATE

__all__ = ["urdf_model"]


def urdf_model(urdf: Path):
    """Pinocchio's model of the URDF ``urdf``'s tree; an :class:`~screwkit.io.closed_tree.ImportError_` in one line
    naming the file and urdfdom's complaint if it cannot read it. A joint limit's negative effort or velocity (no
    limit, :func:`_unlimited_copy`) is read as no limit."""
    _refuse_xacro(urdf)
    _refuse_malformed(urdf)
    try:
        return _pinocchio_model(urdf)
    except ImportError_ as error:
        unlimited = _unlimited_copy(urdf) if "effort" in str(error) or "velocity" in str(error) else None
        if unlimited is None:
            raise
    with unlimited:  # (its name said as the file's)
        try:
            return _pinocchio_model(Path(unlimited.name))
        except ImportError_ as again:
            raise ImportError_(str(again).replace(unlimited.name, str(urdf))) from None


def _pinocchio_model(urdf: Path):
    """:func:`urdf_model` but for a negative effort or velocity."""
    import pinocchio as pin  # Pinocchio: imported where a file of another tool is read

    sys.stderr.flush()
    try:
        kept = os.dup(2)
    except OSError:  # no standard error to hold (closed: a daemon, 2>&-): read as it is
        kept = None
    if kept is None:
        try:
            return pin.buildModelFromUrdf(str(urdf))
        except (RuntimeError, ValueError) as error:
            raise ImportError_(f"{urdf}: Pinocchio cannot read the tree: {error}") from None
    with tempfile.TemporaryFile() as said:
        os.dup2(said.fileno(), 2)
        try:
            model, error = pin.buildModelFromUrdf(str(urdf)), None
        except (RuntimeError, ValueError) as raised:
            model, error = None, raised
        finally:
            os.dup2(kept, 2)
            os.close(kept)
        said.seek(0)
        text = said.read()
    if error is None:
        if text:  # urdfdom's warnings on a file it reads, as they were
            os.write(2, text)
        return model
    complaints = [line.strip().removeprefix("Error:").strip() for line in text.decode(errors="replace").splitlines()
                  if line.strip().startswith("Error:")]
    raise ImportError_(f"{urdf}: Pinocchio cannot read the tree: "
                       + (f"{complaints[0]}." if complaints else f"{error}.").replace("..", "."))


def _unlimited_copy(urdf: Path):
    """A temporary copy of ``urdf`` whose joint limits' negative ``effort`` and ``velocity`` (Gazebo's and
    SDFormat's -1: no limit; Pinocchio refuses them, "min_effort greater than max_effort") are written as 1e30, none
    of which the indices use; None if it has none."""
    from xml.etree import ElementTree

    try:
        tree = ElementTree.parse(urdf)
    except (OSError, ElementTree.ParseError):
        return None
    changed = False
    for limit in tree.getroot().iter("limit"):
        for name in ("effort", "velocity"):
            try:
                negative = float(limit.get(name, "0")) < 0.0
            except ValueError:
                continue
            if negative:
                limit.set(name, "1e30")
                changed = True
    if not changed:
        return None
    copy = tempfile.NamedTemporaryFile("wb", suffix=".urdf", delete=True)
    tree.write(copy, encoding="utf-8", xml_declaration=True)
    copy.flush()
    return copy


def _refuse_malformed(urdf: Path) -> None:
    """What urdfdom's parser, which Pinocchio calls, crashes on or says without naming the element, refused in one
    line naming it: a link with two parent joints, or joints that lead back to a link above them (the parser ends the
    process: a segmentation fault; a loop is closed otherwise in a URDF of another tool, by a robot.yaml's closing
    frames or a Gazebo plugin); an ``<origin>`` or ``<axis>`` without three finite numbers (a joint's, of magnitude
    at most ``LARGEST_COORDINATE``); a revolute or prismatic joint's ``<limit>`` whose lower bound is above its upper
    one (read as no limit before; urdfdom reads no bounds of other joints)."""
    try:
        root = ElementTree.fromstring(tolerant_xml(Path(urdf).read_bytes()))
    except (OSError, ElementTree.ParseError, ValueError):
        return  # (the reader says why)
    for element in [*root.findall("joint"), *root.findall("link")]:
        largest = LARGEST_COORDINATE if element.tag == "joint" else math.inf  # (a link's visuals are not read)
        for part in (part for part in element.iter() if part.tag in ("origin", "axis")):
            for attribute in (name for name in ("xyz", "rpy") if part.get(name) is not None):
                if not _three_numbers(part.get(attribute), largest):
                    raise ImportError_(f"{urdf}: <{element.tag} name='{element.get('name')}'>: <{part.tag} "
                                       f"{attribute}='{part.get(attribute)}'>: expected three finite numbers"
                                       + (f", each at most {largest:g} in magnitude." if largest < math.inf else "."))
        limited = element.tag == "joint" and element.get("type") in ("revolute", "prismatic")  # (others: not read)
        limit = element.find("limit") if limited else None
        bounds = [_number(limit.get(name)) for name in ("lower", "upper")] if limit is not None else []
        if len(bounds) == 2 and None not in bounds and bounds[0] > bounds[1]:
            raise ImportError_(f"{urdf}: <joint name='{element.get('name')}'>: <limit lower='{limit.get('lower')}' "
                               f"upper='{limit.get('upper')}'>: the lower bound is above the upper one.")
    parents: dict[str, tuple[str, str]] = {}  # each link's parent link and joint
    for joint in root.findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            continue  # (urdfdom says what is missing)
        link, name = child.get("link", ""), joint.get("name", "?")
        if link in parents:
            raise ImportError_(f"{urdf}: <link name='{link}'> has two parent joints, {parents[link][1]!r} and "
                               f"{name!r}: a URDF's joints form a tree (a loop is closed otherwise, e.g. by a "
                               "robot.yaml's closing frames).")
        parents[link] = (parent.get("link", ""), name)
    for start in parents:
        seen, link = [start], parents[start][0]
        while link in parents and link not in seen:
            seen.append(link)
            link = parents[link][0]
        if link == start:
            joints = " -> ".join(parents[name][1] for name in reversed(seen))
            raise ImportError_(f"{urdf}: joints {joints} lead from <link name='{start}'> back to itself: a URDF's "
                               "joints form a tree.")


def _number(text: str | None) -> float | None:
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def _three_numbers(text: str, largest: float) -> bool:
    """Three finite numbers, each at most ``largest`` in magnitude (a joint's, as in screwkit's own URDF:
    :data:`~screwkit.model.urdf_element_reader.LARGEST_COORDINATE`; ``1e308`` overflows once squared)."""
    values = [_number(word) for word in text.split()]
    return len(values) == 3 and all(value is not None and math.isfinite(value) and abs(value) <= largest
                                    for value in values)


def _refuse_xacro(urdf: Path) -> None:
    """A xacro file (ROS's macro language for URDF) given as a URDF is refused in one line: its macros, properties and
    ``${...}`` expressions are not URDF, and what Pinocchio would make of it is another robot or a complaint about a
    number that is an expression."""
    try:
        text = re.sub(r"<!--.*?-->", "", Path(urdf).read_text(errors="replace"), flags=re.DOTALL)  # (not comments)
    except OSError:
        return  # (the reader says why)
    found = next((mark for mark in ("<xacro:", "${") if mark in text), None)  # (not the namespace alone, which
    # xacro's output keeps on <robot>, nor a $(find ...) in a mesh's file name, which is not read)
    if found is not None:
        raise ImportError_(f"{urdf}: a xacro file (it holds {found!r}), not a URDF: expand it first, e.g. "
                           f"`xacro {Path(urdf).name} -o robot.urdf` (ROS's xacro), and read robot.urdf.")
