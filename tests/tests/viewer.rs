//! The viewer in a real browser: `swarm view` replaying a recorded run and `swarm run --view` following a live
//! one, driven through headless Chromium (chromedriver) as a user would: the page's numbers are checked against
//! the record files, the scrubber and a click on a robot against the supervisors replayed here from
//! `events.csv`, and bad run directories against their messages.

use std::collections::HashMap;
use std::path::Path;

use supervisor_gen::compiled::SupervisorSet;
use swarm_system_tests::browser::{Browser, ServedPage, distinct_colours};
use swarm_system_tests::{run_to_completion, workspace_file};

const CONFIG: &str = "configs/foraging/quick.argos";

/// Every robot's (x, y, heading, alive) at every tick of `trajectory.csv`.
fn trajectory(dir: &Path) -> HashMap<u64, Vec<(f32, f32, f32, bool)>> {
    let text = swarm_system_tests::run_text(dir, "trajectory.csv");
    let mut ticks: HashMap<u64, Vec<(f32, f32, f32, bool)>> = HashMap::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let number = |i: usize| f[i].parse::<f32>().expect("a number");
        ticks
            .entry(f[0].parse().expect("a tick"))
            .or_default()
            .push((number(3), number(4), number(5), f[9] == "1"));
    }
    ticks
}

/// Asserts that the page shows every robot where `trajectory.csv` has it at the tick it shows (`tick`, when
/// given), and returns that tick. Tick and robots are read in one script: a live page may move on between two.
fn assert_shows_recorded_tick(browser: &Browser, dir: &Path, tick: Option<u64>) -> u64 {
    let frame = browser.eval("{tick: viewer.tick(), robots: viewer.robots()}");
    let shown_tick = frame["tick"].as_u64().expect("a displayed tick");
    if let Some(tick) = tick {
        assert_eq!(shown_tick, tick);
    }
    let shown = frame["robots"].as_array().expect("the displayed robots");
    let recorded = &trajectory(dir)[&shown_tick];
    assert_eq!(shown.len(), recorded.len());
    for (index, (robot, &(x, y, heading, alive))) in shown.iter().zip(recorded).enumerate() {
        let at = |key: &str| robot[key].as_f64().map(|v| v as f32);
        assert_eq!(
            (at("x"), at("y"), at("heading"), robot["alive"].as_bool()),
            (Some(x), Some(y), Some(heading), Some(alive)),
            "robot {index} at tick {shown_tick}"
        );
    }
    shown_tick
}

/// The supervisors' states of `robot` after every event it fired up to `tick`, replayed from `events.csv`
/// through its compiled set: (supervisor name, state).
fn replayed_states(dir: &Path, robot: usize, tick: u64) -> Vec<(String, u64)> {
    let set = SupervisorSet::read(&dir.join("supervisors/fc.ptsct")).expect("the compiled set");
    let ids: HashMap<&str, u8> = set
        .events
        .iter()
        .enumerate()
        .map(|(id, e)| (e.name.as_str(), id as u8))
        .collect();
    let mut states = vec![0u16; set.supervisors.len()];
    let events = swarm_system_tests::run_text(dir, "events.csv");
    for line in events.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (t, r) = (
            f[0].parse::<u64>().expect("tick"),
            f[1].parse::<usize>().expect("robot"),
        );
        let Some(&event) = ids.get(f[3]) else {
            continue;
        };
        if r != robot || t > tick {
            continue;
        }
        for (state, supervisor) in states.iter_mut().zip(&set.supervisors) {
            if let Some(next) = supervisor.states[usize::from(*state)]
                .transitions
                .iter()
                .find(|t| t.event == event)
            {
                *state = next.target;
            }
        }
    }
    set.supervisors
        .iter()
        .zip(states)
        .map(|(s, state)| (s.name.clone(), u64::from(state)))
        .collect()
}

fn shown_states(browser: &Browser) -> Vec<(String, u64)> {
    browser
        .eval("viewer.selected().supervisors")
        .as_array()
        .expect("the panel's supervisors")
        .iter()
        .map(|s| {
            (
                s["name"].as_str().unwrap_or_default().to_owned(),
                s["state"].as_u64().unwrap_or(u64::MAX),
            )
        })
        .collect()
}

/// Saves a screenshot where the README's picture comes from when `SWARM_UPDATE_SCREENSHOT` is set, and checks
/// it is not blank.
fn check_screenshot(browser: &Browser, name: &str) {
    let png = browser.screenshot();
    assert!(
        distinct_colours(&png) > 50,
        "the {name} screenshot is blank"
    );
    let target = workspace_file("target").join(format!("{name}.png"));
    std::fs::write(&target, &png).expect("the screenshot is written");
    if std::env::var_os("SWARM_UPDATE_SCREENSHOT").is_some() {
        std::fs::write(
            workspace_file("docs/images").join(format!("{name}.png")),
            &png,
        )
        .expect("docs image");
    }
}

#[test]
fn replay_shows_recorded_ticks_scrubbing_and_a_robots_supervisors() {
    let run = tempfile::tempdir().expect("temp dir");
    let outcome = run_to_completion(
        CONFIG,
        run.path(),
        &["--ticks", "300", "--fault", "kill robots=3 tick=150"],
    );
    assert!(outcome.output.status.success(), "{}", outcome.stderr());
    let dir = run.path().display().to_string();
    let page = ServedPage::start(&["view", &dir, "--port", "0"]);
    let browser = Browser::start();
    browser.open(&page.url);
    browser.wait_for("viewer.ready");
    assert_eq!(browser.eval("viewer.problems()"), serde_json::json!([]));
    assert_eq!(
        browser.eval("document.querySelector('#robot-count').textContent.trim()"),
        "5"
    );
    assert_shows_recorded_tick(&browser, run.path(), None);

    // Scrub as a user drags the slider: the input's value changes and it fires `input`.
    browser.eval(
        "(() => { const s = document.querySelector('#scrubber'); s.value = 200; \
         s.dispatchEvent(new Event('input', {bubbles: true})); return true; })()",
    );
    browser.wait_for("viewer.whenDisplayed(200)");
    assert_shows_recorded_tick(&browser, run.path(), Some(200));
    let robots = browser.eval("viewer.robots()");
    assert_eq!(robots[3]["alive"], false, "robot 3 was killed at tick 150");

    let at = browser.eval("viewer.screenOf(1)");
    browser.click_at(at["x"].as_f64().expect("x"), at["y"].as_f64().expect("y"));
    browser.wait_for("viewer.whenSelected(1, 200)");
    let expected = replayed_states(run.path(), 1, 200);
    assert!(
        expected.iter().any(|(_, state)| *state != 0),
        "the robot's supervisors moved"
    );
    assert_eq!(shown_states(&browser), expected);
    let marker = browser.eval("document.querySelector('#markers').innerHTML");
    assert!(
        marker.as_str().unwrap_or_default().contains("fault:kill"),
        "{marker}"
    );

    check_screenshot(&browser, "viewer");
    assert_eq!(browser.console_errors(), Vec::<String>::new());
    assert_eq!(page.interrupt(), Some(130));
}

#[test]
fn live_view_follows_a_running_swarm_and_the_run_goes_on_when_it_closes() {
    const TICKS: u64 = 400;
    let run = tempfile::tempdir().expect("temp dir");
    let config = workspace_file(CONFIG).display().to_string();
    let (out, ticks) = (run.path().display().to_string(), TICKS.to_string());
    let page = ServedPage::start(&[
        "run",
        &config,
        "--no-progress",
        "--real-time",
        "--ticks",
        &ticks,
        "--out",
        &out,
        "--view",
        "--view-port",
        "0",
    ]);
    let browser = Browser::start();
    browser.open(&page.url);
    browser.wait_for("viewer.ready");
    let live = browser.eval("viewer.live()");
    assert_eq!(
        (live["live"].as_bool(), live["following"].as_bool()),
        (Some(true), Some(true)),
        "{live}"
    );
    let now = browser.eval("viewer.tick()").as_u64().unwrap_or(0);
    browser.wait_for(&format!("viewer.whenLiveTick({})", now + 10));
    let shown = assert_shows_recorded_tick(&browser, run.path(), None);
    assert!(shown >= now + 10 && shown < TICKS, "tick {shown}");
    check_screenshot(&browser, "viewer-live");
    assert_eq!(browser.console_errors(), Vec::<String>::new());

    // The page goes away mid-run; the run does not notice, ends on its own, and its viewer stays up.
    drop(browser);
    page.wait_for_output("the run is over");
    assert_eq!(swarm_system_tests::run_summary(run.path())["ticks"], TICKS);
    assert_eq!(page.interrupt(), Some(0), "Ctrl-C after a finished run");
}

#[test]
fn bad_run_directories_are_explained_in_the_page_and_the_terminal() {
    let run = tempfile::tempdir().expect("temp dir");
    let outcome = run_to_completion(CONFIG, run.path(), &["--ticks", "50", "--records", "csv"]);
    assert!(outcome.output.status.success(), "{}", outcome.stderr());

    // An older run (no scene.json) and a trajectory cut in the middle of a row.
    std::fs::remove_file(run.path().join("scene.json")).expect("scene removed");
    let trajectory = run.path().join("trajectory.csv");
    let text = std::fs::read(&trajectory).expect("trajectory");
    std::fs::write(&trajectory, &text[..text.len() - 7]).expect("trajectory cut");
    let dir = run.path().display().to_string();
    let page = ServedPage::start(&["view", &dir, "--port", "0"]);
    let browser = Browser::start();
    browser.open(&page.url);
    browser.wait_for("viewer.ready");
    let banner = browser.eval("document.querySelector('#problem').textContent");
    let banner = banner.as_str().unwrap_or_default();
    assert!(banner.contains("scene.json is missing"), "{banner}");
    assert!(banner.contains("trajectory.csv: the last"), "{banner}");
    let terminal = std::fs::read_to_string(page.log.path()).expect("the terminal's log");
    assert!(terminal.contains("scene.json is missing"), "{terminal}");
    assert_eq!(browser.console_errors(), Vec::<String>::new());

    // A malformed row: the page names the file and line, the server keeps serving.
    let mut rows = String::from_utf8(text.clone()).expect("UTF-8");
    rows.insert_str(
        rows.find("\n1,").expect("tick 1") + 1,
        "1,zero,ep0,1,1,1,0,0,0,1\n",
    );
    std::fs::write(&trajectory, rows).expect("trajectory edited");
    let bad = tempfile::tempdir().expect("temp dir");
    for file in ["trajectory.csv", "events.csv", "summary.json"] {
        std::fs::copy(run.path().join(file), bad.path().join(file)).expect("copied");
    }
    let second = ServedPage::start(&["view", &bad.path().display().to_string(), "--port", "0"]);
    browser.open(&second.url);
    browser.wait_for("viewer.ready");
    let problems = browser.eval("viewer.problems()").to_string();
    assert!(
        problems.contains("trajectory.csv:7: `zero` in the `robot` column"),
        "{problems}"
    );

    // A Parquet trajectory cut short: the page names the file, the server keeps serving.
    let cut = tempfile::tempdir().expect("temp dir");
    std::fs::copy(
        run.path().join("summary.json"),
        cut.path().join("summary.json"),
    )
    .expect("copied");
    std::fs::write(cut.path().join("trajectory.csv"), &text).expect("written");
    let exported = swarm_system_tests::swarm(&[
        "export",
        &cut.path().display().to_string(),
        "--format",
        "parquet",
    ]);
    assert!(exported.output.status.success(), "{}", exported.stderr());
    std::fs::remove_file(cut.path().join("trajectory.csv")).expect("CSV removed");
    let parquet = cut.path().join("trajectory.parquet");
    let bytes = std::fs::read(&parquet).expect("Parquet");
    std::fs::write(&parquet, &bytes[..bytes.len() - 20]).expect("cut");
    let third = ServedPage::start(&["view", &cut.path().display().to_string(), "--port", "0"]);
    browser.open(&third.url);
    browser.wait_for("viewer.ready");
    let problems = browser.eval("viewer.problems()").to_string();
    assert!(
        problems.contains("trajectory.parquet: not a readable Parquet file"),
        "{problems}"
    );
    browser.open(&page.url);
    browser.wait_for("viewer.ready");
    assert_eq!(third.interrupt(), Some(130));
    assert_eq!(second.interrupt(), Some(130));
    assert_eq!(page.interrupt(), Some(130));

    // A port in use and a folder that does not exist: a clear error, exit 1.
    let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("a port");
    let port = taken.local_addr().expect("its address").port().to_string();
    let refused = swarm_system_tests::swarm(&["view", &dir, "--port", &port]);
    assert_eq!(refused.output.status.code(), Some(1));
    assert!(
        refused.stderr().contains("is in use by another program"),
        "{}",
        refused.stderr()
    );
    let missing = swarm_system_tests::swarm(&["view", "/nonexistent/run"]);
    assert_eq!(missing.output.status.code(), Some(1));
    assert!(
        missing
            .stderr()
            .contains("/nonexistent/run: not a run directory"),
        "{}",
        missing.stderr()
    );
}

/// Cells of the `pheromone.bin` frame of `tick` where any channel is above zero.
fn marked_cells(dir: &Path, tick: u64) -> usize {
    let scene: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("scene.json")).expect("scene.json"))
            .expect("JSON");
    let layout = &scene["pheromone"];
    let number = |key: &str| layout[key].as_u64().expect("a pheromone layout number") as usize;
    let (nx, ny, channels, every) = (
        number("nx"),
        number("ny"),
        number("channels"),
        number("every") as u64,
    );
    let frame = 8 + nx * ny * channels;
    let bytes = std::fs::read(dir.join("pheromone.bin")).expect("pheromone.bin");
    let start = (tick / every) as usize * frame;
    let cells = &bytes[start + 8..start + frame];
    (0..nx * ny)
        .filter(|&c| (0..channels).any(|ch| cells[ch * nx * ny + c] > 0))
        .count()
}

#[test]
fn replay_draws_the_pheromone_field_recorded_for_the_shown_second() {
    let run = tempfile::tempdir().expect("temp dir");
    let outcome = run_to_completion(
        "configs/pheromone_foraging/pheromone_foraging.argos",
        run.path(),
        &["--ticks", "400", "--robots", "20"],
    );
    assert!(outcome.output.status.success(), "{}", outcome.stderr());
    let expected = marked_cells(run.path(), 380);
    assert!(expected > 0, "the swarm laid pheromone by tick 380");
    let page = ServedPage::start(&["view", &run.path().display().to_string(), "--port", "0"]);
    let browser = Browser::start();
    browser.open(&page.url);
    browser.wait_for("viewer.ready");
    browser.eval("(viewer.seek(395), true)");
    // The world records the field once a second (20 ticks): tick 395 shows the field of tick 380.
    browser.wait_for("viewer.whenPheromone(380)");
    assert_eq!(browser.eval("viewer.pheromone().cells"), expected);
    check_screenshot(&browser, "viewer-pheromone");
    assert_eq!(browser.console_errors(), Vec::<String>::new());
    assert_eq!(page.interrupt(), Some(130));
}

/// A benchmark, not a check: plays the run in `SWARM_VIEWER_BENCH_RUN` (e.g. 1,000 robots x 10,000 ticks) at 16x
/// in headless Chromium for 10 s and prints how many frames the page drew and how many distinct ticks it showed.
/// `SWARM_VIEWER_BENCH_RUN=/tmp/long cargo test --release -p swarm-system-tests --test viewer -- --ignored --nocapture`
#[test]
#[ignore]
fn playing_a_long_run() {
    let dir = std::env::var("SWARM_VIEWER_BENCH_RUN")
        .expect("SWARM_VIEWER_BENCH_RUN names a run directory");
    swarm_system_tests::bin_dir();
    let started = std::time::Instant::now();
    let page = ServedPage::start(&["view", &dir, "--port", "0"]);
    let serving = started.elapsed();
    let browser = Browser::start();
    browser.open(&page.url);
    browser.wait_for("viewer.ready");
    let ready = started.elapsed();
    let played = browser.wait_for(
        "(() => { const s = document.querySelector('#speed'); s.value = '16'; \
         s.dispatchEvent(new Event('change', {bubbles: true})); \
         const before = viewer.counts(), tick = viewer.tick(), t0 = performance.now(); \
         document.querySelector('#play').click(); \
         return new Promise(done => setTimeout(() => { const after = viewer.counts(); \
           done({seconds: (performance.now() - t0) / 1000, draws: after.draws - before.draws, \
                 ticks: after.ticksShown - before.ticksShown, advanced: viewer.tick() - tick}); }, 10000)); })()",
    );
    println!(
        "{dir}: URL after {serving:.2?}, first frame drawn after {ready:.2?}; playing at 16x: {played}; console errors: {:?}",
        browser.console_errors()
    );
    assert_eq!(page.interrupt(), Some(130));
}

#[test]
fn replay_draws_a_pushed_box_where_objects_csv_puts_it() {
    let run = tempfile::tempdir().expect("temp dir");
    let outcome = run_to_completion("configs/transport/sample2.argos", run.path(), &[]);
    assert!(outcome.output.status.success(), "{}", outcome.stderr());
    let objects = std::fs::read_to_string(run.path().join("objects.csv")).expect("objects.csv");
    let rows: Vec<Vec<&str>> = objects
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let middle = &rows[rows.len() / 2];
    assert_eq!(middle[1], "obstacle", "the pushed box moves: {middle:?}");
    let tick: u64 = middle[0].parse().expect("a tick");
    let page = ServedPage::start(&["view", &run.path().display().to_string(), "--port", "0"]);
    let browser = Browser::start();
    browser.open(&page.url);
    browser.wait_for("viewer.ready");
    browser.eval(&format!("(viewer.seek({tick}), true)"));
    browser.wait_for(&format!("viewer.whenObjects({tick})"));
    let shown = browser.eval("viewer.objects().obstacles");
    let index: u64 = middle[2].parse().expect("an index");
    let entry = shown
        .as_array()
        .and_then(|all| all.iter().find(|e| e[0] == index))
        .unwrap_or_else(|| panic!("obstacle {index} in {shown}"));
    let pose: Vec<f32> = (0..3)
        .map(|i| entry[1][i].as_f64().unwrap_or(f64::NAN) as f32)
        .collect();
    let recorded: Vec<f32> = middle[4..7]
        .iter()
        .map(|v| v.parse().expect("a number"))
        .collect();
    assert_eq!(pose, recorded, "the box at tick {tick}");
    assert_eq!(browser.console_errors(), Vec::<String>::new());
    assert_eq!(page.interrupt(), Some(130));
}
