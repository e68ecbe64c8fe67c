//! Long syntheses report their progress to an installed sink (its own test binary: the sink is process-wide).

use std::sync::{Arc, Mutex};

use supervisor_gen::architecture::Architecture;
use supervisor_gen::families::transfer_line;
use supervisor_gen::pipeline::{SynthesisOptions, synthesize};
use supervisor_gen::progress::{self, Sink};

#[derive(Default)]
struct Recorder {
    lines: Arc<Mutex<Vec<String>>>,
}

impl Sink for Recorder {
    fn stage(&self, what: &str) {
        self.lines.lock().unwrap().push(format!("stage {what}"));
    }
    fn states(&self, states: usize) {
        self.lines.lock().unwrap().push(format!("states {states}"));
    }
    fn round(&self, round: u32, removed: usize) {
        self.lines
            .lock()
            .unwrap()
            .push(format!("round {round} {removed}"));
    }
}

#[test]
fn a_synthesis_reports_its_products_states_and_supc_rounds() {
    let lines = Arc::new(Mutex::new(Vec::new()));
    progress::install(Box::new(Recorder {
        lines: Arc::clone(&lines),
    }));
    // 6 machines, buffers of 3: the closed loop has 65,536 states.
    let project = transfer_line(6, 3);
    let synthesis = synthesize(
        &project,
        Architecture::Monolithic,
        SynthesisOptions::default(),
    )
    .expect("the transfer line is synthesisable");
    let lines = lines.lock().unwrap();
    for stage in [
        "stage product G_mon",
        "stage product E_mon",
        "stage SupC of",
        "stage minimising S_mon",
    ] {
        assert!(
            lines.iter().any(|l| l.starts_with(stage)),
            "no `{stage}` in {lines:?}"
        );
    }
    let explored: Vec<usize> = lines
        .iter()
        .filter_map(|l| l.strip_prefix("states ")?.parse().ok())
        .collect();
    assert!(
        explored.contains(&progress::STATES_PER_REPORT),
        "{explored:?}"
    );
    let rounds = lines.iter().filter(|l| l.starts_with("round ")).count();
    assert_eq!(rounds as u32, synthesis.supervisors[0].rounds, "{lines:?}");
}
