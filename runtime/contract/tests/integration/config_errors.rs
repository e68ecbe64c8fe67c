//! Every error path of the configuration parser: each bad input gives exactly one located message
//! `file:line:column: message (hint)`, and a file with several problems reports all of them.

use swarm_contract::config::Experiment;

const PATH: &str = "configs/test.argos";

/// A valid configuration; tests replace one placeholder with the bad part.
const BASE: &str = r#"<?xml version="1.0" ?>
<argos-configuration>
  <framework>
    <system threads="0"/>
    FRAMEWORK
  </framework>
  <controllers>
    <test_controller id="fdc" library="agent">
      <actuators>
        <epuck_wheels implementation="default"/>
      </actuators>
      <sensors>
        SENSORS
      </sensors>
      <params velocity="12.8"/>
    </test_controller>
  </controllers>
  <arena size="3,3,1" center="0,0,0.5">
    ARENA
  </arena>
  <physics_engines>
    ENGINES
  </physics_engines>
  <media>
    MEDIA
  </media>
</argos-configuration>
"#;

const FRAMEWORK: &str = r#"<experiment length="0" ticks_per_second="20" random_seed="124"/>"#;
const SENSORS: &str = r#"<epuck_proximity implementation="default"/>"#;
const ARENA: &str =
    r#"<box id="wall" size="3,0.1,0.5" movable="false"><body position="0,1.5,0"/></box>"#;
const ENGINES: &str = r#"<dynamics2d id="dyn2d"/>"#;
const MEDIA: &str = r#"<led id="leds"/>"#;

/// The base with one or more placeholders replaced (the others get their valid default).
fn config(replacements: &[(&str, &str)]) -> String {
    let mut text = BASE.to_string();
    for (key, value) in replacements {
        text = text.replace(key, value);
    }
    for (key, value) in [
        ("FRAMEWORK", FRAMEWORK),
        ("SENSORS", SENSORS),
        ("ARENA", ARENA),
        ("ENGINES", ENGINES),
        ("MEDIA", MEDIA),
    ] {
        text = text.replace(key, value);
    }
    text
}

/// `line:column` (1-based, characters) of the first occurrence of `needle` in `text`.
fn at(text: &str, needle: &str) -> String {
    let offset = text
        .find(needle)
        .unwrap_or_else(|| panic!("'{needle}' not in the test config"));
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    format!("{line}:{column}")
}

fn errors(text: &str) -> Vec<String> {
    match Experiment::parse(PATH, text) {
        Ok((_, warnings)) => panic!("expected errors, loaded with warnings {warnings:?}"),
        Err(e) => e.errors.iter().map(ToString::to_string).collect(),
    }
}

/// Asserts that `text` fails with exactly one error, located at `needle`.
fn assert_error(text: &str, needle: &str, message: &str) {
    assert_eq!(
        errors(text),
        [format!("{PATH}:{}: {message}", at(text, needle))]
    );
}

#[test]
fn the_base_configuration_is_valid() {
    let (exp, warnings) = Experiment::parse(PATH, &config(&[])).expect("valid base");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(exp.arena.entities.len(), 1);
}

// ---- XML and document structure ----

#[test]
fn malformed_xml_is_located() {
    let text = config(&[("ARENA", "<box id=\"b\">\n    </cylinder>")]);
    let errs = errors(&text);
    assert_eq!(errs.len(), 1);
    let expected = format!(
        "{PATH}:{}: malformed XML: ill-formed document: expected `</box>`, but `</cylinder>` was found",
        at(&text, "</cylinder>")
    );
    assert_eq!(errs[0], expected);
}

#[test]
fn root_must_be_argos_configuration() {
    let text = "<configuration/>";
    assert_error(
        text,
        "<configuration",
        "the root element is <configuration>, expected <argos-configuration>",
    );
}

#[test]
fn unknown_section_suggests_the_closest_section() {
    let text = config(&[("<media>", "<medias>"), ("</media>", "</medias>")]);
    assert_error(
        &text,
        "<medias>",
        "unknown element <medias> in <argos-configuration> (did you mean 'media'?)",
    );
}

#[test]
fn a_section_may_appear_once() {
    let text = config(&[("  <media>", "  <media/>\n  <media>")]);
    let first = at(&text, "<media/>");
    assert_error(
        &text,
        "<media>",
        &format!("<media> appears twice in <argos-configuration> (first at {first})"),
    );
}

#[test]
fn framework_arena_and_physics_engines_are_required() {
    let text = "<argos-configuration>\n  <media/>\n</argos-configuration>";
    let errs = errors(text);
    assert_eq!(
        errs,
        [
            format!("{PATH}:1:1: <argos-configuration> has no <framework> section"),
            format!("{PATH}:1:1: <argos-configuration> has no <physics_engines> section"),
            format!("{PATH}:1:1: <argos-configuration> has no <arena> section"),
        ]
    );
}

#[test]
fn unreadable_file_names_the_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("missing.argos");
    let err = Experiment::load(&path).expect_err("missing file");
    let message = err.to_string();
    assert!(
        message.starts_with(&format!("{}: cannot read the file: ", path.display())),
        "{message}"
    );
}

// ---- framework ----

#[test]
fn experiment_element_is_required() {
    let text = config(&[("FRAMEWORK", "")]);
    assert_error(
        &text,
        "<framework>",
        "<framework> has no <experiment> element",
    );
}

#[test]
fn ticks_per_second_must_be_positive() {
    let text = config(&[(
        "FRAMEWORK",
        r#"<experiment ticks_per_second="0" random_seed="1"/>"#,
    )]);
    assert_error(
        &text,
        "ticks_per_second=",
        "'ticks_per_second' in <experiment> must be greater than 0",
    );
}

#[test]
fn ticks_per_second_is_required() {
    let text = config(&[("FRAMEWORK", r#"<experiment random_seed="1"/>"#)]);
    assert_error(
        &text,
        "<experiment",
        "<experiment> is missing the attribute 'ticks_per_second'",
    );
}

#[test]
fn random_seed_must_be_an_integer() {
    let text = config(&[(
        "FRAMEWORK",
        r#"<experiment ticks_per_second="10" random_seed="abc"/>"#,
    )]);
    assert_error(
        &text,
        "random_seed=",
        "invalid 'random_seed' in <experiment>: 'abc' is not a non-negative integer",
    );
}

#[test]
fn negative_length_is_rejected() {
    let text = config(&[(
        "FRAMEWORK",
        r#"<experiment length="-5" ticks_per_second="10" random_seed="1"/>"#,
    )]);
    assert_error(
        &text,
        "length=",
        "'length' in <experiment> must be at least 0, got -5",
    );
}

#[test]
fn unknown_framework_element_suggests_a_name() {
    let text = config(&[("FRAMEWORK", &format!("{FRAMEWORK}<experiments/>"))]);
    assert_error(
        &text,
        "<experiments",
        "unknown element <experiments> in <framework> (did you mean 'experiment'?)",
    );
}

// ---- controllers and devices ----

#[test]
fn unknown_sensor_suggests_the_registered_name() {
    let text = config(&[("SENSORS", r#"<epuck_prox implementation="default"/>"#)]);
    assert_error(
        &text,
        "<epuck_prox",
        "unknown sensor 'epuck_prox' in controller 'fdc' (did you mean 'epuck_proximity'?)",
    );
}

#[test]
fn actuator_under_sensors_says_where_it_belongs() {
    let text = config(&[("SENSORS", r#"<epuck_wheels implementation="default"/>"#)]);
    assert_error(
        &text,
        "<epuck_wheels implementation=\"default\"/>\n      </sensors>",
        "'epuck_wheels' is an actuator, not a sensor, in controller 'fdc' (declare it under <actuators>)",
    );
}

#[test]
fn a_device_is_declared_once_per_controller() {
    let text = config(&[("SENSORS", &format!("{SENSORS}\n        <epuck_proximity/>"))]);
    let first = at(&text, SENSORS);
    assert_error(
        &text,
        "<epuck_proximity/>",
        &format!("duplicate sensor 'epuck_proximity' in controller 'fdc' (first at {first})"),
    );
}

#[test]
fn controller_ids_are_unique() {
    let text = config(&[(
        "  </controllers>",
        "    <other id=\"fdc\"/>\n  </controllers>",
    )]);
    assert_error(
        &text,
        "id=\"fdc\"/>",
        "duplicate controller id 'fdc' (first at 8:5)",
    );
}

#[test]
fn controller_needs_an_id() {
    let text = config(&[("  </controllers>", "    <other/>\n  </controllers>")]);
    assert_error(&text, "<other/>", "<other> is missing the attribute 'id'");
}

#[test]
fn unknown_controller_child_suggests_params() {
    let text = config(&[("<params velocity", "<param velocity")]);
    assert_error(
        &text,
        "<param ",
        "unknown element <param> in <test_controller> (did you mean 'params'?)",
    );
}

#[test]
fn camera_needs_a_medium() {
    let text = config(&[(
        "SENSORS",
        r#"<epuck_omnidirectional_camera implementation="rot_z_only"/>"#,
    )]);
    assert_error(
        &text,
        "<epuck_omnidirectional_camera",
        "sensor 'epuck_omnidirectional_camera' in controller 'fdc' needs a 'medium' naming a <led> medium",
    );
}

#[test]
fn undeclared_medium_suggests_adding_it() {
    let text = config(&[
        (
            "SENSORS",
            r#"<epuck_omnidirectional_camera medium="cams"/>"#,
        ),
        ("MEDIA", ""),
    ]);
    assert_error(
        &text,
        "medium=\"cams\"",
        "sensor 'epuck_omnidirectional_camera' in controller 'fdc' uses medium 'cams', which <media> does not declare (add <led id=\"cams\"/> to <media>)",
    );
}

#[test]
fn misspelt_medium_suggests_the_declared_one() {
    let text = config(&[("SENSORS", r#"<epuck_omnidirectional_camera medium="led"/>"#)]);
    assert_error(
        &text,
        "medium=\"led\"",
        "sensor 'epuck_omnidirectional_camera' in controller 'fdc' uses medium 'led', which <media> does not declare (did you mean 'leds'?)",
    );
}

#[test]
fn medium_of_the_wrong_kind_is_rejected() {
    let text = config(&[
        ("SENSORS", r#"<epuck_omnidirectional_camera medium="rab"/>"#),
        ("MEDIA", r#"<range_and_bearing id="rab"/>"#),
    ]);
    assert_error(
        &text,
        "medium=\"rab\"",
        "sensor 'epuck_omnidirectional_camera' in controller 'fdc' uses medium 'rab', which is a <range_and_bearing> medium; it needs a <led> medium",
    );
}

#[test]
fn rab_data_size_is_one_to_four_bytes() {
    let text = config(&[
        (
            "SENSORS",
            r#"<range_and_bearing medium="rab" data_size="5"/>"#,
        ),
        ("MEDIA", r#"<range_and_bearing id="rab"/>"#),
    ]);
    assert_error(
        &text,
        "data_size=",
        "'data_size' in <range_and_bearing> must be between 1 and 4, got 5",
    );
}

#[test]
fn noise_level_must_not_be_negative() {
    let text = config(&[("SENSORS", r#"<epuck_proximity noise_level="-0.1"/>"#)]);
    assert_error(
        &text,
        "noise_level=",
        "'noise_level' in <epuck_proximity> must be at least 0, got -0.1",
    );
}

#[test]
fn bad_boolean_is_located_at_the_attribute() {
    let text = config(&[("SENSORS", r#"<epuck_proximity argos_uniform_ring="yes"/>"#)]);
    assert_error(
        &text,
        "argos_uniform_ring=",
        "invalid 'argos_uniform_ring' in <epuck_proximity>: 'yes' is not 'true' or 'false'",
    );
}

#[test]
fn supervisors_list_has_no_empty_entries() {
    let text = config(&[(
        "<params velocity=\"12.8\"/>",
        r#"<params supervisors="models/a.xml,,models/b.xml"/>"#,
    )]);
    assert_error(
        &text,
        "supervisors=",
        "'supervisors' in <params> has an empty entry: 'models/a.xml,,models/b.xml' (separate supervisor files with single commas)",
    );
}

#[test]
fn velocity_param_is_a_non_negative_number() {
    let text = config(&[("velocity=\"12.8\"", "velocity=\"fast\"")]);
    assert_error(
        &text,
        "velocity=",
        "invalid 'velocity' in <params>: 'fast' is not a number",
    );
}

#[test]
fn profile_param_is_not_empty() {
    let text = config(&[("<params velocity=\"12.8\"/>", r#"<params profile=" "/>"#)]);
    assert_error(
        &text,
        "profile=",
        "'profile' in <params> is empty (name an agent profile, e.g. obstacle_avoidance)",
    );
}

// ---- arena entities ----

#[test]
fn vectors_need_three_components() {
    let text = config(&[(
        "ARENA",
        r#"<box id="b" size="0.1,0.1" movable="false"><body position="0,0,0"/></box>"#,
    )]);
    assert_error(
        &text,
        "size=\"0.1,0.1\"",
        "invalid 'size' in <box>: '0.1,0.1' has 2 component(s), expected a vector \"x,y,z\"",
    );
}

#[test]
fn hand_placed_entity_needs_a_body() {
    let text = config(&[(
        "ARENA",
        r#"<box id="b" size="0.1,0.1,0.1" movable="false"/>"#,
    )]);
    assert_error(
        &text,
        "<box id=\"b\"",
        "<box> placed by hand needs a <body position=\"x,y,z\" orientation=\"z,y,x\"/>",
    );
}

#[test]
fn body_position_is_required() {
    let text = config(&[(
        "ARENA",
        r#"<box id="b" size="0.1,0.1,0.1"><body orientation="0,0,0"/></box>"#,
    )]);
    assert_error(&text, "<body", "<body> is missing the attribute 'position'");
}

#[test]
fn distribute_template_has_no_body() {
    let text = config(&[(
        "ARENA",
        r#"<distribute>
      <position method="uniform" min="-1,-1,0" max="1,1,0"/>
      <orientation method="constant" values="0,0,0"/>
      <entity quantity="2" max_trials="10">
        <box id="b" size="0.1,0.1,0.1"><body position="0,0,0"/></box>
      </entity>
    </distribute>"#,
    )]);
    assert_error(
        &text,
        "<body",
        "<body> is not allowed in a <distribute> template: <position> and <orientation> place each <box>",
    );
}

#[test]
fn movable_entity_needs_a_mass() {
    let text = config(&[(
        "ARENA",
        r#"<cylinder id="c" radius="0.1" height="0.2" movable="true"><body position="0,0,0"/></cylinder>"#,
    )]);
    assert_error(
        &text,
        "<cylinder",
        "a movable <cylinder> needs a 'mass' (kg)",
    );
}

#[test]
fn sizes_must_be_positive() {
    let text = config(&[(
        "ARENA",
        r#"<cylinder id="c" radius="0" height="0.2"><body position="0,0,0"/></cylinder>"#,
    )]);
    assert_error(
        &text,
        "radius=",
        "'radius' in <cylinder> must be greater than 0, got 0",
    );
}

#[test]
fn other_robot_models_are_not_supported() {
    let text = config(&[("ARENA", r#"<eye-bot id="eb"/>"#)]);
    assert_error(
        &text,
        "<eye-bot",
        "entity <eye-bot> is not supported: the world simulates e-pucks, foot-bots and <disc-robot>s",
    );
}

#[test]
fn a_device_of_another_robot_is_refused_where_it_is_declared() {
    let text = config(&[(
        "ARENA",
        r#"<e-puck id="ep"><body position="0,0,0"/><controller config="fdc"/></e-puck>"#,
    )])
    .replace(SENSORS, r#"<footbot_proximity implementation="default"/>"#);
    let robot_at = at(&text, "<e-puck");
    assert_error(
        &text,
        "<footbot_proximity",
        &format!(
            "'footbot_proximity' exists only on the foot-bot, but <e-puck> 'ep' at {robot_at} uses controller \
             'fdc' (use the generic name (e.g. proximity, light, ground) or a controller for this robot)"
        ),
    );
}

#[test]
fn only_a_movable_object_can_be_lifted() {
    let text = config(&[(
        "ARENA",
        r#"<box id="b" size="0.3,0.3,0.2" movable="false" lift_by="2"><body position="0,0,0"/></box>"#,
    )]);
    assert_error(
        &text,
        "lift_by=",
        "'lift_by' needs a movable <box> (movable=\"true\" and a mass)",
    );
    let text = config(&[(
        "ARENA",
        r#"<cylinder id="c" radius="0.1" height="0.2" movable="true" mass="1" lift_by="0"><body position="0,0,0"/></cylinder>"#,
    )]);
    assert_error(
        &text,
        "lift_by=",
        "'lift_by' in <cylinder> must be between 1 and 64, got 0",
    );
}

#[test]
fn a_footbot_payload_beyond_four_bytes_is_refused() {
    let text = config(&[(
        "ARENA",
        r#"<foot-bot id="fb" rab_data_size="11"><body position="0,0,0"/><controller config="fdc"/></foot-bot>"#,
    )])
    .replace("<epuck_wheels implementation=\"default\"/>", "<differential_steering implementation=\"default\"/>")
    .replace(SENSORS, r#"<footbot_proximity implementation="default"/>"#);
    assert_error(
        &text,
        "rab_data_size=",
        "'rab_data_size' in <foot-bot> must be between 1 and 4, got 11",
    );
}

#[test]
fn unknown_entity_suggests_the_closest() {
    let text = config(&[("ARENA", r#"<cylindre id="c"/>"#)]);
    assert_error(
        &text,
        "<cylindre",
        "unknown element <cylindre> in <arena> (did you mean 'cylinder'?)",
    );
}

#[test]
fn epuck_needs_a_controller() {
    let text = config(&[(
        "ARENA",
        r#"<e-puck id="ep0"><body position="0,0,0"/></e-puck>"#,
    )]);
    assert_error(
        &text,
        "<e-puck",
        "<e-puck> needs a <controller config=\"controller id\"/>",
    );
}

#[test]
fn robot_controller_must_be_declared() {
    let text = config(&[(
        "ARENA",
        r#"<e-puck id="ep0"><body position="0,0,0"/><controller config="fcd"/></e-puck>"#,
    )]);
    assert_error(
        &text,
        "<e-puck",
        "<e-puck> 'ep0' refers to controller 'fcd', which <controllers> does not declare (did you mean 'fdc'?)",
    );
}

#[test]
fn hand_placed_ids_are_unique() {
    let text = config(&[(
        "ARENA",
        &format!("{ARENA}\n    {}", ARENA.replace("<box", "<box ")),
    )]);
    let first = at(&text, "<box id");
    assert_error(
        &text,
        "<box  id",
        &format!("duplicate id 'wall': <box> 'wall' at {first} already uses it"),
    );
}

const ROBOTS: &str = r#"<distribute>
      <position method="uniform" min="-1,-1,0" max="1,1,0"/>
      <orientation method="gaussian" mean="0,0,0" std_dev="360,0,0"/>
      <entity quantity="40" max_trials="100">
        <e-puck id="fb"><controller config="fdc"/></e-puck>
      </entity>
    </distribute>"#;

#[test]
fn hand_placed_id_must_not_clash_with_generated_ids() {
    let text = config(&[(
        "ARENA",
        &format!("{ROBOTS}\n    <box id=\"fb39\" size=\"1,1,1\"><body position=\"0,0,0\"/></box>"),
    )]);
    let distribute = at(&text, "<distribute>");
    assert_error(
        &text,
        "<box id=\"fb39\"",
        &format!(
            "duplicate id 'fb39': <box> 'fb39' clashes with the ids generated by the <distribute> at {distribute}"
        ),
    );
}

#[test]
fn ids_beyond_the_generated_range_are_free() {
    let text = config(&[(
        "ARENA",
        &format!(
            "{ROBOTS}\n    <box id=\"fb40\" size=\"1,1,1\"><body position=\"0,0,0\"/></box>\n    <box id=\"fb03\" size=\"1,1,1\"><body position=\"0,0,0\"/></box>"
        ),
    )]);
    assert!(Experiment::parse(PATH, &text).is_ok());
}

#[test]
fn distributions_with_the_same_base_id_must_not_overlap() {
    let second = ROBOTS.replace("quantity=\"40\"", "quantity=\"5\" base_num=\"38\"");
    let text = config(&[("ARENA", &format!("{ROBOTS}\n    {second}"))]);
    let first = at(&text, "<distribute>");
    let second_entity = at(&text, "<entity quantity=\"5\"");
    assert_eq!(
        errors(&text),
        [format!(
            "{PATH}:{second_entity}: <distribute> generates id 'fb38', which the <distribute> at {first} also generates (give the templates different ids or non-overlapping base_num ranges)"
        )]
    );
}

#[test]
fn a_base_id_ending_in_digits_can_clash_with_a_shorter_base() {
    // "fb" with 40 robots makes fb10..fb39; "fb1" with 5 makes fb10..fb14.
    let second = ROBOTS
        .replace("quantity=\"40\"", "quantity=\"5\"")
        .replace("id=\"fb\"", "id=\"fb1\"");
    let text = config(&[("ARENA", &format!("{ROBOTS}\n    {second}"))]);
    let errs = errors(&text);
    assert_eq!(errs.len(), 1, "{errs:?}");
    assert!(errs[0].contains("generates id 'fb10'"), "{}", errs[0]);
}

fn distribution(position: &str, orientation: &str, entity: &str) -> String {
    format!(
        r#"<distribute>
      {position}
      {orientation}
      {entity}
    </distribute>"#
    )
}

const CONSTANT_ORIENTATION: &str = r#"<orientation method="constant" values="0,0,0"/>"#;
const BOXES: &str =
    r#"<entity quantity="20" max_trials="10"><box id="b" size="0.1,0.1,0.1"/></entity>"#;

#[test]
fn uniform_min_must_not_exceed_max() {
    let position = r#"<position method="uniform" min="1,-1,0" max="-1,1,0"/>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, BOXES),
    )]);
    assert_error(
        &text,
        "min=",
        "uniform position min '1,-1,0' exceeds max '-1,1,0' in x",
    );
}

#[test]
fn hand_placed_entity_must_be_inside_the_arena() {
    let text = config(&[(
        "ARENA",
        r#"<box id="b" size="0.1,0.1,0.1"><body position="1.6,0,0"/></box>"#,
    )]);
    assert_error(
        &text,
        "<box",
        "<box> 'b' at 1.6,0,0 is outside the arena (the arena spans x -1.5..1.5, y -1.5..1.5)",
    );
}

#[test]
fn uniform_range_must_stay_inside_the_arena() {
    let position = r#"<position method="uniform" min="-1.5,-1.5,0" max="1.5,2,0"/>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, BOXES),
    )]);
    assert_error(
        &text,
        "<position",
        "<distribute> positions from -1.5,-1.5,0 to 1.5,2,0 reach outside the arena (the arena spans x -1.5..1.5, y -1.5..1.5)",
    );
}

#[test]
fn grid_must_stay_inside_the_arena() {
    let position = r#"<position method="grid" center="0,0,0" distances="1,1,0" layout="5,1,1"/>"#;
    let entity = r#"<entity quantity="5" max_trials="1"><box id="b" size="0.1,0.1,0.1"/></entity>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, entity),
    )]);
    assert_error(
        &text,
        "<position",
        "<distribute> positions from -2,0,0 to 2,0,0 reach outside the arena (the arena spans x -1.5..1.5, y -1.5..1.5)",
    );
}

#[test]
fn grid_quantity_must_fit_the_layout() {
    let position =
        r#"<position method="grid" center="0,0,0" distances="0.2,0.2,0" layout="4,4,1"/>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, BOXES),
    )]);
    assert_error(
        &text,
        "quantity=",
        "quantity 20 exceeds the grid layout's 4x4x1 = 16 cells",
    );
}

#[test]
fn grid_layout_needs_a_cell_on_every_axis() {
    let position =
        r#"<position method="grid" center="0,0,0" distances="0.2,0.2,0" layout="4,4,0"/>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, BOXES),
    )]);
    assert_error(
        &text,
        "layout=",
        "grid 'layout' needs at least 1 cell along each axis, got 4,4,0",
    );
}

#[test]
fn grid_is_a_position_method_only() {
    let position = r#"<position method="constant" values="0,0,0"/>"#;
    let orientation = r#"<orientation method="grid" center="0,0,0"/>"#;
    let text = config(&[("ARENA", &distribution(position, orientation, BOXES))]);
    assert_error(
        &text,
        "method=\"grid\"",
        "unknown orientation method 'grid' (expected uniform, gaussian, constant) (grid places positions only)",
    );
}

#[test]
fn misspelt_method_suggests_the_closest() {
    let position = r#"<position method="uniforn" min="0,0,0" max="1,1,0"/>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, BOXES),
    )]);
    assert_error(
        &text,
        "method=\"uniforn\"",
        "unknown position method 'uniforn' (expected uniform, gaussian, constant, grid) (did you mean 'uniform'?)",
    );
}

#[test]
fn gaussian_std_dev_must_not_be_negative() {
    let position = r#"<position method="gaussian" mean="0,0,0" std_dev="-0.1,0.1,0"/>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, BOXES),
    )]);
    assert_error(
        &text,
        "std_dev=",
        "gaussian position 'std_dev' must not be negative",
    );
}

#[test]
fn entity_holds_exactly_one_template() {
    let position = r#"<position method="constant" values="0,0,0"/>"#;
    let entity = r#"<entity quantity="1" max_trials="1"><box id="a" size="1,1,1"/><box id="b" size="1,1,1"/></entity>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, entity),
    )]);
    assert_error(
        &text,
        "<entity",
        "<entity> must contain exactly one entity template, found 2",
    );
}

#[test]
fn floors_cannot_be_distributed() {
    let position = r#"<position method="constant" values="0,0,0"/>"#;
    let entity =
        r#"<entity quantity="1" max_trials="1"><floor id="f" source="loop_functions"/></entity>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, entity),
    )]);
    assert_error(&text, "<floor", "<floor> cannot be distributed");
}

#[test]
fn distribute_needs_an_orientation() {
    let position = r#"<position method="constant" values="0,0,0"/>"#;
    let text = config(&[("ARENA", &distribution(position, "", BOXES))]);
    assert_error(&text, "<distribute>", "<distribute> has no <orientation>");
}

#[test]
fn max_trials_is_required() {
    let position = r#"<position method="constant" values="0,0,0"/>"#;
    let entity = r#"<entity quantity="1"><box id="a" size="1,1,1"/></entity>"#;
    let text = config(&[(
        "ARENA",
        &distribution(position, CONSTANT_ORIENTATION, entity),
    )]);
    assert_error(
        &text,
        "<entity",
        "<entity> is missing the attribute 'max_trials'",
    );
}

#[test]
fn misspelt_colour_suggests_a_name() {
    let text = config(&[(
        "ARENA",
        r#"<light id="l" position="0,0,1" color="yelow" intensity="3" medium="leds"/>"#,
    )]);
    assert_error(
        &text,
        "color=",
        "invalid 'color' in <light>: 'yelow' is not a colour name (e.g. 'red') or \"r,g,b[,a]\" with 0-255 components (did you mean 'yellow'?)",
    );
}

#[test]
fn light_intensity_must_be_positive() {
    let text = config(&[(
        "ARENA",
        r#"<light id="l" position="0,0,1" color="yellow" intensity="0" medium="leds"/>"#,
    )]);
    assert_error(
        &text,
        "intensity=",
        "'intensity' in <light> must be greater than 0, got 0",
    );
}

#[test]
fn light_needs_a_declared_led_medium() {
    let text = config(&[
        (
            "ARENA",
            r#"<light id="l" position="0,0,1" color="yellow" intensity="3" medium="leds"/>"#,
        ),
        ("MEDIA", ""),
    ]);
    assert_error(
        &text,
        "medium=",
        "<light> uses medium 'leds', which <media> does not declare (add <led id=\"leds\"/> to <media>)",
    );
}

#[test]
fn unknown_floor_source_suggests_one() {
    let text = config(&[("ARENA", r#"<floor id="f" source="region"/>"#)]);
    assert_error(
        &text,
        "source=",
        "unknown floor source 'region' (expected loop_functions, image or regions) (did you mean 'regions'?)",
    );
}

#[test]
fn regions_belong_to_a_regions_floor() {
    let text = config(&[(
        "ARENA",
        r#"<floor id="f" source="loop_functions"><region min="0,0" max="1,1" color="black"/></floor>"#,
    )]);
    assert_error(
        &text,
        "<region",
        "<region> is not allowed in a <floor source=\"loop_functions\"> (use source=\"regions\" to paint regions)",
    );
}

#[test]
fn region_min_must_not_exceed_max() {
    let text = config(&[(
        "ARENA",
        r#"<floor id="f" source="regions"><region min="0,0" max="-1,1" color="black"/></floor>"#,
    )]);
    assert_error(&text, "<region", "<region> min '0,0' exceeds max '-1,1'");
}

#[test]
fn image_floor_needs_a_path() {
    let text = config(&[("ARENA", r#"<floor id="f" source="image"/>"#)]);
    assert_error(&text, "<floor", "<floor> is missing the attribute 'path'");
}

// ---- physics engines ----

#[test]
fn three_d_engines_are_not_supported() {
    let text = config(&[("ENGINES", r#"<dynamics3d id="dyn3d"/>"#)]);
    let errs = errors(&text);
    let loc = at(&text, "<dynamics3d");
    assert_eq!(
        errs,
        [
            format!(
                "{PATH}:{}: <physics_engines> declares no engine (add <dynamics2d id=\"dyn2d\"/>)",
                at(&text, "<physics_engines>")
            ),
            format!(
                "{PATH}:{loc}: physics engine <dynamics3d> is not supported: the world is 2-D (use <dynamics2d id=\"dyn2d\"/>)"
            ),
        ]
    );
}

#[test]
fn one_physics_engine_only() {
    let text = config(&[(
        "ENGINES",
        "<dynamics2d id=\"a\"/>\n    <dynamics2d id=\"b\"/>",
    )]);
    let first = at(&text, "<dynamics2d id=\"a\"");
    assert_error(
        &text,
        "<dynamics2d id=\"b\"",
        &format!(
            "a second physics engine (first at {first}): the world runs one dynamics2d engine over the whole arena"
        ),
    );
}

// ---- media ----

#[test]
fn unsupported_medium_lists_the_supported_ones() {
    let text = config(&[("MEDIA", r#"<simple_radio id="radio"/>"#)]);
    assert_error(
        &text,
        "<simple_radio",
        "medium <simple_radio> is not supported (supported media: led, range_and_bearing, pheromone, messages)",
    );
}

#[test]
fn medium_ids_are_unique_across_kinds() {
    let text = config(&[(
        "MEDIA",
        "<led id=\"m\"/>\n    <range_and_bearing id=\"m\"/>",
    )]);
    let first = at(&text, "<led");
    assert_error(
        &text,
        "<range_and_bearing",
        &format!("duplicate medium id 'm' (first at {first})"),
    );
}

#[test]
fn pheromone_field_has_at_most_two_channels() {
    let text = config(&[(
        "MEDIA",
        r#"<pheromone id="p" cell_size="0.05">
      <channel name="a" evaporation="0.001"/>
      <channel name="b" evaporation="0.001"/>
      <channel name="c" evaporation="0.001"/>
    </pheromone>"#,
    )]);
    assert_error(
        &text,
        "<channel name=\"c\"",
        "<pheromone> declares 3 channels; the sensor frame carries at most 2",
    );
}

#[test]
fn pheromone_evaporation_is_a_fraction() {
    let text = config(&[(
        "MEDIA",
        r#"<pheromone id="p" cell_size="0.05"><channel name="a" evaporation="1.5"/></pheromone>"#,
    )]);
    assert_error(
        &text,
        "evaporation=",
        "'evaporation' in <channel> must be between 0 and 1, got 1.5",
    );
}

#[test]
fn pheromone_channel_names_are_unique() {
    let text = config(&[(
        "MEDIA",
        "<pheromone id=\"p\" cell_size=\"0.05\">\n      <channel name=\"a\" evaporation=\"0\"/>\n      <channel name=\"a\" evaporation=\"0\"/>\n    </pheromone>",
    )]);
    let first = at(&text, "<channel");
    let second = at(
        &text,
        "<channel name=\"a\" evaporation=\"0\"/>\n    </pheromone>",
    );
    assert_eq!(
        errors(&text),
        [format!(
            "{PATH}:{second}: duplicate pheromone channel 'a' (first at {first})"
        )]
    );
}

#[test]
fn pheromone_field_needs_a_channel() {
    let text = config(&[("MEDIA", r#"<pheromone id="p" cell_size="0.05"/>"#)]);
    assert_error(
        &text,
        "<pheromone",
        "<pheromone> declares no <channel> (add e.g. <channel name=\"food\" evaporation=\"0.001\"/>)",
    );
}

// ---- all errors at once ----

#[test]
fn every_error_in_a_file_is_reported_in_file_order() {
    let text = config(&[
        ("FRAMEWORK", r#"<experiment ticks_per_second="0"/>"#),
        ("SENSORS", r#"<epuck_prox/>"#),
        (
            "ARENA",
            r#"<box id="b" size="1,1" movable="false"><body position="0,0,0"/></box>"#,
        ),
    ]);
    let errs = errors(&text);
    assert_eq!(errs.len(), 3, "{errs:?}");
    assert!(errs[0].contains("ticks_per_second"), "{}", errs[0]);
    assert!(
        errs[1].contains("unknown sensor 'epuck_prox'"),
        "{}",
        errs[1]
    );
    assert!(errs[2].contains("invalid 'size' in <box>"), "{}", errs[2]);
}

#[test]
fn bad_fixture_file_reports_its_path_line_and_column() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/bad/unknown_sensor.argos");
    let err = Experiment::load(&path).expect_err("bad fixture");
    assert_eq!(
        err.to_string(),
        format!(
            "{}:12:9: unknown sensor 'epuck_prox' in controller 'fdc' (did you mean 'epuck_proximity'?)",
            path.display()
        )
    );
}

#[test]
fn a_limit_in_system_must_be_a_whole_number_above_zero() {
    let text = config(&[(
        r#"<system threads="0"/>"#,
        r#"<system threads="0" tick_deadline_ms="0"/>"#,
    )]);
    assert_error(
        &text,
        r#"tick_deadline_ms="0""#,
        "in <system>: limit tick_deadline_ms=0: the value must be a whole number above 0",
    );
}

#[test]
fn limits_in_system_override_the_defaults_and_a_misspelt_one_is_named() {
    let text = config(&[(
        r#"<system threads="0"/>"#,
        r#"<system threads="0" join_timeout_ms="4000" tick_deadline="300"/>"#,
    )]);
    let (experiment, warnings) = Experiment::parse(PATH, &text).expect("valid");
    let limits = experiment.framework.limits;
    assert_eq!(limits.join_timeout_ms, 4000);
    assert_eq!(
        limits.tick_deadline_ms, 500,
        "the misspelt attribute sets nothing"
    );
    let warnings: Vec<String> = warnings.iter().map(ToString::to_string).collect();
    assert!(
        warnings.iter().any(
            |w| w.contains("'tick_deadline'") && w.contains("did you mean 'tick_deadline_ms'?")
        ),
        "{warnings:?}"
    );
}

#[test]
fn an_arena_larger_than_the_physics_can_place_precisely_is_refused() {
    for size in ["1e15,3,1", "3,1e38,1", "10000.5,3,1"] {
        let text = config(&[(r#"size="3,3,1""#, &format!(r#"size="{size}""#))]);
        let errors = errors(&text);
        assert_eq!(errors.len(), 1, "{size}: {errors:?}");
        assert!(
            errors[0].contains("arena 'size' must be positive and at most 10000 m in x and y"),
            "{size}: {errors:?}"
        );
    }
}

#[test]
fn messages_medium_limits_are_bounded() {
    let text = config(&[("MEDIA", r#"<messages id="net" loss="1.5"/>"#)]);
    assert_error(
        &text,
        "loss=",
        "'loss' in <messages> must be between 0 and 1, got 1.5",
    );
    let text = config(&[("MEDIA", r#"<messages id="net" max_payload="300"/>"#)]);
    assert_error(
        &text,
        "max_payload=",
        "'max_payload' in <messages> must be between 1 and 256, got 300",
    );
    let text = config(&[("MEDIA", r#"<messages id="net" max_per_tick="0"/>"#)]);
    assert_error(
        &text,
        "max_per_tick=",
        "'max_per_tick' in <messages> must be between 1 and 32, got 0",
    );
}

/// The base with `<coordinators>` holding `coordinators`, and `arena` in the arena.
fn with_coordinators(arena: &str, coordinators: &str) -> String {
    config(&[("ARENA", arena)]).replace(
        "</argos-configuration>",
        &format!("  <coordinators>{coordinators}</coordinators>\n</argos-configuration>"),
    )
}

#[test]
fn a_coordinator_names_a_declared_controller_and_an_id_of_its_own() {
    let text = with_coordinators(
        ARENA,
        r#"<coordinator id="store"><controller config="fcd"/></coordinator>"#,
    );
    assert_eq!(
        errors(&text),
        [format!(
            "{PATH}:{}: <coordinator> 'store' refers to controller 'fcd', which <controllers> does not declare \
             (did you mean 'fdc'?)",
            at(&text, "<coordinator id")
        )]
    );
    let robot = r#"<e-puck id="ep"><body position="0,0,0"/><controller config="fdc"/></e-puck>"#;
    let text = with_coordinators(
        robot,
        r#"<coordinator id="ep"><controller config="fdc"/></coordinator>"#,
    );
    assert_error(
        &text,
        "<coordinator id",
        "duplicate id 'ep': a robot of the arena already uses it",
    );
}

#[test]
fn a_robot_joins_at_one_moment_from_the_first_tick_on() {
    let robot = |attributes: &str| {
        format!(
            r#"<e-puck id="ep" {attributes}><body position="0,0,0"/><controller config="fdc"/></e-puck>"#
        )
    };
    let text = config(&[("ARENA", &robot(r#"join_tick="0""#))]);
    assert_error(
        &text,
        "join_tick=",
        "'join_tick' in <e-puck> must be at least 1, got 0",
    );
    let text = config(&[("ARENA", &robot(r#"join_tick="5" spare="true""#))]);
    assert_error(
        &text,
        "<e-puck",
        "<e-puck> gives join_tick and spare; give at most one of join_tick, join_time and spare",
    );
}
