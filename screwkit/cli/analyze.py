"""``screwkit analyze``: every index at one pose."""

from __future__ import annotations

import json
import re

import click
import numpy as np

from screwkit.cli.options import (
    GreedyOption,
    analysis_options,
    check_average,
    fail,
    json_option,
    load_mechanism,
    mechanism_argument,
    parse_pose,
    reading_options,
)
from screwkit.closure.forward_kinematics import forward_from_starts
from screwkit.closure.on_the_way import OTHER_ASSEMBLY, singular_on_the_way
from screwkit.common.units import angle_beyond_limit, angle_limit
from screwkit.indices.registry import INDICES
from screwkit.io.closed_tree import GROUNDED
from screwkit.io.locking import GUESSED
from screwkit.model import Mechanism
from screwkit.studies import indices_at_pose
from screwkit.studies.coordinates import shown_number

__all__ = ["analyze", "print_report"]


def _names(names: list[str]) -> str:
    return ", ".join(names)


def _ties(groups: list[list[str]]) -> str:
    """The first of tied worst cases, and how many more tie with it."""
    others = len(groups) - 1
    return _names(groups[0]) + (f" (tied with {others} other set{'s' if others > 1 else ''})" if others else "")


def _limiting(detail: dict) -> str:
    """``submechanism ..., limited by ...`` of a report's ``lmti_detail`` or ``fault_detail`` entry."""
    if not detail.get("submechanism"):
        return "no n actuators left to hold the platform"
    tied = len(detail["tied_submechanisms"])
    return (f"best submechanism {_names(detail['submechanism'])}"
            + (f" (tied with {tied} other{'s' if tied > 1 else ''})" if tied else "")
            + f", limited by {_names(detail['limiting'])}")


def _grounded(lines) -> str | None:
    """The import report's note on a model that joins no link to the world (its canonical link held fixed), if any."""
    return next((line.strip() for line in lines if GROUNDED in line), None)


def _point_away(lines) -> str | None:
    """From a converted file's report, its point output when it lies away from the frame the output was named by
    (further than the file's rounding: ``the point where the chains meet on body ..., 0.0158 m in the plane from frame
    ...``, where one at the frame reads ``at frame ...``); else None."""
    found = re.search(r"output (the point where the chains meet on body .*? from frame '[^']*')", lines[0]) \
        if lines else None
    return found.group(1) if found else None


def print_report(report: dict) -> None:
    """The indices at one pose as text (from :meth:`screwkit.indices.results.Indices.to_dict`)."""
    pose = ", ".join(f"{k} = {v:g}" for k, v in report["pose"].items())
    if report.get("at_file"):  # a graph at the file's configuration (or --initial's): where its output frame is there
        pose = f"{report['at_file']} ({pose})" if pose else report["at_file"]
    redundancy = report.get("redundancy", len(report["actuators"]) - report["dof"])
    guessed = " (guessed: the file names none; --actuate names them)" if report.get("actuators_guessed") else ""
    grounded = f"; {report['base_guessed']}" if report.get("base_guessed") else ""
    count = len(report["actuators"])
    click.echo(f"{report['mechanism']}: {count} actuator{'' if count == 1 else 's'}{guessed}, {report['dof']} DOF "
               f"({f'{redundancy} redundant' if redundancy else 'no redundancy'}), at {pose}{grounded}")
    moved = _point_away(report.get("converted", []))
    if moved:  # the pose is the meeting point's, not the named (or found) frame's: said beside it, not only at the end
        click.echo(f"  output: {moved} (--output-type frame: the frame's)")
    if report.get("dependent"):
        click.echo("  dependent (parasitic) coordinates: "
                   + ", ".join(f"{k} = {v:.6g}" for k, v in report["dependent"].items()))
    if report.get("constraint_singular"):
        click.echo(f"  CONSTRAINT SINGULARITY: {report['instantaneous_dof']} instantaneous DOF at this pose, "
                   f"mobility {report['dof']}")
    modes = report.get("working_mode", {})
    if modes:
        if len(set(modes.values())) == 1:
            click.echo(f"  working mode: every chain {next(iter(modes.values()))}")
        else:
            click.echo("  working mode: " + "; ".join(f"{chain} {mode}" for chain, mode in modes.items()))
    for passed in report.get("singular_on_the_way", []):
        at = ", ".join(f"{k} = {v:.6g}" for k, v in passed["pose"].items())
        click.echo(f"  NOTE: on the straight way from the reference pose, chain {passed['chain']}'s joints are "
                   f"singular at {at}: two of its assemblies meet there, and this one keeps the reference's "
                   f"working-mode sign, {OTHER_ASSEMBLY} (--initial JOINT VALUE on each actuator assembles the other)")
    configuration = report.get("configuration", {})
    if configuration:
        actuated = [f"{name} = " + (_slide(entry["value"]) if entry["unit"] == "m" else
                                    f"{entry['value'] + 0.0:.3f}") + f" {entry['unit']}"
                    for name, entry in configuration.items() if entry["actuated"]]
        click.echo("  actuators: " + ", ".join(actuated))
    click.echo("")
    click.echo("ITI per actuator (Eq. 6)")
    lowest = report.get("iti_lowest") or [min(report["iti_actuators"], key=report["iti_actuators"].get)]
    mark = "  <- lowest" + (" (tied)" if len(lowest) > 1 else "")
    for name, value in report["iti_actuators"].items():
        click.echo(f"  {name:<32s} {value:.4f}{mark if name in lowest else ''}")
    click.echo(f"ITI  (Eq. 7)                        {report['iti']:.4f}")
    click.echo(f"LMTI (Eq. 11, all actuators)        {report['lmti']:.4f}")
    if "lmti_detail" in report:
        click.echo(f"  {_limiting(report['lmti_detail'])}")
        others = report["lmti_detail"]["oti_actuators"]
        if others:
            click.echo("  OTI per actuator there (Eq. 8): " + ", ".join(f"{k} {v:.4f}" for k, v in others.items()))
    if not redundancy:
        click.echo("No redundancy (a = n): any failed actuator leaves the platform uncontrolled, so F_O1 = F_IO1 = 0.")
    else:
        if report["fault_type"] != "free-swinging":
            click.echo(f"Faults: {report['fault_type']} failures")
        ties = report.get("worst_fault_ties", {})
        for j in report["f_o"]:
            worst = _ties(ties[j]) if ties.get(j) else _names(report["worst_faults"].get(j, []))
            click.echo(f"F_O{j:<2s}(Eq. 12) {report['f_o'][j]:.4f}   F_IO{j:<2s}(Eq. 14) {report['f_io'][j]:.4f}"
                       f"   worst fault: {worst}")
            detail = report.get("fault_detail", {}).get(j)
            if detail and "submechanism" in detail:
                click.echo(f"  after it: {_limiting(detail)}")
    if report["cti"] == "not applicable":
        click.echo(f"CTI  not applicable: {report['cti_reason']}")
    else:
        click.echo(f"CTI  (constraint transmission)      {report['cti']:.4f}")
        for j, value in report.get("f_c", {}).items():
            click.echo(f"F_C{j:<2s}(worst CTI, {j} fault(s))      {value:.4f}")
    for record in INDICES.values():  # indices added to the registry: every value, generically
        if record.compute is None or record.name not in report:
            continue
        values = report[record.name]
        for j, value in (values.items() if isinstance(values, dict) else [("", values)]):
            shown = "n/a" if value is None or isinstance(value, str) else f"{value:.4f}"
            click.echo(f"{record.label}{j} ({record.equation}) {shown}")
    if not redundancy:
        click.echo("Every actuator is needed: none can fail with the platform still held (no mutual interference).")
    elif report["not_mutual_interference"]:
        click.echo("Not mutual-interference actuators (every F_Oj is 0): "
                   + ", ".join(report["not_mutual_interference"]))
    else:
        click.echo("All actuators are mutual-interference actuators.")


def actuator_numbers(text: str, names, slides) -> list[float]:
    """The values ``--actuators`` gives (deg for a hinge, m for a slide; one per actuator of ``names``, ``slides``
    saying which slide) in rad and m, each checked: numbers, as many as actuators, finite, angles within 100 turns."""
    try:
        values = [float(word) for word in text.split()]
    except ValueError:
        raise fail(f"Expected numbers after --actuators, got {text!r}.") from None
    if len(values) != len(names):
        raise fail(f"Expected --actuators with {len(names)} value{'s' * (len(names) != 1)} (one per actuator: "
                   f"{', '.join(names)}), got {len(values)}.")
    for name, value, slide in zip(names, values, slides):  # as --pose: finite, angles within 100 turns
        if not np.isfinite(value):
            raise fail(f"Expected finite values after --actuators, got {value} for {name}.")
        if not slide and abs(value) > angle_limit(degrees=True):
            raise fail(str(angle_beyond_limit(f"--actuators ({name})", value, degrees=True)))
    return [value if slide else float(np.deg2rad(value)) for value, slide in zip(values, slides)]


def pose_from_actuators(mechanism, text: str, start):
    """The task pose where every actuator has the value given (deg or m), found from ``start``."""
    names = mechanism.actuator_names
    values = actuator_numbers(text, names, [mechanism.chains[c].prismatic[k] for c, k in
                                            mechanism.actuator_positions()])
    solution, found = forward_from_starts(mechanism, values, start)
    if not bool(np.asarray(solution.reachable).reshape(-1)[0]):
        if found:  # (several with the reference's modes)
            raise fail(f"The actuator values of {mechanism.name!r} are not reached from the start pose, and {found}: "
                       "give a start near the one meant with --pose.")
        agree = "redundant actuators must agree with one another, and " if len(names) > mechanism.dof else ""
        raise fail(f"No closed pose of {mechanism.name!r} has these actuator values near the start pose "
                   f"({agree}the pose may lie on another assembly, past a singular configuration from the start, or "
                   "out of reach; give another start with --pose, or for a file of another tool --initial on each "
                   "actuator).")
    return np.asarray(solution.poses).reshape(-1)


@click.command()
@mechanism_argument
@click.option("--pose", cls=GreedyOption, metavar="VALUES|NAME",
              help="Platform pose: x y phi (planar) or x y z roll pitch yaw, in m and deg, or a named pose "
                   "(screwkit info lists them). Default: the file's home pose. Legs with loops inside them: as many "
                   "values as it has task coordinates (screwkit info lists them; the others follow), else the output "
                   "frame's x y z [roll pitch yaw] (3 or 6 values).")
@click.option("--actuators", "actuator_values", cls=GreedyOption, metavar="VALUES",
              help="Pose given by every actuator's value instead (deg for revolute, m for prismatic, in the order "
                   "screwkit info lists them): forward kinematics from --pose (default home), whose working mode "
                   "it keeps; where that finds no pose, from starts about the reference pose, the one pose in "
                   "the reference's working and assembly modes (up to three task coordinates).")
@analysis_options(closed_forms=False, average=True)
@reading_options
@json_option
def analyze(mechanism: str, pose, actuator_values, analysis, reading, as_json: bool) -> None:
    """Every index (ITI, LMTI, F_Oj, F_IOj, worst faults, CTI) of MECHANISM at one pose (with --aggregate mean,
    also the average case of F_Oj over the failures)."""

    loaded = load_mechanism(mechanism, reading, graphs=True, limits=analysis.limits, batches=False)  # one pose
    check_average(analysis, loaded)
    with analysis.indices():  # the average case registered, if asked, for the report
        _analyze(loaded, pose, actuator_values, analysis, as_json)


def _analyze(loaded, pose, actuator_values, analysis, as_json: bool) -> None:
    """The body of :func:`analyze` on a loaded mechanism."""
    if not isinstance(loaded, Mechanism):  # a GraphMechanism: legs with loops inside them
        return _analyze_graph(loaded, pose, actuator_values, analysis, as_json)
    target = parse_pose(loaded, pose)
    if actuator_values is not None:
        target = pose_from_actuators(loaded, actuator_values, target)
    try:
        result = indices_at_pose(loaded, target, threshold=analysis.threshold, limits=analysis.limits,
                                 fault_type=analysis.fault_type)
    except ValueError as error:
        raise fail(str(error)) from None
    report = result.to_dict()
    passed = singular_on_the_way(loaded, target) if pose is not None or actuator_values is not None else []
    if passed:  # the working mode's sign kept past a configuration where two assemblies of a chain meet
        report["singular_on_the_way"] = [
            {"chain": chain, "pose": {name: shown_number(name, value, loaded.length_scale)
                                      for name, value in zip(loaded.task_coordinates, at)}} for chain, at in passed]
    if loaded.assembly_notes:  # the file's loops were open as written (also said on stderr when loading)
        report["assembly"] = list(loaded.assembly_notes)
    if loaded.import_report:  # a file of another tool: which body and which point the indices are for
        report["converted"] = list(loaded.import_report)
        report["actuators_guessed"] = any(GUESSED in line for line in loaded.import_report)
        report["base_guessed"] = _grounded(loaded.import_report)
    if as_json:
        click.echo(json.dumps(report))
    else:
        print_report(report)
    for number, line in enumerate([] if as_json else loaded.import_report):  # (with --json: its "converted")
        click.echo(f"(converted from {line})" if number == 0 else f" {line}", err=True)


def _slide(value: float) -> str:
    """A slide's value as printed: to the micrometre, or to 6 significant digits below a millimetre (a slide of a
    micrometre robot read 0.000000 m), round-off below a femtometre (a slide at 0) as 0."""
    value = 0.0 if abs(value) < 1e-15 else value + 0.0
    return f"{value:.6f}" if abs(value) >= 1e-3 else f"{value:.6g}"


def _analyze_graph(graph, pose: str | None, actuator_values: str | None, analysis, as_json: bool) -> None:
    """``analyze`` of a mechanism whose legs have loops inside them: at the file's configuration, at ``--pose`` given
    as its task coordinates (m, deg; the dependent ones wherever the closures put them, as in a map), or with the
    output frame at ``--pose x y z [roll pitch yaw]`` (m, deg; the world frame, the file's orientation by default);
    then, with ``--actuators``, where the actuators take the values given, reached from there by continuation."""
    try:
        graph.check_study(fault_type=analysis.fault_type)
    except ValueError as error:
        raise fail(str(error)) from None
    shown = {}
    if pose is not None:
        try:
            values = [float(word) for word in pose.split()]
        except ValueError:
            values = []
        if len(values) not in (graph.n_task, 3, 6) or not np.all(np.isfinite(values)):
            raise fail(f"{graph.tree.source}: its legs have loops inside them: --pose takes its task coordinates "
                       f"{' '.join(graph.task_coordinates)} (m, deg), or the output frame's x y z (m) and optionally "
                       f"roll pitch yaw (deg), got {pose!r}.")
        if len(values) == graph.n_task:  # the task coordinates, as map and sweep take them: the dependent ones follow
            graph, shown = _graph_at_task_pose(graph, values, analysis.limits), dict(zip(graph.task_coordinates,
                                                                                         values))
        else:  # the output frame's position, its orientation given or the one it has
            for angle in values[3:]:
                if abs(angle) > angle_limit(degrees=True):
                    raise fail(str(angle_beyond_limit("--pose", angle, degrees=True)))
            rpy = np.radians(values[3:]) if len(values) == 6 else None
            try:
                graph = graph.at_pose(values[:3], rpy, limits=analysis.limits)
            except ValueError as error:
                raise fail(str(error)) from None
            shown = dict(zip(("x", "y", "z", "roll", "pitch", "yaw"), values))
    if actuator_values is not None:
        graph = _graph_at_actuators(graph, actuator_values, analysis.limits)
        shown = {name: shown_number(name, value, graph.length_scale)
                 for name, value in zip(graph.task_coordinates, graph.task_pose())}
    try:
        result = graph.indices(threshold=analysis.threshold, fault_type=analysis.fault_type)
    except ValueError as error:
        raise fail(str(error)) from None
    at_file = not shown  # the file's configuration: its output frame's task coordinates in the JSON, as given ones are
    if at_file:
        shown = {name: shown_number(name, value, graph.length_scale)
                 for name, value in zip(graph.task_coordinates, graph.task_pose())}
    report = {**result.to_dict(), "mechanism": graph.name, "pose": shown, "converted": graph.report.lines()}
    report["actuators_guessed"] = any(GUESSED in line for line in report["converted"])
    report["base_guessed"] = _grounded(report["converted"])
    if as_json:
        click.echo(json.dumps(report))
    else:
        started = ", ".join(f"--initial {name} {value:g}" for name, value in graph.tree.initial)
        print_report({**report, "at_file": at_file and (f"the configuration assembled from {started}" if started
                                                        else "the file's configuration")})
        click.echo(f"(analysed as a graph from {graph.report.lines()[0]})", err=True)


def _graph_at_actuators(graph, text: str, limits: bool):
    """The graph with its actuators at the values of ``--actuators`` (deg for a hinge, m for a slide, in the order
    ``info`` lists them), by continuation from its configuration (:meth:`GraphMechanism.at_actuators`)."""
    values = actuator_numbers(text, graph.actuators, graph.actuator_slides)
    try:
        return graph.at_actuators(values, limits=limits)
    except ValueError as error:
        raise fail(str(error)) from None


def _graph_at_task_pose(graph, values: list[float], limits: bool):
    """The graph closed with its task coordinates at ``values`` (m, deg), its dependent (parasitic) ones wherever the
    closures put them, reached by continuation from the file's configuration (as :meth:`GraphMechanism.solve` solves
    the poses of a map)."""
    from screwkit.io.graph import graph_mechanism  # the graph reader: when a graph is analysed

    try:
        task = graph.poses_from_degrees(values, where="--pose")
    except ValueError as error:
        raise fail(str(error)) from None
    q, reached = graph.solve(task[None], limits=limits)
    if not reached[0]:
        raise fail(graph.unreachable(task, limits=limits)[1] + ".")
    try:
        return graph_mechanism(graph.tree, q=q[0], scale=graph.scale)
    except ValueError as error:
        raise fail(str(error)) from None
