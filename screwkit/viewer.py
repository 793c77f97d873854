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

:func:`animate_sweep` turns a batch of poses into a Meshcat animation (one keyframe per
reachable pose), :func:`export_html` writes the scene as one offline HTML page (the viewer's
JavaScript inlined), and :data:`view` is the ``screwkit view`` command.

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

from __future__ import annotations

import contextlib
import io
import os
import re
import select
import subprocess
import sys
import tempfile
import time
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Self

import click
import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.transmission import DEFAULT_THRESHOLD

__all__ = [
    "COLORMAP_NAME",
    "FAILED_COLOR",
    "LOOPBACK_HOST",
    "Marker",
    "Scene",
    "ViewerServer",
    "animate_sweep",
    "colors_from_values",
    "export_html",
    "resolve_actuators",
    "show",
    "start_viewer",
    "view",
]

LOOPBACK_HOST = "127.0.0.1"
"""The only address the Meshcat servers started here listen on."""
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
BASE_COLOR = (0.80, 0.80, 0.82, 1.0)
PLATFORM_COLOR = (0.30, 0.32, 0.38, 1.0)
WRENCH_COLOR = (1.0, 0.50, 0.05, 1.0)
"""RGBA of the actuation wrench lines (orange: no viridis colour is orange)."""
TWIST_COLOR = (0.85, 0.10, 0.75, 1.0)
"""RGBA of the output twist axes, instantaneous centres and translation arrows (magenta)."""
BACKGROUND_COLORS = ((0.98, 0.98, 0.98), (0.80, 0.82, 0.85))
"""Top and bottom colours of the viewer background (light grey, so coloured chains stand out)."""
MARKER_KINDS = ("actuation_wrench", "actuation_couple", "twist_axis", "instantaneous_centre", "translation",
                "failed_actuator", "link", "joint")
"""Kinds of :class:`Marker`."""

_SERVER_CODE = r"""
import os, sys
import tornado.web
host = sys.argv[1]
_listen = tornado.web.Application.listen
def _listen_on_host(self, port, address=None, **kwargs):
    return _listen(self, port, host, **kwargs)
tornado.web.Application.listen = _listen_on_host
from meshcat.servers.zmqserver import ZMQWebSocketBridge
bridge = ZMQWebSocketBridge(host=host)
sys.stdout.write("zmq_url=%s\nweb_url=%s\n" % (bridge.zmq_url, bridge.web_url))
sys.stdout.flush()
quiet = os.open(os.devnull, os.O_WRONLY)
os.dup2(quiet, 1)
os.dup2(quiet, 2)
bridge.run()
"""
"""Started as ``python -c``: meshcat's ZeroMQ/websocket bridge with tornado's ``listen``
forced onto ``host`` (meshcat passes no address, which means every interface)."""


# ----------------------------------------------------------------------------------------
# Server
# ----------------------------------------------------------------------------------------
class ViewerServer:
    """A Meshcat server child process listening on :data:`LOOPBACK_HOST` only.

    Start it with :meth:`start`; stop it with :meth:`stop` (also called when the object is
    garbage collected or Python exits).

    Attributes
    ----------
    process : subprocess.Popen
        The server process (meshcat's ``ZMQWebSocketBridge``).
    zmq_url : str
        ``tcp://127.0.0.1:PORT`` the Python client sends commands to.
    web_url : str
        ``http://127.0.0.1:PORT/static/``, the page of the viewer.
    """

    def __init__(self, process: subprocess.Popen, zmq_url: str, web_url: str):
        self.process = process
        self.zmq_url = zmq_url
        self.web_url = web_url
        self._finalizer = weakref.finalize(self, _stop_process, process)
        _SERVERS.add(self)

    @classmethod
    def start(cls, host: str = LOOPBACK_HOST, timeout: float = 30.0) -> ViewerServer:
        """Start a server bound to ``host`` and wait until it reports its URLs.

        Parameters
        ----------
        host : str
            Listening address of both the web and the ZeroMQ socket. Keep the default
            ``"127.0.0.1"`` unless the viewer must be reachable from other machines.
        timeout : float
            Seconds to wait for the server to start.

        Raises
        ------
        RuntimeError
            The server exited or did not report its URLs in time (the message quotes its output).
        """
        with tempfile.TemporaryFile() as errors:
            process = subprocess.Popen([sys.executable, "-c", _SERVER_CODE, host], stdin=subprocess.DEVNULL,
                                       stdout=subprocess.PIPE, stderr=errors, start_new_session=True)
            urls: dict[str, str] = {}
            problem = None
            deadline = time.monotonic() + timeout
            try:
                while len(urls) < 2:
                    remaining = deadline - time.monotonic()
                    if remaining <= 0 or not select.select([process.stdout], [], [], remaining)[0]:
                        problem = f"did not report its URLs within {timeout:g} s"
                        break
                    line = process.stdout.readline()
                    if not line:  # end of its output: the server exited
                        process.wait(timeout=5)
                        problem = "exited"
                        break
                    key, separator, value = line.decode("utf-8", "replace").strip().partition("=")
                    if separator:
                        urls[key] = value
            except BaseException:
                _stop_process(process)
                raise
            if problem is not None:
                _stop_process(process)
                errors.seek(0)
                output = errors.read().decode("utf-8", "replace").strip()
                raise RuntimeError(f"The Meshcat server on {host} {problem} (exit code {process.returncode}): "
                                   f"{output[-2000:] or 'no output'}")
        process.stdout.close()
        return cls(process, urls["zmq_url"], urls["web_url"])

    @property
    def running(self) -> bool:
        """Whether the server process is alive."""
        return self.process.poll() is None

    def stop(self) -> None:
        """Terminate the server process (kill it if it does not exit within 5 s); idempotent."""
        self._finalizer()

    def __repr__(self) -> str:
        state = "running" if self.running else f"stopped ({self.process.returncode})"
        return f"ViewerServer(web_url={self.web_url!r}, pid={self.process.pid}, {state})"


_SERVERS: weakref.WeakSet = weakref.WeakSet()


def servers_to_stop() -> bool:
    """Whether some server process started here is still to be stopped (at the latest at exit)."""
    return any(server._finalizer.alive for server in _SERVERS)


def _stop_process(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    if process.stdout is not None and not process.stdout.closed:
        process.stdout.close()


def start_viewer(server: ViewerServer | None = None, *, timeout: float = 30.0):
    """A ``meshcat.Visualizer`` connected to a server on 127.0.0.1, with screwkit's background.

    Parameters
    ----------
    server : ViewerServer, optional
        Connect to this server; default: start a new one (``viewer.window.server_proc`` is
        its process, as with ``meshcat.Visualizer()``).
    timeout : float
        Seconds to wait for the server to start, and for each reply of the server.

    Returns
    -------
    meshcat.Visualizer
        ``viewer.window.screwkit_server`` holds the :class:`ViewerServer`.
    """
    import zmq

    meshcat = _import_meshcat()
    server = ViewerServer.start(timeout=timeout) if server is None else server
    with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints the URL
        viewer = meshcat.Visualizer(zmq_url=server.zmq_url)
    viewer.window.zmq_socket.setsockopt(zmq.RCVTIMEO, int(max(timeout, 60.0) * 1000))
    viewer.window.server_proc = server.process
    viewer.window.screwkit_server = server
    _style_viewer(viewer)
    return viewer


def _import_meshcat():
    """``import meshcat`` without its DeprecationWarning (its server module imports zmq.eventloop.ioloop)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import meshcat
        import meshcat.servers.zmqserver
    return meshcat


def _style_viewer(viewer) -> None:
    top, bottom = BACKGROUND_COLORS
    viewer["/Background"].set_property("top_color", list(top))
    viewer["/Background"].set_property("bottom_color", list(bottom))


# ----------------------------------------------------------------------------------------
# Colours, actuators, markers
# ----------------------------------------------------------------------------------------
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
    mechanism : screwkit.mechanism.Mechanism
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
    names = [f"{chain}:{joint}" for chain, joint in mechanism.actuators]
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
        hits = [i for i, (chain, joint) in enumerate(mechanism.actuators) if text in (names[i], joint, chain)]
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
    """

    path: str
    kind: str
    actuator: int | None
    start: NDArray[np.float64]
    end: NDArray[np.float64]
    failed: bool = False
    chain: int | None = None

    @property
    def direction(self) -> NDArray[np.float64]:
        """Unit vector from ``start`` to ``end`` (zeros for a point marker)."""
        difference = self.end - self.start
        norm = np.linalg.norm(difference)
        return difference / norm if norm > 0 else np.zeros(3)


# ----------------------------------------------------------------------------------------
# The scene
# ----------------------------------------------------------------------------------------
@dataclass(eq=False)
class Scene:
    """A mechanism drawn in a Meshcat viewer, with the indices it shows.

    Made by :func:`show` and :func:`animate_sweep`. Use it as a context manager, or call
    :meth:`close`, to stop a server it started.

    Attributes
    ----------
    mechanism : screwkit.mechanism.Mechanism
    poses : ndarray, shape (frames, n_task)
        The drawn poses (metres, radians): one for :func:`show`, the reachable poses of the
        sweep for :func:`animate_sweep`.
    result : screwkit.transmission.TransmissionResult
        Indices at the poses (batch shape ``()`` for :func:`show`, ``(frames,)`` for a sweep).
    failed : tuple of int
        Failed actuators (indices into ``mechanism.actuators``).
    color_by : {"iti", "oti"}
    chain_values : ndarray, shape (frames, n_chains)
        The index each chain is coloured by (NaN: none); the drawn colours are those of the
        first frame.
    chain_colors : ndarray, shape (n_chains, 4)
        RGBA drawn for each chain (failed chains: :data:`FAILED_COLOR`).
    best_submechanisms : tuple
        Per frame, the best working submechanism (actuator indices) or None.
    frame_markers : tuple of tuple of Marker
        Per frame, the overlays drawn.
    visualizer : pinocchio.visualize.MeshcatVisualizer
    viewer : meshcat.Visualizer
    server : ViewerServer or None
        The server this scene started (None when drawn into a given viewer).
    frame_rate : float or None
        Frames per second of the animation (None for a still scene).
    display_offset : ndarray, shape (3,)
        Translation of the drawing (``/meshcat``, grid and axes) in the viewer, which puts the
        mechanism's centre on Meshcat's fixed orbit target; markers are in the mechanism's
        world frame.
    """

    mechanism: Any
    poses: NDArray[np.float64]
    result: Any
    failed: tuple[int, ...]
    color_by: str
    chain_values: NDArray[np.float64]
    chain_colors: NDArray[np.float64]
    best_submechanisms: tuple
    frame_markers: tuple
    visualizer: Any = field(repr=False)
    viewer: Any = field(repr=False)
    server: ViewerServer | None = None
    frame_rate: float | None = None
    display_offset: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))

    @property
    def pose(self) -> NDArray[np.float64]:
        """The (first) drawn pose."""
        return self.poses[0]

    @property
    def markers(self) -> tuple[Marker, ...]:
        """The overlays of the (first) frame."""
        return self.frame_markers[0]

    @property
    def url(self) -> str:
        """The viewer page, ``http://127.0.0.1:PORT/static/``."""
        return self.viewer.url()

    def markers_of_kind(self, kind: str, frame: int = 0) -> list[Marker]:
        """The markers of one kind (see :data:`MARKER_KINDS`) in a frame."""
        if kind not in MARKER_KINDS:
            raise ValueError(f"Expected a marker kind among {', '.join(MARKER_KINDS)}, got {kind!r}.")
        return [marker for marker in self.frame_markers[frame] if marker.kind == kind]

    def static_html(self) -> str:
        """The scene as one self-contained HTML page (see :func:`export_html`)."""
        return self.viewer.static_html()

    def close(self) -> None:
        """Disconnect and stop the server this scene started (nothing else); idempotent."""
        if self.server is not None:
            with contextlib.suppress(Exception):
                self.viewer.window.zmq_socket.close(linger=0)
            self.server.stop()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exception) -> None:
        self.close()


def show(mechanism, pose: ArrayLike | None = None, *, failed=None, threshold: float = DEFAULT_THRESHOLD,
         color_by: Literal["iti", "oti"] = "iti", viewer=None, open_browser: bool = False) -> Scene:
    """Draw a mechanism at one pose, coloured by its indices, with its screws.

    See the module docstring for what is drawn and in which colours.

    Parameters
    ----------
    mechanism : Mechanism, str or path
        A loaded mechanism, a bundled name or a URDF path (see :func:`screwkit.mechanism.load`).
    pose : array_like, shape (n_task,), optional
        Platform pose in metres and radians; default the home pose.
    failed : int, str or sequence of them, optional
        Failed actuators (see :func:`resolve_actuators`).
    threshold : float
        Singularity threshold *p* (m) of the indices.
    color_by : {"iti", "oti"}
        Colour each chain by the lowest ITI of its working actuators, or by the OTI of the
        best working submechanism that uses one of them.
    viewer : meshcat.Visualizer, Scene or pinocchio MeshcatVisualizer, optional
        Draw into this viewer (everything under ``/meshcat/screwkit`` is replaced); default:
        start a server on 127.0.0.1 (:func:`start_viewer`), stopped by :meth:`Scene.close`.
    open_browser : bool
        Open the viewer page in the default browser.

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        An unreachable pose (naming the chain), an unknown actuator, or a bad ``color_by``.
    """
    mechanism = _mechanism(mechanism)
    pose = np.asarray(mechanism.home_pose if pose is None else pose, dtype=float)
    pose = mechanism.check_poses(pose)
    if pose.ndim != 1:
        raise ValueError(f"Expected one pose with shape ({mechanism.n_task},), got {pose.shape}; "
                         "use animate_sweep for several poses.")
    return _draw(mechanism, pose[None], failed, threshold, color_by, viewer, open_browser, frame_rate=None,
                 strict=True, squeeze=True)


def animate_sweep(mechanism, poses: ArrayLike, *, failed=None, threshold: float = DEFAULT_THRESHOLD,
                  color_by: Literal["iti", "oti"] = "iti", viewer=None, frame_rate: float = 10.0,
                  loop: bool = True, open_browser: bool = False) -> Scene:
    """Animate the mechanism along a sweep of poses, with its screws following.

    The first reachable pose is drawn as by :func:`show` (chain colours from its indices);
    a Meshcat animation then moves the links, the wrench lines, the twist axes and the
    instantaneous centres through the reachable poses (unreachable ones are skipped), one
    keyframe per pose. Markers that do not exist in a frame (a centre at infinity, a twist
    of a frame without a working submechanism) are hidden in it.

    Parameters
    ----------
    mechanism : Mechanism, str or path
    poses : array_like, shape (frames, n_task)
        Platform poses in metres and radians, in the order to play them.
    failed, threshold, color_by, viewer, open_browser
        As for :func:`show`.
    frame_rate : float
        Keyframes per second.
    loop : bool
        Repeat the animation (else play it once).

    Returns
    -------
    Scene
        ``scene.poses`` are the animated (reachable) poses.

    Raises
    ------
    ValueError
        No reachable pose, or bad arguments.
    """
    mechanism = _mechanism(mechanism)
    poses = mechanism.check_poses(poses).reshape(-1, mechanism.n_task)
    if not frame_rate > 0:
        raise ValueError(f"Expected `frame_rate` > 0, got {frame_rate}.")
    return _draw(mechanism, poses, failed, threshold, color_by, viewer, open_browser, frame_rate=float(frame_rate),
                 strict=False, squeeze=False, loop=loop)


def export_html(target, path: str | os.PathLike) -> Path:
    """Write a scene as one self-contained HTML page that works offline.

    The page is Meshcat's ``static_html()``: the viewer's JavaScript and every drawing
    command inlined, no network access. It is written to a temporary file in the same
    folder and moved into place (``os.replace``), so a reader never sees a partial file.

    Parameters
    ----------
    target : Scene, meshcat.Visualizer or pinocchio MeshcatVisualizer
    path : str or path-like
        The HTML file (its folder must exist).

    Returns
    -------
    pathlib.Path
    """
    viewer = _meshcat_viewer(target)
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ValueError(f"Cannot write {path}: the folder {folder} does not exist.")
    html = viewer.static_html()
    descriptor, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(descriptor, "w", encoding="utf-8") as handle:
            handle.write(html)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(temporary, 0o666 & ~_umask())
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise
    return path


def _umask() -> int:
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    return 0o022


def _mechanism(mechanism):
    if isinstance(mechanism, (str, os.PathLike)):
        from screwkit.mechanism import load

        return load(mechanism)
    return mechanism


def _meshcat_viewer(target):
    if isinstance(target, Scene):
        if target.server is not None and not target.server.running:
            raise ValueError("The scene's server is stopped (Scene.close was called): export or draw before closing.")
        return target.viewer
    if hasattr(target, "static_html") and hasattr(target, "window"):
        return target
    if hasattr(target, "viewer") and hasattr(target.viewer, "static_html"):
        return target.viewer  # pinocchio's MeshcatVisualizer
    raise ValueError("Expected a Scene, a meshcat.Visualizer or a pinocchio MeshcatVisualizer, "
                     f"got {type(target).__name__}.")


# ----------------------------------------------------------------------------------------
# Drawing
# ----------------------------------------------------------------------------------------
@dataclass
class _Frames:
    """Everything per pose that the drawing needs (leading axis: frames)."""

    poses: NDArray
    configurations: NDArray  # (F, nq)
    chain_points: list  # per chain (F, m_i, 3), world
    centres: NDArray  # (F, 3) platform origin, world
    result: Any  # batched over F


def _solve_frames(mechanism, poses: NDArray, threshold: float, strict: bool) -> _Frames:
    from screwkit.transmission import analyze

    solution = mechanism.solve(poses)
    reachable = np.asarray(solution.reachable)
    if not np.all(reachable):
        if strict:
            mechanism.solve_one(poses[int(np.flatnonzero(~reachable)[0])])  # raises, naming the chain
        if not np.any(reachable):
            raise ValueError(f"None of the {poses.shape[0]} poses is reachable for mechanism {mechanism.name!r}.")
        poses = poses[reachable]
        solution = mechanism.solve(poses)
    screws = mechanism.chain_screws(solution)
    result = analyze(screws, threshold=threshold, keep_twists=True)
    configurations = mechanism.configuration_vector(solution.joint_values, solution.poses)
    _, translation = mechanism.transforms_from_poses(solution.poses)
    centres = translation @ np.asarray(mechanism.rotation_world_base).T + np.asarray(mechanism.translation_world_base)
    return _Frames(poses=np.asarray(solution.poses),
                   configurations=np.asarray(configurations).reshape(poses.shape[0], -1),
                   chain_points=[np.asarray(s.points) for s in screws], centres=centres, result=result)


def _best_submechanism(result, frame: int, failed: tuple[int, ...]) -> int | None:
    """Index of the working submechanism with the highest OTI (None if there is none)."""
    otis = np.asarray(result.oti_submechanisms)[frame]
    working = np.array([not set(sub) & set(failed) for sub in result.submechanisms], dtype=bool)
    scores = np.where(working & np.isfinite(otis), otis, -np.inf)
    if scores.size == 0 or not np.isfinite(np.max(scores)):
        return None
    return int(np.argmax(scores))


def _chain_values(mechanism, result, frame: int, failed: tuple[int, ...], color_by: str) -> NDArray:
    chain_index = {chain.name: index for index, chain in enumerate(mechanism.chains)}
    actuators_of = [[] for _ in mechanism.chains]
    for actuator, (chain, _) in enumerate(mechanism.actuators):
        if actuator not in failed:
            actuators_of[chain_index[chain]].append(actuator)
    values = np.full(len(mechanism.chains), np.nan)
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


def _label(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)


def _frame_markers(mechanism, frames: _Frames, frame: int, failed: tuple[int, ...], best: int | None,
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
        label = _label(f"{actuator}-{chain_name}-{joint_name}")
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
            markers.extend(_twist_markers(mechanism, slot, actuator, twist, centre, length))
    for chain, position, failed_link in bare_links:
        points = frames.chain_points[chain][frame]
        start, end = points[position], points[position + 1]
        if np.linalg.norm(end - start) < 1e-9 * length:  # e.g. the cross of a universal joint
            continue
        name = _label(mechanism.chains[chain].name)
        markers.append(Marker(f"{ROOT_PATH}/links/{name}/{position}", "link", None, start.copy(), end.copy(),
                              failed=failed_link, chain=chain))
        for end_index, point in ((position, start), (position + 1, end)):
            markers.append(Marker(f"{ROOT_PATH}/links/{name}/joint_{end_index}", "joint", None, point.copy(),
                                  point.copy(), failed=failed_link, chain=chain))
    unique: dict[str, Marker] = {}
    for marker in markers:
        unique.setdefault(marker.path, marker)
    return list(unique.values())


def _twist_markers(mechanism, slot: int, actuator: int, twist: NDArray, centre: NDArray, length: float) -> list[Marker]:
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
            if mechanism.is_planar:
                in_plane = axis_point + direction * (centre[2] - axis_point[2]) / direction[2] \
                    if abs(direction[2]) > 1e-12 else nearest
                markers.append(Marker(f"{base}/centre", "instantaneous_centre", actuator, in_plane, in_plane.copy()))
            return markers
    direction = centre_velocity / max(np.linalg.norm(centre_velocity), 1e-300)
    return [Marker(f"{base}/translation", "translation", actuator, centre.copy(), centre + 0.6 * length * direction)]


def _visual_model(mechanism):
    import warnings

    import pinocchio

    try:
        return pinocchio.buildGeomFromUrdfString(mechanism.model, mechanism.description.text,
                                                 pinocchio.GeometryType.VISUAL, None,
                                                 [str(Path(mechanism.path).resolve().parent)])
    except Exception as error:  # noqa: BLE001 - Pinocchio raises plain RuntimeErrors; draw rods instead
        warnings.warn(f"{mechanism.path}: cannot load the visual geometry ({str(error).strip()[:200]}); "
                      "drawing rods between joints instead.", stacklevel=3)
        return pinocchio.GeometryModel()


def _geometry_owners(mechanism, visual_model) -> tuple[list, list]:
    """Per geometry object its owner ("base", "platform", chain index), and the bare links.

    A bare link is ``(chain, position, failed)``: the link after tree joint ``position`` of a
    chain has no visual geometry.
    """
    model = mechanism.model
    platform_joint = model.getJointId(mechanism.platform_joint)
    owner_of_joint = {0: "base", platform_joint: "platform"}
    joints_of_chain = []
    for index, chain in enumerate(mechanism.chains):
        ids = [model.getJointId(name) for name in chain.joint_names if model.existJointName(name)]
        joints_of_chain.append(ids)
        for joint_id in ids:
            owner_of_joint[joint_id] = index
    owners = [owner_of_joint.get(obj.parentJoint, "base") for obj in visual_model.geometryObjects]
    with_visual = {obj.parentJoint for obj in visual_model.geometryObjects}
    bare = [(index, position) for index, ids in enumerate(joints_of_chain)
            for position, joint_id in enumerate(ids) if joint_id not in with_visual]
    return owners, bare


def _failed_joint_ids(mechanism, failed: tuple[int, ...]) -> tuple[set, set]:
    """Joint ids of failed actuated joints, and chains whose every actuator failed."""
    model = mechanism.model
    joint_ids = {model.getJointId(joint) for index, (_, joint) in enumerate(mechanism.actuators)
                 if index in failed and model.existJointName(joint)}
    chains = set()
    for index, chain in enumerate(mechanism.chains):
        members = [i for i, (name, _) in enumerate(mechanism.actuators) if name == chain.name]
        if members and all(i in failed for i in members):
            chains.add(index)
    return joint_ids, chains


def _draw(mechanism, poses, failed, threshold, color_by, viewer, open_browser, *, frame_rate, strict, squeeze,
          loop=True) -> Scene:
    import pinocchio

    _import_meshcat()
    from pinocchio.visualize import MeshcatVisualizer

    if color_by not in ("iti", "oti"):
        raise ValueError(f"Expected `color_by` 'iti' or 'oti', got {color_by!r}.")
    failed = resolve_actuators(mechanism, failed)
    frames = _solve_frames(mechanism, poses, threshold, strict)
    count = frames.poses.shape[0]
    result = frames.result
    best = tuple(_best_submechanism(result, frame, failed) for frame in range(count))
    chain_values = np.stack([_chain_values(mechanism, result, frame, failed, color_by) for frame in range(count)])
    visual_model = _visual_model(mechanism)
    owners, bare = _geometry_owners(mechanism, visual_model)
    failed_joints, failed_chains = _failed_joint_ids(mechanism, failed)
    model = mechanism.model
    bare_links = []
    for chain, position in bare:
        tree_joints = [name for name in mechanism.chains[chain].joint_names if model.existJointName(name)]
        joint_id = model.getJointId(tree_joints[position])
        bare_links.append((chain, position, chain in failed_chains or joint_id in failed_joints))
    markers = tuple(tuple(_frame_markers(mechanism, frames, frame, failed, best[frame], bare_links))
                    for frame in range(count))
    chain_colors = colors_from_values(chain_values[0])
    for chain in failed_chains:
        chain_colors[chain] = FAILED_COLOR

    server = None
    if viewer is None:
        meshcat_viewer = start_viewer()
        server = meshcat_viewer.window.screwkit_server
    else:
        meshcat_viewer = _meshcat_viewer(viewer)
    try:
        meshcat_viewer[ROOT_PATH].delete()
        if getattr(meshcat_viewer.window, "screwkit_animated", False):
            _clear_animation(meshcat_viewer)
        visualizer = MeshcatVisualizer(model, None, visual_model)
        visualizer.initViewer(viewer=meshcat_viewer)
        visualizer.loadViewerModel(rootNodeName=f"{ROOT_PATH}/mechanism")
        for geometry, owner in zip(visual_model.geometryObjects, owners):
            if owner == "base":
                color = BASE_COLOR
            elif owner == "platform":
                color = PLATFORM_COLOR
            elif owner in failed_chains or geometry.parentJoint in failed_joints:
                color = FAILED_COLOR
            else:
                color = tuple(chain_colors[owner])
            node = visualizer.getViewerNodeName(geometry, pinocchio.GeometryType.VISUAL)
            meshcat_viewer[node].set_property("color", [float(c) for c in color])
        visualizer.display(frames.configurations[0])
        all_markers = {}
        for frame_markers in markers:
            for marker in frame_markers:
                all_markers.setdefault(marker.path, marker)
        for marker in all_markers.values():
            _create_marker(meshcat_viewer, marker, mechanism, chain_colors)
        for marker in markers[0]:
            meshcat_viewer[marker.path].set_transform(_marker_matrix(marker))
        for path in set(all_markers) - {marker.path for marker in markers[0]}:
            meshcat_viewer[path].set_property("visible", False)
        display_offset = _frame_view(meshcat_viewer, mechanism, frames)
        if frame_rate is not None:
            _animate(meshcat_viewer, visualizer, visual_model, frames, markers, all_markers, frame_rate, loop)
    except BaseException:
        if server is not None:
            with contextlib.suppress(Exception):
                meshcat_viewer.window.zmq_socket.close(linger=0)
            server.stop()
        raise
    if squeeze:
        result = _squeeze_result(result)
    scene = Scene(mechanism=mechanism, poses=frames.poses, result=result, failed=failed, color_by=color_by,
                  chain_values=chain_values, chain_colors=chain_colors, best_submechanisms=tuple(
                      None if b is None else tuple(result.submechanisms[b]) for b in best),
                  frame_markers=markers, visualizer=visualizer, viewer=meshcat_viewer, server=server,
                  frame_rate=frame_rate, display_offset=display_offset)
    if open_browser:
        meshcat_viewer.open()
    return scene


def _squeeze_result(result):
    """A one-configuration result with batch shape ``()``."""
    import dataclasses

    changes = {}
    for item in dataclasses.fields(result):
        value = getattr(result, item.name)
        if item.name == "batch_shape":
            changes[item.name] = ()
        elif isinstance(value, np.ndarray) and value.ndim >= 1 and value.shape[0] == 1:
            changes[item.name] = value[0]
        elif isinstance(value, dict):
            changes[item.name] = {key: (v[0] if isinstance(v, np.ndarray) and v.ndim >= 1 and v.shape[0] == 1 else v)
                                  for key, v in value.items()}
    return dataclasses.replace(result, **changes)


def _hex(color) -> int:
    red, green, blue = (round(255 * float(np.clip(c, 0.0, 1.0))) for c in color[:3])
    return (red << 16) + (green << 8) + blue


def _material(color):
    from meshcat import geometry

    alpha = float(color[3]) if len(color) > 3 else 1.0
    return geometry.MeshLambertMaterial(color=_hex(color), opacity=alpha, transparent=alpha < 1.0)


def _line_radius(mechanism) -> float:
    return 0.008 * float(mechanism.length_scale)


def _create_marker(viewer, marker: Marker, mechanism, chain_colors) -> None:
    """Send the geometry of a marker (placed later by :func:`_marker_matrix`)."""
    from meshcat import geometry, transformations

    radius = _line_radius(mechanism)
    length = float(np.linalg.norm(marker.end - marker.start))
    node = viewer[marker.path]
    if marker.kind in ("actuation_wrench", "actuation_couple", "twist_axis", "translation"):
        color = WRENCH_COLOR if marker.kind.startswith("actuation") else TWIST_COLOR
        color = FAILED_COLOR if marker.failed else color
        material = _material(color)
        node["line"].set_object(geometry.Cylinder(length, radius), material)
        head = 6.0 * radius
        heads = [1.0, -1.0] if marker.kind == "actuation_couple" else [1.0]
        for number, sign in enumerate(heads):
            rotation = transformations.rotation_matrix(np.pi if sign < 0 else 0.0, [1.0, 0.0, 0.0])
            rotation[:3, 3] = [0.0, sign * (length / 2.0 - head / 2.0), 0.0]
            node[f"head_{number}"].set_object(geometry.Cylinder(head, radiusTop=0.0, radiusBottom=2.5 * radius),
                                              material)
            node[f"head_{number}"].set_transform(rotation)
    elif marker.kind == "instantaneous_centre":
        node.set_object(geometry.Sphere(3.0 * radius), _material(TWIST_COLOR))
    elif marker.kind == "failed_actuator":
        size = 0.12 * float(mechanism.length_scale)
        material = _material(FAILED_MARKER_COLOR)
        for number, angle in enumerate((np.pi / 4, -np.pi / 4)):
            node[f"bar_{number}"].set_object(geometry.Box([size, 0.18 * size, 0.18 * size]), material)
            node[f"bar_{number}"].set_transform(transformations.rotation_matrix(angle, [0.0, 0.0, 1.0]))
    elif marker.kind == "link":
        color = FAILED_COLOR if marker.failed else tuple(chain_colors[marker.chain])
        node.set_object(geometry.Cylinder(1.0, 2.0 * radius), _material(color))
    elif marker.kind == "joint":
        color = FAILED_COLOR if marker.failed else tuple(chain_colors[marker.chain])
        node.set_object(geometry.Sphere(3.0 * radius), _material(color))


def _rotation_with_y_along(direction: NDArray) -> NDArray:
    """A rotation whose y axis (three.js cylinders) is ``direction``."""
    norm = np.linalg.norm(direction)
    if not norm > 0:
        return np.eye(3)
    y_axis = direction / norm
    helper = np.array([1.0, 0.0, 0.0]) if abs(y_axis[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    x_axis = np.cross(y_axis, helper)
    x_axis /= np.linalg.norm(x_axis)
    z_axis = np.cross(x_axis, y_axis)
    return np.column_stack([x_axis, y_axis, z_axis])


def _marker_placement(marker: Marker) -> tuple[NDArray, NDArray, NDArray]:
    """Position, rotation and scale of a marker's node."""
    if marker.kind in ("instantaneous_centre", "failed_actuator", "joint"):
        return marker.start, np.eye(3), np.ones(3)
    rotation = _rotation_with_y_along(marker.end - marker.start)
    middle = 0.5 * (marker.start + marker.end)
    if marker.kind == "link":
        return middle, rotation, np.array([1.0, max(float(np.linalg.norm(marker.end - marker.start)), 1e-9), 1.0])
    return middle, rotation, np.ones(3)


def _marker_matrix(marker: Marker) -> NDArray:
    position, rotation, scale = _marker_placement(marker)
    matrix = np.eye(4)
    matrix[:3, :3] = rotation * scale
    matrix[:3, 3] = position
    return matrix


def _frame_view(viewer, mechanism, frames: _Frames) -> NDArray[np.float64]:
    """Centre the mechanism on the orbit target and place the camera; return the display offset.

    Meshcat 0.3 orbits about the viewer's origin and cannot move that target, so the scene
    (``/meshcat``) and the ground grid and axes are shifted together by ``-centre``: the
    picture is the mechanism's world, centred where the camera looks.
    """
    points = np.concatenate([points[0].reshape(-1, 3) for points in frames.chain_points] + [frames.centres[:1]])
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    if mechanism.is_planar:
        centre[2] = 0.0
    reach = max(float(np.max(np.linalg.norm(points - centre, axis=-1))), 0.5 * float(mechanism.length_scale), 1e-3)
    if mechanism.is_planar:
        direction, distance = np.array([0.3, -0.75, 1.0]), 1.9 * reach
    else:
        direction, distance = np.array([1.0, -1.4, 0.7]), 2.4 * reach
    shift = np.eye(4)
    shift[:3, 3] = -centre
    for path in ("/meshcat", "/Grid", "/Axes"):
        viewer[path].set_transform(shift)
    position = distance * direction / np.linalg.norm(direction)
    # The camera sits in the viewer's y-up "rotated" frame: (x, z, -y) of the world.
    viewer["/Cameras/default/rotated/<object>"].set_property(
        "position", [float(position[0]), float(position[2]), float(-position[1])])
    return -centre


def _clear_animation(viewer) -> None:
    import meshcat.animation

    viewer.set_animation(meshcat.animation.Animation(), play=False)
    viewer.window.screwkit_animated = False


def _animate(viewer, visualizer, visual_model, frames: _Frames, markers, all_markers, frame_rate, loop) -> None:
    import meshcat.animation
    import pinocchio
    from meshcat import transformations

    model, data = visualizer.model, visualizer.data
    visual_data = visualizer.visual_data
    animation = meshcat.animation.Animation(default_framerate=frame_rate)
    for frame, configuration in enumerate(frames.configurations):
        pinocchio.forwardKinematics(model, data, configuration)
        pinocchio.updateGeometryPlacements(model, data, visual_model, visual_data)
        with animation.at_frame(viewer, frame) as keyframe:
            for index, geometry in enumerate(visual_model.geometryObjects):
                node = visualizer.getViewerNodeName(geometry, pinocchio.GeometryType.VISUAL)
                keyframe[node].set_transform(visual_data.oMg[index].homogeneous)
                scale = np.asarray(geometry.meshScale, dtype=float).ravel()
                if not np.allclose(scale, 1.0):
                    keyframe[node].set_property("scale", "vector3", [float(s) for s in scale])
            present = {marker.path: marker for marker in markers[frame]}
            for path in all_markers:
                marker = present.get(path)
                keyframe[path].set_property("visible", "boolean", marker is not None)
                if marker is None:
                    continue
                position, rotation, scale = _marker_placement(marker)
                matrix = np.eye(4)
                matrix[:3, :3] = rotation
                matrix[:3, 3] = position
                keyframe[path].set_property("position", "vector3", [float(p) for p in position])
                quaternion = transformations.quaternion_from_matrix(matrix)  # (w, x, y, z)
                keyframe[path].set_property("quaternion", "quaternion",
                                            [float(quaternion[1]), float(quaternion[2]), float(quaternion[3]),
                                             float(quaternion[0])])
                if marker.kind == "link":
                    keyframe[path].set_property("scale", "vector3", [float(s) for s in scale])
    viewer.set_animation(animation, play=True, repetitions=10**6 if loop else 1)
    viewer.window.screwkit_animated = True


# ----------------------------------------------------------------------------------------
# Command line
# ----------------------------------------------------------------------------------------
class _ViewCommand(click.Command):
    """``view`` with its ``--pose`` option (screwkit.cli's GreedyOption) added on first use.

    :mod:`screwkit.cli` imports this module to register the command, so importing
    :mod:`screwkit.cli` here at import time would be circular.
    """

    def get_params(self, ctx: click.Context) -> list[click.Parameter]:
        if not any(parameter.name == "pose" for parameter in self.params):
            from screwkit.cli import GreedyOption

            self.params.insert(1, GreedyOption(
                ["--pose"], help="Platform pose: x y phi (planar) or x y z roll pitch yaw; m and deg. "
                                 "Default: the file's home pose."))
        return super().get_params(ctx)


@click.command("view", cls=_ViewCommand)
@click.argument("mechanism")
@click.option("--failed", "failed", multiple=True, metavar="NAME_OR_INDEX",
              help="A failed actuator: 0-based index, CHAIN:JOINT, joint or chain name. Repeatable.")
@click.option("--html", "html_path", type=click.Path(dir_okay=False),
              help="Write a self-contained offline HTML file and exit instead of serving.")
@click.option("--sweep-phi", "sweep_phi", metavar="START:STOP:STEP",
              help="Animate a planar sweep of phi (deg, stop exclusive) at the x y of --pose.")
@click.option("--frame-rate", type=click.FloatRange(min=0, min_open=True), default=10.0, show_default=True,
              help="--sweep-phi: keyframes per second.")
@click.option("--color-by", type=click.Choice(["iti", "oti"]), default="iti", show_default=True,
              help="Colour chains by their lowest ITI or by the OTI of their best working submechanism.")
@click.option("--threshold", type=float, default=DEFAULT_THRESHOLD, show_default=True,
              help="Singularity threshold p on the moment arm (m).")
@click.option("--open", "open_browser", is_flag=True, help="Open the viewer in the default browser.")
def view(mechanism: str, pose, failed, html_path, sweep_phi, frame_rate, color_by, threshold, open_browser) -> None:
    """Show MECHANISM in a Meshcat viewer (served on 127.0.0.1), coloured by its indices.

    Chains are coloured by index (viridis: 0 purple, 1 yellow), actuation wrench lines are
    orange, output twist axes and instantaneous centres of the best submechanism magenta,
    failed actuators red.
    """
    from screwkit.cli import _load, _pose, _range

    loaded = _load(mechanism)
    target = _pose(loaded, pose)
    failures = list(failed)  # indices or names, see resolve_actuators
    try:
        if sweep_phi is not None:
            if not loaded.is_planar:
                raise click.ClickException(f"--sweep-phi sweeps a planar mechanism; {loaded.name!r} is spatial.")
            angles = _range(sweep_phi, "--sweep-phi", True)
            poses = np.repeat(target[None], angles.size, axis=0)
            poses[:, 2] = angles
            scene = animate_sweep(loaded, poses, failed=failures, threshold=threshold, color_by=color_by,
                                  frame_rate=frame_rate)
        else:
            scene = show(loaded, target, failed=failures, threshold=threshold, color_by=color_by)
    except (ValueError, RuntimeError) as error:
        raise click.ClickException(str(error)) from None
    with scene:
        _echo_legend(scene)
        if html_path is not None:
            try:
                written = export_html(scene, html_path)
            except (ValueError, OSError) as error:
                raise click.ClickException(str(error)) from None
            click.echo(f"Wrote {written}")
            return
        try:  # from the moment the URL is shown, Ctrl+C stops the server and exits cleanly
            click.echo(f"Serving at {scene.url} (127.0.0.1 only); press Ctrl+C to stop.")
            if open_browser:
                scene.viewer.open()
            while scene.server.running:
                time.sleep(0.5)
        except KeyboardInterrupt:
            click.echo("Stopped.")
            return
        raise click.ClickException(
            f"The Meshcat server stopped unexpectedly (exit code {scene.server.process.returncode}).")


def _echo_legend(scene: Scene) -> None:
    mechanism = scene.mechanism
    frames = scene.poses.shape[0]
    what = "lowest ITI of its working actuators" if scene.color_by == "iti" else "OTI of its best working submechanism"
    extra = f" (first of {frames} frames)" if frames > 1 else ""
    click.echo(f"{mechanism.name}: chains coloured by the {what}{extra}; viridis 0 purple .. 1 yellow")
    names = [f"{chain}:{joint}" for chain, joint in mechanism.actuators]
    for index, chain in enumerate(mechanism.chains):
        value = scene.chain_values[0, index]
        failed = [names[i] for i in scene.failed if mechanism.actuators[i][0] == chain.name]
        note = f"  failed: {', '.join(failed)}" if failed else ""
        shown = "-" if np.isnan(value) else f"{value:.4f}"
        click.echo(f"  {chain.name:<24s} {shown}{note}")
    best = scene.best_submechanisms[0]
    if best is None:
        click.echo("No working submechanism: no output twist drawn.")
    else:
        click.echo("Output twists of the best working submechanism: " + ", ".join(names[i] for i in best))
