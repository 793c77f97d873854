"""screwkit: screw-theory fault-tolerance indices for redundantly actuated parallel robots.

The top-level API, each name imported when first used (so that ``import screwkit`` loads nothing heavy)::

    import screwkit
    mechanism = screwkit.load("planar_5rrr")
    result = screwkit.indices_at_pose(mechanism, mechanism.named_pose("paper_fig_2a"))
    result.lmti, result.f_o[1]

* :func:`load` -- a bundled mechanism or a file (URDF, MJCF, Gepetto) as a :class:`~screwkit.model.Mechanism`;
* :func:`indices_at_pose`, :func:`indices_at_poses` -- every index at platform poses;
* :func:`analyze` -- every index from chain screws (no file, no closure);
* :class:`Indices` -- the one result type.

The packages name the layers, bottom up: :mod:`screwkit.common` (tolerances, units, rotations, the plumbing
of compiled kernels), :mod:`screwkit.screw` (the screw algebra, chain screws, motion spaces, constraint
wrenches, the plain-numpy reference of the pipeline), :mod:`screwkit.model` (what a file says),
:mod:`screwkit.indices` (the indices; :mod:`screwkit.indices.compiled` their numba kernels),
:mod:`screwkit.closure` (closure solving), :mod:`screwkit.io` (loading, files of other tools),
:mod:`screwkit.studies` (sweeps, maps, design search), :mod:`screwkit.plots`, :mod:`screwkit.viewer`,
:mod:`screwkit.cli`.
"""

from __future__ import annotations

from screwkit.common.lazy import lazy_attributes

__version__ = "0.1.0"

__all__ = ["load", "analyze", "indices_at_pose", "indices_at_poses", "Indices", "__version__"]

_API = {
    "load": "screwkit.io.loader",
    "analyze": "screwkit.indices.analysis",
    "indices_at_pose": "screwkit.studies.poses",
    "indices_at_poses": "screwkit.studies.poses",
    "Indices": "screwkit.indices.results",
}


__getattr__, __dir__ = lazy_attributes("screwkit", _API, globals())
