//! Harmless unsupported elements and attributes load with a located warning instead of an error.

use swarm_contract::config::Experiment;

const PATH: &str = "configs/test.argos";

fn warnings(text: &str) -> Vec<String> {
    match Experiment::parse(PATH, text) {
        Ok((_, warnings)) => warnings.iter().map(ToString::to_string).collect(),
        Err(e) => panic!("expected a valid configuration, got:\n{e}"),
    }
}

/// A valid configuration with `framework`, `sensor`, `arena` and `extra` (after `<media>`) inserted.
fn config(framework: &str, sensor: &str, arena: &str, extra: &str) -> String {
    format!(
        r#"<argos-configuration>
  <framework>
    {framework}
  </framework>
  <controllers>
    <c id="fdc">
      <sensors>
        {sensor}
      </sensors>
    </c>
  </controllers>
  <arena size="3,3,1">
    {arena}
  </arena>
  <physics_engines>
    <dynamics2d id="dyn2d"><boundaries/></dynamics2d>
  </physics_engines>
  <media><led id="leds"/></media>
  {extra}
</argos-configuration>"#
    )
}

const EXPERIMENT: &str = r#"<experiment ticks_per_second="10" random_seed="7"/>"#;
const PROXIMITY: &str = "<epuck_proximity/>";
const BOUNDARIES: &str =
    "configs/test.argos:16:28: <boundaries> is ignored: the engine covers the whole arena";

#[test]
fn show_rays_is_accepted_and_ignored() {
    let text = config(EXPERIMENT, r#"<epuck_proximity show_rays="true"/>"#, "", "");
    assert_eq!(
        warnings(&text),
        [
            "configs/test.argos:8:26: 'show_rays' is ignored: there is no GUI to draw rays in"
                .to_string(),
            BOUNDARIES.to_string(),
        ]
    );
}

#[test]
fn unknown_attribute_is_ignored_with_a_did_you_mean() {
    let text = config(
        EXPERIMENT,
        r#"<epuck_proximity noise_levle="0.02"/>"#,
        "",
        "",
    );
    assert_eq!(
        warnings(&text)[0],
        "configs/test.argos:8:26: unknown attribute 'noise_levle' in <epuck_proximity> is ignored (did you mean 'noise_level'?)"
    );
}

#[test]
fn visualization_and_user_functions_are_ignored() {
    let visualization = r#"<visualization>
    <qt-opengl>
      <camera><placement idx="0" position="0,0,3" look_at="0,0,0" lens_focal_length="20"/></camera>
      <user_functions library="x" label="y"/>
    </qt-opengl>
  </visualization>"#;
    let text = config(EXPERIMENT, PROXIMITY, "", visualization);
    assert_eq!(
        warnings(&text),
        [
            BOUNDARIES.to_string(),
            "configs/test.argos:19:3: <visualization> is ignored: runs are headless".to_string(),
            "configs/test.argos:22:7: <user_functions> is ignored: there is no GUI to draw in"
                .to_string(),
        ]
    );
}

#[test]
fn absent_or_zero_seed_is_left_to_the_launcher() {
    for experiment in [
        r#"<experiment ticks_per_second="10"/>"#,
        r#"<experiment ticks_per_second="10" random_seed="0"/>"#,
    ] {
        let text = config(experiment, PROXIMITY, "", "");
        let (exp, warnings) = Experiment::parse(PATH, &text).expect("valid");
        assert_eq!(exp.framework.random_seed, None);
        assert_eq!(
            warnings[0].to_string(),
            "configs/test.argos:3:5: no random_seed (absent or 0): the launcher draws one from the clock and prints it"
        );
    }
}

#[test]
fn profiling_and_positional_grid_size_are_ignored() {
    let framework = format!("{EXPERIMENT}\n    <profiling file=\"p.txt\"/>");
    let text = config(&framework, PROXIMITY, "", "").replace(
        r#"<arena size="3,3,1">"#,
        r#"<arena size="3,3,1" positional_grid_size="10,10,1">"#,
    );
    assert_eq!(
        warnings(&text),
        [
            "configs/test.argos:4:5: <profiling> is ignored: use `cargo bench` and the run log".to_string(),
            "configs/test.argos:13:23: 'positional_grid_size' is ignored: the world indexes space itself".to_string(),
            "configs/test.argos:17:28: <boundaries> is ignored: the engine covers the whole arena".to_string(),
        ]
    );
}

#[test]
fn mass_of_a_fixed_box_is_ignored() {
    let arena =
        r#"<box id="b" size="1,1,1" movable="false" mass="2"><body position="0,0,0"/></box>"#;
    let text = config(EXPERIMENT, PROXIMITY, arena, "");
    assert_eq!(
        warnings(&text)[0],
        "configs/test.argos:13:46: 'mass' is ignored: this <box> is not movable"
    );
}

#[test]
fn medium_on_a_device_without_one_is_ignored() {
    let text = config(EXPERIMENT, r#"<epuck_proximity medium="leds"/>"#, "", "");
    assert_eq!(
        warnings(&text)[0],
        "configs/test.argos:8:26: 'medium' is ignored: sensor 'epuck_proximity' in controller 'fdc' uses no medium"
    );
}

#[test]
fn target_led_above_the_camera_is_flagged() {
    let arena = r#"<target id="t" radius="0.02" height="0.05" led_height="0.2" medium="leds"><body position="0,0,0"/></target>"#;
    let text = config(EXPERIMENT, PROXIMITY, arena, "");
    assert_eq!(
        warnings(&text)[0],
        "configs/test.argos:13:48: target LED at 0.2 m is not below the e-puck camera (0.122 m): cameras will not see it"
    );
}

#[test]
fn footbot_perspective_camera_attributes_are_ignored_with_a_warning() {
    let arena = r#"<foot-bot id="fb" perspective_camera_front="false"><body position="0,0,0"/><controller config="fdc"/></foot-bot>"#;
    let text = config(EXPERIMENT, "<proximity/>", arena, "");
    assert_eq!(
        warnings(&text)[0],
        "configs/test.argos:13:23: 'perspective_camera_front' is ignored: the world simulates no perspective camera"
    );
}
