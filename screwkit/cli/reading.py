"""How MECHANISM's file is read: the record of the reading options and the options of files of other tools."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

import click

from screwkit.closure.assembly import LIMITS_IGNORED

__all__ = ["Reading", "reading_record", "lock_option", "actuate_option", "initial_option", "output_frame_option",
           "output_type_option", "grouped_notes", "LOCK_HELP", "ACTUATE_HELP", "INITIAL_HELP", "FILE_OPTIONS"]


@dataclass(frozen=True)
class Reading:
    """How MECHANISM's file is read: its length unit, and for a file of another tool the frame whose body is the
    platform and whether the output is a point or that frame (``--length-unit``, ``--output``, ``--output-type``),
    the joints held at their values in the file (``--lock``), the actuated joints named instead of the file's
    (``--actuate``) and the joint values the assembly starts from instead of the file's (``--initial``)."""

    length_unit: str | None = None
    output: str | None = None
    output_type: str | None = None
    lock: tuple[str, ...] = ()
    actuate: tuple[str, ...] = ()
    initial: tuple[tuple[str, float], ...] = ()


def reading_record(length_unit: str | None = None, output_frame: str | None = None, output_type: str | None = None,
                   lock=(), actuate=(), initial=()) -> Reading:
    return Reading(length_unit, output_frame, output_type, tuple(lock or ()), tuple(actuate or ()),
                   tuple(tuple(pair) for pair in initial or ()))


LOCK_HELP = ("For a file of another tool: hold this joint at its value in the file (repeatable): a serial stage "
             "before the parallel part, such as a turntable every leg stands on; a passive joint inside a loop that "
             "the file writes open is held where the loops close; a ball or universal joint is held whole by its "
             "name.")


ACTUATE_HELP = ("For a file of another tool: drive this joint (repeatable): the actuators are the joints named "
                "instead of those the file marks or screwkit guesses (listed, as ever, in the legs' order).")


INITIAL_HELP = ("For a file of another tool: start the reference assembly with this joint at VALUE (deg for a "
                "revolute joint, m for a prismatic one) instead of the file's value, held there while the loops close "
                "(repeatable): a file written at a dead centre (a crank and its rod on one line) or with a joint "
                "outside its limits; --lock then holds the joint at VALUE.")


def lock_option(function: Callable) -> Callable:
    return click.option("--lock", multiple=True, metavar="JOINT", help=LOCK_HELP)(function)


def actuate_option(function: Callable) -> Callable:
    return click.option("--actuate", multiple=True, metavar="JOINT", help=ACTUATE_HELP)(function)


def initial_option(function: Callable) -> Callable:
    return click.option("--initial", multiple=True, nargs=2, type=(str, float), metavar="JOINT VALUE",
                        help=INITIAL_HELP)(function)


def output_frame_option(function: Callable) -> Callable:
    return click.option("--output", "output_frame", default=None, metavar="FRAME",
                        help="For a file of another tool: the frame (MJCF: site or body) whose body is the platform; "
                             "default a frame named effector, end_effector, eff, ee, tool, tcp, foot or platform, "
                             "else the body where most closures meet.")(function)


def output_type_option(function: Callable) -> Callable:
    return click.option("--output-type", type=click.Choice(["point", "frame"]), default=None,
                        help="For a file of another tool: a point output (where the chains meet) or the output "
                             "frame; default: the point when every closure meets the platform at one point and its "
                             "rotations about it are idle, else the frame.")(function)


FILE_OPTIONS = (output_frame_option, output_type_option, lock_option, actuate_option, initial_option)
"""The options of a file of another tool, in the order every command that reads MECHANISM shows them."""


def grouped_notes(notes) -> list[str]:
    """``notes`` with the :data:`LIMITS_IGNORED` ones that say the same of several joints (a hexapod's six slides
    at 0, outside one range) said once, naming the joints, where the first of them stood: the line a command prints."""
    read = [(note, re.fullmatch(rf"{re.escape(LIMITS_IGNORED)}joint ('.*?'): (.*)", note)) for note in notes]
    shared: dict[str, list[str]] = {}
    for _, named in read:
        if named:
            shared.setdefault(named.group(2), []).append(named.group(1))
    out = []
    for note, named in read:
        if not named:
            out.append(note)
        elif shared[named.group(2)][0] == named.group(1):
            joints = shared[named.group(2)]
            where = named.group(2) if len(joints) == 1 else named.group(2).replace("puts the joint at", "puts each at")
            out.append(f"{LIMITS_IGNORED}joint{'s' if len(joints) > 1 else ''} {', '.join(joints)}: {where}")
    return out
