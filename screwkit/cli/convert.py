"""``screwkit convert``: a closed-loop robot of another tool, written in screwkit's URDF convention."""

from __future__ import annotations

import json
import re
from pathlib import Path

import click

from screwkit.cli.options import (
    fail,
    ignore_limits_option,
    json_option,
    length_unit_option,
    option_group,
    overwrite_option,
    quiet_option,
)
from screwkit.cli.reading import FILE_OPTIONS, Reading, reading_record
from screwkit.closure.assembly import DRAWN_AT_ROUNDING, NOT_OPEN_LOOPS
from screwkit.io import ImportError_, ImportReport, is_foreign, with_reference_configuration
from screwkit.io.drawn_loops import FRAMES_WRITTEN
from screwkit.io.loader import converted_mechanism, load, load_text
from screwkit.studies.files import atomic_text, check_output

__all__ = ["convert"]


@click.command()
@click.argument("source", type=click.Path(dir_okay=False, path_type=Path))
@click.argument("out", type=click.Path(dir_okay=False, path_type=Path))
@option_group("reading", reading_record, length_unit_option, *FILE_OPTIONS)
@ignore_limits_option
@overwrite_option
@quiet_option
@json_option
def convert(source: Path, out: Path, reading: Reading, ignore_limits: bool, overwrite: bool, quiet: bool,
            as_json: bool) -> None:
    """Write SOURCE (an MJCF or SDFormat file, or a URDF tree with a Gepetto robot.yaml beside it) to OUT in screwkit's
    URDF convention: loops, transmissions and the assembled reference configuration (lengths in SOURCE's unit:
    --length-unit says which, and OUT says it in a <units> element). A file already in the convention whose joint
    values leave loops open is written back with them closed. With --ignore-limits, a reference assembly outside a
    joint's limits is written all the same (the limits as in SOURCE: the file written then needs --ignore-limits
    too)."""
    if not source.is_file():
        raise fail(f"{source}: no such file.")
    if source.suffix.lower() not in (".xml", ".mjcf", ".sdf", ".urdf"):
        raise fail(f"{source}: expected an MJCF file (.xml, .mjcf), an SDFormat file (.sdf) or a URDF with a "
                   "robot.yaml beside it.")
    try:
        check_output(out, (".urdf",), overwrite=overwrite)
    except ValueError as error:
        raise fail(str(error)) from None
    try:
        if is_foreign(source):  # (the frame read where an actuator turns the legs' meeting point, as analyze does)
            text, report, mechanism = converted_mechanism(source, output=reading.output,
                                                          output_type=reading.output_type, lock=reading.lock,
                                                          actuate=reading.actuate, initial=reading.initial,
                                                          length_unit=reading.length_unit, limits=not ignore_limits)
            text = _with_units(text, reading.length_unit)
        else:  # screwkit's own convention: the loops the file leaves open, closed and written back (the options of
            # files of other tools refused by the loader, as on every command)
            own = load(source, limits=not ignore_limits, output=reading.output, output_type=reading.output_type,
                       lock=reading.lock, actuate=reading.actuate, initial=reading.initial,
                       length_unit=reading.length_unit)
            text = _with_units(with_reference_configuration(own.description.text, own), reading.length_unit)
            report = ImportReport(source=str(source), file_format="screwkit URDF", output="as in the file",
                                  planar=own.is_planar, motors=list(own.actuator_names))
            drawn = any(note.startswith(DRAWN_AT_ROUNDING) and FRAMES_WRITTEN in note for note in own.assembly_notes)
            report.notes = [f"assembled: {note}" for note in own.assembly_notes if not note.startswith(NOT_OPEN_LOOPS)
                            ] or ["every loop closes as written" + (" to the file's rounding (below)" if drawn else "")]
            # (the others: below, from the file written)
            mechanism = load_text(text, str(source), limits=not ignore_limits)  # what is written must load
    except (ImportError_, ValueError) as error:
        raise fail(str(error)) from None
    still_open = [note for note in mechanism.assembly_notes if not note.startswith(NOT_OPEN_LOOPS)]
    if still_open:
        raise fail(f"{out}: the converted file still leaves loops open: {'; '.join(still_open)}")
    report.notes += [note for note in mechanism.assembly_notes if note.startswith(NOT_OPEN_LOOPS)]
    atomic_text(out, text)
    summary = {"source": str(source), "written": str(out), "format": report.file_format,
               "platform_body": report.platform_body, "output": report.output, "planar": report.planar,
               "dof": mechanism.dof, "task_coordinates": list(mechanism.task_coordinates),
               "actuators": list(mechanism.actuator_names), "chains": report.chains, "locked_joints": report.locked,
               "left_out_joints": report.dropped, "notes": report.notes,
               "closure_gaps_m": {name: {"file": report.gaps_before[name], "assembled": report.gaps_after[name]}
                                  for name in report.gaps_before}}
    if as_json:
        click.echo(json.dumps(summary, indent=2))
    elif not quiet:
        for line in report.lines():
            click.echo(line, err=True)
        click.echo(f"wrote {out}: {mechanism.dof} DOF ({' '.join(mechanism.task_coordinates)}), "
                   f"{len(mechanism.actuators)} actuators", err=True)


def _with_units(text: str, unit: str | None) -> str:
    """The URDF ``text`` saying its lengths are in ``unit`` (its ``<units>`` elements replaced by one), or as it is
    for None: the file written reads as SOURCE read with --length-unit."""
    if unit is None:
        return text
    text = re.sub(r"\s*<units\b[^>]*?(?:/>|>.*?</units\s*>)", "", text, flags=re.DOTALL)
    opening = re.search(r"<robot\b[^>]*>", text)
    return f'{text[:opening.end()]}\n  <units length="{unit}"/>{text[opening.end():]}'
