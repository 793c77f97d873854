r"""Meshcat views of a mechanism and its screws, live or as a self-contained HTML file.

:func:`show` draws a mechanism at one pose with Pinocchio's
:class:`pinocchio.visualize.MeshcatVisualizer` (the URDF's visual geometry: meshes or
box/cylinder/sphere primitives; links without a visual are drawn as rods between their joint
points) and overlays the screws the indices are made of:

* every **chain** coloured by its index with the :data:`COLORMAP_NAME` colour map
  (``viridis``: 0 dark purple, 0.5 teal, 1 yellow; see :func:`colors_from_values`): by
  default the lowest ITI of its working actuators (Eq. 6), or with ``color_by="oti"`` the OTI
  (Eq. 9) of the best working submechanism it takes part in;
* the **actuation wrench** of every actuator as a long thin orange line (:data:`WRENCH_COLOR`)
  along its axis, centred on its characteristic point (the chain's platform-joint point
  projected on the axis), with an arrowhead in the sense of the force ``f``; a pure couple is
  drawn along its moment with two heads;
* the **output twists** (Eq. 8) of the best working submechanism (the highest OTI among the
  non-redundant actuator sets without a failed actuator) in magenta (:data:`TWIST_COLOR`):
  the screw axis as a line with an arrowhead along :math:`\omega`, and for a planar mechanism
  a sphere at the **instantaneous centre** in the platform plane,

  .. math:: p = \frac{\omega \times v}{\lVert\omega\rVert^2};

  a twist at infinity (a translation) is drawn as an arrow along the velocity of the
  platform centre;
* **failed actuators** (``failed=``) in red (:data:`FAILED_COLOR`): their chain transparent
  red when all its actuators failed (else the links they drive), a red cross at the actuated
  joint, and their wrench line transparent red. The best submechanism and the ``oti``
  colours skip submechanisms that use a failed actuator.

A mechanism whose legs have loops inside them (:class:`screwkit.io.GraphMechanism`) has no visual geometry
here: its legs' bodies are drawn as rods between the joints and closure frames that hold them, its base and
platform as the outlines of the points where the legs hold them, its legs coloured in the same way, without screws
(its indices keep none; :mod:`screwkit.viewer.graph_drawing`).

:func:`animate_sweep` turns a batch of poses into a Meshcat animation (one keyframe per
reachable pose), :func:`export_html` writes the scene as one offline HTML page (the viewer's
JavaScript inlined), and the ``screwkit view`` command is :mod:`screwkit.cli.view`.

**Server.** A scene started here runs its own Meshcat server (:class:`ViewerServer`, a child
process) whose web and ZeroMQ sockets listen on ``127.0.0.1`` only: ``meshcat.Visualizer()``
would start ``meshcat.servers.zmqserver``, whose tornado web server listens on every
interface (``Application.listen(port)`` without an address), so the server here is started
with ``listen`` bound to the loopback address. Stop it with :meth:`Scene.close` (or a
``with`` block); it is also stopped when the Python process exits.

**Camera.** Meshcat 0.3 orbits about the viewer's origin, so the drawing, the ground grid and
the axes are shifted together to put the mechanism's centre there
(:attr:`Scene.display_offset`); markers and transforms under ``/meshcat`` stay in the
mechanism's world frame.

Pinocchio and Meshcat are imported inside the functions: ``import screwkit.viewer`` stays light.
"""

from screwkit.viewer.markers import (
    COLORMAP_NAME,
    FAILED_COLOR,
    MARKER_KINDS,
    TWIST_COLOR,
    WRENCH_COLOR,
    Marker,
    colors_from_values,
    resolve_actuators,
)
from screwkit.viewer.scene import Scene, animate_sweep, export_html, show
from screwkit.viewer.server import (
    LOOPBACK_HOST,
    ViewerServer,
    servers_to_stop,
    start_viewer,
)

__all__ = [
    "COLORMAP_NAME",
    "FAILED_COLOR",
    "LOOPBACK_HOST",
    "MARKER_KINDS",
    "TWIST_COLOR",
    "WRENCH_COLOR",
    "Marker",
    "Scene",
    "ViewerServer",
    "animate_sweep",
    "colors_from_values",
    "export_html",
    "resolve_actuators",
    "servers_to_stop",
    "show",
    "start_viewer",
]
