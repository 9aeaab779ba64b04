//! Error collection: every stage pushes its problems here and carries on, so
//! that a model with five mistakes reports five errors at once (the pattern of
//! `serde_derive`'s `Ctxt`).

use std::cell::RefCell;

use proc_macro2::Span;

use crate::front::yaml_tree::YamlSource;

/// Where something in a model came from.
///
/// Inline models carry the token's span. YAML models carry the span of the
/// `file = "..."` literal plus the YAML node and the byte offset inside its
/// scalar; the node's line and column are recovered only when an error is
/// reported (see [`YamlSource::locate`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Loc {
    pub span: Span,
    pub node: Option<YamlPos>,
}

/// A position inside a YAML document: the node's index in document order and
/// a byte offset into its scalar text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct YamlPos {
    pub node: usize,
    pub offset: usize,
}

impl Loc {
    /// A location inside inline tokens.
    pub fn span(span: Span) -> Self {
        Loc { span, node: None }
    }

    /// The same location moved `offset` bytes further into its scalar (for
    /// tokens of a YAML expression). Inline locations are unchanged.
    pub fn shifted(self, offset: usize) -> Self {
        Loc {
            span: self.span,
            node: self.node.map(|p| YamlPos {
                node: p.node,
                offset: p.offset + offset,
            }),
        }
    }
}

/// The error collector shared, by reference, by every stage.
pub(crate) struct Ctxt {
    errors: RefCell<Option<Vec<(Loc, String)>>>,
    yaml: Option<YamlSource>,
}

impl Ctxt {
    /// A collector for an inline model.
    pub fn new() -> Self {
        Ctxt {
            errors: RefCell::new(Some(Vec::new())),
            yaml: None,
        }
    }

    /// A collector for a model read from YAML: errors are prefixed with
    /// `path:line:column`.
    pub fn with_yaml(source: YamlSource) -> Self {
        Ctxt {
            errors: RefCell::new(Some(Vec::new())),
            yaml: Some(source),
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
            let text = match (&self.yaml, loc.node) {
                (Some(yaml), Some(pos)) => format!("{}: {message}", yaml.describe(pos)),
                (Some(yaml), None) => format!("{}: {message}", yaml.display),
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
