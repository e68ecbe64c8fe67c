//! Seeded, bounded fuzzing of every input the project reads: experiment files (`.argos`), model XML, grid TOML,
//! `--fault` texts and every message that crosses the network between the world and its hosts.
//!
//! Each input of the seed corpus (the repository's own configurations, models and grids, plus the inputs that
//! once crashed or hung a reader, kept as regression cases) is mutated a fixed number of times with a fixed seed:
//! byte flips, insertions of bytes and of the format's own tokens, deletions, duplications, truncations and
//! invalid UTF-8. Every mutant must be read or refused; a refusal must name the file. A panic, an abort (stack
//! overflow) or a hang fails the test, and the mutant can be rebuilt from the seed and the case's index.
//!
//! The number of mutants is fixed, not the time, so the test does the same work on every machine. Set
//! `SWARM_FUZZ_MUTANTS` to fuzz longer (e.g. `SWARM_FUZZ_MUTANTS=20000 cargo test -p swarm-system-tests --test
//! fuzz --release`) and `SWARM_FUZZ_SEED` for another sequence.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use swarm_cli::experiment::grid::Grid;
use swarm_contract::config::Experiment;
use swarm_contract::config::faults::FaultSchedule;
use swarm_contract::mail::{Address, Mailbox};
use swarm_contract::messages::{ActuatorCommand, SensorFrame, SupervisorSnapshot};
use swarm_remote::auth::{HostKey, Seal};
use swarm_remote::codec::{self, DEFAULT_MAX_PAYLOAD, Header, Kind};
use swarm_remote::host_to_world::{AssignmentReply, OrderReply, Reply, ReplyEntry};
use swarm_remote::world_to_host::{
    Assignment, FrameEntry, Order, OrderAction, kill_payload, parse_kill,
};
use swarm_system_tests::workspace_file;

/// Mutants per corpus entry unless `SWARM_FUZZ_MUTANTS` says otherwise.
const DEFAULT_MUTANTS: usize = 400;
const DEFAULT_SEED: u64 = 0x5eed_f022;

fn mutants() -> usize {
    std::env::var("SWARM_FUZZ_MUTANTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_MUTANTS)
}

/// The random source of corpus entry `case`: the same for every run with the same seed.
fn rng(case: u64) -> StdRng {
    let seed = std::env::var("SWARM_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_SEED);
    StdRng::seed_from_u64(seed ^ case.wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// One mutant of `input`: one to four edits, some with tokens of the input's format.
fn mutate(rng: &mut StdRng, input: &[u8], tokens: &[&[u8]]) -> Vec<u8> {
    let mut out = input.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        let len = out.len();
        let at = if len == 0 {
            0
        } else {
            rng.random_range(0..len)
        };
        match rng.random_range(0..8) {
            0 if len > 0 => out[at] ^= 1 << rng.random_range(0..8),
            1 => out.insert(at, rng.random()),
            2 if !tokens.is_empty() => {
                let token = tokens[rng.random_range(0..tokens.len())];
                out.splice(at..at, token.iter().copied());
            }
            3 if len > 0 => {
                let end = (at + rng.random_range(1..64)).min(len);
                out.drain(at..end);
            }
            4 if len > 0 => {
                let end = (at + rng.random_range(1..256)).min(len);
                let chunk = out[at..end].to_vec();
                out.splice(at..at, chunk);
            }
            5 => out.truncate(at),
            6 => out.insert(at, [0xff, 0xc3, 0x80][rng.random_range(0..3)]),
            _ if len > 0 => out[at] = rng.random(),
            _ => out.push(rng.random()),
        }
    }
    out
}

/// Runs `read` on `mutants()` mutants of each corpus entry (and on the entry itself).
fn fuzz(corpus: &[(String, Vec<u8>)], tokens: &[&[u8]], mut read: impl FnMut(&str, &[u8])) {
    let count = mutants();
    for (case, (name, input)) in corpus.iter().enumerate() {
        read(name, input);
        let mut rng = rng(case as u64);
        for _ in 0..count {
            read(name, &mutate(&mut rng, input, tokens));
        }
    }
}

/// The repository's files under `configs/` whose names end in `suffix`.
fn corpus_files(suffix: &str) -> Vec<(String, Vec<u8>)> {
    fn walk(dir: &Path, suffix: &str, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, suffix, out);
            } else if path.to_string_lossy().ends_with(suffix) {
                out.push(path);
            }
        }
    }
    let mut paths = Vec::new();
    walk(&workspace_file("configs"), suffix, &mut paths);
    paths.sort();
    assert!(!paths.is_empty(), "no {suffix} file in configs/");
    paths
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).expect("a corpus file");
            (p.display().to_string(), bytes)
        })
        .collect()
}

/// `depth` nested elements named `name` inside `open`/`close`.
fn nested(open: &str, name: &str, depth: usize, close: &str) -> Vec<u8> {
    let mut text = String::from(open);
    text.push_str(&format!("<{name}>").repeat(depth));
    text.push_str(&format!("</{name}>").repeat(depth));
    text.push_str(close);
    text.into_bytes()
}

/// Fuzzes a text format read from files. Text goes through `parse` in memory, as if read from the corpus file
/// (so paths relative to it resolve). Bytes that are not UTF-8 go through a real file and `load`, as `swarm`
/// reads them, so the refusal is the one a user sees. Every refusal must name the file.
fn fuzz_text_files<E: std::fmt::Display>(
    corpus: &[(String, Vec<u8>)],
    tokens: &[&[u8]],
    parse: impl Fn(&Path, &str) -> Result<(), E>,
    load: impl Fn(&Path) -> Result<(), E>,
) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    fuzz(corpus, tokens, |name, bytes| {
        let file = Path::new(name).file_name().expect("a file name");
        let result = match std::str::from_utf8(bytes) {
            Ok(text) => parse(Path::new(name), text),
            Err(_) => {
                let path = dir.path().join(file);
                std::fs::write(&path, bytes).expect("a temporary file");
                load(&path)
            }
        };
        if let Err(e) = result {
            let message = e.to_string();
            assert!(
                message.contains(&*file.to_string_lossy()),
                "a refusal of {name} does not name the file:\n{message}"
            );
        }
    });
}

#[test]
fn experiment_files_are_read_or_refused_with_their_name() {
    let mut corpus = corpus_files(".argos");
    let base = String::from_utf8(corpus[0].1.clone()).expect("UTF-8");
    let name = corpus[0].0.clone();
    // Once a stack overflow, a 16 GiB allocation, a quadratic parse or a huge grid.
    corpus.push((
        name.clone(),
        nested(
            "<argos-configuration>",
            "a",
            30_000,
            "</argos-configuration>",
        ),
    ));
    let long_line = format!(
        "<argos-configuration><!-- {} --></argos-configuration>",
        "x".repeat(800_000)
    );
    corpus.push((name.clone(), long_line.into_bytes()));
    let arena = base.find("<arena size=\"").expect("an arena") + "<arena size=\"".len();
    let end = arena + base[arena..].find('"').expect("a closing quote");
    for size in ["1e15", "1e38", "20000"] {
        let text = format!("{}{size},{size},1{}", &base[..arena], &base[end..]);
        corpus.push((name.clone(), text.into_bytes()));
    }
    corpus.push((name.clone(), b"\xff\xfe<argos-configuration>".to_vec()));
    let tokens: &[&[u8]] = &[
        b"<",
        b">",
        b"/>",
        b"\"",
        b"=",
        b"<!--",
        b"-->",
        b"<![CDATA[",
        b"&amp;",
        b"&#0;",
        b"<params",
        b"<arena ",
        b"<e-puck ",
        b"quantity=\"",
        b"size=\"",
        b"1e38",
        b"-1",
        b"NaN",
        b"4294967296",
        b"<faults>",
        b"<kill robots=\"0-4294967295\" tick=\"1\"/>",
        b"<hosts>",
        b"\n",
    ];
    fuzz_text_files(
        &corpus,
        tokens,
        |path, text| Experiment::parse(path, text).map(|_| ()),
        |path| Experiment::load(path).map(|_| ()),
    );
}

#[test]
fn fault_texts_are_read_or_refused_before_any_expansion() {
    let experiment = workspace_file("configs/obstacle_avoidance/obstacle_avoidance.argos");
    let (experiment, _) = Experiment::load(&experiment).expect("the experiment");
    let corpus: Vec<(String, Vec<u8>)> = [
        "kill robots=3 tick=50",
        "kill robots=0-4294967295 tick=1",
        "freeze robots=1,2 tick=5 duration=10",
        "restart policy=on-failure max_restarts=2 backoff=0",
        "kill fraction=0.5 tick=100",
    ]
    .iter()
    .map(|t| ("--fault".to_owned(), t.as_bytes().to_vec()))
    .collect();
    let tokens: &[&[u8]] = &[
        b"=",
        b" ",
        b"-",
        b",",
        b"4294967295",
        b"1e300",
        b"robots=",
        b"tick=",
    ];
    fuzz(&corpus, tokens, |_, bytes| {
        let text = String::from_utf8_lossy(bytes).into_owned();
        if let Err(e) = FaultSchedule::for_run(&experiment, &[text], 40) {
            assert!(e.to_string().contains("--fault"), "{e}");
        }
    });
}

#[test]
fn model_files_are_read_or_refused_with_their_name() {
    let mut corpus = corpus_files(".xml");
    let name = corpus[0].0.clone();
    corpus.push((
        name.clone(),
        nested("<automata>", "x", 1_000_000, "</automata>"),
    ));
    corpus.push((name, b"<automata \xff>".to_vec()));
    let tokens: &[&[u8]] = &[
        b"<",
        b">",
        b"/>",
        b"\"",
        b"=",
        b"<state ",
        b"<transition ",
        b"<event ",
        b"initial=\"true\"",
        b"probability=\"",
        b"1.5",
        b"-0",
        b"&lt;",
        b"<!DOCTYPE x [<!ENTITY a \"aaaa\">]>",
    ];
    fuzz(&corpus, tokens, |name, bytes| {
        let text = String::from_utf8_lossy(bytes);
        if let Err(problems) = supervisor_gen::xml_read::read_model(name, &text, None) {
            for problem in problems {
                let message = problem.to_string();
                assert!(message.contains(name), "{message}");
            }
        }
    });
}

#[test]
fn grid_files_are_read_or_refused_with_their_name() {
    let corpus = corpus_files(".toml");
    let tokens: &[&[u8]] = &[
        b"[",
        b"]",
        b"=",
        b"\"",
        b"\n",
        b"seeds = ",
        b"ticks = ",
        b"1e400",
        b"-1",
        b"[[",
        b"{",
        b"\\u0000",
    ];
    fuzz_text_files(
        &corpus,
        tokens,
        |path, text| Grid::parse(path, text).map(|_| ()),
        |path| Grid::load(path).map(|_| ()),
    );
}

/// One message of every type that crosses the network, as sent.
fn network_corpus() -> Vec<(String, Vec<u8>)> {
    let assignment = Assignment {
        run: 0x1234,
        host: 1,
        name: "beta".into(),
        epoch: 2,
        config: "/experiments/oa.argos".into(),
        seed: 7,
        robots_override: Some(4),
        robots: vec![(2, "oa".into()), (3, "oa".into())],
        tick_deadline_ms: 250,
        join_timeout_ms: 1000,
        agent_exit_grace_ms: 500,
        pin_agents: true,
        realtime_priority: false,
        mail: true,
        compiled_supervisors: vec![("oa".into(), vec![1, 2, 3])],
        limits: vec!["tick_deadline_ms=300".into()],
        resume: vec![(5, SupervisorSnapshot::default())],
    };
    let order = Order {
        run: 0x1234,
        epoch: 2,
        number: 9,
        robot: 3,
        action: OrderAction::Respawn {
            tick: 4,
            snapshot: Box::default(),
        },
    };
    let mut mailbox = Mailbox::empty(2);
    mailbox
        .send(Address::Within(0.5), b"a message")
        .expect("fits");
    mailbox.send(Address::To(3), &[9; 40]).expect("fits");
    let (frame_2, frame_3) = (SensorFrame::empty(2), SensorFrame::empty(3));
    let mut frames = Vec::new();
    codec::encode_batch(
        &mut frames,
        &Header::new(Kind::Frames, 0x1234, 1, 2, 17),
        &[2, 3],
        [(&frame_2, Some(&mailbox)), (&frame_3, None)],
    )
    .expect("encodes");
    let (answered, dead) = (Reply::Answered(ActuatorCommand::idle(2, 17)), Reply::Dead);
    let mut replies = Vec::new();
    codec::encode_batch(
        &mut replies,
        &Header::new(Kind::Replies, 0x1234, 1, 2, 17),
        &[2, 3],
        [(&answered, Some(&mailbox)), (&dead, None)],
    )
    .expect("encodes");
    vec![
        (
            "assignment".into(),
            codec::encode_versioned(&assignment).expect("encodes"),
        ),
        (
            "order".into(),
            codec::encode_message(&order).expect("encodes"),
        ),
        (
            "assignment reply".into(),
            codec::encode_message(&AssignmentReply::Refused {
                epoch: 2,
                reason: "no".into(),
            })
            .expect("encodes"),
        ),
        (
            "order reply".into(),
            codec::encode_message(&OrderReply::Failed {
                reason: "gone".into(),
            })
            .expect("encodes"),
        ),
        ("frames".into(), frames),
        ("replies".into(), replies),
        ("kill".into(), kill_payload(0x1234, 2)),
        // Once ended a host's share before anything decoded it.
        ("16 random bytes".into(), vec![0xA5; 16]),
    ]
}

#[test]
fn network_messages_decode_or_are_refused_and_no_altered_message_passes_its_tag() {
    let seal = Seal::Key(Arc::new(HostKey::from_secret(&[7; 32])));
    let mut frames_out = vec![FrameEntry::empty(0); 2];
    let mut replies_out = vec![ReplyEntry::MISSING; 2];
    let corpus = network_corpus();
    let mut originals: Vec<Vec<u8>> = Vec::new();
    for (_, bytes) in &corpus {
        let mut sealed = bytes.clone();
        seal.seal("swarm/channel", &mut sealed);
        originals.push(sealed);
    }
    let max = DEFAULT_MAX_PAYLOAD;
    fuzz(&corpus, &[&[0xff; 9], &[0; 9], &[0x80]], |_, bytes| {
        let _ = codec::decode_versioned::<Assignment>(bytes, max);
        let _ = codec::decode_message::<Order>(bytes, max);
        let _ = codec::decode_message::<AssignmentReply>(bytes, max);
        let _ = codec::decode_message::<OrderReply>(bytes, max);
        let _ = codec::decode_batch(bytes, Kind::Frames, &[2, 3], &mut frames_out, max);
        let _ = codec::decode_batch(bytes, Kind::Replies, &[2, 3], &mut replies_out, max);
        let _ = parse_kill(bytes);
    });
    let sealed_corpus: Vec<(String, Vec<u8>)> = corpus
        .iter()
        .zip(&originals)
        .map(|((name, _), sealed)| (name.clone(), sealed.clone()))
        .collect();
    fuzz(&sealed_corpus, &[], |name, bytes| {
        if seal.open("swarm/channel", bytes).is_ok() {
            assert!(
                originals.iter().any(|o| o.as_slice() == bytes),
                "an altered {name} message passed its tag"
            );
        }
    });
}
