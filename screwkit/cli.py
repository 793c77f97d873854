"""The ``screwkit`` command line.

Every command takes a MECHANISM: the name of a bundled robot (``screwkit list``) or the path
of a URDF file following docs/urdf-convention.md. Lengths are metres and angles degrees.
Errors are one line (``Error: ...``) with exit status 1.
"""

from __future__ import annotations

import json
import sys

import click
import numpy as np

from screwkit.transmission import DEFAULT_THRESHOLD


class GreedyOption(click.Option):
    """An option taking every value up to the next option: ``--pose -0.2 0 45``.

    Negative numbers are values, not options. The values arrive joined by spaces.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("multiple", False)
        super().__init__(*args, **kwargs)
        self._previous_process = None

    def add_to_parser(self, parser, ctx):
        def process(value, state):
            values = [value]
            while state.rargs:
                token = state.rargs[0]
                if token.startswith("--") or (token.startswith("-") and not _is_number(token)):
                    break
                values.append(state.rargs.pop(0))
            self._previous_process(" ".join(values), state)

        result = super().add_to_parser(parser, ctx)
        for name in self.opts:
            our_parser = parser._long_opt.get(name) or parser._short_opt.get(name)
            if our_parser:
                self._previous_process = our_parser.process
                our_parser.process = process
        return result


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _load(name: str):
    from screwkit.mechanism import load

    try:
        return load(name)
    except ValueError as error:
        raise click.ClickException(str(error)) from None


def _floats(values, what: str) -> list[float]:
    try:
        return [float(v) for v in values]
    except ValueError:
        raise click.ClickException(f"Expected numbers after {what}, got {' '.join(values)}.") from None


def _pose(mechanism, values) -> np.ndarray:
    from screwkit.analysis import poses_from_degrees

    if values is None:  # the reference assembly of the file
        return np.asarray(mechanism.home_pose, dtype=float)
    values = values.split()
    numbers = _floats(values, "--pose")
    if len(numbers) != mechanism.n_task:
        raise click.ClickException(
            f"Expected --pose with {mechanism.n_task} values ({', '.join(mechanism.task_coordinates)}) for "
            f"mechanism {mechanism.name!r}, got {len(numbers)}: {' '.join(values)}.")
    try:
        return poses_from_degrees(mechanism, numbers)
    except ValueError as error:
        raise click.ClickException(str(error)) from None


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="screwkit")
def app() -> None:
    """Screw-theory transmission and fault-tolerance indices of redundantly actuated parallel robots."""


@app.command("list")
def list_command() -> None:
    """List the bundled mechanisms."""
    from screwkit.mechanism import bundled_names

    for name in bundled_names():
        click.echo(name)


def pose_report(mechanism, pose, result) -> dict:
    """The indices at one pose as a JSON-ready dictionary."""
    names = [f"{chain}:{joint}" for chain, joint in mechanism.actuators]
    angular = {"phi", "roll", "pitch", "yaw"}
    return {
        "mechanism": mechanism.name,
        "pose": {name: float(np.rad2deg(value)) + 0.0 if name in angular else float(value) + 0.0
                 for name, value in zip(mechanism.task_coordinates, pose)},
        "dof": result.dof,
        "actuators": names,
        "iti": float(result.iti),
        "iti_actuators": {name: float(v) for name, v in zip(names, result.iti_actuators)},
        "lmti": float(result.lmti),
        "f_o": {str(j): float(v) for j, v in result.f_o.items()},
        "f_io": {str(j): float(v) for j, v in result.f_io.items()},
        "worst_faults": {str(j): [names[i] for i in np.atleast_1d(v)] for j, v in result.worst_faults.items()},
        "not_mutual_interference": [name for name, ok in zip(names, result.mutual_interference) if not ok],
        "threshold_m": result.threshold,
    }


def _print_report(report: dict) -> None:
    pose = ", ".join(f"{k} = {v:g}" for k, v in report["pose"].items())
    click.echo(f"{report['mechanism']}: {len(report['actuators'])} actuators, {report['dof']} DOF, at {pose}")
    click.echo("")
    click.echo("ITI per actuator (Eq. 6)")
    lowest = min(report["iti_actuators"], key=report["iti_actuators"].get)
    for name, value in report["iti_actuators"].items():
        click.echo(f"  {name:<32s} {value:.4f}{'  <- lowest' if name == lowest else ''}")
    click.echo(f"ITI  (Eq. 7)                        {report['iti']:.4f}")
    click.echo(f"LMTI (Eq. 11, all actuators)        {report['lmti']:.4f}")
    if not report["f_o"]:
        click.echo("No redundancy (a = n): no fault-tolerance index is defined.")
    for j in report["f_o"]:
        worst = ", ".join(report["worst_faults"].get(j, []))
        click.echo(f"F_O{j:<2s}(Eq. 12) {report['f_o'][j]:.4f}   F_IO{j:<2s}(Eq. 14) {report['f_io'][j]:.4f}"
                   f"   worst fault: {worst}")
    if report["not_mutual_interference"]:
        click.echo("Not mutual-interference actuators (every F_Oj is 0): "
                   + ", ".join(report["not_mutual_interference"]))
    else:
        click.echo("All actuators are mutual-interference actuators.")


@app.command()
@click.argument("mechanism")
@click.option("--pose", cls=GreedyOption,
              help="Platform pose: x y phi (planar) or x y z roll pitch yaw; m and deg. Default: the file's home pose.")
@click.option("--threshold", type=float, default=DEFAULT_THRESHOLD, show_default=True,
              help="Singularity threshold p on the moment arm (m).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object instead of the report.")
def analyze(mechanism: str, pose, threshold: float, as_json: bool) -> None:
    """Every index (ITI, LMTI, F_Oj, F_IOj) of MECHANISM at one pose."""
    from screwkit.analysis import analyze_pose

    loaded = _load(mechanism)
    target = _pose(loaded, pose)
    try:
        result = analyze_pose(loaded, target, threshold=threshold)
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    report = pose_report(loaded, target, result)
    if as_json:
        click.echo(json.dumps(report))
    else:
        _print_report(report)


@app.command()
@click.argument("mechanism")
@click.option("--samples", type=click.IntRange(min=1), default=10_000, show_default=True,
              help="Random reachable configurations to compare.")
@click.option("--seed", type=int, default=0, show_default=True)
def verify(mechanism: str, samples: int, seed: int) -> None:
    """Compare the generic screw path with the paper's planar closed forms on random poses."""
    from screwkit.analysis import _closed_form_result, planar_points
    from screwkit.transmission import analyze as analyze_screws

    loaded = _load(mechanism)
    if not loaded.is_planar:
        raise click.ClickException(f"verify compares with the planar closed forms; {loaded.name!r} is spatial.")
    rng = np.random.default_rng(seed)
    home = np.asarray(loaded.home_pose, dtype=float)
    poses = home + np.column_stack([rng.uniform(-0.5, 0.5, samples * 4), rng.uniform(-0.5, 0.5, samples * 4),
                                    rng.uniform(-np.pi, np.pi, samples * 4)])
    solution = loaded.solve(poses)
    keep = np.flatnonzero(solution.reachable)[:samples]
    if keep.size == 0:
        raise click.ClickException("No reachable pose among the samples.")
    solution = loaded.solve(poses[keep])
    try:
        planar_points(loaded, solution)
    except ValueError as error:
        raise click.ClickException(str(error)) from None
    generic = analyze_screws(loaded.chain_screws(solution))
    closed = _closed_form_result(loaded, solution, DEFAULT_THRESHOLD, None, None)
    rows = [("ITI per actuator", generic.iti_actuators, closed.iti_actuators),
            ("OTI per submechanism", generic.oti_submechanisms, closed.oti_submechanisms),
            ("LMTI", generic.lmti, closed.lmti)]
    rows += [(f"F_O{j}", generic.f_o[j], closed.f_o[j]) for j in generic.f_o]
    rows += [(f"F_IO{j}", generic.f_io[j], closed.f_io[j]) for j in generic.f_io]
    click.echo(f"{loaded.name}: generic screw path vs closed forms (Eqs. 23, 34-38, A4) on {keep.size} poses")
    worst = 0.0
    for label, first, second in rows:
        deviation = float(np.max(np.abs(first - second)))
        worst = max(worst, deviation)
        click.echo(f"  {label:<22s} largest deviation {deviation:.2e}")
    click.echo(f"largest deviation: {worst:.2e}")
    if worst > 1e-9:
        sys.exit(1)


def main() -> None:  # pragma: no cover - console entry point
    app()
