//! Turns the located element tree of a `.argos` file into an [`Experiment`], collecting every error and warning.
//!
//! Each section has its own module; [`Ctx`] carries the file path, the diagnostics found so far and the
//! references that can only be checked once every section is read (media and controller ids, entity ids; see
//! [`checks`]). Parsing never stops at the first error: a bad item is dropped, its error recorded, and the rest is
//! still read, so one run reports everything that is wrong.

mod arena;
mod checks;
mod controllers;
mod coordinators;
mod distribute;
mod engines;
mod floor;
mod framework;

use std::path::{Path, PathBuf};

use super::diagnostic::{ConfigErrors, Diagnostic};
use super::model::{Element, Experiment, Location, Media};
use super::registry::MediumKind;
use super::suggest::did_you_mean;
use super::values::Value;
use super::xml::parse_tree;

/// A reference to a medium by id, checked against `<media>` once everything is read.
pub(crate) struct MediumRef {
    /// The id written in `medium`.
    pub id: String,
    /// The kind of medium needed.
    pub kind: MediumKind,
    /// Where the `medium` attribute is.
    pub location: Location,
    /// Who refers to it, e.g. `sensor 'epuck_omnidirectional_camera' in controller 'fc'`.
    pub user: String,
}

/// Parsing state: diagnostics and deferred references.
pub(crate) struct Ctx {
    path: PathBuf,
    errors: Vec<Diagnostic>,
    warnings: Vec<Diagnostic>,
    /// Media references to check at the end.
    pub medium_refs: Vec<MediumRef>,
}

impl Ctx {
    /// A fresh context for the file at `path`.
    pub(crate) fn new(path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            errors: Vec::new(),
            warnings: Vec::new(),
            medium_refs: Vec::new(),
        }
    }

    /// The folder relative paths in the file are resolved against.
    pub(crate) fn base_dir(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new(""))
    }

    /// The file being read.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// The errors found (warnings are dropped).
    pub(crate) fn into_errors(self) -> Vec<Diagnostic> {
        self.errors
    }

    /// Records an error with an optional hint.
    pub(crate) fn error(
        &mut self,
        location: Location,
        message: impl Into<String>,
        hint: Option<String>,
    ) {
        let mut d = Diagnostic::new(self.path.clone(), location, message);
        d.hint = hint;
        self.errors.push(d);
    }

    /// Records a warning with an optional hint.
    pub(crate) fn warn(
        &mut self,
        location: Location,
        message: impl Into<String>,
        hint: Option<String>,
    ) {
        let mut d = Diagnostic::new(self.path.clone(), location, message);
        d.hint = hint;
        self.warnings.push(d);
    }

    /// Reads an optional attribute; a malformed value is an error at the attribute and yields `None`.
    pub(crate) fn attr<T: Value>(&mut self, el: &Element, name: &str) -> Option<T> {
        let attribute = el.attributes.get(name)?;
        match T::parse_value(&attribute.value) {
            Ok(v) => Some(v),
            Err(reason) => {
                self.error(
                    attribute.location,
                    format!("invalid '{name}' in <{}>: {reason}", el.name),
                    None,
                );
                None
            }
        }
    }

    /// Reads a mandatory attribute; absence is an error at the element.
    pub(crate) fn required<T: Value>(&mut self, el: &Element, name: &str) -> Option<T> {
        if !el.attributes.contains_key(name) {
            self.error(
                el.location,
                format!("<{}> is missing the attribute '{name}'", el.name),
                None,
            );
            return None;
        }
        self.attr(el, name)
    }

    /// Checks that a parsed number lies in `[min, max]` (`max` optional); an error at the attribute if not.
    pub(crate) fn in_range(
        &mut self,
        el: &Element,
        name: &str,
        value: f64,
        min: f64,
        max: Option<f64>,
    ) -> bool {
        if value >= min && max.is_none_or(|hi| value <= hi) {
            return true;
        }
        let bound = match max {
            Some(hi) => format!("between {min} and {hi}"),
            None => format!("at least {min}"),
        };
        let at = el.attributes.get(name).map_or(el.location, |a| a.location);
        self.error(
            at,
            format!("'{name}' in <{}> must be {bound}, got {value}", el.name),
            None,
        );
        false
    }

    /// A mandatory attribute that must be strictly positive.
    pub(crate) fn positive(&mut self, el: &Element, name: &str) -> Option<f64> {
        let value: f64 = self.required(el, name)?;
        if value <= 0.0 {
            let at = el.attributes.get(name).map_or(el.location, |a| a.location);
            self.error(
                at,
                format!(
                    "'{name}' in <{}> must be greater than 0, got {value}",
                    el.name
                ),
                None,
            );
            return None;
        }
        Some(value)
    }

    /// Warns about attributes of `el` that are not in `known` (they are ignored), with a did-you-mean hint.
    pub(crate) fn unknown_attributes(&mut self, el: &Element, known: &[&str]) {
        for (name, attribute) in &el.attributes {
            if !known.contains(&name.as_str()) {
                let hint = did_you_mean(name, known.iter().copied());
                self.warn(
                    attribute.location,
                    format!("unknown attribute '{name}' in <{}> is ignored", el.name),
                    hint,
                );
            }
        }
    }

    /// Reports a child element that does not belong in `parent` (an error: the section is one we implement).
    pub(crate) fn unknown_element(&mut self, child: &Element, parent: &str, known: &[&str]) {
        let hint = did_you_mean(&child.name, known.iter().copied());
        self.error(
            child.location,
            format!("unknown element <{}> in <{parent}>", child.name),
            hint,
        );
    }

    /// The children of `parent` named `name`, in file order; every other child is reported with
    /// [`Ctx::unknown_element`]. The flag is `false` when any was.
    pub(crate) fn children_named<'a>(
        &mut self,
        parent: &'a Element,
        name: &str,
    ) -> (Vec<&'a Element>, bool) {
        let mut all_known = true;
        let mut named = Vec::new();
        for child in &parent.children {
            if child.name == name {
                named.push(child);
            } else {
                self.unknown_element(child, &parent.name, &[name]);
                all_known = false;
            }
        }
        (named, all_known)
    }

    /// Reports a second occurrence of an element that may appear once.
    pub(crate) fn duplicate(&mut self, child: &Element, parent: &str, first: Location) {
        self.error(
            child.location,
            format!(
                "<{}> appears twice in <{parent}> (first at {first})",
                child.name
            ),
            None,
        );
    }
}

/// Loads and checks an experiment configuration file.
pub(crate) fn load(path: &Path) -> Result<(Experiment, Vec<Diagnostic>), ConfigErrors> {
    let text = super::input::read_text(path, super::input::MAX_CONFIG_BYTES)
        .map_err(|d| ConfigErrors { errors: vec![d] })?;
    parse_str(path, &text)
}

/// Parses configuration text as if read from `path`.
pub(crate) fn parse_str(
    path: &Path,
    text: &str,
) -> Result<(Experiment, Vec<Diagnostic>), ConfigErrors> {
    let root = parse_tree(path, text).map_err(|d| ConfigErrors { errors: vec![d] })?;
    let mut ctx = Ctx::new(path);
    let experiment = experiment(&mut ctx, &root, path);
    if let Some(experiment) = &experiment {
        checks::run(&mut ctx, experiment);
    }
    let Ctx {
        mut errors,
        mut warnings,
        ..
    } = ctx;
    errors.sort_by_key(|d| d.location);
    warnings.sort_by_key(|d| d.location);
    match experiment {
        Some(experiment) if errors.is_empty() => Ok((experiment, warnings)),
        _ => Err(ConfigErrors { errors }),
    }
}

const SECTIONS: &[&str] = &[
    "framework",
    "controllers",
    "loop_functions",
    "arena",
    "physics_engines",
    "media",
    "visualization",
    "coordinators",
    super::faults::SECTION,
];

/// The root element and its sections.
fn experiment(ctx: &mut Ctx, root: &Element, path: &Path) -> Option<Experiment> {
    if root.name != "argos-configuration" {
        ctx.error(
            root.location,
            format!(
                "the root element is <{}>, expected <argos-configuration>",
                root.name
            ),
            None,
        );
        return None;
    }
    let mut seen: Vec<(&str, Location)> = Vec::new();
    for child in &root.children {
        match SECTIONS.iter().find(|s| **s == child.name) {
            Some(section) => match seen.iter().find(|(s, _)| s == section) {
                Some((_, first)) => ctx.duplicate(child, &root.name, *first),
                None => seen.push((section, child.location)),
            },
            None => ctx.unknown_element(child, &root.name, SECTIONS),
        }
    }
    let section = |name: &str| root.children.iter().find(|c| c.name == name);
    let missing = |ctx: &mut Ctx, name: &str| {
        ctx.error(
            root.location,
            format!("<argos-configuration> has no <{name}> section"),
            None,
        );
    };

    let framework = match section("framework") {
        Some(el) => framework::framework(ctx, el),
        None => {
            missing(ctx, "framework");
            None
        }
    };
    let controllers = match section("controllers") {
        Some(el) => controllers::controllers(ctx, el),
        None => Vec::new(),
    };
    let loop_functions =
        section("loop_functions").and_then(|el| controllers::loop_functions(ctx, el));
    let media = section("media").map_or_else(Media::default, |el| engines::media(ctx, el));
    let physics_engine = match section("physics_engines") {
        Some(el) => engines::physics_engines(ctx, el),
        None => {
            missing(ctx, "physics_engines");
            None
        }
    };
    let arena = match section("arena") {
        Some(el) => arena::arena(ctx, el),
        None => {
            missing(ctx, "arena");
            None
        }
    };
    if let Some(el) = section("visualization") {
        visualization(ctx, el);
    }
    let coordinators = section("coordinators")
        .map(|el| coordinators::coordinators(ctx, el))
        .unwrap_or_default();
    let faults = section(super::faults::SECTION)
        .map(|el| super::faults::read_section(ctx, el))
        .unwrap_or_default();
    Some(Experiment {
        path: path.to_path_buf(),
        framework: framework?,
        controllers,
        loop_functions,
        arena: arena?,
        physics_engine: physics_engine?,
        media,
        coordinators,
        faults,
    })
}

/// `<visualization>`: runs are headless, so it is ignored; both ARGoS camera syntaxes are accepted unread.
fn visualization(ctx: &mut Ctx, el: &Element) {
    ctx.warn(
        el.location,
        "<visualization> is ignored: runs are headless",
        None,
    );
    for renderer in &el.children {
        for child in renderer
            .children
            .iter()
            .filter(|c| c.name == "user_functions")
        {
            ctx.warn(
                child.location,
                "<user_functions> is ignored: there is no GUI to draw in",
                None,
            );
        }
    }
}
