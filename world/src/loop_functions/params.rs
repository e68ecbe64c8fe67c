//! Reading a task's settings from its `<loop_functions>` child element (e.g. `<aggregation gap="0.07"/>`), with
//! errors that name the element's place in the configuration, the attribute and the rule it breaks.
//!
//! Only construction-time code uses this; it never runs per tick.

use crate::error::WorldError;
use crate::loop_functions::LoopFunctionsParams;

/// The attributes of one child element of `<loop_functions>`, checked against the names a task knows.
#[derive(Debug, Clone, Copy)]
pub struct ParamReader<'a> {
    params: &'a LoopFunctionsParams,
    element: &'static str,
}

impl<'a> ParamReader<'a> {
    /// A reader of `<element ...>` inside `params`; any attribute of it not in `known`, and any other child
    /// element, is an error.
    pub fn new(
        params: &'a LoopFunctionsParams,
        element: &'static str,
        known: &[&str],
    ) -> Result<Self, WorldError> {
        params.check_children(&[element])?;
        let prefix = format!("{element}.");
        for key in params.attributes.keys() {
            if let Some(name) = key.strip_prefix(&prefix)
                && !known.contains(&name)
            {
                return Err(WorldError::Invalid {
                    location: params.location.clone(),
                    message: format!(
                        "<{element}> has no attribute '{name}' (known: {})",
                        known.join(", ")
                    ),
                });
            }
        }
        Ok(Self { params, element })
    }

    /// Attribute `name` as a number >= 0, or `default` when absent.
    pub fn non_negative(&self, name: &str, default: f64) -> Result<f64, WorldError> {
        self.number(name, default, |v| v >= 0.0, "a number >= 0")
    }

    /// Attribute `name` as a number > 0, or `default` when absent.
    pub fn positive(&self, name: &str, default: f64) -> Result<f64, WorldError> {
        self.number(name, default, |v| v > 0.0, "a number > 0")
    }

    /// Attribute `name` as a number in [0, 1], or `default` when absent.
    pub fn unit(&self, name: &str, default: f64) -> Result<f64, WorldError> {
        self.number(
            name,
            default,
            |v| (0.0..=1.0).contains(&v),
            "a number in [0, 1]",
        )
    }

    fn number(
        &self,
        name: &str,
        default: f64,
        ok: fn(f64) -> bool,
        expected: &str,
    ) -> Result<f64, WorldError> {
        let Some(raw) = self.raw(name) else {
            return Ok(default);
        };
        match raw.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && ok(v) => Ok(v),
            _ => Err(self.invalid(name, raw, expected)),
        }
    }

    /// Attribute `name` as a whole number >= `min`, or `default` when absent.
    pub fn u64_at_least(&self, name: &str, default: u64, min: u64) -> Result<u64, WorldError> {
        let Some(raw) = self.raw(name) else {
            return Ok(default);
        };
        match raw.trim().parse::<u64>() {
            Ok(v) if v >= min => Ok(v),
            _ => Err(self.invalid(name, raw, &format!("a whole number >= {min}"))),
        }
    }

    /// Attribute `name` as a whole number in `min..=max`, or `default` when absent.
    pub fn u64_between(
        &self,
        name: &str,
        default: u64,
        min: u64,
        max: u64,
    ) -> Result<u64, WorldError> {
        let Some(raw) = self.raw(name) else {
            return Ok(default);
        };
        match raw.trim().parse::<u64>() {
            Ok(v) if (min..=max).contains(&v) => Ok(v),
            _ => Err(self.invalid(name, raw, &format!("a whole number from {min} to {max}"))),
        }
    }

    /// Attribute `name` as exactly `N` finite numbers separated by commas (e.g. a pose `x,y,angle`), or `None`
    /// when absent.
    pub fn numbers<const N: usize>(&self, name: &str) -> Result<Option<[f64; N]>, WorldError> {
        let Some(raw) = self.raw(name) else {
            return Ok(None);
        };
        finite_numbers(raw)
            .map(Some)
            .ok_or_else(|| self.invalid(name, raw, &format!("{N} numbers separated by `,`")))
    }

    /// Attribute `name`, which must be one of `choices`, or `default` when absent.
    pub fn choice(
        &self,
        name: &str,
        choices: &[&'static str],
        default: &'static str,
    ) -> Result<&'static str, WorldError> {
        let Some(raw) = self.raw(name) else {
            return Ok(default);
        };
        choices
            .iter()
            .find(|c| **c == raw.trim())
            .copied()
            .ok_or_else(|| self.invalid(name, raw, &format!("one of {}", choices.join(", "))))
    }

    /// Attribute `name` as a list of points `x,y; x,y; ...` (finite numbers), or `None` when absent.
    pub fn points(&self, name: &str) -> Result<Option<Vec<(f64, f64)>>, WorldError> {
        let Some(raw) = self.raw(name) else {
            return Ok(None);
        };
        raw.split(';')
            .map(|point| {
                finite_numbers::<2>(point)
                    .map(|[x, y]| (x, y))
                    .ok_or_else(|| self.invalid(name, raw, "points `x,y` separated by `;`"))
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    }

    /// Attribute `name` as one point `x,y`, or `default` when absent.
    pub fn point(&self, name: &str, default: (f64, f64)) -> Result<(f64, f64), WorldError> {
        match self.points(name)?.as_deref() {
            None => Ok(default),
            Some([point]) => Ok(*point),
            Some(_) => Err(self.invalid(name, self.raw(name).map_or("", |r| r), "one point `x,y`")),
        }
    }

    /// Attribute `name` as a list of words separated by spaces or commas (empty when absent).
    pub fn words(&self, name: &str) -> Vec<String> {
        self.raw(name).map_or_else(Vec::new, |raw| {
            raw.split([',', ' ', '\t', '\n'])
                .filter(|w| !w.is_empty())
                .map(String::from)
                .collect()
        })
    }

    /// The text of attribute `name`, which the element must have.
    pub fn required(&self, name: &str) -> Result<&str, WorldError> {
        self.raw(name)
            .map(String::as_str)
            .ok_or_else(|| WorldError::Invalid {
                location: self.params.location.clone(),
                message: format!("<{}> needs the attribute '{name}'", self.element),
            })
    }

    /// Attribute `name` as a number > 0, or `None` when it is absent or the word `word` (a named alternative to
    /// a number, e.g. `discovery="sensor"`).
    pub fn positive_or_word(&self, name: &str, word: &str) -> Result<Option<f64>, WorldError> {
        match self.raw(name) {
            Some(raw) if raw.trim() != word => match raw.trim().parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok(Some(v)),
                _ => Err(self.invalid(name, raw, &format!("`{word}` or a number > 0"))),
            },
            _ => Ok(None),
        }
    }

    /// The text of attribute `name` of this element, if given.
    fn raw(&self, name: &str) -> Option<&String> {
        self.params
            .attributes
            .get(&format!("{}.{name}", self.element))
    }

    fn invalid(&self, name: &str, raw: &str, expected: &str) -> WorldError {
        WorldError::Invalid {
            location: self.params.location.clone(),
            message: format!("<{} {name}=\"{raw}\">: must be {expected}", self.element),
        }
    }
}

/// Exactly `N` finite numbers separated by commas, or `None`.
fn finite_numbers<const N: usize>(text: &str) -> Option<[f64; N]> {
    let mut parts = text.split(',');
    let mut out = [0.0; N];
    for slot in &mut out {
        *slot = parts
            .next()?
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())?;
    }
    parts.next().is_none().then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(attrs: &[(&str, &str)]) -> LoopFunctionsParams {
        LoopFunctionsParams {
            label: "x".to_owned(),
            location: "e.argos:3:5".to_owned(),
            attributes: attrs
                .iter()
                .map(|&(k, v)| (k.to_owned(), v.to_owned()))
                .collect(),
            ..LoopFunctionsParams::default()
        }
    }

    #[test]
    fn absent_attribute_takes_the_default() {
        let p = params(&[]);
        let r = ParamReader::new(&p, "task", &["a"]).unwrap();
        assert_eq!(r.unit("a", 0.5).unwrap(), 0.5);
        assert_eq!(r.u64_at_least("a", 7, 1).unwrap(), 7);
    }

    #[test]
    fn another_child_element_is_refused_even_without_attributes() {
        let err = ParamReader::new(&params(&[("tsak.a", "1")]), "task", &["a"])
            .expect_err("refused")
            .to_string();
        assert_eq!(
            err,
            "e.argos:3:5: <loop_functions label=\"x\"> has no child <tsak> (known: <task>)"
        );
        let bare = LoopFunctionsParams {
            children: vec!["tsak".into()],
            ..params(&[])
        };
        assert!(ParamReader::new(&bare, "task", &["a"]).is_err());
    }

    #[test]
    fn whole_number_below_the_minimum_is_rejected() {
        let p = params(&[("task.window", "0")]);
        let r = ParamReader::new(&p, "task", &["window"]).unwrap();
        assert_eq!(
            r.u64_at_least("window", 5, 1).unwrap_err().to_string(),
            "e.argos:3:5: <task window=\"0\">: must be a whole number >= 1"
        );
    }

    #[test]
    fn a_required_attribute_and_a_word_for_a_number() {
        let p = params(&[("task.radius", "sensor"), ("task.cell", "-1")]);
        let r = ParamReader::new(&p, "task", &["radius", "cell", "list"]).unwrap();
        assert_eq!(
            r.required("list").unwrap_err().to_string(),
            "e.argos:3:5: <task> needs the attribute 'list'"
        );
        assert_eq!(r.required("radius").unwrap(), "sensor");
        assert_eq!(r.positive_or_word("radius", "sensor").unwrap(), None);
        assert_eq!(r.positive_or_word("list", "sensor").unwrap(), None);
        assert_eq!(
            r.positive_or_word("cell", "sensor")
                .unwrap_err()
                .to_string(),
            "e.argos:3:5: <task cell=\"-1\">: must be `sensor` or a number > 0"
        );
        let p = params(&[("task.radius", " 0.5 ")]);
        let r = ParamReader::new(&p, "task", &["radius"]).unwrap();
        assert_eq!(r.positive_or_word("radius", "sensor").unwrap(), Some(0.5));
    }

    #[test]
    fn bounded_whole_numbers_and_fixed_counts_of_numbers_as_transport_reads_them() {
        let p = params(&[
            ("task.n", "7"),
            ("task.big", "11"),
            ("task.pose", " 1, -2.5,90 "),
            ("task.short", "1,2"),
            ("task.long", "1,2,3,4"),
            ("task.nan", "1,NaN,3"),
        ]);
        let r =
            ParamReader::new(&p, "task", &["n", "big", "pose", "short", "long", "nan"]).unwrap();
        assert_eq!(r.u64_between("n", 1, 1, 10).unwrap(), 7);
        assert_eq!(r.u64_between("absent", 3, 1, 10).unwrap(), 3);
        assert_eq!(
            r.u64_between("big", 1, 1, 10).unwrap_err().to_string(),
            "e.argos:3:5: <task big=\"11\">: must be a whole number from 1 to 10"
        );
        assert_eq!(r.numbers::<3>("pose").unwrap(), Some([1.0, -2.5, 90.0]));
        assert_eq!(r.numbers::<3>("absent").unwrap(), None);
        for bad in ["short", "long", "nan"] {
            assert!(
                r.numbers::<3>(bad)
                    .unwrap_err()
                    .to_string()
                    .ends_with("must be 3 numbers separated by `,`"),
                "{bad}"
            );
        }
    }

    #[test]
    fn zero_is_not_positive() {
        let p = params(&[("task.every", "0")]);
        let r = ParamReader::new(&p, "task", &["every"]).unwrap();
        assert_eq!(
            r.positive("every", 1.0).unwrap_err().to_string(),
            "e.argos:3:5: <task every=\"0\">: must be a number > 0"
        );
    }
}
