//! Helpers shared by the XML loaders: element lookup, numbers, and errors that name the file,
//! line and column.

use crate::Error;
use roxmltree::{Document, Node};
use std::path::Path;

/// Largest XML file the loaders read (bytes): far above any real scene, small enough that a
/// bogus file cannot exhaust memory.
pub const MAX_XML_BYTES: usize = 512 << 20;

/// An XML document being loaded, for located errors.
pub struct XmlFile<'a, 'input> {
    /// The file's path, for messages.
    pub path: &'a Path,
    /// The parsed document.
    pub doc: &'a Document<'input>,
}

impl<'a, 'input> XmlFile<'a, 'input> {
    /// An error at `node`: file, line, column, element name and message.
    pub fn error(&self, node: Node, message: impl Into<String>) -> Error {
        let pos = self.doc.text_pos_at(node.range().start);
        let what = if node.is_element() {
            format!("<{}>: ", node.tag_name().name())
        } else {
            String::new()
        };
        Error::Parse {
            path: self.path.display().to_string(),
            line: pos.row as usize,
            column: pos.col as usize,
            message: format!("{what}{}", message.into()),
        }
    }

    /// The whitespace-separated numbers in `node`'s text, each finite.
    pub fn floats(&self, node: Node) -> Result<Vec<f32>, Error> {
        let text = node.text().unwrap_or("");
        text.split_ascii_whitespace()
            .map(|t| match t.parse::<f32>() {
                Ok(v) if v.is_finite() => Ok(v),
                Ok(v) => Err(self.error(node, format!("expected a finite number, found {v}"))),
                Err(_) => {
                    Err(self.error(node, format!("expected a number, found '{}'", truncate(t))))
                }
            })
            .collect()
    }

    /// The whitespace-separated non-negative integers in `node`'s text.
    pub fn indices(&self, node: Node) -> Result<Vec<u32>, Error> {
        let text = node.text().unwrap_or("");
        text.split_ascii_whitespace()
            .map(|t| {
                t.parse::<u32>().map_err(|_| {
                    self.error(
                        node,
                        format!(
                            "expected a non-negative integer index, found '{}'",
                            truncate(t)
                        ),
                    )
                })
            })
            .collect()
    }

    /// Exactly `n` numbers from `node`.
    pub fn floats_n(&self, node: Node, n: usize) -> Result<Vec<f32>, Error> {
        let v = self.floats(node)?;
        if v.len() < n {
            return Err(self.error(node, format!("expected {n} numbers, found {}", v.len())));
        }
        Ok(v[..n].to_vec())
    }
}

/// The first child element called `name` (namespace ignored).
pub fn child<'a, 'input>(node: Node<'a, 'input>, name: &str) -> Option<Node<'a, 'input>> {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

/// All child elements called `name`.
pub fn children<'a, 'input: 'a>(
    node: Node<'a, 'input>,
    name: &'a str,
) -> impl Iterator<Item = Node<'a, 'input>> + 'a {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == name)
}

/// The element at a path of child names.
pub fn path<'a, 'input>(node: Node<'a, 'input>, names: &[&str]) -> Option<Node<'a, 'input>> {
    names.iter().try_fold(node, |n, name| child(n, name))
}

/// A token shortened for messages.
pub fn truncate(t: &str) -> String {
    if t.chars().count() > 24 {
        format!("{}...", t.chars().take(24).collect::<String>())
    } else {
        t.to_string()
    }
}

/// Reads a file as text, with errors naming it.
pub fn read_text(path: &Path) -> Result<String, Error> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.len() as usize > MAX_XML_BYTES {
        return Err(Error::Io {
            path: path.display().to_string(),
            message: format!(
                "{} bytes is larger than the {} MiB limit",
                meta.len(),
                MAX_XML_BYTES >> 20
            ),
        });
    }
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    String::from_utf8(bytes).map_err(|e| Error::Io {
        path: path.display().to_string(),
        message: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
    })
}

/// Parses XML text, with errors at the offending line.
pub fn parse_document<'input>(text: &'input str, path: &Path) -> Result<Document<'input>, Error> {
    let options = roxmltree::ParsingOptions {
        allow_dtd: true,
        nodes_limit: 50_000_000,
    };
    Document::parse_with_options(text, options).map_err(|e| {
        let pos = e.pos();
        Error::Parse {
            path: path.display().to_string(),
            line: pos.row as usize,
            column: pos.col as usize,
            message: format!("malformed XML: {e}"),
        }
    })
}
