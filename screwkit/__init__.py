"""screwkit: screw-theory fault-tolerance indices for redundantly actuated parallel robots.

The math core (:mod:`screwkit.screws`, :mod:`screwkit.transmission`,
:mod:`screwkit.closed_forms`, :mod:`screwkit.planar`) imports numpy only; its compiled
per-configuration kernels (:mod:`screwkit._wrench_kernel` and :mod:`screwkit._output_kernel`,
with their helpers in :mod:`screwkit._kernels`; :mod:`screwkit._planar_kernel`; numba) load when
indices are first computed. Everything that touches Pinocchio, files, plots, Meshcat, Dask or the
terminal lives at the edges and is imported lazily.
"""

__version__ = "0.1.0"
