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

Only the standard library and PyYAML are needed to load a model;
:func:`build_casadi` imports CasADi when called. The language's rules are
checked by the Rust front end only (see ``_validate``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

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
BUILTIN_NAMES = ("t", "pi")
RESERVED = set(FUNCTIONS) | set(BUILTIN_NAMES)

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


def load_model(path) -> Model:
    """Read and validate a model file."""
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    return load_model_text(text, str(path))


def load_model_text(text: str, origin: str = "<model>") -> Model:
    """Parse and validate the YAML text of a model."""
    import yaml

    try:
        doc = yaml.load(text, Loader=_yaml_loader())
    except yaml.YAMLError as exc:
        raise ModelError(f"{origin}: invalid YAML: {exc}") from None
    try:
        return _validate(doc)
    except ModelError as exc:
        raise ModelError(f"{origin}: {exc}") from None


def _validate(doc) -> Model:
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
    for key in ("name", "coordinates", "kinetic"):
        if key not in doc:
            raise ModelError(f"missing required key {key!r}")

    name = _ident(doc["name"], "name")
    mdoc = doc.get("doc", "")
    if not isinstance(mdoc, str):
        raise ModelError("doc: expected text")

    kinds: dict[str, str] = {}  # name -> what it is, for uniqueness

    def declare(nm: str, what: str) -> None:
        kinds[nm] = what

    coords_raw = doc["coordinates"]
    if not isinstance(coords_raw, list) or not coords_raw:
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

    kinetic = expr(("kinetic",), _expr_text(doc["kinetic"], "kinetic"), "kinetic")
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
    )

    return model


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
    """Build T, V, Q and h as CasADi SX expressions."""
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
    for nm in model.definitions:
        env[nm] = _to_sx(model.ast[("definition", nm)], env, ca)

    T = _to_sx(model.ast[("kinetic",)], env, ca)
    V = _to_sx(model.ast[("potential",)], env, ca)
    Q = ca.SX.zeros(model.n, 1)
    for i, nm in enumerate(model.coordinates):
        if nm in model.applied:
            Q[i] = _to_sx(model.ast[("force", nm)], env, ca)
    h = ca.SX.zeros(model.k, 1)
    for i, c in enumerate(model.constraints):
        h[i] = _to_sx(model.ast[("constraint", c.name)], env, ca)
    return CasadiModel(t=t, q=q, v=v, u=u, p=p, T=T, V=V, Q=Q, h=h)
