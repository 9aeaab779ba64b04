//! Emission: straight-line Rust from one instruction list.
//!
//! Every output of the model (M, C, G, F, h, J and the force Jacobians) is an
//! entry of one [`Schedule`], built once after common-subexpression
//! elimination. Each generated method evaluates the sub-list its outputs
//! need ([`Schedule::restrict`]), so `eval` shares every temporary and
//! `mass` computes nothing else.
//!
//! The code is written as a careful person would: inputs unpacked once at
//! the top under the model's own names (`let th1 = q[0];`), temporaries used
//! once folded into their one consumer, the others bound to names that say
//! what they hold (`m_0_1` for `M[0,1]`, `sin_th1`, `a7` for anonymous shared
//! ones), constants bound once (`k_0_5`), and the symmetric `M` filled from
//! its upper triangle. Internal names use `Span::mixed_site()`, so they can
//! never capture or shadow a name of the model.

use std::fmt::Write;

use moreau_sym::{Func, Layout as Outputs, Op, Operand, Quantity, Schedule, Slot, VarId};
use proc_macro2::{Ident, Span, TokenStream};
use quote::{format_ident, quote};

use crate::expr::fmt_number;
use crate::front::yaml::track;
use crate::lower::{Layout, Lowered, Var};
use crate::spec::{ModelSpec, Origin};
use crate::{check, render};

/// The local name of an output entry (`m_0_1` for `M[0,1]`, `g_2` for
/// `G[2]`) and the entry it is, for comments.
fn describe(slot: Slot) -> (String, String) {
    let stem = slot.quantity.stem();
    let name = if slot.quantity.is_vector() {
        format!("{stem}_{}", slot.row)
    } else {
        format!("{stem}_{}_{}", slot.row, slot.col)
    };
    (name, slot.describe())
}

/// An expression of the generated code, before it becomes tokens or text.
#[derive(Clone, Debug)]
enum Code {
    /// A model variable, under the model's own name.
    Var(VarId),
    /// A let-bound temporary or constant (internal name).
    Local(String),
    Binary(Op, Box<Code>, Box<Code>),
    Neg(Box<Code>),
    Powi(Box<Code>, i32),
    /// A method call on the scalar: `a.sin()`, `a.powf(b)`, `a.atan2(b)`.
    Method(&'static str, Box<Code>, Option<Box<Code>>),
}

impl Code {
    /// Binding strength: 1 for `+ -`, 2 for `* /`, 3 for unary minus, 4 for
    /// postfix method calls and names.
    fn precedence(&self) -> u8 {
        match self {
            Code::Binary(Op::Add | Op::Sub, ..) => 1,
            Code::Binary(..) => 2,
            Code::Neg(_) => 3,
            _ => 4,
        }
    }
}

/// A method body: unpacked inputs, bindings, and the output entries.
struct Body {
    /// `let name = source;` for each model variable used.
    unpack: Vec<VarId>,
    /// Constants used, with their local names.
    constants: Vec<(String, f64)>,
    /// `let name = code;` in execution order, with the entry it computes.
    lets: Vec<(String, Code, Option<String>)>,
    /// One expression per requested output slot.
    outputs: Vec<Code>,
}

/// Builds the body computing `slots` from the fused list.
fn body(full: &Schedule, outputs_of: &Outputs, slots: &[usize]) -> Body {
    let sched = full.restrict(slots);
    let uses = sched.use_counts();
    // Names: an output names its temporary after the first slot it fills.
    let mut names: Vec<Option<String>> = vec![None; sched.instrs.len()];
    let mut entries: Vec<Option<String>> = vec![None; sched.instrs.len()];
    for (out, &slot) in sched.outputs.iter().zip(slots) {
        if let Operand::Tmp(t) = *out {
            let t = t as usize;
            if names[t].is_none() {
                let (name, entry) = describe(outputs_of.slot(slot));
                names[t] = Some(name);
                entries[t] = Some(entry);
            }
        }
    }
    let mut constants: Vec<(String, f64)> = Vec::new();
    let mut constant = |c: f64| -> Code {
        if let Some((name, _)) = constants.iter().find(|(_, x)| x.to_bits() == c.to_bits()) {
            return Code::Local(name.clone());
        }
        let name = constant_name(c, constants.len());
        constants.push((name.clone(), c));
        Code::Local(name)
    };
    let mut codes: Vec<Option<Code>> = vec![None; sched.instrs.len()];
    let mut lets = Vec::new();
    let mut anonymous = 0;
    for (k, instr) in sched.instrs.iter().enumerate() {
        let mut operand = |a: Operand, codes: &mut Vec<Option<Code>>| -> Code {
            match a {
                Operand::Const(c) => constant(c),
                Operand::Var(v) => Code::Var(v),
                Operand::Tmp(t) => codes[t as usize]
                    .clone()
                    .expect("temporary used before it is computed"),
            }
        };
        let a = operand(instr.args[0], &mut codes);
        let b = (instr.op.arity() == 2).then(|| operand(instr.args[1], &mut codes));
        let code = match (instr.op, b) {
            (Op::Neg, _) => Code::Neg(Box::new(a)),
            (Op::Powi(n), _) => Code::Powi(Box::new(a), n),
            (Op::Func(f), _) => Code::Method(method(f), Box::new(a), None),
            (Op::Pow, Some(b)) => Code::Method("powf", Box::new(a), Some(Box::new(b))),
            (Op::Atan2, Some(b)) => Code::Method("atan2", Box::new(a), Some(Box::new(b))),
            (op, Some(b)) => Code::Binary(op, Box::new(a), Box::new(b)),
            (op, None) => unreachable!("binary operation {op} with one operand"),
        };
        // Fold a temporary into its only consumer unless it is an output.
        if uses[k] == 1 && names[k].is_none() {
            codes[k] = Some(code);
            continue;
        }
        let name = names[k].clone().unwrap_or_else(|| {
            role_name(&code).unwrap_or_else(|| {
                anonymous += 1;
                format!("a{}", anonymous - 1)
            })
        });
        let name = unique(&name, &lets);
        lets.push((name.clone(), code, entries[k].clone()));
        // Every later use reads the binding.
        codes[k] = Some(Code::Local(name));
    }
    let outputs = sched
        .outputs
        .iter()
        .map(|&o| match o {
            Operand::Const(c) => constant(c),
            Operand::Var(v) => Code::Var(v),
            Operand::Tmp(t) => codes[t as usize]
                .clone()
                .expect("output temporary is bound"),
        })
        .collect();
    let mut unpack = Vec::new();
    let mut note = |v: VarId| {
        if !unpack.contains(&v) {
            unpack.push(v);
        }
    };
    for (_, code, _) in &lets {
        visit_vars(code, &mut note);
    }
    for code in &outputs {
        visit_vars(code, &mut note);
    }
    unpack.sort();
    Body {
        unpack,
        constants,
        lets,
        outputs,
    }
}

fn visit_vars(code: &Code, f: &mut impl FnMut(VarId)) {
    match code {
        Code::Var(v) => f(*v),
        Code::Local(_) => {}
        Code::Binary(_, a, b) => {
            visit_vars(a, f);
            visit_vars(b, f);
        }
        Code::Neg(a) | Code::Powi(a, _) => visit_vars(a, f),
        Code::Method(_, a, b) => {
            visit_vars(a, f);
            if let Some(b) = b {
                visit_vars(b, f);
            }
        }
    }
}

/// A name for a shared temporary that says what it holds, when it is a
/// function of one variable (`sin_th1`, `vx_sq`).
fn role_name(code: &Code) -> Option<String> {
    let var = |c: &Code| match c {
        Code::Var(v) => Some(*v),
        _ => None,
    };
    match code {
        Code::Method(m, a, None) => var(a).map(|v| format!("{m}_{{{}}}", v.index())),
        Code::Powi(a, 2) => var(a).map(|v| format!("{{{}}}_sq", v.index())),
        Code::Powi(a, 3) => var(a).map(|v| format!("{{{}}}_cube", v.index())),
        _ => None,
    }
}

/// Makes `name` differ from every binding so far (two outputs can never
/// collide, but role names of different variables could after resolution).
fn unique(name: &str, lets: &[(String, Code, Option<String>)]) -> String {
    if lets.iter().all(|(n, _, _)| n != name) {
        return name.to_string();
    }
    (2..)
        .map(|i| format!("{name}_{i}"))
        .find(|candidate| lets.iter().all(|(n, _, _)| n != candidate))
        .expect("an unused name exists")
}

fn method(f: Func) -> &'static str {
    match f {
        Func::Sqrt => "sqrt",
        Func::Exp => "exp",
        Func::Ln => "ln",
        Func::Sin => "sin",
        Func::Cos => "cos",
        Func::Tan => "tan",
        Func::Sinh => "sinh",
        Func::Cosh => "cosh",
        Func::Tanh => "tanh",
    }
}

/// `k_0_5` for 0.5, `k_2` for 2, `k_m1` for -1; `k<n>` when the value has
/// no short name.
fn constant_name(c: f64, index: usize) -> String {
    match c {
        0.0 => return "zero".into(),
        1.0 => return "one".into(),
        _ => {}
    }
    let text = fmt_number(c);
    if text.len() <= 8 && !text.contains('e') {
        format!("k_{}", text.replace('-', "m").replace('.', "_"))
    } else {
        format!("k{index}")
    }
}

/// Everything the emitter needs about one model.
struct Emitter<'a> {
    spec: &'a ModelSpec,
    layout: Layout,
    outputs: Outputs,
    full: Schedule,
}

impl<'a> Emitter<'a> {
    fn new(spec: &'a ModelSpec, lowered: &Lowered) -> Self {
        let mech = &lowered.mechanics;
        Emitter {
            spec,
            layout: lowered.layout,
            outputs: mech.layout(),
            full: Schedule::new(&lowered.graph, &mech.outputs()),
        }
    }

    /// Slots of the fused `eval`: M, C, G, F, h, J.
    fn eval_slots(&self) -> Vec<usize> {
        self.outputs.indices(&Quantity::EVAL)
    }

    /// The user-facing name of a model variable.
    fn var_name(&self, v: VarId) -> String {
        let spec = self.spec;
        match self.layout.var(v) {
            Var::Coordinate(i) => spec.coordinates[i].q.text.clone(),
            Var::Velocity(i) => spec.coordinates[i].v.text.clone(),
            Var::Time => "t".into(),
            Var::Input(i) => spec.inputs[i].text.clone(),
            Var::Parameter(i) => spec.parameters[i].name.text.clone(),
        }
    }

    /// Resolves `{i}` placeholders of role names into variable names.
    fn resolve(&self, name: &str) -> String {
        let Some(open) = name.find('{') else {
            return name.to_string();
        };
        let close = name[open..].find('}').map_or(name.len(), |c| open + c);
        let index: u32 = name[open + 1..close].parse().unwrap_or(0);
        format!(
            "{}{}{}",
            &name[..open],
            self.var_name(VarId(index)),
            self.resolve(&name[close + 1..])
        )
    }

    fn user_ident(&self, v: VarId) -> Ident {
        Ident::new(&self.var_name(v), Span::call_site())
    }

    fn code_tokens(&self, code: &Code) -> TokenStream {
        let wrap = |inner: &Code, paren: bool| {
            let t = self.code_tokens(inner);
            if paren { quote!((#t)) } else { t }
        };
        match code {
            Code::Var(v) => {
                let id = self.user_ident(*v);
                quote!(#id)
            }
            Code::Local(name) => {
                let id = Ident::new(&self.resolve(name), Span::mixed_site());
                quote!(#id)
            }
            Code::Binary(op, a, b) => {
                let p = code.precedence();
                let a = wrap(a, a.precedence() < p);
                // Floating-point operations do not reassociate: keep the
                // right operand grouped when it binds no tighter.
                let b = wrap(b, b.precedence() <= p);
                match op {
                    Op::Add => quote!(#a + #b),
                    Op::Sub => quote!(#a - #b),
                    Op::Mul => quote!(#a * #b),
                    _ => quote!(#a / #b),
                }
            }
            Code::Neg(a) => {
                let a = wrap(a, a.precedence() < 4);
                quote!(-#a)
            }
            Code::Powi(a, n) => {
                let a = wrap(a, a.precedence() < 4);
                let n = proc_macro2::Literal::i32_unsuffixed(*n);
                quote!(#a.powi(#n))
            }
            Code::Method(m, a, b) => {
                let a = wrap(a, a.precedence() < 4);
                let m = format_ident!("{}", m);
                match b {
                    Some(b) => {
                        let b = self.code_tokens(b);
                        quote!(#a.#m(#b))
                    }
                    None => quote!(#a.#m()),
                }
            }
        }
    }

    fn code_text(&self, code: &Code) -> String {
        let wrap = |inner: &Code, paren: bool| {
            let t = self.code_text(inner);
            if paren { format!("({t})") } else { t }
        };
        match code {
            Code::Var(v) => self.var_name(*v),
            Code::Local(name) => self.resolve(name),
            Code::Binary(op, a, b) => {
                let p = code.precedence();
                let a = wrap(a, a.precedence() < p);
                let b = wrap(b, b.precedence() <= p);
                format!("{a} {} {b}", op.infix().unwrap_or("?"))
            }
            Code::Neg(a) => format!("-{}", wrap(a, a.precedence() < 4)),
            Code::Powi(a, n) => format!("{}.powi({n})", wrap(a, a.precedence() < 4)),
            Code::Method(m, a, b) => {
                let a = wrap(a, a.precedence() < 4);
                match b {
                    Some(b) => format!("{a}.{m}({})", self.code_text(b)),
                    None => format!("{a}.{m}()"),
                }
            }
        }
    }

    /// `let x = q[0]; ... let k_0_5: T = cst(0.5); let m_0_1 = ...;`
    fn prelude(&self, body: &Body) -> TokenStream {
        let mut out = TokenStream::new();
        let (q, v, t, u) = internal_args();
        for &var in &body.unpack {
            let name = self.user_ident(var);
            let source = match self.layout.var(var) {
                Var::Coordinate(i) => {
                    let i = int(i);
                    quote!(#q[#i])
                }
                Var::Velocity(i) => {
                    let i = int(i);
                    quote!(#v[#i])
                }
                Var::Time => quote!(#t),
                Var::Input(i) => {
                    let i = int(i);
                    quote!(#u[#i])
                }
                Var::Parameter(i) => {
                    let field = Ident::new(&self.spec.parameters[i].name.text, Span::call_site());
                    quote!(self.#field)
                }
            };
            out.extend(quote!(let #name = #source;));
        }
        for (name, value) in &body.constants {
            let id = Ident::new(name, Span::mixed_site());
            let value = float(*value);
            out.extend(quote!(let #id: T = ::moreau::__private::cst(#value);));
        }
        for (name, code, _) in &body.lets {
            let id = Ident::new(&self.resolve(name), Span::mixed_site());
            let code = self.code_tokens(code);
            out.extend(quote!(let #id = #code;));
        }
        out
    }

    /// A column-major `SMatrix` of `rows × cols` from output expressions
    /// picked by `at(i, j)`.
    fn matrix(
        &self,
        rows: usize,
        cols: usize,
        at: impl Fn(usize, usize) -> TokenStream,
    ) -> TokenStream {
        let columns = (0..cols).map(|j| {
            let entries = (0..rows).map(|i| at(i, j));
            quote!([#(#entries),*])
        });
        quote!(::moreau::__private::SMatrix::from_array_storage(
            ::moreau::__private::ArrayStorage([#(#columns),*])
        ))
    }

    /// One method body computing the quantities `qs` and returning them
    /// through `ret`, which receives a closure giving entry `(q, i, j)`.
    fn method_body(
        &self,
        qs: &[Quantity],
        ret: impl Fn(&dyn Fn(Quantity, usize, usize) -> TokenStream) -> TokenStream,
    ) -> TokenStream {
        let slots = self.outputs.indices(qs);
        let body = body(&self.full, &self.outputs, &slots);
        let prelude = self.prelude(&body);
        let entry = |quantity: Quantity, row: usize, col: usize| {
            let slot = self.outputs.index(Slot { quantity, row, col });
            let pos = slots
                .iter()
                .position(|&s| s == slot)
                .expect("slot requested");
            self.code_tokens(&body.outputs[pos])
        };
        let value = ret(&entry);
        quote! { #prelude #value }
    }

    fn emit(&self) -> TokenStream {
        let spec = self.spec;
        let (n, k) = (spec.dofs(), spec.constraint_count());
        let name = Ident::new(&spec.name.text, spec.name.loc.span);
        let vis = &spec.vis;
        let nu = spec.inputs.len();
        let (q, v, t, u) = internal_args();
        let vec = |len: usize| {
            let len = int(len);
            quote!(::moreau::__private::SVector<T, #len>)
        };
        let mat = |r: usize, c: usize| {
            let (r, c) = (int(r), int(c));
            quote!(::moreau::__private::SMatrix<T, #r, #c>)
        };
        let (vec_n, vec_k, mat_nn, mat_kn) = (vec(n), vec(k), mat(n, n), mat(k, n));
        let input = vec(nu);

        let mass = self.method_body(&[Quantity::Mass], |e| {
            self.matrix(n, n, |i, j| e(Quantity::Mass, i, j))
        });
        let coriolis = self.method_body(&[Quantity::Coriolis], |e| {
            self.matrix(n, n, |i, j| e(Quantity::Coriolis, i, j))
        });
        let gravity = self.method_body(&[Quantity::Gravity], |e| {
            self.matrix(n, 1, |i, _| e(Quantity::Gravity, i, 0))
        });
        let forces = self.method_body(&[Quantity::Force], |e| {
            self.matrix(n, 1, |i, _| e(Quantity::Force, i, 0))
        });
        let gaps = self.method_body(&[Quantity::Gap], |e| {
            self.matrix(k, 1, |i, _| e(Quantity::Gap, i, 0))
        });
        let jacobian = self.method_body(&[Quantity::Jacobian], |e| {
            self.matrix(k, n, |i, j| e(Quantity::Jacobian, i, j))
        });
        let dynamics = self.method_body(&[Quantity::Mass, Quantity::Force], |e| {
            let m = self.matrix(n, n, |i, j| e(Quantity::Mass, i, j));
            let f = self.matrix(n, 1, |i, _| e(Quantity::Force, i, 0));
            quote!((#m, #f))
        });
        let contact = self.method_body(&[Quantity::Gap, Quantity::Jacobian], |e| {
            let h = self.matrix(k, 1, |i, _| e(Quantity::Gap, i, 0));
            let j = self.matrix(k, n, |i, j| e(Quantity::Jacobian, i, j));
            quote!((#h, #j))
        });
        let linearization = self.method_body(
            &[Quantity::Mass, Quantity::Force, Quantity::ForceDq, Quantity::ForceDv],
            |e| {
                let m = self.matrix(n, n, |i, j| e(Quantity::Mass, i, j));
                let f = self.matrix(n, 1, |i, _| e(Quantity::Force, i, 0));
                let fq = self.matrix(n, n, |i, j| e(Quantity::ForceDq, i, j));
                let fv = self.matrix(n, n, |i, j| e(Quantity::ForceDv, i, j));
                quote!(::moreau::__private::Linearization { mass: #m, forces: #f, forces_dq: #fq, forces_dv: #fv })
            },
        );
        let eval = self.method_body(&Quantity::EVAL, |e| {
            let m = self.matrix(n, n, |i, j| e(Quantity::Mass, i, j));
            let c = self.matrix(n, n, |i, j| e(Quantity::Coriolis, i, j));
            let g = self.matrix(n, 1, |i, _| e(Quantity::Gravity, i, 0));
            let f = self.matrix(n, 1, |i, _| e(Quantity::Force, i, 0));
            let h = self.matrix(k, 1, |i, _| e(Quantity::Gap, i, 0));
            let j = self.matrix(k, n, |i, j| e(Quantity::Jacobian, i, j));
            quote!(::moreau::__private::Terms { mass: #m, coriolis: #c, gravity: #g, forces: #f, gaps: #h, jacobian: #j })
        });
        let mass_dq = self.method_body(&[Quantity::MassDq], |e| {
            self.matrix(n, n, |i, j| e(Quantity::MassDq, i, j))
        });
        let jacobian_dq = self.method_body(&[Quantity::JacobianDq], |e| {
            self.matrix(k, n, |i, j| e(Quantity::JacobianDq, i, j))
        });
        let op_count = int(self.full.restrict(&self.eval_slots()).op_count());

        let strs = |names: Vec<&String>| quote!([#(#names),*]);
        let coordinates = strs(spec.coordinates.iter().map(|c| &c.q.text).collect());
        let velocities = strs(spec.coordinates.iter().map(|c| &c.v.text).collect());
        let constraints = strs(spec.constraints.iter().map(|c| &c.name.text).collect());
        let parameters = strs(spec.parameters.iter().map(|p| &p.name.text).collect());
        let inputs = strs(spec.inputs.iter().map(|i| &i.text).collect());
        let source = render::source(spec);
        let model_name = &spec.name.text;

        let fields = self.fields();
        let defaults = self.defaults();
        let restitution = self.matrix(k, 1, |i, _| {
            let e = spec.restitution_of(i).map_or(0.0, |e| e.value);
            let e = float(e);
            quote!(::moreau::__private::cst(#e))
        });
        let initial = |names: Vec<&String>| {
            let values = names.iter().map(|n| spec.initial_value(n));
            self.matrix(n, 1, |i, _| {
                let x = values.clone().nth(i).unwrap_or(0.0);
                let x = float(x);
                quote!(::moreau::__private::cst(#x))
            })
        };
        let q0 = initial(spec.coordinates.iter().map(|c| &c.q.text).collect());
        let v0 = initial(spec.coordinates.iter().map(|c| &c.v.text).collect());
        let parameter_arms: Vec<TokenStream> = spec
            .parameters
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let field = Ident::new(&p.name.text, Span::call_site());
                let i = int(i);
                quote!(#i => ::core::option::Option::Some(self.#field),)
            })
            .collect();
        let parameter_mut_arms: Vec<TokenStream> = spec
            .parameters
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let field = Ident::new(&p.name.text, Span::call_site());
                let i = int(i);
                quote!(#i => ::core::option::Option::Some(&mut self.#field),)
            })
            .collect();
        let doc = self.doc();
        let tracking = match &spec.origin {
            Origin::Yaml { path, .. } => track(path),
            Origin::Inline => TokenStream::new(),
        };
        let bound = quote!(T: ::moreau::__private::RealField + ::core::marker::Copy);
        let (n, k) = (int(n), int(k));

        quote! {
            #doc
            #[derive(Clone, Copy, Debug, PartialEq)]
            #[allow(non_snake_case)]
            #vis struct #name<T = f64> {
                #fields
            }

            #tracking

            impl<#bound> ::core::default::Default for #name<T> {
                fn default() -> Self {
                    #[allow(non_snake_case)]
                    Self { #defaults restitution: #restitution }
                }
            }

            #[allow(non_snake_case, dead_code)]
            impl<#bound> #name<T> {
                /// Number of degrees of freedom `N`.
                pub const N: usize = #n;
                /// Number of constraints `K`.
                pub const K: usize = #k;

                /// The model with its default parameters.
                #[must_use]
                pub fn new() -> Self {
                    ::core::default::Default::default()
                }

                /// The initial state `(q0, v0)` the model gives (zeros where it
                /// gives none).
                #[must_use]
                pub fn initial_state() -> (#vec_n, #vec_n) {
                    (#q0, #v0)
                }
            }

            #[allow(non_snake_case, unused_variables, clippy::all)]
            impl<#bound> ::moreau::__private::Model<#n, #k> for #name<T> {
                type Scalar = T;
                type Input = #input;

                const INFO: ::moreau::__private::ModelInfo<#n, #k> = ::moreau::__private::ModelInfo {
                    name: #model_name,
                    coordinates: #coordinates,
                    velocities: #velocities,
                    constraints: #constraints,
                    parameters: &#parameters,
                    inputs: &#inputs,
                    source: #source,
                    op_count: #op_count,
                };

                #[inline]
                fn mass(&self, #q: &#vec_n) -> #mat_nn { #mass }
                #[inline]
                fn coriolis(&self, #q: &#vec_n, #v: &#vec_n) -> #mat_nn { #coriolis }
                #[inline]
                fn gravity(&self, #q: &#vec_n) -> #vec_n { #gravity }
                #[inline]
                fn forces(&self, #t: T, #q: &#vec_n, #v: &#vec_n, #u: &#input) -> #vec_n { #forces }
                #[inline]
                fn gaps(&self, #q: &#vec_n) -> #vec_k { #gaps }
                #[inline]
                fn gap_jacobian(&self, #q: &#vec_n) -> #mat_kn { #jacobian }
                #[inline]
                fn restitution(&self) -> #vec_k { self.restitution }
                #[inline]
                fn parameter(&self, index: usize) -> ::core::option::Option<T> {
                    match index { #(#parameter_arms)* _ => ::core::option::Option::None }
                }
                #[inline]
                fn parameter_mut(&mut self, index: usize) -> ::core::option::Option<&mut T> {
                    match index { #(#parameter_mut_arms)* _ => ::core::option::Option::None }
                }
                #[inline]
                fn dynamics(&self, #t: T, #q: &#vec_n, #v: &#vec_n, #u: &#input) -> (#mat_nn, #vec_n) { #dynamics }
                #[inline]
                fn linearization(&self, #t: T, #q: &#vec_n, #v: &#vec_n, #u: &#input) -> ::moreau::__private::Linearization<T, #n> { #linearization }
                #[inline]
                fn contact(&self, #q: &#vec_n) -> (#vec_k, #mat_kn) { #contact }
                #[inline]
                fn eval(&self, #t: T, #q: &#vec_n, #v: &#vec_n, #u: &#input) -> ::moreau::__private::Terms<T, #n, #k> { #eval }
            }

            #[allow(non_snake_case, unused_variables, clippy::all)]
            impl<#bound> ::moreau::__private::Sensitivities<#n, #k> for #name<T> {
                #[inline]
                fn mass_dq(&self, #q: &#vec_n, #v: &#vec_n) -> #mat_nn { #mass_dq }
                #[inline]
                fn jacobian_dq(&self, #q: &#vec_n, #v: &#vec_n) -> #mat_kn { #jacobian_dq }
            }
        }
    }

    fn fields(&self) -> TokenStream {
        let spec = self.spec;
        let mut out = TokenStream::new();
        for p in &spec.parameters {
            let name = Ident::new(&p.name.text, Span::call_site());
            let mut doc = format!(
                "Parameter `{}` (default `{}`).",
                p.name.text,
                fmt_number(p.default.value)
            );
            for line in &p.doc {
                doc.push(' ');
                doc.push_str(line);
            }
            out.extend(quote!(#[doc = #doc] pub #name: T,));
        }
        let k = spec.constraint_count();
        let names: Vec<String> = spec
            .constraints
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let e = spec.restitution_of(i).map_or(0.0, |e| e.value);
                format!("`{}` ({})", c.name.text, fmt_number(e))
            })
            .collect();
        let doc = if k == 0 {
            "Restitution coefficients (the model has no constraints).".to_string()
        } else {
            format!(
                "Restitution coefficient of each constraint, defaults: {}.",
                names.join(", ")
            )
        };
        let k = int(k);
        out.extend(quote!(#[doc = #doc] pub restitution: ::moreau::__private::SVector<T, #k>,));
        out
    }

    fn defaults(&self) -> TokenStream {
        let mut out = TokenStream::new();
        for p in &self.spec.parameters {
            let name = Ident::new(&p.name.text, Span::call_site());
            let value = float(p.default.value);
            out.extend(quote!(#name: ::moreau::__private::cst(#value),));
        }
        out
    }

    fn doc(&self) -> TokenStream {
        let spec = self.spec;
        let mut lines: Vec<String> = spec.doc.iter().map(|l| format!(" {l}")).collect();
        if !lines.is_empty() {
            lines.push(String::new());
        }
        let origin = match &spec.origin {
            Origin::Yaml { .. } => "a YAML model file",
            Origin::Inline => "an inline model",
        };
        let names = |v: Vec<&String>| {
            v.iter()
                .map(|n| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        lines.push(format!(
            " Generated by `moreau::model!` from {origin}: coordinates {}, velocities {}.",
            names(spec.coordinates.iter().map(|c| &c.q.text).collect()),
            names(spec.coordinates.iter().map(|c| &c.v.text).collect()),
        ));
        if !spec.constraints.is_empty() {
            lines.push(String::new());
            lines.push(" Constraints `h(q) ≥ 0`:".into());
            for c in &spec.constraints {
                let doc = if c.doc.is_empty() {
                    String::new()
                } else {
                    format!(" {}", c.doc.join(" "))
                };
                lines.push(format!(" - `{}`: `{} ≥ 0`.{doc}", c.name.text, c.h));
            }
        }
        lines.push(String::new());
        lines.push(" The fused evaluation [`Model::eval`](::moreau::Model::eval) generated for this model:".into());
        lines.push(String::new());
        lines.push(" ```text".into());
        lines.extend(self.listing().lines().map(|l| format!(" {l}")));
        lines.push(" ```".into());
        quote!(#(#[doc = #lines])*)
    }

    /// The fused evaluation as text, with comments naming matrix entries: the
    /// listing the snapshot tests read.
    fn listing(&self) -> String {
        let slots = self.eval_slots();
        let body = body(&self.full, &self.outputs, &slots);
        let mut s = String::new();
        let _ = writeln!(
            s,
            "// {}: fused evaluation of M, C, G, F, h, J ({} operations)",
            self.spec.name.text,
            self.full.restrict(&slots).op_count()
        );
        for &var in &body.unpack {
            let source = match self.layout.var(var) {
                Var::Coordinate(i) => format!("q[{i}]"),
                Var::Velocity(i) => format!("v[{i}]"),
                Var::Time => "t".into(),
                Var::Input(i) => format!("u[{i}]"),
                Var::Parameter(i) => format!("self.{}", self.spec.parameters[i].name.text),
            };
            let _ = writeln!(s, "let {} = {source};", self.var_name(var));
        }
        for (name, value) in &body.constants {
            let _ = writeln!(s, "let {name}: T = cst({});", fmt_number(*value));
        }
        for (name, code, entry) in &body.lets {
            let comment = entry
                .as_ref()
                .map_or(String::new(), |e| format!("  // {e}"));
            let _ = writeln!(
                s,
                "let {} = {};{comment}",
                self.resolve(name),
                self.code_text(code)
            );
        }
        for (slot, code) in slots.iter().zip(&body.outputs) {
            let (name, entry) = describe(self.outputs.slot(*slot));
            let text = self.code_text(code);
            if text != name {
                let _ = writeln!(s, "// {entry} = {text}");
            }
        }
        s
    }
}

/// An integer literal without a suffix (`2`, not `2usize`).
fn int(n: usize) -> proc_macro2::Literal {
    proc_macro2::Literal::usize_unsuffixed(n)
}

/// A float literal without a suffix (`0.5`, not `0.5f64`).
fn float(x: f64) -> proc_macro2::Literal {
    proc_macro2::Literal::f64_unsuffixed(x)
}

/// The method arguments `q`, `v`, `t`, `u`, with mixed-site hygiene.
fn internal_args() -> (Ident, Ident, Ident, Ident) {
    let id = |s: &str| Ident::new(s, Span::mixed_site());
    (id("q"), id("v"), id("t"), id("u"))
}

/// The generated items for a checked, lowered model.
pub(crate) fn emit(spec: &ModelSpec, lowered: &Lowered) -> TokenStream {
    Emitter::new(spec, lowered).emit()
}

/// The fused evaluation as annotated text (for snapshot tests).
#[cfg(test)]
fn listing(spec: &ModelSpec, lowered: &Lowered) -> String {
    Emitter::new(spec, lowered).listing()
}

/// The struct and a stub `impl Model` for a model with errors, so that the
/// user's other uses of the type do not add errors of their own.
pub(crate) fn fallback(spec: &ModelSpec) -> TokenStream {
    if !check::is_field_name(&spec.name.text) {
        return TokenStream::new();
    }
    let name = Ident::new(&spec.name.text, spec.name.loc.span);
    let vis = &spec.vis;
    let (n, k, nu) = (
        int(spec.dofs()),
        int(spec.constraint_count()),
        int(spec.inputs.len()),
    );
    // Only parameters that make valid, distinct fields: the stub must add no
    // error of its own.
    let mut names: Vec<&str> = Vec::new();
    for p in &spec.parameters {
        let text = p.name.text.as_str();
        if check::is_field_name(text) && !names.contains(&text) {
            names.push(text);
        }
    }
    let fields = names.iter().map(|n| {
        let id = Ident::new(n, Span::call_site());
        quote!(pub #id: T,)
    });
    quote! {
        #[allow(non_snake_case, dead_code)]
        #vis struct #name<T = f64> { #(#fields)* pub restitution: ::moreau::__private::SVector<T, #k> }
        #[allow(unused_variables)]
        impl<T: ::moreau::__private::RealField + ::core::marker::Copy> ::moreau::__private::Model<#n, #k> for #name<T> {
            type Scalar = T;
            type Input = ::moreau::__private::SVector<T, #nu>;
            const INFO: ::moreau::__private::ModelInfo<#n, #k> = ::core::unimplemented!();
            fn mass(&self, q: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #n, #n> { ::core::unimplemented!() }
            fn coriolis(&self, q: &::moreau::__private::SVector<T, #n>, v: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #n, #n> { ::core::unimplemented!() }
            fn gravity(&self, q: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SVector<T, #n> { ::core::unimplemented!() }
            fn forces(&self, t: T, q: &::moreau::__private::SVector<T, #n>, v: &::moreau::__private::SVector<T, #n>, u: &Self::Input) -> ::moreau::__private::SVector<T, #n> { ::core::unimplemented!() }
            fn gaps(&self, q: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SVector<T, #k> { ::core::unimplemented!() }
            fn gap_jacobian(&self, q: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #k, #n> { ::core::unimplemented!() }
            fn restitution(&self) -> ::moreau::__private::SVector<T, #k> { ::core::unimplemented!() }
            fn parameter(&self, index: usize) -> ::core::option::Option<T> { ::core::unimplemented!() }
            fn parameter_mut(&mut self, index: usize) -> ::core::option::Option<&mut T> { ::core::unimplemented!() }
        }
        #[allow(unused_variables)]
        impl<T: ::moreau::__private::RealField + ::core::marker::Copy> ::moreau::__private::Sensitivities<#n, #k> for #name<T> {
            fn mass_dq(&self, q: &::moreau::__private::SVector<T, #n>, w: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #n, #n> { ::core::unimplemented!() }
            fn jacobian_dq(&self, q: &::moreau::__private::SVector<T, #n>, v: &::moreau::__private::SVector<T, #n>) -> ::moreau::__private::SMatrix<T, #k, #n> { ::core::unimplemented!() }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ctxt::Ctxt;
    use crate::front::{yaml, yaml_tree::YamlSource};
    use crate::{check, lower};

    /// Reads, checks and lowers a shipped model file.
    fn shipped(stem: &str) -> (ModelSpec, Lowered) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
        let path = dir.join(format!("{stem}.yaml"));
        let text = std::fs::read_to_string(&path).unwrap();
        let source = YamlSource {
            display: format!("models/{stem}.yaml"),
            text: text.clone(),
        };
        let root = source.parse().unwrap();
        let cx = Ctxt::with_yaml(source);
        let spec = yaml::build(&cx, &root, Span::call_site(), &path, text).unwrap();
        check::check(&cx, &spec);
        let lowered = lower::lower(&cx, &spec);
        cx.check().unwrap();
        (spec, lowered.unwrap())
    }

    const SHIPPED: [&str; 5] = [
        "parabola",
        "three_balls",
        "billiard",
        "double_pendulum",
        "arm3",
    ];

    /// The fused evaluation of each shipped model, as text, against its
    /// snapshot in `model-macro/snapshots/` (rewrite them with
    /// `UPDATE_SNAPSHOTS=1`, then read the diff).
    #[test]
    fn fused_listing_matches_snapshot() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("snapshots");
        let mut stale = Vec::new();
        for stem in SHIPPED {
            let (spec, lowered) = shipped(stem);
            let text = listing(&spec, &lowered);
            let path = dir.join(format!("{stem}.txt"));
            if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
                std::fs::write(&path, &text).unwrap();
            } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
                stale.push(stem);
            }
        }
        assert!(
            stale.is_empty(),
            "listings changed for {stale:?}; rerun with UPDATE_SNAPSHOTS=1 and review the diff"
        );
    }

    /// The same model emits the same bytes every time (no hash-map order
    /// leaks into the output).
    #[test]
    fn emission_is_deterministic() {
        for stem in SHIPPED {
            let (spec, lowered) = shipped(stem);
            let once = emit(&spec, &lowered).to_string();
            let (spec, lowered) = shipped(stem);
            assert_eq!(once, emit(&spec, &lowered).to_string(), "{stem}");
        }
    }

    #[test]
    fn output_entries_are_named_after_their_slot() {
        let outputs = Outputs::new(3, 1);
        let m21 = Slot {
            quantity: Quantity::Mass,
            row: 2,
            col: 1,
        };
        assert_eq!(describe(outputs.slot(outputs.index(m21))).0, "m_1_2");
        let j02 = Slot {
            quantity: Quantity::Jacobian,
            row: 0,
            col: 2,
        };
        assert_eq!(describe(j02), ("j_0_2".into(), "J[0,2]".into()));
        let g1 = Slot {
            quantity: Quantity::Gravity,
            row: 1,
            col: 0,
        };
        assert_eq!(describe(g1).0, "g_1");
    }

    #[test]
    fn constants_get_short_names() {
        assert_eq!(constant_name(0.5, 0), "k_0_5");
        assert_eq!(constant_name(-1.0, 0), "k_m1");
        assert_eq!(constant_name(0.0, 3), "zero");
        assert_eq!(constant_name(1.0 / 3.0, 7), "k7");
    }
}
