"""``screwkit list``: the bundled mechanisms."""

from __future__ import annotations

import json

import click

from screwkit.cli.options import json_option
from screwkit.io.loader import bundled_graph_names, bundled_names

__all__ = ["list_command"]


@click.command("list")
@json_option
def list_command(as_json: bool) -> None:
    """List the bundled mechanisms (names MECHANISM accepts besides a file path)."""


    names, graphs = bundled_names(), bundled_graph_names()
    if as_json:
        click.echo(json.dumps({"mechanisms": list(names), "graphs": list(graphs)}))
        return
    for name in names:
        click.echo(name)
    for name in graphs:
        click.echo(f"{name} (legs with loops inside them: analyze, info, sweep, map, trajectory, view)")
