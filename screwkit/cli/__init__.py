"""The ``screwkit`` command line: one module per command.

Every command takes a MECHANISM: the name of a bundled robot (``screwkit list``) or the path
of a URDF file following docs/urdf-convention.md. Lengths are metres and angles degrees; data
go to stdout (or the files named), progress and summaries to stderr. Errors are one line
(``Error: ...``; ``{"error": ...}`` on stdout with ``--json``) with exit status 1.
"""

from __future__ import annotations

import importlib
import os
import sys

import click

from screwkit.cli.options import ScrewkitGroup, report_error

__all__ = ["app", "main", "COMMANDS"]

COMMANDS = {
    "list": "screwkit.cli.list_command:list_command",
    "info": "screwkit.cli.info:info",
    "convert": "screwkit.cli.convert:convert",
    "analyze": "screwkit.cli.analyze:analyze",
    "verify": "screwkit.cli.verify:verify",
    "sweep": "screwkit.cli.sweep:sweep",
    "map": "screwkit.cli.map_command:map_command",
    "trajectory": "screwkit.cli.trajectory:trajectory",
    "design-search": "screwkit.cli.design_search:design_search",
    "plot": "screwkit.cli.plot:plot",
    "view": "screwkit.cli.view:view",
    "warmup": "screwkit.cli.warmup:warmup",
}
"""Every command and where it lives: a command's module is imported only when that command runs
(or ``--help`` lists them), so ``screwkit map`` does not load the viewer, the plots or the design search."""


class LazyGroup(ScrewkitGroup):
    """The command group, importing each command's module on first use."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return list(COMMANDS)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name not in COMMANDS:
            return None
        module, attribute = COMMANDS[name].split(":")
        return getattr(importlib.import_module(module), attribute)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="screwkit")
def app() -> None:
    """Screw-theory transmission and fault-tolerance indices of redundantly actuated parallel robots."""


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
    except MemoryError as error:  # beyond what a study's size check foresaw (screwkit.studies.sizes): one line
        said = str(error).split(" for an array")[0]  # numpy's "Unable to allocate 641. MiB for an array ..."
        report_error(f"Ran out of memory{': ' + said if said else ''}: ask for a smaller study (fewer poses or "
                     "samples, a coarser grid), or split it into parts.", sys.argv[1:])
        code = 1
    except BaseException:
        _stop_compilers()
        raise
    if code:  # a command that failed before it needed its kernels: no compiler outlives it (a command that succeeds
        _stop_compilers()  # has waited for those it used; one it started ahead and did not use fills the cache)
    server = sys.modules.get("screwkit.viewer.server")  # loaded only if a command used the viewer
    if server is not None and server.servers_to_stop():
        sys.exit(code)
    if code is not None and not isinstance(code, int):
        print(code, file=sys.stderr)
        code = 1
    try:
        sys.stdout.flush()
    except OSError as error:  # stdout is a file on a full disk (or a closed pipe): one line, not a traceback
        if not code:  # (a failed command has said why already)
            print(f"Error: Cannot write to stdout: {error.strerror or error}.", file=sys.stderr)
        code = 1
    sys.stderr.flush()
    os._exit(code or 0)


def _stop_compilers() -> None:
    compiling = sys.modules.get("screwkit.common.compiling")  # loaded only if the command computes indices
    if compiling is not None:
        compiling.stop_compiling()
