"""``screwkit map``: the minimum of every index over an orientation set on a grid (the paper's Fig. 5)."""

from __future__ import annotations

import time
from dataclasses import dataclass

import click

from screwkit.cli.option_checks import given
from screwkit.cli.options import (
    GreedyOption,
    Outputs,
    analysis_options,
    check_average,
    connected,
    echo_error,
    execution_options,
    fail,
    load_mechanism,
    mechanism_argument,
    option_group,
    outputs_options,
    parse_range,
    quiet_option,
    reading_options,
)
from screwkit.cli.sweep import fixed_pose, write_outputs
from screwkit.common.units import is_angular
from screwkit.plots import map_figure
from screwkit.studies.maps import disc_size, index_map, map_size, planar_disc_map
from screwkit.studies.tasks import ClusterError

__all__ = ["map_command", "grid_spec", "MapArea"]


def grid_spec(mechanism, text: str, option: str, include_stop: bool):
    """``COORDINATE:START:STOP:STEP`` -> (coordinate, values in m or rad)."""
    name, _, rest = text.partition(":")
    if name not in mechanism.task_coordinates:
        raise fail(f"Unknown coordinate {name!r} in {option} {text!r}; {mechanism.name!r} has "
                   f"{', '.join(mechanism.task_coordinates)}.")
    return name, parse_range(rest, f"{option} {text}", include_stop=include_stop, angular=is_angular(name))


@dataclass(frozen=True)
class MapArea:
    """Where a map is computed: a planar disc (``radius``, ``step``, ``phi_step``) or a spatial grid
    (``grids``, ``overs``, ``at``), as the options give them."""

    radius: float | None
    step: float | None
    phi_step: float
    grids: tuple[str, ...]
    overs: tuple[str, ...]
    at: str | None

    @property
    def planar(self) -> bool:
        return self.radius is not None or self.step is not None

    def check(self) -> None:
        """The options that go together, before the mechanism is loaded."""
        if self.planar:
            if self.grids or self.overs:
                raise fail("A planar map takes --radius and --step (and --phi-step), not --grid/--over.")
            if self.radius is None or self.step is None:
                raise fail(f"A planar map takes --radius and --step (and --phi-step): "
                           f"{'--radius' if self.radius is None else '--step'} is missing.")
            if not 0 < self.phi_step <= 360:
                raise fail(f"Expected 0 < --phi-step <= 360 (deg), got {self.phi_step:g}.")
            if self.at is not None:
                raise fail("--at fixes the other coordinates of a --grid map; a planar map (--radius, --step) is a "
                           "disc about the home pose over every phi: leave out --at, or give --grid x:... --grid "
                           "y:... --over phi:0:360:STEP with --at.")
            return
        if len(self.grids) != 2:
            raise fail("Expected --radius/--step (planar) or exactly two --grid options.")
        if given("phi_step"):
            raise fail("--phi-step is the phi step of a planar map (--radius, --step); with --grid, give the "
                       f"orientation set as --over phi:0:360:{self.phi_step:g}.")


map_area_options = option_group(
    "area", MapArea,
    click.option("--radius", type=float, help="Planar: radius of the disc about the home position (m)."),
    click.option("--step", type=float, help="Planar: grid step in x and y (m)."),
    click.option("--phi-step", type=float, default=1.0, show_default=True,
                 help="Planar: step of the full turn of phi, 0 <= phi < 360 (deg)."),
    click.option("--grid", "grids", multiple=True, metavar="COORDINATE:START:STOP:STEP",
                 help="Spatial: a grid axis, given twice (x axis, then y axis), m or deg; the stop is included: "
                      "x:-0.2:0.2:0.02 is 21 values from -0.2 to 0.2."),
    click.option("--over", "overs", multiple=True, metavar="COORDINATE:START:STOP:STEP",
                 help="Spatial: the orientation set, repeatable (their product), m or deg; the stop is excluded: "
                      "yaw:0:360:15 is 24 angles."),
    click.option("--at", cls=GreedyOption, metavar="VALUES|NAME",
                 help="Spatial: the other coordinates, all task coordinates (m, deg) or a named pose; default home."))


def _map(loaded, area: MapArea, analysis, execution, proceed: bool, quiet: bool):
    """The map of ``area``: its size checked and stated before anything is computed, its time after (on stderr,
    unless ``quiet``)."""
    try:
        if area.planar:
            if not loaded.is_planar:
                raise fail(f"--radius and --step map a planar mechanism's disc; {loaded.name!r} is spatial: give "
                           "--grid twice and --over.")
            size = disc_size(loaded, area.radius, area.step, area.phi_step)
        else:
            grid = dict(grid_spec(loaded, g, "--grid", True) for g in area.grids)
            if len(grid) != 2:
                raise fail(f"Expected two different coordinates in --grid, got {' '.join(area.grids)}.")
            over = dict(grid_spec(loaded, o, "--over", False) for o in area.overs)
            if len(over) != len(area.overs):
                named = [o.partition(":")[0] for o in area.overs]
                repeated = next(name for name in named if named.count(name) > 1)
                raise fail(f"Expected each coordinate at most once in --over (the orientation set is the product of "
                           f"their ranges), got {repeated} {named.count(repeated)} times: {' '.join(area.overs)}.")
            at_pose = fixed_pose(loaded, area.at)
            size = map_size(loaded, grid, over)
        size.check(proceed=proceed)
    except ValueError as error:
        raise fail(str(error)) from None
    with connected(execution) as execution:
        if not quiet:  # before the work, whether or not stderr is a terminal
            echo_error(f"{loaded.name}: mapping {size.description}")
        options = dict(analysis=analysis, execution=execution, as_dataset=False, proceed=proceed)
        start = time.perf_counter()
        try:
            if area.planar:
                result = planar_disc_map(loaded, area.radius, area.step, area.phi_step, **options)
            else:
                result = index_map(loaded, grid, over, at_pose, **options)
        except (ValueError, ClusterError) as error:
            raise fail(str(error)) from None
    elapsed = time.perf_counter() - start
    if not quiet:
        echo_error(f"{loaded.name}: {result.attrs['configurations']:,} configurations in {elapsed:.2f} s "
                   f"({result.attrs['method']})")
    return result


@click.command("map")
@mechanism_argument
@map_area_options
@outputs_options(colour_scale=True)
@analysis_options(average=True)
@execution_options(task_size=True)
@click.option("--yes", is_flag=True, help="Proceed with a map of more than 2e9 configurations.")
@reading_options
@quiet_option
def map_command(mechanism, area: MapArea, outputs: Outputs, analysis, execution, yes, reading, quiet) -> None:
    """Minimum of every index over an orientation set at each point of a grid (Fig. 5).

    Planar: --radius R --step S --phi-step D maps a disc about the home position with phi
    over a full turn. Spatial: --grid x:-0.2:0.2:0.02 --grid y:-0.2:0.2:0.02
    --over yaw:0:360:15, optionally more --over (roll:-10:10:5) and --at (x y z roll pitch yaw).
    --aggregate mean also maps the average case of F_Oj over the failures (f_o_mean<j>).
    The size of the map is stated, and a map too large refused, before anything is computed.
    """

    outputs.check(quiet)
    if outputs.figure is None and (outputs.vmin is not None or outputs.vmax is not None):
        raise fail("--vmin and --vmax are the ends of the colour scale of --figure, and there is none: give --figure "
                   "with them.")
    area.check()
    loaded = load_mechanism(mechanism, reading, limits=analysis.limits, graphs=True)
    check_average(analysis, loaded)
    with analysis.indices():  # the average case registered, if asked: mapped (its worst orientation) and written
        result = _map(loaded, area, analysis, execution, yes, quiet)
        write_outputs(result, outputs, map_figure, quiet, vmin=outputs.vmin, vmax=outputs.vmax)
