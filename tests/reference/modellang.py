"""The moreau model language in Python: a reference front end.

This is an independent implementation of the language that
``models/README.md`` describes (the YAML schema and the expression
grammar), written for the CasADi reference tool
``tests/casadi_reference.py``. It does not share code with the Rust front
ends, on purpose: the point is to check them.

Expressions are parsed by a hand-written recursive-descent parser (no
``eval``) of the grammar stated once, in ``model-macro/src/expr/mod.rs``
(``models/README.md`` points there too).

The YAML is read with PyYAML's ``BaseLoader`` (every scalar a string), so
that YAML 1.1 quirks (``no``/``on``/``off`` read as booleans, ``1e-3`` read
as a string) cannot differ from a YAML 1.2 reader: expressions keep their
exact text and numbers are parsed here. Duplicate mapping keys are errors.

A kinematic tree (`bodies`, or a URDF named by `urdf` with `locked` and
`limits`, and `gravity`) is read by ``tests/reference/tree.py`` (the URDF
with :mod:`xml.etree`), and :func:`build_casadi` adds its kinetic and
potential energies, built from the bodies' poses, to those written; in
expressions, `position_x(body, x, y, z)` (`_y`, `_z`; `position_x(body)`
for the frame's origin) and `direction_x(body, x, y, z)` are the world
coordinates of a point and a direction of a body.

Only the standard library and PyYAML are needed to load a model;
:func:`build_casadi` imports CasADi when called. The language's rules are
checked by the Rust front end only (see ``_validate``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from .tree import JOINT_TYPES, Body, UrdfError, build_tree, read_urdf

__all__ = [
    "ModelError",
    "Model",
    "Constraint",
    "parse_expr",
    "free_names",
    "load_model",
    "load_model_text",
    "build_casadi",
    "FUNCTIONS",
]

# Function name -> number of arguments.
FUNCTIONS = {
    "sqrt": 1,
    "exp": 1,
    "ln": 1,
    "sin": 1,
    "cos": 1,
    "tan": 1,
    "atan2": 2,
    "sinh": 1,
    "cosh": 1,
    "tanh": 1,
}
# The calls of a body's frame: a point (`position_x(body)` or
# `position_x(body, x, y, z)`) or a direction (`direction_x(body, x, y, z)`).
FRAME_FUNCTIONS = {
    f"{kind}_{axis}": (kind, i)
    for kind in ("position", "direction")
    for i, axis in enumerate("xyz")
}
BUILTIN_NAMES = ("t", "pi")
RESERVED = set(FUNCTIONS) | set(FRAME_FUNCTIONS) | set(BUILTIN_NAMES)

IDENT_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
# A number in an expression: 2, 0.5, 1e-3, 2.5E+4, 1. (no sign, no leading dot).
_NUMBER_TOKEN_RE = re.compile(r"[0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?")
# A number as a YAML value (parameters, restitution, initial): may be signed.
_NUMBER_VALUE_RE = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?\Z")


class ModelError(ValueError):
    """A model file that cannot be read, parsed or validated."""


# --------------------------------------------------------------------------
# Expressions
#
# AST nodes are tuples:
#   ("num", float)            a number literal
#   ("name", str)             a name (variable, parameter, definition, t, pi)
#   ("neg", a)                unary minus
#   ("add"|"sub"|"mul"|"div"|"pow", a, b)
#   ("call", fname, (args...))
#   ("frame", "position"|"direction", axis 0..2, body, (x, y, z))
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class _Tok:
    kind: str  # "num", "name", "op", "end"
    text: str
    pos: int


def _tokenize(text: str) -> list[_Tok]:
    toks = []
    i = 0
    n = len(text)
    while i < n:
        c = text[i]
        if c.isspace():
            i += 1
            continue
        if c.isdigit():
            m = _NUMBER_TOKEN_RE.match(text, i)
            end = m.end()
            if end < n and (text[end].isalnum() or text[end] in "_."):
                raise ModelError(f"malformed number {text[i:end + 1]!r} at column {i + 1}")
            toks.append(_Tok("num", m.group(0), i))
            i = end
            continue
        if c.isalpha() or c == "_":
            m = re.compile(r"[A-Za-z_][A-Za-z0-9_]*").match(text, i)
            toks.append(_Tok("name", m.group(0), i))
            i = m.end()
            continue
        if c in "+-*/^(),":
            toks.append(_Tok("op", c, i))
            i += 1
            continue
        raise ModelError(f"unexpected character {c!r} at column {i + 1}")
    toks.append(_Tok("end", "", n))
    return toks


class _Parser:
    def __init__(self, text: str):
        self.text = text
        self.toks = _tokenize(text)
        self.i = 0

    def peek(self) -> _Tok:
        return self.toks[self.i]

    def next(self) -> _Tok:
        tok = self.toks[self.i]
        self.i += 1
        return tok

    def error(self, tok: _Tok, what: str) -> ModelError:
        found = "end of expression" if tok.kind == "end" else repr(tok.text)
        return ModelError(f"{what}, found {found} at column {tok.pos + 1}")

    def expect(self, op: str) -> None:
        tok = self.next()
        if tok.kind != "op" or tok.text != op:
            raise self.error(tok, f"expected {op!r}")

    def is_op(self, *ops: str) -> bool:
        tok = self.peek()
        return tok.kind == "op" and tok.text in ops

    def parse(self):
        if self.peek().kind == "end":
            raise ModelError("empty expression")
        node = self.expr()
        tok = self.peek()
        if tok.kind != "end":
            raise self.error(tok, "expected an operator or the end of the expression")
        return node

    def expr(self):
        node = self.term()
        while self.is_op("+", "-"):
            op = self.next().text
            rhs = self.term()
            node = ("add" if op == "+" else "sub", node, rhs)
        return node

    def term(self):
        node = self.unary()
        while self.is_op("*", "/"):
            op = self.next().text
            rhs = self.unary()
            node = ("mul" if op == "*" else "div", node, rhs)
        return node

    def unary(self):
        if self.is_op("-"):
            self.next()
            return ("neg", self.unary())
        return self.power()

    def power(self):
        base = self.atom()
        if self.is_op("^"):
            self.next()
            # The exponent is a `unary`, so a^b^c = a^(b^c) and 2^-1 is allowed.
            return ("pow", base, self.unary())
        return base

    def atom(self):
        tok = self.next()
        if tok.kind == "num":
            return ("num", float(tok.text))
        if tok.kind == "name":
            if self.is_op("("):
                self.next()
                fname = tok.text
                if fname in FRAME_FUNCTIONS:
                    return self.frame(fname, tok)
                if fname not in FUNCTIONS:
                    raise ModelError(f"unknown function {fname!r} at column {tok.pos + 1}")
                args = [self.expr()]
                while self.is_op(","):
                    self.next()
                    args.append(self.expr())
                self.expect(")")
                if len(args) != FUNCTIONS[fname]:
                    raise ModelError(
                        f"{fname} takes {FUNCTIONS[fname]} argument(s), "
                        f"got {len(args)} at column {tok.pos + 1}"
                    )
                return ("call", fname, tuple(args))
            if tok.text in FUNCTIONS:
                raise ModelError(
                    f"function {tok.text!r} used without arguments at column {tok.pos + 1}"
                )
            return ("name", tok.text)
        if tok.kind == "op" and tok.text == "(":
            node = self.expr()
            self.expect(")")
            return node
        raise self.error(tok, "expected a number, a name or '('")

    def frame(self, fname: str, tok: _Tok):
        kind, axis = FRAME_FUNCTIONS[fname]
        args = [self.expr()]
        while self.is_op(","):
            self.next()
            args.append(self.expr())
        self.expect(")")
        if args[0][0] != "name":
            raise ModelError(
                f"the first argument of {fname} is a body, at column {tok.pos + 1}"
            )
        if len(args) == 4:
            point = tuple(args[1:])
        elif len(args) == 1 and kind == "position":
            point = (("num", 0.0),) * 3
        else:
            raise ModelError(
                f"{fname} takes a body and three coordinates, got {len(args)} "
                f"argument(s) at column {tok.pos + 1}"
            )
        return ("frame", kind, axis, args[0][1], point)


def parse_expr(text: str):
    """Parse one expression of the model language into an AST (tuples)."""
    return _Parser(text).parse()


def free_names(node) -> set[str]:
    """The names an AST refers to directly (not through definitions)."""
    out: set[str] = set()
    stack = [node]
    while stack:
        nd = stack.pop()
        kind = nd[0]
        if kind == "name":
            out.add(nd[1])
        elif kind == "num":
            pass
        elif kind == "neg":
            stack.append(nd[1])
        elif kind == "call":
            stack.extend(nd[2])
        elif kind == "frame":
            stack.extend(nd[4])  # the body is not a number
        else:
            stack.append(nd[1])
            stack.append(nd[2])
    return out


# --------------------------------------------------------------------------
# YAML
# --------------------------------------------------------------------------


def _yaml_loader():
    import yaml

    class Loader(yaml.BaseLoader):
        pass

    def construct_mapping(loader, node, deep=False):
        if not isinstance(node, yaml.MappingNode):
            raise yaml.constructor.ConstructorError(
                None, None, f"expected a mapping, found {node.id}", node.start_mark
            )
        out = {}
        for key_node, value_node in node.value:
            key = loader.construct_object(key_node, deep=True)
            if not isinstance(key, str):
                raise yaml.constructor.ConstructorError(
                    None, None, "mapping keys must be plain names", key_node.start_mark
                )
            if key in out:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r}", key_node.start_mark
                )
            out[key] = loader.construct_object(value_node, deep=True)
        return out

    Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, construct_mapping)
    return Loader


@dataclass
class Constraint:
    name: str
    h: str
    restitution: float


@dataclass
class Model:
    """A validated model. Expression fields keep their source text; ``ast``
    maps each expression's role to its parsed tree."""

    name: str
    doc: str
    coordinates: list[str]
    velocities: list[str]
    parameters: dict[str, float]  # ordered, name -> default
    inputs: list[str]
    definitions: dict[str, str]  # ordered, name -> expression text
    kinetic: str
    potential: str
    applied: dict[str, str]  # coordinate -> expression text (Q)
    constraints: list[Constraint]
    initial: dict[str, float]
    ast: dict = field(default_factory=dict)
    # A kinematic tree (`bodies`, `urdf`): its bodies (tests/reference/tree.py)
    # and the gravity vector's ASTs (None: the default [0, 0, -9.81]).
    bodies: list = field(default_factory=list)
    gravity: list | None = None

    @property
    def n(self) -> int:
        return len(self.coordinates)

    @property
    def k(self) -> int:
        return len(self.constraints)


_KEYS = {
    "name",
    "doc",
    "coordinates",
    "parameters",
    "inputs",
    "definitions",
    "kinetic",
    "potential",
    "applied",
    "constraints",
    "restitution",
    "initial",
    "urdf",
    "locked",
    "limits",
    "bodies",
    "gravity",
}


def _number(value, where: str) -> float:
    if not isinstance(value, str) or not _NUMBER_VALUE_RE.match(value.strip()):
        raise ModelError(f"{where}: expected a number, found {value!r}")
    return float(value.strip())


def _ident(value, where: str) -> str:
    if not isinstance(value, str) or not IDENT_RE.match(value):
        raise ModelError(f"{where}: {value!r} is not a valid name")
    return value


def _expr_text(value, where: str) -> str:
    if not isinstance(value, str):
        raise ModelError(f"{where}: expected an expression, found {type(value).__name__}")
    return value


def _crate_dir(path: Path) -> Path:
    """The nearest directory above ``path`` with a ``Cargo.toml``: what a
    model's ``urdf`` path is relative to."""
    for d in path.resolve().parents:
        if (d / "Cargo.toml").is_file():
            return d
    return Path.cwd()


def load_model(path) -> Model:
    """Read and validate a model file (a `urdf` it names is found relative
    to the nearest directory above it with a ``Cargo.toml``, the crate's)."""
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    return load_model_text(text, str(path), _crate_dir(Path(path)))


def load_model_text(text: str, origin: str = "<model>", crate_dir=None) -> Model:
    """Parse and validate the YAML text of a model; ``crate_dir`` (default:
    the working directory) is where a `urdf` path starts."""
    import yaml

    try:
        doc = yaml.load(text, Loader=_yaml_loader())
    except yaml.YAMLError as exc:
        raise ModelError(f"{origin}: invalid YAML: {exc}") from None
    try:
        return _validate(doc, Path(crate_dir) if crate_dir is not None else Path.cwd())
    except (ModelError, UrdfError) as exc:
        raise ModelError(f"{origin}: {exc}") from None


def _validate(doc, crate_dir: Path) -> Model:
    """Reads the model's structure. The rules of the language (unique and
    reserved names, declared names, restitution in [0, 1], what T, V and h
    may depend on, ...) are the Rust front end's alone (model-macro's
    `check.rs` and `resolve.rs`): every model this tool reads has compiled
    through `model!` first (the shipped files, or `ModelInfo::source` of a
    compiled type), so a second copy of the rules here could only drift.
    What stays is what reading needs: the shapes of the YAML values."""
    if not isinstance(doc, dict):
        raise ModelError("the model must be a YAML mapping")
    unknown = sorted(set(doc) - _KEYS)
    if unknown:
        raise ModelError(f"unknown key(s): {', '.join(unknown)}")
    has_tree = "bodies" in doc or "urdf" in doc
    for key in ("name",) if has_tree else ("name", "coordinates", "kinetic"):
        if key not in doc:
            raise ModelError(f"missing required key {key!r}")

    name = _ident(doc["name"], "name")
    mdoc = doc.get("doc", "")
    if not isinstance(mdoc, str):
        raise ModelError("doc: expected text")

    kinds: dict[str, str] = {}  # name -> what it is, for uniqueness

    def declare(nm: str, what: str) -> None:
        kinds[nm] = what

    coords_raw = doc.get("coordinates", [])
    if coords_raw in ("", None) and has_tree:
        coords_raw = []
    if not isinstance(coords_raw, list) or not (coords_raw or has_tree):
        raise ModelError("coordinates: expected a non-empty list of `position: velocity`")
    coordinates, velocities = [], []
    for i, entry in enumerate(coords_raw):
        if not isinstance(entry, dict) or len(entry) != 1:
            raise ModelError(f"coordinates[{i}]: expected one `position: velocity` entry")
        ((qn, vn),) = entry.items()
        qn = _ident(qn, f"coordinates[{i}]")
        vn = _ident(vn, f"coordinates[{i}]")
        declare(qn, "coordinate")
        declare(vn, "velocity")
        coordinates.append(qn)
        velocities.append(vn)

    params_raw = doc.get("parameters", {})
    if params_raw in ("", None):
        params_raw = {}
    if not isinstance(params_raw, dict):
        raise ModelError("parameters: expected a mapping `name: default`")
    parameters = {}
    for pn, pv in params_raw.items():
        pn = _ident(pn, "parameters")
        declare(pn, "parameter")
        parameters[pn] = _number(pv, f"parameters.{pn}")

    inputs_raw = doc.get("inputs", [])
    if inputs_raw in ("", None):
        inputs_raw = []
    if not isinstance(inputs_raw, list):
        raise ModelError("inputs: expected a list of names")
    inputs = []
    for un in inputs_raw:
        un = _ident(un, "inputs")
        declare(un, "input")
        inputs.append(un)

    ast: dict = {}
    defs_raw = doc.get("definitions", {})
    if defs_raw in ("", None):
        defs_raw = {}
    if not isinstance(defs_raw, dict):
        raise ModelError("definitions: expected a mapping `name: expression`")
    definitions = {}
    for dn, dv in defs_raw.items():
        dn = _ident(dn, "definitions")
        text = _expr_text(dv, f"definitions.{dn}")
        node = _parse_in(text, f"definitions.{dn}")
        declare(dn, "definition")
        definitions[dn] = text
        ast[("definition", dn)] = node

    def expr(role_key, text, where):
        node = _parse_in(text, where)
        ast[role_key] = node
        return text

    # The tree's joints: coordinates after the written ones, the bodies'
    # (in the order written) before the URDF's.
    bodies = _bodies(doc.get("bodies", []), coordinates, velocities)
    limits: dict[str, tuple[float, float]] = {}
    if "urdf" in doc:
        urdf = read_urdf(
            crate_dir / _expr_text(doc["urdf"], "urdf"),
            _names(doc.get("locked", []), "locked"),
            len(coordinates),
        )
        bodies.extend(urdf.bodies)
        for qn, vn in urdf.coordinates:
            coordinates.append(qn)
            velocities.append(vn)
        limits = urdf.limits
    elif "locked" in doc or "limits" in doc:
        raise ModelError("`locked` and `limits` name joints of a URDF, but there is no `urdf`")
    gravity = None
    if "gravity" in doc:
        gravity = _triple(doc["gravity"], "gravity")

    kinetic = expr(("kinetic",), _expr_text(doc.get("kinetic", "0"), "kinetic"), "kinetic")
    potential = expr(
        ("potential",), _expr_text(doc.get("potential", "0"), "potential"), "potential"
    )

    applied_raw = doc.get("applied", {})
    if applied_raw in ("", None):
        applied_raw = {}
    if not isinstance(applied_raw, dict):
        raise ModelError("applied: expected a mapping `coordinate: expression`")
    applied = {}
    for qn, fv in applied_raw.items():
        applied[qn] = expr(("force", qn), _expr_text(fv, f"applied.{qn}"), f"applied.{qn}")

    default_e = None
    if "restitution" in doc:
        default_e = _number(doc["restitution"], "restitution")

    cons_raw = doc.get("constraints", [])
    if cons_raw in ("", None):
        cons_raw = []
    if not isinstance(cons_raw, list):
        raise ModelError("constraints: expected a list")
    constraints = []
    for i, entry in enumerate(cons_raw):
        if not isinstance(entry, dict):
            raise ModelError(f"constraints[{i}]: expected a mapping with name and h")
        extra = sorted(set(entry) - {"name", "h", "restitution"})
        if extra:
            raise ModelError(f"constraints[{i}]: unknown key(s): {', '.join(extra)}")
        if "name" not in entry or "h" not in entry:
            raise ModelError(f"constraints[{i}]: needs `name` and `h`")
        cn = _ident(entry["name"], f"constraints[{i}].name")
        h = expr(("constraint", cn), _expr_text(entry["h"], f"constraints.{cn}.h"),
                 f"constraints.{cn}.h")
        if "restitution" in entry:
            e = _number(entry["restitution"], f"constraints.{cn}.restitution")
        elif default_e is not None:
            e = default_e
        else:
            raise ModelError(
                f"constraints.{cn}: no restitution (give it one, or a top-level `restitution`)"
            )
        constraints.append(Constraint(cn, h, e))
    for joint in _names(doc.get("limits", []), "limits"):
        if joint not in limits:
            raise ModelError(f"limits: `{joint}` is not a moving joint with a <limit lower upper>")
        if default_e is None:
            raise ModelError("limits: the limits' constraints take the top-level `restitution`")
        lower, upper = limits[joint]
        bounds = (("lower", f"{joint} - ({lower!r})"), ("upper", f"({upper!r}) - {joint}"))
        for suffix, text in bounds:
            cn = f"{joint}_{suffix}"
            constraints.append(Constraint(cn, expr(("constraint", cn), text, cn), default_e))

    init_raw = doc.get("initial", {})
    if init_raw in ("", None):
        init_raw = {}
    if not isinstance(init_raw, dict):
        raise ModelError("initial: expected a mapping")
    initial = {}
    for nm, val in init_raw.items():
        initial[nm] = _number(val, f"initial.{nm}")

    model = Model(
        name=name,
        doc=mdoc,
        coordinates=coordinates,
        velocities=velocities,
        parameters=parameters,
        inputs=inputs,
        definitions=definitions,
        kinetic=kinetic,
        potential=potential,
        applied=applied,
        constraints=constraints,
        initial=initial,
        ast=ast,
        bodies=bodies,
        gravity=gravity,
    )

    return model


def _names(value, where: str) -> list[str]:
    if value in ("", None):
        return []
    if not isinstance(value, list):
        raise ModelError(f"{where}: expected a list of names")
    return [_ident(x, where) for x in value]


def _triple(value, where: str) -> list:
    if not isinstance(value, list) or len(value) != 3:
        raise ModelError(f"{where}: expected three expressions [x, y, z]")
    return [_parse_in(_expr_text(x, where), where) for x in value]


_BODY_KEYS = {"name", "parent", "joint", "mass", "com", "inertia"}
_JOINT_KEYS = {"type", "name", "velocity", "axis", "xyz", "rpy"}


def _bodies(raw, coordinates: list[str], velocities: list[str]) -> list:
    """`bodies:` as :class:`tree.Body`; each moving joint appends its
    coordinate (and velocity, `d<name>` by default)."""
    if raw in ("", None):
        return []
    if not isinstance(raw, list):
        raise ModelError("bodies: expected a list of bodies")
    out = []
    zero = ("num", 0.0)
    for i, b in enumerate(raw):
        where = f"bodies[{i}]"
        required = {"name", "joint", "mass"}
        if not isinstance(b, dict) or set(b) - _BODY_KEYS or not required <= set(b):
            raise ModelError(
                f"{where}: a body has name, joint, mass and optionally parent, com, inertia"
            )
        j = b["joint"]
        if not isinstance(j, dict) or set(j) - _JOINT_KEYS or j.get("type") not in JOINT_TYPES:
            raise ModelError(f"{where}.joint: a joint has a type ({', '.join(JOINT_TYPES)}) "
                             f"and name, velocity, axis, xyz, rpy")
        kind = j["type"]
        coordinate = None
        axis = (0.0, 0.0, 1.0)
        if kind != "fixed":
            qn = _ident(j.get("name"), f"{where}.joint.name")
            vn = _ident(j.get("velocity", "d" + qn), f"{where}.joint.velocity")
            coordinate = len(coordinates)
            coordinates.append(qn)
            velocities.append(vn)
            ax = j.get("axis")
            if not isinstance(ax, list) or len(ax) != 3:
                raise ModelError(f"{where}.joint.axis: expected three numbers")
            axis = tuple(_number(x, f"{where}.joint.axis") for x in ax)
            if not any(axis):
                raise ModelError(f"{where}.joint.axis: zero axis")
        parent = b.get("parent", "world")
        inertia = b.get("inertia")
        if inertia is not None and (not isinstance(inertia, list) or len(inertia) != 6):
            raise ModelError(f"{where}.inertia: expected six expressions")
        out.append(
            Body(
                name=_ident(b["name"], f"{where}.name"),
                parent=None if parent == "world" else _ident(parent, f"{where}.parent"),
                kind=kind,
                coordinate=coordinate,
                axis=axis,
                xyz=_triple(j["xyz"], f"{where}.joint.xyz") if "xyz" in j else [zero] * 3,
                rpy=_triple(j["rpy"], f"{where}.joint.rpy") if "rpy" in j else [zero] * 3,
                mass=_parse_in(_expr_text(b["mass"], f"{where}.mass"), f"{where}.mass"),
                com=_triple(b["com"], f"{where}.com") if "com" in b else [zero] * 3,
                inertia=[_parse_in(_expr_text(x, f"{where}.inertia"), f"{where}.inertia")
                         for x in inertia] if inertia is not None else [zero] * 6,
            )
        )
    return out


def _parse_in(text: str, where: str):
    try:
        return parse_expr(text)
    except ModelError as exc:
        raise ModelError(f"{where}: {exc} in {text.strip()!r}") from None


# --------------------------------------------------------------------------
# CasADi
# --------------------------------------------------------------------------


def _to_sx(node, env, ca):
    kind = node[0]
    if kind == "num":
        return ca.SX(node[1])
    if kind == "name":
        return env[node[1]]
    if kind == "neg":
        return -_to_sx(node[1], env, ca)
    if kind == "frame":
        _, fkind, axis, body, point = node
        r, p = env["@frames"][body]
        local = ca.vertcat(*[_to_sx(x, env, ca) for x in point])
        world = ca.mtimes(r, local)
        return (world + p if fkind == "position" else world)[axis]
    if kind == "call":
        args = [_to_sx(a, env, ca) for a in node[2]]
        fname = node[1]
        if fname == "atan2":
            return ca.atan2(args[0], args[1])
        fn = {
            "sqrt": ca.sqrt,
            "exp": ca.exp,
            "ln": ca.log,
            "sin": ca.sin,
            "cos": ca.cos,
            "tan": ca.tan,
            "sinh": ca.sinh,
            "cosh": ca.cosh,
            "tanh": ca.tanh,
        }[fname]
        return fn(args[0])
    a = _to_sx(node[1], env, ca)
    b = _to_sx(node[2], env, ca)
    if kind == "add":
        return a + b
    if kind == "sub":
        return a - b
    if kind == "mul":
        return a * b
    if kind == "div":
        return a / b
    if kind == "pow":
        return a**b
    raise AssertionError(kind)


@dataclass
class CasadiModel:
    """The model's quantities as CasADi SX expressions of the symbols
    ``t`` (scalar), ``q``, ``v`` (N), ``u`` (NU) and ``p`` (parameters)."""

    t: object
    q: object
    v: object
    u: object
    p: object
    T: object
    V: object
    Q: object  # N x 1
    h: object  # K x 1


def build_casadi(model: Model) -> CasadiModel:
    """Build T, V, Q and h as CasADi SX expressions (a tree's energies
    included: :func:`tree.build_tree`)."""
    import casadi as ca

    t = ca.SX.sym("t")
    q = ca.SX.sym("q", model.n)
    v = ca.SX.sym("v", model.n)
    u = ca.SX.sym("u", len(model.inputs))
    p = ca.SX.sym("p", len(model.parameters))
    env = {"t": t, "pi": ca.SX(ca.pi)}
    for i, nm in enumerate(model.coordinates):
        env[nm] = q[i]
    for i, nm in enumerate(model.velocities):
        env[nm] = v[i]
    for i, nm in enumerate(model.inputs):
        env[nm] = u[i]
    for i, nm in enumerate(model.parameters):
        env[nm] = p[i]
    T_tree = V_tree = ca.SX(0)
    if model.bodies:
        grav = model.gravity or [("num", 0.0), ("num", 0.0), ("num", -9.81)]
        try:
            tree = build_tree(
                model.bodies,
                ca.vertcat(*[_to_sx(x, env, ca) for x in grav]),
                q,
                v,
                lambda node: _to_sx(node, env, ca),
                ca,
            )
        except UrdfError as exc:
            raise ModelError(f"{model.name}: {exc}") from None
        env["@frames"] = tree.frames
        T_tree, V_tree = tree.T, tree.V
    for nm in model.definitions:
        env[nm] = _to_sx(model.ast[("definition", nm)], env, ca)

    T = _to_sx(model.ast[("kinetic",)], env, ca) + T_tree
    V = _to_sx(model.ast[("potential",)], env, ca) + V_tree
    Q = ca.SX.zeros(model.n, 1)
    for i, nm in enumerate(model.coordinates):
        if nm in model.applied:
            Q[i] = _to_sx(model.ast[("force", nm)], env, ca)
    h = ca.SX.zeros(model.k, 1)
    for i, c in enumerate(model.constraints):
        h[i] = _to_sx(model.ast[("constraint", c.name)], env, ca)
    return CasadiModel(t=t, q=q, v=v, u=u, p=p, T=T, V=V, Q=Q, h=h)
