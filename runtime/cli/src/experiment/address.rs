//! Addresses of configuration values: a small XPath-like path from the root of a `.argos` file to one attribute
//! of every element it matches, e.g. `arena/distribute[entity/box]/entity@quantity`.
//!
//! Grammar (the root `<argos-configuration>` is implicit):
//!
//! ```text
//! address   = step ("/" step)* "@" attribute
//! step      = (name | "*") predicate*
//! predicate = "[" index "]"                      1-based position among the siblings the step matched
//!           | "[" path? ("@" attribute ("=" value)?)? "]"
//!                                                a descendant path exists (and has the attribute (with the value))
//! ```
//!
//! A few named shortcuts ([`SHORTCUTS`]) stand for common addresses (`robots`, `noise`, ...); they are plain text
//! substitutions, so a shortcut and the address it names behave identically. This module only parses; matching
//! against a document is [`super::document`]'s job.

use std::fmt;

/// Named shortcuts and the addresses they stand for.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("robots", "arena/distribute[entity/e-puck]/entity@quantity"),
    ("noise", "controllers/*/sensors/*@noise_level"),
    ("wheel_noise", "controllers/*/actuators/*@noise_std_dev"),
    ("length", "framework/experiment@length"),
    ("ticks_per_second", "framework/experiment@ticks_per_second"),
];

/// A parsed address.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Address {
    /// The element steps from the root's children down.
    pub steps: Vec<Step>,
    /// The attribute set on every matched element.
    pub attribute: String,
}

/// One step of an address: an element name (or `*`) and its predicates.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Step {
    /// Element name; `None` for `*`.
    pub name: Option<String>,
    /// Conditions every matched element satisfies, in order.
    pub predicates: Vec<Predicate>,
}

/// A condition on an element inside `[...]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Predicate {
    /// `[n]`: the n-th (1-based) of the elements matched so far by this step.
    Index(usize),
    /// `[path@attribute=value]`: some descendant at `path` (the element itself when empty) exists, has
    /// `attribute` when given, with `value` when given.
    Has {
        /// Names (or `None` for `*`) of the descendant path.
        path: Vec<Option<String>>,
        /// Attribute that must be present.
        attribute: Option<String>,
        /// Value that attribute must have.
        value: Option<String>,
    },
}

/// Why an address does not parse.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("bad address '{text}': {reason}")]
pub struct AddressError {
    /// The address as written.
    pub text: String,
    /// What is wrong.
    pub reason: String,
}

impl Address {
    /// Parses an address or a shortcut name.
    pub fn parse(text: &str) -> Result<Address, AddressError> {
        let expanded = SHORTCUTS
            .iter()
            .find(|(name, _)| *name == text.trim())
            .map_or(text.trim(), |(_, address)| address);
        let fail = |reason: String| AddressError {
            text: text.to_owned(),
            reason,
        };
        let (path, attribute) = split_attribute(expanded).ok_or_else(|| {
            let names: Vec<&str> = SHORTCUTS.iter().map(|(n, _)| *n).collect();
            fail(format!(
                "an address ends with '@attribute' (e.g. 'arena/distribute[entity/box]/entity@quantity'), or is \
                 one of the shortcuts {}",
                names.join(", ")
            ))
        })?;
        check_name(attribute).map_err(|r| fail(format!("attribute: {r}")))?;
        let steps = split_outside_brackets(path, '/')
            .into_iter()
            .map(parse_step)
            .collect::<Result<Vec<_>, _>>()
            .map_err(fail)?;
        Ok(Address {
            steps,
            attribute: attribute.to_owned(),
        })
    }
}

impl fmt::Display for Address {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, step) in self.steps.iter().enumerate() {
            if i > 0 {
                f.write_str("/")?;
            }
            f.write_str(step.name.as_deref().unwrap_or("*"))?;
            for predicate in &step.predicates {
                match predicate {
                    Predicate::Index(n) => write!(f, "[{n}]")?,
                    Predicate::Has {
                        path,
                        attribute,
                        value,
                    } => {
                        let names: Vec<&str> =
                            path.iter().map(|n| n.as_deref().unwrap_or("*")).collect();
                        write!(f, "[{}", names.join("/"))?;
                        if let Some(attribute) = attribute {
                            write!(f, "@{attribute}")?;
                        }
                        if let Some(value) = value {
                            write!(f, "={value}")?;
                        }
                        f.write_str("]")?;
                    }
                }
            }
        }
        write!(f, "@{}", self.attribute)
    }
}

/// Splits `path@attribute` at the last `@` outside brackets.
fn split_attribute(text: &str) -> Option<(&str, &str)> {
    let mut depth = 0usize;
    let mut at = None;
    for (i, c) in text.char_indices() {
        match c {
            '[' => depth += 1,
            ']' => depth = depth.saturating_sub(1),
            '@' if depth == 0 => at = Some(i),
            _ => {}
        }
    }
    let at = at?;
    Some((&text[..at], &text[at + 1..]))
}

/// Splits at `separator` where it is not inside `[...]`.
fn split_outside_brackets(text: &str, separator: char) -> Vec<&str> {
    let mut parts = Vec::new();
    let mut depth = 0usize;
    let mut start = 0;
    for (i, c) in text.char_indices() {
        match c {
            '[' => depth += 1,
            ']' => depth = depth.saturating_sub(1),
            c if c == separator && depth == 0 => {
                parts.push(&text[start..i]);
                start = i + c.len_utf8();
            }
            _ => {}
        }
    }
    parts.push(&text[start..]);
    parts
}

fn check_name(name: &str) -> Result<(), String> {
    if name.is_empty() {
        return Err("empty name".into());
    }
    if let Some(bad) = name
        .chars()
        .find(|c| !(c.is_alphanumeric() || matches!(c, '_' | '-' | '.' | ':')))
    {
        return Err(format!("'{name}' contains '{bad}'"));
    }
    Ok(())
}

fn parse_name(name: &str) -> Result<Option<String>, String> {
    if name == "*" {
        return Ok(None);
    }
    check_name(name)?;
    Ok(Some(name.to_owned()))
}

fn parse_step(text: &str) -> Result<Step, String> {
    let (name, mut rest) = match text.find('[') {
        Some(open) => (&text[..open], &text[open..]),
        None => (text, ""),
    };
    let name = parse_name(name).map_err(|r| format!("step '{text}': {r}"))?;
    let mut predicates = Vec::new();
    while !rest.is_empty() {
        let close =
            matching_bracket(rest).ok_or_else(|| format!("step '{text}': '[' is never closed"))?;
        predicates
            .push(parse_predicate(&rest[1..close]).map_err(|r| format!("step '{text}': {r}"))?);
        rest = &rest[close + 1..];
        if !rest.is_empty() && !rest.starts_with('[') {
            return Err(format!(
                "step '{text}': unexpected '{rest}' after a predicate"
            ));
        }
    }
    Ok(Step { name, predicates })
}

/// The byte index of the `]` closing the `[` at the start of `text`.
fn matching_bracket(text: &str) -> Option<usize> {
    let mut depth = 0usize;
    for (i, c) in text.char_indices() {
        match c {
            '[' => depth += 1,
            ']' => {
                depth -= 1;
                if depth == 0 {
                    return Some(i);
                }
            }
            _ => {}
        }
    }
    None
}

fn parse_predicate(text: &str) -> Result<Predicate, String> {
    let text = text.trim();
    if text.is_empty() {
        return Err("empty predicate '[]'".into());
    }
    if text.chars().all(|c| c.is_ascii_digit()) {
        let index: usize = text.parse().map_err(|e| format!("index '{text}': {e}"))?;
        if index == 0 {
            return Err("indices start at 1".into());
        }
        return Ok(Predicate::Index(index));
    }
    let (path, condition) = match text.find('@') {
        Some(at) => (&text[..at], Some(&text[at + 1..])),
        None => (text, None),
    };
    let path = if path.is_empty() {
        Vec::new()
    } else {
        path.split('/')
            .map(parse_name)
            .collect::<Result<Vec<_>, _>>()?
    };
    let (attribute, value) = match condition {
        None => (None, None),
        Some(condition) => match condition.split_once('=') {
            Some((attribute, value)) => (Some(attribute.trim()), Some(unquote(value.trim()))),
            None => (Some(condition.trim()), None),
        },
    };
    if let Some(attribute) = attribute {
        check_name(attribute)?;
    }
    Ok(Predicate::Has {
        path,
        attribute: attribute.map(str::to_owned),
        value: value.map(str::to_owned),
    })
}

fn unquote(value: &str) -> &str {
    for quote in ['\'', '"'] {
        if let Some(inner) = value
            .strip_prefix(quote)
            .and_then(|v| v.strip_suffix(quote))
        {
            return inner;
        }
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Address {
        Address::parse(text).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn address_names_steps_predicates_and_attribute() {
        let address = parse("arena/distribute[entity/box][2]/entity@quantity");
        assert_eq!(address.attribute, "quantity");
        assert_eq!(address.steps.len(), 3);
        assert_eq!(
            address.steps[1].predicates,
            vec![
                Predicate::Has {
                    path: vec![Some("entity".into()), Some("box".into())],
                    attribute: None,
                    value: None
                },
                Predicate::Index(2)
            ]
        );
    }

    #[test]
    fn attribute_predicates_take_quoted_or_bare_values() {
        let a = parse("arena/floor[@source='image']@path");
        let b = parse("arena/floor[@source=image]@path");
        assert_eq!(a, b);
        assert_eq!(a.to_string(), "arena/floor[@source=image]@path");
    }

    #[test]
    fn shortcuts_expand_to_their_addresses() {
        assert_eq!(
            parse("robots"),
            parse("arena/distribute[entity/e-puck]/entity@quantity")
        );
        assert_eq!(
            parse("noise").to_string(),
            "controllers/*/sensors/*@noise_level"
        );
    }

    #[test]
    fn address_without_attribute_is_rejected_with_the_shortcuts_listed() {
        let err = Address::parse("arena/distribute").expect_err("no attribute");
        assert!(err.reason.contains("'@attribute'"), "{err}");
        assert!(err.reason.contains("robots, noise"), "{err}");
    }

    #[test]
    fn malformed_steps_are_rejected() {
        for bad in [
            "arena/distribute[entity@quantity",
            "arena//entity@quantity",
            "arena/distribute[0]@quantity",
            "arena/dist ribute@quantity",
            "arena@",
        ] {
            assert!(Address::parse(bad).is_err(), "{bad} should not parse");
        }
    }
}
