//! Reads XML text into an owned, located element tree ([`Element`]) with quick-xml's streaming reader.
//!
//! Every element and attribute gets the line and column where it starts, computed from quick-xml's byte offsets.
//! Malformed XML becomes one located [`Diagnostic`]. This module knows nothing about the `.argos` vocabulary.

use std::cell::Cell;
use std::collections::BTreeMap;
use std::path::Path;

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use super::diagnostic::Diagnostic;
use super::model::{Attribute, Element, Location};

/// Deepest element nesting accepted: ARGoS files nest about six deep, and a limit keeps a hostile file from
/// exhausting the stack of whatever walks the tree.
pub const MAX_DEPTH: usize = 256;

/// Maps byte offsets of one text to 1-based line and column (columns count characters, not bytes).
///
/// Offsets are asked for mostly in increasing order, so the last answer is kept: the next column on the same line
/// is counted from there, and locating every element of a file costs time linear in its length even when the
/// whole file is one line.
pub(crate) struct LineIndex<'a> {
    text: &'a str,
    line_starts: Vec<usize>,
    /// The last offset located: (offset, line index, 0-based column).
    last: Cell<(usize, usize, usize)>,
}

impl<'a> LineIndex<'a> {
    /// Indexes the line starts of `text`.
    pub(crate) fn new(text: &'a str) -> Self {
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Self {
            text,
            line_starts,
            last: Cell::new((0, 0, 0)),
        }
    }

    /// The location of a byte offset (clamped to the text).
    pub(crate) fn locate(&self, offset: usize) -> Location {
        let offset = offset.min(self.text.len());
        let line = self.line_starts.partition_point(|&start| start <= offset) - 1;
        let start = self.line_starts[line];
        let (last_offset, last_line, last_column) = self.last.get();
        let (from, base) = if last_line == line && (start..=offset).contains(&last_offset) {
            (last_offset, last_column)
        } else {
            (start, 0)
        };
        let column = self
            .text
            .get(from..offset)
            .map_or(offset - start, |part| base + part.chars().count());
        self.last.set((offset, line, column));
        Location {
            line: to_u32(line + 1),
            column: to_u32(column + 1),
        }
    }
}

fn to_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// Parses `text` (the contents of `path`) into its root element.
pub(crate) fn parse_tree(path: &Path, text: &str) -> Result<Element, Diagnostic> {
    // A byte-order mark is invisible in editors, so columns are counted without it.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let index = LineIndex::new(text);
    let error = |offset: usize, message: String| {
        Diagnostic::new(path.to_path_buf(), index.locate(offset), message)
    };

    let mut reader = Reader::from_str(text);
    let config = reader.config_mut();
    config.check_end_names = true;
    config.trim_text(false);

    // The stack of open elements; the root ends up as the single finished top-level element.
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let event = reader.read_event().map_err(|e| {
            error(
                offset(reader.error_position()),
                format!("malformed XML: {e}"),
            )
        })?;
        let end = offset(reader.buffer_position());
        match event {
            Event::Start(start) => {
                let element =
                    open_element(&start, end, 2, text, &index).map_err(|(at, m)| error(at, m))?;
                if stack.len() >= MAX_DEPTH {
                    return Err(Diagnostic::new(
                        path.to_path_buf(),
                        element.location,
                        format!("<{}> nests deeper than {MAX_DEPTH} elements", element.name),
                    ));
                }
                stack.push(element);
            }
            Event::Empty(start) => {
                let element =
                    open_element(&start, end, 3, text, &index).map_err(|(at, m)| error(at, m))?;
                close_element(element, &mut stack, &mut root).map_err(|m| error(end, m))?;
            }
            Event::End(_) => {
                if let Some(element) = stack.pop() {
                    close_element(element, &mut stack, &mut root).map_err(|m| error(end, m))?;
                }
            }
            Event::Text(t) => {
                let decoded = t
                    .decode()
                    .map_err(|e| error(end, format!("malformed text: {e}")))?;
                push_text(&mut stack, &decoded);
            }
            Event::CData(t) => {
                let decoded = t
                    .decode()
                    .map_err(|e| error(end, format!("malformed CDATA: {e}")))?;
                push_text(&mut stack, &decoded);
            }
            Event::GeneralRef(r) => {
                let name = r
                    .decode()
                    .map_err(|e| error(end, format!("malformed reference: {e}")))?;
                let resolved = resolve_reference(&name)
                    .ok_or_else(|| error(end, format!("unknown entity '&{name};'")))?;
                push_text(&mut stack, &resolved);
            }
            Event::Eof => break,
            Event::Comment(_) | Event::Decl(_) | Event::PI(_) | Event::DocType(_) => {}
        }
    }
    if let Some(open) = stack.last() {
        return Err(Diagnostic::new(
            path.to_path_buf(),
            open.location,
            format!("<{}> is never closed", open.name),
        ));
    }
    root.ok_or_else(|| error(0, "the file contains no XML element".to_string()))
}

/// Resolves `amp`, `lt`, ... and character references `#65` / `#x41`.
fn resolve_reference(name: &str) -> Option<String> {
    if let Some(number) = name.strip_prefix('#') {
        let code = match number.strip_prefix('x') {
            Some(hex) => u32::from_str_radix(hex, 16).ok()?,
            None => number.parse().ok()?,
        };
        return char::from_u32(code).map(String::from);
    }
    quick_xml::escape::resolve_predefined_entity(name).map(str::to_string)
}

fn offset(position: u64) -> usize {
    usize::try_from(position).unwrap_or(usize::MAX)
}

fn push_text(stack: &mut [Element], text: &str) {
    if let Some(top) = stack.last_mut() {
        top.text.push_str(text);
    }
}

fn close_element(
    mut element: Element,
    stack: &mut [Element],
    root: &mut Option<Element>,
) -> Result<(), String> {
    element.text = element.text.trim().to_string();
    match stack.last_mut() {
        Some(parent) => parent.children.push(element),
        None if root.is_none() => *root = Some(element),
        None => {
            return Err(format!(
                "second top-level element <{}>: an XML file has one root",
                element.name
            ));
        }
    }
    Ok(())
}

/// Builds an element from a start tag that ended at byte `end`; `markup` is the number of bytes around the tag's
/// content (`<` and `>`, plus `/` for empty tags). Errors carry a byte offset.
fn open_element(
    start: &BytesStart<'_>,
    end: usize,
    markup: usize,
    text: &str,
    index: &LineIndex<'_>,
) -> Result<Element, (usize, String)> {
    let content_len = start.len();
    let tag_start = end.saturating_sub(content_len + markup);
    let content_start = tag_start + 1;
    let name = std::str::from_utf8(start.name().as_ref())
        .map_err(|e| (tag_start, format!("tag name is not UTF-8: {e}")))?
        .to_string();
    let raw = text
        .get(content_start..content_start + content_len)
        .unwrap_or("");

    let mut attributes: BTreeMap<String, Attribute> = BTreeMap::new();
    let mut cursor = name.len();
    // quick-xml's own duplicate check compares each attribute with every earlier one (quadratic in their
    // number); the map below finds duplicates in logarithmic time instead.
    for attribute in start.attributes().with_checks(false) {
        let attribute = attribute.map_err(|e| {
            let at = match &e {
                quick_xml::events::attributes::AttrError::ExpectedEq(p)
                | quick_xml::events::attributes::AttrError::ExpectedValue(p)
                | quick_xml::events::attributes::AttrError::UnquotedValue(p)
                | quick_xml::events::attributes::AttrError::ExpectedQuote(p, _)
                | quick_xml::events::attributes::AttrError::Duplicated(p, _) => content_start + p,
            };
            (at, format!("malformed attribute in <{name}>: {e}"))
        })?;
        let key = std::str::from_utf8(attribute.key.as_ref())
            .map_err(|e| {
                (
                    tag_start,
                    format!("attribute name in <{name}> is not UTF-8: {e}"),
                )
            })?
            .to_string();
        let value = attribute
            .unescape_value()
            .map_err(|e| (tag_start, format!("bad value of '{key}' in <{name}>: {e}")))?
            .into_owned();
        let (key_at, after) = find_attribute(raw, cursor, &key);
        cursor = after;
        let location = index.locate(content_start + key_at);
        if let Some(first) = attributes.get(&key) {
            return Err((
                content_start + key_at,
                format!(
                    "attribute '{key}' appears twice in <{name}> (first at {})",
                    first.location
                ),
            ));
        }
        attributes.insert(key, Attribute { value, location });
    }
    Ok(Element {
        name,
        attributes,
        children: Vec::new(),
        text: String::new(),
        location: index.locate(tag_start),
    })
}

/// Finds attribute `key` in the raw tag content from `cursor`; returns its offset and the offset after its value.
fn find_attribute(raw: &str, cursor: usize, key: &str) -> (usize, usize) {
    let bytes = raw.as_bytes();
    let mut from = cursor.min(raw.len());
    while let Some(found) = raw.get(from..).and_then(|rest| rest.find(key)) {
        let at = from + found;
        let preceded = at == 0 || bytes[at - 1].is_ascii_whitespace();
        let rest = raw[at + key.len()..].trim_start();
        if preceded && rest.starts_with('=') {
            let value = rest[1..].trim_start();
            let value_start = raw.len() - value.len();
            let after = value
                .chars()
                .next()
                .and_then(|quote| {
                    let width = quote.len_utf8();
                    value[width..]
                        .find(quote)
                        .map(|close| value_start + close + 2 * width)
                })
                .unwrap_or(raw.len());
            return (at, after);
        }
        from = at + key.len();
    }
    (cursor, cursor)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_characters_on_each_line() {
        let text = "ab\n\u{e9}x<y";
        let index = LineIndex::new(text);
        assert_eq!(index.locate(0), Location { line: 1, column: 1 });
        assert_eq!(index.locate(3), Location { line: 2, column: 1 });
        assert_eq!(
            index.locate(text.find('<').unwrap_or(0)),
            Location { line: 2, column: 3 }
        );
    }

    #[test]
    fn columns_are_the_same_in_any_order_of_questions() {
        let text = "<a>\u{e9}<b/>\u{e9}\u{e9}<c/></a>\n<d>\u{e9}<e/></d>";
        let fresh = |offset| LineIndex::new(text).locate(offset);
        let index = LineIndex::new(text);
        let offsets: Vec<usize> = text.char_indices().map(|(i, _)| i).collect();
        for &offset in offsets.iter().chain(offsets.iter().rev()) {
            assert_eq!(index.locate(offset), fresh(offset), "offset {offset}");
        }
    }

    #[test]
    fn nesting_deeper_than_the_limit_is_a_located_error_not_a_stack_overflow() {
        let depth = 100_000;
        let text = format!("{}{}", "<a>".repeat(depth), "</a>".repeat(depth));
        let err = parse_tree(Path::new("deep.argos"), &text).expect_err("too deep");
        assert_eq!(
            err.to_string(),
            format!(
                "deep.argos:1:{}: <a> nests deeper than {MAX_DEPTH} elements",
                3 * MAX_DEPTH + 1
            )
        );
    }

    #[test]
    fn a_duplicated_attribute_is_located_at_its_second_occurrence() {
        let err = parse_tree(Path::new("f.argos"), "<a x=\"1\" y=\"2\" x=\"3\"/>")
            .expect_err("duplicate");
        assert_eq!(
            err.to_string(),
            "f.argos:1:16: attribute 'x' appears twice in <a> (first at 1:4)"
        );
    }

    #[test]
    fn elements_and_attributes_are_located() {
        let text = "<a>\n  <b x=\"1\"  y = '2'/>\n  <c>t &amp; u</c>\n</a>";
        let root = parse_tree(Path::new("f.argos"), text).expect("well-formed");
        assert_eq!(root.location, Location { line: 1, column: 1 });
        let b = &root.children[0];
        assert_eq!(b.location, Location { line: 2, column: 3 });
        assert_eq!(b.attributes["x"].location, Location { line: 2, column: 6 });
        assert_eq!(
            b.attributes["y"].location,
            Location {
                line: 2,
                column: 13
            }
        );
        assert_eq!(b.attributes["y"].value, "2");
        assert_eq!(root.children[1].text, "t & u");
    }

    #[test]
    fn attributes_on_continuation_lines_are_located_there() {
        let text = "<experiment length=\"0\"\n            ticks_per_second=\"10\"/>";
        let root = parse_tree(Path::new("f.argos"), text).expect("well-formed");
        assert_eq!(
            root.attributes["ticks_per_second"].location,
            Location {
                line: 2,
                column: 13
            }
        );
    }

    #[test]
    fn attribute_names_inside_values_do_not_confuse_locations() {
        let text = "<a p=\"q=1\" q=\"2\"/>";
        let root = parse_tree(Path::new("f.argos"), text).expect("well-formed");
        assert_eq!(
            root.attributes["q"].location,
            Location {
                line: 1,
                column: 12
            }
        );
    }

    #[test]
    fn byte_order_mark_and_crlf_are_accepted() {
        let text = "\u{feff}<a>\r\n  <b x=\"1\"/>\r\n</a>\r\n";
        let root = parse_tree(Path::new("f.argos"), text).expect("well-formed");
        assert_eq!(root.children[0].location, Location { line: 2, column: 3 });
    }

    #[test]
    fn mismatched_end_tag_is_a_located_error() {
        let text = "<a>\n  <b>\n  </c>\n</a>";
        let err = parse_tree(Path::new("f.argos"), text).expect_err("ill-formed");
        assert_eq!(err.location.line, 3);
        assert!(err.message.starts_with("malformed XML"), "{}", err.message);
    }

    #[test]
    fn unclosed_element_is_reported_where_it_opens() {
        let text = "<a>\n  <b>\n";
        let err = parse_tree(Path::new("f.argos"), text).expect_err("ill-formed");
        assert_eq!(err.to_string(), "f.argos:2:3: <b> is never closed");
    }
}
