//! The straight-line body of one generated method, before it is printed:
//! the variables it unpacks, its constants, its `let` bindings in order and
//! one expression per output entry.
//!
//! Cut from the fused instruction list ([`Schedule::restrict`]) so that
//! every method shares the fused evaluation's temporaries and computes
//! nothing it does not return. A temporary used once is folded into its one
//! consumer; the others are bound to a [`Local`] with a name that says what
//! it holds (the output entry it is, a function of one variable, or an
//! anonymous `a7`).

use std::collections::HashMap;

use moreau_sym::{Func, Layout, Op, Operand, Schedule, VarId};

use super::names::{Local, Names, Role};
use crate::resolve::{Resolved, VarLayout};
use crate::scope::Var;

/// The deepest an expression of the generated code may nest before its
/// parts are bound to names.
const MAX_FOLD_DEPTH: usize = 24;

/// The most operations one folded expression may hold before it is bound
/// to a name: a sum of thousands of single-use terms would otherwise fold
/// into one `let` (its balanced tree never reaches [`MAX_FOLD_DEPTH`]),
/// which no cut of the body into parts can split, and whose type checking
/// and borrow checking grow faster than linearly in rustc.
pub(crate) const MAX_FOLD_SIZE: usize = 64;

/// An expression of the generated code.
#[derive(Clone, Debug)]
pub(crate) enum Code {
    /// A bound name: a model variable, a constant or a temporary.
    Local(Local),
    Binary(Op, Box<Code>, Box<Code>),
    Neg(Box<Code>),
    /// `a.powi(n)`.
    Powi(Box<Code>, i32),
    /// `a.sin()`: the scalar's method of the function's name.
    Func(Func, Box<Code>),
    /// `a.sin_cos()`, the pair `(sin a, cos a)`, bound by a [`Let`] with a
    /// [`pair`](Let::pair).
    SinCos(Box<Code>),
    /// `a.powf(b)`.
    Powf(Box<Code>, Box<Code>),
    /// `y.atan2(x)`.
    Atan2(Box<Code>, Box<Code>),
}

impl Code {
    /// Binding strength: 1 for `+ -`, 2 for `* /`, 3 for unary minus, 4 for
    /// postfix method calls and names.
    pub fn precedence(&self) -> u8 {
        match self {
            Code::Binary(Op::Add | Op::Sub, ..) => 1,
            Code::Binary(..) => 2,
            Code::Neg(_) => 3,
            _ => 4,
        }
    }

    /// Nesting depth of the expression (a name is 1).
    pub fn depth(&self) -> usize {
        match self {
            Code::Local(_) => 1,
            Code::Neg(a) | Code::Powi(a, _) | Code::Func(_, a) | Code::SinCos(a) => 1 + a.depth(),
            Code::Binary(_, a, b) | Code::Powf(a, b) | Code::Atan2(a, b) => {
                1 + a.depth().max(b.depth())
            }
        }
    }

    /// Number of operations and names in the expression (a name is 1).
    pub fn size(&self) -> usize {
        match self {
            Code::Local(_) => 1,
            Code::Neg(a) | Code::Powi(a, _) | Code::Func(_, a) | Code::SinCos(a) => 1 + a.size(),
            Code::Binary(_, a, b) | Code::Powf(a, b) | Code::Atan2(a, b) => 1 + a.size() + b.size(),
        }
    }

    /// Calls `f` on every local the expression reads (variables included).
    pub fn visit_locals(&self, f: &mut impl FnMut(Local)) {
        match self {
            Code::Local(l) => f(*l),
            Code::Neg(a) | Code::Powi(a, _) | Code::Func(_, a) | Code::SinCos(a) => {
                a.visit_locals(f)
            }
            Code::Binary(_, a, b) | Code::Powf(a, b) | Code::Atan2(a, b) => {
                a.visit_locals(f);
                b.visit_locals(f);
            }
        }
    }

    /// Calls `f` on every model variable the expression reads.
    fn visit_vars(&self, f: &mut impl FnMut(Var)) {
        match self {
            Code::Local(Local::Var(v)) => f(*v),
            Code::Local(_) => {}
            Code::Binary(_, a, b) => {
                a.visit_vars(f);
                b.visit_vars(f);
            }
            Code::Neg(a) | Code::Powi(a, _) | Code::Func(_, a) | Code::SinCos(a) => a.visit_vars(f),
            Code::Powf(a, b) | Code::Atan2(a, b) => {
                a.visit_vars(f);
                b.visit_vars(f);
            }
        }
    }
}

/// One `let` of a body: the local, its value and, for an output, the entry
/// it is (for the listing's comment). With a `pair`, the binding is
/// `let (local, pair) = code;` (a [`Code::SinCos`]).
pub(crate) struct Let {
    pub local: Local,
    pub code: Code,
    pub entry: Option<String>,
    pub pair: Option<Local>,
}

/// A method body.
pub(crate) struct Body {
    /// The model variables read, in layout order (unpacked first).
    pub unpack: Vec<Var>,
    /// The constants, `Local::Const(i)` being `constants[i]`.
    pub constants: Vec<f64>,
    pub lets: Vec<Let>,
    /// One expression per requested output, in the order requested.
    pub outputs: Vec<Code>,
    /// The printed names of every local.
    pub names: Names,
}

/// The body computing the fused outputs `indices` (of `outputs`, the
/// model's output layout) from the full schedule `full`.
pub(crate) fn build(
    model: &Resolved<'_>,
    full: &Schedule,
    outputs: &Layout,
    indices: &[usize],
) -> Body {
    let sched = full.restrict(indices);
    let uses = sched.use_counts();
    let mut b = Builder {
        model,
        vars: model.layout,
        names: Names::new(model),
        constants: Vec::new(),
        constant_index: HashMap::new(),
        codes: Vec::with_capacity(sched.instrs.len()),
        lets: Vec::new(),
        temps: 0,
    };
    // An output names its temporary after the first entry it fills.
    let mut output_of = vec![None; sched.instrs.len()];
    for (out, &index) in sched.outputs.iter().zip(indices) {
        if let Operand::Tmp(t) = *out {
            output_of[t as usize].get_or_insert(outputs.slot(index));
        }
    }
    let partner = sin_cos_partners(&sched);
    let mut pending: HashMap<usize, Code> = HashMap::new();
    for (k, instr) in sched.instrs.iter().enumerate() {
        // an output read from a `sin_cos` pair is bound to its slot's name
        let as_output = |b: &mut Builder, code: Code| match output_of[k] {
            Some(slot) => b.bind(Local::Output(slot), code, Some(slot.describe())),
            None => code,
        };
        if let Some(code) = pending.remove(&k) {
            let code = as_output(&mut b, code);
            b.codes.push(Some(code));
            continue;
        }
        if let Some(p) = partner[k] {
            let a = b.operand(instr.args[0]);
            let (sin, cos) = b.bind_sin_cos(a);
            let (mine, theirs) = match instr.op {
                Op::Func(Func::Sin) => (sin, cos),
                _ => (cos, sin),
            };
            pending.insert(p, theirs);
            let mine = as_output(&mut b, mine);
            b.codes.push(Some(mine));
            continue;
        }
        let a = Box::new(b.operand(instr.args[0]));
        let mut second = || Box::new(b.operand(instr.args[1]));
        let code = match instr.op {
            Op::Neg => Code::Neg(a),
            Op::Powi(n) => Code::Powi(a, n),
            Op::Func(f) => Code::Func(f, a),
            Op::Pow => Code::Powf(a, second()),
            Op::Atan2 => Code::Atan2(a, second()),
            op @ (Op::Add | Op::Sub | Op::Mul | Op::Div) => Code::Binary(op, a, second()),
        };
        let code = match output_of[k] {
            Some(slot) => b.bind(Local::Output(slot), code, Some(slot.describe())),
            // Fold a temporary into its only consumer, unless the folded
            // expression would nest deeper than MAX_FOLD_DEPTH (a long sum
            // `a + b + c + ...` is a left-deep tree; rustc's parser and
            // lints recurse over it) or hold more than MAX_FOLD_SIZE
            // operations (its operands are folded only below that size, so
            // measuring it costs at most 2 MAX_FOLD_SIZE).
            None if uses[k] == 1
                && code.depth() < MAX_FOLD_DEPTH
                && code.size() < MAX_FOLD_SIZE =>
            {
                code
            }
            None => {
                let local = role(&code).unwrap_or_else(|| {
                    b.temps += 1;
                    Local::Temp(b.temps - 1)
                });
                b.bind(local, code, None)
            }
        };
        b.codes.push(Some(code));
    }
    let outputs: Vec<Code> = sched.outputs.iter().map(|&o| b.operand(o)).collect();
    let unpack = read_vars(&b, &outputs);
    Body {
        unpack,
        constants: b.constants,
        lets: b.lets,
        outputs,
        names: b.names,
    }
}

/// The model variables the lets and outputs read, in layout order.
fn read_vars(b: &Builder<'_, '_>, outputs: &[Code]) -> Vec<Var> {
    let mut read = vec![false; b.vars.len()];
    for code in b.lets.iter().map(|l| &l.code).chain(outputs) {
        code.visit_vars(&mut |v| read[b.vars.id(v).index()] = true);
    }
    (0..b.vars.len())
        .filter(|&i| read[i])
        .map(|i| b.vars.var(VarId(i as u32)))
        .collect()
}

/// For the first of two instructions `sin a` and `cos a` of one operand,
/// the index of the other (computed together by one `sin_cos`; an output
/// among them is then bound to the pair's name).
fn sin_cos_partners(sched: &Schedule) -> Vec<Option<usize>> {
    let key = |a: Operand| match a {
        Operand::Var(v) => Some((0, v.0)),
        Operand::Tmp(t) => Some((1, t)),
        Operand::Const(_) => None,
    };
    let mut seen: HashMap<(Func, (u8, u32)), usize> = HashMap::new();
    let mut partner = vec![None; sched.instrs.len()];
    for (k, instr) in sched.instrs.iter().enumerate() {
        let (Op::Func(f @ (Func::Sin | Func::Cos)), Some(a)) = (instr.op, key(instr.args[0]))
        else {
            continue;
        };
        let other = if f == Func::Sin { Func::Cos } else { Func::Sin };
        match seen.get(&(other, a)) {
            Some(&first) if partner[first].is_none() => partner[first] = Some(k),
            _ => {
                seen.entry((f, a)).or_insert(k);
            }
        }
    }
    partner
}

/// A role for a shared temporary that is a function of one variable.
fn role(code: &Code) -> Option<Local> {
    let var = |c: &Code| match c {
        Code::Local(Local::Var(v)) => Some(*v),
        _ => None,
    };
    match code {
        Code::Func(f, a) => var(a).map(|v| Local::Role(Role::Func(*f), v)),
        Code::Powi(a, 2) => var(a).map(|v| Local::Role(Role::Square, v)),
        Code::Powi(a, 3) => var(a).map(|v| Local::Role(Role::Cube, v)),
        _ => None,
    }
}

struct Builder<'a, 'm> {
    model: &'a Resolved<'m>,
    vars: VarLayout,
    names: Names,
    constants: Vec<f64>,
    /// The index of each constant in `constants`, by its bits.
    constant_index: HashMap<u64, usize>,
    /// The code of each instruction so far: folded (taken by its one
    /// consumer, so that a long chain is moved, never copied), or its bound
    /// local.
    codes: Vec<Option<Code>>,
    lets: Vec<Let>,
    temps: usize,
}

impl Builder<'_, '_> {
    fn operand(&mut self, a: Operand) -> Code {
        match a {
            Operand::Const(c) => Code::Local(self.constant(c)),
            Operand::Var(v) => Code::Local(Local::Var(self.vars.var(v))),
            Operand::Tmp(t) => match &mut self.codes[t as usize] {
                Some(Code::Local(local)) => Code::Local(*local),
                // a folded temporary has exactly one consumer: move it there
                slot => slot.take().unwrap_or(Code::Local(Local::Temp(usize::MAX))),
            },
        }
    }

    fn constant(&mut self, c: f64) -> Local {
        if let Some(&i) = self.constant_index.get(&c.to_bits()) {
            return Local::Const(i);
        }
        let i = self.constants.len();
        self.constants.push(c);
        self.constant_index.insert(c.to_bits(), i);
        let local = Local::Const(i);
        let readable = local.readable(self.model, c);
        self.names.declare(local, readable);
        local
    }

    /// Binds `code` to `local` and returns the code that reads it.
    fn bind(&mut self, local: Local, code: Code, entry: Option<String>) -> Code {
        let readable = local.readable(self.model, 0.0);
        self.names.declare(local, readable);
        self.lets.push(Let {
            local,
            code,
            entry,
            pair: None,
        });
        Code::Local(local)
    }

    /// Binds `sin a` and `cos a` by one `let (sin, cos) = a.sin_cos();`
    /// and returns the code that reads each.
    fn bind_sin_cos(&mut self, a: Code) -> (Code, Code) {
        let [sin, cos] = [Func::Sin, Func::Cos].map(|f| match a {
            Code::Local(Local::Temp(i)) => Local::TempFunc(f, i),
            _ => role(&Code::Func(f, Box::new(a.clone()))).unwrap_or_else(|| {
                self.temps += 1;
                Local::Temp(self.temps - 1)
            }),
        });
        for local in [sin, cos] {
            let readable = local.readable(self.model, 0.0);
            self.names.declare(local, readable);
        }
        self.lets.push(Let {
            local: sin,
            code: Code::SinCos(Box::new(a)),
            entry: None,
            pair: Some(cos),
        });
        (Code::Local(sin), Code::Local(cos))
    }
}
