"""``screwkit view``: a mechanism in a Meshcat viewer, coloured by its indices."""

from __future__ import annotations

import time
from dataclasses import dataclass

import click
import numpy as np

from screwkit.cli.options import (
    GreedyOption,
    check_outputs,
    echo_error,
    fail,
    load_mechanism,
    mechanism_argument,
    option_group,
    overwrite_option,
    parse_pose,
    parse_range,
    quiet_option,
    reading_options,
    threshold_option,
)
from screwkit.viewer import animate_sweep, export_html, show

__all__ = ["view"]


@dataclass(frozen=True)
class Animation:
    """``--sweep-phi`` (None: one pose, no animation) and its keyframes per second."""

    sweep_phi: str | None
    frame_rate: float


@dataclass(frozen=True)
class Colouring:
    """What the chains are coloured by, and the singularity threshold of the indices (m)."""

    color_by: str
    threshold: float


def _echo_legend(scene) -> None:
    """The chains' values and the drawn twists (stdout: the data of the picture)."""
    mechanism = scene.mechanism
    frames = scene.poses.shape[0]
    what = "lowest ITI of its working actuators" if scene.color_by == "iti" else "OTI of its best working submechanism"
    extra = f" (first of {frames} frames)" if frames > 1 else ""
    click.echo(f"{mechanism.name}: chains coloured by the {what}{extra}; viridis 0 purple .. 1 yellow")
    names = mechanism.actuator_names
    for index, chain in enumerate(mechanism.chains):
        value = scene.chain_values[0, index]
        failed = [names[i] for i in scene.failed if mechanism.actuators[i][0] == chain.name]
        note = f"  failed: {', '.join(failed)}" if failed else ""
        shown = "-" if np.isnan(value) else f"{value:.4f}"
        click.echo(f"  {chain.name:<24s} {shown}{note}")
    best = scene.best_submechanisms[0]
    if best is None:
        click.echo("No working submechanism: no output twist drawn.")
    else:
        click.echo("Output twists of the best working submechanism: " + ", ".join(names[i] for i in best))


@click.command("view")
@mechanism_argument
@click.option("--pose", cls=GreedyOption, metavar="VALUES|NAME",
              help="Platform pose: x y phi (planar) or x y z roll pitch yaw, in m and deg, or a named pose. "
                   "Default: the file's home pose.")
@click.option("--failed", "failed", multiple=True, metavar="NAME_OR_INDEX",
              help="A failed actuator: 0-based index, CHAIN:JOINT, joint or chain name. Repeatable.")
@click.option("--html", "html_path", type=click.Path(dir_okay=False),
              help="Write a self-contained offline HTML file (.html) and exit instead of serving.")
@option_group(
    "animation", Animation,
    click.option("--sweep-phi", "sweep_phi", metavar="START:STOP:STEP",
                 help="Animate a planar sweep of phi (deg; the stop is excluded) at the x y of --pose."),
    click.option("--frame-rate", type=click.FloatRange(min=0, min_open=True), default=10.0, show_default=True,
                 help="--sweep-phi: keyframes per second (1/s)."))
@option_group(
    "colouring", Colouring,
    click.option("--color-by", type=click.Choice(["iti", "oti"]), default="iti", show_default=True,
                 help="Colour chains by their lowest ITI or by the OTI of their best working submechanism."),
    threshold_option)
@reading_options
@click.option("--open", "open_browser", is_flag=True, help="Open the viewer in the default browser.")
@overwrite_option
@quiet_option
def view(mechanism: str, pose, failed, html_path, animation: Animation, colouring: Colouring, reading,
         open_browser, overwrite, quiet) -> None:
    """Show MECHANISM in a Meshcat viewer (served on 127.0.0.1), coloured by its indices.

    Chains are coloured by index (viridis: 0 purple, 1 yellow), actuation wrench lines are
    orange, output twist axes and instantaneous centres of the best submechanism magenta,
    failed actuators red. The legend goes to stdout, the server's address to stderr.
    """

    check_outputs({"--html": (html_path, (".html", ".htm"))}, overwrite, quiet)
    loaded = load_mechanism(mechanism, reading)
    target = parse_pose(loaded, pose)
    failures = list(failed)  # indices or names, see screwkit.viewer.resolve_actuators
    try:
        if animation.sweep_phi is not None:
            if not loaded.is_planar:
                raise fail(f"--sweep-phi sweeps a planar mechanism; {loaded.name!r} is spatial.")
            angles = parse_range(animation.sweep_phi, "--sweep-phi", angular=True)
            poses = np.repeat(target[None], angles.size, axis=0)
            poses[:, 2] = angles
            scene = animate_sweep(loaded, poses, failed=failures, threshold=colouring.threshold,
                                  color_by=colouring.color_by, frame_rate=animation.frame_rate)
        else:
            scene = show(loaded, target, failed=failures, threshold=colouring.threshold, color_by=colouring.color_by)
    except (ValueError, RuntimeError) as error:
        raise fail(str(error)) from None
    with scene:
        _echo_legend(scene)
        if html_path is not None:
            try:
                written = export_html(scene, html_path)
            except (ValueError, OSError) as error:
                raise fail(str(error)) from None
            if not quiet:
                echo_error(f"wrote {written}")
            return
        try:  # from the moment the URL is shown, Ctrl+C stops the server and exits cleanly
            echo_error(f"Serving at {scene.url} (127.0.0.1 only); press Ctrl+C to stop.")
            if open_browser:
                scene.viewer.open()
            while scene.server.running:
                time.sleep(0.5)
        except KeyboardInterrupt:
            echo_error("Stopped.")
            return
        raise fail(f"The Meshcat server stopped unexpectedly (exit code {scene.server.process.returncode}).")
