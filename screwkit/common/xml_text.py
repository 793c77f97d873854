"""XML text as the readers of other tools take it.

MuJoCo, Gazebo's libsdformat and Drake parse with tinyxml2, which is lenient where Python's parser (expat) refuses a
file as not well-formed. :func:`tolerant_xml` writes what they take and Python does not as Python reads it, changing
nothing a reader looks at:

* an XML declaration written ``<? xml ...?>`` (a space after ``<?``: a published Gazebo Stewart platform's first line)
  or after blank space: written ``<?xml`` at the start (the declaration says nothing of the robot);
* ``--`` inside a comment (an ASCII drawing of the mechanism: a published Drake four-bar), or a comment ending in
  ``-``: each ``--`` written ``- -`` (a comment is not read);
* a namespace prefix used and never declared (``<drake:ball_constraint>`` in a file without ``xmlns:drake``, which
  Drake reads): declared on the root element as ``urn:screwkit:undeclared:PREFIX``, so that the element is read with
  its prefix's own namespace as a declared one would be.
"""

from __future__ import annotations

import re

__all__ = ["tolerant_xml", "tolerant_declaration", "UNDECLARED"]

DECLARATION = re.compile(rb"\A\s*<\?\s*xml(?=\s|\?)")
"""An XML declaration, with the blank space tinyxml2 allows before it and after its ``<?``."""
COMMENT = re.compile(rb"<!--(.*?)-->", re.S)
PREFIXED = re.compile(rb"<\s*/?\s*([A-Za-z_][\w.-]*):[A-Za-z_]|\s([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*\s*=")
DECLARED = re.compile(rb"xmlns:([A-Za-z_][\w.-]*)\s*=")
ROOT = re.compile(rb"<([A-Za-z_][\w:.-]*)")
UNDECLARED = "urn:screwkit:undeclared:"
"""The namespace an undeclared prefix is given (followed by the prefix)."""


def tolerant_declaration(data: bytes) -> bytes:
    """``data`` with its XML declaration, if any, starting the text as ``<?xml``."""
    match = DECLARATION.match(data)
    return b"<?xml" + data[match.end():] if match else data


def _comment(match: re.Match) -> bytes:
    body = re.sub(rb"-(?=-)", b"- ", match.group(1))
    return b"<!--" + (body + b" " if body.endswith(b"-") else body) + b"-->"


def tolerant_xml(data: bytes | str) -> bytes:
    """``data`` (bytes, or text) as Python's parser reads what tinyxml2 takes (the module says what changes)."""
    data = tolerant_declaration(data.encode() if isinstance(data, str) else data)
    if b"<!--" in data:
        data = COMMENT.sub(_comment, data)
    if b":" not in data:
        return data
    visible = COMMENT.sub(b"", data)  # prefixes in comments are not read
    used = {m.group(1) or m.group(2) for m in PREFIXED.finditer(visible)} - {b"xml", b"xmlns"}
    missing = sorted(used - set(DECLARED.findall(visible)))
    if not missing:
        return data
    try:
        start = _root_start(data)
    except (ValueError, AttributeError):  # no root element: the parser says what is wrong
        return data
    declarations = b"".join(b' xmlns:' + prefix + b'="' + UNDECLARED.encode() + prefix + b'"' for prefix in missing)
    return data[:start] + declarations + data[start:]


def _root_start(data: bytes) -> int:
    """Where the root element's name ends (after the declaration, comments, processing instructions and a
    doctype)."""
    position = 0
    while True:
        opening = data.index(b"<", position)
        if data.startswith(b"<!--", opening):
            position = data.index(b"-->", opening) + 3
        elif data.startswith(b"<?", opening):
            position = data.index(b"?>", opening) + 2
        elif data.startswith(b"<!", opening):
            position = data.index(b">", opening) + 1
        else:
            return ROOT.match(data, opening).end()
