"""A file in screwkit's own convention written rounded, read as what its author drew.

A file written by hand or by a tool that rounds (``rpy="1.570796 ..."``, an angle of 0.3238066 written 0.323807)
draws axes meant to be parallel up to 1e-6 rad apart. Read exactly, it is another mechanism: the bundled Delta
(``delta_4.urdf``, Tsai's R-U-U legs) written to 6 decimals read 2 DOF instead of 3 and refused its own home pose;
written to 5 decimals, its first loop did not close (4e-7 rad, which its legs' five joints cannot take up). The
files of other tools are read as drawn where they are converted (:mod:`screwkit.io.rounding`); this is the same
reading of the chains of a file in screwkit's convention, before their canonical points (:mod:`screwkit.closure.
canonical`) and the reference assembly:

1. **Parallel axes.** Every joint axis of every chain, and every axis of a revolute, prismatic or universal loop
   joint, at the file's reference configuration (the loop joints' values fitted to the file's frames; a chain that
   does not close there, where its joints close it, as ``screwkit convert`` writes it back), grouped by
   :func:`~screwkit.io.rounding.parallel_axes` within :data:`~screwkit.common.tolerances.FILE_ROUNDING`. Two axes
   of one chain are grouped within more where the file writes angles rounded between them (``1.5708`` for pi/2:
   :mod:`screwkit.io.written_angles`) only if every hinge between them is parallel to them, so that they are
   parallel whatever its values (:func:`_structural`); two axes parallel at the reference configuration only are
   not given that much: two arms' shoulder hinges, each arm's pan at 0 (a base turn written ``3.14`` turned each
   arm's hinges by 8e-4 rad and moved its ITI by 1.9e-2), or an arm's pan and its second wrist hinge, its middle
   hinges' values summing to zero (1.1e-5 on its ITI). Two axes of two chains that are both fixed in the platform
   (:func:`_fixed_in_platform`: each chain welded onto it, every hinge after the axis parallel to it) are parallel
   whatever the configuration, and are grouped within the rounding of the angles between each and the platform
   (:meth:`~screwkit.io.written_angles.WrittenTurns.to_platform`): the two-arm cell's last wrist hinges, one line
   through the object both arms grasp, came out 1.6e-5 rad apart written to 5 decimals, and F_O2 read 0.454 where
   it is 0. So are two axes of two chains both fixed in the base (:func:`_fixed_in_base`: two legs' motors), to the
   rounding on their ways from it, and a loop joint's axis, to its loop's rounding; these are grouped first
   (:func:`_parallel`). A turned joint's placement turns with it, so that at the
   reference configuration every frame after its motion stays where it was (as
   :func:`~screwkit.io.rounding.turned_joint` does in a converted file): :func:`turned_geometry`.
2. **Loops closed within the rounding.** A chain whose loop its own joints cannot close onto the platform's loop
   frame (damped Newton from the file's values) but leave within ``FILE_ROUNDING`` of it (rad, and lengths over
   the mechanism's size) has the platform's loop frame written where the chain closes: the two frames of a loop
   are one frame, drawn twice. In a file in screwkit's convention its gap in rad is allowed ``FILE_ROUNDING`` plus
   the rounding of the angles around the loop (:meth:`~screwkit.io.written_angles.WrittenTurns.around`: the Delta
   with its right angles written ``1.5708``, 1.28e-5 rad), and the frame is written where the chain ends at the
   joint values at which step 1 made its axes parallel, its joints' nearest to closing it (:func:`_closing`). One
   left further apart, but within ten times that, is refused here, in one line naming the loop and saying that it
   is of the order of a file's rounding; one further still is left to the assembly, which refuses it as before.

A file of another tool, converted (:mod:`screwkit.io.star`), has step 2 only: its axes were read as drawn where it
was converted, but a redundant closure written rounded is closed there only as well as it closes, and the chain
written from it is left that far open (Gepetto's parallelogram Delta turned in the world and written to 6 decimals,
6e-7 m: refused as not closing). A planar one's loop frame is not turned out of its plane (:func:`_tilts_the_plane`).

Nothing changes in an exact file: where no axis would turn by more than :data:`UNSEEN`, none is turned (the
bundled ``coop_arms.urdf`` writes pi/2 as ``1.5707963267900003``, 4.9e-12 off), and a loop its chain closes is not
touched: every bundled mechanism reads as before, bit for bit. What is changed is said, in one note starting
:data:`~screwkit.closure.assembly.DRAWN_AT_ROUNDING`.
"""

from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from screwkit.closure.assembly import DRAWN_AT_ROUNDING, mechanism_size
from screwkit.closure.chain_kinematics import chain_forward_kinematics
from screwkit.closure.newton import file_fit, newton_solve_chain
from screwkit.common.rotations import rotation_about_axis, rotation_vector_from_rotation
from screwkit.common.tolerances import FILE_ROUNDING, MOTION_SPACE_TOLERANCE, NEWTON_TOLERANCE
from screwkit.io.rounding import EXACT, parallel_axes
from screwkit.io.written_angles import WIDENING_LIMIT, WrittenTurns, written_turns
from screwkit.model.chain import ChainGeometry
from screwkit.model.mechanism import Mechanism

__all__ = ["drawn_loops", "turned_geometry", "UNSEEN", "NEAR_ROUNDING", "FRAMES_WRITTEN"]

FRAMES_WRITTEN = "loop frames that meet to the file's rounding written as one"
"""The part of the :data:`~screwkit.closure.assembly.DRAWN_AT_ROUNDING` note that says loop frames were written where
their chains close (``screwkit convert`` then does not say that every loop closes as written)."""

UNSEEN = MOTION_SPACE_TOLERANCE
"""Rad: axes a file draws at most this far from parallel are left as written (their twists are already dependent to
:data:`~screwkit.common.tolerances.MOTION_SPACE_TOLERANCE`, and a turn this small moves no index beyond it)."""
NEAR_ROUNDING = 10.0 * FILE_ROUNDING
"""A loop its chain leaves open by more than ``FILE_ROUNDING`` (rad, lengths over the mechanism's size) and at most
this is refused as of the order of a file's rounding (module docstring)."""

_MOST = FILE_ROUNDING + WIDENING_LIMIT
"""The most any two axes are allowed apart and made parallel (rad): a tilt of more than half a degree beyond the
file's rounding is the author's (:data:`~screwkit.io.written_angles.WIDENING_LIMIT`)."""

_AXIS_LOOPS = {"revolute": 1, "continuous": 1, "prismatic": 1, "universal": 2}
"""The loop joint types with axes, and how many."""


def drawn_loops(mechanism: Mechanism) -> Mechanism:
    """``mechanism`` (chains as read from a file in screwkit's convention, not assembled) with its axes made
    parallel and its loops closed within the file's rounding (module docstring); its ``assembly_notes`` say what
    changed. A converted file (its axes read as drawn where it was converted) has step 2 only: its chains are left
    open by the rounding of redundant closures, which the conversion closed as well as they close."""
    scale = mechanism_size(mechanism, mechanism.chains)
    values, axes, closes = (list(found) for found in zip(*(_file_values(mechanism, index, scale)
                                                          for index in range(len(mechanism.chains)))))
    converted = bool(mechanism.description.converted_from)
    if converted and all(closes):
        return mechanism
    turns = functools.cache(lambda: WrittenTurns() if converted else written_turns(mechanism.description.source,
                                                                                   mechanism.description.text))
    roundings = functools.cache(lambda: [min(turns().around(chain.loop_name), WIDENING_LIMIT)
                                         for chain in mechanism.chains])  # (each loop's, read once it is needed)
    for index in (index for index, closed in enumerate(closes) if not closed):  # (read where the loops close)
        values[index], axes[index] = _closing(mechanism, index, values[index], axes[index], scale,
                                              None if converted else FILE_ROUNDING + roundings()[index])
    geometries, turn, most = ([chain.geometry for chain in mechanism.chains], 0.0, "") \
        if converted else _parallel(mechanism, values, axes, turns, roundings)
    notes = []
    if turn:
        notes.append(f"joint axes that agree to the file's rounding written parallel (the largest turn {turn:.2g} "
                     f"rad, of joint {most!r})")
    moved = []
    for index, chain in enumerate(mechanism.chains):
        if closes[index] and geometries[index] is chain.geometry:  # (as written, closed: nothing to do)
            continue
        geometry, gap = _closed(mechanism, index, geometries[index], values[index], scale,
                                None if converted else FILE_ROUNDING + roundings()[index])
        geometries[index] = geometry
        if gap is not None:
            moved.append((chain.loop_name, *gap))
    if moved:
        loop, metres, radians = moved[_first_most([item[1] / scale + item[2] for item in moved])]
        change = " and ".join([f"moved {metres:.2g} m"] * (metres > EXACT * scale) + [f"turned {radians:.2g} rad"] *
                              (radians > EXACT))
        names = ", ".join(repr(name) for name, _, _ in moved)
        notes.append(f"{FRAMES_WRITTEN} (loop{'s' * (len(moved) > 1)} "
                     f"{names}; the most, {loop!r}, its platform frame {change})")
    if not notes:
        return mechanism
    chains = tuple(replace(chain, geometry=geometry) for chain, geometry in zip(mechanism.chains, geometries))
    return replace(mechanism, chains=chains,
                   assembly_notes=mechanism.assembly_notes + (DRAWN_AT_ROUNDING + "; ".join(notes),))


def _file_values(mechanism: Mechanism, index: int, scale: float) -> tuple[NDArray[np.float64], NDArray, bool]:
    """Chain ``index``'s joint values as the file writes them (:func:`~screwkit.closure.newton.file_fit`); the
    axes (base frame) of its tree joints and of its loop joint there; whether the loop closes there (the fit's gap
    at most :data:`~screwkit.common.tolerances.NEWTON_TOLERANCE`, in rad and the mechanism's ``scale``)."""
    geometry = mechanism.chains[index].geometry
    values, frames, position_gap, rotation_gap = file_fit(mechanism, index)
    loop_axes = frames.leg_rotation @ geometry.loop_axes[:_AXIS_LOOPS.get(geometry.loop_type, 0)].T
    if geometry.loop_type == "universal":  # (its second axis turns with its first)
        first = rotation_about_axis(geometry.loop_axes[0], values[geometry.n_tree_joints])
        loop_axes[:, 1] = frames.leg_rotation @ first @ geometry.loop_axes[1]
    axes = np.concatenate([frames.axes[: geometry.n_tree_joints], loop_axes.T])
    return values, axes, max(position_gap / scale, rotation_gap) <= NEWTON_TOLERANCE


def _closing(mechanism: Mechanism, index: int, values: NDArray, axes: NDArray, scale: float, limit: float | None
             ) -> tuple[NDArray, NDArray]:
    """Chain ``index``'s joint values and axes where its joints close its loop (damped Newton from the file's
    ``values``), so that its axes are read where the mechanism is assembled, as ``screwkit convert`` writes it back;
    with a ``limit`` (a file in screwkit's convention: its loop's rounding, :func:`_closed`), also where they come
    nearest to closing it, if that is within ten times the limit: its loop frame is then written there (step 2), and
    its axes are made parallel there (step 1), where the mechanism is assembled; ``values`` and ``axes`` as they are
    where they do not close it."""
    geometry = mechanism.chains[index].geometry
    solved, converged = _solved(mechanism, index, geometry, values, scale)
    frames = chain_forward_kinematics(geometry, solved)
    if not converged and limit is not None:
        target_rotation, target_translation = mechanism.loop_targets(index, mechanism.home_rotation,
                                                                     mechanism.home_translation)
        converged = _beyond(*_apart(frames, target_rotation, target_translation, scale), limit) * FILE_ROUNDING \
            <= NEAR_ROUNDING
    return (solved, frames.axes[: len(axes)]) if converged else (values, axes)


def _solved(mechanism: Mechanism, index: int, geometry: ChainGeometry, values: NDArray, scale: float
            ) -> tuple[NDArray, bool]:
    """Chain ``index`` (its ``geometry``) closed onto the platform's loop frame at home by damped Newton from
    ``values``, and whether it closed to :data:`~screwkit.common.tolerances.NEWTON_TOLERANCE`."""
    target_rotation, target_translation = mechanism.loop_targets(index, mechanism.home_rotation,
                                                                 mechanism.home_translation)
    solved, converged, _ = newton_solve_chain(geometry, target_rotation[None], target_translation[None],
                                              values[None], tolerance=NEWTON_TOLERANCE, max_iterations=200,
                                              length=scale)
    return solved[0], bool(converged[0])


def _turned_frames(geometry: ChainGeometry, values: NDArray) -> tuple[list[NDArray], NDArray]:
    """The rotation (base frame) of each tree joint's frame after its motion at ``values``, and of the leg-side loop
    frame."""
    rotation, after = np.eye(3), []
    for index in range(geometry.n_tree_joints):
        rotation = rotation @ geometry.joint_rotations[index]
        if not geometry.joint_prismatic[index]:
            rotation = rotation @ rotation_about_axis(geometry.joint_axes[index], values[index])
        after.append(rotation)
    return after, rotation @ geometry.leg_loop_rotation


def _parallel(mechanism: Mechanism, values, axes, turns, roundings) -> tuple[list[ChainGeometry], float, str]:
    """Every chain's geometry with the axes :func:`parallel_axes` groups made parallel (step 1 of the module
    docstring), the largest turn (0: none) and the joint turned most; ``turns()``, the file's
    :class:`~screwkit.io.written_angles.WrittenTurns`, ``roundings()`` each loop's rounding (at most
    ``WIDENING_LIMIT``).

    In passes. First the axes parallel whatever the configuration, each chain's (:func:`_structural`), then across
    chains those fixed in the base (:func:`_fixed_in_base`) or in the platform (:func:`_fixed_in_platform`): linked
    pairwise each within its allowance, every two of a group within theirs or, not linked themselves, within the sum
    along a way of linked pairs (:func:`_through`: the Schoenflies mechanism written to 3 decimals read 0 DOF, a leg's
    loop hinge held to ``FILE_ROUNDING`` of another leg's motor). A group across chains that fails so leaves each
    chain's groups as they are (one pair of two legs' motors 6e-7 rad beyond its allowance undid their legs' own
    grouping). Then every axis, each pair within ``FILE_ROUNDING`` (and a loop joint's axis its loop's rounding,
    :meth:`~screwkit.io.written_angles.WrittenTurns.around`: the closure sets its direction, to that) plus how far the
    passes before turned each (:func:`_grown`). No pair is allowed more than :data:`_MOST`. In one pass, an axis
    parallel to the others at the reference configuration only, linked to them, held every axis of the group to
    ``FILE_ROUNDING`` of every other: the bundled Delta with its right angles written ``1.5708`` kept one leg's motor
    1.55e-5 rad off its elbow, and read 2 DOF."""
    owners = [(index, dof) for index, chain_axes in enumerate(axes) for dof in range(len(chain_axes))]
    directions = [direction for chain_axes in axes for direction in chain_axes]
    geometries = [chain.geometry for chain in mechanism.chains]
    if len(directions) < 2:
        return geometries, 0.0, ""
    units = np.array(directions) / np.linalg.norm(directions, axis=1, keepdims=True)
    crosses = np.linalg.norm(np.cross(units[:, None], units[None]), axis=-1)
    if not np.any((crosses > UNSEEN) & (crosses <= FILE_ROUNDING + WIDENING_LIMIT)):
        return geometries, 0.0, ""  # (an exact file: its file is not read again)
    names = [mechanism.chains[index].joint_names[dof] for index, dof in owners]
    chain_rows = [np.array([k for k, (owner, _) in enumerate(owners) if owner == index], dtype=int)
                  for index in range(len(mechanism.chains))]
    loose = np.zeros(len(owners))  # (a loop joint's axis: its loop's rounding)
    for chain, rows, rounding in zip(mechanism.chains, chain_rows, roundings()):
        loose[rows[chain.geometry.n_tree_joints:]] = rounding
    widened = np.minimum(turns().allowances(names) + loose[:, None] + loose[None], _MOST)
    linked = np.zeros(crosses.shape, dtype=bool)  # (the pairs parallel whatever the configuration)
    to_platform = np.full(len(owners), np.nan)  # (the rounding between an axis fixed in the platform and it)
    in_base = np.zeros(len(owners), dtype=bool)
    for chain, rows in zip(mechanism.chains, chain_rows):
        block = np.ix_(rows, rows)
        slides = chain.geometry.dof_prismatic[:rows.size]
        linked[block] = _structural(crosses[block], slides, widened[block])
        for dof in _fixed_in_platform(chain, crosses[block], slides, widened[block]):
            to_platform[rows[dof]] = turns().to_platform(chain.joint_names[dof], chain.loop_name)
        in_base[rows[_fixed_in_base(chain, crosses[block], slides, widened[block])]] = True
    allowed = np.where(linked, widened, np.minimum(FILE_ROUNDING + loose[:, None] + loose[None], _MOST))
    chain_of = np.array([owner for owner, _ in owners])
    apart = chain_of[:, None] != chain_of[None]
    both = to_platform[:, None] + to_platform[None]  # (nan unless both axes are fixed in the platform)
    across = np.isfinite(both) & apart
    allowed[across] = FILE_ROUNDING + np.minimum(both[across], WIDENING_LIMIT)
    based = in_base[:, None] & in_base[None] & apart  # (their paths from the base: the rounding between them)
    allowed[based] = widened[based]
    inside, linked = linked.copy(), linked | across | based
    own, _ = parallel_axes(units, _through(allowed, inside), links=inside)  # (each chain's, then across chains)
    first, _ = parallel_axes(own, _through(_grown(allowed, own, units), linked), links=linked)
    turned, _ = parallel_axes(first, _grown(allowed, first, units))
    moved = np.linalg.norm(np.cross(turned, units), axis=1)
    turn = float(np.max(moved))
    if turn <= UNSEEN:
        return geometries, 0.0, ""
    for index, (chain, rows) in enumerate(zip(mechanism.chains, chain_rows)):
        if np.any(moved[rows] > 0.0):
            geometries[index] = turned_geometry(chain.geometry, values[index], turned[rows], moved[rows] > 0.0)
    return geometries, turn, names[_first_most(moved)]


def _grown(allowed: NDArray, turned: NDArray, units: NDArray) -> NDArray[np.float64]:
    """The allowances ``allowed`` of every two axes grown by how far the passes before turned each (``turned`` from
    ``units``), at most :data:`_MOST`: an axis near one as written is that near it as made parallel."""
    turns = np.linalg.norm(np.cross(turned, units), axis=1)
    return np.minimum(allowed + turns[:, None] + turns[None], _MOST)


def _through(allowed: NDArray, linked: NDArray) -> NDArray[np.float64]:
    """Each pair's allowance for the first pass of :func:`_parallel`: its own where it is ``linked`` (parallel
    whatever the configuration), else the least sum of the allowances along a way of linked pairs from one to the
    other (infinite where there is none): two axes each parallel to a third whatever the configuration are parallel
    to each other, to the sum of the two roundings (a leg's loop hinge, parallel to its motor, and another leg's
    motor)."""
    through = np.where(linked, allowed, np.inf)
    for middle in range(through.shape[0]):  # (Floyd-Warshall: a few tens of axes)
        through = np.minimum(through, through[:, middle, None] + through[None, middle, :])
    return np.where(linked, allowed, np.minimum(through, _MOST))


def _structural(crosses: NDArray, slides, widened: NDArray) -> NDArray[np.bool_]:
    """Which two of one chain's axes (``crosses`` of every two, in the chain's order; ``slides`` the prismatic ones;
    ``widened`` their allowances) stay parallel whatever the values of the joints between them: every hinge between
    them within its allowance of parallel to the first. A UR arm's base pan and its second wrist hinge are parallel
    when its three middle hinges' values sum to zero, and are not grouped for a right angle written 1.57 between
    them."""
    count = crosses.shape[0]
    linked = np.zeros((count, count), dtype=bool)
    for first in range(count):
        for second in range(first, count):
            hinges = [k for k in range(first + 1, second) if not slides[k]]
            if all(crosses[k, first] <= widened[k, first] for k in hinges):
                linked[first, second] = linked[second, first] = True
    return linked


def _fixed_in_base(chain, crosses: NDArray, slides, widened: NDArray) -> list[int]:
    """The tree joints of ``chain`` whose axis keeps its direction in the base whatever the joint values: every hinge
    before it parallel to it within its allowance (:func:`_kept`). Two such axes of two chains (two legs' motors,
    each with its elbow's first hinge) are parallel whatever the configuration, to the rounding of the angles on
    their ways from the base."""
    return _kept(chain.geometry.n_tree_joints, crosses, slides, widened, before=True)


def _fixed_in_platform(chain, crosses: NDArray, slides, widened: NDArray) -> list[int]:
    """The tree joints of ``chain`` whose axis keeps its direction in the platform whatever the joint values: its loop
    fixed (a weld onto the platform), and every hinge after it parallel to it within its allowance (:func:`_kept`)."""
    return [] if chain.geometry.loop_type != "fixed" else _kept(chain.geometry.n_tree_joints, crosses, slides,
                                                                widened, before=False)


def _kept(count: int, crosses: NDArray, slides, widened: NDArray, before: bool) -> list[int]:
    """The hinges among a chain's ``count`` tree joints that every hinge before them (else after them) is parallel to
    within its allowance (``crosses`` of every two of its axes, ``slides`` the prismatic ones, ``widened`` their
    allowances): their directions do not depend on those joints' values."""
    return [dof for dof in range(count) if not slides[dof] and
            all(slides[k] or crosses[k, dof] <= widened[k, dof] for k in (range(dof) if before else
                                                                         range(dof + 1, count)))]


def _first_most(values) -> int:
    """The first of ``values`` within 1 % of the largest: the one a note names, the same whatever round-off tells
    values that are equal by the mechanism's symmetry apart (in a turned world, listed in another order)."""
    values = np.asarray(values, dtype=float)
    return int(np.flatnonzero(values >= 0.99 * values.max())[0])


def turned_geometry(geometry: ChainGeometry, values: NDArray, directions: NDArray, which: NDArray) -> ChainGeometry:
    """``geometry`` with the axes ``which`` (tree joints, then the loop joint's) along ``directions`` (base frame),
    every frame after a turned joint's motion at ``values`` where it was: a revolute's placement turned by
    ``R(a, q) R(a', -q)``, a slide's moved by ``(a - a') q``; a universal loop's second axis, turned, moves the
    chain's end frame by its turn times its value, which step 2 of the module docstring takes up."""
    rotations, translations = geometry.joint_rotations.copy(), geometry.joint_translations.copy()
    axes, loop_axes = geometry.joint_axes.copy(), geometry.loop_axes.copy()
    leg_rotation, leg_translation = geometry.leg_loop_rotation.copy(), geometry.leg_loop_translation.copy()
    after, leg = _turned_frames(geometry, values)
    count = geometry.n_tree_joints
    for index in np.flatnonzero(which[:count]):
        value, written = values[index], axes[index].copy()
        axes[index] = after[index].T @ directions[index]
        if geometry.joint_prismatic[index]:
            translations[index] = translations[index] + rotations[index] @ ((written - axes[index]) * value)
        else:
            rotations[index] = (rotations[index] @ rotation_about_axis(written, value)
                                @ rotation_about_axis(axes[index], -value))
    if which[count:].any():
        value, written = values[count], loop_axes[0].copy()
        if geometry.loop_type == "prismatic":
            loop_axes[0] = leg.T @ directions[count]
            leg_translation = leg_translation + leg_rotation @ ((written - loop_axes[0]) * value)
        else:
            middle = leg @ rotation_about_axis(written, value)  # after the loop's first rotation: kept
            loop_axes[0] = middle.T @ directions[count]
            leg_rotation = leg_rotation @ rotation_about_axis(written, value) @ rotation_about_axis(loop_axes[0],
                                                                                                   -value)
            if geometry.loop_type == "universal":
                loop_axes[1] = middle.T @ directions[count + 1]
    return replace(geometry, joint_rotations=rotations, joint_translations=translations, joint_axes=axes,
                   loop_axes=loop_axes, leg_loop_rotation=leg_rotation, leg_loop_translation=leg_translation)


def _closed(mechanism: Mechanism, index: int, geometry: ChainGeometry, values: NDArray, scale: float,
            limit: float | None) -> tuple[ChainGeometry, tuple[float, float] | None]:
    """``geometry`` with the platform's loop frame written where the chain closes, when its joints leave the loop
    within the file's rounding but no closer (step 2 of the module docstring), and how far it moved (length, rad);
    else ``geometry`` and None. A ValueError names a loop left open by more, up to ten times that.

    The file's rounding is ``limit`` for a file in screwkit's convention: ``FILE_ROUNDING`` plus the rounding of the
    angles around the loop (:meth:`~screwkit.io.written_angles.WrittenTurns.around`); its frame is written where the
    chain ends at ``values``, where its axes were made parallel (:func:`_closing`, :func:`_parallel`), so that they
    are parallel where the mechanism is assembled: written where Newton took the chain from there, a Delta's
    platform-side hinge turned off its motor's by what the hinges across it took up. A converted file's (None:
    ``FILE_ROUNDING``) is written where the chain comes nearest (damped Newton from ``values``)."""
    # (the platform's loop frame is the file's until written here: the targets are the mechanism's)
    target_rotation, target_translation = mechanism.loop_targets(index, mechanism.home_rotation,
                                                                 mechanism.home_translation)
    if max(_apart(chain_forward_kinematics(geometry, values), target_rotation, target_translation, scale)) \
            <= NEWTON_TOLERANCE:
        return geometry, None
    converged = False
    if limit is None:
        values, converged = _solved(mechanism, index, geometry, values, scale)
    end = chain_forward_kinematics(geometry, values)
    radians, lengths = _apart(end, target_rotation, target_translation, scale)
    limit = FILE_ROUNDING if limit is None else limit
    beyond = _beyond(radians, lengths, limit)
    if converged or beyond * FILE_ROUNDING > NEAR_ROUNDING:
        return geometry, None
    if beyond > 1.0:
        rounded = "" if limit == FILE_ROUNDING else \
            f", {limit - FILE_ROUNDING:.2g} rad of it the rounding of the angles written around the loop"
        raise mechanism.description.fail(
            f"<loop name='{mechanism.chains[index].loop_name}'>",
            f"does not close at the reference configuration: its chain's joints leave its frames {radians:.3g} rad "
            f"and {lengths * scale:.3g} m apart at the closest, of the order of a file's rounding but beyond what is "
            f"read as drawn ({limit:.2g} rad{rounded}, and {FILE_ROUNDING:g} of the mechanism's size, {scale:.3g} m): "
            "written to that or finer (a CAD export's 6 decimals in metres, for a mechanism of 10 cm or more), such a "
            "loop is closed as drawn.")
    rotation = mechanism.home_rotation.T @ end.end_rotation
    translation = mechanism.home_rotation.T @ (end.end_translation - mechanism.home_translation)
    change = rotation_vector_from_rotation(geometry.platform_loop_rotation.T @ rotation)
    if _tilts_the_plane(mechanism, geometry, change):
        return geometry, None
    turn = float(np.linalg.norm(change))
    metres = float(np.linalg.norm(translation - geometry.platform_loop_translation))
    return replace(geometry, platform_loop_rotation=rotation, platform_loop_translation=translation), (metres, turn)


def _tilts_the_plane(mechanism: Mechanism, geometry: ChainGeometry, change: NDArray) -> bool:
    """Whether turning a converted planar mechanism's platform loop frame by ``change`` (a rotation vector in that
    frame) would turn it out of the plane: its chain then meets the platform only at the reference pose (the
    conversion wrote every axis along the plane's normal; a loop frame turned 3.6e-6 rad off it left Gepetto's
    five-bar, written to 5 decimals, missing every other pose by more than Newton's tolerance). Such a loop is left
    to the assembly, which refuses it as not closing."""
    if not (mechanism.description.converted_from and mechanism.is_planar):
        return False
    normal = geometry.platform_loop_rotation.T @ np.array([0.0, 0.0, 1.0])  # (the plane's normal: the base's z)
    return float(np.linalg.norm(np.cross(change, normal))) > UNSEEN


def _beyond(radians: float, lengths: float, limit: float) -> float:
    """How far a loop is left open, in units of what is read as drawn: ``limit`` in rad (:func:`_closed`),
    ``FILE_ROUNDING`` in lengths over the mechanism's size."""
    return max(radians / limit, lengths / FILE_ROUNDING)


def _apart(frames, rotation: NDArray, translation: NDArray, scale: float) -> tuple[float, float]:
    """How far a chain's end ``frames`` are from a loop frame: the angle (rad) and the distance over ``scale``."""
    return (float(np.linalg.norm(rotation_vector_from_rotation(frames.end_rotation.T @ rotation))),
            float(np.linalg.norm(frames.end_translation - translation)) / scale)
