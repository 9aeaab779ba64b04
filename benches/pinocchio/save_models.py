"""Saves the benchmark's robots as Pinocchio text archives (what
benches/pinocchio/shim.cpp loads; the wheel ships no urdfdom headers for
C++ to parse the URDFs itself), NAME.txt, and their joints' names in
Pinocchio's order, one a line, NAME.joints (the benchmark matches them with
moreau's coordinates, whose order differs where a link has several
children): python save_models.py OUT_DIR."""

import sys
from pathlib import Path

import pinocchio as pin

HERE = Path(__file__).resolve().parent
ROBOTS = [
    ("ur5", "ur5_robot.urdf", []),
    ("panda", "panda.urdf", ["panda_finger_joint1", "panda_finger_joint2"]),
    ("serial_12", "serial_12.urdf", []),
    ("go1", "go1.urdf", []),
]

out = Path(sys.argv[1])
for name, urdf, locked in ROBOTS:
    full = pin.buildModelFromUrdf(str(HERE.parent / "robots" / urdf))
    ids = [full.getJointId(j) for j in locked]
    model = pin.buildReducedModel(full, ids, pin.neutral(full)) if ids else full
    assert model.nq == model.nv, f"{name}: a joint of more than one coordinate"
    model.saveToText(str(out / f"{name}.txt"))
    joints = [model.names[i] for i in range(1, model.njoints)]
    (out / f"{name}.joints").write_text("".join(j + "\n" for j in joints))
