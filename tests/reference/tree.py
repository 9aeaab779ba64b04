"""Kinematic trees for the CasADi reference: a URDF reader and the
Lagrangian route.

A second, independent reading of what ``models/README.md`` ("Bodies",
"URDF") and the ``tree`` module docs of model-macro say, written for
``tests/casadi_reference.py``; it shares no code with the Rust front ends
or with moreau's recursions (composite rigid bodies, Newton–Euler), which
it exists to check:

* the URDF is read with :mod:`xml.etree.ElementTree`: the root link (no
  joint's child) is the world; every other link is a body attached by the
  joint whose child it is (``revolute``/``continuous`` turn, ``prismatic``
  slides, ``fixed``); joints in ``locked`` are held at zero (fixed);
  moving joints become coordinates (velocity ``d<name>``) in the
  depth-first order of the tree, children in the order of the file; a
  link's ``<inertial>`` gives mass, centre of mass and the inertia about it,
  turned by the inertial ``rpy``; ``limits`` turn ``<limit lower upper>``
  into the constraints ``<joint>_lower = q − lower`` and ``<joint>_upper =
  upper − q``, after the written ones.
* the tree's energies, not its recursions: each body's world pose is the
  product of the joint transforms along its chain (URDF's ``origin``:
  translation ``xyz``, then ``R = Rz(yaw) Ry(pitch) Rx(roll)``; a revolute
  joint turns by ``q`` about its unit axis, written here through the unit
  quaternion ``(cos q/2, sin q/2 a)``, a prismatic one slides by ``q`` along
  it); the velocity of the centre of mass and the body's angular velocity
  come from CasADi's forward AD of the pose (``ċ = (∂c/∂q) v``,
  ``[ω_b]× = Rᵀ Ṙ``), and

  ``T = Σ ½ m |ċ|² + ½ ω_bᵀ I ω_b``,    ``V = −Σ m gᵀ c``

  with ``I`` the inertia about the centre of mass in the body's frame.
  ``M``, ``C``, ``G``, ``F`` and every derivative then follow as for a model
  whose energies are written by hand.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Body", "Urdf", "read_urdf", "build_tree"]

JOINT_TYPES = ("revolute", "prismatic", "fixed")


@dataclass
class Body:
    """A body of the tree. Expression fields are ASTs of the model language
    (``("num", x)`` for a URDF's numbers)."""

    name: str
    parent: str | None  # None: the world
    kind: str  # "revolute" | "prismatic" | "fixed"
    coordinate: int | None  # index into the model's coordinates
    axis: tuple[float, float, float]  # as written (normalized when built)
    xyz: list
    rpy: list
    mass: object
    com: list
    inertia: list  # ixx, ixy, ixz, iyy, iyz, izz about the centre of mass
    # The URDF's inertial rpy: the inertia above is given in a frame turned
    # by it (zeros for bodies written in YAML).
    inertia_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass
class Urdf:
    """What a URDF gives a model."""

    bodies: list[Body]
    coordinates: list[tuple[str, str]]  # (q name, v name), in order
    limits: dict[str, tuple[float, float]] = field(default_factory=dict)


class UrdfError(ValueError):
    """A URDF or a tree that cannot be read (the caller adds where)."""


def _num(x: float):
    return ("num", float(x))


def _floats(elem, key: str, default: list[float], where: str) -> list[float]:
    if elem is None or elem.get(key) is None:
        return list(default)
    text = elem.get(key)
    try:
        vals = [float(s) for s in text.split()]
    except ValueError:
        vals = []
    if len(vals) != len(default) or not all(math.isfinite(x) for x in vals):
        raise UrdfError(f"{where}: {key}={text!r} is not {len(default)} finite number(s)")
    return vals


def _link(joint, end: str, path) -> str:
    """The link named by a joint's ``<parent>`` or ``<child>``."""
    elem = joint.find(end)
    name = None if elem is None else elem.get("link")
    if name is None:
        raise UrdfError(f"{path}: joint `{joint.get('name')}` has no <{end} link=...>")
    return name


def read_urdf(path: Path, locked: list[str], first_coordinate: int) -> Urdf:
    """Read the URDF at ``path``; the joints in ``locked`` are held at zero.
    Coordinates are numbered from ``first_coordinate``."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise UrdfError(f"{path}: cannot read the URDF: {exc}") from None
    if root.tag != "robot":
        raise UrdfError(f"{path}: the root element is <{root.tag}>, not <robot>")
    links: dict[str, ET.Element] = {}
    for link in root.findall("link"):
        links[link.get("name")] = link
    joints = root.findall("joint")
    names = [j.get("name") for j in joints]
    for name in locked:
        if name not in names:
            raise UrdfError(f"{path}: `{name}` is not a joint: it cannot be locked")
    children: dict[str, list[ET.Element]] = {}
    child_links = set()
    for j in joints:
        parent, child = (_link(j, end, path) for end in ("parent", "child"))
        for link in (parent, child):
            if link not in links:
                raise UrdfError(f"{path}: joint `{j.get('name')}` names no link `{link}`")
        if child in child_links:
            raise UrdfError(f"{path}: link `{child}` is the child of two joints")
        child_links.add(child)
        children.setdefault(parent, []).append(j)
    roots = [name for name in links if name not in child_links]
    if len(roots) != 1:
        raise UrdfError(f"{path}: {len(roots)} root links: {roots}")

    out = Urdf(bodies=[], coordinates=[])
    stack = [(j, None) for j in reversed(children.get(roots[0], []))]
    while stack:
        j, parent = stack.pop()
        name = j.get("name")
        where = f"{path}: joint `{name}`"
        jtype = j.get("type")
        if name in locked:
            kind = "fixed"
        elif jtype in ("revolute", "continuous"):
            kind = "revolute"
        elif jtype in ("prismatic", "fixed"):
            kind = jtype
        else:
            raise UrdfError(f"{where}: type {jtype!r} is not supported (unless locked)")
        if j.find("mimic") is not None and name not in locked:
            raise UrdfError(f"{where}: mimic joints must be locked")
        origin = j.find("origin")
        xyz = _floats(origin, "xyz", [0.0, 0.0, 0.0], where)
        rpy = _floats(origin, "rpy", [0.0, 0.0, 0.0], where)
        axis = _floats(j.find("axis"), "xyz", [1.0, 0.0, 0.0], where)
        coordinate = None
        if kind != "fixed":
            if not any(axis):
                raise UrdfError(f"{where}: zero axis")
            coordinate = first_coordinate + len(out.coordinates)
            out.coordinates.append((name, "d" + name))
            lim = j.find("limit")
            if lim is not None and lim.get("lower") is not None and lim.get("upper") is not None:
                out.limits[name] = (float(lim.get("lower")), float(lim.get("upper")))
        child = _link(j, "child", path)
        inertial = links[child].find("inertial")
        mass, com, rpy_in, inertia = 0.0, [0.0] * 3, [0.0] * 3, [0.0] * 6
        if inertial is not None:
            iw = f"{path}: link `{child}`"
            o = inertial.find("origin")
            com = _floats(o, "xyz", [0.0] * 3, iw)
            rpy_in = _floats(o, "rpy", [0.0] * 3, iw)
            (mass,) = _floats(inertial.find("mass"), "value", [0.0], iw)
            ie = inertial.find("inertia")
            inertia = [
                _floats(ie, k, [0.0], iw)[0] for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
            ]
        out.bodies.append(
            Body(
                name=child,
                parent=parent,
                kind=kind,
                coordinate=coordinate,
                axis=tuple(axis),
                xyz=[_num(x) for x in xyz],
                rpy=[_num(x) for x in rpy],
                mass=_num(mass),
                com=[_num(x) for x in com],
                inertia=[_num(x) for x in inertia],
                inertia_rpy=tuple(rpy_in),
            )
        )
        stack.extend((c, child) for c in reversed(children.get(child, [])))
        if len(stack) > len(joints):
            raise UrdfError(f"{path}: the joints form a cycle")
    return out


# --------------------------------------------------------------------------
# CasADi: poses and energies
# --------------------------------------------------------------------------


def _rpy(ca, r, p, y):
    """URDF's fixed-axis roll-pitch-yaw: Rz(y) Ry(p) Rx(r)."""
    rx = ca.SX(3, 3)
    rx[0, 0] = 1
    rx[1, 1], rx[1, 2], rx[2, 1], rx[2, 2] = ca.cos(r), -ca.sin(r), ca.sin(r), ca.cos(r)
    ry = ca.SX(3, 3)
    ry[1, 1] = 1
    ry[0, 0], ry[0, 2], ry[2, 0], ry[2, 2] = ca.cos(p), ca.sin(p), -ca.sin(p), ca.cos(p)
    rz = ca.SX(3, 3)
    rz[2, 2] = 1
    rz[0, 0], rz[0, 1], rz[1, 0], rz[1, 1] = ca.cos(y), -ca.sin(y), ca.sin(y), ca.cos(y)
    return ca.mtimes([rz, ry, rx])


def _about_axis(ca, a, angle):
    """The rotation by ``angle`` about the unit vector ``a``, from the unit
    quaternion ``(w, x, y, z) = (cos angle/2, sin angle/2 a)``."""
    w = ca.cos(angle / 2)
    s = ca.sin(angle / 2)
    x, y, z = s * a[0], s * a[1], s * a[2]
    return ca.vertcat(
        ca.horzcat(1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
        ca.horzcat(2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
        ca.horzcat(2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
    )


@dataclass
class TreeSX:
    """Each body's world pose ``(R, p)`` (body frame to world; origin), and
    the tree's kinetic and potential energies."""

    frames: dict
    T: object
    V: object


def build_tree(bodies: list[Body], gravity, q, v, number, ca) -> TreeSX:
    """Poses and energies of ``bodies`` (any order; parents by name).
    ``number(ast)`` turns a body's expression into SX; ``gravity`` is a 3×1
    SX."""
    by_name = {b.name: b for b in bodies}
    frames: dict = {}

    def pose(name: str, seen=()):
        if name in frames:
            return frames[name]
        if name in seen:
            raise UrdfError(f"the bodies form a cycle through `{name}`")
        if name not in by_name:
            raise UrdfError(f"`{name}` is not a body")
        b = by_name[name]
        if b.parent is None:
            r0, p0 = ca.SX.eye(3), ca.SX.zeros(3, 1)
        else:
            r0, p0 = pose(b.parent, seen + (name,))
        xyz = ca.vertcat(*[number(e) for e in b.xyz])
        r_origin = _rpy(ca, *[number(e) for e in b.rpy])
        norm = math.sqrt(sum(x * x for x in b.axis))
        a = [x / norm for x in b.axis]
        qi = q[b.coordinate] if b.coordinate is not None else None
        if b.kind == "revolute":
            r = ca.mtimes([r0, r_origin, _about_axis(ca, a, qi)])
            p = p0 + ca.mtimes(r0, xyz)
        elif b.kind == "prismatic":
            r = ca.mtimes(r0, r_origin)
            slide = ca.mtimes(r_origin, ca.DM(a)) * qi
            p = p0 + ca.mtimes(r0, xyz + slide)
        else:
            r = ca.mtimes(r0, r_origin)
            p = p0 + ca.mtimes(r0, xyz)
        frames[name] = (r, p)
        return frames[name]

    T = ca.SX(0)
    V = ca.SX(0)
    for b in bodies:
        r, p = pose(b.name)
        m = number(b.mass)
        c = p + ca.mtimes(r, ca.vertcat(*[number(e) for e in b.com]))
        cdot = ca.jtimes(c, q, v)
        rdot = ca.reshape(ca.jtimes(ca.reshape(r, 9, 1), q, v), 3, 3)
        omega_skew = ca.mtimes(r.T, rdot)  # [ω_b]×, skew up to rounding
        w = 0.5 * ca.vertcat(
            omega_skew[2, 1] - omega_skew[1, 2],
            omega_skew[0, 2] - omega_skew[2, 0],
            omega_skew[1, 0] - omega_skew[0, 1],
        )
        xx, xy, xz, yy, yz, zz = (number(e) for e in b.inertia)
        inertia = ca.vertcat(
            ca.horzcat(xx, xy, xz), ca.horzcat(xy, yy, yz), ca.horzcat(xz, yz, zz)
        )
        if any(b.inertia_rpy):
            turn = _rpy(ca, *b.inertia_rpy)
            inertia = ca.mtimes([turn, inertia, turn.T])
        T = T + 0.5 * m * ca.dot(cdot, cdot) + 0.5 * ca.dot(w, ca.mtimes(inertia, w))
        V = V - m * ca.dot(gravity, c)
    return TreeSX(frames=frames, T=T, V=V)
