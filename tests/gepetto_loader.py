"""Gepetto's own reading of a robot.yaml's ``joint_name`` / ``joint_type``: the joint and frame rebuilding of
``completeRobotLoader`` in example-parallel-robots' ``example_parallel_robots/loader_tools.py`` (commit
``52e64b31c2ef122feffa571b78134d4529f9050a``), copied as written, so that screwkit's
:func:`screwkit.io.gepetto.replaced_joints` is checked against that tool's reading, not against itself. Left out:
the visual and collision models (``RobotWrapper.BuildFromURDF`` reads meshes; the kinematic model is
``pin.buildModelFromUrdf``'s), the constraints and the actuation model (read from the same yaml keys by screwkit
too), and ``simplifyModel`` (which turns three massless revolutes through one point into a ball joint; none of
the files tested has such a triple once replaced).

The package is not on PyPI; its code is under the licence below.

BSD 3-Clause License

Copyright (C) 2024 LAAS-CNRS, INRIA
All rights reserved.

Redistribution and use in source and binary forms, with or without
modification, are permitted provided that the following conditions are met:

* Redistributions of source code must retain the above copyright notice, this
  list of conditions and the following disclaimer.

* Redistributions in binary form must reproduce the above copyright notice,
  this list of conditions and the following disclaimer in the documentation
  and/or other materials provided with the distribution.

* Neither the name of the copyright holder nor the names of its
  contributors may be used to endorse or promote products derived from
  this software without specific prior written permission.

THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS"
AND ANY EXPRESS OR IMPLIED WARRANTIES, INCLUDING, BUT NOT LIMITED TO, THE
IMPLIED WARRANTIES OF MERCHANTABILITY AND FITNESS FOR A PARTICULAR PURPOSE ARE
DISCLAIMED. IN NO EVENT SHALL THE COPYRIGHT HOLDER OR CONTRIBUTORS BE LIABLE
FOR ANY DIRECT, INDIRECT, INCIDENTAL, SPECIAL, EXEMPLARY, OR CONSEQUENTIAL
DAMAGES (INCLUDING, BUT NOT LIMITED TO, PROCUREMENT OF SUBSTITUTE GOODS OR
SERVICES; LOSS OF USE, DATA, OR PROFITS; OR BUSINESS INTERRUPTION) HOWEVER
CAUSED AND ON ANY THEORY OF LIABILITY, WHETHER IN CONTRACT, STRICT LIABILITY,
OR TORT (INCLUDING NEGLIGENCE OR OTHERWISE) ARISING IN ANY WAY OUT OF THE USE
OF THIS SOFTWARE, EVEN IF ADVISED OF THE POSSIBILITY OF SUCH DAMAGE.
"""

from __future__ import annotations

import pinocchio as pin
import yaml


def gepetto_model(urdf_path, yaml_path):
    """The model example-parallel-robots' ``completeRobotLoader`` builds from these files (kinematics only)."""
    model = pin.buildModelFromUrdf(str(urdf_path))
    yaml_content = yaml.safe_load(open(yaml_path).read())

    # Update model
    if "joint_name" in yaml_content.keys():
        update_joint = yaml_content["joint_name"]
        joints_types = yaml_content["joint_type"]
    else:
        update_joint = []
        joints_types = []

    fixed_joints_names = []
    new_model = pin.Model()

    ujoints_type = {"X": pin.JointModelRX, "Y": pin.JointModelRY, "Z": pin.JointModelRZ}

    for old_place, old_iner, old_name, old_parent, old_joint in list(
        zip(
            model.jointPlacements,
            model.inertias,
            model.names,
            model.parents,
            model.joints,
        )
    )[1:]:
        parent = new_model.getJointId(model.names[old_parent])
        place = old_place
        name = old_name
        if old_name in update_joint:
            joint_type = joints_types[update_joint.index(old_name)]
            if joint_type == "SPHERICAL":
                joint_model = pin.JointModelSpherical()
            elif joint_type == "FIXED":
                joint_model = old_joint
                fixed_joints_names.append(old_joint.id)
            if "UJOINT" in joint_type:
                type1 = ujoints_type[joint_type[-2]]
                type2 = ujoints_type[joint_type[-1]]

                parent = new_model.addJoint(
                    parent, type1(), place, old_name + f"_{joint_type[-2]}"
                )
                joint_model = type2()
                place = pin.SE3.Identity()
                name = old_name + f"_{joint_type[-1]}"
        else:
            joint_model = old_joint
        jid = new_model.addJoint(parent, joint_model, place, name)
        new_model.appendBodyToJoint(jid, old_iner, pin.SE3.Identity())

    # Frames - Add ujoints frames
    for f in model.frames:
        old_name, old_parent, old_place, old_type = (
            f.name,
            f.parentJoint,
            f.placement,
            f.type,
        )
        # For ujoints, create frames for the joints
        if (
            old_name in update_joint
        ):  # If the frame is a joint frame for a joint that as been updated
            assert old_type == pin.JOINT, "Frame type should be JOINT"
            assert model.names[old_parent] == old_name, (
                "Frame parent should be the joint"
            )
            assert old_place == pin.SE3.Identity(), "Frame placement should be Identity"
            joint_type = joints_types[update_joint.index(old_name)]
            if "UJOINT" in joint_type:  # If this joint is a ujoint
                ujoint_frame = pin.Frame(
                    old_name + f"_{joint_type[-2]}",
                    new_model.getJointId(old_name + f"_{joint_type[-2]}"),
                    pin.SE3.Identity(),
                    pin.FrameType.JOINT,
                )
                new_model.addFrame(ujoint_frame, False)
                ujoint_frame = pin.Frame(
                    old_name + f"_{joint_type[-1]}",
                    new_model.getJointId(old_name + f"_{joint_type[-1]}"),
                    pin.SE3.Identity(),
                    pin.FrameType.JOINT,
                )
                new_model.addFrame(ujoint_frame, False)
            else:
                name = old_name
                parent = new_model.getJointId(model.names[old_parent])
                assert old_type == pin.JOINT, "Frame type should be JOINT"
                joint_frame = pin.Frame(name, parent, old_place, old_type)
                new_model.addFrame(joint_frame, False)

        elif (
            model.names[old_parent] in update_joint
        ):  # Frame is attached to a joint that has been modified (but is not this joint frame)
            joint_type = joints_types[update_joint.index(model.names[old_parent])]

            if "UJOINT" in joint_type:  # The parent joint is ujoint
                type2 = ujoints_type[joint_type[-1]]
                name = old_name
                parent = new_model.getJointId(
                    model.names[old_parent] + f"_{joint_type[-1]}"
                )
                place = old_place
                frame_type = old_type

            else:  # The parent joint is not ujoint
                name = old_name
                parent = new_model.getJointId(model.names[old_parent])
                place = old_place
                frame_type = old_type

            frame = pin.Frame(name, parent, place, frame_type)
            new_model.addFrame(frame, False)
        else:  # The frame corresponds to the joint
            name = old_name
            parent = new_model.getJointId(model.names[old_parent])
            place = old_place
            frame_type = old_type
            frame = pin.Frame(name, parent, place, frame_type)
            new_model.addFrame(frame, False)

    new_model.frames.__delitem__(0)
    new_model = pin.buildReducedModel(new_model, fixed_joints_names, pin.neutral(new_model))
    return new_model
