"""``screwkit map``: the minimum of every index over an orientation set on a grid (the paper's Fig. 5)."""

from __future__ import annotations

import time

import click

from screwkit.cli.options import (
    GreedyOption,
    check_colour_scale,
    check_outputs,
    colour_scale_options,
    echo_error,
    fail,
    fault_option,
    ignore_limits_option,
    length_unit_option,
    load_mechanism,
    mechanism_argument,
    overwrite_option,
    parse_range,
    quiet_option,
    scheduler_client,
    threshold_option,
)
from screwkit.cli.sweep import fixed_pose, write_outputs
from screwkit.common.units import is_angular
from screwkit.plots import map_figure
from screwkit.studies.files import DATA_SUFFIXES, FIGURE_SUFFIXES
from screwkit.studies.maps import disc_size, index_map, map_size, planar_disc_map
from screwkit.studies.tasks import CONNECT_TIMEOUT, ClusterError

__all__ = ["map_command", "grid_spec"]


def grid_spec(mechanism, text: str, option: str, include_stop: bool):
    """``COORDINATE:START:STOP:STEP`` -> (coordinate, values in m or rad)."""
    name, _, rest = text.partition(":")
    if name not in mechanism.task_coordinates:
        raise fail(f"Unknown coordinate {name!r} in {option} {text!r}; {mechanism.name!r} has "
                   f"{', '.join(mechanism.task_coordinates)}.")
    return name, parse_range(rest, f"{option} {text}", include_stop=include_stop, angular=is_angular(name))


@click.command("map")
@mechanism_argument
@click.option("--radius", type=float, help="Planar: radius of the disc about the home position (m).")
@click.option("--step", type=float, help="Planar: grid step in x and y (m).")
@click.option("--phi-step", type=float, default=1.0, show_default=True,
              help="Planar: step of the full turn of phi, 0 <= phi < 360 (deg).")
@click.option("--grid", "grids", multiple=True, metavar="COORDINATE:START:STOP:STEP",
              help="Spatial: a grid axis, given twice (x axis, then y axis), m or deg; the stop is included: "
                   "x:-0.2:0.2:0.02 is 21 values from -0.2 to 0.2.")
@click.option("--over", "overs", multiple=True, metavar="COORDINATE:START:STOP:STEP",
              help="Spatial: the orientation set, repeatable (their product), m or deg; the stop is excluded: "
                   "yaw:0:360:15 is 24 angles.")
@click.option("--at", cls=GreedyOption, metavar="VALUES|NAME",
              help="Spatial: the other coordinates, all task coordinates (m, deg) or a named pose; default home.")
@click.option("--out", type=click.Path(dir_okay=False), help="Data file: .nc (netCDF) or .csv.")
@click.option("--figure", "figure_path", type=click.Path(dir_okay=False), help="Figure file: .png, .pdf or .svg.")
@colour_scale_options
@threshold_option
@fault_option
@click.option("--closed-forms", is_flag=True, help="Use the paper's planar closed forms instead of the generic path.")
@ignore_limits_option
@click.option("--scheduler", metavar="ADDRESS",
              help="Address of a running dask.distributed scheduler, e.g. tcp://host:8786 (default: local threads).")
@click.option("--connect-timeout", type=click.FloatRange(min=0, min_open=True), default=CONNECT_TIMEOUT,
              show_default=True, help="Seconds to wait for the --scheduler to answer.")
@click.option("--task-size", type=click.IntRange(min=1),
              help="Configurations (grid points x orientations) per task (default: at most 131,072 and at least "
                   "16,384, and 4 tasks per core of this machine where the map is large enough).")
@click.option("--yes", is_flag=True, help="Proceed with a map of more than 2e9 configurations.")
@length_unit_option
@overwrite_option
@quiet_option
def map_command(mechanism, radius, step, phi_step, grids, overs, at, out, figure_path, vmin, vmax, threshold,
                fault_type, closed_forms, ignore_limits, scheduler, connect_timeout, task_size, yes, length_unit,
                overwrite, quiet) -> None:
    """Minimum of every index over an orientation set at each point of a grid (Fig. 5).

    Planar: --radius R --step S --phi-step D maps a disc about the home position with phi
    over a full turn. Spatial: --grid x:-0.2:0.2:0.02 --grid y:-0.2:0.2:0.02
    --over yaw:0:360:15, optionally more --over (roll:-10:10:5) and --at (x y z roll pitch yaw).
    The size of the map is stated, and a map too large refused, before anything is computed.
    """

    check_outputs({"--out": (out, DATA_SUFFIXES), "--figure": (figure_path, FIGURE_SUFFIXES)}, overwrite, quiet)
    check_colour_scale(vmin, vmax)
    planar = radius is not None or step is not None
    if planar:
        if radius is None or step is None or grids or overs:
            raise fail("A planar map takes --radius and --step (and --phi-step), not --grid/--over.")
        if not 0 < phi_step <= 360:
            raise fail(f"Expected 0 < --phi-step <= 360 (deg), got {phi_step:g}.")
    elif len(grids) != 2:
        raise fail("Expected --radius/--step (planar) or exactly two --grid options.")
    loaded = load_mechanism(mechanism, length_unit)
    try:
        if planar:
            if not loaded.is_planar:
                raise fail(f"--radius and --step map a planar mechanism's disc; {loaded.name!r} is spatial: give "
                           "--grid twice and --over.")
            size = disc_size(loaded, radius, step, phi_step)
        else:
            grid = dict(grid_spec(loaded, g, "--grid", True) for g in grids)
            if len(grid) != 2:
                raise fail(f"Expected two different coordinates in --grid, got {' '.join(grids)}.")
            over = dict(grid_spec(loaded, o, "--over", False) for o in overs)
            at_pose = fixed_pose(loaded, at)
            size = map_size(loaded, grid, over)
        size.check(proceed=yes)
    except ValueError as error:
        raise fail(str(error)) from None
    with scheduler_client(scheduler, connect_timeout) as client:
        if not quiet:  # before the work, whether or not stderr is a terminal
            echo_error(f"{loaded.name}: mapping {size.description}")
        options = dict(threshold=threshold, fault_type=fault_type, closed_forms=closed_forms,
                       limits=not ignore_limits, scheduler=client, progress=False if quiet else None,
                       connect_timeout=connect_timeout, configurations_per_task=task_size, as_dataset=False,
                       proceed=yes)
        start = time.perf_counter()
        try:
            if planar:
                result = planar_disc_map(loaded, radius, step, phi_step, **options)
            else:
                result = index_map(loaded, grid, over, at_pose, **options)
        except (ValueError, ClusterError) as error:
            raise fail(str(error)) from None
    elapsed = time.perf_counter() - start
    if not quiet:
        echo_error(f"{loaded.name}: {result.attrs['configurations']:,} configurations in {elapsed:.2f} s "
                   f"({result.attrs['method']})")
    write_outputs(result, out, figure_path, map_figure, quiet, vmin=vmin, vmax=vmax)
