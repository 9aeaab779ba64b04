#!/usr/bin/python3
"""Reference trajectories from Siconos for the moreau plant stepper.

Run with Debian's own interpreter, ``/usr/bin/python3`` (it is the one that
sees ``python3-siconos``; CI installs it with
``apt-get install -y python3-siconos python3-yaml python3-numpy``)::

    /usr/bin/python3 tests/siconos_reference.py            # (re)write the fixtures
    /usr/bin/python3 tests/siconos_reference.py --check    # compare with the committed ones
    /usr/bin/python3 tests/siconos_reference.py --time     # wall-clock time per step
    /usr/bin/python3 tests/siconos_reference.py --verify   # re-derive Siconos' steps in numpy

Two models, hand-coded here from the physics (an independent reference, not
derived from the moreau YAML front end); only parameter values and the
initial state are read from ``models/*.yaml``, and asserted equal to the ones
this code assumes (the model text is asserted too, whitespace-normalised, so
that an edited model cannot silently drift away from its reference):

* ``parabola``: the paper's Example 1. Unit point mass, gravity 9.81 in -y,
  h1 = y - x^2 >= 0 (floor), h2 = c - y >= 0 (ceiling, c = 8), e = 0.9,
  tau = 1e-3, final time 10 s.
* ``double_pendulum``: absolute angles th1, th2 from the downward vertical,
  point masses m1, m2 at the ends of massless links l1, l2, joint damping as
  the YAML's ``applied``; h_wall = wall - x_tip, h_floor = y_tip + floor,
  e = 0.8, tau = 1e-3, final time 5 s.

Both are simulated with Siconos' ``MoreauJeanOSI(theta=0.5, gamma=0.5)`` in a
``TimeStepping`` simulation with a fixed step, an ``LCP`` one-step problem
(Lemke, the default) and TimeStepping's default Newton loop (nonlinear, tolerance
1e-6 on the 2-norm of the dynamics residual, at most 50 iterations; set
explicitly below so that it is visible). Both models are ``LagrangianDS``
(the parabola with a constant mass matrix and a constant FExt) with Python
``LagrangianScleronomousR`` relations and ``NewtonImpactNSL`` laws. What
Siconos computes per step, formula by formula, is written up in
``tests/reference/siconos_notes.md`` and re-implemented in numpy by
``--verify`` (which checks it against Siconos' output).

Outputs (in ``tests/fixtures/siconos/``):

* ``<model>.csv``: ``#`` header lines (Siconos version, tau, theta, gamma,
  Newton settings), then ``k,t,q...,v...``; row k is the state after k steps
  (k = 0 is the initial state); floats written with ``repr()`` (shortest
  round-trip form); ``t`` is Siconos' own time value.
* ``<model>_steps.csv``: per step k >= 1 (the step from k-1 to k): the number
  of Newton iterations, the index set used in that step (``active_<name>``, 1
  if the constraint was in Siconos' index set 1) and the impulse multipliers
  ``lambda_<name>`` of the last Newton iteration (lambda(1) of the
  interaction; 0 outside the index set). These locate the first step where a
  re-implementation departs from Siconos.

Determinism: the simulation has no randomness and no threading; two runs on
one machine give byte-identical files. ``--check`` nevertheless compares
numerically, |a - b| <= 1e-12 * max(|a|, |b|, column scale) (the column
scale is the largest magnitude in that column, so that values crossing zero
are judged relative to their column), rather than byte by byte: the files
print every float with ``repr()``, so a single last-bit difference changes
the text, and last bits are not pinned across machines. Siconos and numpy
call BLAS/LAPACK (OpenBLAS picks its kernels at run time from the CPU, and
OPENBLAS_CORETYPE may be set), glibc's libm picks sin/cos variants at run
time too, and a rebuilt package may contract a*b+c into fused multiply-adds
differently. Such differences are ~1e-16. The damped double pendulum keeps
them there. The parabola is a billiard that amplifies a difference about
tenfold per impact (a 1e-16 perturbation at its third impact reaches ~1e-9
at 10 s), so a last-bit change there would show up; its arithmetic is,
however, nearly all exact or kernel-independent (M = I, W^-1 of the
identity, no transcendental functions, a 1x1 LCP solved by a division). A
parabola-only failure whose differences start tiny at an impact and grow
impact by impact is this amplification, not a change in Siconos.
``--check`` exits 1 with the first offending row and column if the files
differ, and 2 if a fixture is missing.

``--verify`` re-implements the per-step algorithm documented in
``tests/reference/siconos_notes.md`` in numpy (``mimic_step``) and compares it
with Siconos, both step by step from Siconos' own states and over the whole
trajectory; on this machine both fixtures are reproduced bit for bit. It also
checks the hand-coded FGyr and Jacobians against finite differences.

``--time`` runs each simulation loop (``computeOneStep(); nextStep()``)
without recording and prints the best-of-5 wall-clock time per step; nothing
is written. It times two builds of each model: the one used for the fixtures,
whose model functions are Python callbacks (SWIG directors, a few
microseconds each, which dominate the step), and one with the same functions
compiled into C plugins (needs ``cc``), Siconos' native way of plugging
functions and the fair figure for a speed comparison; it checks that both
end in the same state.
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time

try:
    import numpy as np
    import yaml
    import siconos
    import siconos.kernel as sk
except ImportError as err:  # pragma: no cover
    sys.exit("siconos_reference.py: %s. Run it with Debian's "
             "/usr/bin/python3 after `apt-get install -y python3-siconos python3-yaml "
             "python3-numpy`." % err)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODELS_DIR = os.path.join(ROOT, "models")
FIXTURES_DIR = os.path.join(ROOT, "tests", "fixtures", "siconos")

THETA = 0.5
GAMMA = 0.5
TAU = 1e-3
NEWTON_TOLERANCE = 1e-6     # TimeStepping's default
NEWTON_MAX_ITERATIONS = 50  # TimeStepping's default
RTOL = 1e-12


def siconos_version():
    """The Python module's version string and the Debian package version.

    Debian's 4.4.0+dfsg-2 carries an upstream patch that bumps the version
    string to 4.5.0 after the 4.4.0 release, so both are reported.
    """
    deb = "unknown"
    try:
        deb = subprocess.run(
            ["dpkg-query", "-W", "-f=${Version}", "python3-siconos"],
            capture_output=True, text=True, check=True).stdout.strip() or "unknown"
    except (OSError, subprocess.CalledProcessError):
        pass
    return "siconos module %s, Debian python3-siconos %s" % (siconos.version, deb)


# ---------------------------------------------------------------------------
# The models, hand-coded from the physics.
#
# Siconos' Lagrangian convention is M(q) q'' + FGyr(q, v) + FInt(t, q, v)
# = FExt(t) + p, and it works with forces = FExt - FInt - FGyr (the negative
# of the paper's F). Jacobians are those of FInt and FGyr.
# ---------------------------------------------------------------------------

def _norm(text):
    return " ".join(str(text).split())


def load_yaml(name):
    with open(os.path.join(MODELS_DIR, name)) as f:
        return yaml.safe_load(f)


def _check(cond, what):
    if not cond:
        raise SystemExit("siconos_reference.py: the model file disagrees with "
                         "the hand-coded reference: %s" % what)


def _check_common(doc, fname, coords, params, kinetic, potential, constraints,
                  restitution, forces=None):
    _check([tuple(c.items())[0] for c in doc["coordinates"]] == coords,
           "%s coordinates %r" % (fname, doc["coordinates"]))
    _check(list(doc["parameters"].keys()) == list(params.keys()),
           "%s parameter names %r" % (fname, list(doc["parameters"].keys())))
    for k, v in params.items():
        _check(float(doc["parameters"][k]) == v,
               "%s parameter %s = %r, expected %r" % (fname, k, doc["parameters"][k], v))
    _check(_norm(doc["kinetic"]) == _norm(kinetic), "%s kinetic %r" % (fname, doc["kinetic"]))
    _check(_norm(doc.get("potential", "0")) == _norm(potential),
           "%s potential %r" % (fname, doc.get("potential")))
    got = [(c["name"], _norm(c["h"]), c.get("restitution")) for c in doc["constraints"]]
    _check(got == [(n, _norm(h), None) for n, h in constraints],
           "%s constraints %r" % (fname, got))
    _check(float(doc["restitution"]) == restitution,
           "%s restitution %r" % (fname, doc["restitution"]))
    got_forces = {k: _norm(v) for k, v in (doc.get("applied") or {}).items()}
    _check(got_forces == {k: _norm(v) for k, v in (forces or {}).items()},
           "%s applied forces %r" % (fname, doc.get("applied")))


class Parabola:
    """The paper's Example 1 (models/parabola.yaml)."""

    name = "parabola"
    yaml_file = "parabola.yaml"
    final_time = 10.0
    q_names = ["x", "y"]
    v_names = ["vx", "vy"]
    constraint_names = ["floor", "ceiling"]
    params = {"m": 1.0, "g": 9.81, "c": 8.0}
    restitution = 0.9
    initial = {"x": 1.5, "y": 4.0, "vx": 3.0, "vy": 9.0}

    def __init__(self):
        doc = load_yaml(self.yaml_file)
        _check(doc["name"] == "Parabola", "name %r" % doc["name"])
        _check_common(doc, self.yaml_file, [("x", "vx"), ("y", "vy")], self.params,
                      "0.5 * m * (vx^2 + vy^2)", "m * g * y",
                      [("floor", "y - x^2"), ("ceiling", "c - y")], self.restitution)
        init = {k: float(v) for k, v in doc["initial"].items()}
        _check(init == self.initial, "%s initial %r" % (self.yaml_file, doc["initial"]))
        self.q0 = [self.initial["x"], self.initial["y"]]
        self.v0 = [self.initial["vx"], self.initial["vy"]]
        p = self.params
        self.m, self.g, self.c = p["m"], p["g"], p["c"]
        self.e = [self.restitution, self.restitution]

    # M constant, forces = FExt = (0, -m g), no FInt/FGyr (so no Jacobians).
    def mass(self, q):
        return np.array([[self.m, 0.0], [0.0, self.m]])

    def fext(self):
        return [0.0, -self.m * self.g]

    def forces(self, t, q, v):
        return np.array(self.fext())

    def dforces_dq(self, t, q, v):
        return None

    def dforces_dv(self, t, q, v):
        return None

    def gap(self, i, q):
        if i == 0:
            return q[1] - q[0] ** 2
        return self.c - q[1]

    def gap_jacobian(self, i, q):
        if i == 0:
            return (-2.0 * q[0], 1.0)
        return (0.0, -1.0)


class DoublePendulum:
    """The double pendulum (models/double_pendulum.yaml).

    T = 1/2 (m1+m2) l1^2 w1^2 + 1/2 m2 l2^2 w2^2 + m2 l1 l2 w1 w2 cos(th1-th2)
    V = -(m1+m2) g l1 cos th1 - m2 g l2 cos th2,
    Q = (-b w1 + b (w2 - w1), -b (w2 - w1))  (damping b in both joints; the
    torque of joint 2 reacts on link 1).
    Lagrange's equations give, with a = m2 l1 l2, s = sin(th1-th2), c = cos(th1-th2):
      M(q)  = [[(m1+m2) l1^2, a c], [a c, m2 l2^2]]
      FGyr  = (a s w2^2, -a s w1^2)                       (C(q, v) v)
      FInt  = ((m1+m2) g l1 sin th1 + b w1 - b (w2 - w1), m2 g l2 sin th2 + b (w2 - w1))
                                                          (G - Q)
    and forces = -FInt - FGyr.
    """

    name = "double_pendulum"
    yaml_file = "double_pendulum.yaml"
    final_time = 5.0
    q_names = ["th1", "th2"]
    v_names = ["w1", "w2"]
    constraint_names = ["wall", "floor"]
    params = {"m1": 1.0, "m2": 1.0, "l1": 1.0, "l2": 1.0, "g": 9.81, "b": 0.05,
              "wall": 1.2, "floor": 1.6}
    restitution = 0.8
    initial = {"th1": -0.8, "th2": -1.0}

    def __init__(self):
        doc = load_yaml(self.yaml_file)
        _check(doc["name"] == "DoublePendulum", "name %r" % doc["name"])
        _check_common(
            doc, self.yaml_file, [("th1", "w1"), ("th2", "w2")], self.params,
            "0.5 * (m1 + m2) * l1^2 * w1^2 + 0.5 * m2 * l2^2 * w2^2"
            " + m2 * l1 * l2 * w1 * w2 * cos(th1 - th2)",
            "-(m1 + m2) * g * l1 * cos(th1) - m2 * g * l2 * cos(th2)",
            [("wall", "wall - x_tip"), ("floor", "y_tip + floor")], self.restitution,
            forces={"th1": "-b * w1 + b * (w2 - w1)", "th2": "-b * (w2 - w1)"})
        defs = {k: _norm(v) for k, v in doc["definitions"].items()}
        _check(defs == {"x_tip": "l1 * sin(th1) + l2 * sin(th2)",
                        "y_tip": "-l1 * cos(th1) - l2 * cos(th2)"},
               "%s definitions %r" % (self.yaml_file, doc["definitions"]))
        init = {k: float(v) for k, v in doc["initial"].items()}
        _check(init == self.initial, "%s initial %r" % (self.yaml_file, doc["initial"]))
        # Missing initial entries are 0 (models/README.md).
        self.q0 = [self.initial.get("th1", 0.0), self.initial.get("th2", 0.0)]
        self.v0 = [self.initial.get("w1", 0.0), self.initial.get("w2", 0.0)]
        p = self.params
        self.m1, self.m2, self.l1, self.l2 = p["m1"], p["m2"], p["l1"], p["l2"]
        self.g, self.b, self.wall, self.floor = p["g"], p["b"], p["wall"], p["floor"]
        self.e = [self.restitution, self.restitution]

    # Scalar kernels (plain floats: they are called from Siconos callbacks).
    def mass_entries(self, q):
        a = self.m2 * self.l1 * self.l2
        c = math.cos(q[0] - q[1])
        return ((self.m1 + self.m2) * self.l1 * self.l1, a * c, self.m2 * self.l2 * self.l2)

    def fint(self, q, v):
        return ((self.m1 + self.m2) * self.g * self.l1 * math.sin(q[0])
                + (self.b * v[0] - self.b * (v[1] - v[0])),
                self.m2 * self.g * self.l2 * math.sin(q[1]) + self.b * (v[1] - v[0]))

    def fgyr(self, q, v):
        a = self.m2 * self.l1 * self.l2
        s = math.sin(q[0] - q[1])
        return (a * s * v[1] * v[1], -a * s * v[0] * v[0])

    def jac_fint_q(self, q, v):
        return (((self.m1 + self.m2) * self.g * self.l1 * math.cos(q[0]), 0.0),
                (0.0, self.m2 * self.g * self.l2 * math.cos(q[1])))

    def jac_fint_v(self, q, v):
        return ((2.0 * self.b, -self.b), (-self.b, self.b))

    def jac_fgyr_q(self, q, v):
        a = self.m2 * self.l1 * self.l2
        c = math.cos(q[0] - q[1])
        return ((a * c * v[1] * v[1], -a * c * v[1] * v[1]),
                (-a * c * v[0] * v[0], a * c * v[0] * v[0]))

    def jac_fgyr_v(self, q, v):
        a = self.m2 * self.l1 * self.l2
        s = math.sin(q[0] - q[1])
        return ((0.0, 2.0 * a * s * v[1]), (-2.0 * a * s * v[0], 0.0))

    # numpy forms (for --verify).
    def mass(self, q):
        m11, m12, m22 = self.mass_entries(q)
        return np.array([[m11, m12], [m12, m22]])

    def forces(self, t, q, v):
        return -np.array(self.fint(q, v)) - np.array(self.fgyr(q, v))

    def dforces_dq(self, t, q, v):
        return -np.array(self.jac_fint_q(q, v)) - np.array(self.jac_fgyr_q(q, v))

    def dforces_dv(self, t, q, v):
        return -np.array(self.jac_fint_v(q, v)) - np.array(self.jac_fgyr_v(q, v))

    def gap(self, i, q):
        if i == 0:
            return self.wall - (self.l1 * math.sin(q[0]) + self.l2 * math.sin(q[1]))
        return (-self.l1 * math.cos(q[0]) - self.l2 * math.cos(q[1])) + self.floor

    def gap_jacobian(self, i, q):
        if i == 0:
            return (-self.l1 * math.cos(q[0]), -self.l2 * math.cos(q[1]))
        return (self.l1 * math.sin(q[0]), self.l2 * math.sin(q[1]))


MODELS = {"parabola": Parabola, "double_pendulum": DoublePendulum}


# ---------------------------------------------------------------------------
# Siconos objects. Known pitfalls of the Debian bindings (4.4.0):
#  * a Python subclass of LagrangianScleronomousR crashes unless it overrides
#    computeDotJachq (a no-op is enough) and C(), the latter returning a
#    Python-owned SimpleMatrix registered with setJachqPtr and filled in
#    computeJachq;
#  * passing a SimpleMatrix to LagrangianDS.__init__ of a Python subclass
#    aborts (SWIG ownership assertion); pass a numpy array, then setMassPtr;
#  * directors replace every C++ overload of a method by the one Python
#    method, so computeMass/computeFInt/... take the (time,) or
#    (time, q, v) forms alike (the short forms mean "at the DS's current
#    q and v");
#  * LagrangianDS only allocates jacobianqForces/jacobianvForces (and so only
#    puts the Jacobians into W) in init_forces(), which the set*Ptr setters
#    do not call: call it once all pointers are set.
# ---------------------------------------------------------------------------

CALLS = [0]  # callback counter, for --time


class GapRelation(sk.LagrangianScleronomousR):
    """h_i(q) >= 0 with its Jacobian, as a Python scleronomous relation."""

    def __init__(self, model, index):
        sk.LagrangianScleronomousR.__init__(self)
        self._model = model
        self._index = index
        self._J = sk.SimpleMatrix(1, 2)
        self.setJachqPtr(self._J)

    def computeh(self, q, z, y):
        CALLS[0] += 1
        y[0] = self._model.gap(self._index, q)

    def computeJachq(self, q, z):
        CALLS[0] += 1
        a, b = self._model.gap_jacobian(self._index, q)
        self._J.setValue(0, 0, a)
        self._J.setValue(0, 1, b)

    def computeDotJachq(self, q, z, qdot):
        pass

    def C(self):
        return self._J


class PendulumDS(sk.LagrangianDS):
    """The double pendulum as a LagrangianDS with Python M, FInt, FGyr and Jacobians."""

    def __init__(self, model):
        sk.LagrangianDS.__init__(self, np.array(model.q0), np.array(model.v0), np.eye(2))
        self._model = model
        self._M = sk.SimpleMatrix(2, 2)
        self._fint = sk.SiconosVector(2)
        self._fgyr = sk.SiconosVector(2)
        self._Kint = sk.SimpleMatrix(2, 2)
        self._Cint = sk.SimpleMatrix(2, 2)
        self._Kgyr = sk.SimpleMatrix(2, 2)
        self._Cgyr = sk.SimpleMatrix(2, 2)
        self.setMassPtr(self._M)
        self.setFIntPtr(self._fint)
        self.setFGyrPtr(self._fgyr)
        self.setJacobianFIntqPtr(self._Kint)
        self.setJacobianFIntqDotPtr(self._Cint)
        self.setJacobianFGyrqPtr(self._Kgyr)
        self.setJacobianFGyrqDotPtr(self._Cgyr)
        self.init_forces()
        self.computeMass()

    def _qv(self, args):
        if args:
            return args[0], args[1]
        return self.q(), self.velocity()

    @staticmethod
    def _set2(mat, rows):
        for i in range(2):
            for j in range(2):
                mat.setValue(i, j, rows[i][j])

    def computeMass(self, *args):
        CALLS[0] += 1
        q = args[0] if args else self.q()
        m11, m12, m22 = self._model.mass_entries(q)
        self._set2(self._M, ((m11, m12), (m12, m22)))

    def computeFInt(self, t, *args):
        CALLS[0] += 1
        f = self._model.fint(*self._qv(args))
        self._fint.setValue(0, f[0])
        self._fint.setValue(1, f[1])

    def computeFGyr(self, *args):
        CALLS[0] += 1
        f = self._model.fgyr(*self._qv(args))
        self._fgyr.setValue(0, f[0])
        self._fgyr.setValue(1, f[1])

    def computeJacobianFIntq(self, t, *args):
        CALLS[0] += 1
        self._set2(self._Kint, self._model.jac_fint_q(*self._qv(args)))

    def computeJacobianFIntqDot(self, t, *args):
        CALLS[0] += 1
        self._set2(self._Cint, self._model.jac_fint_v(*self._qv(args)))

    def computeJacobianFGyrq(self, *args):
        CALLS[0] += 1
        self._set2(self._Kgyr, self._model.jac_fgyr_q(*self._qv(args)))

    def computeJacobianFGyrqDot(self, *args):
        CALLS[0] += 1
        self._set2(self._Cgyr, self._model.jac_fgyr_v(*self._qv(args)))


def build(model):
    """The Siconos simulation of a model: (sim, ds, interactions)."""
    if isinstance(model, Parabola):
        ds = sk.LagrangianDS(np.array(model.q0), np.array(model.v0), model.mass(model.q0))
        ds.setFExtPtr(np.array(model.fext()))
    else:
        ds = PendulumDS(model)
    nsds = sk.NonSmoothDynamicalSystem(0.0, model.final_time)
    nsds.insertDynamicalSystem(ds)
    relations = [GapRelation(model, i) for i in range(len(model.constraint_names))]
    inters = [sk.Interaction(sk.NewtonImpactNSL(e), r) for e, r in zip(model.e, relations)]
    for inter in inters:
        nsds.link(inter, ds)
    osi = sk.MoreauJeanOSI(THETA, GAMMA)
    assert osi.useGamma() and osi.gamma() == GAMMA and osi.theta() == THETA
    td = sk.TimeDiscretisation(0.0, TAU)
    lcp = sk.LCP()  # Lemke
    sim = sk.TimeStepping(nsds, td, osi, lcp)
    sim.setNewtonOptions(sk.SICONOS_TS_NONLINEAR)
    sim.setNewtonTolerance(NEWTON_TOLERANCE)
    sim.setNewtonMaxIteration(NEWTON_MAX_ITERATIONS)
    # keep the Python objects alive as long as the simulation
    sim._keep = (ds, nsds, relations, inters, osi, td, lcp)
    return sim, ds, inters


def simulate(model):
    """Run Siconos; return (states, steps): rows of the two CSV files."""
    sim, ds, inters = build(model)
    q = ds.q()          # numpy views on the DS state
    v = ds.velocity()
    numbers = [inter.number() for inter in inters]
    states = [[0, 0.0] + [float(x) for x in q] + [float(x) for x in v]]
    steps = []
    k = 0
    while sim.hasNextEvent():
        sim.computeOneStep()
        k += 1
        active_numbers = {i.number() for i in sim.indexSet(1).interactions()}
        active = [1 if n in active_numbers else 0 for n in numbers]
        lam = [float(inter.lambda_(1)[0]) for inter in inters]
        states.append([k, float(sim.nextTime())] + [float(x) for x in q]
                      + [float(x) for x in v])
        steps.append([k, int(sim.getNewtonNbIterations())] + active + lam)
        sim.nextStep()
    return states, steps


# The same model functions as compiled C plugins (Siconos' native way of
# plugging functions), for --time only: the Python directors above cost a
# few microseconds per call, which would dominate the per-step time. The C
# bodies evaluate the same expressions in the same order as the Python ones
# (gcc without -ffast-math and with -ffp-contract=off neither reorders nor
# fuses them, and both call the C library's sin/cos), so the trajectories are
# the same; --time checks that. Matrices are column-major (Siconos' dense
# matrices are ublas column_major).

def _c(x):
    return repr(float(x))


def c_source(model):
    if isinstance(model, Parabola):
        return """
#include <math.h>
void h_floor(unsigned int nq, double *q, unsigned int ny, double *y, unsigned int nz, double *z)
{ y[0] = q[1] - q[0] * q[0]; }
void J_floor(unsigned int nq, double *q, unsigned int ny, double *J, unsigned int nz, double *z)
{ J[0] = -2.0 * q[0]; J[1] = 1.0; }
void h_ceiling(unsigned int nq, double *q, unsigned int ny, double *y, unsigned int nz, double *z)
{ y[0] = C_ - q[1]; }
void J_ceiling(unsigned int nq, double *q, unsigned int ny, double *J, unsigned int nz, double *z)
{ J[0] = 0.0; J[1] = -1.0; }
""".replace("C_", _c(model.c))
    # q ** 2 in Python is q * q for floats (correctly rounded square).
    src = """
#include <math.h>
#define M1 %(m1)s
#define M2 %(m2)s
#define L1 %(l1)s
#define L2 %(l2)s
#define G %(g)s
#define B %(b)s
#define WALL %(wall)s
#define FLOOR %(floor)s
void mass(unsigned int n, double *q, double *M, unsigned int nz, double *z)
{
  double a = M2 * L1 * L2, c = cos(q[0] - q[1]);
  M[0] = (M1 + M2) * L1 * L1; M[1] = a * c; M[2] = a * c; M[3] = M2 * L2 * L2;
}
void fint(double t, unsigned int n, double *q, double *v, double *f, unsigned int nz, double *z)
{
  f[0] = (M1 + M2) * G * L1 * sin(q[0]) + (B * v[0] - B * (v[1] - v[0]));
  f[1] = M2 * G * L2 * sin(q[1]) + B * (v[1] - v[0]);
}
void fgyr(unsigned int n, double *q, double *v, double *f, unsigned int nz, double *z)
{
  double a = M2 * L1 * L2, s = sin(q[0] - q[1]);
  f[0] = a * s * v[1] * v[1]; f[1] = -a * s * v[0] * v[0];
}
void jac_fint_q(double t, unsigned int n, double *q, double *v, double *K, unsigned int nz, double *z)
{
  K[0] = (M1 + M2) * G * L1 * cos(q[0]); K[1] = 0.0; K[2] = 0.0; K[3] = M2 * G * L2 * cos(q[1]);
}
void jac_fint_v(double t, unsigned int n, double *q, double *v, double *C, unsigned int nz, double *z)
{
  C[0] = 2.0 * B; C[1] = -B; C[2] = -B; C[3] = B;
}
void jac_fgyr_q(unsigned int n, double *q, double *v, double *K, unsigned int nz, double *z)
{
  double a = M2 * L1 * L2, c = cos(q[0] - q[1]);
  K[0] = a * c * v[1] * v[1]; K[1] = -a * c * v[0] * v[0];
  K[2] = -a * c * v[1] * v[1]; K[3] = a * c * v[0] * v[0];
}
void jac_fgyr_v(unsigned int n, double *q, double *v, double *C, unsigned int nz, double *z)
{
  double a = M2 * L1 * L2, s = sin(q[0] - q[1]);
  C[0] = 0.0; C[1] = -2.0 * a * s * v[0]; C[2] = 2.0 * a * s * v[1]; C[3] = 0.0;
}
void h_wall(unsigned int nq, double *q, unsigned int ny, double *y, unsigned int nz, double *z)
{ y[0] = WALL - (L1 * sin(q[0]) + L2 * sin(q[1])); }
void J_wall(unsigned int nq, double *q, unsigned int ny, double *J, unsigned int nz, double *z)
{ J[0] = -L1 * cos(q[0]); J[1] = -L2 * cos(q[1]); }
void h_floor(unsigned int nq, double *q, unsigned int ny, double *y, unsigned int nz, double *z)
{ y[0] = (-L1 * cos(q[0]) - L2 * cos(q[1])) + FLOOR; }
void J_floor(unsigned int nq, double *q, unsigned int ny, double *J, unsigned int nz, double *z)
{ J[0] = L1 * sin(q[0]); J[1] = L2 * sin(q[1]); }
"""
    return src % {k: "(" + _c(v) + ")" for k, v in model.params.items()}


def build_c(model, plugin_dir):
    """The Siconos simulation with C plugins compiled into plugin_dir; None without a compiler."""
    base = os.path.join(plugin_dir, model.name)
    with open(base + ".c", "w") as f:
        f.write(c_source(model))
    try:
        subprocess.run(["cc", "-O2", "-ffp-contract=off", "-fPIC", "-shared", "-o", base + ".so",
                        base + ".c", "-lm"], check=True, capture_output=True)
    except (OSError, subprocess.CalledProcessError) as err:
        print("note: cannot compile C plugins (%s); skipping the C-plugin timing" % err)
        return None
    so = base + ".so"
    if isinstance(model, Parabola):
        ds = sk.LagrangianDS(np.array(model.q0), np.array(model.v0), model.mass(model.q0))
        ds.setFExtPtr(np.array(model.fext()))
    else:
        ds = sk.LagrangianDS(np.array(model.q0), np.array(model.v0), np.eye(2))
        ds.setComputeMassFunction(so, "mass")
        ds.setComputeFIntFunction(so, "fint")
        ds.setComputeFGyrFunction(so, "fgyr")
        ds.setComputeJacobianFIntqFunction(so, "jac_fint_q")
        ds.setComputeJacobianFIntqDotFunction(so, "jac_fint_v")
        ds.setComputeJacobianFGyrqFunction(so, "jac_fgyr_q")
        ds.setComputeJacobianFGyrqDotFunction(so, "jac_fgyr_v")
        ds.computeMass()
    nsds = sk.NonSmoothDynamicalSystem(0.0, model.final_time)
    nsds.insertDynamicalSystem(ds)
    relations = [sk.LagrangianScleronomousR("%s:h_%s" % (base, n), "%s:J_%s" % (base, n))
                 for n in model.constraint_names]
    inters = [sk.Interaction(sk.NewtonImpactNSL(e), r) for e, r in zip(model.e, relations)]
    for inter in inters:
        nsds.link(inter, ds)
    osi = sk.MoreauJeanOSI(THETA, GAMMA)
    td = sk.TimeDiscretisation(0.0, TAU)
    lcp = sk.LCP()
    sim = sk.TimeStepping(nsds, td, osi, lcp)
    sim.setNewtonOptions(sk.SICONOS_TS_NONLINEAR)
    sim.setNewtonTolerance(NEWTON_TOLERANCE)
    sim.setNewtonMaxIteration(NEWTON_MAX_ITERATIONS)
    sim._keep = (ds, nsds, relations, inters, osi, td, lcp)
    return sim, ds, inters


def time_loop(make, repeats=5):
    """Best-of-`repeats` wall-clock seconds per step of the bare Siconos loop
    (computeOneStep + nextStep; building the simulation is not timed), and
    the final state of the last run."""
    best = None
    for _ in range(repeats):
        sim, ds, inters = make()
        CALLS[0] = 0
        n = 0
        t0 = time.perf_counter()
        while sim.hasNextEvent():
            sim.computeOneStep()
            sim.nextStep()
            n += 1
        dt = time.perf_counter() - t0
        per = dt / n
        if best is None or per < best[0]:
            best = (per, n, CALLS[0] / n, dt)
        final = [float(x) for x in ds.q()] + [float(x) for x in ds.velocity()]
    return best + (final,)


# ---------------------------------------------------------------------------
# Files.
# ---------------------------------------------------------------------------

def header_lines(model):
    return [
        "# Siconos reference trajectory: %s (models/%s), written by tests/siconos_reference.py"
        % (model.name, model.yaml_file),
        "# siconos: %s" % siconos_version(),
        "# MoreauJeanOSI theta=%r gamma=%r; TimeStepping tau=%r t0=0.0 T=%r; "
        "Newton nonlinear tol=%r max_iter=%d; LCP Lemke"
        % (THETA, GAMMA, TAU, model.final_time, NEWTON_TOLERANCE, NEWTON_MAX_ITERATIONS),
    ]


def fmt(x):
    return repr(x) if isinstance(x, float) else str(x)


def write_files(model, states, steps, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    head = header_lines(model)
    cols = ["k", "t"] + model.q_names + model.v_names
    with open(os.path.join(out_dir, model.name + ".csv"), "w") as f:
        f.write("\n".join(head) + "\n")
        f.write(",".join(cols) + "\n")
        for row in states:
            f.write(",".join(fmt(x) for x in row) + "\n")
    scols = (["k", "newton_iterations"]
             + ["active_" + n for n in model.constraint_names]
             + ["lambda_" + n for n in model.constraint_names])
    with open(os.path.join(out_dir, model.name + "_steps.csv"), "w") as f:
        f.write("\n".join(head) + "\n")
        f.write("# row k: the step from state k-1 to state k; active_*: in Siconos' index set 1"
                " during that step; lambda_*: lambda(1) of the last Newton iteration\n")
        f.write(",".join(scols) + "\n")
        for row in steps:
            f.write(",".join(fmt(x) for x in row) + "\n")


def read_csv(path):
    comments, header, rows = [], None, []
    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("#"):
                comments.append(line)
            elif header is None:
                header = line.split(",")
            elif line:
                rows.append([float(x) for x in line.split(",")])
    return comments, header, np.array(rows)


def compare_file(name, ref_path, new_path):
    """Return None if the files agree (numerically), else a message."""
    if not os.path.exists(ref_path):
        return "missing fixture %s" % ref_path
    rc, rh, ra = read_csv(ref_path)
    nc, nh, na = read_csv(new_path)
    for a, b in zip(rc, nc):
        if a != b and not a.startswith("# siconos:"):
            return "%s: header differs:\n  committed: %s\n  now:       %s" % (name, a, b)
    if len(rc) != len(nc):
        return "%s: number of header lines differs" % name
    if rc[1:2] != nc[1:2]:
        print("note: %s: Siconos version differs:\n  committed: %s\n  now:       %s"
              % (name, rc[1], nc[1]))
    if rh != nh:
        return "%s: columns differ: committed %r, now %r" % (name, rh, nh)
    if ra.shape != na.shape:
        return "%s: shape differs: committed %r, now %r" % (name, ra.shape, na.shape)
    scale = np.max(np.abs(ra), axis=0) if ra.size else np.zeros(0)
    bound = RTOL * np.maximum(np.maximum(np.abs(ra), np.abs(na)), scale)
    bad = np.abs(ra - na) > bound
    if bad.any():
        i, j = np.argwhere(bad)[0]
        return ("%s: %d values differ by more than %g relative; first at row k=%d, column %s: "
                "committed %r, now %r (|diff| %.3g)"
                % (name, int(bad.sum()), RTOL, int(ra[i, 0]), rh[j], ra[i, j], na[i, j],
                   abs(ra[i, j] - na[i, j])))
    return None


# ---------------------------------------------------------------------------
# --verify: the per-step algorithm of MoreauJeanOSI + TimeStepping (Siconos
# 4.4.0, see tests/reference/siconos_notes.md) re-implemented in numpy, and
# checks of the hand-coded physics against finite differences.
# ---------------------------------------------------------------------------

# Small dense linear algebra. Products and sums are written out in plain
# scalar arithmetic, in the order Siconos' ublas code evaluates them (numpy's
# dot/matmul go through OpenBLAS, whose kernels may reorder sums and fuse
# multiply-adds: that alone parts the parabola's trajectories at the 1e-16
# level at its third impact). Linear solves go through LAPACK's dgesv
# (dgetrf + dgetrs), as Siconos' SimpleMatrix::Solve does (PLU factorisation
# by dgetrf, then dgetrs).

def _matvec(A, x):
    return [sum_in_order(A[i][j] * x[j] for j in range(len(x))) for i in range(len(A))]


def sum_in_order(terms):
    acc = 0.0
    first = True
    for t in terms:
        acc = t if first else acc + t
        first = False
    return acc


def _solve(A, b):
    """x with A x = b by LU with partial pivoting (LAPACK, like W.Solve in Siconos)."""
    return [float(x) for x in np.linalg.solve(np.array(A, dtype=float), np.array(b, dtype=float))]


def solve_lcp(A, b):
    """0 <= lam _|_ A lam + b >= 0 as numerics' lcp_driver_DenseMatrix does for
    these sizes: z = 0 if b >= 0 (trivial case); z = -b/A if n = 1; else Lemke,
    here replaced by enumeration (the solution is unique: A is a P-matrix)."""
    n = len(b)
    if all(x >= 0.0 for x in b):
        return [0.0] * n
    if n == 1:
        return [-b[0] / A[0][0]]
    for mask in range(1, 1 << n):
        S = [i for i in range(n) if mask >> i & 1]
        lam = [0.0] * n
        sol = _solve([[A[i][j] for j in S] for i in S], [-b[i] for i in S])
        for i, x in zip(S, sol):
            lam[i] = x
        w = [x + y for x, y in zip(_matvec(A, lam), b)]
        if all(x >= 0.0 for x in lam) and all(w[i] >= -1e-12 * (1.0 + abs(b[i]))
                                               for i in range(n) if i not in S):
            return lam
    raise RuntimeError("LCP: no solution found")


def tk(j):
    """TimeDiscretisation::getTk(j) = t0 + h*j with t0 = 0."""
    return 0.0 + TAU * j


def index_set(model, k, q, v):
    """Siconos' index set for step k+1 from the state after step k:
    h_i(q) + gamma * (t_{k+1} - t_k) * (J_i(q) v) <= 0."""
    h = tk(k + 1) - tk(k)
    out = []
    for i in range(len(model.constraint_names)):
        J = model.gap_jacobian(i, q)
        y1 = J[0] * v[0] + J[1] * v[1]
        out.append(model.gap(i, q) + GAMMA * h * y1 <= 0.0)
    return out


def mimic_step(model, k, q_old, v_old, active):
    """One TimeStepping/MoreauJeanOSI step from state k-1 to k, as in the notes.

    Returns (q, v, newton_iterations, lambda)."""
    th = THETA
    t = tk(k)
    h = tk(k) - tk(k - 1)          # Simulation::timeStep(): t_{k+1} - t_k, not TAU
    n, m = 2, len(model.constraint_names)
    M = lambda qq: model.mass(qq).tolist()
    F = lambda tt, qq, vv: list(model.forces(tt, qq, vv))
    # what the previous step left in memory
    f_old = F(tk(k - 1), q_old, v_old)                           # forcesMemory
    y1_old = [sum_in_order(model.gap_jacobian(i, q_old)[j] * v_old[j] for j in range(n))
              for i in range(m)]                                  # y_k(1)
    e = model.e

    def residu_free(qq, vv, f_new):
        # residuFree = M(q)(v - v_k) - h(1-theta) f_k - h theta f(t_{k+1}, q, v)
        r = _matvec(M(qq), [vv[j] - v_old[j] for j in range(n)])
        return [(r[j] + (-h * (1 - th)) * f_old[j]) + (-h * th) * f_new[j] for j in range(n)]

    def W_of(qq, vv):
        W = M(qq)
        C = model.dforces_dv(t, qq, vv)
        K = model.dforces_dq(t, qq, vv)
        for i in range(n):
            for j in range(n):
                if C is not None:
                    W[i][j] = W[i][j] + (-h * th) * C[i][j]
                if K is not None:
                    W[i][j] = W[i][j] + (-h * h * th * th) * K[i][j]
        return W

    # computeInitialNewtonState: q = (h theta v + h (1-theta) v_k) + q_k with v = v_k
    vi = list(v_old)
    qi = [(h * th * vi[j] + h * (1 - th) * v_old[j]) + q_old[j] for j in range(n)]
    res = residu_free(qi, vi, F(t, qi, vi))
    it = 0
    while True:
        it += 1
        W = W_of(qi, vi)                                           # at (q^i, v^i), t_{k+1}
        Wr = _solve(W, res)
        vfree = [-Wr[j] + vi[j] for j in range(n)]
        Ji = [model.gap_jacobian(i, qi) for i in range(m)]        # J(q^i)
        lam = [0.0] * m
        idx = [i for i in range(m) if active[i]]
        if idx:
            WiJt = [_solve(W, [Ji[i][j] for j in range(n)]) for i in idx]   # W^-1 J_i^T
            A = [[sum_in_order(Ji[a][j] * WiJt[bb][j] for j in range(n)) for bb in range(len(idx))]
                 for a in idx]
            b = [sum_in_order(Ji[a][j] * vfree[j] for j in range(n)) + e[a] * y1_old[a] for a in idx]
            for a, x in zip(idx, solve_lcp(A, b)):
                lam[a] = x
        p = [0.0] * n
        for i in range(m):
            for j in range(n):
                p[j] = p[j] + lam[i] * Ji[i][j]
        Wp = _solve(W, p)
        vi = [Wp[j] + vfree[j] for j in range(n)]
        qi = [(h * th * vi[j] + h * (1 - th) * v_old[j]) + q_old[j] for j in range(n)]
        res = residu_free(qi, vi, F(t, qi, vi))
        r = [res[j] - p[j] for j in range(n)]
        if math.sqrt(sum_in_order(x * x for x in r)) <= NEWTON_TOLERANCE or it >= NEWTON_MAX_ITERATIONS:
            break
    return qi, vi, it, lam


def mimic(model, nsteps):
    """The whole trajectory with mimic_step; returns states and steps like simulate()."""
    q, v = list(map(float, model.q0)), list(map(float, model.v0))
    states = [[0, tk(0)] + q + v]
    steps = []
    active = index_set(model, 0, q, v)
    for k in range(1, nsteps + 1):
        q, v, it, lam = mimic_step(model, k, q, v, active)
        states.append([k, tk(k)] + q + v)
        steps.append([k, it] + [int(a) for a in active] + lam)
        active = index_set(model, k, q, v)
    return states, steps


def replay(model, states):
    """mimic_step from each of Siconos' states k-1; returns rows like simulate()."""
    out_states, out_steps = [states[0]], []
    for k in range(1, len(states)):
        q_old, v_old = states[k - 1][2:4], states[k - 1][4:6]
        active = index_set(model, k - 1, q_old, v_old)
        q, v, it, lam = mimic_step(model, k, q_old, v_old, active)
        out_states.append([k, tk(k)] + q + v)
        out_steps.append([k, it] + [int(a) for a in active] + lam)
    return out_states, out_steps


def check_physics(model, rng):
    """The hand-coded FGyr and Jacobians against finite differences of M and F."""
    if not isinstance(model, DoublePendulum):
        return 0.0
    worst = 0.0
    eps = 1e-6
    for _ in range(20):
        q = rng.uniform(-3, 3, 2)
        v = rng.uniform(-3, 3, 2)
        # FGyr = (sum_j dM/dq_j v_j) v - 1/2 (v^T dM/dq_i v)_i
        dM = [(model.mass(q + eps * e) - model.mass(q - eps * e)) / (2 * eps) for e in np.eye(2)]
        fgyr = (dM[0] * v[0] + dM[1] * v[1]) @ v - 0.5 * np.array([v @ dM[i] @ v for i in range(2)])
        worst = max(worst, np.max(np.abs(fgyr - np.array(model.fgyr(q, v)))))
        for i, e in enumerate(np.eye(2)):
            dq = (model.forces(0, q + eps * e, v) - model.forces(0, q - eps * e, v)) / (2 * eps)
            dv = (model.forces(0, q, v + eps * e) - model.forces(0, q, v - eps * e)) / (2 * eps)
            worst = max(worst, np.max(np.abs(dq - model.dforces_dq(0, q, v)[:, i])),
                        np.max(np.abs(dv - model.dforces_dv(0, q, v)[:, i])))
            dh = [(model.gap(c, q + eps * e) - model.gap(c, q - eps * e)) / (2 * eps) for c in range(2)]
            worst = max(worst, max(abs(dh[c] - model.gap_jacobian(c, q)[i]) for c in range(2)))
    return worst


def verify():
    rng = np.random.default_rng(1)
    ok = True
    for cls in MODELS.values():
        model = cls()
        fd = check_physics(model, rng)
        states, steps = simulate(model)
        S, St = np.array(states), np.array(steps)
        nl = len(model.constraint_names)
        print("%s: %d steps; finite-difference check of the hand-coded derivatives: %.2g"
              % (model.name, len(states) - 1, fd))
        ok &= fd < 1e-6
        for label, (ms, mst) in (("one-step replay from Siconos' states", replay(model, states)),
                                 ("whole trajectory", mimic(model, len(states) - 1))):
            M, Mt = np.array(ms), np.array(mst)
            d = np.max(np.abs(S[:, 2:] - M[:, 2:]), axis=1)
            exact = int(np.argmax(d > 0)) if (d > 0).any() else len(d)
            same_t = np.array_equal(S[:, 1], M[:, 1])
            same_iters = np.array_equal(St[:, 1], Mt[:, 1])
            same_active = np.array_equal(St[:, 2:2 + nl], Mt[:, 2:2 + nl])
            dlam = np.max(np.abs(St[:, 2 + nl:] - Mt[:, 2 + nl:]))
            good = same_t and same_iters and same_active
            if label.startswith("one-step"):
                good &= d.max() < 1e-13
            ok &= good
            print("  %-38s max|state diff| %.3g, max|lambda diff| %.3g, bit-identical up to row %d,"
                  " same t %s, same Newton counts %s, same index sets %s: %s"
                  % (label, d.max(), dlam, exact, same_t, same_iters, same_active,
                     "OK" if good else "MISMATCH"))
    return ok


# ---------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--check", action="store_true",
                   help="regenerate into a temporary directory and compare with the committed fixtures")
    g.add_argument("--time", action="store_true", help="print wall-clock time per step")
    g.add_argument("--verify", action="store_true",
                   help="check the documented per-step algorithm (numpy) against Siconos")
    ap.add_argument("--out", default=FIXTURES_DIR, help="output directory (default: %(default)s)")
    ap.add_argument("--models", nargs="*", choices=sorted(MODELS), default=list(MODELS))
    args = ap.parse_args(argv)

    if args.time:
        print(siconos_version())
        print("wall-clock time of the Siconos loop (computeOneStep + nextStep), best of 5 runs:")
        with tempfile.TemporaryDirectory() as plugin_dir:
            for name in args.models:
                model = MODELS[name]()
                per, n, calls, total, final_py = time_loop(lambda: build(model))
                print("  %-16s Python callbacks: %6d steps  %.3f s  %7.2f us/step  (%.1f callbacks/step)"
                      % (name, n, total, per * 1e6, calls))
                if build_c(model, plugin_dir) is None:
                    continue
                per, n, _, total, final_c = time_loop(lambda: build_c(model, plugin_dir))
                same = "same final state" if final_c == final_py else \
                    "final state differs by %.3g" % max(abs(a - b) for a, b in zip(final_c, final_py))
                print("  %-16s C plugins:        %6d steps  %.3f s  %7.2f us/step  (%s)"
                      % (name, n, total, per * 1e6, same))
        return 0
    if args.verify:
        return 0 if verify() else 1
    if args.check:
        failures = []
        missing = False
        with tempfile.TemporaryDirectory() as tmp:
            for name in args.models:
                model = MODELS[name]()
                states, steps = simulate(model)
                write_files(model, states, steps, tmp)
                for fname in (name + ".csv", name + "_steps.csv"):
                    msg = compare_file(fname, os.path.join(args.out, fname), os.path.join(tmp, fname))
                    if msg:
                        failures.append(msg)
                        missing |= msg.startswith("missing")
        if failures:
            print("siconos_reference.py --check: the Siconos trajectories differ from the "
                  "committed fixtures in %s:" % args.out, file=sys.stderr)
            for msg in failures:
                print("  " + msg, file=sys.stderr)
            print("(regenerate with /usr/bin/python3 tests/siconos_reference.py if the change "
                  "is intended)", file=sys.stderr)
            return 2 if missing else 1
        print("siconos_reference.py --check: %s agree with Siconos (rtol %g)"
              % (", ".join(args.models), RTOL))
        return 0
    for name in args.models:
        model = MODELS[name]()
        states, steps = simulate(model)
        write_files(model, states, steps, args.out)
        print("wrote %s (%d states)" % (os.path.join(args.out, name + ".csv"), len(states)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
