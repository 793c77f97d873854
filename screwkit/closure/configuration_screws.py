"""The joint screws of a closed mechanism: the hand-over from closure solving to the math core.

:func:`chain_screws` turns a :class:`~screwkit.closure.solve.Solution` into one
:class:`~screwkit.screw.chain_screws.ChainScrews` per chain (world-frame twists of every joint DoF, their
points, the actuated joints and the joint names), written into one component-major block of
memory that :func:`screwkit.indices.analysis.analyze` reads in place.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from typing import Literal, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.closure.chain_kinematics import (
    COMPILED_FROM,
    chain_forward_kinematics,
    transform_axes_and_points,
    twists_from_axes_and_points,
)
from screwkit.closure.solve import Solution, check_solution
from screwkit.closure.threads import block_threads
from screwkit.common.compiling import CLOSED_FORM_KERNEL, prepare_kernels
from screwkit.model.mechanism import Mechanism
from screwkit.screw.chain_screws import ChainScrews

__all__ = ["chain_screws", "joint_screws"]


def _compiled(mechanism: Mechanism, batch: tuple[int, ...]) -> bool:
    """Whether chain_screws builds a batch's screws with the compiled kernel: spatial, flat and large
    (the planar closed forms broadcast constant components, which numpy skips)."""
    return not mechanism.is_planar and len(batch) == 1 and batch[0] >= COMPILED_FROM


def _chain_screws_from_frames(mechanism: Mechanism, index: int, axes: NDArray, points: NDArray, frame: str,
                              twist_block: NDArray | None = None, point_block: NDArray | None = None,
                              compiled: bool = False) -> ChainScrews:
    """Screws of one chain; ``twist_block`` (zeroed unless ``compiled``) and ``point_block``, (6 or 3, m, ...),
    receive them; ``compiled``: by the compiled kernel (see :func:`_compiled`)."""
    chain = mechanism.chains[index]
    if frame == "world" and not mechanism.base_is_world:
        axes, points = transform_axes_and_points(mechanism.rotation_world_base, mechanism.translation_world_base,
                                                 axes, points)
    if compiled:
        prepare_kernels((CLOSED_FORM_KERNEL,))
        from screwkit.closure.compiled.closed_form import joint_screws_kernel  # numba: large batches only

        joint_screws_kernel(np.ascontiguousarray(axes, dtype=float), np.ascontiguousarray(points, dtype=float),
                            np.asarray(chain.prismatic, dtype=bool), twist_block, point_block)
        return ChainScrews(np.moveaxis(twist_block, (0, 1), (-1, -2)), np.moveaxis(point_block, (0, 1), (-1, -2)),
                           chain.actuated, chain.name, joint_names=chain.joint_names)
    twists = twists_from_axes_and_points(axes, points, chain.prismatic, out=twist_block)
    if point_block is not None:
        point_block[...] = np.moveaxis(points, (-1, -2), (0, 1))
        points = np.moveaxis(point_block, (0, 1), (-1, -2))
    return ChainScrews(twists, points, chain.actuated, chain.name, joint_names=chain.joint_names)


def chain_screws(
    mechanism: Mechanism,
    solution: Solution,
    *,
    frame: Literal["world", "base"] = "world",
    unreachable: Literal["raise", "drop", "reference"] = "raise",
) -> list[ChainScrews]:
    """Joint screws of every chain at solved configurations, one ChainScrews per chain.

    Parameters
    ----------
    mechanism : Mechanism
    solution : Solution
        From :func:`~screwkit.closure.solve` or :func:`~screwkit.closure.forward`.
    frame : {"world", "base"}
        Express twists and points in the world frame (URDF root) or the base link frame.
    unreachable : {"raise", "drop", "reference"}
        What to do with configurations where not all chains closed: raise a ValueError,
        drop them (the batch becomes 1-D over the reachable configurations, in C order of
        ``solution.reachable``), or fill them with the reference assembly's screws (finite
        placeholders: mask the results with ``solution.reachable``).
    """
    check_solution(mechanism, solution, "chain_screws")
    if frame not in ("world", "base"):
        raise ValueError(f"Expected `frame` 'world' or 'base', got {frame!r}.")
    if unreachable not in ("raise", "drop", "reference"):
        raise ValueError(f"Expected `unreachable` 'raise', 'drop' or 'reference', got {unreachable!r}.")
    mask = np.asarray(solution.reachable)
    all_reachable = bool(np.all(mask))
    if unreachable == "raise" and not all_reachable:
        first = tuple(int(i) for i in np.argwhere(~mask)[0]) if mask.ndim else ()
        raise ValueError(
            f"{int(np.sum(~mask))} of {mask.size} configurations are unreachable (first at index {first}); "
            "pass unreachable='drop' or 'reference' to chain_screws, or mask the poses."
        )
    # Every chain's twists and points go into one component-major block (6 or 3, J, batch),
    # chain after chain along the joint axis, which analyze() then reads in place.
    batch = (int(mask.sum()),) if not all_reachable and unreachable == "drop" else mask.shape
    starts = np.cumsum([0] + [chain.n_joints for chain in mechanism.chains])
    compiled = _compiled(mechanism, batch)
    twist_block = (np.empty if compiled else np.zeros)((6, starts[-1]) + batch)
    point_block = np.empty((3, starts[-1]) + batch)

    def screws_of_chain(index: int) -> ChainScrews:
        axes, points = solution.joint_axes[index], solution.joint_points[index]
        if not all_reachable and unreachable == "drop":
            axes, points = axes[mask], points[mask]
        elif not all_reachable:
            frames = chain_forward_kinematics(mechanism.chains[index].geometry,
                                              mechanism.chains[index].reference_values)
            axes = np.where(mask[..., None, None], axes, frames.axes)
            points = np.where(mask[..., None, None], points, frames.points)
        joints = slice(starts[index], starts[index + 1])
        return _chain_screws_from_frames(mechanism, index, axes, points, frame, twist_block[:, joints],
                                         point_block[:, joints], compiled)

    threads = min(len(mechanism.chains), block_threads())
    if mask.size >= 1 << 16 and threads > 1:  # chains in parallel (numpy releases the GIL)
        with ThreadPoolExecutor(threads) as pool:
            return list(pool.map(screws_of_chain, range(len(mechanism.chains))))
    return [screws_of_chain(index) for index in range(len(mechanism.chains))]


def joint_screws(mechanism: Mechanism, joint_values: Sequence[ArrayLike], *,
                 frame: Literal["world", "base"] = "world") -> list[ChainScrews]:
    """Joint screws at arbitrary joint values (forward kinematics only, no closure).

    ``joint_values`` holds one array (..., m_i) per chain.
    """
    joint_values = tuple(joint_values)
    if len(joint_values) != len(mechanism.chains):
        raise ValueError(f"Expected joint values for {len(mechanism.chains)} chains, got {len(joint_values)}.")
    screws = []
    for index, values in enumerate(joint_values):
        frames = chain_forward_kinematics(mechanism.chains[index].geometry, values)
        screws.append(_chain_screws_from_frames(mechanism, index, frames.axes, frames.points, frame))
    return screws
