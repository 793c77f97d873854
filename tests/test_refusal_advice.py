"""What a refusal advises, followed to its end on a published robot's neck: ToddlerBot's head pitch (an excerpt of
MuJoCo Menagerie's ``toddlerbot_2xc_fixed.xml``, MIT, in ``tests/data/gallery/excerpts``), whose motor rides on
the head and turns a plate that two rods hold to the yaw link (a parallelogram drawn 7 micrometres off).

* With no ``--output``, the body taken as the platform carries the loop, which is left out: then no loop acts on
  it, and the refusal names that body and ``--output``.
* With ``--output head``, the serial-leg reading advised ``--lock neck_pitch_act --lock neck_pitch_front``: holding
  the only actuator, which then ends in "no leg has an actuator". It now hands the file to the graph reading, which
  advises holding the yaw joint that carries the head and the motor (not the head's own pin), and then says the
  neck cannot move as written: MuJoCo's own constraint Jacobian of the four rod ends over the four pitch-side
  joints has rank 4 (its smallest singular value 3.6e-9 of the largest: the drawn parallelogram is not one).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from helpers import mujoco_rows, one_line_error, screwkit

NECK = Path(__file__).parent / "data" / "gallery" / "excerpts" / "toddlerbot_neck" / "neck.xml"
PITCH_SIDE = ("neck_pitch", "neck_pitch_act", "neck_pitch_front", "neck_pitch_back")


def test_a_platform_that_carries_the_loop_is_named_with_the_option_that_moves_it():
    one_line_error(screwkit("info", NECK), "no loop acts on the platform 'neck_yaw_link'",
                   "name another --output, on a body the loops reach")


def test_the_advice_holds_no_actuator_and_ends_where_mujoco_finds_the_neck_rigid_as_written():
    first = one_line_error(screwkit("info", NECK, "--output", "head"), "actuated joint 'neck_pitch_act'",
                           "--lock neck_yaw_driven")
    assert "--lock neck_pitch_act" not in first and "--lock neck_pitch " not in first, first
    one_line_error(screwkit("info", NECK, "--output", "head", "--lock", "neck_yaw_driven"),
                   "the platform 'head' cannot move")
    model = mujoco.MjModel.from_xml_path(str(NECK))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    connects = [row for row in range(data.nefc) if data.efc_type[row] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
                and data.efc_id[row] < 4]  # the four <connect>s, three rows each
    assert len(connects) == 12
    columns = [model.jnt_dofadr[model.joint(name).id] for name in PITCH_SIDE]
    values = np.linalg.svd(mujoco_rows(model, data)[connects][:, columns], compute_uv=False)
    assert values[-1] / values[0] > 1e-10 and np.sum(values > 1e-12 * values[0]) == 4  # no exact motion
