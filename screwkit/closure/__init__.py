"""Closure solving: from platform poses to closed chains and their joint screws.

Functions of an immutable :class:`~screwkit.model.Mechanism` and of configurations:

* :func:`solve`, :func:`solve_one`: close every chain for platform poses (closed forms or
  batched damped Newton), keeping the working mode and the joint limits;
* :func:`forward`: platform poses from actuator values;
* :func:`chain_screws`: the world-frame joint screws of solved configurations, the input of
  :func:`screwkit.indices.analysis.analyze`;
* :func:`thread_limit`: bound the threads closure solving uses (inside parallel tasks).

Modules: :mod:`~screwkit.closure.chain_kinematics` (one chain's forward kinematics and
twists), :mod:`~screwkit.closure.newton`, :mod:`~screwkit.closure.analytic` (closed-form
chain solvers; the spatial ones, and the joint screws, of large batches compiled in
``_closed_form_kernel``), :mod:`~screwkit.closure.assembly` (the reference assembly and working modes),
:mod:`~screwkit.closure.solve`, :mod:`~screwkit.closure.forward_kinematics`,
:mod:`~screwkit.closure.configuration_screws`, :mod:`~screwkit.closure.threads`.
"""

from screwkit.closure.assembly import working_modes
from screwkit.closure.configuration_screws import chain_screws, joint_screws
from screwkit.closure.forward_kinematics import forward
from screwkit.closure.solve import (
    Solution,
    UnreachablePose,
    actuator_values,
    closure_residuals,
    solve,
    solve_one,
    unreachable_reason,
)
from screwkit.closure.threads import thread_limit

__all__ = [
    "Solution",
    "UnreachablePose",
    "solve",
    "solve_one",
    "forward",
    "actuator_values",
    "closure_residuals",
    "unreachable_reason",
    "chain_screws",
    "joint_screws",
    "thread_limit",
    "working_modes",
]
