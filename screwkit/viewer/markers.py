"""What a scene draws over a mechanism, computed from its indices (no Meshcat here).

Colours of the chains from their indices (:func:`colors_from_values`, viridis), the actuation
wrench lines, the output twists and instantaneous centres of the best working submechanism,
failed actuators, and rods for links without a visual: one :class:`Marker` each, in the
mechanism's world frame.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure import chain_screws, solve, solve_one
from screwkit.model.pinocchio_bridge import configuration_vector
from screwkit.studies.poses import analyze_solution

__all__ = [
    "ROOT_PATH",
    "COLORMAP_NAME",
    "NO_INDEX_COLOR",
    "FAILED_COLOR",
    "FAILED_MARKER_COLOR",
    "WRENCH_COLOR",
    "TWIST_COLOR",
    "MARKER_KINDS",
    "Marker",
    "Frames",
    "colors_from_values",
    "resolve_actuators",
    "solve_frames",
    "best_submechanism",
    "chain_index_values",
    "chain_names",
    "actuator_pairs",
    "markers_of_frame",
    "twist_markers",
]


ROOT_PATH = "screwkit"
"""Meshcat path (under ``/meshcat``) of everything a scene draws."""


COLORMAP_NAME = "viridis"
"""Colour map of the chain indices: 0 dark purple, 0.5 teal, 1 yellow (perceptually uniform,
readable in grey and by colour-blind readers); linear between the 17 samples of
:data:`_VIRIDIS_SAMPLES`."""


_VIRIDIS_SAMPLES = np.array([
    (0.2670, 0.0049, 0.3294), (0.2823, 0.0950, 0.4173), (0.2788, 0.1755, 0.4834), (0.2590, 0.2515, 0.5247),
    (0.2297, 0.3224, 0.5457), (0.1994, 0.3876, 0.5546), (0.1727, 0.4488, 0.5579), (0.1490, 0.5081, 0.5573),
    (0.1276, 0.5669, 0.5506), (0.1206, 0.6258, 0.5335), (0.1579, 0.6838, 0.5017), (0.2461, 0.7389, 0.4520),
    (0.3692, 0.7889, 0.3829), (0.5160, 0.8312, 0.2943), (0.6785, 0.8637, 0.1895), (0.8456, 0.8873, 0.0997),
    (0.9932, 0.9062, 0.1439),
])
"""matplotlib's viridis at 0, 1/16, ..., 1."""


NO_INDEX_COLOR = (0.55, 0.55, 0.58, 1.0)
"""RGBA of a chain without an index value (no working actuator, or an undefined index)."""


FAILED_COLOR = (0.86, 0.08, 0.08, 0.35)
"""RGBA of the links of a failed actuator: transparent red."""


FAILED_MARKER_COLOR = (0.86, 0.08, 0.08, 1.0)
"""RGBA of the cross drawn at a failed actuated joint."""


WRENCH_COLOR = (1.0, 0.50, 0.05, 1.0)
"""RGBA of the actuation wrench lines (orange: no viridis colour is orange)."""


TWIST_COLOR = (0.85, 0.10, 0.75, 1.0)
"""RGBA of the output twist axes, instantaneous centres and translation arrows (magenta)."""


MARKER_KINDS = ("actuation_wrench", "actuation_couple", "twist_axis", "instantaneous_centre", "translation",
                "failed_actuator", "link", "joint")
"""Kinds of :class:`Marker`."""


def colors_from_values(values: ArrayLike, alpha: float = 1.0) -> NDArray[np.float64]:
    """RGBA colours (..., 4) of index values in [0, 1] with the viridis map.

    Values are clipped to [0, 1]; NaN gives :data:`NO_INDEX_COLOR`.

    Examples
    --------
    >>> colors_from_values([0.0, 1.0]).round(3)
    array([[0.267, 0.005, 0.329, 1.   ],
           [0.993, 0.906, 0.144, 1.   ]])
    """
    values = np.asarray(values, dtype=float)
    samples = np.linspace(0.0, 1.0, len(_VIRIDIS_SAMPLES))
    clipped = np.clip(np.nan_to_num(values, nan=0.0), 0.0, 1.0)
    rgb = np.stack([np.interp(clipped, samples, _VIRIDIS_SAMPLES[:, channel]) for channel in range(3)], -1)
    colors = np.concatenate([rgb, np.full(values.shape + (1,), float(alpha))], -1)
    return np.where(np.isnan(values)[..., None], np.asarray(NO_INDEX_COLOR), colors)


def resolve_actuators(mechanism, actuators) -> tuple[int, ...]:
    """Indices into ``mechanism.actuators`` of actuators given by index or name.

    Parameters
    ----------
    mechanism : screwkit.model.Mechanism
    actuators : int, str or sequence of them, optional
        Each one a 0-based index, ``"CHAIN:JOINT"`` (as in the reports), a joint name, or a
        chain name (all the actuators of that chain). ``None`` gives ``()``.

    Returns
    -------
    tuple of int
        Sorted, without repeats.

    Raises
    ------
    ValueError
        An index out of range or an unknown name (the message lists the actuators).
    TypeError
        Something that is neither an index nor a name.
    """
    if actuators is None:
        return ()
    if isinstance(actuators, (int, np.integer, str)):
        actuators = [actuators]
    pairs = actuator_pairs(mechanism)
    names = [f"{chain}:{joint}" for chain, joint in pairs]
    chosen: set[int] = set()
    for actuator in actuators:
        if isinstance(actuator, (int, np.integer)) and not isinstance(actuator, bool):
            if not 0 <= actuator < len(names):
                raise ValueError(f"Expected actuator indices in 0..{len(names) - 1} for mechanism "
                                 f"{mechanism.name!r}, got {actuator}.")
            chosen.add(int(actuator))
            continue
        if not isinstance(actuator, str):
            raise TypeError(f"Expected an actuator index or name, got {actuator!r}.")
        text = actuator.strip()
        if re.fullmatch(r"\d+", text):
            chosen.update(resolve_actuators(mechanism, [int(text)]))
            continue
        hits = [i for i, (chain, joint) in enumerate(pairs) if text in (names[i], joint, chain)]
        if not hits:
            raise ValueError(f"Unknown actuator {actuator!r} for mechanism {mechanism.name!r}; actuators are "
                             f"0..{len(names) - 1}: {', '.join(names)} (a chain name selects all its actuators).")
        chosen.update(hits)
    return tuple(sorted(chosen))


@dataclass(frozen=True, eq=False)
class Marker:
    """One drawn overlay, in the world frame of the mechanism (metres).

    Attributes
    ----------
    path : str
        Meshcat path of its node (under ``/meshcat``).
    kind : str
        One of :data:`MARKER_KINDS`: ``"actuation_wrench"`` (``start`` -> ``end`` along the
        force, centred on the characteristic point), ``"actuation_couple"`` (along the moment
        of a pure couple), ``"twist_axis"`` (along :math:`\\omega`), ``"instantaneous_centre"``
        (``start == end`` the centre, in the platform plane), ``"translation"`` (a twist at
        infinity: from the platform centre along its velocity), ``"failed_actuator"``
        (``start == end`` the actuated joint), ``"link"`` (a rod between two joint points of a
        link without a visual) and ``"joint"`` (a sphere at such a joint point).
    actuator : int or None
        Index into ``mechanism.actuators`` (wrench, twist and failure markers).
    start, end : ndarray, shape (3,)
    failed : bool
        Drawn in :data:`FAILED_COLOR`.
    chain : int or None
        Chain index (link, joint and failure markers).
    body : str or None
        ``"base"`` or ``"platform"`` for a link or joint of those bodies (drawn in their colours), else None.
    """

    path: str
    kind: str
    actuator: int | None
    start: NDArray[np.float64]
    end: NDArray[np.float64]
    failed: bool = False
    chain: int | None = None
    body: str | None = None

    @property
    def direction(self) -> NDArray[np.float64]:
        """Unit vector from ``start`` to ``end`` (zeros for a point marker)."""
        difference = self.end - self.start
        norm = np.linalg.norm(difference)
        return difference / norm if norm > 0 else np.zeros(3)


@dataclass
class Frames:
    """Everything per pose that the drawing needs (leading axis: frames)."""

    poses: NDArray
    configurations: NDArray  # (F, nq)
    chain_points: list  # per chain (F, m_i, 3), world
    centres: NDArray  # (F, 3) platform origin, world
    result: Any  # batched over F
    loop_points: list = None  # per chain (F, 3): the platform-side loop frame's origin, world (where the leg ends)
    kept: NDArray = None  # (F,) which of the poses asked for these frames are (the reachable ones)


def solve_frames(mechanism, poses: NDArray, threshold: float, strict: bool, limits: bool = True) -> Frames:
    solution = solve(mechanism, poses, limits=limits)
    reachable = np.asarray(solution.reachable)
    kept = np.flatnonzero(reachable)
    if not np.all(reachable):
        if strict:
            solve_one(mechanism, poses[int(np.flatnonzero(~reachable)[0])], limits=limits)  # raises, naming them
        if not np.any(reachable):
            raise ValueError(f"None of the {poses.shape[0]} poses is reachable for mechanism {mechanism.name!r}.")
        poses = poses[reachable]
        solution = solve(mechanism, poses, limits=limits)
    screws = chain_screws(mechanism, solution)
    result = analyze_solution(mechanism, solution, threshold=threshold, keep_twists=True)
    configurations = configuration_vector(mechanism, solution.joint_values, solution.full_poses)
    rotation, translation = mechanism.transforms_from_poses(solution.full_poses)
    to_world = np.asarray(mechanism.rotation_world_base).T, np.asarray(mechanism.translation_world_base)
    centres = translation @ to_world[0] + to_world[1]
    loop_points = [(translation + rotation @ chain.geometry.platform_loop_translation) @ to_world[0] + to_world[1]
                   for chain in mechanism.chains]
    return Frames(poses=np.asarray(solution.poses),
                   configurations=np.asarray(configurations).reshape(poses.shape[0], -1),
                   chain_points=[np.asarray(s.points) for s in screws], centres=centres, result=result,
                   loop_points=loop_points, kept=kept)


def best_submechanism(result, frame: int, failed: tuple[int, ...]) -> int | None:
    """Index of the working submechanism with the highest OTI (None if there is none)."""
    otis = np.asarray(result.oti_submechanisms)[frame]
    working = np.array([not set(sub) & set(failed) for sub in result.submechanisms], dtype=bool)
    scores = np.where(working & np.isfinite(otis), otis, -np.inf)
    if scores.size == 0 or not np.isfinite(np.max(scores)):
        return None
    return int(np.argmax(scores))


def chain_names(mechanism) -> list[str]:
    """The names of a mechanism's chains: a serial mechanism's chains, a graph's legs."""
    legs = getattr(mechanism, "legs", None)
    return [leg.name for leg in (legs if legs is not None else mechanism.chains)]


def actuator_pairs(mechanism) -> list[tuple[str, str]]:
    """``(chain, joint)`` of every actuator, in order: a serial mechanism's pairs, a graph's ``leg:joint`` split."""
    return [tuple(actuator.split(":", 1)) if isinstance(actuator, str) else tuple(actuator)
            for actuator in mechanism.actuators]


def chain_index_values(mechanism, result, frame: int, failed: tuple[int, ...], color_by: str) -> NDArray:
    names = chain_names(mechanism)
    chain_index = {name: index for index, name in enumerate(names)}
    actuators_of = [[] for _ in names]
    for actuator, (chain, _) in enumerate(actuator_pairs(mechanism)):
        if actuator not in failed:
            actuators_of[chain_index[chain]].append(actuator)
    values = np.full(len(names), np.nan)
    if color_by == "iti":
        iti = np.asarray(result.iti_actuators)[frame]
        for chain, members in enumerate(actuators_of):
            if members:
                values[chain] = float(np.min(iti[members]))
    else:
        otis = np.asarray(result.oti_submechanisms)[frame]
        for chain, members in enumerate(actuators_of):
            scores = [otis[s] for s, sub in enumerate(result.submechanisms)
                      if set(sub) & set(members) and not set(sub) & set(failed) and np.isfinite(otis[s])]
            if scores:
                values[chain] = float(np.max(scores))
    return values


def node_label(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)


def markers_of_frame(mechanism, frames: Frames, frame: int, failed: tuple[int, ...], best: int | None,
                   bare_links: list) -> list[Marker]:
    """The overlays of one frame (see :class:`Marker`)."""
    result = frames.result
    length = float(mechanism.length_scale)
    chain_index = {chain.name: index for index, chain in enumerate(mechanism.chains)}
    markers: list[Marker] = []
    centre = frames.centres[frame]
    wrenches = np.asarray(result.actuation_wrenches)[frame]
    for actuator, (chain_name, joint_name) in enumerate(mechanism.actuators):
        chain = chain_index[chain_name]
        points = frames.chain_points[chain][frame]
        force, moment = wrenches[actuator, :3], wrenches[actuator, 3:]
        label = node_label(f"{actuator}-{chain_name}-{joint_name}")
        is_failed = actuator in failed
        force_norm = np.linalg.norm(force)
        if force_norm > 1e-9 * max(np.linalg.norm(moment) / length, 1.0):
            direction = force / force_norm
            on_axis = np.cross(force, moment) / force_norm**2
            middle = on_axis + direction * np.dot(points[-1] - on_axis, direction)
            kind = "actuation_wrench"
        else:
            direction = moment / max(np.linalg.norm(moment), 1e-300)
            middle = points[-1]
            kind = "actuation_couple"
        markers.append(Marker(f"{ROOT_PATH}/actuation_wrenches/{label}", kind, actuator, middle - length * direction,
                              middle + length * direction, failed=is_failed, chain=chain))
        if is_failed:
            joint = mechanism.chains[chain].joint_names.index(joint_name)
            markers.append(Marker(f"{ROOT_PATH}/failed/{label}", "failed_actuator", actuator, points[joint].copy(),
                                  points[joint].copy(), failed=True, chain=chain))
    if best is not None:
        twists = np.asarray(result.output_twists)[frame, best]
        for slot, (actuator, twist) in enumerate(zip(result.submechanisms[best], twists)):
            markers.extend(twist_markers(mechanism, slot, actuator, twist, centre, length))
    for chain, position, failed_link in bare_links:
        points = frames.chain_points[chain][frame]
        # the link after the last tree joint of a leg welded to the platform (no loop joint) ends on the platform
        start = points[position]
        end = points[position + 1] if position + 1 < len(points) else frames.loop_points[chain][frame]
        if np.linalg.norm(end - start) < 1e-9 * length:  # e.g. the cross of a universal joint
            continue
        name = node_label(mechanism.chains[chain].name)
        markers.append(Marker(f"{ROOT_PATH}/links/{name}/{position}", "link", None, start.copy(), end.copy(),
                              failed=failed_link, chain=chain))
        for end_index, point in ((position, start), (position + 1, end)):
            markers.append(Marker(f"{ROOT_PATH}/links/{name}/joint_{end_index}", "joint", None, point.copy(),
                                  point.copy(), failed=failed_link, chain=chain))
    unique: dict[str, Marker] = {}
    for marker in markers:
        unique.setdefault(marker.path, marker)
    return list(unique.values())


def twist_markers(mechanism, slot: int, actuator: int, twist: NDArray, centre: NDArray, length: float) -> list[Marker]:
    """Axis (and planar instantaneous centre) of one output twist, or its translation arrow."""
    omega, velocity = twist[:3], twist[3:]
    centre_velocity = velocity + np.cross(omega, centre)
    scale = max(np.linalg.norm(omega) * length, np.linalg.norm(centre_velocity))
    if not scale > 0:
        return []
    omega_norm = np.linalg.norm(omega)
    base = f"{ROOT_PATH}/output_twists/{slot}"
    if omega_norm * length > 1e-9 * scale:
        axis_point = np.cross(omega, velocity) / omega_norm**2
        direction = omega / omega_norm
        nearest = axis_point + direction * np.dot(centre - axis_point, direction)
        if np.linalg.norm(nearest - centre) < 50.0 * length:
            markers = [Marker(f"{base}/axis", "twist_axis", actuator, nearest - length * direction,
                              nearest + length * direction)]
            if mechanism.is_planar:  # the axis is normal to the platform plane: it meets it at `nearest`
                markers.append(Marker(f"{base}/centre", "instantaneous_centre", actuator, nearest, nearest.copy()))
            return markers
    direction = centre_velocity / max(np.linalg.norm(centre_velocity), 1e-300)
    return [Marker(f"{base}/translation", "translation", actuator, centre.copy(), centre + 0.6 * length * direction)]

