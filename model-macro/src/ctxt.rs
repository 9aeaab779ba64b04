//! Error collection: every stage pushes its problems here and carries on, so
//! that a model with five mistakes reports five errors at once (the pattern of
//! `serde_derive`'s `Ctxt`).

use std::cell::RefCell;

use crate::loc::{Loc, YamlPos};

/// Turns a YAML position into `path:line:column`; the YAML front end hands
/// one to the context as a value, so that this module knows nothing of YAML.
pub(crate) trait Locate {
    /// `path:line:column` of `pos`.
    fn describe(&self, pos: YamlPos) -> String;
    /// The file's path as shown to the user.
    fn display(&self) -> &str;
}

/// The error collector shared, by reference, by every stage.
pub(crate) struct Ctxt {
    errors: RefCell<Option<Vec<(Loc, String)>>>,
    locator: Option<Box<dyn Locate>>,
}

impl Ctxt {
    /// A collector for an inline model.
    pub fn new() -> Self {
        Ctxt {
            errors: RefCell::new(Some(Vec::new())),
            locator: None,
        }
    }

    /// A collector for a model read from a file: errors are prefixed with
    /// `path:line:column` by `locator`.
    pub fn with_locator(locator: impl Locate + 'static) -> Self {
        Ctxt {
            errors: RefCell::new(Some(Vec::new())),
            locator: Some(Box::new(locator)),
        }
    }

    /// Records an error at `loc` and carries on.
    pub fn error(&self, loc: Loc, message: impl Into<String>) {
        self.errors
            .borrow_mut()
            .as_mut()
            .expect("Ctxt used after check")
            .push((loc, message.into()));
    }

    /// Whether any error has been recorded so far.
    pub fn has_errors(&self) -> bool {
        self.errors.borrow().as_ref().is_some_and(|e| !e.is_empty())
    }

    /// Folds every recorded error into one `syn::Error` (in the order they
    /// were found), or `Ok` when there is none.
    pub fn check(self) -> syn::Result<()> {
        let errors = self.errors.borrow_mut().take().unwrap_or_default();
        let mut combined: Option<syn::Error> = None;
        for (loc, message) in errors {
            let text = match (&self.locator, loc.node) {
                (Some(file), Some(pos)) => format!("{}: {message}", file.describe(pos)),
                (Some(file), None) => format!("{}: {message}", file.display()),
                _ => message,
            };
            let error = syn::Error::new(loc.span, text);
            match &mut combined {
                Some(all) => all.combine(error),
                None => combined = Some(error),
            }
        }
        combined.map_or(Ok(()), Err)
    }
}

impl Drop for Ctxt {
    fn drop(&mut self) {
        if !std::thread::panicking() && self.errors.borrow().is_some() {
            panic!("forgot to check for errors");
        }
    }
}
