"""The mechanism model: what a mechanism file describes, as immutable records.

* :class:`Mechanism`, :class:`Chain`, :class:`ChainGeometry`: the model (see
  :mod:`~screwkit.model.mechanism`, :mod:`~screwkit.model.chain`);
* :mod:`~screwkit.model.urdf_reader`: the safe XML pass over a URDF (loops, transmissions,
  reference configuration, named poses, units), into the records of
  :mod:`~screwkit.model.urdf_description`, element by element (:mod:`~screwkit.model.urdf_element_reader`);
* :mod:`~screwkit.model.urdf_writer`: writing mechanisms in the same convention;
* :mod:`~screwkit.model.builder`: the chains of a file, through Pinocchio's tree;
* :mod:`~screwkit.model.pinocchio_bridge`: everything asked of Pinocchio.

Load a mechanism with :func:`screwkit.io.loader.load`.
"""

from screwkit.model.chain import Chain, ChainGeometry
from screwkit.model.mechanism import (
    PLANAR_TASK_COORDINATES,
    SPATIAL_TASK_COORDINATES,
    Mechanism,
    require_mechanism,
)

__all__ = ["Mechanism", "require_mechanism", "Chain", "ChainGeometry", "PLANAR_TASK_COORDINATES",
           "SPATIAL_TASK_COORDINATES"]
