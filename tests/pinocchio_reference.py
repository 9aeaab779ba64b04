#!/usr/bin/env python3
"""Pinocchio reference values for the URDF models of moreau (issue 11).

For each robot below, the URDF shipped in ``tests/robots/urdf/`` (copied
from the ``example-robot-data`` wheel, whose copy must be byte-identical, or
written for these tests: ``synthetic/``) is
loaded with Pinocchio (fixed base; the ``locked`` joints held at zero with
``buildReducedModel``), and at seeded configurations (one coordinate per joint, the angle of a
continuous joint too) the script writes:

- ``M``: the mass matrix (CRBA, both triangles);
- ``nle``: the nonlinear effects ``C(q, v) v + G(q)`` (RNEA with zero
  acceleration);
- ``G``: the generalized gravity;
- ``points``: the world position of a point fixed in a link's frame, and
  its linear Jacobian ``∂p/∂q`` (from the frame Jacobian in the
  LOCAL_WORLD_ALIGNED convention: ``J_lin − [R r]× J_ang``).

The Rust test ``tests/robots/pinocchio.rs`` compares the generated code with these
numbers to 1e-10 relative. The files are JSON, one per robot, in
``tests/fixtures/pinocchio/``::

    python tests/pinocchio_reference.py            # (re)write the fixtures
    python tests/pinocchio_reference.py --check    # compare with the committed files

``--check`` regenerates in memory and compares with the committed files:
same structure, floats equal to within 1e-12 relative to the largest
magnitude of the same array (the tolerance only absorbs libm differences
between machines; any real change of a model moves values far more).
Exit status 0 when everything matches, 1 otherwise.

Requirements: ``tests/requirements-pinocchio.txt`` (exact pins).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

ROOT = Path(__file__).resolve().parent.parent
FIXTURES = ROOT / "tests" / "fixtures" / "pinocchio"
CHECK_RTOL = 1e-12
SAMPLES = 8

# name, URDF in the repository, its path in the wheel, locked joints, and the
# points (link, point in the link's frame) whose positions are written.
ROBOTS = [
    (
        "ur5",
        "tests/robots/urdf/ur_description/ur5_robot.urdf",
        "ur_description/urdf/ur5_robot.urdf",
        [],
        [("tool0", [0.01, -0.02, 0.05]), ("forearm_link", [0.0, 0.0, 0.0])],
    ),
    (
        "panda",
        "tests/robots/urdf/panda_description/panda.urdf",
        "panda_description/urdf/panda.urdf",
        ["panda_finger_joint1", "panda_finger_joint2"],
        [("panda_hand", [0.0, 0.0, 0.1]), ("panda_link4", [0.03, 0.0, -0.02])],
    ),
    (
        "slider_arm",
        "tests/robots/urdf/synthetic/slider_arm.urdf",
        None,
        [],
        [("tool", [0.02, 0.01, 0.05]), ("side", [0.0, 0.1, -0.03])],
    ),
    (
        "serial_12",
        "tests/robots/urdf/synthetic/serial/serial_12.urdf",
        None,
        [],
        [("l12", [0.02, -0.01, 0.1]), ("l6", [0.0, 0.0, 0.0])],
    ),
    (
        "go1",
        "tests/robots/urdf/go1_description/go1.urdf",
        "go1_description/urdf/go1.urdf",
        [],
        [("FR_foot", [0.0, 0.0, 0.0]), ("RL_foot", [0.0, 0.0, 0.0])],
    ),
    # a link and a joint of the same name (`gripper`): the point is the link's
    (
        "so100",
        "tests/robots/urdf/so_arm_description/so100.urdf",
        "so_arm_description/urdf/so100.urdf",
        [],
        [("gripper", [0.01, -0.02, 0.05]), ("jaw", [0.0, 0.0, 0.0])],
    ),
    # the Panda's fingers as the URDF has them: the second mimics the first
    # (Pinocchio's `mimic=True`), a point on each finger
    (
        "panda_mimic",
        "tests/robots/urdf/panda_description/panda.urdf",
        "panda_description/urdf/panda.urdf",
        [],
        [("panda_rightfinger", [0.0, 0.01, 0.04]), ("panda_leftfinger", [0.0, -0.01, 0.04])],
    ),
    # names that are not identifiers (`joint_0.0`, `link_3.0_tip`)
    (
        "allegro",
        "tests/robots/urdf/allegro_hand_description/allegro_left_hand.urdf",
        "allegro_hand_description/urdf/allegro_left_hand.urdf",
        [],
        [("link_15.0_tip", [0.0, 0.0, 0.0]), ("link_3.0_tip", [0.01, 0.0, 0.0])],
    ),
]


def wheel_copy_matches(repo_path: Path, wheel_rel) -> bool:
    """Whether the repository's copy is the wheel's file, byte for byte
    (``wheel_rel`` is None for a URDF written for these tests)."""
    from importlib.metadata import distribution

    if wheel_rel is None:
        return True
    wanted = "robots/" + wheel_rel
    for f in distribution("example-robot-data").files or []:
        if str(f).endswith(wanted):
            return Path(f.locate()).read_bytes() == repo_path.read_bytes()
    raise SystemExit(f"example-robot-data has no {wanted}")


def moving(model):
    """The joints with a coordinate of their own: not those that mimic
    another (nv = 0)."""
    return [i for i in range(1, model.njoints) if model.joints[i].nv > 0]


def configuration(model, angles):
    """Pinocchio's configuration vector for one coordinate per joint: a
    continuous joint (nq = 2) is stored as (cos θ, sin θ)."""
    q = []
    for i, x in zip(moving(model), angles):
        q.extend([math.cos(x), math.sin(x)] if model.joints[i].nq == 2 else [x])
    return np.array(q)


def skew(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def reference(name, urdf, wheel_rel, locked, points):
    path = ROOT / urdf
    if not wheel_copy_matches(path, wheel_rel):
        raise SystemExit(f"{urdf}: differs from the example-robot-data wheel's {wheel_rel}")
    # the URDF's mimic joints follow their joints where none is locked (the
    # Panda's first fixture locks both fingers, as buildReducedModel needs)
    full = pin.buildModelFromUrdf(str(path), mimic=not locked)
    ids = [full.getJointId(j) for j in locked]
    model = pin.buildReducedModel(full, ids, pin.neutral(full)) if ids else full
    data = model.createData()
    assert all(model.joints[i].nv == 1 for i in moving(model)), "a fixed base of 1-dof joints"
    joints = [model.names[i] for i in moving(model)]
    assert [model.joints[i].idx_v for i in moving(model)] == list(range(model.nv))
    rng = np.random.default_rng(11)
    samples = []
    for _ in range(SAMPLES):
        q = rng.uniform(-math.pi, math.pi, model.nv)
        v = rng.uniform(-2.0, 2.0, model.nv)
        q_pin = configuration(model, q)
        M = pin.crba(model, data, q_pin)
        M = np.triu(M) + np.triu(M, 1).T
        nle = pin.nonLinearEffects(model, data, q_pin, v)
        G = pin.computeGeneralizedGravity(model, data, q_pin)
        pin.computeJointJacobians(model, data, q_pin)
        pin.updateFramePlacements(model, data)
        out = []
        for link, r in points:
            # the link's frame, not a joint's of the same name
            fid = model.getFrameId(link, pin.FrameType.BODY)
            assert model.frames[fid].name == link, link
            oMf = data.oMf[fid]
            world_r = oMf.rotation @ np.array(r)
            p = oMf.translation + world_r
            J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            Jp = J[:3] - skew(world_r) @ J[3:]
            out.append({"link": link, "point": r, "position": p.tolist(), "jacobian": Jp.tolist()})
        samples.append(
            {
                "q": q.tolist(),
                "v": v.tolist(),
                "M": M.tolist(),
                "nle": nle.tolist(),
                "G": G.tolist(),
                "points": out,
            }
        )
    return {
        "robot": name,
        "urdf": urdf,
        "locked": locked,
        "pinocchio": pin.__version__,
        "joints": joints,
        "samples": samples,
    }


def _max_abs(x) -> float:
    if isinstance(x, list):
        return max((_max_abs(y) for y in x), default=0.0)
    return abs(x) if isinstance(x, float) else 0.0


def compare(old, new, path, out, scale=0.0):
    if type(old) is not type(new):
        out.append(f"{path}: {type(old).__name__} != {type(new).__name__}")
    elif isinstance(old, dict):
        for k in sorted(set(old) | set(new)):
            if k not in old or k not in new:
                out.append(f"{path}.{k}: present in only one file")
            else:
                s = max(_max_abs(old[k]), _max_abs(new[k])) if isinstance(old[k], list) else scale
                compare(old[k], new[k], f"{path}.{k}", out, s)
    elif isinstance(old, list):
        if len(old) != len(new):
            out.append(f"{path}: length {len(old)} != {len(new)}")
        else:
            for i, (a, b) in enumerate(zip(old, new)):
                compare(a, b, f"{path}[{i}]", out, scale)
    elif isinstance(old, float):
        if abs(old - new) > CHECK_RTOL * max(scale, abs(old), abs(new)):
            out.append(f"{path}: {old!r} != {new!r}")
    elif old != new:
        out.append(f"{path}: {old!r} != {new!r}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="compare with the committed fixtures")
    args = ap.parse_args(argv)
    FIXTURES.mkdir(parents=True, exist_ok=True)
    failures = []
    for robot in ROBOTS:
        data = reference(*robot)
        target = FIXTURES / f"{robot[0]}.json"
        if args.check:
            if not target.exists():
                failures.append(f"{target}: missing (run without --check)")
                continue
            out = []
            compare(json.loads(target.read_text()), data, "$", out)
            if out:
                failures.append(f"{target}: {len(out)} difference(s):\n    " + "\n    ".join(out[:20]))
            else:
                print(f"{target.relative_to(ROOT)}: matches ({len(data['samples'])} samples)")
        else:
            target.write_text(json.dumps(data, indent=1) + "\n")
            print(f"wrote {target.relative_to(ROOT)}")
    for f in failures:
        print(f, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
