"""``screwkit plot``: the figure of a saved map or sweep, drawn again without computing anything."""

from __future__ import annotations

import click

from screwkit.cli.options import (
    check_colour_scale,
    check_outputs,
    colour_scale_options,
    echo_error,
    fail,
    overwrite_option,
    quiet_option,
)
from screwkit.plots import map_figure, save_figure, sweep_figure
from screwkit.studies.files import FIGURE_SUFFIXES, read_result

__all__ = ["plot"]


@click.command()
@click.argument("data", metavar="FILE.nc")
@click.option("--figure", "figure_path", type=click.Path(dir_okay=False), required=True,
              help="Figure file: .png, .pdf or .svg.")
@colour_scale_options
@overwrite_option
@quiet_option
def plot(data, figure_path, vmin, vmax, overwrite, quiet) -> None:
    """Draw the figure of a map or a sweep from its netCDF file (screwkit map/sweep --out FILE.nc), as --figure
    draws it, without computing it again."""
    check_outputs({"--figure": (figure_path, FIGURE_SUFFIXES)}, overwrite, quiet, others={"FILE": data})
    check_colour_scale(vmin, vmax)
    try:
        kind, dataset = read_result(data)
    except ValueError as error:
        raise fail(str(error)) from None
    if kind == "sweep" and (vmin is not None or vmax is not None):
        raise fail(f"--vmin and --vmax set a map's colour scale; {data} holds a sweep.")
    try:
        figure = map_figure(dataset, vmin=vmin, vmax=vmax) if kind == "map" else sweep_figure(dataset)
    except (ValueError, KeyError) as error:
        raise fail(f"{data}: cannot draw this {kind} ({error}).") from None
    save_figure(figure, figure_path)
    if not quiet:
        echo_error(f"wrote {figure_path}: the {kind} of {dataset.attrs.get('mechanism', data)}")
