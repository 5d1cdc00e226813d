//! The parsed document with its spans: turns byte offsets and key paths into [`Location`]s.
//!
//! The text is parsed once into toml's span-carrying [`DeTable`]; the raw serde types are
//! deserialized from (a clone of) that tree, and the tree is kept so that:
//! - a serde error, which carries only a byte span, can be given its key path, and
//! - a validation error, which knows only its key path, can be given its line:col and the
//!   value exactly as written in the file.

use std::ops::Range;
use std::path::Path;

use serde::Deserialize;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

use crate::error::{ConfigError, LineCol, Location};
use crate::raw::RawFile;

/// The text of one configuration file, its name, and its parse tree with spans.
pub(crate) struct Source<'a> {
    text: &'a str,
    origin: &'a Path,
    doc: Spanned<DeTable<'a>>,
}

impl<'a> Source<'a> {
    /// Parses the TOML syntax. Errors are [`ConfigError::Syntax`].
    pub fn parse(text: &'a str, origin: &'a Path) -> Result<Self, ConfigError> {
        match DeTable::parse(text) {
            Ok(doc) => Ok(Source { text, origin, doc }),
            Err(e) => Err(ConfigError::Syntax {
                at: Location {
                    file: origin.to_path_buf(),
                    line_col: e.span().map(|s| LineCol::of_offset(text, s.start)),
                },
                message: e.message().trim_end().to_owned(),
            }),
        }
    }

    /// The file's name as given.
    pub fn origin(&self) -> &'a Path {
        self.origin
    }

    /// Deserializes the raw types. Errors are [`ConfigError::Schema`] with the key path.
    pub fn raw(&self) -> Result<RawFile, ConfigError> {
        let de = toml::de::Deserializer::from(self.doc.clone());
        RawFile::deserialize(de).map_err(|e| {
            // Errors about the document itself (a missing top-level table) carry the root
            // table's span, which is empty: report them without position or key.
            let (at, key) = match e.span() {
                Some(span) if span != self.doc.span() => {
                    (self.at_offset(span.start), self.key_path_at(span.start))
                }
                _ => (self.at(None), String::new()),
            };
            ConfigError::Schema {
                at,
                key,
                message: e.message().trim_end().to_owned(),
            }
        })
    }

    fn at(&self, line_col: Option<LineCol>) -> Location {
        Location {
            file: self.origin.to_path_buf(),
            line_col,
        }
    }

    fn at_offset(&self, offset: usize) -> Location {
        self.at(Some(LineCol::of_offset(self.text, offset)))
    }

    /// Location of the value at `path`; if the path does not exist, of its deepest existing
    /// ancestor (so a missing key points at its table); tables point at their key.
    pub fn locate(&self, path: &[&str]) -> Location {
        let mut table = self.doc.get_ref();
        let mut best: Option<Range<usize>> = None;
        let mut i = 0;
        while let Some(seg) = path.get(i) {
            let Some((key, value)) = table.get_key_value(*seg) else {
                break;
            };
            best = Some(key.span());
            i += 1;
            let mut value = value;
            // An array of tables (`[[bus]]`) is entered by the index that follows its key.
            if let DeValue::Array(items) = value.get_ref() {
                match path
                    .get(i)
                    .and_then(|ix| ix.parse::<usize>().ok())
                    .and_then(|ix| items.get(ix))
                {
                    Some(item) => {
                        value = item;
                        best = Some(item.span());
                        i += 1;
                    }
                    None => {
                        best = Some(value.span());
                        break;
                    }
                }
            }
            match value.get_ref() {
                DeValue::Table(inner) => table = inner,
                _ => {
                    best = Some(value.span());
                    break;
                }
            }
        }
        match best {
            Some(span) => self.at_offset(span.start),
            None => self.at(None),
        }
    }

    /// The value at `path` exactly as written, if it is on one line.
    pub fn written(&self, path: &[&str]) -> Option<String> {
        let mut table = self.doc.get_ref();
        let mut i = 0;
        loop {
            let value = table.get(*path.get(i)?)?;
            i += 1;
            let value = match value.get_ref() {
                DeValue::Array(items) if i < path.len() => {
                    let item = items.get(path[i].parse::<usize>().ok()?)?;
                    i += 1;
                    item
                }
                _ => value,
            };
            if i == path.len() {
                let text = self.text.get(value.span())?;
                return (!text.contains('\n')).then(|| text.to_owned());
            }
            table = value.get_ref().as_table()?;
        }
    }

    /// Dotted key path of the deepest key or value containing byte `offset`, with `[i]` for
    /// array elements; empty if the offset is in no key or value.
    fn key_path_at(&self, offset: usize) -> String {
        let mut path = String::new();
        descend_table(self.doc.get_ref(), offset, &mut path);
        path
    }
}

fn contains(span: &Range<usize>, offset: usize) -> bool {
    span.contains(&offset) || (span.is_empty() && span.start == offset)
}

fn descend_table(table: &DeTable<'_>, offset: usize, path: &mut String) {
    for (key, value) in table.iter() {
        if contains(&key.span(), offset) {
            push_key(path, key.get_ref());
            return;
        }
        if contains(&value.span(), offset) || is_header_table(value, offset) {
            push_key(path, key.get_ref());
            descend_value(value.get_ref(), offset, path);
            return;
        }
    }
}

/// A `[header]` table's span covers only its header, not its keys: also descend into it when
/// one of its entries contains the offset.
fn is_header_table(value: &Spanned<DeValue<'_>>, offset: usize) -> bool {
    match value.get_ref() {
        DeValue::Table(t) => t.iter().any(|(k, v)| {
            contains(&k.span(), offset) || contains(&v.span(), offset) || is_header_table(v, offset)
        }),
        _ => false,
    }
}

fn descend_value(value: &DeValue<'_>, offset: usize, path: &mut String) {
    match value {
        DeValue::Table(t) => descend_table(t, offset, path),
        DeValue::Array(items) => {
            if let Some((i, item)) = items
                .iter()
                .enumerate()
                .find(|(_, v)| contains(&v.span(), offset))
            {
                path.push_str(&format!("[{i}]"));
                descend_value(item.get_ref(), offset, path);
            }
        }
        _ => {}
    }
}

fn push_key(path: &mut String, key: &str) {
    if !path.is_empty() {
        path.push('.');
    }
    path.push_str(key);
}
