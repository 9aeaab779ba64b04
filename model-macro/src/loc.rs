//! Where something in a model came from: a span for inline tokens, a node
//! and offset for YAML. Every stage carries these; only the error context
//! turns them into messages.

use proc_macro2::Span;

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
