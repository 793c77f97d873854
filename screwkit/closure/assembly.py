"""The reference assembly of a mechanism: closed loops, working modes, solvers and mobility.

:func:`assemble` takes a mechanism model whose chains were read from a file (geometry,
joints, actuators) and derives, once, what closure solving needs: each chain's joint values
at the reference assembly (checking that its loop closes there), the closed-form solver that
fits it (or why none does) and the working mode (branch) that reproduces the reference
assembly, and the platform's DOF. Every problem is a one-line ValueError naming the file, the
element and what was found.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.analytic import closed_form_for
from screwkit.closure.chain_kinematics import (
    chain_forward_kinematics,
    twists_from_axes_and_points,
    wrap_revolute_values,
)
from screwkit.closure.modes import describe_modes, meeting_modes, small_steps, values_at
from screwkit.closure.newton import file_fit, newton_solve_chain, task_rows, with_point_signs, working_sign
from screwkit.closure.point_turns import check_turns
from screwkit.closure.solve import outside_limits, run_closed_form, solve
from screwkit.closure.task_space import (
    TASK_RANK_TOLERANCE,
    chain_ranks,
    close_constraining_chains,
    constraining_chains,
    infer_task_axes,
    motion_space_at,
    singular_chains,
)
from screwkit.common.rotations import wrap_angle
from screwkit.common.tolerances import (
    BRANCH_MATCH_TOLERANCE,
    CLOSURE_TOLERANCE,
    FILE_ROUNDING,
    MOTION_SPACE_TOLERANCE,
    NEWTON_TOLERANCE,
)
from screwkit.model.chain import Chain
from screwkit.model.mechanism import Mechanism
from screwkit.model.urdf_description import initial_remedy

__all__ = ["assemble", "mobility", "mobility_notes", "rounded_dof_note", "working_modes", "mechanism_size",
           "LIMITS_IGNORED", "DOF_AT_ROUNDING", "DRAWN_AT_ROUNDING", "DOF_MARGIN", "MODES_MEET", "NOT_OPEN_LOOPS"]


LIMITS_IGNORED = "limits ignored: "
"""How a note of :attr:`~screwkit.model.mechanism.Mechanism.assembly_notes` that is not an open loop starts: a
reference assembly outside a joint's limits, read with ``limits=False``."""
DOF_AT_ROUNDING = "DOF decided at the file's rounding: "
"""How a note of :attr:`~screwkit.model.mechanism.Mechanism.assembly_notes` starts that says the DOF count turns on
a singular value of the order of a file's rounding (:func:`mobility_notes`)."""
DRAWN_AT_ROUNDING = "drawn to the file's rounding: "
"""How a note starts that says what :func:`screwkit.io.drawn_loops.drawn_loops` idealised (axes, loop frames)."""
MODES_MEET = "operation modes: "
"""How a note of :attr:`~screwkit.model.mechanism.Mechanism.assembly_notes` starts that names the operation modes
meeting at a constraint-singular reference assembly and the one followed
(:func:`screwkit.closure.modes.describe_modes`)."""
GENERIC_SAMPLES = 6
"""Random samples near the reference assembly from which the mobility is read (:func:`_generic_samples`); when one
does not close, or the reference assembly is a constraint singularity, :func:`_mode_samples` adds more."""
MODE_SAMPLES = 12
"""Samples added near a constraint-singular reference assembly to find the operation modes that meet there, of each
kind (:func:`_mode_samples`)."""
NOT_OPEN_LOOPS = (LIMITS_IGNORED, DOF_AT_ROUNDING, DRAWN_AT_ROUNDING, MODES_MEET)
"""The starts of the notes of :attr:`~screwkit.model.mechanism.Mechanism.assembly_notes` that are not open loops."""
DOF_MARGIN = float(np.sqrt(FILE_ROUNDING))
"""Relative: a singular value counted by :func:`mobility` (above :data:`MOTION_SPACE_TOLERANCE`) but at most this is
of the order of a file's rounding rather than of its geometry: the geometric middle of :data:`FILE_ROUNDING` and 1.
Every bundled and published mechanism read so far has its smallest at 0.01 or more; a spherical manipulator whose axes
miss their centre by 1.3e-5 of its size (beyond what is idealised on reading) has one at 1.5e-5."""

def _tidy(value: float) -> str:
    """A number for messages: 6 significant digits, round-off below 1e-12 shown as 0."""
    value = float(value)
    return "0" if abs(value) < 1e-12 else f"{value:.6g}"


def mechanism_size(mechanism: Mechanism, chains: tuple[Chain, ...]) -> float:
    """The largest distance of a joint of the reference assembly, or the platform, from the centroid of the chains'
    base joints: the mechanism's own size, the same in any world frame and in any order of its chains (the base
    frame's origin, which files put anywhere, is not one of its points)."""
    points, base = [mechanism.home_translation[None]], []
    for chain in chains:
        geometry = chain.geometry
        tree = np.array([mechanism.description.reference_configuration.get(name, 0.0)
                         for name in chain.joint_names[: geometry.n_tree_joints]])
        frames = chain_forward_kinematics(geometry, np.concatenate([tree, np.zeros(geometry.n_dofs - tree.size)]))
        points.append(frames.points)
        points.append(frames.leg_translation[None])
        base.append(frames.points[:1])
    centre = np.mean(np.concatenate(base), axis=0)
    return max(float(np.max(np.linalg.norm(np.concatenate(points) - centre, axis=-1))), 1e-12)


def _reference_values(mechanism: Mechanism, index: int, chain: Chain, length_scale: float,
                      limits: bool = True) -> tuple[NDArray[np.float64], list[str]]:
    """Joint values of the reference assembly, and notes: when the file's values left the loop open, and (with
    ``limits`` False) when they are outside a joint's limits.

    The file's tree joint values (``<reference_configuration>`` or 0) with the loop joint's best
    fit; when the loop frames stay apart (a CAD export, a hand-edited file), the leg's joints are
    moved to close it with the platform where the file puts it (damped Newton from those values,
    so the working mode is usually the nearest one) and the gap closed is returned as a note. A ValueError
    names the loop when it cannot be closed, or the joint the assembly puts outside its limits (with ``limits``
    False that is a note instead).
    """
    description, geometry = mechanism.description, chain.geometry
    values, _, position_gap, rotation_gap = file_fit(mechanism, index)
    target_rotation, target_translation = mechanism.loop_targets(index, mechanism.home_rotation,
                                                                 mechanism.home_translation)
    note = None
    if position_gap > CLOSURE_TOLERANCE * length_scale or rotation_gap > CLOSURE_TOLERANCE:
        scale = np.where(np.asarray(geometry.dof_prismatic), length_scale, 1.0)
        solved, converged, residual = newton_solve_chain(geometry, target_rotation[None], target_translation[None],
                                                         values[None], tolerance=NEWTON_TOLERANCE, max_iterations=200,
                                                         length=length_scale)
        if not converged[0]:
            raise description.fail(
                f"<loop name='{chain.loop_name}'>",
                f"does not close at the reference configuration: the loop frames are {_tidy(position_gap)} m and "
                f"{_tidy(rotation_gap)} rad apart (tree joints at their <reference_configuration> values or 0, "
                f"platform at its joint origin), and moving the chain's joints leaves them {_tidy(residual[0])} "
                "(m and rad) apart.",
            )
        most = int(np.argmax(np.abs(solved[0] - values) / scale))
        change = float(solved[0][most] - values[most])
        values = solved[0]
        unit = "m" if geometry.dof_prismatic[most] else "rad"
        note = (f"loop {chain.loop_name!r} was {_tidy(position_gap)} m and {_tidy(rotation_gap)} rad open at the "
                f"file's joint values: closed by moving the joints of chain {chain.name!r} (most: "
                f"{chain.joint_names[most]!r} by {_tidy(change)} {unit})")
    values = wrap_revolute_values(geometry, values)
    outside = int(outside_limits(chain.joint_limits, chain.prismatic, values[None], length_scale)[0])
    if outside >= 0:
        lower, upper = chain.joint_limits[outside]
        where = (f"the reference assembly puts the joint at {_tidy(values[outside])}, outside its "
                 f"limits [{_tidy(lower)}, {_tidy(upper)}]")
        if limits:
            name = chain.joint_names[outside]
            degrees = "" if chain.prismatic[outside] else f" ({np.degrees(lower):.6g} to {np.degrees(upper):.6g} deg)"
            start = (f"; --initial JOINT VALUE on this joint{degrees} or on the one driving it, in place of another "
                     "value given, starts the assembly inside them" if description.converted_from else "")
            raise description.fail(f"<joint name='{name}'>",
                                   f"{where} (--ignore-limits, or limits=False, reads it all the same{start}).")
        limit_note = f"{LIMITS_IGNORED}joint {chain.joint_names[outside]!r}: {where}"
        return values, [n for n in (note, limit_note) if n]
    return values, [note] if note else []


def _check_planar(mechanism: Mechanism, chain: Chain, values: NDArray) -> None:
    frames = chain_forward_kinematics(chain.geometry, values)
    for name, axis, prismatic in zip(chain.joint_names, frames.axes, chain.prismatic):
        along_normal = abs(axis[2])
        if ((prismatic and along_normal > CLOSURE_TOLERANCE)
                or (not prismatic and abs(along_normal - 1.0) > CLOSURE_TOLERANCE)):
            raise mechanism.description.fail(
                f"<loop name='{chain.loop_name}'>",
                f"the platform moves in the base x-y plane (planar joint {mechanism.platform_joint!r}) but joint "
                f"{name!r} of this chain is not a planar joint (revolute about z or prismatic in x-y).",
            )


def _matching_branch(mechanism: Mechanism, index: int, solver) -> tuple[int, ...] | None:
    """The closed-form branch closest to the reference assembly, if it reproduces it (else None)."""
    chain = mechanism.chains[index]
    prismatic = np.asarray(chain.geometry.dof_prismatic)
    branches = [tuple(1 if (code >> bit) & 1 == 0 else -1 for bit in range(solver.n_branches))
                for code in range(2**solver.n_branches)]
    if solver.planar:  # one working mode at a time
        probe = replace(mechanism, chains=mechanism.chains[:index] + (replace(chain, closed_form=solver),)
                        + mechanism.chains[index + 1:])
        results = [run_closed_form(probe, index, mechanism.home_full_pose[None], branch) for branch in branches]
        reachable = [bool(result.reachable[0]) for result in results]
        values = [(result.values() if callable(result.values) else result.values)[0] for result in results]
    else:  # every working mode in one batch: the home pose once per mode
        poses = np.repeat(mechanism.home_full_pose[None], len(branches), 0)
        result = solver.solve(*mechanism.loop_targets(index, *mechanism.transforms_from_poses(poses)),
                              np.array(branches, dtype=float))
        reachable, values = list(result.reachable), list(result.values)
    best, closest = None, np.inf
    for branch, closed, value in zip(branches, reachable, values):
        if not closed:
            continue
        difference = value - chain.reference_values
        difference[~prismatic] = wrap_angle(difference[~prismatic])
        difference[prismatic] /= mechanism.length_scale
        distance = float(np.max(np.abs(difference), initial=0.0))
        if distance < closest:
            best, closest = branch, distance
    return best if closest < BRANCH_MATCH_TOLERANCE else None


def mobility(mechanism: Mechanism, chains: tuple[Chain, ...]) -> int:
    """DOF of the platform at the reference assembly: the dimension of the intersection of the chains' twist spaces.

    Twists are taken about the centroid of the platform joints with lengths in units of the chains' own size (the
    root-mean-square distance of their joints from that centroid), so the count does not depend on the unit or the
    frame (the mechanism's length scale was once the distance from the base's origin, and grew with it)."""
    return _mobility(mechanism, chains)[0]


def _mobility(mechanism: Mechanism, chains: tuple[Chain, ...]) -> tuple[int, list[tuple[str, NDArray]]]:
    """:func:`mobility`, and the singular values it counted of each chain's twists (named by the chain; each twist
    scaled to unit norm, relative to the largest: a slide's twist is otherwise one over the length scale, and a
    chain of slides and hinges drawn small would read as nearly dependent) and of the chains' stacked complements
    (named ""; orthonormal rows)."""
    rows = task_rows(mechanism.is_planar)
    frames = [chain_forward_kinematics(chain.geometry, chain.reference_values) for chain in chains]
    centre = np.mean([f.points[-1] for f in frames], axis=0)
    offsets = np.concatenate([f.points - centre for f in frames])
    size = float(np.sqrt(np.mean(np.sum(offsets**2, axis=1)))) or mechanism.length_scale  # (all at one point: any)
    complements, smallest = [], []
    for chain, chain_frames in zip(chains, frames):
        twists = twists_from_axes_and_points(chain_frames.axes, chain_frames.points - centre, chain.prismatic)
        twists = np.concatenate([twists[:, :3], twists[:, 3:] / size], axis=-1)[:, rows].T
        left, singular, _ = np.linalg.svd(twists)
        largest = max(1.0, singular[0] if singular.size else 1.0)
        rank = int(np.sum(singular > MOTION_SPACE_TOLERANCE * largest))
        complements.append(left[:, rank:].T)
        units = np.linalg.svd(twists / np.maximum(np.linalg.norm(twists, axis=0), 1e-300), compute_uv=False)
        smallest.append((chain.name, units[:rank] / max(units[0] if units.size else 1.0, 1e-300)))
    stacked = np.concatenate(complements, axis=0)
    if stacked.size == 0:
        return len(rows), smallest
    singular = np.linalg.svd(stacked, compute_uv=False)
    rank = int(np.sum(singular > MOTION_SPACE_TOLERANCE))
    smallest.append(("", singular[:rank]))
    return len(rows) - rank, smallest


def mobility_notes(mechanism: Mechanism, chains: tuple[Chain, ...]) -> tuple[int, list[str]]:
    """:func:`mobility`, and a note (:data:`DOF_AT_ROUNDING`) for each count that turns on singular values at most
    :data:`DOF_MARGIN`: a chain whose joint screws are independent only to the order of a file's rounding (written
    exactly, it may have fewer freedoms), or constraints of the chains independent of each other only so far
    (written exactly, the platform may have more DOF: axes meant to meet or to be parallel, written rounded)."""
    dof, counted = _mobility(mechanism, chains)
    notes = []
    for name, values in counted:
        small = values[values <= DOF_MARGIN]
        if not small.size:
            continue
        if name:
            notes.append(f"{DOF_AT_ROUNDING}chain {name!r}: its joint screws are independent only to "
                         f"{small.min():.2g} (relative), the order of a file's rounding (or the reference assembly is "
                         f"that near a singularity of the chain); written exactly, it may have up to {small.size} "
                         "freedom(s) fewer")
        else:
            notes.append(rounded_dof_note(dof, small, "chains"))
    return dof, notes


def rounded_dof_note(dof: int, small: NDArray, legs: str) -> str:
    """The :data:`DOF_AT_ROUNDING` note of a platform whose ``legs``' constraints are independent of each other only
    to the singular values ``small`` (each at most :data:`DOF_MARGIN`)."""
    return (f"{DOF_AT_ROUNDING}{dof} DOF, with the {legs}' constraints independent of each other only to "
            f"{np.min(small):.2g} (relative), the order of a file's rounding (or the reference assembly is that near "
            f"a constraint singularity); written exactly (axes meant to meet or to be parallel written so), the "
            f"platform may have up to {dof + len(small)} DOF")


def assemble(mechanism: Mechanism, limits: bool = True) -> Mechanism:
    """The mechanism with its reference assembly, solvers, working modes, length scale and DOF.

    ``mechanism`` holds chains as read from the file (geometry, joints, limits, actuators);
    the result is the complete, immutable model. ``limits`` False: a reference assembly outside a joint's
    limits is a note of :attr:`~screwkit.model.mechanism.Mechanism.assembly_notes`, not an error.
    """
    length_scale = mechanism_size(mechanism, mechanism.chains)
    mechanism = replace(mechanism, length_scale=length_scale)
    chains, notes = [], []
    for index, chain in enumerate(mechanism.chains):
        values, chain_notes = _reference_values(mechanism, index, chain, length_scale, limits)
        notes += chain_notes
        if mechanism.is_planar:
            _check_planar(mechanism, chain, values)
        frames = chain_forward_kinematics(chain.geometry, values)
        chains.append(replace(chain, reference_values=values, reference_sign=working_sign(mechanism, index, frames)))
    mechanism = replace(mechanism, chains=tuple(chains), assembly_notes=mechanism.assembly_notes + tuple(notes))
    solved = []
    for index, chain in enumerate(mechanism.chains):
        solver, reason = closed_form_for(chain.geometry, mechanism.is_planar, length_scale)
        branch = None
        if solver is not None:
            branch = _matching_branch(mechanism, index, solver)
            if branch is None:
                reason = (f"damped Newton: {solver.kind} fits the chain's joints but none of its working modes "
                          "reproduces the reference assembly")
                solver = None
        if solver is None:
            branch = chain.reference_sign
        solved.append(replace(chain, closed_form=solver, branch=branch, solver=solver.kind if solver else "newton",
                              solver_reason=reason))
    dof, notes = mobility_notes(mechanism, tuple(solved))
    mechanism = replace(mechanism, chains=tuple(solved), assembly_notes=mechanism.assembly_notes + tuple(notes))
    return replace(mechanism, dof=dof)


def point_dof(mechanism: Mechanism, full_pose, joint_values, dof: int) -> int:
    """DOF of a point output (the platform frame's origin): the dimension of the velocities the point has
    over the platform's ``dof``-dimensional motion space at a closed configuration. The rotations about
    the point that the platform can perform add nothing; a platform that cannot rotate about it (a
    five-bar's distal link) loses nothing."""
    _, basis = motion_space_at(mechanism, np.asarray(full_pose)[None], [np.asarray(v)[None] for v in joint_values])
    translations = basis[0][~mechanism.pose_angular][:, :dof]
    singular = np.linalg.svd(translations, compute_uv=False)
    return int(np.sum(singular > TASK_RANK_TOLERANCE))


def _locking_chains(mechanism: Mechanism, full_pose, joint_values) -> str:
    """What a DOF-0 refusal adds: the chains each of which, left out, lets the platform move (a loop whose joints'
    axes are not quite aligned, as a CAD export or a cambered axle writes them: the others would move it)."""
    if len(mechanism.chains) < 2:
        return ""
    locking = []
    for left_out in range(len(mechanism.chains)):
        kept = [k for k in range(len(mechanism.chains)) if k != left_out]
        others = replace(mechanism, chains=tuple(mechanism.chains[k] for k in kept))
        dofs, _ = motion_space_at(others, np.asarray(full_pose)[None],
                                  [np.asarray(joint_values[k])[None] for k in kept])
        if dofs[0] >= 1:
            chain = mechanism.chains[left_out]  # (a converted file's loop joints are its closure's, not joints)
            joints = [name for name in chain.joint_names
                      if not (mechanism.description.converted_from and name.startswith(f"{chain.name}_loop"))]
            joints = f"joint{'s' if len(joints) > 1 else ''} {', '.join(joints)}" if joints else "its closure's joint"
            locking.append((f"{chain.name} ({joints})", int(dofs[0])))
    if not locking:
        return "; no one chain locks it: without any one of them it still cannot move"
    rigid = ("a loop with no motion: a structure, or a joint axis slightly out of line with the rest of its loop "
             "(as a CAD export's rounding or a cambered axle writes it); the file is read as written")
    if len(locking) == len(mechanism.chains):
        return (f"; any one chain left out, the others would let it move (chains "
                f"{', '.join(name for name, _ in locking)}): {rigid}")
    without = " or ".join(f"without chain {name} it would move ({dof} DOF)" for name, dof in locking)
    return f"; {without}: {rigid}"


def idle_rotation_count(mechanism: Mechanism) -> int:
    """Rotations of the platform about a point output (none for a frame output): 1 planar, 3 spatial."""
    return 0 if mechanism.output_point is None else (1 if mechanism.is_planar else 3)


def _generic_samples(mechanism: Mechanism, count: int = GENERIC_SAMPLES, seed: int = 0, moving=None):
    """Closed configurations near the reference assembly, off any special pose: random small full-pose
    offsets (of the pose coordinates ``moving``, a mask; every one by default), each brought back onto the closure by
    the least change of every pose coordinate."""
    chains = constraining_chains(mechanism)
    rng = np.random.default_rng(seed)
    offsets = rng.uniform(-1.0, 1.0, (count, mechanism.n_pose)) * np.where(
        mechanism.pose_angular, 0.05, 0.05 * mechanism.length_scale) * (1.0 if moving is None else moving)
    poses = mechanism.home_full_pose + offsets
    values = [np.broadcast_to(mechanism.chains[i].reference_values, (count, mechanism.chains[i].n_joints))
              for i in chains]
    poses, values, converged, _ = close_constraining_chains(mechanism, chains, poses, values,
                                                      tuple(range(mechanism.n_pose)), 1e-11, 60, 0.5)
    return chains, poses[converged], [v[converged] for v in values]


def _mode_samples(mechanism: Mechanism, poses, values):
    """The generic samples ``poses``, ``values`` and more, to find the operation modes meeting at the reference
    assembly: :data:`MODE_SAMPLES` random ones, and as many offset in the translations alone and in the rotations
    alone (a mode that keeps the platform's orientation is found by the first whatever the random ones find)."""
    angular = np.asarray(mechanism.pose_angular, dtype=bool)
    more = [_generic_samples(mechanism, MODE_SAMPLES, seed=1),
            _generic_samples(mechanism, MODE_SAMPLES, seed=2, moving=~angular),
            _generic_samples(mechanism, MODE_SAMPLES, seed=3, moving=angular)]
    chains, batches = more[0][0], [(poses, values)] + [batch[1:] for batch in more]
    return (chains, np.concatenate([batch[0] for batch in batches]),
            [np.concatenate([batch[1][k] for batch in batches]) for k in range(len(chains))])


def _check_not_at_dead_centre(mechanism: Mechanism, ranks: list[int]) -> None:
    """Refuse a reference assembly where a chain is stretched or folded (a crank and its rod on one line: its
    joints' twists span less there than at joint values near it): the platform's DOF there is not its mobility (a
    five-bar drawn with a leg stretched read as a redundant 1-DOF mechanism), and the working mode is not decided.
    Names the chains and how to give joint values away from it."""
    chains = singular_chains(mechanism, ranks)
    if not chains:
        return
    description = mechanism.description
    remedy = (initial_remedy(description.converted_from) if description.converted_from else
              "write its <reference_configuration> away from it")
    raise description.fail(f"<robot name='{mechanism.name}'>", f"the reference assembly is a singular configuration: "
                           f"chain{'s' if len(chains) > 1 else ''} {', '.join(chains)} "
                           f"{'are' if len(chains) > 1 else 'is'} stretched or folded there (its joints' twists span "
                           "less than at joint values near it: a dead centre, such as a crank and its rod on one "
                           "line), where the platform moves less than the mechanism does elsewhere and the working "
                           f"mode is not decided; {remedy}.")


def _check_actuator_count(mechanism: Mechanism, needed: int) -> None:
    """At least as many actuators as the output's DOF (its mobility, not the instantaneous DOF at the reference
    assembly: a 3-UPU built at its constraint singularity has 5 there, and its 3 slides drive it)."""
    actuators = mechanism.actuator_names
    if len(actuators) < needed:
        driven = {name.split(":", 1)[-1] for name in actuators}
        passive = list(dict.fromkeys(name for chain in mechanism.chains for name in
                                     chain.joint_names[:chain.geometry.n_tree_joints] if name not in driven))
        held = (f"; or hold a passive joint that moves it, --lock JOINT (an adaptive finger's spring joint; the "
                f"chains' passive joints: {', '.join(passive[:8])}{', ...' if len(passive) > 8 else ''})"
                if mechanism.description.converted_from and passive else "")
        raise mechanism.description.fail(
            f"<robot name='{mechanism.name}'>",
            f"{len(actuators)} actuator(s) ({', '.join(actuators)}) for an output with {needed} DOF: at least "
            f"{needed} are needed (mark the actuated joints: a <transmission> in URDF, an <actuator> in MJCF; or name "
            f"them with --actuate JOINT in a file of another tool{held}).")


def task_space(mechanism: Mechanism, declared: tuple[str, ...] | None = None) -> Mechanism:
    """The mechanism with its mobility, its instantaneous DOF at the reference assembly and its task coordinates.

    The DOF at the reference assembly (:attr:`~Mechanism.dof` as :func:`assemble` found it) is the
    *instantaneous* DOF there; the mechanism's *mobility* is the DOF at generic closed
    configurations near it (the least found at a few). When the reference assembly has more, it
    is a constraint singularity. Task coordinates are the file's ``<task_coordinates>`` when it
    declares them (checked to be independent), else inferred from the motion space at a generic
    configuration (:func:`~screwkit.closure.task_space.infer_task_axes`).
    """
    names = mechanism.pose_coordinates
    idle = idle_rotation_count(mechanism)
    instantaneous = mechanism.dof
    mobility, at_pose, at_values = (instantaneous, mechanism.home_full_pose,
                                    [c.reference_values for c in mechanism.chains])
    ranks = chain_ranks(mechanism)
    _check_not_at_dead_centre(mechanism, ranks)
    chains = constraining_chains(mechanism, ranks)
    modes = []
    if chains:
        chain_indices, poses, values = _generic_samples(mechanism)
        more = not idle and poses.shape[0] < GENERIC_SAMPLES
        if more:  # random offsets that do not close: a mode they miss (a U-P-U platform's translations alone left)
            chain_indices, poses, values = _mode_samples(mechanism, poses, values)
        if poses.shape[0]:
            subset = replace(mechanism, chains=tuple(mechanism.chains[i] for i in chain_indices))
            dofs, _ = motion_space_at(subset, poses, values)
            sample = int(np.argmin(dofs))
            if dofs[sample] < instantaneous:
                mobility = int(dofs[sample])
                at_pose, at_values = poses[sample], values_at(mechanism, chain_indices, values, sample)
                if not idle:  # a constraint singularity: the operation modes that meet there, each tried
                    if not more:
                        chain_indices, poses, values = _mode_samples(mechanism, poses, values)
                    modes = meeting_modes(mechanism, chain_indices, poses, values, mobility)
    frame_mobility = mobility  # (the platform's own; a point output's is fewer where it turns about the point)
    if idle:
        instantaneous = point_dof(mechanism, mechanism.home_full_pose, [c.reference_values for c in mechanism.chains],
                                  instantaneous)
        check_turns(mechanism, at_pose, at_values, mobility)
        mobility = point_dof(mechanism, at_pose, at_values, mobility)
    if mobility < 1 and idle and frame_mobility > 0:
        raise mechanism.description.fail("<output type='point'>", "the output point cannot move: every platform "
                                                                  "motion is a rotation about it.")
    if mobility < 1:  # rigid: its closures leave the platform no motion (as a CAD export's rounding can make them)
        drawn = next((note for note in mechanism.assembly_notes if note.startswith(DRAWN_AT_ROUNDING)), None)
        raise mechanism.description.fail(f"<robot name='{mechanism.name}'>", "the platform cannot move: its chains "
                                         "leave it no motion at the reference assembly (DOF 0)"
                                         + _locking_chains(mechanism, at_pose, at_values)
                                         + ("" if drawn is None else f"; as read, {drawn}: written more exactly, "
                                            "it may move") + ".")
    mechanism = replace(mechanism, dof=mobility, instantaneous_dof=instantaneous)
    _check_actuator_count(mechanism, mobility)
    if modes:
        if declared is not None and len(modes) > 1:  # the mode in which the declared coordinates are independent
            axes = [names.index(name) for name in declared if name in names]
            modes = sorted(modes, key=lambda mode: np.linalg.svd(mode.space[axes], compute_uv=False)[-1]
                           <= TASK_RANK_TOLERANCE)
        at_pose, at_values = modes[0].pose, list(modes[0].values)
        if len(modes) > 1 or modes[0].driven < modes[0].probes:
            mechanism = replace(mechanism, assembly_notes=mechanism.assembly_notes
                                + (MODES_MEET + describe_modes(mechanism, modes),))
    candidates = [i for i, name in enumerate(names) if not (idle and name in ("phi", "roll", "pitch", "yaw"))]
    if declared is not None:
        unknown = [name for name in declared if name not in names]
        if unknown or len(set(declared)) != len(declared):
            raise mechanism.description.fail("<task_coordinates>", f"expected distinct names among {', '.join(names)}, "
                                                                   f"got {' '.join(declared)}.")
        axes = tuple(sorted(names.index(name) for name in declared))
        if any(axis not in candidates for axis in axes):
            raise mechanism.description.fail("<task_coordinates>", "a point output has no orientation coordinate: "
                                                                   "its rotations about the point are idle.")
        subset = replace(mechanism, chains=tuple(c for c in mechanism.chains))
        _, basis = motion_space_at(subset, at_pose[None], [np.asarray(v)[None] for v in at_values])
        singular = np.linalg.svd(basis[0][list(axes)][:, :mobility + idle], compute_uv=False)
        if len(axes) != mobility or (singular.size and singular[-1] <= 1e-6):
            raise mechanism.description.fail(
                "<task_coordinates>", f"{' '.join(declared)} cannot drive a platform of mobility {mobility}: "
                f"they are not {mobility} independent coordinates of its motion.")
        return with_point_signs(replace(mechanism, task_axes=axes, task_source="declared",
                                        held_axes=_held(mechanism, modes, axes)))
    if mobility == mechanism.n_pose:
        return mechanism
    axes = infer_task_axes(mechanism, at_pose, at_values, mobility, candidates)  # (then the signs task axes decide)
    return with_point_signs(replace(mechanism, task_axes=axes, task_source="inferred", held_axes=_held(mechanism, modes,
                                                                                                        axes)))


def _held(mechanism: Mechanism, modes, axes) -> tuple[int, ...]:
    """The dependent angles held at the reference assembly's values: every one, when the operation mode followed
    (the first of ``modes``) does not turn the platform (its least-turning sample has no rotation rate above
    :data:`~screwkit.closure.task_space.TASK_RANK_TOLERANCE`); else none."""
    if not modes or modes[0].turning:
        return ()
    held = tuple(i for i, angle in enumerate(mechanism.pose_angular) if angle and i not in axes)
    # the mode's small steps must close with the orientation held (legs that translate the platform only to a file's
    # rounding would not: they are left to the closure)
    home = mechanism.home_full_pose[list(axes)]
    trial = replace(mechanism, task_axes=tuple(axes), held_axes=held, named_poses={"home": home})
    closed = solve(trial, small_steps(home, trial.angular, mechanism.length_scale), limits=False).reachable
    return held if closed.all() else ()


def working_modes(mechanism: Mechanism) -> dict[str, str]:
    """Per chain, the working mode (branch) its closure keeps, in words: the closed form's branch, or for a
    chain closed by damped Newton the reference assembly's, followed by continuation."""
    modes = {}
    for chain in mechanism.chains:
        if chain.closed_form is not None:
            modes[chain.name] = f"{chain.closed_form.describe_branch(chain.branch)} ({chain.solver})"
        elif chain.branch is not None:
            sign = "joint-twist determinant" if chain.geometry.n_dofs == len(task_rows(mechanism.is_planar)) else \
                "map to the output point"
            modes[chain.name] = (f"the reference assembly's sign of the chain's {sign} ({int(chain.branch):+d}), kept "
                                 "from it (damped Newton)")
        else:
            modes[chain.name] = "the reference assembly's, followed from it (damped Newton)"
    return modes
