//! The terminal's view of a long synthesis: one spinner line on stderr saying which product or SupC round is
//! running and how far it got. Installed only when stderr is a terminal; cleared as soon as synthesis returns,
//! before anything else is printed.

use std::sync::{Mutex, OnceLock, PoisonError};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use supervisor_gen::progress::Sink;

/// An indicatif spinner as the library's progress sink.
struct Spinner {
    bar: ProgressBar,
    /// The current stage, repeated in every message so that a frame never shows one stage with another's news.
    stage: Mutex<String>,
}

impl Spinner {
    fn show(&self, detail: &str) {
        let stage = self.stage.lock().unwrap_or_else(PoisonError::into_inner);
        self.bar.set_message(format!("{stage}{detail}"));
    }
}

impl Sink for Spinner {
    fn stage(&self, what: &str) {
        what.clone_into(&mut self.stage.lock().unwrap_or_else(PoisonError::into_inner));
        self.show("");
    }

    fn states(&self, states: usize) {
        self.show(&format!(": {states} states explored"));
    }

    fn round(&self, round: u32, removed: usize) {
        self.show(&format!(": round {round}, {removed} states removed"));
    }
}

static BAR: OnceLock<ProgressBar> = OnceLock::new();

/// Installs a spinner on stderr as the process's progress sink when stderr is a terminal.
pub fn install() {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return;
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr_with_hz(4));
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    supervisor_gen::progress::install(Box::new(Spinner {
        bar: bar.clone(),
        stage: Mutex::new(String::new()),
    }));
    let _ = BAR.set(bar);
}

/// Clears the spinner for good (synthesis is over).
pub fn finish() {
    if let Some(bar) = BAR.get() {
        bar.finish_and_clear();
    }
}
