//! A small interpreter for the Rust the macro emits, independent of the
//! emitter: it parses the generated tokens with `syn` and evaluates one
//! method's body by the names printed in it.
//!
//! Names are looked up as text, innermost `let` first, so two bindings
//! that print the same name shadow each other here exactly as they would in
//! rustc. The method's own arguments (`q`, `v`, `t`, `u`) are only ever
//! indexed or read before any binding of the same name, which is how the
//! emitter uses them; anything else it meets is an error, not a guess.

use std::collections::HashMap;

use syn::{BinOp, Expr, ImplItem, Item, Lit, Pat, Stmt, UnOp};

/// A value of the generated code.
#[derive(Clone, Debug)]
pub(crate) enum Value {
    Num(f64),
    /// A column-major matrix (`SMatrix::from_array_storage`).
    Mat {
        rows: usize,
        cols: usize,
        data: Vec<f64>,
    },
    Array(Vec<Value>),
    Tuple(Vec<Value>),
    Struct(Vec<(String, Value)>),
}

impl Value {
    fn num(&self) -> Result<f64, String> {
        match self {
            Value::Num(x) => Ok(*x),
            other => Err(format!("expected a number, found {other:?}")),
        }
    }

    /// Every matrix inside, in order, as `(rows, cols, column-major data)`.
    pub fn matrices(&self) -> Vec<(usize, usize, Vec<f64>)> {
        match self {
            Value::Mat { rows, cols, data } => vec![(*rows, *cols, data.clone())],
            Value::Tuple(items) | Value::Array(items) => {
                items.iter().flat_map(Value::matrices).collect()
            }
            Value::Struct(fields) => fields.iter().flat_map(|(_, v)| v.matrices()).collect(),
            Value::Num(_) => Vec::new(),
        }
    }
}

/// The methods of the generated `impl`s, by name.
pub(crate) struct Methods {
    methods: HashMap<String, syn::ImplItemFn>,
}

impl Methods {
    /// Parses the macro's output and keeps the methods of its trait impls.
    pub fn parse(tokens: proc_macro2::TokenStream) -> Result<Methods, String> {
        let file: syn::File = syn::parse2(tokens).map_err(|e| e.to_string())?;
        let mut methods = HashMap::new();
        for item in file.items {
            if let Item::Impl(imp) = item
                && imp.trait_.is_some()
            {
                for it in imp.items {
                    if let ImplItem::Fn(f) = it {
                        methods.insert(f.sig.ident.to_string(), f);
                    }
                }
            }
        }
        Ok(Methods { methods })
    }

    /// The `let` names of method `name`, in order.
    pub fn bindings(&self, name: &str) -> Vec<String> {
        let Some(f) = self.methods.get(name) else {
            return Vec::new();
        };
        f.block
            .stmts
            .iter()
            .filter_map(|s| match s {
                Stmt::Local(l) => pat_name(&l.pat),
                _ => None,
            })
            .collect()
    }

    /// Calls method `name` with the arguments `args` (`q`, `v`, `t`, `u` as
    /// vectors) and the parameter fields `fields` of `self`.
    pub fn call(
        &self,
        name: &str,
        args: &[(&str, Vec<f64>)],
        fields: &[(String, f64)],
    ) -> Result<Value, String> {
        let f = self
            .methods
            .get(name)
            .ok_or_else(|| format!("no method `{name}`"))?;
        let mut env = Env {
            args,
            fields,
            lets: Vec::new(),
        };
        let mut last = None;
        for stmt in &f.block.stmts {
            match stmt {
                Stmt::Local(l) => {
                    let init = l.init.as_ref().ok_or("let without a value")?;
                    let v = env.eval(&init.expr)?;
                    match (&l.pat, v) {
                        (Pat::Tuple(t), Value::Tuple(vs)) if t.elems.len() == vs.len() => {
                            for (p, v) in t.elems.iter().zip(vs) {
                                let n = pat_name(p).ok_or("unsupported pattern")?;
                                env.lets.push((n, v));
                            }
                        }
                        (pat, v) => {
                            let n = pat_name(pat).ok_or("unsupported pattern")?;
                            env.lets.push((n, v));
                        }
                    }
                }
                Stmt::Expr(e, None) => last = Some(env.eval(e)?),
                _ => return Err("unsupported statement".into()),
            }
        }
        last.ok_or_else(|| "no result".to_string())
    }
}

fn pat_name(p: &Pat) -> Option<String> {
    match p {
        Pat::Ident(i) => Some(i.ident.to_string()),
        Pat::Type(t) => pat_name(&t.pat),
        _ => None,
    }
}

struct Env<'a> {
    args: &'a [(&'a str, Vec<f64>)],
    fields: &'a [(String, f64)],
    lets: Vec<(String, Value)>,
}

impl Env<'_> {
    fn lookup(&self, name: &str) -> Result<Value, String> {
        if let Some((_, v)) = self.lets.iter().rev().find(|(n, _)| n == name) {
            return Ok(v.clone());
        }
        match self.args.iter().find(|(n, _)| *n == name) {
            Some((_, v)) if v.len() == 1 && name == "t" => Ok(Value::Num(v[0])),
            Some(_) => Err(format!("argument `{name}` used whole")),
            None => Err(format!("unbound name `{name}`")),
        }
    }

    fn eval(&mut self, e: &Expr) -> Result<Value, String> {
        match e {
            Expr::Lit(l) => match &l.lit {
                Lit::Float(f) => Ok(Value::Num(f.base10_parse().map_err(|e| e.to_string())?)),
                Lit::Int(i) => Ok(Value::Num(
                    i.base10_parse::<i64>().map_err(|e| e.to_string())? as f64,
                )),
                _ => Err("unsupported literal".into()),
            },
            Expr::Path(p) => {
                let name = p
                    .path
                    .segments
                    .last()
                    .ok_or("empty path")?
                    .ident
                    .to_string();
                self.lookup(&name)
            }
            Expr::Paren(p) => self.eval(&p.expr),
            Expr::Unary(u) => match u.op {
                UnOp::Neg(_) => Ok(Value::Num(-self.eval(&u.expr)?.num()?)),
                _ => Err("unsupported unary operator".into()),
            },
            Expr::Binary(b) => {
                let (x, y) = (self.eval(&b.left)?.num()?, self.eval(&b.right)?.num()?);
                Ok(Value::Num(match b.op {
                    BinOp::Add(_) => x + y,
                    BinOp::Sub(_) => x - y,
                    BinOp::Mul(_) => x * y,
                    BinOp::Div(_) => x / y,
                    _ => return Err("unsupported binary operator".into()),
                }))
            }
            Expr::MethodCall(m) => self.method(m),
            Expr::Call(c) => self.call(c),
            Expr::Array(a) => Ok(Value::Array(
                a.elems
                    .iter()
                    .map(|x| self.eval(x))
                    .collect::<Result<_, _>>()?,
            )),
            Expr::Tuple(t) => Ok(Value::Tuple(
                t.elems
                    .iter()
                    .map(|x| self.eval(x))
                    .collect::<Result<_, _>>()?,
            )),
            Expr::Struct(s) => {
                let mut fields = Vec::new();
                for f in &s.fields {
                    let syn::Member::Named(name) = &f.member else {
                        return Err("unnamed field".into());
                    };
                    fields.push((name.to_string(), self.eval(&f.expr)?));
                }
                Ok(Value::Struct(fields))
            }
            Expr::Index(i) => {
                let Expr::Path(p) = &*i.expr else {
                    return Err("index of a non-name".into());
                };
                let name = p.path.get_ident().ok_or("index of a path")?.to_string();
                let k = self.eval(&i.index)?.num()? as usize;
                let (_, v) = self
                    .args
                    .iter()
                    .find(|(n, _)| *n == name)
                    .ok_or_else(|| format!("`{name}` is not an argument"))?;
                v.get(k)
                    .map(|&x| Value::Num(x))
                    .ok_or_else(|| format!("{name}[{k}] out of range"))
            }
            Expr::Field(f) => {
                let syn::Member::Named(name) = &f.member else {
                    return Err("unnamed field".into());
                };
                let name = name.to_string();
                self.fields
                    .iter()
                    .find(|(n, _)| *n == name)
                    .map(|(_, x)| Value::Num(*x))
                    .ok_or_else(|| format!("no field `{name}`"))
            }
            other => Err(format!(
                "unsupported expression `{}`",
                quote::quote!(#other)
            )),
        }
    }

    fn method(&mut self, m: &syn::ExprMethodCall) -> Result<Value, String> {
        let x = self.eval(&m.receiver)?.num()?;
        let args: Vec<f64> = m
            .args
            .iter()
            .map(|a| self.eval(a).and_then(|v| v.num()))
            .collect::<Result<_, _>>()?;
        let method = m.method.to_string();
        let one = |f: fn(f64) -> f64| Ok(Value::Num(f(x)));
        match (method.as_str(), args.as_slice()) {
            ("sin", []) => one(f64::sin),
            ("cos", []) => one(f64::cos),
            ("sin_cos", []) => Ok(Value::Tuple(vec![Value::Num(x.sin()), Value::Num(x.cos())])),
            ("tan", []) => one(f64::tan),
            ("sqrt", []) => one(f64::sqrt),
            ("exp", []) => one(f64::exp),
            ("ln", []) => one(f64::ln),
            ("sinh", []) => one(f64::sinh),
            ("cosh", []) => one(f64::cosh),
            ("tanh", []) => one(f64::tanh),
            ("powi", [n]) => Ok(Value::Num(x.powi(*n as i32))),
            ("powf", [y]) => Ok(Value::Num(x.powf(*y))),
            ("atan2", [y]) => Ok(Value::Num(x.atan2(*y))),
            _ => Err(format!("unsupported method `{method}`")),
        }
    }

    fn call(&mut self, c: &syn::ExprCall) -> Result<Value, String> {
        let Expr::Path(p) = &*c.func else {
            return Err("call of a non-path".into());
        };
        let f = p
            .path
            .segments
            .last()
            .ok_or("empty path")?
            .ident
            .to_string();
        let mut args: Vec<Value> = c
            .args
            .iter()
            .map(|a| self.eval(a))
            .collect::<Result<_, _>>()?;
        match (f.as_str(), args.len()) {
            ("cst" | "ArrayStorage", 1) => Ok(args.remove(0)),
            // the runtime's trigonometry for the model's scalar
            ("sin", 1) => Ok(Value::Num(args.remove(0).num()?.sin())),
            ("cos", 1) => Ok(Value::Num(args.remove(0).num()?.cos())),
            ("sin_cos", 1) => {
                let x = args.remove(0).num()?;
                Ok(Value::Tuple(vec![Value::Num(x.sin()), Value::Num(x.cos())]))
            }
            ("from_array_storage", 1) => {
                let Value::Array(columns) = args.remove(0) else {
                    return Err("storage is not an array".into());
                };
                let cols = columns.len();
                let mut data = Vec::new();
                let mut rows = 0;
                for col in columns {
                    let Value::Array(entries) = col else {
                        return Err("column is not an array".into());
                    };
                    rows = entries.len();
                    for x in entries {
                        data.push(x.num()?);
                    }
                }
                Ok(Value::Mat { rows, cols, data })
            }
            _ => Err(format!("unsupported call `{f}`")),
        }
    }
}
