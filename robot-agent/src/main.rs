//! `robot-agent`: one robot's process. Loads and checks its controller before the first tick, so every startup
//! failure (unknown controller or profile, bad supervisor file, unbound event, bad parameter) exits non-zero with
//! the reason for the launcher to report; then joins the run and answers every tick: wait for the frame, step
//! the controller, send the command. A restarted agent (`--resume`) continues from the world's record
//! ([`robot_agent::resume`]). SIGTERM or SIGINT asks the agent to leave the run: it stops at its next tick
//! without answering it and exits 0 (the launcher restarts it only under the `always` policy).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow};
use clap::Parser;
use robot_agent::control::{self, Control};
use robot_agent::controller::{self, Plan};
use robot_agent::from_config;
use robot_agent::params::Params;
use robot_agent::resume::Resumer;
use robot_agent::zygote::{Forked, Zygote};
use swarm_contract::config::{Controller, Experiment};
use swarm_contract::limits::Limits;
use swarm_contract::messages::ActuatorCommand;
use swarm_contract::protocol::launcher_to_agent::{
    AgentArgs, ZygoteArgs, ZygoteOrder, ZygoteReply,
};
use swarm_contract::protocol::resume::ResumePoint;
use swarm_contract::transport::{AgentLink, AgentNode, RunSpec, TransportError, WorldEnd};
use tracing::{debug, info};

/// One robot of a swarm run.
#[derive(Debug, Parser)]
#[command(name = "robot-agent", version)]
struct Args {
    /// Which robot of which run: the flags the launcher and `swarm host` pass.
    #[command(flatten)]
    agent: AgentArgs,
    /// Without --config: controller element name, as a `<controllers>` child would be named.
    #[arg(long, default_value = "", conflicts_with = "config")]
    element: String,
    /// Without --config: operational-procedure profile (with --supervisors).
    #[arg(long, requires = "supervisors", conflicts_with = "config")]
    profile: Option<String>,
    /// Without --config: comma-separated XML model files, one folder of them, or one compiled supervisor-set file
    /// (with --profile), relative to the working directory.
    #[arg(long, requires = "profile", conflicts_with = "config")]
    supervisors: Option<String>,
    /// Without --config: controller parameter, as an attribute of <params> (repeatable), e.g. --param velocity=5.
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param, conflicts_with = "config")]
    params: Vec<(String, String)>,
    /// Load, synthesise and bind the controller, print its event names by id as a JSON array on standard output,
    /// then exit without joining the run.
    #[arg(long)]
    check: bool,
    /// With --check: also write the controller's compiled supervisor set to this file (nothing for a native
    /// controller).
    #[arg(long = "write-supervisors", requires = "check")]
    write_supervisors: Option<PathBuf>,
}

fn parse_param(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((name, value)) if !name.is_empty() => Ok((name.to_owned(), value.to_owned())),
        _ => Err(format!("`{s}` is not NAME=VALUE")),
    }
}

/// Loads the experiment configuration, with the run's robot count when `swarm run --robots` changed it.
fn load_experiment(path: &Path, robots: Option<u32>) -> Result<Experiment> {
    let (experiment, warnings) = Experiment::load(path).map_err(|errors| anyhow!("{errors}"))?;
    let experiment = match robots {
        Some(robots) => experiment
            .with_robot_count(robots)
            .map_err(|errors| anyhow!("{errors}"))?,
        None => experiment,
    };
    for w in &warnings {
        debug!("{w}");
    }
    Ok(experiment)
}

/// Plans and builds robot `robot`'s controller (`controller`) of `experiment`; `compiled` replaces the supervisors
/// its parameters name.
fn build_from_config(
    experiment: &Experiment,
    controller: &Controller,
    seed: u64,
    robot: u32,
    compiled: Option<&Path>,
) -> Result<(Plan, Control)> {
    let (plan, control) = from_config::build(experiment, controller, seed, robot, compiled)?;
    info!(
        controller = controller.id.as_str(),
        seed, "robot runs {plan}"
    );
    Ok((plan, control))
}

/// The run's limits: the configuration's `<system>` ones with the command line's `--limit` overrides.
fn limits_of(experiment: &Experiment, overrides: &[String]) -> Result<Limits> {
    let mut limits = experiment.framework.limits;
    limits.apply(overrides)?;
    Ok(limits)
}

/// Plans and builds the robot's controller from the configuration or from the manual flags; also the run's limits
/// (the configuration's `<system>` ones with the command line's `--limit` overrides).
fn build_control(args: &Args) -> Result<(Plan, Control, Limits)> {
    if let Some(path) = &args.agent.config {
        let experiment = load_experiment(path, args.agent.robots)?;
        let seed = match (args.agent.seed, experiment.framework.random_seed) {
            (Some(seed), _) | (None, Some(seed)) => seed,
            (None, None) => anyhow::bail!(
                "{}: random_seed is left to the clock; pass the run's seed with --seed",
                path.display()
            ),
        };
        let controller = match &args.agent.controller {
            Some(id) => from_config::controller_by_id(&experiment, id)?,
            None => from_config::controller_of(&experiment, args.agent.robot)?,
        };
        let (plan, control) = build_from_config(
            &experiment,
            controller,
            seed,
            args.agent.robot,
            args.agent.compiled_supervisors.as_deref(),
        )?;
        let limits = limits_of(&experiment, &args.agent.limits)?;
        return Ok((plan, control, limits));
    }
    let mut pairs = args.params.clone();
    if let (Some(profile), Some(supervisors)) = (&args.profile, &args.supervisors) {
        pairs.push(("profile".to_owned(), profile.clone()));
        pairs.push(("supervisors".to_owned(), supervisors.clone()));
    }
    let params = Params::new(pairs);
    let base_dir = std::env::current_dir().context("cannot resolve relative paths")?;
    let plan = controller::plan(&args.element, &params, &base_dir)?;
    let seed = args.agent.seed.unwrap_or(0);
    let control = control::build(&plan, &params, seed, args.agent.robot)?;
    info!(seed, "robot runs {plan}");
    let mut limits = Limits::default();
    limits.apply(&args.agent.limits)?;
    Ok((plan, control, limits))
}

/// Writes the compiled supervisor set of `plan` to `path` (nothing for a native controller).
fn write_supervisors(plan: &Plan, path: &Path) -> Result<()> {
    if let Some(set) = control::supervisor_set(plan)? {
        set.write(path)
            .with_context(|| format!("writing the compiled supervisors to {}", path.display()))?;
        info!(file = %path.display(), "compiled supervisor set written");
    }
    Ok(())
}

/// Pause between two attempts to join.
const JOIN_RETRY_PAUSE: Duration = Duration::from_millis(20);

/// Joins the run. A replacement agent can start before the world's dead-node cleanup has freed the ports and
/// the node place of the agent it replaces (iceoryx2 offers no notification of that), so an exhausted limit is
/// retried for a while ([`Limits::agent_join_retry_ms`]).
fn join(run: &RunSpec, robot: u32, limits: &Limits, mut joining: Joining) -> Result<AgentLink> {
    let started = Instant::now();
    loop {
        match joining.attempt(run, robot, limits.agent_board_wait()) {
            Err(e) if limit_reached(&e) && started.elapsed() < limits.agent_join_retry() => {
                std::thread::sleep(JOIN_RETRY_PAUSE);
            }
            other => return Ok(other?),
        }
    }
}

/// Whether joining failed on an iceoryx2 limit that a dead agent may still hold.
fn limit_reached(error: &TransportError) -> bool {
    match error {
        TransportError::ServiceFull { .. } => true,
        TransportError::Iceoryx { detail, .. } => detail.contains("ExceedsMax"),
        _ => false,
    }
}

/// Which robot of which run an agent serves, and from where it resumes.
struct Seat<'a> {
    run: &'a RunSpec,
    robot: u32,
    slot: u32,
    resume: Option<&'a Path>,
}

/// How an agent joins its run.
enum Joining {
    /// Started as a program of its own (by the launcher, a host, or by hand): it makes its node when it joins and
    /// watches the world process itself.
    OnItsOwn,
    /// Forked by the zygote under `swarm run`: the launcher ends it if the world dies ([`WorldEnd::ByParent`]). The
    /// node made while the world got ready is used by the first attempt; a retry makes a new one.
    FromZygote(Option<AgentNode>),
}

impl Joining {
    /// One attempt to join robot `robot` of `run`.
    fn attempt(
        &mut self,
        run: &RunSpec,
        robot: u32,
        board_wait: Duration,
    ) -> Result<AgentLink, TransportError> {
        match self {
            Joining::OnItsOwn => AgentLink::join_waiting(run, robot, board_wait),
            Joining::FromZygote(early_node) => {
                let node = match early_node.take() {
                    Some(node) => node,
                    None => AgentNode::create(run, robot)?,
                };
                AgentLink::join_on(run, node, board_wait, WorldEnd::ByParent)
            }
        }
    }
}

/// Answers every tick of the run until the world ends it.
fn serve(seat: &Seat<'_>, control: &mut Control, limits: &Limits, joining: Joining) -> Result<()> {
    let point = match seat.resume {
        Some(path) => Some(ResumePoint::read(path)?),
        None => None,
    };
    let mut resumer = Resumer::new(point);
    let join_started = Instant::now();
    let mut link = join(seat.run, seat.slot, limits, joining)?;
    info!(
        run = seat.run.name(),
        robot = seat.robot,
        slot = seat.slot,
        took = ?join_started.elapsed(),
        "joined the run"
    );
    match tick_loop(&mut link, control, &mut resumer, seat.robot)? {
        Ending::RunEnded => link.release_ended_run(),
        Ending::Leaving => drop(link),
    }
    Ok(())
}

/// Why an agent's tick loop ended.
enum Ending {
    /// The world ended the run.
    RunEnded,
    /// The agent was asked to leave a run that goes on.
    Leaving,
}

/// The agent's tick loop: step the controller on each tick's frame and answer, until the world ends the run or
/// the agent is asked to stop.
#[unsafe(link_section = "swarm_hot")]
#[inline(never)]
fn tick_loop(
    link: &mut AgentLink,
    control: &mut Control,
    resumer: &mut Resumer,
    robot: u32,
) -> Result<Ending> {
    // One command lives across ticks: wheel speeds and LEDs persist until an action changes them.
    let mut command = ActuatorCommand::idle(robot, 0);
    link.set_sender(robot);
    while let Some(mut tick) = link.next_tick().context("waiting for a tick")? {
        if STOP_REQUESTED.load(Ordering::Relaxed) {
            info!(robot, "asked to stop: leaving the run");
            return Ok(Ending::Leaving);
        }
        let (frame, inbox, outbox) = tick.parts();
        if resumer.before_step(control, frame)? {
            control.step(frame, inbox, outbox, &mut command);
        } else {
            command.events_len = 0;
        }
        tick.answer(&mut command);
    }
    info!(robot, "the world ended the run");
    Ok(Ending::RunEnded)
}

/// Set by SIGTERM and SIGINT.
static STOP_REQUESTED: AtomicBool = AtomicBool::new(false);

extern "C" fn request_stop(_: nix::libc::c_int) {
    STOP_REQUESTED.store(true, Ordering::Relaxed);
}

/// Makes SIGTERM and SIGINT ask the agent to leave the run instead of killing it.
fn install_stop_handler() -> Result<()> {
    use nix::sys::signal::{SaFlags, SigAction, SigHandler, SigSet, Signal, sigaction};
    let action = SigAction::new(
        SigHandler::Handler(request_stop),
        SaFlags::SA_RESTART,
        SigSet::empty(),
    );
    for signal in [Signal::SIGTERM, Signal::SIGINT] {
        // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
        unsafe { sigaction(signal, &action) }
            .with_context(|| format!("installing the {signal} handler"))?;
    }
    Ok(())
}

fn run(args: &Args) -> Result<()> {
    if args.agent.iox_root.is_none() && !args.check {
        anyhow::bail!("--iox-root is required to join a run (only --check works without it)");
    }
    let (plan, mut control, limits) = build_control(args)
        .with_context(|| format!("robot {}: cannot start its controller", args.agent.robot))?;
    let Some(root) = args.agent.iox_root.as_deref().filter(|_| !args.check) else {
        if let Some(path) = &args.write_supervisors {
            write_supervisors(&plan, path)?;
        }
        info!(robot = args.agent.robot, "controller checked");
        println!("{}", serde_json::to_string(&control.event_names())?);
        return Ok(());
    };
    install_stop_handler()?;
    let run = RunSpec::new(&args.agent.run, root)?;
    let seat = Seat {
        run: &run,
        robot: args.agent.robot,
        slot: args.agent.slot.unwrap_or(args.agent.robot),
        resume: args.agent.resume.as_deref(),
    };
    serve(&seat, &mut control, &limits, Joining::OnItsOwn)
        .with_context(|| format!("robot {} in run {}", args.agent.robot, args.agent.run))
}

/// `robot-agent zygote`: starts many agents of one run by forking this process once it has loaded the
/// configuration (see `robot_agent::zygote`). The launcher and `swarm host` start their robots this way.
#[derive(Debug, Parser)]
#[command(name = "robot-agent zygote", version)]
struct ZygoteCli {
    #[command(flatten)]
    args: ZygoteArgs,
}

/// Reads the zygote's orders (one robot per line) up to an empty line or the end of its standard input: all of
/// them before the first fork, so the launcher never waits on a full pipe while the zygote writes its replies.
fn read_orders() -> Result<Vec<ZygoteOrder>> {
    let mut orders = Vec::new();
    for (number, line) in std::io::stdin().lines().enumerate() {
        let line = line.context("reading the zygote's orders")?;
        if line.is_empty() {
            break;
        }
        let order = line
            .parse()
            .map_err(|e| anyhow!("standard input, line {}: {e}", number + 1))?;
        orders.push(order);
    }
    Ok(orders)
}

/// The zygote: loads the experiment once, then forks one agent per order and answers with its process id.
fn run_zygote(args: &ZygoteArgs) -> Result<()> {
    let experiment = load_experiment(&args.config, args.robots)?;
    let limits = limits_of(&experiment, &args.limits)?;
    let run = RunSpec::new(&args.run.run, &args.run.iox_root)?;
    let orders = read_orders()?;
    // Each robot's controller, found once for all (a robot's own lookup walks every participant).
    let participants = experiment.participants();
    let controller_of = |robot: u32| {
        let participant = participants.get(robot as usize)?;
        experiment.controller(participant.controller)
    };
    install_stop_handler()?;
    let zygote = Zygote::prepare().context("preparing to fork agents")?;
    // SAFETY: `Zygote::prepare` found this process with one thread, and it starts none before forking.
    match unsafe { robot_agent::huge_text::move_code_to_huge_pages() } {
        Ok(outcome) => tracing::debug!(?outcome, "the agents' code"),
        Err(e) => tracing::warn!("the agents' code stays on small pages: {e}"),
    }
    let mut out = std::io::stdout();
    for order in orders {
        let reply = match zygote.fork_agent() {
            Ok(Forked::Agent) => {
                let seat = Seat {
                    run: &run,
                    robot: order.robot,
                    slot: order.slot,
                    resume: None,
                };
                let controller = controller_of(order.robot);
                let code =
                    agent_from_zygote(&zygote, &experiment, controller, args, &limits, &seat);
                zygote.exit_agent(code);
            }
            Ok(Forked::Zygote(pid)) => ZygoteReply::Started {
                robot: order.robot,
                pid,
            },
            Err(e) => ZygoteReply::Failed {
                robot: order.robot,
                reason: format!("cannot fork: {e}"),
            },
        };
        // Flushed before the next fork, so no agent inherits an unwritten reply.
        writeln!(out, "{reply}")
            .and_then(|()| out.flush())
            .context("answering the launcher")?;
    }
    Ok(())
}

/// The life of one agent forked by the zygote, as `robot-agent --run ... --robot ...` would live it; its exit code.
fn agent_from_zygote(
    zygote: &Zygote,
    experiment: &Experiment,
    controller: Option<&Controller>,
    args: &ZygoteArgs,
    limits: &Limits,
    seat: &Seat<'_>,
) -> i32 {
    let log = swarm_contract::run_dir::agent_log_in(&args.logs, seat.robot);
    if let Err(e) = zygote.become_agent(&log) {
        eprintln!("error: robot {}: cannot become an agent: {e}", seat.robot);
        return 1;
    }
    // Without the zygote's lookup, the robot's own one says what is wrong.
    let served = controller
        .map_or_else(|| from_config::controller_of(experiment, seat.robot), Ok)
        .map_err(anyhow::Error::from)
        .and_then(|controller| {
            let compiled = args.compiled_for(&controller.id);
            build_from_config(
                experiment,
                controller,
                args.seed,
                seat.robot,
                compiled.as_deref(),
            )
        })
        .with_context(|| format!("robot {}: cannot start its controller", seat.robot))
        .and_then(|(_, mut control)| {
            // The node needs only the run's iceoryx2 root: made now, it is ready when the world is.
            let node = AgentNode::create(seat.run, seat.slot)?;
            zygote
                .wait_for_the_run()
                .context("waiting for the run's shared memory")?;
            serve(seat, &mut control, limits, Joining::FromZygote(Some(node)))
                .with_context(|| format!("robot {} in run {}", seat.robot, seat.run.name()))
        });
    exit_code(served)
}

/// Reports `result` the way every agent does; its exit code.
fn exit_code(result: Result<()>) -> i32 {
    match result {
        Ok(()) => 0,
        Err(err) => {
            eprintln!(
                "error: {}",
                swarm_contract::logging::error_chain(err.as_ref())
            );
            1
        }
    }
}

fn main() -> ExitCode {
    swarm_contract::logging::init("info,supervisor_gen=warn");
    let result = if std::env::args_os().nth(1).is_some_and(|a| a == "zygote") {
        run_zygote(&ZygoteCli::parse_from(std::env::args_os().skip(1)).args)
    } else {
        run(&Args::parse())
    };
    ExitCode::from(exit_code(result) as u8)
}
