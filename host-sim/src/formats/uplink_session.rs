//! The uplink to a live probe over its serial port (`docs/protocol.md`,
//! "Uplink"): each command is sent and its reply awaited among the
//! probe's telemetry (`Decoder::unknown_body`, `decode_reply_body`),
//! matched by sequence number; without a reply it is sent again, up to
//! the attempts allowed (a setting sent twice is acknowledged twice and
//! stored once). A station taken on request follows its ACK.

use crate::formats::display::{reply_text, station_text};
use anyhow::{bail, Context, Result};
use mwd_core::protocol::frame::station_flags;
use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::{
    encode_command, Command, Reply, ReplyStatus, MAX_COMMAND_WIRE_LEN,
};
use mwd_core::protocol::{Decoder, Payload, StationSurvey};
use std::io::{ErrorKind, Read, Write};
use std::time::{Duration, Instant};

/// A link to a live probe over its serial port: commands sent, replies
/// awaited among its telemetry.
pub struct Session {
    port: Box<dyn serialport::SerialPort>,
    decoder: Decoder,
    next_seq: u16,
    timeout: Duration,
    attempts: u32,
    /// Station frames that came after the last reply.
    stations: Vec<StationSurvey>,
}

impl Session {
    /// Opens `port` at `baud`: each reply is awaited `timeout`, a command
    /// sent up to `attempts` times.
    pub fn open(port: &str, baud: u32, timeout: Duration, attempts: u32) -> Result<Self> {
        let serial = serialport::new(port, baud)
            .timeout(Duration::from_millis(20))
            .open()
            .with_context(|| format!("opening serial port {port}"))?;
        Ok(Self {
            port: serial,
            decoder: Decoder::new(),
            // A new number each run, so a late reply to an earlier run's
            // command is not taken for this one's.
            next_seq: rand::random(),
            timeout,
            attempts,
            stations: Vec::new(),
        })
    }

    /// Sends each command (a label and the command) in turn, showing
    /// `show` a line for each reply (and the station a take-a-station
    /// command brings); returns how many were refused (NAK) or never
    /// answered.
    pub fn send_all(
        &mut self,
        commands: &[(String, Command)],
        mut show: impl FnMut(&str),
    ) -> Result<usize> {
        let mut refused = 0;
        for (label, command) in commands {
            match self.send(command) {
                Ok(reply) => {
                    show(&format!("{label}: {}", reply_text(&reply)));
                    refused += usize::from(reply.status != ReplyStatus::Ack);
                    // A station taken on request follows its ACK.
                    if reply.status == ReplyStatus::Ack && matches!(command, Command::TakeStation) {
                        match self.await_requested_station()? {
                            Some(station) => show(&format!("  {}", station_text(&station))),
                            None => {
                                show("  the station frame did not arrive");
                                refused += 1;
                            }
                        }
                    }
                }
                Err(e) => {
                    show(&format!("{label}: {e:#}"));
                    refused += 1;
                }
            }
        }
        Ok(refused)
    }

    /// Sends `command` until its reply comes or the attempts run out.
    pub fn send(&mut self, command: &Command) -> Result<Reply> {
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
    pub fn await_requested_station(&mut self) -> Result<Option<StationSurvey>> {
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
