"""``screwkit sweep``: every series of the paper's Fig. 4 along one pose coordinate."""

from __future__ import annotations

import click
import numpy as np

from screwkit.cli.options import (
    GreedyOption,
    Outputs,
    analysis_options,
    check_average,
    echo_error,
    fail,
    load_mechanism,
    mechanism_argument,
    outputs_options,
    parse_pose,
    parse_range,
    quiet_option,
    reading_options,
)
from screwkit.closure.on_the_way import OTHER_ASSEMBLY
from screwkit.common.units import is_angular
from screwkit.indices.registry import column_record, is_column
from screwkit.plots import save_figure, sweep_figure
from screwkit.studies.files import write_dataset
from screwkit.studies.sweep import sweep as run_sweep
from screwkit.studies.tables import wide_csv

__all__ = ["sweep", "fixed_pose", "write_outputs"]


def fixed_pose(mechanism, at: str | None) -> np.ndarray:
    """``--at``: every task coordinate (m, deg), a named pose, or for a planar mechanism just x y (its phi, if it
    has one, at the home pose's)."""
    if at is not None and mechanism.is_planar and len(at.split()) == 2 and mechanism.n_task == 3:
        at = f"{at} {float(np.rad2deg(mechanism.home_pose[2]))!r}"
    return parse_pose(mechanism, at, "--at")


def write_outputs(dataset, outputs: Outputs, figure_function, quiet: bool, **figure_options) -> None:
    """Write the data file and the figure (both checked before the computation), saying so on stderr.

    With neither, the data go to stdout as a CSV table.
    """
    out, figure_path = outputs.out, outputs.figure
    if not out and not figure_path:
        click.echo(wide_csv(dataset), nl=False)  # (a map's GridMap, a sweep's PlainDataset: without xarray)
        return
    if out:
        write_dataset(dataset, out)
        if not quiet:
            echo_error(f"wrote {out}")
    if figure_path:
        data = dataset.to_dataset() if hasattr(dataset, "to_dataset") else dataset  # a GridMap, a PlainDataset
        save_figure(figure_function(data, **figure_options), figure_path)
        if not quiet:
            echo_error(f"wrote {figure_path}")


@click.command()
@mechanism_argument
@click.option("--at", cls=GreedyOption, metavar="VALUES|NAME",
              help="Fixed pose: every task coordinate (m, deg), a named pose, or x y for a planar mechanism "
                   "(phi from the home pose). Default: the home pose.")
@click.option("--phi", "phi_range", metavar="START:STOP:STEP",
              help="Planar shorthand for --sweep phi:START:STOP:STEP "
                   "(deg; the stop is excluded: 0:360:1 is 360 angles).")
@click.option("--sweep", "sweep_spec", metavar="COORDINATE:START:STOP:STEP",
              help="The swept coordinate and its range, m or deg; the stop is excluded (yaw:0:360:1 is 360 angles).")
@outputs_options()
@analysis_options(average=True)
@reading_options
@quiet_option
def sweep(mechanism, at, phi_range, sweep_spec, outputs: Outputs, analysis, reading, quiet) -> None:
    """Sweep one pose coordinate: every series of the paper's Figure 4 along it.

    The data go to --out (or, with neither --out nor --figure, to stdout as CSV); the minima
    found are summarised on stderr.
    """

    outputs.check(quiet)
    loaded = load_mechanism(mechanism, reading, limits=analysis.limits, graphs=True)
    check_average(analysis, loaded)
    if (phi_range is None) == (sweep_spec is None):
        raise fail("Expected exactly one of --phi START:STOP:STEP or --sweep COORDINATE:START:STOP:STEP.")
    if phi_range is not None:
        coordinate, text = "phi", phi_range
    else:
        coordinate, _, text = sweep_spec.partition(":")
    if coordinate not in loaded.task_coordinates:
        raise fail(f"Unknown coordinate {coordinate!r} to sweep; {loaded.name!r} has "
                   f"{', '.join(loaded.task_coordinates)}.")
    values = parse_range(text, "--phi" if phi_range else "--sweep", angular=is_angular(coordinate))
    with analysis.indices():  # the average case registered, if asked: computed, summarised, written
        try:
            dataset = run_sweep(loaded, fixed_pose(loaded, at), coordinate, values, **analysis.keywords(),
                                as_dataset=False)  # (plain arrays: written and printed without xarray)
        except ValueError as error:
            raise fail(str(error)) from None
        if not quiet:
            series_of = {name: np.asarray(entry[1]) for name, entry in dataset.variables.items()}
            swept = np.asarray(dataset.coords[coordinate][1])
            echo_error(f"{loaded.name}: swept {coordinate} over {values.size} values "
                       f"({int(series_of['reachable'].sum())} reachable)")
            redundant = len(loaded.actuators) > loaded.dof
            if not redundant:
                echo_error("  no redundancy (a = n): F_O1 = F_IO1 = 0 everywhere")
            for name in [v for v in series_of if is_column(v) and (redundant or column_record(v)[1] is None)]:
                series = series_of[name]
                if np.any(np.isfinite(series)):
                    echo_error(f"  min {name:<6s} {np.nanmin(series):.4f} at {coordinate} = "
                               f"{swept[np.nanargmin(series)]:g}")
            if "past_singular" in series_of:
                _say_past_singular(swept, dataset.coords["singular_chain"][1], series_of["past_singular"], coordinate)
        write_outputs(dataset, outputs, sweep_figure, quiet)


def _say_past_singular(values, chains, past, coordinate: str) -> None:
    """A NOTE for each chain whose joints are singular somewhere on the way from the reference pose to some of the
    swept poses (``past``, (values, chains)): those poses are on the assembly that keeps the reference's working-mode
    sign."""
    for chain, passed in zip(chains, np.asarray(past).T):
        if passed.any():
            shown = ", ".join(f"{value:g}" for value in values[passed][:6]) + (", ..." if passed.sum() > 6 else "")
            echo_error(f"NOTE: at {coordinate} = {shown} ({int(passed.sum())} of {values.size} values), the straight "
                       f"way from the reference pose passes a configuration where chain {chain}'s joints are "
                       "singular: two of its assemblies meet there, and these poses keep the reference's working-mode "
                       f"sign, {OTHER_ASSEMBLY} (analyze --pose says where; --initial JOINT VALUE on each actuator "
                       "assembles the other)")
