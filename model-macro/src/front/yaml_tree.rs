//! A YAML document as a tree of nodes numbered in document order, read with
//! `yaml_serde`.
//!
//! `yaml_serde` reports positions only in its errors, so a node's line and
//! column are recovered on demand, and only when an error must be reported:
//! [`YamlSource::locate`] parses the text again with a visitor that fails at
//! the wanted node, and the parser stamps that failure with the node's
//! position. Models that compile never pay for it.

use std::cell::Cell;
use std::fmt;

use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};

use crate::expr::fmt_number;
use crate::loc::YamlPos;

/// A YAML node and its index in document order.
#[derive(Clone, Debug)]
pub(crate) struct YNode {
    pub index: usize,
    pub kind: YKind,
}

/// The shapes of a [`YNode`].
#[derive(Clone, Debug)]
pub(crate) enum YKind {
    Str(String),
    Num(f64),
    Bool,
    Null,
    Seq(Vec<YNode>),
    Map(Vec<(YNode, YNode)>),
}

impl YNode {
    /// The node's text if it is a scalar string or number (numbers printed in
    /// the model language's form).
    pub fn scalar_text(&self) -> Option<String> {
        match &self.kind {
            YKind::Str(s) => Some(s.clone()),
            YKind::Num(x) => Some(fmt_number(*x)),
            _ => None,
        }
    }

    /// A short description of the node's shape, for messages.
    pub fn shape(&self) -> &'static str {
        match self.kind {
            YKind::Str(_) => "a string",
            YKind::Num(_) => "a number",
            YKind::Bool => "a boolean",
            YKind::Null => "nothing",
            YKind::Seq(_) => "a list",
            YKind::Map(_) => "a mapping",
        }
    }

    /// This node's position, at the start of its text.
    pub fn pos(&self) -> YamlPos {
        YamlPos {
            node: self.index,
            offset: 0,
        }
    }
}

/// A YAML model file: the path to show in messages and its text.
#[derive(Clone, Debug)]
pub(crate) struct YamlSource {
    pub display: String,
    pub text: String,
}

thread_local! {
    /// Index the next visited node gets.
    static NEXT: Cell<usize> = const { Cell::new(0) };
    /// Index of the node whose visit must fail (to learn its position).
    static PROBE: Cell<usize> = const { Cell::new(usize::MAX) };
}

impl YamlSource {
    /// Parses the whole document into a tree.
    pub fn parse(&self) -> Result<YNode, yaml_serde::Error> {
        NEXT.with(|n| n.set(0));
        PROBE.with(|p| p.set(usize::MAX));
        yaml_serde::from_str(&self.text)
    }

    /// Line and column (both 1-based) and byte index where node `index`
    /// starts.
    pub fn locate(&self, index: usize) -> Option<(usize, usize, usize)> {
        NEXT.with(|n| n.set(0));
        PROBE.with(|p| p.set(index));
        let result = yaml_serde::from_str::<YNode>(&self.text);
        PROBE.with(|p| p.set(usize::MAX));
        let location = result.err()?.location()?;
        Some((location.line(), location.column(), location.index()))
    }

    /// `path:line:column` of a position. The offset into a scalar is added
    /// to the column when the scalar is written on one line (plain or
    /// quoted); for block scalars the position of the scalar is given.
    pub fn describe(&self, pos: YamlPos) -> String {
        let Some((line, column, index)) = self.locate(pos.node) else {
            return self.display.clone();
        };
        let rest = self.text.get(index..).unwrap_or("");
        let line_len = rest.find('\n').unwrap_or(rest.len());
        let (line, column) = match rest.as_bytes().first() {
            Some(b'"' | b'\'') if pos.offset + 1 < line_len => (line, column + 1 + pos.offset),
            Some(b'|' | b'>') => self.in_block(line, pos.offset).unwrap_or((line, column)),
            _ if pos.offset < line_len => (line, column + pos.offset),
            _ => (line, column),
        };
        format!("{}:{line}:{column}", self.display)
    }

    /// Line and column of byte `offset` of a block scalar (`|` or `>`) whose
    /// indicator is on line `line`: its content lines follow, one more
    /// indented, and folded or not, each line break of the source is one
    /// character of the value.
    fn in_block(&self, line: usize, mut offset: usize) -> Option<(usize, usize)> {
        let lines: Vec<&str> = self.text.lines().skip(line).collect();
        let first = lines.iter().find(|l| !l.trim().is_empty())?;
        let indent = first.len() - first.trim_start().len();
        for (i, l) in lines.iter().enumerate() {
            if !l.trim().is_empty() && l.len() - l.trim_start().len() < indent {
                break;
            }
            let content = l.get(indent..).unwrap_or("");
            if offset <= content.len() {
                return Some((line + 1 + i, indent + offset + 1));
            }
            offset -= content.len() + 1;
        }
        None
    }
}

fn next_index<E: de::Error>() -> Result<usize, E> {
    let index = NEXT.with(|n| {
        let i = n.get();
        n.set(i + 1);
        i
    });
    if PROBE.with(|p| p.get()) == index {
        Err(E::custom("located"))
    } else {
        Ok(index)
    }
}

impl<'de> Deserialize<'de> for YNode {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<YNode, D::Error> {
        d.deserialize_any(NodeVisitor)
    }
}

struct NodeVisitor;

impl NodeVisitor {
    fn leaf<E: de::Error>(kind: YKind) -> Result<YNode, E> {
        Ok(YNode {
            index: next_index()?,
            kind,
        })
    }
}

impl<'de> Visitor<'de> for NodeVisitor {
    type Value = YNode;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any YAML value")
    }

    fn visit_str<E: de::Error>(self, s: &str) -> Result<YNode, E> {
        Self::leaf(YKind::Str(s.to_string()))
    }

    fn visit_f64<E: de::Error>(self, x: f64) -> Result<YNode, E> {
        Self::leaf(YKind::Num(x))
    }

    fn visit_i64<E: de::Error>(self, x: i64) -> Result<YNode, E> {
        Self::leaf(YKind::Num(x as f64))
    }

    fn visit_u64<E: de::Error>(self, x: u64) -> Result<YNode, E> {
        Self::leaf(YKind::Num(x as f64))
    }

    fn visit_bool<E: de::Error>(self, _: bool) -> Result<YNode, E> {
        Self::leaf(YKind::Bool)
    }

    fn visit_unit<E: de::Error>(self) -> Result<YNode, E> {
        Self::leaf(YKind::Null)
    }

    fn visit_none<E: de::Error>(self) -> Result<YNode, E> {
        Self::leaf(YKind::Null)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<YNode, A::Error> {
        let index = next_index()?;
        let mut items = Vec::new();
        while let Some(item) = seq.next_element()? {
            items.push(item);
        }
        Ok(YNode {
            index,
            kind: YKind::Seq(items),
        })
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<YNode, A::Error> {
        let index = next_index()?;
        let mut entries = Vec::new();
        while let Some(entry) = map.next_entry()? {
            entries.push(entry);
        }
        Ok(YNode {
            index,
            kind: YKind::Map(entries),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(text: &str) -> YamlSource {
        YamlSource {
            display: "m.yaml".into(),
            text: text.into(),
        }
    }

    #[test]
    fn nodes_are_numbered_in_document_order_and_located() {
        let src = source("name: Ball\ncoordinates:\n  - y: vy\nkinetic: 0.5 * vy^2\n");
        let root = src.parse().unwrap();
        let YKind::Map(entries) = &root.kind else {
            panic!("root is not a map")
        };
        let (key, value) = &entries[2];
        assert_eq!(key.scalar_text().as_deref(), Some("kinetic"));
        assert_eq!(src.locate(value.index).map(|l| (l.0, l.1)), Some((4, 10)));
        // offset 6 into `0.5 * vy^2` is `vy`
        let pos = YamlPos {
            node: value.index,
            offset: 6,
        };
        assert_eq!(src.describe(pos), "m.yaml:4:16");
    }

    #[test]
    fn quoted_scalars_shift_past_the_quote() {
        let src = source("h: \"y - x^2\"\n");
        let root = src.parse().unwrap();
        let YKind::Map(entries) = &root.kind else {
            panic!("root is not a map")
        };
        let pos = YamlPos {
            node: entries[0].1.index,
            offset: 4,
        };
        assert_eq!(src.describe(pos), "m.yaml:1:9");
    }

    #[test]
    fn offsets_into_folded_block_scalars_land_on_their_line() {
        let src = source("kinetic: >-\n  0.5 * m * vx^2\n  + vy^4\n");
        let root = src.parse().unwrap();
        let YKind::Map(entries) = &root.kind else {
            panic!("root is not a map")
        };
        let node = entries[0].1.index;
        // "0.5 * m * vx^2 + vy^4": `vy` is at byte 17, on the third line
        let pos = YamlPos { node, offset: 17 };
        assert_eq!(src.describe(pos), "m.yaml:3:5");
        let pos = YamlPos { node, offset: 10 };
        assert_eq!(src.describe(pos), "m.yaml:2:13");
    }

    #[test]
    fn numbers_keep_their_value() {
        let src = source("a: 1\nb: 2.5\nc: -3\n");
        let root = src.parse().unwrap();
        let YKind::Map(entries) = &root.kind else {
            panic!("root is not a map")
        };
        let values: Vec<String> = entries.iter().map(|e| e.1.scalar_text().unwrap()).collect();
        assert_eq!(values, ["1", "2.5", "-3"]);
    }
}
