//! A small located element tree built with quick-xml's streaming reader, shared by the model readers.
//!
//! It checks well-formedness only (code `X1`, with the position quick-xml reports) and keeps the line:column of every
//! element and attribute. It knows nothing about models; the readers interpret the tree.

use quick_xml::Reader;
use quick_xml::events::attributes::AttrError;
use quick_xml::events::{BytesStart, Event};

use crate::diagnostics::{Code, Diagnostic, LineIndex, Position};
use crate::source::Located;

/// One attribute: its name, unescaped value and the position of its name.
#[derive(Debug, Clone)]
pub(crate) struct Attr {
    pub key: String,
    pub value: Located<String>,
}

/// One element with its attributes, child elements and any non-whitespace text directly inside it.
#[derive(Debug, Clone)]
pub(crate) struct Element {
    pub name: String,
    pub at: Position,
    pub attrs: Vec<Attr>,
    pub children: Vec<Element>,
    pub text: Option<Located<String>>,
}

impl Element {
    /// The value of attribute `key`, if present.
    pub fn attr(&self, key: &str) -> Option<&Located<String>> {
        self.attrs.iter().find(|a| a.key == key).map(|a| &a.value)
    }
}

/// Deepest element nesting accepted: models nest four deep, and a limit keeps a hostile file from exhausting the
/// stack of whatever walks (or drops) the tree.
pub const MAX_DEPTH: usize = 256;

/// Parses `text` into its root element, or the first well-formedness error as an `X1` diagnostic.
pub(crate) fn parse(file: &str, text: &str) -> Result<Element, Diagnostic> {
    let index = LineIndex::new(text);
    let x1 = |at: Position, message: String| Diagnostic::new(Code::X1, file, at, message);
    let mut reader = Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let event = match reader.read_event() {
            Ok(event) => event,
            Err(err) => {
                let offset = usize::try_from(reader.error_position()).unwrap_or(usize::MAX);
                return Err(x1(index.position(offset), format!("malformed XML: {err}")));
            }
        };
        match event {
            Event::Start(start) => {
                let element = element(file, &index, &start)?;
                if root.is_some() {
                    return Err(x1(element.at, "content after the root element".into()));
                }
                if stack.len() >= MAX_DEPTH {
                    return Err(x1(
                        element.at,
                        format!(
                            "`<{}>` nests deeper than {MAX_DEPTH} elements",
                            element.name
                        ),
                    ));
                }
                stack.push(element);
            }
            Event::Empty(start) => {
                let element = element(file, &index, &start)?;
                match stack.last_mut() {
                    Some(parent) => parent.children.push(element),
                    None if root.is_none() => root = Some(element),
                    None => return Err(x1(element.at, "content after the root element".into())),
                }
            }
            Event::End(_) => {
                // quick-xml checks that end names match, so the stack is never empty here.
                if let Some(done) = stack.pop() {
                    match stack.last_mut() {
                        Some(parent) => parent.children.push(done),
                        None => root = Some(done),
                    }
                }
            }
            Event::Text(t) => {
                let at = index.position_of(t.as_ref());
                let value = t
                    .decode()
                    .map_err(|e| x1(at, format!("malformed text: {e}")))?
                    .into_owned();
                match stack.last_mut() {
                    Some(parent) => {
                        parent.text.get_or_insert(Located { value, at });
                    }
                    None => return Err(x1(at, "text outside the root element".into())),
                }
            }
            Event::CData(c) => {
                let at = index.position_of(c.as_ref());
                if let Some(parent) = stack.last_mut() {
                    let value = String::from_utf8_lossy(c.as_ref()).into_owned();
                    parent.text.get_or_insert(Located { value, at });
                }
            }
            Event::GeneralRef(r) => {
                let at = index.position_of(r.as_ref());
                if let Some(parent) = stack.last_mut() {
                    let value = String::from_utf8_lossy(r.as_ref()).into_owned();
                    parent.text.get_or_insert(Located { value, at });
                }
            }
            Event::Eof => break,
            Event::Decl(_) | Event::PI(_) | Event::DocType(_) | Event::Comment(_) => {}
        }
    }
    if let Some(open) = stack.first() {
        let innermost = stack.last().unwrap_or(open);
        return Err(x1(
            innermost.at,
            format!("element `<{}>` is never closed", innermost.name),
        ));
    }
    root.ok_or_else(|| {
        x1(
            index.position(text.len()),
            "the file has no root element".into(),
        )
    })
}

/// Builds an element (without children) from a start tag, reading its attributes with positions.
fn element(
    file: &str,
    index: &LineIndex<'_>,
    start: &BytesStart<'_>,
) -> Result<Element, Diagnostic> {
    let content: &[u8] = start.as_ref();
    let tag_at = index.position_of(content);
    // The tag content starts right after `<`.
    let at = Position {
        line: tag_at.line,
        column: tag_at.column.saturating_sub(1).max(1),
    };
    let name = String::from_utf8_lossy(start.name().as_ref()).into_owned();
    let base = index.offset_of(content);
    let mut attrs = Vec::new();
    for attr in start.attributes() {
        let attr = attr.map_err(|e| {
            let (rel, what) = match e {
                AttrError::ExpectedEq(p) => (p, "attribute name is not followed by `=`"),
                AttrError::ExpectedValue(p) => (p, "attribute has no value after `=`"),
                AttrError::UnquotedValue(p) => (p, "attribute value is not enclosed in quotes"),
                AttrError::ExpectedQuote(p, _) => (p, "attribute value has no closing quote"),
                AttrError::Duplicated(p, _) => (p, "attribute appears twice"),
            };
            Diagnostic::new(
                Code::X1,
                file,
                index.position(base + rel),
                format!("malformed attribute in `<{name}>`: {what}"),
            )
        })?;
        let key_at = index.position_of(attr.key.as_ref());
        let key = String::from_utf8_lossy(attr.key.as_ref()).into_owned();
        let value = attr
            .unescape_value()
            .map_err(|e| {
                Diagnostic::new(
                    Code::X1,
                    file,
                    key_at,
                    format!("malformed value of attribute `{key}`: {e}"),
                )
            })?
            .into_owned();
        attrs.push(Attr {
            key,
            value: Located { value, at: key_at },
        });
    }
    Ok(Element {
        name,
        at,
        attrs,
        children: Vec::new(),
        text: None,
    })
}
