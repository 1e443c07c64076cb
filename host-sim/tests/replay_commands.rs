//! The replay of captures in which the probe carried out uplink commands
//! (issue 15): a synthetic probe (the navigator the firmware runs, driven
//! with the commands) writes its downlink in the firmware's order
//! (`SharedProbe::main_loop_pass`, then `UplinkService::serve`: a reply
//! after the navigation frames of the samples navigated before it, the raw
//! frames running ahead by the navigation's lag), and the replay must
//! carry out every acknowledged command at the same sample, or say why it
//! could not.

mod common;

use common::{refused, run, s, scratch};
use host_sim::formats::capture::{self, CaptureWriter};
use host_sim::replay::commands::CommandOutcome;
use host_sim::replay::{self, Replayer, StepLossReason};
use mwd_core::earth::Position;
use mwd_core::probe::Navigator;
use mwd_core::protocol::frame::{nav_mode, raw_flags, station_flags, NO_PART};
use mwd_core::protocol::uplink::{
    encode_command, Command, IndexingProcedure, NakReason, Reply, ReplyStatus, MAX_COMMAND_WIRE_LEN,
};
use mwd_core::protocol::{Event, EventKind, Payload, RawPart, RawSample, StationSurvey};
use mwd_core::sensor_units::{
    m_s2_to_accel_count, rad_s_to_gyro_count, PART_MOUNTINGS, STANDARD_GRAVITY_M_S2,
};

/// A still, level probe's sample `n`.
fn still(n: u32) -> RawSample {
    let parts = PART_MOUNTINGS.map(|m| RawPart {
        accel: m
            .body_to_sensor([0.0, 0.0, STANDARD_GRAVITY_M_S2])
            .map(m_s2_to_accel_count),
        flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID,
        ..RawPart::default()
    });
    RawSample {
        time_us: u64::from(n) * 50_000,
        sample_counter: n,
        parts,
    }
}

/// What the synthetic probe sent, in order (its index is the frame's
/// place in the capture, for [`capture::without_frame`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Sent {
    Raw(u32),
    Nav(u32, u8),
    Station(StationSurvey),
    Reply(Reply),
    Boot,
}

/// The probe: the firmware's navigator, its stored configuration, and the
/// downlink it writes.
struct Probe {
    navigator: Navigator,
    site: Position,
    config_version: u32,
    sent: Vec<Sent>,
    out: CaptureWriter<Vec<u8>>,
    uplink: Vec<u8>,
    /// The tool turns about its axis from this sample on.
    turning_from: Option<u32>,
}

impl Probe {
    /// Power-on, defaults, version 0 (docs/protocol.md "Event codes").
    fn new() -> Self {
        Self::booted(0x0101)
    }

    /// A probe whose boot event's value is `boot_value`.
    fn booted(boot_value: u32) -> Self {
        let mut probe = Self {
            navigator: Navigator::new(Position::paper_site()),
            site: Position::paper_site(),
            config_version: 0,
            sent: Vec::new(),
            out: CaptureWriter::new(Vec::new()),
            uplink: Vec::new(),
            turning_from: None,
        };
        probe.write(Payload::Event(Event {
            time_us: 0,
            kind: EventKind::Boot,
            part: NO_PART,
            code: 1,
            value: boot_value,
        }));
        probe.sent.push(Sent::Boot);
        probe
    }

    fn write(&mut self, payload: Payload) {
        self.out.write(&payload).unwrap();
        self.sent.push(match payload {
            Payload::Raw(r) => Sent::Raw(r.sample_counter),
            Payload::Nav(n) => Sent::Nav(n.sample_counter, n.mode),
            Payload::Station(st) => Sent::Station(st),
            Payload::Event(_) => return,
        });
    }

    /// Sample `n`: still, or turning at 0.05 rad/s about the body z axis.
    fn sample(&self, n: u32) -> RawSample {
        let mut raw = still(n);
        if self.turning_from.is_some_and(|from| n >= from) {
            for (part, m) in raw.parts.iter_mut().zip(PART_MOUNTINGS) {
                part.gyro_rate = rad_s_to_gyro_count(m.gyro_rate_from_body([0.0, 0.0, 0.05]));
            }
        }
        raw
    }

    /// Runs `samples` samples, the navigation `lag` samples behind the
    /// acquisition; each command of `commands` is served after the
    /// navigation of its sample, as the main loop does.
    fn run(&mut self, samples: u32, lag: u32, commands: &[(u32, Command)]) {
        let mut seq = 1;
        for n in 0..samples + lag {
            if n < samples {
                self.write(Payload::Raw(self.sample(n)));
            }
            let Some(navigated) = n.checked_sub(lag) else {
                continue;
            };
            let solution = self.navigator.step(&self.sample(navigated));
            self.write(Payload::Nav(solution));
            if let Some(station) = self.navigator.take_station() {
                self.write(Payload::Station(station));
            }
            for (_, command) in commands.iter().filter(|(at, _)| *at == navigated) {
                self.serve(seq, command, navigated);
                seq += 1;
            }
        }
    }

    /// Carries out one command as `UplinkService::serve` and the board's
    /// main loop do, and writes its reply.
    fn serve(&mut self, seq: u16, command: &Command, after: u32) {
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq, command, &mut wire).unwrap();
        self.uplink.extend_from_slice(&wire[..n]);
        let mut station = None;
        let done = match command {
            Command::StartSurveying => self.navigator.start_surveying(),
            Command::TakeStation => self.navigator.take_station_now().map(|s| {
                station = Some(s);
            }),
            Command::IndexToolface(p) => self.navigator.index_toolface(*p),
            Command::Realign => {
                self.navigator = Navigator::new(self.site);
                Ok(())
            }
            Command::SetSite(site) => {
                self.site = *site;
                self.config_version += 1;
                Ok(())
            }
            _ => Ok(()),
        };
        let time_us = u64::from(after + 1) * 50_000;
        let mut reply = Reply::ack(time_us, seq, command.kind() as u8, self.config_version);
        if done.is_err() {
            reply.status = ReplyStatus::Nak(NakReason::NotReady);
        }
        self.out.write_reply(&reply).unwrap();
        self.sent.push(Sent::Reply(reply));
        if let Some(station) = station {
            self.write(Payload::Station(station));
        }
    }

    fn bytes(self) -> (Vec<u8>, Vec<Sent>, Vec<u8>) {
        (self.out.finish().unwrap(), self.sent, self.uplink)
    }
}

/// Replays `bytes`, knowing the host's `uplink` log when given.
fn replayed(bytes: &[u8], uplink: Option<&[u8]>) -> Replayer {
    let capture = capture::decode_bytes(bytes);
    let mut replayer = Replayer::new(Position::paper_site());
    for (seq, command) in uplink
        .map(replay::commands::decode_uplink_log)
        .unwrap_or_default()
    {
        replayer.knows_sent_command(seq, &command);
    }
    for received in capture.in_order() {
        replayer.push_received(received);
    }
    replayer
}

/// Start surveying after sample 150 (the 5 s coarse alignment and 2.5 s of
/// the fine one, which start surveying may end after the still detector's
/// 1.95 s), then a station on request: the probe navigates from sample
/// 151, 52 s before the full alignment would have ended.
fn early_survey() -> Vec<(u32, Command)> {
    vec![
        (40, Command::StartSurveying), // coarse alignment: NAK not ready
        (150, Command::StartSurveying),
        (400, Command::TakeStation),
    ]
}

#[test]
fn an_early_start_surveying_and_a_requested_station_replay_bit_for_bit() {
    for lag in [0, 3] {
        let mut probe = Probe::new();
        probe.run(500, lag, &early_survey());
        let (bytes, sent, _) = probe.bytes();
        assert!(sent.contains(&Sent::Nav(151, nav_mode::NAVIGATING)));
        assert!(sent.contains(&Sent::Nav(150, nav_mode::FINE_ALIGNMENT)));
        let requested = sent
            .iter()
            .filter(|s| matches!(s, Sent::Station(st) if st.flags & station_flags::REQUESTED != 0))
            .count();
        assert_eq!(requested, 1, "lag {lag}");

        let mut replayer = replayed(&bytes, None);
        let outcomes: Vec<_> = replayer
            .commands()
            .iter()
            .map(|c| (c.after_sample, c.outcome))
            .collect();
        assert_eq!(
            outcomes,
            [
                (Some(40), CommandOutcome::Refused),
                (Some(150), CommandOutcome::Replayed),
                (Some(400), CommandOutcome::Replayed),
            ],
            "lag {lag}"
        );
        assert!(
            replayer.step_losses().is_empty(),
            "{:?}",
            replayer.step_losses()
        );
        let (_, stations) = replayer.stations();
        assert_eq!(
            (stations.replayed, stations.probe, stations.matched),
            (1, 1, 1),
            "lag {lag}: {stations:?}"
        );
        let (rows, summary) = replayer.finish();
        assert_eq!(
            (summary.matched, summary.mismatched, summary.unchecked),
            (500, 0, 0),
            "lag {lag}"
        );
        assert_eq!(rows[151].solution.mode, nav_mode::NAVIGATING);
    }
}

#[test]
fn a_replay_without_the_replies_never_shows_silent_parity() {
    let mut probe = Probe::new();
    probe.run(500, 1, &early_survey());
    let (bytes, _, _) = probe.bytes();
    let mut capture = capture::decode_bytes(&bytes);
    assert_eq!(capture.replies.len(), 3);
    // The telemetry frames alone (the replies' sequence numbers missing):
    // the 60 s alignment is assumed, and the probe navigating from sample
    // 151 says a reply was probably lost.
    let mut replayer = Replayer::new(Position::paper_site());
    capture.frames.iter().for_each(|f| {
        replayer.push(f);
    });
    assert!(matches!(
        replayer.step_losses()[0].reason,
        StepLossReason::ModeDiffers {
            frames_lost: true,
            ..
        }
    ));
    let (_, summary) = replayer.finish();
    assert_eq!(
        (summary.matched, summary.mismatched, summary.unchecked),
        (151, 0, 349)
    );
    // The same reply read as a NAK, nothing lost: a difference.
    capture.replies[1].reply.status = ReplyStatus::Nak(NakReason::NotReady);
    let mut replayer = Replayer::new(Position::paper_site());
    capture.in_order().for_each(|r| {
        replayer.push_received(r);
    });
    let loss = replayer.step_losses()[0];
    assert!(loss.reason.is_a_difference(), "{loss:?}");
    let (_, summary) = replayer.finish();
    assert_eq!((summary.matched, summary.mismatched), (151, 1));
}

#[test]
fn a_realign_replays_and_one_with_a_new_site_is_not_compared_after_it() {
    let realign = [(150, Command::StartSurveying), (300, Command::Realign)];
    let mut probe = Probe::new();
    probe.run(450, 1, &realign);
    let (bytes, sent, _) = probe.bytes();
    assert!(sent.contains(&Sent::Nav(301, nav_mode::COARSE_ALIGNMENT)));
    let (_, summary) = replayed(&bytes, None).finish();
    assert_eq!(
        (summary.matched, summary.mismatched, summary.unchecked),
        (450, 0, 0)
    );

    let moved = Position::new(0.5, 1.0, 300.0);
    let mut probe = Probe::new();
    probe.run(
        450,
        1,
        &[(100, Command::SetSite(moved)), (300, Command::Realign)],
    );
    let (bytes, _, _) = probe.bytes();
    let replayer = replayed(&bytes, None);
    let losses: Vec<_> = replayer
        .step_losses()
        .iter()
        .map(|l| (l.from_sample, l.reason))
        .collect();
    assert_eq!(losses, [(301, StepLossReason::ConfigurationChanged)]);
    let (_, summary) = replayer.finish();
    assert_eq!(
        (summary.matched, summary.mismatched, summary.unchecked),
        (301, 0, 149)
    );
}

#[test]
fn a_reboot_into_another_configuration_is_not_compared() {
    let mut first = Probe::new();
    first.run(150, 1, &[]);
    // Software reset, configuration 2 from flash: settings the capture
    // does not carry.
    let mut second = Probe::booted(0x0002_0203);
    second.run(150, 1, &[]);
    let mut bytes = first.bytes().0;
    bytes.extend(second.bytes().0);
    let replayer = replayed(&bytes, None);
    let losses: Vec<_> = replayer
        .step_losses()
        .iter()
        .map(|l| (l.run, l.from_sample, l.reason))
        .collect();
    assert_eq!(losses, [(1, 0, StepLossReason::ConfigurationChanged)]);
    let (_, summary) = replayer.finish();
    assert_eq!(
        (summary.matched, summary.unchecked, summary.restarts),
        (150, 150, 1)
    );
}

/// The frame index of the reply to `command_seq`.
fn reply_index(sent: &[Sent], command_seq: u16) -> usize {
    sent.iter()
        .position(|s| matches!(s, Sent::Reply(r) if r.command_seq == command_seq))
        .unwrap()
}

#[test]
fn a_lost_reply_shows_as_a_mode_the_replay_is_not_in_never_as_silent_parity() {
    let mut probe = Probe::new();
    probe.run(500, 1, &early_survey());
    let (bytes, sent, _) = probe.bytes();
    // The ACK of start surveying (command 2) lost on the line.
    let damaged = capture::without_frame(&bytes, reply_index(&sent, 2));
    let replayer = replayed(&damaged, None);
    let losses: Vec<_> = replayer
        .step_losses()
        .iter()
        .map(|l| (l.from_sample, l.reason))
        .collect();
    assert_eq!(
        losses,
        [(
            151,
            StepLossReason::ModeDiffers {
                probe_mode: nav_mode::NAVIGATING,
                replay_mode: nav_mode::FINE_ALIGNMENT,
                frames_lost: true
            }
        )]
    );
    let (_, summary) = replayer.finish();
    assert_eq!(
        (summary.matched, summary.mismatched, summary.unchecked),
        (151, 0, 349)
    );
}

#[test]
fn a_lost_reply_to_take_a_station_is_not_called_a_difference() {
    let mut probe = Probe::new();
    // Still until sample 600, then turning: the still period's station is
    // sent on request at 400, and its end sends nothing more.
    probe.turning_from = Some(600);
    let commands = [(150, Command::StartSurveying), (400, Command::TakeStation)];
    probe.run(700, 1, &commands);
    let (bytes, sent, _) = probe.bytes();
    let mut whole = replayed(&bytes, None);
    let (_, st) = whole.stations();
    assert_eq!((st.replayed, st.probe, st.matched), (1, 1, 1), "{st:?}");

    // The ACK (command 2) lost: the replay ends the station at the turn,
    // unflagged, against the probe's requested frame.
    let mut replayer = replayed(&capture::without_frame(&bytes, reply_index(&sent, 2)), None);
    let (rows, st) = replayer.stations();
    assert_eq!(rows[0].station.flags & station_flags::REQUESTED, 0);
    assert_eq!(
        (
            st.replayed,
            st.probe,
            st.matched,
            st.mismatched,
            st.unchecked
        ),
        (1, 1, 0, 0, 1),
        "{st:?}"
    );
    assert_eq!(
        replayer.step_losses()[0].reason,
        StepLossReason::StationCommandLost { station: 1 }
    );
    // The navigation is untouched by the command: still compared.
    let (_, summary) = replayer.finish();
    assert_eq!((summary.mismatched, summary.unchecked), (0, 0));
}

#[test]
fn a_command_whose_place_was_lost_is_not_guessed() {
    let mut probe = Probe::new();
    probe.run(300, 0, &[(150, Command::StartSurveying)]);
    let (bytes, sent, _) = probe.bytes();
    // The navigation frame right before the ACK: the replay knows the
    // command came after sample 149's, not whether after 150's too.
    let nav = sent
        .iter()
        .position(|s| *s == Sent::Nav(150, nav_mode::FINE_ALIGNMENT))
        .unwrap();
    assert_eq!(nav + 1, reply_index(&sent, 1));
    let replayer = replayed(&capture::without_frame(&bytes, nav), None);
    assert_eq!(replayer.commands()[0].after_sample, Some(149));
    assert!(!replayer.commands()[0].place_known);
    assert_eq!(
        replayer.step_losses()[0].reason,
        StepLossReason::CommandPlaceUnknown { command_seq: 1 }
    );
    let (_, summary) = replayer.finish();
    assert_eq!((summary.matched, summary.mismatched), (150, 0));
}

/// Toolface indexing (2 positions of 3 s) on the still probe: its first
/// dwell is sent once the probe has been still for 3 s.
fn indexing() -> Vec<(u32, Command)> {
    let procedure = IndexingProcedure {
        positions: 2,
        dwell_s: 3,
    };
    vec![
        (150, Command::StartSurveying),
        (160, Command::IndexToolface(procedure)),
        (400, Command::TakeStation),
    ]
}

#[test]
fn indexing_stations_are_compared_with_the_uplink_log_and_only_then() {
    let mut probe = Probe::new();
    probe.run(450, 1, &indexing());
    let (bytes, sent, uplink) = probe.bytes();
    let dwells = sent
        .iter()
        .filter(|s| matches!(s, Sent::Station(st) if st.flags & station_flags::INDEXING_DWELL != 0))
        .count();
    assert_eq!(dwells, 2, "the dwell and its requested repeat");

    let mut with_log = replayed(&bytes, Some(&uplink));
    assert!(with_log.step_losses().is_empty());
    let (_, st) = with_log.stations();
    assert_eq!(
        (st.replayed, st.probe, st.matched, st.unchecked),
        (2, 2, 2, 0)
    );
    let (_, summary) = with_log.finish();
    assert_eq!((summary.matched, summary.unchecked), (450, 0));

    // Without it the navigation is still compared, the stations are not.
    let mut without = replayed(&bytes, None);
    assert_eq!(
        without.step_losses()[0].reason,
        StepLossReason::IndexingUnknown { command_seq: 2 }
    );
    let (_, st) = without.stations();
    assert_eq!((st.matched, st.mismatched, st.unchecked), (0, 0, 2));
    let (_, summary) = without.finish();
    assert_eq!((summary.matched, summary.unchecked), (450, 0));
}

#[test]
fn the_cli_replays_the_commands_and_exits_by_what_it_could_compare() {
    let dir = scratch("replay-commands", "cli");
    let mut probe = Probe::new();
    probe.run(450, 1, &indexing());
    let (bytes, sent, uplink) = probe.bytes();
    let capture = dir.join("probe.bin");
    let log = dir.join("uplink.bin");
    std::fs::write(&capture, &bytes).unwrap();
    std::fs::write(&log, &uplink).unwrap();

    let full = run(&["replay", s(&capture), "--uplink", s(&log)]);
    assert_eq!(full.code, Some(0), "{}{}", full.stdout, full.stderr);
    assert!(
        full.stdout
            .contains("command 1 start surveying ACK: replayed after sample 150"),
        "{}",
        full.stdout
    );
    assert!(full
        .stdout
        .contains("450 identical, 0 different, 0 not compared"));

    let no_log = run(&["replay", s(&capture)]);
    assert_eq!(no_log.code, Some(2), "{}{}", no_log.stdout, no_log.stderr);
    assert!(no_log
        .stdout
        .contains("toolface indexing (command 2) without its parameters"));

    let lost = dir.join("lost.bin");
    std::fs::write(&lost, capture::without_frame(&bytes, reply_index(&sent, 1))).unwrap();
    let lost_reply = run(&["replay", s(&lost), "--uplink", s(&log)]);
    assert_eq!(lost_reply.code, Some(2), "{}", lost_reply.stdout);
    assert!(
        lost_reply
            .stdout
            .contains("most likely the reply to a start surveying or re-align"),
        "{}",
        lost_reply.stdout
    );
    let missing = dir.join("no-such-log.bin");
    let bad_log = run(&["replay", s(&capture), "--uplink", s(&missing)]);
    refused(&bad_log, "uplink log");
    let _ = std::fs::remove_dir_all(dir);
}
