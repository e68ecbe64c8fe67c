//! Controller parameters: the attributes of a controller's `<params>` element, read with typed getters.
//!
//! Profiles and native controllers read their numbers (speeds in cm/s, thresholds) from here once at startup;
//! nothing here runs per tick. Errors name the parameter and the offending value; the caller adds the file and
//! line of the `<params>` element.

use std::collections::BTreeSet;
use std::sync::{Arc, Mutex, PoisonError};

use thiserror::Error;

/// A bad controller parameter.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// The value does not parse as the expected type.
    #[error("parameter `{name}` = \"{value}\" is not {expected}")]
    Malformed {
        /// Parameter name.
        name: String,
        /// Value as written.
        value: String,
        /// What was expected, e.g. "a finite number".
        expected: &'static str,
    },
    /// The value parses but lies outside the allowed range.
    #[error("parameter `{name}` = {value} is out of range: {rule}")]
    OutOfRange {
        /// Parameter name.
        name: String,
        /// Value as written.
        value: String,
        /// The rule it breaks, e.g. "must be >= 0".
        rule: &'static str,
    },
}

/// The largest capacity a parameter may ask for: the runtime's most participants.
pub const MAX_CAPACITY: usize = 1 << 20;

/// The attributes of a `<params>` element, in document order, and the run's seed.
///
/// Every name a controller asks for is remembered (by every clone alike), so that after the controller is built
/// the parameters nobody asked for ([`Params::unread`]) can be reported: a misspelt attribute is otherwise
/// silently ignored.
#[derive(Debug, Clone, Default)]
pub struct Params {
    entries: Vec<(String, String)>,
    run_seed: u64,
    asked: Arc<Mutex<BTreeSet<String>>>,
}

impl PartialEq for Params {
    fn eq(&self, other: &Self) -> bool {
        self.entries == other.entries && self.run_seed == other.run_seed
    }
}

impl Eq for Params {}

impl Params {
    /// Parameters from name/value pairs (later duplicates win, as in an XML attribute map).
    pub fn new<I, K, V>(pairs: I) -> Self
    where
        I: IntoIterator<Item = (K, V)>,
        K: Into<String>,
        V: Into<String>,
    {
        Self {
            entries: pairs
                .into_iter()
                .map(|(k, v)| (k.into(), v.into()))
                .collect(),
            run_seed: 0,
            asked: Arc::default(),
        }
    }

    /// The same parameters in a run seeded with `seed` (for profiles whose defaults follow the run).
    pub fn with_run_seed(mut self, seed: u64) -> Self {
        self.run_seed = seed;
        self
    }

    /// The run's seed (0 unless set with [`Params::with_run_seed`]).
    pub fn run_seed(&self) -> u64 {
        self.run_seed
    }

    /// The raw value of `name`, if given.
    pub fn get(&self, name: &str) -> Option<&str> {
        let mut asked = self.asked.lock().unwrap_or_else(PoisonError::into_inner);
        if !asked.contains(name) {
            asked.insert(name.to_owned());
        }
        drop(asked);
        self.entries
            .iter()
            .rev()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The parameters given but never asked for, each with the closest name that was asked for (a likely
    /// typo), in document order.
    pub fn unread(&self) -> Vec<(&str, Option<String>)> {
        let asked = self.asked.lock().unwrap_or_else(PoisonError::into_inner);
        let mut seen = BTreeSet::new();
        self.entries
            .iter()
            .map(|(name, _)| name.as_str())
            .filter(|name| !asked.contains(*name) && seen.insert(*name))
            .map(|name| {
                let hint = swarm_contract::config::suggest::did_you_mean(
                    name,
                    asked.iter().map(String::as_str),
                );
                (name, hint)
            })
            .collect()
    }

    /// `name` as a whole number >= 0 that fits `T` (e.g. `u32`, `u64`), or `default` when absent.
    pub fn whole_or<T: std::str::FromStr>(&self, name: &str, default: T) -> Result<T, ParamError> {
        let Some(raw) = self.get(name) else {
            return Ok(default);
        };
        raw.trim().parse::<T>().map_err(|_| ParamError::Malformed {
            name: name.to_owned(),
            value: raw.to_owned(),
            expected: "a whole number >= 0",
        })
    }

    /// `name` as a capacity (how much a controller keeps: robots, tasks, obstacles, regions) from 1 to
    /// [`MAX_CAPACITY`], or `default` when absent: a controller reserves its memory up front, so an absurd value
    /// must be an error, not an allocation that fails.
    pub fn capacity_or(&self, name: &str, default: usize) -> Result<usize, ParamError> {
        let count = self.whole_or(name, default)?;
        if count == 0 || count > MAX_CAPACITY {
            return Err(ParamError::OutOfRange {
                name: name.to_owned(),
                value: count.to_string(),
                rule: "must be from 1 to 1048576",
            });
        }
        Ok(count)
    }

    /// `name` as a finite `f32`, or `default` when absent.
    pub fn f32_or(&self, name: &str, default: f32) -> Result<f32, ParamError> {
        let Some(raw) = self.get(name) else {
            return Ok(default);
        };
        match raw.trim().parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(ParamError::Malformed {
                name: name.to_owned(),
                value: raw.to_owned(),
                expected: "a finite number",
            }),
        }
    }

    /// `name` as a finite `f32` >= 0 (a speed), or `default` when absent.
    pub fn non_negative_f32_or(&self, name: &str, default: f32) -> Result<f32, ParamError> {
        let v = self.f32_or(name, default)?;
        if v >= 0.0 {
            Ok(v)
        } else {
            Err(ParamError::OutOfRange {
                name: name.to_owned(),
                value: self.get(name).unwrap_or_default().to_owned(),
                rule: "must be >= 0",
            })
        }
    }

    /// `name` as a finite `f32` > 0, or `default` when absent.
    pub fn positive_f32_or(&self, name: &str, default: f32) -> Result<f32, ParamError> {
        let v = self.f32_or(name, default)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(ParamError::OutOfRange {
                name: name.to_owned(),
                value: self.get(name).unwrap_or_default().to_owned(),
                rule: "must be > 0",
            })
        }
    }

    /// `name`, which must be one of `choices`, or `default` when absent.
    pub fn choice_or<'a>(
        &self,
        name: &str,
        choices: &[&'a str],
        default: &'a str,
    ) -> Result<&'a str, ParamError> {
        match self.get(name).map(str::trim) {
            None => Ok(default),
            Some(raw) => {
                choices
                    .iter()
                    .find(|c| **c == raw)
                    .copied()
                    .ok_or_else(|| ParamError::Malformed {
                        name: name.into(),
                        value: raw.into(),
                        expected: "one of the documented choices",
                    })
            }
        }
    }

    /// `name` as `true` or `false`, or `default` when absent.
    pub fn flag_or(&self, name: &str, default: bool) -> Result<bool, ParamError> {
        let default = if default { "true" } else { "false" };
        Ok(self.choice_or(name, &["true", "false"], default)? == "true")
    }

    /// `name` as a finite `f32` in `[0, 1]` (a sensor reading), or `default` when absent.
    pub fn unit_f32_or(&self, name: &str, default: f32) -> Result<f32, ParamError> {
        let v = self.f32_or(name, default)?;
        if (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err(ParamError::OutOfRange {
                name: name.to_owned(),
                value: self.get(name).unwrap_or_default().to_owned(),
                rule: "must be in [0, 1]",
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absent_parameter_takes_the_default() {
        assert_eq!(Params::default().f32_or("velocity", 12.8), Ok(12.8));
    }

    #[test]
    fn velocity_parses_as_written_in_the_thesis_config() {
        let p = Params::new([("velocity", "12.8")]);
        assert_eq!(p.non_negative_f32_or("velocity", 1.0), Ok(12.8));
    }

    #[test]
    fn non_numeric_value_names_parameter_and_value() {
        let p = Params::new([("velocity", "fast")]);
        let err = p.f32_or("velocity", 12.8).unwrap_err();
        assert_eq!(
            err.to_string(),
            "parameter `velocity` = \"fast\" is not a finite number"
        );
    }

    #[test]
    fn negative_velocity_is_rejected() {
        let p = Params::new([("velocity", "-3")]);
        let err = p.non_negative_f32_or("velocity", 12.8).unwrap_err();
        assert_eq!(
            err.to_string(),
            "parameter `velocity` = -3 is out of range: must be >= 0"
        );
    }

    #[test]
    fn threshold_above_one_is_rejected() {
        let p = Params::new([("theta_obs", "1.5")]);
        assert!(matches!(
            p.unit_f32_or("theta_obs", 0.1),
            Err(ParamError::OutOfRange { .. })
        ));
    }

    #[test]
    fn infinite_value_is_malformed() {
        let p = Params::new([("velocity", "inf")]);
        assert!(matches!(
            p.f32_or("velocity", 12.8),
            Err(ParamError::Malformed { .. })
        ));
    }
}
