//! `host-sim probe configure | status | align | survey | station | index | reboot`: commands
//! to a live probe over its serial port (`docs/protocol.md`, "Uplink"),
//! through `host_sim::formats::uplink_session`: each command is sent and
//! its reply awaited, sent again up to `--attempts` times without one.
//! Exit status 1 when any command was refused (NAK) or never answered.

use anyhow::{bail, Result};
use host_sim::formats::uplink_session::Session;
use host_sim::survey::job::Job;
use mwd_core::protocol::uplink::fields::{INDEX_DWELL_S, INDEX_POSITIONS};
use mwd_core::protocol::uplink::{Command, IndexingProcedure};
use std::path::PathBuf;
use std::time::Duration;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    action: Action,
}

#[derive(clap::Subcommand, Debug)]
enum Action {
    /// Send a job file's site, tie-in, calibration and still settings (if
    /// it has them), then ask for the configuration's version.
    Configure {
        /// The job file (JSON: site, tie-in, calibration file, still settings).
        #[arg(long)]
        job: PathBuf,
        #[command(flatten)]
        link: LinkArgs,
    },
    /// Ask for the configuration's version.
    Status(LinkArgs),
    /// Align again (the probe must be still).
    Align(LinkArgs),
    /// Start surveying (drilling mode): end the static alignment now, so
    /// the string may move (refused in the alignment's first 6 s).
    Survey(LinkArgs),
    /// Take a station survey now (the probe must be still); the station
    /// frame follows the ACK on the downlink.
    Station(LinkArgs),
    /// Start the guided toolface-indexing procedure: the probe reports
    /// each dwell it detects.
    Index {
        /// Toolface positions to visit (2 to 36).
        #[arg(long, value_parser = clap::value_parser!(u8)
            .range(INDEX_POSITIONS.0 as i64..=INDEX_POSITIONS.1 as i64))]
        positions: u8,
        /// Seconds to hold each position (3 to 600).
        #[arg(long, value_parser = clap::value_parser!(u16)
            .range(INDEX_DWELL_S.0 as i64..=INDEX_DWELL_S.1 as i64))]
        dwell_s: u16,
        #[command(flatten)]
        link: LinkArgs,
    },
    /// Reboot the probe.
    Reboot(LinkArgs),
}

#[derive(clap::Args, Debug)]
struct LinkArgs {
    /// The probe's serial port (e.g. /dev/ttyUSB0, or QEMU's pty).
    #[arg(long)]
    port: String,
    #[arg(long, default_value_t = 115_200)]
    baud: u32,
    /// How long to wait for each reply, milliseconds.
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u64).range(10..=60_000))]
    reply_timeout_ms: u64,
    /// Sends of a command before giving up on its reply.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=20))]
    attempts: u32,
}

pub fn run(args: Args) -> Result<()> {
    let (link, commands) = commands(args.action)?;
    let timeout = Duration::from_millis(link.reply_timeout_ms);
    let mut session = Session::open(&link.port, link.baud, timeout, link.attempts)?;
    let refused = session.send_all(&commands, |line| outln!("{line}"))?;
    if refused > 0 {
        bail!("{refused} of {} commands not acknowledged", commands.len());
    }
    Ok(())
}

/// The link and the commands to send (each with its label) of an action.
fn commands(action: Action) -> Result<(LinkArgs, Vec<(String, Command)>)> {
    Ok(match action {
        Action::Configure { job, link } => {
            let job = Job::load(&job)?;
            let mut commands = job.commands();
            commands.push(("report configuration".into(), Command::ReportConfig));
            (link, commands)
        }
        Action::Status(link) => (
            link,
            vec![("report configuration".into(), Command::ReportConfig)],
        ),
        Action::Align(link) => (link, vec![("re-align".into(), Command::Realign)]),
        Action::Survey(link) => (
            link,
            vec![("start surveying".into(), Command::StartSurveying)],
        ),
        Action::Station(link) => (link, vec![("take a station".into(), Command::TakeStation)]),
        Action::Index {
            positions,
            dwell_s,
            link,
        } => (
            link,
            vec![(
                format!("toolface indexing, {positions} positions of {dwell_s} s"),
                Command::IndexToolface(IndexingProcedure { positions, dwell_s }),
            )],
        ),
        Action::Reboot(link) => (link, vec![("reboot".into(), Command::Reboot)]),
    })
}
