//! A `.argos` text with the byte spans of its elements and attribute values, so that [`Address`]es can be
//! matched and values replaced in place: everything else in the file (comments, layout, order) stays as written,
//! and a derived configuration differs from its base only where a factor set a value.
//!
//! This module never interprets the `.argos` vocabulary; the configuration parser validates the result.

use std::ops::Range;

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};

use super::address::{Address, Predicate, Step};

/// One element of the document.
#[derive(Debug, Clone)]
struct Node {
    name: String,
    /// Attributes in file order: name and the byte range of the raw value (between the quotes).
    attributes: Vec<(String, Range<usize>)>,
    /// Byte offset right after the tag name, where a new attribute is inserted.
    name_end: usize,
    /// Where new children go: the offset of the end tag, or for a self-closing element the range of its `/>`.
    content_end: ContentEnd,
    children: Vec<usize>,
}

/// Where the content of an element ends.
#[derive(Debug, Clone, Copy)]
enum ContentEnd {
    /// Byte offset of `</name>`.
    EndTag(usize),
    /// Byte offset of the `/>` of a self-closing element.
    SelfClosing(usize),
}

/// An indexed `.argos` text.
#[derive(Debug, Clone)]
pub struct Document {
    text: String,
    nodes: Vec<Node>,
    root: usize,
}

/// One value to write: the attribute `attribute` of element `node` gets `value`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Edit {
    node: usize,
    attribute: String,
    value: String,
}

/// Why an address cannot be applied to a document.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DocumentError {
    /// The text is not well-formed XML.
    #[error("malformed XML at byte {offset}: {message}")]
    Malformed {
        /// Byte offset of the problem.
        offset: usize,
        /// What quick-xml says.
        message: String,
    },
    /// An address matches no element.
    #[error("'{address}' matches no element: {detail}")]
    NoMatch {
        /// The address.
        address: String,
        /// Which step found nothing and what was there instead.
        detail: String,
    },
}

impl Edit {
    /// The same edit writing `value` instead.
    pub fn with_value(self, value: String) -> Edit {
        Edit { value, ..self }
    }
}

impl Document {
    /// Indexes `text`.
    pub fn parse(text: &str) -> Result<Document, DocumentError> {
        let mut reader = Reader::from_str(text);
        reader.config_mut().check_end_names = true;
        let mut nodes: Vec<Node> = Vec::new();
        let mut stack: Vec<usize> = Vec::new();
        let mut roots: Vec<usize> = Vec::new();
        loop {
            let before = offset(reader.buffer_position());
            let event = reader.read_event().map_err(|e| DocumentError::Malformed {
                offset: offset(reader.error_position()),
                message: e.to_string(),
            })?;
            match event {
                Event::Start(start) | Event::Empty(start) => {
                    let empty = text
                        .get(..offset(reader.buffer_position()))
                        .is_some_and(|before| before.ends_with("/>"));
                    let mut node = index_tag(text, &start)?;
                    if empty {
                        node.content_end =
                            ContentEnd::SelfClosing(offset(reader.buffer_position()) - 2);
                    }
                    let id = nodes.len();
                    nodes.push(node);
                    match stack.last() {
                        Some(&parent) => nodes[parent].children.push(id),
                        None => roots.push(id),
                    }
                    if !empty {
                        stack.push(id);
                    }
                }
                Event::End(_) => {
                    if let Some(node) = stack.pop() {
                        nodes[node].content_end = ContentEnd::EndTag(before);
                    }
                }
                Event::Eof => break,
                _ => {}
            }
        }
        let root = match roots.as_slice() {
            [root] => *root,
            _ => {
                return Err(DocumentError::Malformed {
                    offset: 0,
                    message: format!("expected one root element, found {}", roots.len()),
                });
            }
        };
        Ok(Document {
            text: text.to_owned(),
            nodes,
            root,
        })
    }

    /// The edits that set `address` to `value` on every element it matches; an error if it matches none.
    pub fn edits(&self, address: &Address, value: &str) -> Result<Vec<Edit>, DocumentError> {
        let mut current = vec![self.root];
        for (i, step) in address.steps.iter().enumerate() {
            let next = self.step(&current, step);
            if next.is_empty() {
                let found: Vec<&str> = {
                    let mut names: Vec<&str> = current
                        .iter()
                        .flat_map(|&n| &self.nodes[n].children)
                        .map(|&c| self.nodes[c].name.as_str())
                        .collect();
                    names.sort_unstable();
                    names.dedup();
                    names
                };
                let under = if i == 0 {
                    format!("<{}>", self.nodes[self.root].name)
                } else {
                    format!("'{}'", path_text(&address.steps[..i]))
                };
                return Err(DocumentError::NoMatch {
                    address: address.to_string(),
                    detail: format!(
                        "nothing at '{}'; the elements under {under} are: {}",
                        path_text(&address.steps[..=i]),
                        if found.is_empty() {
                            "none".to_owned()
                        } else {
                            found.join(", ")
                        }
                    ),
                });
            }
            current = next;
        }
        Ok(current
            .into_iter()
            .map(|node| Edit {
                node,
                attribute: address.attribute.clone(),
                value: value.to_owned(),
            })
            .collect())
    }

    /// The current (unescaped) values of `address` on every element it matches, in document order (`None` where
    /// the attribute is absent).
    pub fn values(&self, address: &Address) -> Vec<Option<String>> {
        let mut current = vec![self.root];
        for step in &address.steps {
            current = self.step(&current, step);
        }
        current
            .into_iter()
            .map(|n| {
                self.attribute(n, &address.attribute)
                    .map(|r| unescaped(&self.text[r]))
            })
            .collect()
    }

    /// The text with `edits` applied (later edits of the same attribute win).
    pub fn apply(&self, edits: &[Edit]) -> String {
        // (offset, replaced range end, attribute, new text), applied from the end so earlier offsets stay valid.
        // New attributes of one element all go in at the same offset, so an edit replaces an earlier one only
        // when it is about the same attribute of the same element.
        let mut splices: Vec<(usize, usize, &str, String)> = Vec::new();
        for edit in edits {
            let escaped = quick_xml::escape::escape(edit.value.as_str()).into_owned();
            let (start, end, new) = match self.attribute(edit.node, &edit.attribute) {
                Some(range) => (range.start, range.end, escaped),
                None => {
                    let at = self.nodes[edit.node].name_end;
                    (at, at, format!(" {}=\"{escaped}\"", edit.attribute))
                }
            };
            splices.retain(|(s, e, attribute, _)| {
                !(*s == start && *e == end && *attribute == edit.attribute)
            });
            splices.push((start, end, &edit.attribute, new));
        }
        splices.sort_by_key(|(start, _, _, _)| std::cmp::Reverse(*start));
        let mut text = self.text.clone();
        for (start, end, _, new) in splices {
            text.replace_range(start..end, &new);
        }
        text
    }

    /// The text with `child` (XML) added as the last child of the first element at `path` (element names from
    /// the root's children down); missing elements of the path are created.
    pub fn with_child(&self, path: &[&str], child: &str) -> String {
        let mut node = self.root;
        for (depth, name) in path.iter().enumerate() {
            let next = self.nodes[node]
                .children
                .iter()
                .copied()
                .find(|&c| self.nodes[c].name == *name);
            match next {
                Some(next) => node = next,
                None => {
                    let mut created = child.to_owned();
                    for name in path[depth..].iter().rev() {
                        created = format!("<{name}>\n{created}\n</{name}>");
                    }
                    return self.insert_into(node, &created);
                }
            }
        }
        self.insert_into(node, child)
    }

    /// The text with `xml` inserted at the end of element `node`'s content.
    fn insert_into(&self, node: usize, xml: &str) -> String {
        let mut text = self.text.clone();
        match self.nodes[node].content_end {
            ContentEnd::EndTag(at) => text.insert_str(at, &format!("{xml}\n")),
            ContentEnd::SelfClosing(at) => {
                let name = &self.nodes[node].name;
                text.replace_range(at..at + 2, &format!(">\n{xml}\n</{name}>"));
            }
        }
        text
    }

    fn attribute(&self, node: usize, name: &str) -> Option<Range<usize>> {
        self.nodes[node]
            .attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, r)| r.clone())
    }

    /// The children of `parents` that match `step`, in document order.
    fn step(&self, parents: &[usize], step: &Step) -> Vec<usize> {
        let mut matched: Vec<usize> = parents
            .iter()
            .flat_map(|&p| self.nodes[p].children.iter().copied())
            .filter(|&c| step.name.as_ref().is_none_or(|n| *n == self.nodes[c].name))
            .collect();
        for predicate in &step.predicates {
            matched = match predicate {
                Predicate::Index(n) => matched.get(n - 1).copied().into_iter().collect(),
                Predicate::Has {
                    path,
                    attribute,
                    value,
                } => matched
                    .into_iter()
                    .filter(|&node| self.has(node, path, attribute.as_deref(), value.as_deref()))
                    .collect(),
            };
        }
        matched
    }

    fn has(
        &self,
        node: usize,
        path: &[Option<String>],
        attribute: Option<&str>,
        value: Option<&str>,
    ) -> bool {
        let mut current = vec![node];
        for name in path {
            current = current
                .iter()
                .flat_map(|&p| self.nodes[p].children.iter().copied())
                .filter(|&c| name.as_ref().is_none_or(|n| *n == self.nodes[c].name))
                .collect();
        }
        current.into_iter().any(|n| match attribute {
            None => true,
            Some(attribute) => self
                .attribute(n, attribute)
                .is_some_and(|range| value.is_none_or(|v| unescaped(&self.text[range]) == v)),
        })
    }
}

/// The element path of `steps` as written in an address.
fn path_text(steps: &[Step]) -> String {
    let address = Address {
        steps: steps.to_vec(),
        attribute: String::new(),
    };
    address.to_string().trim_end_matches('@').to_owned()
}

fn unescaped(raw: &str) -> String {
    quick_xml::escape::unescape(raw).map_or_else(|_| raw.to_owned(), |v| v.into_owned())
}

fn offset(position: u64) -> usize {
    usize::try_from(position).unwrap_or(usize::MAX)
}

/// The byte position of `part` inside `whole` (both borrow the same text).
fn position_in(whole: &str, part: &[u8]) -> Option<usize> {
    let start = (part.as_ptr() as usize).checked_sub(whole.as_ptr() as usize)?;
    (start + part.len() <= whole.len()).then_some(start)
}

fn index_tag(text: &str, start: &BytesStart<'_>) -> Result<Node, DocumentError> {
    let malformed = |offset: usize, message: String| DocumentError::Malformed { offset, message };
    let raw: &[u8] = start;
    let raw_at =
        position_in(text, raw).ok_or_else(|| malformed(0, "tag outside the text".into()))?;
    let name = String::from_utf8_lossy(start.name().as_ref()).into_owned();
    let mut attributes = Vec::new();
    for attribute in start.attributes() {
        let attribute =
            attribute.map_err(|e| malformed(raw_at, format!("malformed attribute: {e}")))?;
        let key = String::from_utf8_lossy(attribute.key.as_ref()).into_owned();
        let value_at = position_in(text, attribute.value.as_ref())
            .ok_or_else(|| malformed(raw_at, format!("value of '{key}' outside the text")))?;
        attributes.push((key, value_at..value_at + attribute.value.len()));
    }
    Ok(Node {
        name_end: raw_at + start.name().as_ref().len(),
        content_end: ContentEnd::EndTag(raw_at),
        name,
        attributes,
        children: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"<?xml version="1.0"?>
<!-- a comment that must survive -->
<argos-configuration>
  <arena size="2,2,1">
    <distribute>
      <entity quantity="10" max_trials="100"><e-puck id="ep"/></entity>
    </distribute>
    <distribute>
      <entity quantity="1" max_trials="100"><box id="box" size="0.1,0.1,0.4"/></entity>
    </distribute>
  </arena>
  <controllers>
    <c id="a"><sensors><epuck_proximity implementation="default"/><epuck_light noise_level="0.01"/></sensors></c>
  </controllers>
</argos-configuration>
"#;

    #[test]
    fn children_go_last_into_existing_self_closing_or_created_elements() {
        let document = Document::parse(TEXT).expect("parses");
        let added = document.with_child(&["arena"], "<box id=\"b2\"/>");
        assert!(
            added.contains("</distribute>\n  <box id=\"b2\"/>\n</arena>"),
            "{added}"
        );
        let created = document.with_child(&["framework", "system"], "<x/>");
        assert!(
            created.contains(
                "<framework>\n<system>\n<x/>\n</system>\n</framework>\n</argos-configuration>"
            ),
            "{created}"
        );
        let closed = Document::parse("<a><b k=\"1\"/></a>").expect("parses");
        assert_eq!(
            closed.with_child(&["b"], "<c/>"),
            "<a><b k=\"1\">\n<c/>\n</b></a>"
        );
        for text in [added, created] {
            Document::parse(&text).expect("still well-formed");
        }
    }

    fn set(text: &str, address: &str, value: &str) -> String {
        let document = Document::parse(text).unwrap_or_else(|e| panic!("{e}"));
        let address = Address::parse(address).unwrap_or_else(|e| panic!("{e}"));
        let edits = document
            .edits(&address, value)
            .unwrap_or_else(|e| panic!("{e}"));
        document.apply(&edits)
    }

    #[test]
    fn setting_a_value_changes_only_that_value() {
        let derived = set(TEXT, "arena/distribute[entity/box]/entity@quantity", "5");
        assert_eq!(
            derived,
            TEXT.replace(r#"quantity="1" "#, r#"quantity="5" "#),
            "comments, layout and every other value stay as written"
        );
    }

    #[test]
    fn robots_shortcut_sets_the_epuck_distribution() {
        let derived = set(TEXT, "robots", "4");
        assert!(derived.contains(r#"<entity quantity="4" max_trials="100"><e-puck"#));
        assert!(derived.contains(r#"<entity quantity="1" max_trials="100"><box"#));
    }

    #[test]
    fn missing_attribute_is_inserted_on_every_matched_element() {
        let derived = set(TEXT, "noise", "0.05");
        assert!(
            derived.contains(r#"<epuck_proximity noise_level="0.05" implementation="default"/>"#)
        );
        assert!(derived.contains(r#"<epuck_light noise_level="0.05"/>"#));
    }

    #[test]
    fn several_missing_attributes_of_one_element_are_all_inserted() {
        let document = Document::parse(TEXT).expect("parses");
        let mut edits = Vec::new();
        for (attribute, value) in [("k1", "1"), ("k2", "2"), ("k1", "3")] {
            let address = Address::parse(&format!("arena@{attribute}")).expect("an address");
            edits.extend(document.edits(&address, value).expect("edits"));
        }
        let derived = document.apply(&edits);
        let arena = derived
            .lines()
            .find(|l| l.contains("<arena"))
            .expect("the arena");
        assert!(
            arena.contains(r#"k1="3""#) && arena.contains(r#"k2="2""#),
            "{arena}"
        );
        assert!(!arena.contains(r#"k1="1""#), "{arena}");
    }

    #[test]
    fn values_are_escaped() {
        let derived = set(TEXT, "arena@size", "a<b");
        assert!(derived.contains(r#"<arena size="a&lt;b">"#));
    }

    #[test]
    fn unmatched_step_names_what_is_there() {
        let document = Document::parse(TEXT).unwrap_or_else(|e| panic!("{e}"));
        let address = Address::parse("arena/distribute[entity/cylinder]/entity@quantity")
            .unwrap_or_else(|e| panic!("{e}"));
        let err = document.edits(&address, "1").expect_err("no cylinder");
        assert_eq!(
            err.to_string(),
            "'arena/distribute[entity/cylinder]/entity@quantity' matches no element: nothing at \
             'arena/distribute[entity/cylinder]'; the elements under 'arena' are: distribute"
        );
    }

    #[test]
    fn index_predicate_picks_one_of_the_matches() {
        let derived = set(TEXT, "arena/distribute[2]/entity@max_trials", "7");
        assert!(derived.contains(r#"quantity="1" max_trials="7""#));
        assert!(derived.contains(r#"quantity="10" max_trials="100""#));
    }

    #[test]
    fn attribute_value_predicate_selects_elements() {
        let document = Document::parse(TEXT).unwrap_or_else(|e| panic!("{e}"));
        let address = Address::parse("arena/distribute/entity/*[@id=box]@size")
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            document.values(&address),
            vec![Some("0.1,0.1,0.4".to_owned())]
        );
    }
}
