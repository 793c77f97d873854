"""The ``screwkit`` command line: one module per command.

Every command takes a MECHANISM: the name of a bundled robot (``screwkit list``) or the path
of a URDF file following docs/urdf-convention.md. Lengths are metres and angles degrees; data
go to stdout (or the files named), progress and summaries to stderr. Errors are one line
(``Error: ...``; ``{"error": ...}`` on stdout with ``--json``) with exit status 1.
"""

from __future__ import annotations

import os
import sys

import click

from screwkit.cli.analyze import analyze
from screwkit.cli.design_search import design_search
from screwkit.cli.info import info
from screwkit.cli.list_command import list_command
from screwkit.cli.map_command import map_command
from screwkit.cli.options import ScrewkitGroup
from screwkit.cli.sweep import sweep
from screwkit.cli.verify import verify
from screwkit.cli.view import view
from screwkit.viewer.server import servers_to_stop

__all__ = ["app", "main"]


@click.group(cls=ScrewkitGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="screwkit")
def app() -> None:
    """Screw-theory transmission and fault-tolerance indices of redundantly actuated parallel robots."""


for command in (list_command, info, analyze, verify, sweep, map_command, design_search, view):
    app.add_command(command)


def main() -> None:
    """Console entry point: run the command, then end the process without the interpreter's teardown.

    Tearing down numba's compiler, Pinocchio and Dask takes about 0.3 s after every command,
    although each command has written, closed and flushed its results when it returns. The
    process then ends at once with the command's exit status, unless a Meshcat server started
    by ``view`` is still to be stopped by its finaliser (a normal exit runs it).
    """
    try:
        app()
        code = 0
    except SystemExit as stop:
        code = stop.code

    if servers_to_stop():
        sys.exit(code)
    if code is not None and not isinstance(code, int):
        print(code, file=sys.stderr)
        code = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code or 0)
