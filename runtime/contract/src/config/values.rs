//! Attribute value syntax: numbers, booleans, vectors `"x, y, z"`, Euler angles, colours and integer triples.
//!
//! Each parser returns a short reason on failure; the caller adds file, line, column and attribute name.

use crate::messages::Rgb;

use super::model::{Euler, Vec2, Vec3};

/// A value that can be written in an attribute.
pub(crate) trait Value: Sized {
    /// What the value should look like, for error messages (e.g. `a vector "x,y,z"`).
    const EXPECTED: &'static str;

    /// Parses the attribute text.
    fn parse_value(text: &str) -> Result<Self, String>;
}

impl Value for String {
    const EXPECTED: &'static str = "a string";

    fn parse_value(text: &str) -> Result<Self, String> {
        Ok(text.to_string())
    }
}

impl Value for f64 {
    const EXPECTED: &'static str = "a number";

    fn parse_value(text: &str) -> Result<Self, String> {
        let value: f64 = text
            .trim()
            .parse()
            .map_err(|_| format!("'{text}' is not {}", Self::EXPECTED))?;
        if value.is_finite() {
            Ok(value)
        } else {
            Err(format!("'{text}' is not a finite number"))
        }
    }
}

impl Value for u32 {
    const EXPECTED: &'static str = "a non-negative integer";

    fn parse_value(text: &str) -> Result<Self, String> {
        text.trim()
            .parse()
            .map_err(|_| format!("'{text}' is not {}", Self::EXPECTED))
    }
}

impl Value for u64 {
    const EXPECTED: &'static str = "a non-negative integer";

    fn parse_value(text: &str) -> Result<Self, String> {
        text.trim()
            .parse()
            .map_err(|_| format!("'{text}' is not {}", Self::EXPECTED))
    }
}

impl Value for bool {
    const EXPECTED: &'static str = "'true' or 'false'";

    fn parse_value(text: &str) -> Result<Self, String> {
        match text.trim() {
            "true" => Ok(true),
            "false" => Ok(false),
            _ => Err(format!("'{text}' is not {}", Self::EXPECTED)),
        }
    }
}

/// Splits `"a, b, c"` into exactly `n` parsed components.
fn components<T: Value>(text: &str, n: usize, expected: &str) -> Result<Vec<T>, String> {
    let parts: Vec<&str> = text.split(',').collect();
    if parts.len() != n {
        return Err(format!(
            "'{text}' has {} component(s), expected {expected}",
            parts.len()
        ));
    }
    parts
        .iter()
        .map(|p| {
            T::parse_value(p).map_err(|_| {
                format!(
                    "'{text}' is not {expected}: '{}' is not {}",
                    p.trim(),
                    T::EXPECTED
                )
            })
        })
        .collect()
}

impl Value for Vec3 {
    const EXPECTED: &'static str = "a vector \"x,y,z\"";

    fn parse_value(text: &str) -> Result<Self, String> {
        let c = components::<f64>(text, 3, Self::EXPECTED)?;
        Ok(Vec3::new(c[0], c[1], c[2]))
    }
}

impl Value for Vec2 {
    const EXPECTED: &'static str = "a vector \"x,y\"";

    fn parse_value(text: &str) -> Result<Self, String> {
        let c = components::<f64>(text, 2, Self::EXPECTED)?;
        Ok(Vec2 { x: c[0], y: c[1] })
    }
}

impl Value for Euler {
    const EXPECTED: &'static str = "Euler angles \"z,y,x\" in degrees";

    fn parse_value(text: &str) -> Result<Self, String> {
        let c = components::<f64>(text, 3, Self::EXPECTED)?;
        Ok(Euler {
            z_deg: c[0],
            y_deg: c[1],
            x_deg: c[2],
        })
    }
}

impl Value for [u32; 3] {
    const EXPECTED: &'static str = "three integers \"nx,ny,nz\"";

    fn parse_value(text: &str) -> Result<Self, String> {
        let c = components::<u32>(text, 3, Self::EXPECTED)?;
        Ok([c[0], c[1], c[2]])
    }
}

/// ARGoS' named colours (`CColor`), plus `grayN` / `greyN` for N = 0..=100.
const NAMED_COLORS: &[(&str, Rgb)] = &[
    ("black", Rgb { r: 0, g: 0, b: 0 }),
    (
        "white",
        Rgb {
            r: 255,
            g: 255,
            b: 255,
        },
    ),
    ("red", Rgb { r: 255, g: 0, b: 0 }),
    ("green", Rgb { r: 0, g: 255, b: 0 }),
    ("blue", Rgb { r: 0, g: 0, b: 255 }),
    (
        "magenta",
        Rgb {
            r: 255,
            g: 0,
            b: 255,
        },
    ),
    (
        "cyan",
        Rgb {
            r: 0,
            g: 255,
            b: 255,
        },
    ),
    (
        "yellow",
        Rgb {
            r: 255,
            g: 255,
            b: 0,
        },
    ),
    (
        "orange",
        Rgb {
            r: 255,
            g: 140,
            b: 0,
        },
    ),
    (
        "brown",
        Rgb {
            r: 165,
            g: 42,
            b: 42,
        },
    ),
    (
        "purple",
        Rgb {
            r: 160,
            g: 32,
            b: 240,
        },
    ),
];

/// The names of the named colours, for did-you-mean hints.
pub(crate) fn color_names() -> impl Iterator<Item = &'static str> {
    NAMED_COLORS.iter().map(|(name, _)| *name)
}

impl Value for Rgb {
    const EXPECTED: &'static str =
        "a colour name (e.g. 'red') or \"r,g,b[,a]\" with 0-255 components";

    fn parse_value(text: &str) -> Result<Self, String> {
        let name = text.trim();
        if let Some((_, rgb)) = NAMED_COLORS.iter().find(|(n, _)| *n == name) {
            return Ok(*rgb);
        }
        if let Some(level) = name
            .strip_prefix("gray")
            .or_else(|| name.strip_prefix("grey"))
        {
            return match level.parse::<u32>() {
                Ok(level) if level <= 100 => {
                    let v = u8::try_from(level * 255 / 100).unwrap_or(u8::MAX);
                    Ok(Rgb { r: v, g: v, b: v })
                }
                _ => Err(format!(
                    "'{text}' is not a grey level: use gray0 .. gray100"
                )),
            };
        }
        let parts: Vec<&str> = name.split(',').collect();
        if parts.len() == 3 || parts.len() == 4 {
            let bytes: Option<Vec<u8>> =
                parts.iter().map(|p| p.trim().parse::<u8>().ok()).collect();
            if let Some(b) = bytes {
                return Ok(Rgb {
                    r: b[0],
                    g: b[1],
                    b: b[2],
                });
            }
        }
        Err(format!("'{text}' is not {}", Self::EXPECTED))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_tolerate_spaces_around_components() {
        assert_eq!(Vec3::parse_value("3, 3, 1"), Ok(Vec3::new(3.0, 3.0, 1.0)));
        assert_eq!(
            Vec3::parse_value(" -1.5 ,0,0.5 "),
            Ok(Vec3::new(-1.5, 0.0, 0.5))
        );
    }

    #[test]
    fn vectors_need_exactly_three_numbers() {
        assert_eq!(
            Vec3::parse_value("1,2"),
            Err("'1,2' has 2 component(s), expected a vector \"x,y,z\"".to_string())
        );
        assert_eq!(
            Vec3::parse_value("1,x,2"),
            Err("'1,x,2' is not a vector \"x,y,z\": 'x' is not a number".to_string())
        );
    }

    #[test]
    fn numbers_must_be_finite() {
        assert!(f64::parse_value("inf").is_err());
        assert!(f64::parse_value("NaN").is_err());
        assert_eq!(f64::parse_value("12.8"), Ok(12.8));
    }

    #[test]
    fn booleans_are_true_or_false() {
        assert_eq!(bool::parse_value("true"), Ok(true));
        assert_eq!(bool::parse_value("false"), Ok(false));
        assert!(bool::parse_value("yes").is_err());
    }

    #[test]
    fn colours_by_argos_name_grey_level_or_components() {
        assert_eq!(
            Rgb::parse_value("yellow"),
            Ok(Rgb {
                r: 255,
                g: 255,
                b: 0
            })
        );
        assert_eq!(
            Rgb::parse_value("gray50"),
            Ok(Rgb {
                r: 127,
                g: 127,
                b: 127
            })
        );
        assert_eq!(
            Rgb::parse_value("10, 20, 30, 255"),
            Ok(Rgb {
                r: 10,
                g: 20,
                b: 30
            })
        );
        assert!(Rgb::parse_value("reddish").is_err());
        assert!(Rgb::parse_value("256,0,0").is_err());
    }
}
