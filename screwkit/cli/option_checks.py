"""Checks of the execution and analysis options shared by several commands (``--scheduler``, ``--connect-timeout``,
``--threshold``): each a one-line error naming the option, before any work."""

from __future__ import annotations

import math

import click

from screwkit.studies.tasks import Execution, check_address, check_connect_timeout

__all__ = ["execution_record", "finite_threshold", "given"]


def given(name: str) -> bool:
    """Whether the option of parameter ``name`` was given (on the command line or by its environment variable),
    not left at its default."""
    context = click.get_current_context(silent=True)
    return context is not None and context.get_parameter_source(name) in (
        click.core.ParameterSource.COMMANDLINE, click.core.ParameterSource.ENVIRONMENT)


def execution_record(scheduler: str | None, connect_timeout: float, task_size: int | None, quiet: bool) -> Execution:
    """The :class:`~screwkit.studies.tasks.Execution` of ``--scheduler``, ``--connect-timeout`` and ``--task-size``:
    a timeout that is a number of seconds (0 < SECONDS <= a day), given only with a scheduler, and a scheduler
    address screwkit can use (tcp:// or tls://, a port from 1 to 65535)."""
    try:
        connect_timeout = check_connect_timeout(connect_timeout, "--connect-timeout")
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    if scheduler is None and given("connect_timeout"):
        raise click.ClickException("--connect-timeout is how long to wait for --scheduler, and there is none: give "
                                   "--scheduler ADDRESS with it, or leave it out (local threads).")
    if scheduler is not None:
        try:
            check_address(scheduler)
        except ValueError as error:
            raise click.ClickException(f"--scheduler: {error}") from None
    return Execution(scheduler=scheduler, connect_timeout=connect_timeout, configurations_per_task=task_size,
                     progress=False if quiet else None)


def finite_threshold(context, parameter, value: float | None) -> float | None:
    """``--threshold``'s callback: a finite number (inf made every index 0, NaN every pose singular)."""
    if value is not None and not math.isfinite(value):
        raise click.ClickException(f"Expected a finite --threshold (the singularity threshold p on the moment arm, m), "
                                   f"got {value}.")
    return value
