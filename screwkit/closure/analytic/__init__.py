"""Closed-form solvers of the chain types that have one (numpy only, batched).

Each solver class recognises its chain type from a :class:`~screwkit.model.chain.ChainGeometry`
(:meth:`from_geometry` returns the solver, or a :class:`Rejection` saying why the chain is not of
that type) and solves whole batches of platform poses block by block, in threads:

* :class:`PlanarRevoluteChain` (``planar_rrr``): elbow by the intersection of two circles;
* :class:`PlanarSliderChain` (``planar_rpr``): the leg direction and length;
* :class:`LegVectorChain` (``ups``): the leg vector, pointed by the universal joint (Paden-Kahan 2);
* :class:`CrankRodChain` (``rus``): the crank angle from a circle-sphere intersection.

The planar ones are in :mod:`screwkit.closure.analytic.planar`, the spatial ones in
:mod:`screwkit.closure.analytic.spatial`, what they return in :mod:`screwkit.closure.analytic.results`;
this module lists them (:data:`CLOSED_FORMS`) and picks the one that fits a chain (:func:`closed_form_for`).

Recognition uses :data:`screwkit.common.tolerances.CLOSURE_TOLERANCE`, the tolerance at which a file's
loops must close, so a file written to 6 decimals keeps its closed forms.
"""

from __future__ import annotations

from screwkit.closure.analytic.planar import PlanarClosedForm as PlanarClosedForm
from screwkit.closure.analytic.planar import PlanarRevoluteChain, PlanarSliderChain
from screwkit.closure.analytic.results import ClosedFormResult, Rejection
from screwkit.closure.analytic.spatial import CrankRodChain, KernelKind, LegVectorChain
from screwkit.closure.analytic.spatial import SpatialClosedForm as SpatialClosedForm
from screwkit.model.chain import ChainGeometry

__all__ = [
    "ClosedFormResult",
    "KernelKind",
    "Rejection",
    "PlanarRevoluteChain",
    "PlanarSliderChain",
    "LegVectorChain",
    "CrankRodChain",
    "CLOSED_FORMS",
    "closed_form_for",
]


CLOSED_FORMS = (PlanarRevoluteChain, PlanarSliderChain, LegVectorChain, CrankRodChain)
"""Closed-form chain solvers tried, in order, for every chain."""


def closed_form_for(geometry: ChainGeometry, planar: bool, length: float = 1.0) -> tuple[object | None, str]:
    """The first closed form of :data:`CLOSED_FORMS` that fits the chain, and why.

    Parameters
    ----------
    geometry : ChainGeometry
    planar : bool
        Whether the mechanism is planar (only planar closed forms are tried, else only spatial ones).
    length : float
        The mechanism's length scale (m): point coincidences are judged relative to it.

    Returns
    -------
    solver : object or None
        A solver instance, or None when no closed form fits (the chain is solved by Newton).
    reason : str
        Which closed form matched, or for each one tried why it does not fit.
    """
    rejections = []
    for solver_class in CLOSED_FORMS:
        if solver_class.planar != planar:
            continue
        solver = solver_class.from_geometry(geometry, length)
        if not isinstance(solver, Rejection):
            return solver, f"closed form {solver_class.kind}: {solver_class.__doc__.strip().splitlines()[0]}"
        rejections.append(f"not {solver.kind} ({solver.reason})")
    return None, "damped Newton: " + "; ".join(rejections)

