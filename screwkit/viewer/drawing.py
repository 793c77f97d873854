"""Sending a mechanism, its colours and its markers to Meshcat, still or animated.

Meshcat 0.3 orbits about the viewer's origin, so the drawing, the ground grid and the axes are
shifted together to put the mechanism's centre there (:func:`frame_view`); markers under
``/meshcat`` stay in the mechanism's world frame. Pinocchio and Meshcat are imported inside
the functions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from screwkit.viewer.markers import (
    FAILED_COLOR,
    FAILED_MARKER_COLOR,
    ROOT_PATH,
    TWIST_COLOR,
    WRENCH_COLOR,
    Frames,
    Marker,
)

__all__ = [
    "ANIMATION_PATH",
    "BASE_COLOR",
    "PLATFORM_COLOR",
    "load_visual_model",
    "geometry_owners",
    "failed_joint_ids",
    "create_marker",
    "marker_matrix",
    "frame_view",
    "clear_animation",
    "animate",
]


BASE_COLOR = (0.80, 0.80, 0.82, 1.0)
ANIMATION_PATH = f"/meshcat/{ROOT_PATH}/animation"
"""Where the server keeps a scene's animation (:func:`animate`): after the drawing, and deleted with it."""


PLATFORM_COLOR = (0.30, 0.32, 0.38, 1.0)


def load_visual_model(mechanism):
    import warnings

    import pinocchio

    try:
        return pinocchio.buildGeomFromUrdfString(mechanism.pinocchio_model, mechanism.description.text,
                                                 pinocchio.GeometryType.VISUAL, None,
                                                 [str(Path(mechanism.path).resolve().parent)])
    except Exception as error:  # noqa: BLE001 - Pinocchio raises plain RuntimeErrors; draw rods instead
        warnings.warn(f"{mechanism.path}: cannot load the visual geometry ({str(error).strip()[:200]}); "
                      "drawing rods between joints instead.", stacklevel=3)
        return pinocchio.GeometryModel()


def geometry_owners(mechanism, visual_model) -> tuple[list, list]:
    """Per geometry object its owner ("base", "platform", chain index), and the bare links.

    A bare link is ``(chain, position, failed)``: the link after tree joint ``position`` of a
    chain has no visual geometry.
    """
    model = mechanism.pinocchio_model
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


def failed_joint_ids(mechanism, failed: tuple[int, ...]) -> tuple[set, set]:
    """Joint ids of failed actuated joints, and chains whose every actuator failed."""
    model = mechanism.pinocchio_model
    joint_ids = {model.getJointId(joint) for index, (_, joint) in enumerate(mechanism.actuators)
                 if index in failed and model.existJointName(joint)}
    chains = set()
    for index, chain in enumerate(mechanism.chains):
        members = [i for i, (name, _) in enumerate(mechanism.actuators) if name == chain.name]
        if members and all(i in failed for i in members):
            chains.add(index)
    return joint_ids, chains


def hex_color(color) -> int:
    red, green, blue = (round(255 * float(np.clip(c, 0.0, 1.0))) for c in color[:3])
    return (red << 16) + (green << 8) + blue


def lambert_material(color):
    from meshcat import geometry

    alpha = float(color[3]) if len(color) > 3 else 1.0
    return geometry.MeshLambertMaterial(color=hex_color(color), opacity=alpha, transparent=alpha < 1.0)


def line_radius(mechanism) -> float:
    return 0.008 * float(mechanism.length_scale)


def create_marker(viewer, marker: Marker, mechanism, chain_colors) -> None:
    """Send the geometry of a marker (placed later by :func:`marker_matrix`)."""
    from meshcat import geometry, transformations

    radius = line_radius(mechanism)
    length = float(np.linalg.norm(marker.end - marker.start))
    node = viewer[marker.path]
    if marker.kind in ("actuation_wrench", "actuation_couple", "twist_axis", "translation"):
        color = WRENCH_COLOR if marker.kind.startswith("actuation") else TWIST_COLOR
        color = FAILED_COLOR if marker.failed else color
        material = lambert_material(color)
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
        node.set_object(geometry.Sphere(3.0 * radius), lambert_material(TWIST_COLOR))
    elif marker.kind == "failed_actuator":
        size = 0.12 * float(mechanism.length_scale)
        material = lambert_material(FAILED_MARKER_COLOR)
        for number, angle in enumerate((np.pi / 4, -np.pi / 4)):
            node[f"bar_{number}"].set_object(geometry.Box([size, 0.18 * size, 0.18 * size]), material)
            node[f"bar_{number}"].set_transform(transformations.rotation_matrix(angle, [0.0, 0.0, 1.0]))
    elif marker.kind in ("link", "joint"):
        color = (FAILED_COLOR if marker.failed else BASE_COLOR if marker.body == "base"
                 else PLATFORM_COLOR if marker.body == "platform" else tuple(chain_colors[marker.chain]))
        shape = geometry.Cylinder(1.0, 2.0 * radius) if marker.kind == "link" else geometry.Sphere(3.0 * radius)
        node.set_object(shape, lambert_material(color))


def rotation_with_y_along(direction: NDArray) -> NDArray:
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


def marker_placement(marker: Marker) -> tuple[NDArray, NDArray, NDArray]:
    """Position, rotation and scale of a marker's node."""
    if marker.kind in ("instantaneous_centre", "failed_actuator", "joint"):
        return marker.start, np.eye(3), np.ones(3)
    rotation = rotation_with_y_along(marker.end - marker.start)
    middle = 0.5 * (marker.start + marker.end)
    if marker.kind == "link":
        return middle, rotation, np.array([1.0, max(float(np.linalg.norm(marker.end - marker.start)), 1e-9), 1.0])
    return middle, rotation, np.ones(3)


def marker_matrix(marker: Marker) -> NDArray:
    position, rotation, scale = marker_placement(marker)
    matrix = np.eye(4)
    matrix[:3, :3] = rotation * scale
    matrix[:3, 3] = position
    return matrix


def frame_view(viewer, mechanism, frames: Frames) -> NDArray[np.float64]:
    """Centre the mechanism on the orbit target and place the camera; return the display offset.

    Meshcat 0.3 orbits about the viewer's origin and cannot move that target, so the scene
    (``/meshcat``) and the ground grid and axes are shifted together by ``-centre``: the
    picture is the mechanism's world, centred where the camera looks. A planar mechanism's centre is on its
    platform's plane, and the camera looks at that plane from the same side and angle, wherever and however
    tilted its world frame puts the plane.
    """
    points = np.concatenate([points[0].reshape(-1, 3) for points in frames.chain_points] + [frames.centres[:1]])
    rotation = np.asarray(getattr(mechanism, "rotation_world_base", np.eye(3)), dtype=float)
    origin = np.asarray(getattr(mechanism, "translation_world_base", np.zeros(3)), dtype=float)
    in_base = (points - origin) @ rotation  # the bounding box in the base frame: it moves with the mechanism
    centre = rotation @ (0.5 * (in_base.min(axis=0) + in_base.max(axis=0))) + origin
    if mechanism.is_planar:  # onto the platform's plane (its base frame's x-y plane, wherever the world puts it)
        normal = rotation[:, 2]
        centre = centre - normal * float(np.dot(centre - frames.centres[0], normal))
    reach = max(float(np.max(np.linalg.norm(points - centre, axis=-1))), 0.5 * float(mechanism.length_scale), 1e-3)
    if mechanism.is_planar:  # the same view of the plane however the world frame tilts it
        direction, distance = rotation @ np.array([0.3, -0.75, 1.0]), 1.9 * reach
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


def clear_animation(viewer) -> None:
    import meshcat.animation

    viewer.set_animation(meshcat.animation.Animation(), play=False)
    viewer.window.screwkit_animated = False


def animate(viewer, visualizer, visual_model, frames: Frames, markers, all_markers, frame_rate, loop,
            colours: dict[str, NDArray] | None = None, times: NDArray | None = None) -> None:
    """One keyframe per frame: the links (of ``visualizer``'s geometry: none when it is None), and the markers (shown
    or hidden); with ``colours`` (per Meshcat path of a drawn object, its RGB(A) colour at each frame, (frames, 3 or
    4)), the material colour of each follows too.
    The keyframe of frame ``k``, drawn for pose ``frames.kept[k]`` of those asked for, is at ``frames.kept[k] /
    frame_rate`` seconds, or with ``times`` (seconds, increasing, one per pose asked for) at
    ``times[frames.kept[k]] - times[0]``: Meshcat then plays the motion at its own pace, interpolating between
    keyframes, and unreachable poses left out keep their time."""
    import meshcat.animation
    import pinocchio
    from meshcat import transformations

    animation = meshcat.animation.Animation(default_framerate=frame_rate)
    kept = np.arange(len(frames.configurations)) if frames.kept is None else np.asarray(frames.kept)
    at = (kept if times is None  # keyframe numbers (Meshcat: frame / fps s)
          else (np.asarray(times, dtype=float)[kept] - float(times[0])) * frame_rate)
    geometries = [] if visualizer is None else visual_model.geometryObjects
    for frame, configuration in enumerate(frames.configurations):
        if visualizer is not None:
            pinocchio.forwardKinematics(visualizer.model, visualizer.data, configuration)
            pinocchio.updateGeometryPlacements(visualizer.model, visualizer.data, visual_model,
                                               visualizer.visual_data)
        with animation.at_frame(viewer, int(at[frame]) if times is None else float(at[frame])) as keyframe:
            for index, geometry in enumerate(geometries):
                node = visualizer.getViewerNodeName(geometry, pinocchio.GeometryType.VISUAL)
                keyframe[node].set_transform(visualizer.visual_data.oMg[index].homogeneous)
                scale = np.asarray(geometry.meshScale, dtype=float).ravel()
                if not np.allclose(scale, 1.0):
                    keyframe[node].set_property("scale", "vector3", [float(s) for s in scale])
            present = {marker.path: marker for marker in markers[frame]}
            for path in all_markers:
                marker = present.get(path)
                keyframe[path].set_property("visible", "boolean", marker is not None)
                if marker is None:
                    continue
                position, rotation, scale = marker_placement(marker)
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
            for path, values in (colours or {}).items():  # the mesh itself: three.js binds its .material.color
                keyframe[f"{path}/<object>"].set_property("material.color", "color",
                                                           [float(c) for c in values[frame][:3]])
    viewer.window.send(_animation_command(animation, play=True, repetitions=10**6 if loop else 1))
    viewer.window.screwkit_animated = True


def _animation_command(animation, play: bool, repetitions: int):
    """Meshcat's ``set_animation`` command, kept by the server at :data:`ANIMATION_PATH` rather than at the root.

    The server replays what it keeps node by node, parents first (a browser that connects later, and
    ``static_html``): kept at the root, the animation would come before the drawing, and its colour tracks would
    bind to placeholders that the drawing then replaces (a ``set_object`` replaces the node's object); kept at a
    node made after everything it animates, it comes after them.
    """
    from meshcat.commands import SetAnimation

    class SetAnimationAt(SetAnimation):
        __slots__ = ()

        def lower(self):
            return {**super().lower(), "path": ANIMATION_PATH}

    return SetAnimationAt(animation, play=play, repetitions=repetitions)

