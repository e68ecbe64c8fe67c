//! The generated Rust module compiles, embeds exactly the compiled bytes, and dispatches to the right callbacks.
//!
//! `algo_generated/worked_example.rs` is the generator's output for the section 9 worked example, checked in and
//! compiled here through `include!`. The first test regenerates it and fails if the generator's output drifted;
//! run it with `SUPERVISOR_GEN_BLESS=1` to rewrite the file after an intended change.

use std::path::Path;

use supervisor_gen::automaton::{Automaton, EventTable, ModelKind};
use supervisor_gen::codegen::generate_rust;
use supervisor_gen::compiled::SupervisorSet;

mod generated {
    include!("algo_generated/worked_example.rs");
}

const GOLDEN: &str = "tests/integration/algo_generated/worked_example.rs";

include!("../common/section9_example.rs");

/// The section 9 worked example compiled.
fn worked_example() -> SupervisorSet {
    let (ev, g) = section9_example();
    SupervisorSet::from_supervisors(&ev, &[g]).unwrap()
}

#[test]
fn checked_in_generated_module_is_current() {
    let src = generate_rust(
        &worked_example(),
        "the worked example of docs/ptsct.md section 9",
    );
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(GOLDEN);
    if std::env::var_os("SUPERVISOR_GEN_BLESS").is_some() {
        std::fs::write(&path, &src).unwrap();
    }
    let on_disk = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        on_disk, src,
        "generated code changed; rerun with SUPERVISOR_GEN_BLESS=1 if intended"
    );
}

#[test]
fn generated_static_array_parses_to_the_same_set() {
    let set = worked_example();
    assert_eq!(generated::SUPERVISOR_SET.to_vec(), set.to_bytes());
    assert_eq!(
        SupervisorSet::from_bytes(&generated::SUPERVISOR_SET).unwrap(),
        set
    );
    assert_eq!(generated::MEM_CONS, 57);
    assert_eq!(
        generated::EVENTS,
        [("a", true), ("b", true), ("c", true), ("u", false)]
    );
    assert_eq!(generated::MEMBERSHIP, [[true]; 4]);
    assert_eq!(generated::SUPERVISORS, ["example"]);
}

/// Records which callbacks ran.
struct Recorder {
    acted: Vec<&'static str>,
}

impl generated::Callbacks for Recorder {
    type Context = bool;
    fn act_a(&mut self, _: &mut bool) {
        self.acted.push("a");
    }
    fn act_b(&mut self, _: &mut bool) {
        self.acted.push("b");
    }
    fn act_c(&mut self, _: &mut bool) {
        self.acted.push("c");
    }
    fn check_u(&self, sensor: &bool) -> bool {
        *sensor
    }
}

#[test]
fn dispatch_binds_event_ids_to_their_callbacks() {
    let mut r = Recorder { acted: Vec::new() };
    let mut ctx = true;
    assert!(generated::act(&mut r, generated::event::C, &mut ctx));
    assert!(generated::act(&mut r, generated::event::A, &mut ctx));
    assert!(generated::act(&mut r, generated::event::B, &mut ctx));
    assert!(!generated::act(&mut r, generated::event::U, &mut ctx));
    assert_eq!(r.acted, vec!["c", "a", "b"]);
    assert!(generated::check(&r, generated::event::U, &true));
    assert!(!generated::check(&r, generated::event::U, &false));
    assert!(!generated::check(&r, generated::event::A, &true));
}
