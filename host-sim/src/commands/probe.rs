//! `host-sim probe configure | status | align | survey | station | index | reboot`: commands
//! to a live probe over its serial port (`docs/protocol.md`, "Uplink").
//! Each command is sent and its reply awaited among the probe's telemetry
//! (`Decoder::unknown_body`, `decode_reply_body`), matched by sequence
//! number; without a reply it is sent again, up to `--attempts` times (a
//! setting sent twice is acknowledged twice and stored once). Exit status
//! 1 when any command was refused (NAK) or never answered.

use anyhow::{bail, Context, Result};
use host_sim::formats::display::{reply_text, station_text};
use host_sim::survey::job::Job;
use mwd_core::protocol::frame::station_flags;
use mwd_core::protocol::uplink::fields::{INDEX_DWELL_S, INDEX_POSITIONS};
use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::{
    encode_command, Command, IndexingProcedure, Reply, ReplyStatus, MAX_COMMAND_WIRE_LEN,
};
use mwd_core::protocol::{Decoder, Payload, StationSurvey};
use std::io::{ErrorKind, Read, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

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
    let (link, commands) = match args.action {
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
    };
    let port = serialport::new(&link.port, link.baud)
        .timeout(Duration::from_millis(20))
        .open()
        .with_context(|| format!("opening serial port {}", link.port))?;
    let mut session = Session {
        port,
        decoder: Decoder::new(),
        // A new number each run, so a late reply to an earlier run's
        // command is not taken for this one's.
        next_seq: rand::random(),
        timeout: Duration::from_millis(link.reply_timeout_ms),
        attempts: link.attempts,
        stations: Vec::new(),
    };
    let mut refused = 0;
    for (label, command) in &commands {
        match session.send(command) {
            Ok(reply) => {
                outln!("{label}: {}", reply_text(&reply));
                refused += usize::from(reply.status != ReplyStatus::Ack);
                // A station taken on request follows its ACK.
                if reply.status == ReplyStatus::Ack && matches!(command, Command::TakeStation) {
                    match session.await_requested_station()? {
                        Some(station) => outln!("  {}", station_text(&station)),
                        None => {
                            outln!("  the station frame did not arrive");
                            refused += 1;
                        }
                    }
                }
            }
            Err(e) => {
                outln!("{label}: {e:#}");
                refused += 1;
            }
        }
    }
    if refused > 0 {
        bail!("{refused} of {} commands not acknowledged", commands.len());
    }
    Ok(())
}

struct Session {
    port: Box<dyn serialport::SerialPort>,
    decoder: Decoder,
    next_seq: u16,
    timeout: Duration,
    attempts: u32,
    /// Station frames that came after the last reply.
    stations: Vec<StationSurvey>,
}

impl Session {
    /// Sends `command` until its reply comes or the attempts run out.
    fn send(&mut self, command: &Command) -> Result<Reply> {
        let seq = self.next_seq;
        self.next_seq = seq.wrapping_add(1);
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq, command, &mut wire)?;
        for _ in 0..self.attempts {
            self.port
                .write_all(&wire[..n])
                .and_then(|()| self.port.flush())
                .context("writing to the serial port")?;
            if let Some(reply) = self.await_reply(seq)? {
                return Ok(reply);
            }
        }
        bail!(
            "no reply after {} attempts of {} ms",
            self.attempts,
            self.timeout.as_millis()
        )
    }

    /// Reads until the reply to `seq` comes (the rest of that read is
    /// decoded too: a station frame may follow the reply at once).
    fn await_reply(&mut self, seq: u16) -> Result<Option<Reply>> {
        self.stations.clear();
        let mut found = None;
        self.read_until(|_, reply| {
            if let Some(reply) = reply.filter(|r| r.command_seq == seq) {
                found = Some(reply);
            }
            found.is_some()
        })?;
        Ok(found)
    }

    /// The station frame flagged requested, from what followed the reply
    /// or what comes within the reply timeout.
    fn await_requested_station(&mut self) -> Result<Option<StationSurvey>> {
        let requested = |s: &StationSurvey| s.flags & station_flags::REQUESTED != 0;
        if let Some(station) = self.stations.iter().copied().find(requested) {
            return Ok(Some(station));
        }
        let mut found = None;
        self.read_until(|station, _| {
            found = found.or(station.filter(requested));
            found.is_some()
        })?;
        Ok(found)
    }

    /// Reads the port for up to the reply timeout, showing `done` each
    /// station frame and reply, until it returns true; telemetry frames
    /// are passed over, replies found among the kinds the telemetry
    /// decoder does not know. Station frames are kept in `stations`.
    fn read_until(
        &mut self,
        mut done: impl FnMut(Option<StationSurvey>, Option<Reply>) -> bool,
    ) -> Result<()> {
        let deadline = Instant::now() + self.timeout;
        let mut buf = [0u8; 256];
        let mut finished = false;
        while !finished && Instant::now() < deadline {
            let got = match self.port.read(&mut buf) {
                Ok(got) => got,
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::Interrupted) => 0,
                Err(e) => return Err(e).context("reading the serial port"),
            };
            for b in &buf[..got] {
                let station = match self.decoder.push(*b).map(|f| f.payload) {
                    Some(Payload::Station(s)) => Some(s),
                    _ => None,
                };
                let reply = self.decoder.unknown_body().map(decode_reply_body);
                let reply = reply.and_then(|r| r.ok()).map(|(_, r)| r);
                if finished {
                    self.stations.extend(station);
                } else if station.is_some() || reply.is_some() {
                    finished = done(station, reply);
                }
            }
        }
        Ok(())
    }
}
