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
from screwkit.plots.trajectory import trajectory_figure, trajectory_from_dataset
from screwkit.studies.files import FIGURE_SUFFIXES, read_result

__all__ = ["plot"]


def _check_index_values(data, dataset) -> None:
    """Every real variable holds indices (or the fraction of reachable poses): values in [0, 1], NaN where
    unreachable; anything else (inf, 7.0) would be drawn as a colour or as unreachable grey."""
    import numpy as np

    for name in dataset.data_vars:
        values = np.asarray(dataset[name].values)
        if values.dtype.kind != "f":
            continue
        bad = values[~np.isnan(values) & ~((values >= -1e-9) & (values <= 1.0 + 1e-9))]
        if bad.size:
            raise fail(f"{data}: variable {name!r} has {bad.size} value(s) outside [0, 1] (e.g. {bad.flat[0]:g}); "
                       "an index lies in [0, 1], NaN where unreachable.")


@click.command()
@click.argument("data", metavar="FILE.nc")
@click.option("--figure", "figure_path", type=click.Path(dir_okay=False), required=True,
              help="Figure file: .png, .pdf or .svg.")
@colour_scale_options
@overwrite_option
@quiet_option
def plot(data, figure_path, vmin, vmax, overwrite, quiet) -> None:
    """Draw the figure of a map, a sweep or a trajectory from its netCDF file (screwkit map/sweep/trajectory --out
    FILE.nc), as --figure draws it, without computing it again."""
    check_outputs({"--figure": (figure_path, FIGURE_SUFFIXES)}, overwrite, quiet, others={"FILE": data})
    check_colour_scale(vmin, vmax)
    try:
        kind, dataset = read_result(data)
    except ValueError as error:
        raise fail(str(error)) from None
    _check_index_values(data, dataset)
    if kind != "map" and (vmin is not None or vmax is not None):
        raise fail(f"--vmin and --vmax set a map's colour scale; {data} holds a {kind}.")
    try:
        if kind == "map":
            figure = map_figure(dataset, vmin=vmin, vmax=vmax)
        elif kind == "sweep":
            figure = sweep_figure(dataset)
        else:
            figure = trajectory_figure(trajectory_from_dataset(dataset))
    except (ValueError, KeyError, TypeError) as error:
        raise fail(f"{data}: cannot draw this {kind} ({error}).") from None
    save_figure(figure, figure_path)
    if not quiet:
        echo_error(f"wrote {figure_path}: the {kind} of {dataset.attrs.get('mechanism', data)}")
