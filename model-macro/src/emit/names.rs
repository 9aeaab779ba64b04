//! What a name in the generated code stands for, and the printed names.
//!
//! A binding of the generated code is a [`Local`]: a model variable under
//! the user's own name, a constant, an output entry, a function of one
//! variable (a "role": `sin_th1`, `th1_sq`) or an anonymous temporary. Each
//! gets a readable name ([`Local::readable`]) and [`Names`] prints it:
//! the readable name if nothing else printed so far, no user name and no
//! argument of the method already has it, else that name with the first
//! free suffix `_2`, `_3`, ... Every printed name is checked against the
//! set of names taken, so two locals can never print the same name, and no
//! local prints a user's name, by construction and whatever the user's
//! names are (`sin_x` and `x_sq` give `sin_x_sq` once, then `sin_x_sq_2`).

use std::collections::{HashMap, HashSet};

use moreau_sym::{Func, Slot};

use crate::expr::fmt_number;
use crate::resolve::Resolved;
use crate::scope::Var;

/// A binding of a generated method body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Local {
    /// A model variable, printed as the user named it.
    Var(Var),
    /// The `i`-th constant of the body.
    Const(usize),
    /// An output entry (`m_0_1` for `M[0,1]`).
    Output(Slot),
    /// A function of one variable, named after it.
    Role(Role, Var),
    /// The `i`-th anonymous shared temporary (`a0`, `a1`, ...).
    Temp(usize),
    /// `sin` or `cos` of the `i`-th temporary (`sin_a1`), bound by a
    /// `sin_cos`.
    TempFunc(Func, usize),
}

/// What a role local computes from its variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Role {
    /// `f(x)`: `sin_x`.
    Func(Func),
    /// `x^2`: `x_sq`.
    Square,
    /// `x^3`: `x_cube`.
    Cube,
}

impl Local {
    /// The name this local would like to print as. `value` is the value of
    /// a constant (ignored for other locals).
    pub fn readable(self, model: &Resolved<'_>, value: f64) -> String {
        match self {
            Local::Var(var) => model.var_name(var).to_string(),
            Local::Const(i) => constant_name(value, i),
            Local::Output(slot) => {
                let stem = slot.quantity.stem();
                if slot.quantity.is_vector() {
                    format!("{stem}_{}", slot.row)
                } else {
                    format!("{stem}_{}_{}", slot.row, slot.col)
                }
            }
            Local::Role(Role::Func(f), var) => format!("{}_{}", f.name(), model.var_name(var)),
            Local::Role(Role::Square, var) => format!("{}_sq", model.var_name(var)),
            Local::Role(Role::Cube, var) => format!("{}_cube", model.var_name(var)),
            Local::Temp(i) => format!("a{i}"),
            Local::TempFunc(f, i) => format!("{}_a{i}", f.name()),
        }
    }
}

/// `k_0_5` for 0.5, `k_2` for 2, `k_m1` for -1; `k<index>` when the value
/// has no short name.
pub(crate) fn constant_name(c: f64, index: usize) -> String {
    match c {
        0.0 => return "zero".into(),
        1.0 => return "one".into(),
        _ => {}
    }
    let text = fmt_number(c);
    if text.len() <= 8 && !text.contains('e') && c.is_finite() {
        format!("k_{}", text.replace('-', "m").replace('.', "_"))
    } else {
        format!("k{index}")
    }
}

/// The printed names of one method body: injective over its locals and
/// disjoint from every user name and every argument name.
pub(crate) struct Names {
    printed: HashMap<Local, String>,
    taken: HashSet<String>,
}

/// The methods' arguments and the type parameter: no local prints as one.
const ARGUMENTS: [&str; 6] = ["q", "v", "t", "u", "T", "self"];

impl Names {
    /// A fresh table for a body of `model`: every user name is taken (and
    /// printed as itself), and so are the methods' argument names.
    pub fn new(model: &Resolved<'_>) -> Names {
        let mut names = Names {
            printed: HashMap::new(),
            taken: ARGUMENTS.iter().map(|s| (*s).to_string()).collect(),
        };
        let spec = model.spec;
        for (name, _) in spec.declared() {
            names.taken.insert(name.text.clone());
        }
        let l = model.layout;
        let vars = (0..l.n)
            .flat_map(|i| [Var::Coordinate(i), Var::Velocity(i)])
            .chain((0..l.inputs).map(Var::Input))
            .chain((0..l.parameters).map(Var::Parameter))
            .chain([Var::Time]);
        for var in vars {
            names
                .printed
                .insert(Local::Var(var), model.var_name(var).to_string());
        }
        names
    }

    /// Gives `local` its printed name: `readable` if free, else the first
    /// free `readable_2`, `readable_3`, ... A local declared twice keeps its
    /// first name.
    pub fn declare(&mut self, local: Local, readable: String) -> &str {
        if !self.printed.contains_key(&local) {
            let name = if self.taken.contains(&readable) {
                (2..)
                    .map(|i| format!("{readable}_{i}"))
                    .find(|c| !self.taken.contains(c))
                    .unwrap_or_default()
            } else {
                readable
            };
            self.taken.insert(name.clone());
            self.printed.insert(local, name);
        }
        &self.printed[&local]
    }

    /// The printed name of a declared local (user names are declared from
    /// the start).
    pub fn get(&self, local: Local) -> &str {
        self.printed.get(&local).map_or("", String::as_str)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_get_short_names() {
        assert_eq!(constant_name(0.5, 0), "k_0_5");
        assert_eq!(constant_name(-1.0, 0), "k_m1");
        assert_eq!(constant_name(0.0, 3), "zero");
        assert_eq!(constant_name(1.0 / 3.0, 7), "k7");
    }
}
