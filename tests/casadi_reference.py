#!/usr/bin/env python3
"""CasADi reference values and CasADi-generated C code for moreau models.

For each model file (by default every ``models/*.yaml``) this script parses
the model with its own implementation of the model language
(``tests/reference/modellang.py``: recursive-descent parser, no ``eval``),
builds it in CasADi SX with symbols ``t``, ``q``, ``v``, ``u`` and the
parameters ``p``, and computes with CasADi's own differentiation:

* ``M = ∂²T/∂v²`` (``casadi.hessian``),
* ``C_ij = Σ_k ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i) v_k`` (Christoffel),
* ``G = ∂V/∂q``, ``F = C v + G − Q`` (``Q`` from ``applied``, 0 where missing),
* ``h`` and ``J = ∂h/∂q`` (row ``i`` is ``∇h_iᵀ``).

A kinematic tree (``bodies``, or ``urdf`` with ``locked`` and ``limits``:
the robots of ``tests/robots/``) goes the same way, by the Lagrangian route:
``tests/reference/tree.py`` reads the URDF with ``xml.etree``, poses each
body by the chain of its joints' transforms and writes its kinetic and
potential energies (``Σ ½ m |ċ|² + ½ ω_bᵀ I ω_b``, ``−Σ m gᵀ c``); moreau
builds the same quantities by recursions instead (composite rigid bodies,
Newton–Euler). For a tree, ``∂F/∂q`` and ``∂F/∂v`` are taken of Lagrange's
form of ``F`` (checked equal to the Christoffel form below), whose graph is
far smaller.

Internal checks at every sample point (the script fails if one does not hold):

* Lagrange's equations: ``F = (∂²T/∂v∂q) v − ∂T/∂q + G − Q`` to 1e-12
  relative to the largest term of either sum,
* ``Ṁ − 2C`` skew-symmetric and ``M`` symmetric (same tolerance),
* ``M`` independent of ``v`` (symbolically) and ``T`` homogeneous quadratic in
  ``v`` (``T(q, 0) = 0`` and ``∂T/∂v(q, 0) = 0``, numerically).
  A warning (not an error) is printed if ``M`` is not positive definite.

Outputs, per model file ``<stem>.yaml``:

1. ``tests/fixtures/casadi/<stem>.json``: the model's names, the CasADi
   version, the seed, operation counts and sample points with inputs and
   outputs (schema below).
2. ``benches/casadi/<cname>.c`` and ``.h``: CasADi's C code (CodeGenerator,
   ``with_header``) for the fused Function ``<cname>_eval(t, q, v, u, p) ->
   (M, C, G, F, h, J)`` built with ``cse=True``, all outputs dense and
   column-major (CasADi's layout; ``J`` is K×N). ``<cname>`` is the file stem
   with every character outside ``[A-Za-z0-9_]`` replaced by ``_``.

Sample points: ``numpy.random.default_rng(seed)`` with
``seed = zlib.crc32(stem.encode("utf-8"))``; for each point in order the
draws are ``t ~ U[0, 10]``, ``q ~ U[-1.5, 1.5]^N``, ``v ~ U[-2, 2]^N``,
``u ~ U[-1, 1]^NU``, then one factor ``~ U[0.5, 1.5]`` per parameter. The
first 4 points use the YAML defaults exactly (their factors are drawn and
discarded); the others use ``default × factor`` (zero defaults stay 0).
The points are independent of the machine (PCG64 and ``uniform`` are plain
integer and floating-point arithmetic); numpy is pinned all the same.

JSON schema (keys sorted; floats written with ``repr``, so they round-trip)::

    {
      "c_function": str,            # name of the generated C function
      "casadi_n_instructions": int, # Function.n_instructions() of the fused Function
      "casadi_op_count": int,       # ... minus OP_INPUT/OP_OUTPUT/OP_CONST/OP_PARAMETER
      "casadi_op_kinds": {str: int},# the counted instructions by CasADi opcode name
      "casadi_version": str,
      "constraints": [str],         # K names, in order
      "coordinates": [str],         # N names of q
      "file": str,                  # file name of the model, e.g. "arm3.yaml"
      "format": 1,
      "inputs": [str],              # NU names of u
      "k": int, "n": int,
      "model": str,                 # the model's `name`
      "parameter_defaults": [float],
      "parameters": [str],          # names in YAML order (the order of p)
      "restitution": [float],       # K coefficients
      "seed": int,
      "source_sha256": str,         # sha256 of the model file's bytes
      "velocities": [str],          # N names of v
      "points": [                   # one object per line
        {"t": float, "q": [N], "v": [N], "u": [NU], "p": [NP],
         "M": [[N] x N], "C": [[N] x N], "G": [N], "F": [N],
        "dFdq": [[N] x N], "dFdv": [[N] x N] (∂F/∂q, ∂F/∂v, rows = F_i),
         "h": [K], "J": [[N] x K]}  # matrices as lists of rows
      ]
    }

With ``--no-c`` only the JSON is written, without CSE and without the
four keys of CasADi's operation counts and C function (``c_function``,
``casadi_n_instructions``, ``casadi_op_count``, ``casadi_op_kinds``): the
robots' fixtures (``tests/fixtures/casadi/robots/``), whose Lagrangian
graphs are large (the 12-joint chain's fused Function has millions of
instructions) and whose op counts are not compared.

``--agree A B`` writes nothing: it evaluates models A and B (the same
coordinates, inputs and constraints; B's parameters taken by name from A's
point, B's defaults for the others) at A's sample points and requires every
output to agree to 1e-12 relative to the largest entry of A's (for ``C``,
``∂F/∂v`` and ``∂(M v)/∂q``, sums of ``(∂M/∂q) v`` whose terms cancel where
``M`` is stationary, at least ``max|M| max|v|``): the two-link tree of
``tests/robots/two_link.yaml`` against its energies written by hand.

Usage::

    python tests/casadi_reference.py            # regenerate all models
    python tests/casadi_reference.py --check    # compare with the committed files
    python tests/casadi_reference.py --model my_model.yaml --out DIR
    python tests/casadi_reference.py --model my_model.yaml --out DIR --check
    python tests/casadi_reference.py $(printf -- '--model %s ' tests/robots/*.yaml) \\
        --out tests/fixtures/casadi/robots --no-c [--check]
    python tests/casadi_reference.py --agree tests/robots/two_link.yaml \\
        tests/robots/two_link_energies.yaml

``--check`` regenerates into a temporary directory and compares with the
files in place: the JSON structure (keys, list lengths, strings, integers)
must be identical; floats must agree to within 4 ulps, or 1e-14 relative to
the larger of the two, or 1e-14 relative to the largest magnitude in the same
output array of the same point. The tolerance exists because the outputs go
through the C math library (sin, cos, ...), which may differ in the last bit
between machines; libm differences must not fail the check, while any real
change of a model or of this script changes values far beyond it. The C files
must be byte-identical (they do not depend on libm). Exit status: 0 when
everything matches, 1 when something differs (each difference is listed), 2
on a usage or model error.

Requirements: ``tests/requirements-casadi.txt`` (exact pins: another CasADi
version generates different C code and operation counts, and the JSON
records the version).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import re
import struct
import sys
import tempfile
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from reference.modellang import Model, ModelError, build_casadi, load_model  # noqa: E402

FORMAT = 1
PINNED_CASADI = "3.8.2"
N_POINTS = 32
N_DEFAULT_POINTS = 4
LAGRANGE_RTOL = 1e-12
CHECK_ULPS = 4
CHECK_RTOL = 1e-14
AGREE_RTOL = 1e-12

MODELS_DIR = REPO / "models"
FIXTURES_DIR = REPO / "tests" / "fixtures" / "casadi"
BENCH_DIR = REPO / "benches" / "casadi"


# --------------------------------------------------------------------------
# Building the model
# --------------------------------------------------------------------------


def c_name(stem: str) -> str:
    name = re.sub(r"[^A-Za-z0-9_]", "_", stem)
    if not name or name[0].isdigit():
        name = "m_" + name
    return name


def build(model: Model, cname: str, cse: bool = True):
    """Return (fused Function, check Function). ``cse``: the fused Function
    is built with CasADi's common-subexpression elimination (what its
    operation count and C code are taken from)."""
    import casadi as ca

    cm = build_casadi(model)
    n = model.n
    q, v = cm.q, cm.v

    M, _grad = ca.hessian(cm.T, v)
    M = ca.SX(M)
    if ca.depends_on(M, v):
        raise ModelError(
            f"{model.name}: T is not quadratic in the velocities "
            "(its Hessian in v depends on v)"
        )
    dM = [ca.jacobian(M[:, j], q) for j in range(n)]  # dM[j][i, k] = ∂M_ij/∂q_k
    C = ca.SX.zeros(n, n)
    for i in range(n):
        for j in range(n):
            acc = ca.SX(0)
            for k in range(n):
                gam = 0.5 * (dM[j][i, k] + dM[k][i, j] - dM[k][j, i])
                acc = acc + gam * v[k]
            C[i, j] = acc
    G = ca.gradient(cm.V, q)
    Cv = ca.mtimes(C, v)
    F = Cv + G - cm.Q
    h = cm.h
    J = ca.jacobian(h, q) if model.k else ca.SX.zeros(0, n)

    outs = [ca.densify(x) for x in (M, C, G, F, h, J)]
    fused = ca.Function(
        f"{cname}_eval",
        [cm.t, q, v, cm.u, cm.p],
        outs,
        ["t", "q", "v", "u", "p"],
        ["M", "C", "G", "F", "h", "J"],
        {"cse": cse},
    )

    # Independent check: Lagrange's equations, Ṁ - 2C skew, homogeneity of T.
    dTdv = ca.gradient(cm.T, v)
    dTdq = ca.gradient(cm.T, q)
    Tqv_v = ca.mtimes(ca.jacobian(dTdv, q), v)
    F_lag = Tqv_v - dTdq + G - cm.Q
    Mdot = ca.SX.zeros(n, n)
    for j in range(n):
        Mdot[:, j] = ca.mtimes(dM[j], v)
    zero_v = ca.SX.zeros(n, 1)
    T0 = ca.substitute(cm.T, v, zero_v)
    dTdv0 = ca.substitute(dTdv, v, zero_v)
    terms = ca.horzcat(Cv, G, cm.Q, Tqv_v, dTdq)
    # The force Jacobians ∂F/∂q and ∂F/∂v (what an implicit Moreau–Jean step
    # puts in its iteration matrix); not part of the fused op count. A
    # tree's are taken of Lagrange's form of F (equal to the Christoffel form
    # to 1e-12, checked below), whose graph is far smaller than that of the
    # n³ Christoffel symbols: the 12-joint chain's Christoffel form took
    # minutes and gigabytes.
    f_diff = F_lag if model.bodies else F
    dF = (ca.jacobian(f_diff, q), ca.jacobian(f_diff, v))
    # What a covariance-propagating estimator needs: ∂(M v)/∂q and ∂(J v)/∂q
    # at fixed v (CasADi's AD of the products).
    dMv = ca.jacobian(ca.mtimes(M, v), q)
    dJv = ca.jacobian(ca.mtimes(J, v), q) if model.k else ca.SX.zeros(0, n)
    check = ca.Function(
        f"{cname}_check",
        [cm.t, q, v, cm.u, cm.p],
        [
            ca.densify(x)
            for x in (F_lag, Mdot - 2 * C, T0, dTdv0, terms, Mdot, C, cm.T, *dF, dMv, dJv)
        ],
    )
    return fused, check


def op_counts(fn):
    import casadi as ca

    skip = {ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_CONST, ca.OP_PARAMETER}
    names = {}
    for attr in dir(ca):
        if attr.startswith("OP_"):
            val = getattr(ca, attr)
            if isinstance(val, int):
                names.setdefault(val, attr)
    kinds: dict[str, int] = {}
    count = 0
    for k in range(fn.n_instructions()):
        op = fn.instruction_id(k)
        if op in skip:
            continue
        count += 1
        nm = names.get(op, f"OP_{op}")
        kinds[nm] = kinds.get(nm, 0) + 1
    return fn.n_instructions(), count, dict(sorted(kinds.items()))


# --------------------------------------------------------------------------
# Sampling and evaluation
# --------------------------------------------------------------------------


def seed_for(stem: str) -> int:
    return zlib.crc32(stem.encode("utf-8"))


def sample_points(model: Model, seed: int, n_points: int):
    import numpy as np

    rng = np.random.default_rng(seed)
    defaults = [float(x) for x in model.parameters.values()]
    pts = []
    for idx in range(n_points):
        t = float(rng.uniform(0.0, 10.0))
        q = [float(x) for x in rng.uniform(-1.5, 1.5, model.n)]
        v = [float(x) for x in rng.uniform(-2.0, 2.0, model.n)]
        u = [float(x) for x in rng.uniform(-1.0, 1.0, len(model.inputs))]
        factors = [float(x) for x in rng.uniform(0.5, 1.5, len(defaults))]
        if idx < N_DEFAULT_POINTS:
            p = list(defaults)
        else:
            p = [d * f for d, f in zip(defaults, factors)]
        pts.append({"t": t, "q": q, "v": v, "u": u, "p": p})
    return pts


def _np(x):
    import numpy as np

    return np.array(x.full() if hasattr(x, "full") else x, dtype=float)


def _rows(a):
    return [[float(x) for x in row] for row in a]


def evaluate(model: Model, fused, check, pts, origin: str):
    import numpy as np

    failures = []
    for idx, pt in enumerate(pts):
        args = [pt["t"], pt["q"], pt["v"], pt["u"], pt["p"]]
        M, C, G, F, h, J = (_np(x) for x in fused(*args))
        F_lag, skew, T0, dTdv0, terms, Mdot, C2, T, dFdq, dFdv, dMv, dJv = (
            _np(x) for x in check(*args)
        )
        for name, arr in (("M", M), ("C", C), ("G", G), ("F", F), ("h", h), ("J", J)):
            if not np.all(np.isfinite(arr)):
                failures.append(
                    f"point {idx}: {name} is not finite: {arr.reshape(-1).tolist()}"
                )
        where = f"point {idx}"
        F = F.reshape(-1)
        F_lag = F_lag.reshape(-1)
        scale = np.max(np.abs(np.column_stack([terms, F, F_lag])), axis=1)
        err = np.abs(F - F_lag)
        bad = err > LAGRANGE_RTOL * scale
        if np.any(bad):
            failures.append(
                f"{where}: F = C v + G - Q differs from Lagrange's equations: "
                f"F = {F.tolist()}, Lagrange = {F_lag.tolist()}, |diff| = {err.tolist()}"
            )
        mscale = max(np.max(np.abs(Mdot)), 2 * np.max(np.abs(C2)), 0.0)
        if np.max(np.abs(skew + skew.T), initial=0.0) > LAGRANGE_RTOL * mscale:
            failures.append(f"{where}: Mdot - 2C is not skew-symmetric: {skew.tolist()}")
        if np.max(np.abs(M - M.T), initial=0.0) > LAGRANGE_RTOL * np.max(np.abs(M)):
            failures.append(f"{where}: M is not symmetric: {M.tolist()}")
        T, T0 = T.item(), T0.item()
        tscale = max(abs(T), float(np.max(np.abs(M))) * float(np.dot(pt["v"], pt["v"])))
        if abs(T0) > LAGRANGE_RTOL * tscale or np.max(
            np.abs(dTdv0), initial=0.0
        ) > LAGRANGE_RTOL * max(tscale, 1.0):
            failures.append(
                f"{where}: T is not a homogeneous quadratic form in v "
                f"(T(q, 0) = {T0!r}, dT/dv(q, 0) = {dTdv0.reshape(-1).tolist()})"
            )
        try:
            np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            print(f"warning: {where}: M is not positive definite", file=sys.stderr)
        pt.update(
            {
                "M": _rows(M),
                "C": _rows(C),
                "G": [float(x) for x in G.reshape(-1)],
                "F": [float(x) for x in F],
                "h": [float(x) for x in h.reshape(-1)],
                "J": _rows(J.reshape(model.k, model.n)),
                "dFdq": _rows(dFdq),
                "dFdv": _rows(dFdv),
                "dMvdq": _rows(dMv),
                "dJvdq": _rows(dJv.reshape(model.k, model.n)),
            }
        )
    if failures:
        more = f"\n  ... and {len(failures) - 8} more" if len(failures) > 8 else ""
        raise ModelError(
            f"{origin}: internal checks failed at {len(failures)} place(s):\n  "
            + "\n  ".join(failures[:8])
            + more
        )
    return pts


# --------------------------------------------------------------------------
# Output
# --------------------------------------------------------------------------


def dump_json(obj) -> str:
    """Sorted keys, two-space indent, one sample point per line."""
    lines = ["{"]
    items = sorted(obj.items())
    for i, (key, val) in enumerate(items):
        comma = "," if i + 1 < len(items) else ""
        if key == "points":
            lines.append(f"  {json.dumps(key)}: [")
            for j, pt in enumerate(val):
                pc = "," if j + 1 < len(val) else ""
                lines.append("    " + json.dumps(pt, sort_keys=True, allow_nan=False) + pc)
            lines.append("  ]" + comma)
        else:
            lines.append(
                f"  {json.dumps(key)}: {json.dumps(val, sort_keys=True, allow_nan=False)}{comma}"
            )
    lines.append("}")
    return "\n".join(lines) + "\n"


def generate(model_path: Path, json_dir: Path, c_dir: Path | None, n_points: int):
    """Generate the JSON and (unless ``c_dir`` is None) the C files for one
    model; return their paths."""
    import casadi as ca

    model_path = Path(model_path)
    stem = model_path.stem
    cname = c_name(stem)
    model = load_model(model_path)
    fused, check = build(model, cname, cse=c_dir is not None)
    seed = seed_for(stem)
    pts = sample_points(model, seed, n_points)
    pts = evaluate(model, fused, check, pts, model_path.name)

    data = {}
    if c_dir is not None:
        n_instr, n_ops, kinds = op_counts(fused)
        data = {
            "c_function": fused.name(),
            "casadi_n_instructions": n_instr,
            "casadi_op_count": n_ops,
            "casadi_op_kinds": kinds,
        }
    data |= {
        "casadi_version": ca.__version__,
        "constraints": [c.name for c in model.constraints],
        "coordinates": list(model.coordinates),
        "file": model_path.name,
        "format": FORMAT,
        "inputs": list(model.inputs),
        "k": model.k,
        "model": model.name,
        "n": model.n,
        "parameter_defaults": [float(x) for x in model.parameters.values()],
        "parameters": list(model.parameters),
        "points": pts,
        "restitution": [float(c.restitution) for c in model.constraints],
        "seed": seed,
        "source_sha256": hashlib.sha256(model_path.read_bytes()).hexdigest(),
        "velocities": list(model.velocities),
    }
    json_dir.mkdir(parents=True, exist_ok=True)
    json_path = json_dir / f"{stem}.json"
    json_path.write_text(dump_json(data), encoding="utf-8")
    if c_dir is None:
        return [json_path], data

    c_dir.mkdir(parents=True, exist_ok=True)
    cg = ca.CodeGenerator(f"{cname}.c", {"with_header": True})
    cg.add(fused)
    cg.generate(str(c_dir) + os.sep)
    return [json_path, c_dir / f"{cname}.c", c_dir / f"{cname}.h"], data


# --------------------------------------------------------------------------
# --check
# --------------------------------------------------------------------------


def _ordered(x: float) -> int:
    i = struct.unpack("<q", struct.pack("<d", x))[0]
    return i if i >= 0 else -(i & 0x7FFFFFFFFFFFFFFF)


def _float_close(a: float, b: float, scale: float) -> bool:
    if a == b:
        return True
    if math.isnan(a) or math.isnan(b) or math.isinf(a) or math.isinf(b):
        return False
    if abs(_ordered(a) - _ordered(b)) <= CHECK_ULPS:
        return True
    diff = abs(a - b)
    return diff <= CHECK_RTOL * max(abs(a), abs(b)) or diff <= CHECK_RTOL * scale


def _max_abs(x) -> float:
    if isinstance(x, list):
        return max((_max_abs(y) for y in x), default=0.0)
    if isinstance(x, float):
        return abs(x) if math.isfinite(x) else 0.0
    return 0.0


def compare_json(old, new, path: str, out: list, scale: float = 0.0):
    def kind(x):
        if isinstance(x, bool):
            return "bool"
        if isinstance(x, (int, float)):
            return "float" if isinstance(x, float) else "int"
        return type(x).__name__

    if kind(old) != kind(new):
        out.append(f"{path}: type {kind(old)} != {kind(new)}")
        return
    if isinstance(old, dict):
        for k in sorted(set(old) | set(new)):
            if k not in new:
                out.append(f"{path}.{k}: missing in the regenerated file")
            elif k not in old:
                out.append(f"{path}.{k}: missing in the committed file")
            else:
                sub_scale = scale
                if isinstance(old[k], list) and path.startswith("$.points["):
                    # one output array of one point: its own scale
                    sub_scale = max(_max_abs(old[k]), _max_abs(new[k]))
                compare_json(old[k], new[k], f"{path}.{k}", out, sub_scale)
    elif isinstance(old, list):
        if len(old) != len(new):
            out.append(f"{path}: length {len(old)} != {len(new)}")
            return
        for i, (a, b) in enumerate(zip(old, new)):
            compare_json(a, b, f"{path}[{i}]", out, scale)
    elif isinstance(old, float):
        if not _float_close(old, new, scale):
            out.append(f"{path}: {old!r} != {new!r}")
    elif old != new:
        out.append(f"{path}: {old!r} != {new!r}")


def check_files(pairs, expected_extra_dirs):
    """pairs: (committed path, regenerated path). Returns a list of differences."""
    diffs = []
    for committed, fresh in pairs:
        if not committed.exists():
            diffs.append(f"{committed}: missing (run without --check to create it)")
            continue
        if committed.suffix == ".json":
            try:
                old = json.loads(committed.read_text(encoding="utf-8"))
            except ValueError as exc:
                diffs.append(f"{committed}: not valid JSON: {exc}")
                continue
            new = json.loads(fresh.read_text(encoding="utf-8"))
            out: list = []
            compare_json(old, new, "$", out)
            if out:
                shown = out[:20]
                more = f"\n    ... and {len(out) - 20} more" if len(out) > 20 else ""
                diffs.append(
                    f"{committed}: {len(out)} difference(s):\n    " + "\n    ".join(shown) + more
                )
        else:
            if committed.read_bytes() != fresh.read_bytes():
                a = committed.read_text(encoding="utf-8", errors="replace").splitlines()
                b = fresh.read_text(encoding="utf-8", errors="replace").splitlines()
                first = next(
                    (i for i, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b))
                )
                diffs.append(
                    f"{committed}: differs from the regenerated file "
                    f"(first at line {first + 1}; {len(a)} vs {len(b)} lines)"
                )
    known = {c.resolve() for c, _ in pairs}
    for d, pattern in expected_extra_dirs:
        if d.is_dir():
            for f in sorted(d.glob(pattern)):
                if f.resolve() not in known:
                    diffs.append(f"{f}: not generated from any model (stale?)")
    return diffs


# --------------------------------------------------------------------------
# main
# --------------------------------------------------------------------------


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description="CasADi reference values and C code for moreau models.",
        epilog="See the module docstring for the JSON schema and the --check tolerance.",
    )
    ap.add_argument(
        "--model",
        action="append",
        metavar="FILE",
        help="model file (repeatable); default: every models/*.yaml",
    )
    ap.add_argument(
        "--out",
        metavar="DIR",
        help="write JSON, .c and .h into DIR "
        "(default: tests/fixtures/casadi and benches/casadi)",
    )
    ap.add_argument(
        "--check",
        action="store_true",
        help="regenerate into a temporary directory and compare with the files in place",
    )
    ap.add_argument(
        "--points", type=int, default=N_POINTS, help=f"sample points (default {N_POINTS})"
    )
    ap.add_argument(
        "--no-c",
        action="store_true",
        help="write the JSON only, without the operation counts (no C code, no CSE)",
    )
    ap.add_argument(
        "--agree",
        nargs=2,
        metavar=("A", "B"),
        help="check that two model files are the same model (every output to "
        f"{AGREE_RTOL:g} at A's sample points); writes nothing",
    )
    args = ap.parse_args(argv)

    try:
        import casadi
        import numpy  # noqa: F401
        import yaml  # noqa: F401
    except ImportError as exc:
        print(
            f"error: {exc}; install the pinned tools with "
            "`pip install -r tests/requirements-casadi.txt`",
            file=sys.stderr,
        )
        return 2
    if casadi.__version__ != PINNED_CASADI:
        print(
            f"warning: CasADi {casadi.__version__} is not the pinned {PINNED_CASADI} "
            "(tests/requirements-casadi.txt): the C code and operation counts will differ",
            file=sys.stderr,
        )

    if args.points < N_DEFAULT_POINTS:
        ap.error(f"--points must be at least {N_DEFAULT_POINTS}")
    if args.agree:
        try:
            return agree(*(Path(m) for m in args.agree), args.points)
        except (ModelError, OSError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
    if args.model:
        models = [Path(m) for m in args.model]
        for m in models:
            if not m.is_file():
                print(f"error: {m}: no such file", file=sys.stderr)
                return 2
    else:
        models = sorted(MODELS_DIR.glob("*.yaml"))
        if not models:
            print(f"error: no models in {MODELS_DIR}", file=sys.stderr)
            return 2
    stems = [m.stem for m in models]
    if len(set(stems)) != len(stems) or len({c_name(s) for s in stems}) != len(stems):
        print("error: two model files have the same (C) name", file=sys.stderr)
        return 2

    if args.out:
        json_dir = c_dir = Path(args.out)
    else:
        json_dir, c_dir = FIXTURES_DIR, BENCH_DIR
    if args.no_c:
        c_dir = None

    try:
        if not args.check:
            for m in models:
                paths, data = generate(m, json_dir, c_dir, args.points)
                counts = (
                    f"op_count={data['casadi_op_count']} "
                    f"n_instructions={data['casadi_n_instructions']} "
                    if "casadi_op_count" in data
                    else ""
                )
                print(
                    f"{m.name}: {data['model']} N={data['n']} K={data['k']} {counts}-> "
                    + ", ".join(_rel(p) for p in paths)
                )
            return 0

        with tempfile.TemporaryDirectory(prefix="casadi-ref-") as tmp:
            tmp_json = Path(tmp) / "json"
            tmp_c = None if c_dir is None else Path(tmp) / "c"
            pairs = []
            for m in models:
                paths, _ = generate(m, tmp_json, tmp_c, args.points)
                for p in paths:
                    dest = (json_dir if p.suffix == ".json" else c_dir) / p.name
                    pairs.append((dest, p))
            extra = []
            if not args.model and not args.out:
                extra = [(json_dir, "*.json")]
                if c_dir is not None:
                    extra += [(c_dir, "*.c"), (c_dir, "*.h")]
            diffs = check_files(pairs, extra)
    except ModelError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2

    if diffs:
        print(
            "casadi_reference --check: the committed files differ from the regenerated ones "
            "(regenerate with `python tests/casadi_reference.py` if the change is intended):",
            file=sys.stderr,
        )
        for d in diffs:
            print(f"  {d}", file=sys.stderr)
        return 1
    print(f"casadi_reference --check: {len(pairs)} files match ({len(models)} models)")
    return 0


def agree(path_a: Path, path_b: Path, n_points: int) -> int:
    """Model B against model A at A's sample points: the same coordinates in
    the same order, B's parameters by name from A's point (B's default for a
    parameter A does not have), the same constraints; every output M, C, G,
    F, h, J, ∂F/∂q, ∂F/∂v, ∂(M v)/∂q, ∂(J v)/∂q to AGREE_RTOL relative to
    the largest entry of A's (for C, ∂F/∂v and ∂(M v)/∂q, sums of (∂M/∂q) v
    whose terms cancel where M is stationary, at least max|M| max|v|). 0
    when they agree, 1 otherwise."""
    import numpy as np

    ma, mb = load_model(path_a), load_model(path_b)
    if (ma.coordinates, ma.velocities) != (mb.coordinates, mb.velocities):
        raise ModelError(f"{path_a} and {path_b} have different coordinates")
    if [c.name for c in ma.constraints] != [c.name for c in mb.constraints]:
        raise ModelError(f"{path_a} and {path_b} have different constraints")
    if ma.inputs != mb.inputs:
        raise ModelError(f"{path_a} and {path_b} have different inputs")
    fa, ca_ = build(ma, "a", cse=False)
    fb, cb = build(mb, "b", cse=False)
    pts = evaluate(ma, fa, ca_, sample_points(ma, seed_for(path_a.stem), n_points), path_a.name)
    names_a = list(ma.parameters)
    bad, worst = [], {}
    for idx, pt in enumerate(pts):
        pb = [
            pt["p"][names_a.index(nm)] if nm in names_a else default
            for nm, default in mb.parameters.items()
        ]
        other = {k: pt[k] for k in ("t", "q", "v", "u")}
        other["p"] = pb
        (other,) = evaluate(mb, fb, cb, [other], path_b.name)
        for key in ("M", "C", "G", "F", "h", "J", "dFdq", "dFdv", "dMvdq", "dJvdq"):
            a, b = np.array(pt[key], dtype=float), np.array(other[key], dtype=float)
            scale = float(np.max(np.abs(a), initial=0.0))
            if key in ("C", "dFdv", "dMvdq"):
                # sums of (∂M/∂q) v, whose terms cancel where M is stationary
                scale = max(scale, float(np.max(np.abs(pt["M"]))) * float(np.max(np.abs(pt["v"]))))
            err = float(np.max(np.abs(a - b), initial=0.0)) / scale if scale > 0 else 0.0
            worst[key] = max(worst.get(key, 0.0), err)
            if not err <= AGREE_RTOL:
                bad.append(f"point {idx}: {key} differs by {err:.3e} (relative)")
    print(
        f"casadi_reference --agree {path_a.name} {path_b.name}: largest relative difference "
        + ", ".join(f"{k} {v:.1e}" for k, v in worst.items())
    )
    if bad:
        print("  " + "\n  ".join(bad[:20]), file=sys.stderr)
        return 1
    return 0


def _rel(p: Path) -> str:
    try:
        return str(p.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(p)


if __name__ == "__main__":
    sys.exit(main())
