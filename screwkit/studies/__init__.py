"""Studies: indices at poses, sweeps, workspace maps and design searches of a mechanism.

* :func:`indices_at_poses`, :func:`indices_at_pose` (:mod:`~screwkit.studies.poses`): closure ->
  screws -> :class:`~screwkit.indices.results.Indices`;
* :func:`~screwkit.studies.sweep.sweep`: the paper's Fig. 4 series along one coordinate;
* :mod:`~screwkit.studies.maps`: the Fig. 5 maps (minimum over an orientation set on a grid);
* :func:`~screwkit.studies.trajectory.trajectory`: every index along a path (:mod:`~screwkit.studies.paths`) and
  the stretches each actuator failure leaves uncontrollable, refined between samples
  (:mod:`~screwkit.studies.refinement`), its changes of working mode (:mod:`~screwkit.studies.branches`), paths
  given as actuator values (:mod:`~screwkit.studies.actuator_paths`);
* :mod:`~screwkit.studies.design.permutations`: the paper's permutation selection;
* :mod:`~screwkit.studies.design.families`, :mod:`~screwkit.studies.design.objectives`,
  :mod:`~screwkit.studies.design.optimise`: parametric mechanism families, the metrics of a map's
  fault-tolerant region, and the design search over a family (one objective or a Pareto front);
* :mod:`~screwkit.studies.tasks` (Dask) and :mod:`~screwkit.studies.files` (atomic netCDF/CSV).
"""

from screwkit.studies.poses import indices_at_pose, indices_at_poses

__all__ = ["indices_at_poses", "indices_at_pose"]
