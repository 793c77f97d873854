"""XML text as the readers of other tools take it.

MuJoCo and Gazebo's libsdformat parse with tinyxml2, which takes an XML declaration written ``<? xml ...?>`` (a space
after ``<?``: a published Gazebo Stewart platform's first line) or after blank space; Python's parser refuses both as
not well-formed. The declaration says nothing of the robot (version and encoding), so :func:`tolerant_declaration`
writes it as Python reads it and the rest of the file is read as written.
"""

from __future__ import annotations

import re

__all__ = ["tolerant_declaration"]

DECLARATION = re.compile(rb"\A\s*<\?\s*xml(?=\s|\?)")
"""An XML declaration, with the blank space tinyxml2 allows before it and after its ``<?``."""


def tolerant_declaration(data: bytes) -> bytes:
    """``data`` with its XML declaration, if any, starting the text as ``<?xml``."""
    match = DECLARATION.match(data)
    return b"<?xml" + data[match.end():] if match else data
