//! `swarm-world`: the world process of a run.
//!
//! Builds the arena from the experiment, creates the run's shared-memory services for N robots, says `ready`,
//! waits for the agents, then runs the lockstep: sense every robot into the shared frames, wake the agents, wait
//! for their commands (a dead or late robot never blocks: it holds still), act, step physics and media, record.
//! Progress goes to standard output as [`WorldReport`] lines for the launcher; the launcher's lines on standard
//! input (death notices, restarts, applied faults) and the fault schedule are handled in [`faults`], the same
//! way whether the robots run here or on hosts.
//! SIGINT/SIGTERM end the run after the current tick with every record flushed. Normally started by `swarm run`;
//! the flags are documented by `swarm-world --help`. With hosts (`--hosts` or `<hosts>`), the robots run on
//! `swarm host` daemons reached over zenoh instead ([`remote`]).

mod faults;
mod pacing;
mod post;
mod remote;
mod ticking_cpu;

use std::io::Write;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use swarm_contract::config::Experiment;
use swarm_contract::config::faults::FaultSchedule;
use swarm_contract::disk_budget::DiskBudget;
use swarm_contract::messages::ActuatorCommand;
use swarm_contract::protocol::launcher_to_world::WorldArgs;
use swarm_contract::protocol::world_to_launcher::WorldReport;
use swarm_contract::transport::{LinkConfig, RunSpec, WorldLink, priority};
use swarm_remote::plan::{HostsArgs, HostsPlan};
use swarm_world::World;
use swarm_world::recorder::Recorder;

use faults::FaultDriver;
use pacing::Pacer;
use post::PostOffice;
use remote::Link;
use ticking_cpu::TickingCpu;

/// Minimum interval between two progress reports to the launcher.
const REPORT_INTERVAL: Duration = Duration::from_millis(50);

/// The world process of a swarm run.
#[derive(Debug, Parser)]
#[command(name = "swarm-world", version, about)]
struct Cli {
    #[command(flatten)]
    args: WorldArgs,
    #[command(flatten)]
    hosts: HostsArgs,
}

fn main() -> ExitCode {
    // SAFETY: the process has one thread here.
    if let Err(e) = unsafe { swarm_remote::session::configure_zenoh_runtime() } {
        eprintln!("swarm-world: error: {e}");
        return ExitCode::FAILURE;
    }
    swarm_contract::logging::init("info");
    let cli = Cli::parse();
    match run(&cli.args, &cli.hosts) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!(
                "swarm-world: error: {}",
                swarm_contract::logging::error_chain(e.as_ref())
            );
            ExitCode::FAILURE
        }
    }
}

/// Prints one report line for the launcher.
fn report(line: WorldReport) {
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{line}");
    let _ = out.flush();
}

fn run(args: &WorldArgs, hosts: &HostsArgs) -> anyhow::Result<()> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("installing the stop handler")?;

    let (experiment, _warnings) = Experiment::load(&args.config)?;
    let experiment = match args.robots {
        Some(n) => experiment.with_robot_count(n)?,
        None => experiment,
    };
    let mut world = World::new(&experiment, args.seed)?;
    // The launcher resolved the run's length (`--ticks`, else the experiment's `length`): it wins both ways.
    world.set_max_ticks((args.ticks > 0).then_some(args.ticks));
    // The transport, the fault schedule and the records count every participant: the robots, then the
    // coordinators; the world simulates the robots' bodies only.
    let bodies = world.robot_count();
    let robots = world.participant_count();
    let schedule = FaultSchedule::for_run(&experiment, &args.faults, robots as u32)?;
    world.set_dead_bodies(schedule.dead_bodies);
    let roster: Vec<(String, String)> = experiment
        .participants()
        .into_iter()
        .map(|p| (p.id, p.controller.to_owned()))
        .collect();

    let run = RunSpec::new(&args.run.run, &args.run.iox_root)?;
    let mut limits = experiment.framework.limits;
    limits.apply(&args.limits)?;
    let mut link_config = LinkConfig::new(robots as u32);
    link_config.tick_deadline = limits.tick_deadline();
    link_config.pin_chains = experiment.framework.pin_agents;
    link_config.realtime = priority::tick_at_realtime(experiment.framework.realtime_priority);
    link_config.mail = world.has_mail();
    let (mut link, launcher) = match HostsPlan::resolve(experiment.framework.hosts.as_ref(), hosts)?
    {
        None => {
            let link = WorldLink::create(&run, link_config)?;
            let launcher = faults::follow_launcher(Some(link.death_notices()));
            (Link::Local(link), launcher)
        }
        Some(plan) => {
            let controllers = roster.iter().map(|(_, c)| c.clone()).collect();
            let link = Link::remote(
                plan,
                args,
                controllers,
                &limits,
                link_config.pin_chains,
                experiment.framework.realtime_priority,
                link_config.mail,
            )?;
            (link, faults::follow_launcher(None))
        }
    };
    let mut faults = FaultDriver::new(
        &link,
        &world,
        &schedule,
        args.seed,
        launcher,
        args.out.clone(),
        &limits,
    )?
    .with_arrivals(faults::Arrivals::new(&experiment));
    // The agents may join as soon as the link exists: they join while the record files and the first snapshot
    // are made.
    report(WorldReport::Ready {
        robots: robots as u32,
    });
    let mut recorder = Recorder::create(&args.out, &world, &[0], args.records)?;
    let mut post = PostOffice::new(&world, link.robots());
    recorder.record(&mut world)?;

    let mut commands: Vec<ActuatorCommand> = (0..robots)
        .map(|i| ActuatorCommand::idle(i as u32, 0))
        .collect();
    faults.wait_for_agents(&mut link, &mut world, &mut recorder, &commands)?;
    let mut cpu = None;
    let started = Instant::now();
    let mut pacer = Pacer::new(args.real_time, experiment.framework.ticks_per_second);
    let mut has_command = vec![false; robots];
    let mut robot_steps: u64 = 0;
    // Commands that missed their tick's deadline: a run with none is a pure function of (config, seed, faults).
    let mut commands_missing: u64 = 0;
    let mut last_report = Instant::now();
    let mut tick_micros: Vec<u32> = Vec::with_capacity(args.ticks.min(1 << 24) as usize);
    let mut budget = DiskBudget::new(&args.out, limits.disk_reserve_mb, limits.records_max_mb);
    let mut stopped_early = None;
    while !stop.load(Ordering::Relaxed) && !world.is_finished() {
        faults.before_tick(
            link.tick() + 1,
            &mut link,
            &mut world,
            &mut recorder,
            &commands,
        )?;
        let tick_started = Instant::now();
        let outcome = link.tick_with(|_, first, frames| world.sense_robots(first, frames))?;
        for robot in 0..robots {
            match link
                .command(robot as u32)
                .filter(|_| faults.is_alive(robot))
            {
                Some(command) => {
                    commands[robot] = *command;
                    has_command[robot] = true;
                    recorder.record_command(robot, command);
                }
                None => has_command[robot] = false,
            }
        }
        world.act_and_step(&commands[..bodies], &has_command[..bodies]);
        if let Some(post) = &mut post {
            post.after_tick(&mut link, &mut world, &faults, &mut recorder);
        }
        recorder.record(&mut world)?;
        tick_micros.push(u32::try_from(tick_started.elapsed().as_micros()).unwrap_or(u32::MAX));
        robot_steps += u64::from(outcome.answered);
        commands_missing += u64::from(outcome.missing);
        if outcome.tick == 1 || last_report.elapsed() >= REPORT_INTERVAL {
            last_report = Instant::now();
            report(WorldReport::Tick {
                tick: outcome.tick,
                answered: outcome.answered,
                missing: outcome.missing,
                dead: outcome.dead,
            });
        }
        if outcome.tick == 1 {
            cpu = TickingCpu::start(&link, robot_steps);
        }
        pacer.end_of_tick(outcome.tick);
        if let Some(reason) = budget.exceeded() {
            tracing::error!(tick = outcome.tick, "stopping the run: {reason}");
            stopped_early = Some(reason);
            break;
        }
    }
    let ticking = started.elapsed().as_secs_f64();
    tracing::debug!("last tick done");
    // The agents' CPU accounts (a `/proc` file each, about 10 ms at 1,000 robots) are read while the record files
    // are completed: both must be done before the agents are let go, and the records mostly wait for the
    // recording thread.
    let ticks = link.tick();
    let cpu = cpu.map(|cpu| (cpu.same_agents(&link), cpu));
    let (cpu, records) = std::thread::scope(|scope| {
        let reading = scope
            .spawn(|| cpu.map(|(same_agents, cpu)| cpu.summary(ticks, robot_steps, same_agents)));
        let records = recorder.complete_records();
        (reading.join().ok().flatten(), records)
    });
    records?;
    let mut extra = serde_json::json!({
        "robot_steps": robot_steps,
        "commands_missing": commands_missing,
        "ticking_seconds": ticking,
        "robot_steps_per_second": if ticking > 0.0 { robot_steps as f64 / ticking } else { 0.0 },
        "tick_micros_p50": percentile(&mut tick_micros, 0.50),
        "tick_micros_p99": percentile(&mut tick_micros, 0.99),
        "real_time": pacer.summary(ticks),
        "limits": limits,
        "stopped_early": stopped_early,
    });
    if let Some(object) = extra.as_object_mut() {
        object.insert("alive_final".into(), faults.alive_count().into());
        object.insert("arrivals".into(), faults.arrivals_summary());
        if let Some(post) = &post {
            object.insert("messages".into(), post.summary());
        }
        if let Some(hosts) = link.summary() {
            object.insert("hosts".into(), hosts);
        }
        if let Some(serde_json::Value::Object(cpu)) = cpu {
            object.extend(cpu);
        }
    }
    // The record files were completed while the agents still slept (see `Recorder::complete_records`); now the
    // agents exit while the final snapshot is drawn.
    link.end();
    recorder.finish(&world, extra)?;
    report(WorldReport::Finished { ticks });
    Ok(())
}

/// The `q` quantile of the tick times in microseconds (0 when there were no ticks).
fn percentile(samples: &mut [u32], q: f64) -> u32 {
    if samples.is_empty() {
        return 0;
    }
    samples.sort_unstable();
    let rank = ((samples.len() - 1) as f64 * q).round() as usize;
    samples[rank.min(samples.len() - 1)]
}
