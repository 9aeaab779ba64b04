#!/usr/bin/env python3
"""Writes serial_N.urdf (N = 2..12) beside this file: serial chains of N
revolute joints in 3-D, written for moreau's tests and scaling figures (no
upstream; same license as moreau).

Joint k turns about one of six unit axes in turn (z, y, x and three skewed
ones), its frame placed by a varied offset and roll-pitch-yaw; link k has a
varied mass, centre of mass and an inertia with products, turned by its own
roll-pitch-yaw. The chain of N joints is the first N links of the chain of
12, so the models differ only in length. Deterministic: rerunning rewrites
the same bytes.

    python3 tests/robots/urdf/synthetic/serial/gen.py
"""

from pathlib import Path

HERE = Path(__file__).resolve().parent
AXES = [
    (0.0, 0.0, 1.0),
    (0.0, 1.0, 0.0),
    (1.0, 0.0, 0.0),
    (0.6, 0.8, 0.0),
    (0.0, -0.6, 0.8),
    (0.48, 0.6, 0.64),
]


def f(x: float) -> str:
    return f"{x + 0.0:.4g}"


def vec(v) -> str:
    return " ".join(f(x) for x in v)


def link(k: int) -> str:
    mass = 2.0 - 0.1 * k
    com = (0.02 * ((k % 3) - 1), -0.01 * ((k % 2) * 2 - 1), 0.08 + 0.005 * k)
    rpy = (0.1 * (k % 4), -0.15 * (k % 3), 0.2 * (k % 5))
    d = 0.02 + 0.002 * k
    return f"""  <link name="l{k}">
    <inertial>
      <origin xyz="{vec(com)}" rpy="{vec(rpy)}"/>
      <mass value="{f(mass)}"/>
      <inertia ixx="{f(d)}" ixy="{f(0.001 * ((k % 3) - 1))}" ixz="{f(0.0005 * (k % 2))}" iyy="{f(1.2 * d)}" iyz="{f(-0.0007 * (k % 4 == 1))}" izz="{f(0.8 * d)}"/>
    </inertial>
  </link>
"""


def joint(k: int) -> str:
    xyz = (0.01 * (k % 2), -0.02 * (k % 3 == 1), 0.15 + 0.01 * (k % 4))
    rpy = (0.3 * ((k % 3) - 1), 0.2 * (k % 2), -0.25 * (k % 4 == 2))
    return f"""  <joint name="j{k}" type="revolute">
    <parent link="l{k - 1}"/>
    <child link="l{k}"/>
    <origin xyz="{vec(xyz)}" rpy="{vec(rpy)}"/>
    <axis xyz="{vec(AXES[(k - 1) % len(AXES)])}"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/>
  </joint>
"""


def chain(n: int) -> str:
    parts = [
        '<?xml version="1.0"?>\n',
        f"<!-- Written by gen.py beside this file: a serial chain of {n} revolute joints. -->\n",
        f'<robot name="serial_{n}">\n',
        '  <link name="l0"/>\n',
    ]
    for k in range(1, n + 1):
        parts.append(link(k))
        parts.append(joint(k))
    parts.append("</robot>\n")
    return "".join(parts)


def main() -> None:
    for n in range(2, 13):
        (HERE / f"serial_{n}.urdf").write_text(chain(n))


if __name__ == "__main__":
    main()
