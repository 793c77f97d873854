"""Scenes: a mechanism drawn in Meshcat at one pose (:func:`show`) or along a sweep or a path
(:func:`animate_sweep`), and exported as one offline HTML page (:func:`export_html`)."""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Self

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.common.tolerances import SINGULARITY_THRESHOLD
from screwkit.io.closed_tree import LegWithLoops
from screwkit.io.graph import GraphMechanism
from screwkit.io.loader import bundled_graph_names, bundled_path, load
from screwkit.studies.files import atomic_text
from screwkit.studies.paths import checked_times
from screwkit.viewer.drawing import (
    BASE_COLOR,
    PLATFORM_COLOR,
    animate,
    clear_animation,
    create_marker,
    failed_joint_ids,
    frame_view,
    geometry_owners,
    load_visual_model,
    marker_matrix,
)
from screwkit.viewer.graph_drawing import graph_markers, solve_graph_frames
from screwkit.viewer.markers import (
    FAILED_COLOR,
    MARKER_KINDS,
    ROOT_PATH,
    Marker,
    best_submechanism,
    chain_index_values,
    colors_from_values,
    markers_of_frame,
    resolve_actuators,
    solve_frames,
)
from screwkit.viewer.server import ViewerServer, import_meshcat, start_viewer

__all__ = ["Scene", "show", "animate_sweep", "export_html"]


@dataclass(eq=False)
class Scene:
    """A mechanism drawn in a Meshcat viewer, with the indices it shows.

    Made by :func:`show` and :func:`animate_sweep`. Use it as a context manager, or call
    :meth:`close`, to stop a server it started.

    Attributes
    ----------
    mechanism : screwkit.model.Mechanism
    poses : ndarray, shape (frames, n_task)
        The drawn poses (metres, radians): one for :func:`show`, the reachable poses of the
        sweep for :func:`animate_sweep`.
    result : screwkit.indices.analysis.TransmissionResult
        Indices at the poses (batch shape ``()`` for :func:`show`, ``(frames,)`` for a sweep).
    failed : tuple of int
        Failed actuators (indices into ``mechanism.actuators``).
    color_by : {"iti", "oti"}
    chain_values : ndarray, shape (frames, n_chains)
        The index each chain is coloured by (NaN: none); the drawn colours are those of the
        first frame.
    chain_colors : ndarray, shape (n_chains, 4)
        RGBA drawn for each chain (failed chains: :data:`FAILED_COLOR`); an animation turns
        them to the colours of ``chain_values`` frame by frame.
    best_submechanisms : tuple
        Per frame, the best working submechanism (actuator indices) or None.
    frame_markers : tuple of tuple of Marker
        Per frame, the overlays drawn.
    visualizer : pinocchio.visualize.MeshcatVisualizer or None
        The visualizer of the mechanism's geometry (None for a mechanism whose legs have loops inside them, drawn
        as rods and spheres).
    viewer : meshcat.Visualizer
    server : ViewerServer or None
        The server this scene started (None when drawn into a given viewer).
    frame_rate : float or None
        Frames per second of the animation (None for a still scene).
    display_offset : ndarray, shape (3,)
        Translation of the drawing (``/meshcat``, grid and axes) in the viewer, which puts the
        mechanism's centre on Meshcat's fixed orbit target; markers are in the mechanism's
        world frame.
    times : ndarray, shape (frames,), or None
        Seconds at which each animated pose is reached when the animation follows the poses' own times (a path
        with a time column, or ``times``); None otherwise.
    kept : ndarray of int, shape (frames,)
        Which of the poses asked for are drawn (the reachable ones, in order): an animation skips the others and
        keeps the time base of all of them (see :func:`animate_sweep`).
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
    times: NDArray[np.float64] | None = None
    kept: NDArray[np.int64] = field(default_factory=lambda: np.zeros(1, dtype=int))

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


def show(mechanism, pose: ArrayLike | None = None, *, failed=None, threshold: float = SINGULARITY_THRESHOLD,
         color_by: Literal["iti", "oti"] = "iti", viewer=None, open_browser: bool = False,
         limits: bool = True) -> Scene:
    """Draw a mechanism at one pose, coloured by its indices, with its screws.

    See the module docstring for what is drawn and in which colours.

    Parameters
    ----------
    mechanism : Mechanism, str or path
        A loaded mechanism, a bundled name or a URDF path (see :func:`screwkit.io.loader.load`).
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
    limits : bool
        Whether a pose that puts a joint beyond its position limits is unreachable (``--ignore-limits``: False).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        An unreachable pose (naming the chain), an unknown actuator, or a bad ``color_by``.
    """
    mechanism = mechanism_of(mechanism)
    pose = np.asarray(mechanism.home_pose if pose is None else pose, dtype=float)
    pose = mechanism.check_poses(pose)
    if pose.ndim != 1:
        raise ValueError(f"Expected one pose with shape ({mechanism.n_task},), got {pose.shape}; "
                         "use animate_sweep for several poses.")
    return _draw(mechanism, pose[None], failed, threshold, color_by, viewer, open_browser, None, limits)


def animate_sweep(mechanism, poses: ArrayLike, *, failed=None, threshold: float = SINGULARITY_THRESHOLD,
                  color_by: Literal["iti", "oti"] = "iti", viewer=None, frame_rate: float = 10.0,
                  loop: bool = True, open_browser: bool = False, times: ArrayLike | None = None,
                  limits: bool = True) -> Scene:
    """Animate the mechanism along a sweep of poses or a path, with its screws and colours following.

    The first reachable pose is drawn as by :func:`show` (chain colours from its indices);
    a Meshcat animation then moves the links, the wrench lines, the twist axes and the
    instantaneous centres through the reachable poses, one keyframe per pose, and turns the
    colour of every working chain to that of its index at the pose (``scene.chain_values``;
    a failed chain stays red). Markers that do not exist in a frame (a centre at infinity, a
    twist of a frame without a working submechanism) are
    hidden in it.

    Unreachable poses are skipped (``scene.kept`` names the drawn ones) with their time: the keyframe of pose
    ``k`` stays at ``k / frame_rate`` (or ``times[k] - times[0]``) seconds, pose 0's time being the clip's start
    even when pose 0 is unreachable, so the platform moves straight across a skipped stretch in the time the path
    takes over it, and before the first reachable pose it waits there.

    Parameters
    ----------
    mechanism : Mechanism, str or path
    poses : array_like, shape (frames, n_task), or Path
        Platform poses in metres and radians, in the order to play them, or a
        :class:`~screwkit.studies.paths.Path` (its samples; with its times, if it has any).
    failed, threshold, color_by, viewer, open_browser, limits
        As for :func:`show`.
    frame_rate : float
        Keyframes per second (without times); with times, the clip's time base (keyframe numbers per second).
    loop : bool
        Repeat the animation (else play it once).
    times : array_like, shape (frames,), optional
        Seconds at which the platform is at each pose (finite, increasing; default: a path's own times, else
        none): the animation then plays the motion at its own pace, pose ``k`` at ``times[k] - times[0]``.

    Returns
    -------
    Scene
        ``scene.poses`` are the animated (reachable) poses.

    Raises
    ------
    ValueError
        No reachable pose, or bad arguments.
    """
    mechanism = mechanism_of(mechanism)
    if times is None:
        times = getattr(poses, "times", None)
    poses = mechanism.check_poses(getattr(poses, "poses", poses)).reshape(-1, mechanism.n_task)
    if not frame_rate > 0:
        raise ValueError(f"Expected `frame_rate` > 0, got {frame_rate}.")
    return _draw(mechanism, poses, failed, threshold, color_by, viewer, open_browser,
                 _Animation(float(frame_rate), loop, checked_times(times, poses.shape[0])), limits)


def export_html(target, path: str | os.PathLike) -> Path:
    """Write a scene as one self-contained HTML page that works offline.

    The page is Meshcat's ``static_html()``: the viewer's JavaScript and every drawing
    command inlined, no network access. It is written as every output is
    (:func:`screwkit.studies.files.atomic_write`): a temporary file in the same folder, moved into
    place, so a reader never sees a partial file.

    Parameters
    ----------
    target : Scene, meshcat.Visualizer or pinocchio MeshcatVisualizer
    path : str or path-like
        The HTML file (its folder must exist).

    Returns
    -------
    pathlib.Path
    """
    viewer = meshcat_viewer_of(target)
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ValueError(f"Cannot write {path}: the folder {folder} does not exist.")
    atomic_text(path, viewer.static_html())
    return path


def mechanism_of(mechanism):
    """A loaded mechanism, or one loaded from a bundled name or a path: a file whose legs have loops inside them as
    a :class:`~screwkit.io.GraphMechanism` at the file's configuration."""
    if not isinstance(mechanism, (str, os.PathLike)):
        return mechanism
    try:
        return load(mechanism)
    except LegWithLoops as error:
        from screwkit.io import graph_mechanism, read_closed_tree  # readers of other tools: for such a file only

        name = os.fspath(mechanism)
        try:
            return graph_mechanism(read_closed_tree(bundled_path(name) if name in bundled_graph_names() else name))
        except ValueError as graph_error:
            raise error.refusal(graph_error) from None


def meshcat_viewer_of(target):
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


@dataclass(frozen=True)
class _Animation:
    """The keyframes of :func:`animate_sweep`: per second, whether they repeat, and the poses' times (s) if given."""

    frame_rate: float
    loop: bool
    times: NDArray | None = None


@dataclass(frozen=True)
class _Geometry:
    """A serial mechanism's visual geometry (Pinocchio's), who owns each object, and what failed."""

    visual_model: Any
    owners: list
    failed_joints: set
    failed_chains: set


def _serial_drawing(mechanism, poses, failed, threshold, strict: bool, limits: bool = True):
    """Frames, markers and geometry of a mechanism of serial legs."""
    frames = solve_frames(mechanism, poses, threshold, strict, limits)
    best = tuple(best_submechanism(frames.result, frame, failed) for frame in range(frames.poses.shape[0]))
    visual_model = load_visual_model(mechanism)
    owners, bare = geometry_owners(mechanism, visual_model)
    failed_joints, failed_chains = failed_joint_ids(mechanism, failed)
    model = mechanism.pinocchio_model
    bare_links = []
    for chain, position in bare:
        tree_joints = [name for name in mechanism.chains[chain].joint_names if model.existJointName(name)]
        joint_id = model.getJointId(tree_joints[position])
        bare_links.append((chain, position, chain in failed_chains or joint_id in failed_joints))
    markers = tuple(tuple(markers_of_frame(mechanism, frames, frame, failed, best[frame], bare_links))
                    for frame in range(frames.poses.shape[0]))
    return frames, best, markers, _Geometry(visual_model, owners, failed_joints, failed_chains)


def _graph_drawing(mechanism, poses, failed, threshold, strict: bool, limits: bool = True):
    """Frames and markers of a mechanism whose legs have loops inside them (no geometry: rods and spheres)."""
    frames = solve_graph_frames(mechanism, poses, threshold, strict, limits)
    best = tuple(best_submechanism(frames.result, frame, failed) for frame in range(frames.poses.shape[0]))
    return frames, best, graph_markers(mechanism, frames, failed), None


def _show_geometry(meshcat_viewer, mechanism, geometry: _Geometry, chain_colors, chain_of_node: dict):
    """Pinocchio's visualizer of the serial mechanism's geometry in its colours (``chain_of_node`` gets the nodes
    an animation recolours)."""
    import pinocchio
    from pinocchio.visualize import MeshcatVisualizer

    visualizer = MeshcatVisualizer(mechanism.pinocchio_model, None, geometry.visual_model)
    visualizer.initViewer(viewer=meshcat_viewer)
    visualizer.loadViewerModel(rootNodeName=f"{ROOT_PATH}/mechanism")
    for shape, owner in zip(geometry.visual_model.geometryObjects, geometry.owners):
        node = visualizer.getViewerNodeName(shape, pinocchio.GeometryType.VISUAL)
        if owner == "base":
            color = BASE_COLOR
        elif owner == "platform":
            color = PLATFORM_COLOR
        elif owner in geometry.failed_chains or shape.parentJoint in geometry.failed_joints:
            color = FAILED_COLOR
        else:
            color = tuple(chain_colors[owner])
            chain_of_node[node] = owner
        meshcat_viewer[node].set_property("color", [float(c) for c in color])
    return visualizer


def _draw(mechanism, poses, failed, threshold, color_by, viewer, open_browser, animation: _Animation | None,
          limits: bool = True) -> Scene:
    """Draw :func:`show`'s one pose (``animation`` None: an unreachable pose is an error) or
    :func:`animate_sweep`'s poses (the unreachable ones skipped); a mechanism whose legs have loops inside them as
    rods and spheres (:mod:`screwkit.viewer.graph_drawing`)."""
    import_meshcat()

    if color_by not in ("iti", "oti"):
        raise ValueError(f"Expected `color_by` 'iti' or 'oti', got {color_by!r}.")
    failed = resolve_actuators(mechanism, failed)
    one_pose = animation is None
    is_graph = isinstance(mechanism, GraphMechanism)
    frames, best, markers, geometry = (_graph_drawing if is_graph else _serial_drawing)(
        mechanism, poses, failed, threshold, one_pose, limits)
    count = frames.poses.shape[0]
    result = frames.result
    chain_values = np.stack([chain_index_values(mechanism, result, frame, failed, color_by) for frame in range(count)])
    chain_colors = colors_from_values(chain_values[0])
    for chain in ({mechanism.actuator_legs[a] for a in failed} if is_graph else geometry.failed_chains):
        chain_colors[chain] = FAILED_COLOR

    server = None
    if viewer is None:
        meshcat_viewer = start_viewer()
        server = meshcat_viewer.window.screwkit_server
    else:
        meshcat_viewer = meshcat_viewer_of(viewer)
    try:
        meshcat_viewer[ROOT_PATH].delete()
        if getattr(meshcat_viewer.window, "screwkit_animated", False):
            clear_animation(meshcat_viewer)
        chain_of_node = {}  # drawn in its chain's colour: the colour an animation changes frame by frame
        visualizer = None
        if geometry is not None:
            visualizer = _show_geometry(meshcat_viewer, mechanism, geometry, chain_colors, chain_of_node)
            visualizer.display(frames.configurations[0])
        all_markers = {}
        for frame_markers in markers:
            for marker in frame_markers:
                all_markers.setdefault(marker.path, marker)
        for marker in all_markers.values():
            create_marker(meshcat_viewer, marker, mechanism, chain_colors)
            if marker.kind in ("link", "joint") and not marker.failed and marker.chain is not None:
                chain_of_node[marker.path] = marker.chain
        for marker in markers[0]:
            meshcat_viewer[marker.path].set_transform(marker_matrix(marker))
        for path in set(all_markers) - {marker.path for marker in markers[0]}:
            meshcat_viewer[path].set_property("visible", False)
        display_offset = frame_view(meshcat_viewer, mechanism, frames)
        if animation is not None:
            frame_colors = colors_from_values(chain_values)  # (frames, chains, 4)
            animate(meshcat_viewer, visualizer, None if geometry is None else geometry.visual_model, frames, markers,
                    all_markers, animation.frame_rate,
                    animation.loop, {node: frame_colors[:, chain] for node, chain in chain_of_node.items()},
                    animation.times)
    except BaseException:
        if server is not None:
            with contextlib.suppress(Exception):
                meshcat_viewer.window.zmq_socket.close(linger=0)
            server.stop()
        raise
    if one_pose:
        result = result.at(0)
    scene = Scene(mechanism=mechanism, poses=frames.poses, result=result, failed=failed, color_by=color_by,
                  chain_values=chain_values, chain_colors=chain_colors, best_submechanisms=tuple(
                      None if b is None else tuple(result.submechanisms[b]) for b in best),
                  frame_markers=markers, visualizer=visualizer, viewer=meshcat_viewer, server=server,
                  frame_rate=None if one_pose else animation.frame_rate, display_offset=display_offset,
                  times=None if one_pose or animation.times is None else animation.times[frames.kept],
                  kept=np.asarray(frames.kept, dtype=int))
    if open_browser:
        meshcat_viewer.open()
    return scene

