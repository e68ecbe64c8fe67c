//! A real browser for the viewer's tests: Debian's headless Chromium driven through chromedriver (WebDriver),
//! and the `swarm` process whose page it opens. Both are stopped, with every process they started, when dropped.

use std::io::BufRead;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use fantoccini::actions::{InputSource, MOUSE_BUTTON_LEFT, MouseActions, PointerAction};
use fantoccini::wd::{TimeoutConfiguration, WebDriverCompatibleCommand};
use serde_json::{Value, json};

use crate::{bin_dir, remove_run_leftovers, workspace_root};

/// Where Debian's packages put the browser and its driver (`.ci/run` installs them).
const CHROMIUM: &str = "/usr/bin/chromium";
const CHROMEDRIVER: &str = "/usr/bin/chromedriver";
/// How long a page may take to settle before a wait fails the test (a bound, not a timing assertion).
const SCRIPT_LIMIT: Duration = Duration::from_secs(120);

/// A headless Chromium session.
pub struct Browser {
    runtime: tokio::runtime::Runtime,
    client: Option<fantoccini::Client>,
    driver: Child,
    _profile: tempfile::TempDir,
}

/// chromedriver's log endpoint: the browser's console messages since the last call.
#[derive(Debug)]
struct BrowserLog;

impl WebDriverCompatibleCommand for BrowserLog {
    fn endpoint(
        &self,
        base: &url::Url,
        session: Option<&str>,
    ) -> Result<url::Url, url::ParseError> {
        base.join(&format!("session/{}/se/log", session.unwrap_or_default()))
    }

    fn method_and_body(&self, _: &url::Url) -> (http::Method, Option<String>) {
        (
            http::Method::POST,
            Some(json!({"type": "browser"}).to_string()),
        )
    }
}

impl Browser {
    /// Starts chromedriver and a headless Chromium session with a fresh profile and a 1280 x 800 window.
    pub fn start() -> Browser {
        assert!(
            Path::new(CHROMIUM).exists() && Path::new(CHROMEDRIVER).exists(),
            "the viewer's tests need Debian's chromium and chromium-driver packages (.ci/run installs them)"
        );
        let port = crate::free_port("127.0.0.1");
        let mut driver = Command::new(CHROMEDRIVER)
            .arg(format!("--port={port}"))
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            // Its own process group, so that every browser process it started goes with it.
            .process_group(0)
            .spawn()
            .expect("chromedriver starts");
        let mut banner = std::io::BufReader::new(driver.stdout.take().expect("piped"));
        let mut line = String::new();
        while !line.contains("started successfully") {
            line.clear();
            let read = banner.read_line(&mut line).expect("chromedriver's output");
            assert!(read > 0, "chromedriver ended before it was ready");
        }
        let profile = tempfile::tempdir().expect("a browser profile folder");
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .expect("a runtime for the WebDriver client");
        let mut capabilities = serde_json::Map::new();
        capabilities.insert(
            "goog:chromeOptions".into(),
            json!({
                "binary": CHROMIUM,
                "args": [
                    "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                    "--disable-background-networking", "--disable-component-update", "--disable-sync",
                    "--window-size=1280,800", format!("--user-data-dir={}", profile.path().display()),
                ],
            }),
        );
        capabilities.insert("goog:loggingPrefs".into(), json!({"browser": "ALL"}));
        let client = runtime
            .block_on(
                fantoccini::ClientBuilder::new(
                    hyper_util::client::legacy::connect::HttpConnector::new(),
                )
                .capabilities(capabilities)
                .connect(&format!("http://127.0.0.1:{port}")),
            )
            .expect("a Chromium session");
        runtime
            .block_on(client.update_timeouts(TimeoutConfiguration::new(
                Some(SCRIPT_LIMIT),
                Some(SCRIPT_LIMIT),
                None,
            )))
            .expect("timeouts set");
        Browser {
            runtime,
            client: Some(client),
            driver,
            _profile: profile,
        }
    }

    fn client(&self) -> &fantoccini::Client {
        self.client
            .as_ref()
            .expect("the session is open until drop")
    }

    /// Opens `url`.
    pub fn open(&self, url: &str) {
        self.runtime
            .block_on(self.client().goto(url))
            .expect("the page opens");
    }

    /// The value of the JavaScript expression `expression`.
    pub fn eval(&self, expression: &str) -> Value {
        self.runtime
            .block_on(
                self.client()
                    .execute(&format!("return ({expression});"), vec![]),
            )
            .unwrap_or_else(|e| panic!("evaluating {expression}: {e}"))
    }

    /// Waits for the promise `expression` evaluates to and returns what it resolves with.
    pub fn wait_for(&self, expression: &str) -> Value {
        let script = format!(
            "const done = arguments[arguments.length - 1];
             Promise.resolve({expression}).then(v => done({{ok: v === undefined ? null : v}}),
                                                e => done({{error: String(e)}}));"
        );
        let answer = self
            .runtime
            .block_on(self.client().execute_async(&script, vec![]))
            .unwrap_or_else(|e| panic!("waiting for {expression}: {e}"));
        assert!(
            answer.get("error").is_none(),
            "{expression} failed: {answer}"
        );
        answer["ok"].clone()
    }

    /// Clicks the left mouse button at viewport coordinates (`x`, `y`), in CSS pixels.
    pub fn click_at(&self, x: f64, y: f64) {
        let mouse = MouseActions::new("mouse".into())
            .then(PointerAction::MoveTo {
                duration: None,
                x: x.round(),
                y: y.round(),
            })
            .then(PointerAction::Down {
                button: MOUSE_BUTTON_LEFT,
            })
            .then(PointerAction::Up {
                button: MOUSE_BUTTON_LEFT,
            });
        self.runtime
            .block_on(self.client().perform_actions(mouse))
            .expect("the click is performed");
    }

    /// A PNG screenshot of the window.
    pub fn screenshot(&self) -> Vec<u8> {
        self.runtime
            .block_on(self.client().screenshot())
            .expect("a screenshot")
    }

    /// The console messages of level SEVERE (errors, failed requests, uncaught exceptions) since the last call.
    pub fn console_errors(&self) -> Vec<String> {
        let log = self
            .runtime
            .block_on(self.client().issue_cmd(BrowserLog))
            .expect("the browser's log");
        log.as_array()
            .map(|entries| {
                entries
                    .iter()
                    .filter(|e| e["level"] == "SEVERE")
                    .map(|e| e["message"].as_str().unwrap_or_default().to_owned())
                    .collect()
            })
            .unwrap_or_default()
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if let Some(client) = self.client.take() {
            let _ = self.runtime.block_on(client.close());
        }
        let group = nix::unistd::Pid::from_raw(-(self.driver.id() as i32));
        let _ = nix::sys::signal::kill(group, nix::sys::signal::Signal::SIGKILL);
        let _ = self.driver.wait();
    }
}

/// How many distinct colours a PNG has (a blank page has one or two).
pub fn distinct_colours(png_bytes: &[u8]) -> usize {
    let decoder = png::Decoder::new(std::io::Cursor::new(png_bytes));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).expect("PNG pixels");
    let channels = info.color_type.samples();
    let mut colours: Vec<&[u8]> = pixels[..info.buffer_size()].chunks(channels).collect();
    colours.sort_unstable();
    colours.dedup();
    colours.len()
}

/// A `swarm` process serving a viewer page (`swarm view`, or `swarm run --view`).
pub struct ServedPage {
    child: Child,
    /// The page's address, as the process printed it.
    pub url: String,
    /// The process's standard error, kept in a file (a pipe nobody reads could fill and stall it).
    pub log: tempfile::NamedTempFile,
    /// Its standard output after the URL, line by line, read by a thread of its own.
    output: std::sync::mpsc::Receiver<String>,
}

impl ServedPage {
    /// Starts `swarm <args>` and returns once it printed its viewer's URL.
    pub fn start(args: &[&str]) -> ServedPage {
        let log = tempfile::NamedTempFile::new().expect("a log file");
        let dir = bin_dir();
        let mut child = Command::new(dir.join("swarm"))
            .args(args)
            .env("SWARM_BIN_DIR", dir)
            .env("RUST_LOG", "info")
            .current_dir(workspace_root())
            .stdout(Stdio::piped())
            .stderr(log.reopen().expect("the log file"))
            .spawn()
            .expect("swarm starts");
        let mut out = std::io::BufReader::new(child.stdout.take().expect("piped"));
        let mut line = String::new();
        let url = loop {
            line.clear();
            let read = out.read_line(&mut line).expect("swarm's output");
            if read == 0 {
                let log_text = std::fs::read_to_string(log.path()).unwrap_or_default();
                panic!("swarm {args:?} ended without serving a page:\n{log_text}");
            }
            if let Some(at) = line.find("http://") {
                break line[at..]
                    .split_whitespace()
                    .next()
                    .unwrap_or_default()
                    .to_owned();
            }
        };
        let (lines, output) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in out.lines().map_while(Result::ok) {
                let _ = lines.send(line);
            }
        });
        ServedPage {
            child,
            url,
            log,
            output,
        }
    }

    /// Waits for a line of standard output containing `needle` and returns it.
    pub fn wait_for_output(&self, needle: &str) -> String {
        loop {
            match self.output.recv() {
                Ok(line) if line.contains(needle) => return line,
                Ok(_) => {}
                Err(_) => panic!("swarm ended before it printed {needle:?}"),
            }
        }
    }

    /// Stops the process with Ctrl-C and returns its exit code.
    pub fn interrupt(mut self) -> Option<i32> {
        let pid = nix::unistd::Pid::from_raw(self.child.id() as i32);
        nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGINT).expect("interrupt swarm");
        self.child.wait().expect("swarm exits").code()
    }
}

impl Drop for ServedPage {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
        remove_run_leftovers(&format!("sw{:x}-", self.child.id()));
    }
}
