//! The main loop's side of the uplink on every board: takes the bytes the
//! UART's receive interrupt put in the inbox ([`super::uplink_rx`]),
//! answers each command on the downlink (an ACK or a NAK, kind 5) and
//! keeps the configuration in the board's flash ([`super::config_store`]).
//!
//! The survey commands (start surveying, take a station, toolface
//! indexing) are carried out on the navigator here, between navigation
//! steps, and answered by what it did: an ACK when they took effect, a NAK
//! with the navigator's reason (not ready, not still) when not
//! (`mwd_core::probe::navigator::commands`). A station taken on request
//! follows its ACK on the downlink.
//!
//! Acquisition is never delayed by it: it runs in the main loop, takes at
//! most a given number of bytes per call, and queues a reply only when the
//! transmit queue has the room a navigation step needs
//! ([`NAV_ROOM_BYTES`]); otherwise the bytes wait in the inbox for the
//! next pass, so a reply never takes the room of a raw frame.

use embedded_storage::nor_flash::NorFlash;
use mwd_core::config::ProbeConfig;
use mwd_core::probe::navigator::commands::Refusal;
use mwd_core::probe::Navigator;
use mwd_core::protocol::uplink::{NakReason, ReplyStatus};
use mwd_core::protocol::{Payload, StationSurvey};
use mwd_core::timing::sample_time_us;

use super::boot::ConfigSource;
use super::budget::NAV_ROOM_BYTES;
use super::config_store::{ConfigStore, LoadSource};
use super::frame_queue::TX_QUEUE_LEN;
use super::shared::SharedProbe;
use super::transmitter::Transmitter;
use super::uplink_rx::{apply, Action, InboxReader, UplinkReceiver, UplinkStats};

/// What a board does for a command the service acknowledged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoardAction {
    /// Restart the navigation from the configuration (site, calibration).
    Realign,
    /// Restart the MCU once the reply has left.
    Reboot,
}

/// The receiver, the configuration in use and its flash.
pub struct UplinkService<F> {
    receiver: UplinkReceiver,
    config: ProbeConfig,
    /// `None` when the board's flash region is unusable: settings are then
    /// refused (NAK storage failed) rather than kept only until a reset.
    store: Option<ConfigStore<F>>,
    source: ConfigSource,
    replies_dropped: u32,
}

impl<F: NorFlash> UplinkService<F> {
    /// Loads the configuration from the two slots at `base` of `flash`
    /// (the defaults when neither holds a valid record, or when the region
    /// does not fit them). Never inlined, like [`Self::serve`]: its record
    /// buffers must not become part of the caller's (the main loop's)
    /// frame, which is live under every navigation step (stack budget,
    /// docs/budgets.md).
    #[inline(never)]
    pub fn load(flash: F, base: u32) -> Self {
        let mut store = ConfigStore::new(flash, base).ok();
        let (config, source) = match store.as_mut().map(|s| s.load()) {
            Some(loaded) => match loaded.source {
                LoadSource::Slot { .. } => (loaded.config, ConfigSource::Flash),
                LoadSource::Defaults => (loaded.config, ConfigSource::Defaults),
            },
            None => (ProbeConfig::default(), ConfigSource::Defaults),
        };
        #[cfg(feature = "defmt")]
        match source {
            ConfigSource::Flash => {
                defmt::info!("configuration v{=u32} from flash", config.version)
            }
            _ => defmt::info!("configuration: the defaults (no valid flash record)"),
        }
        Self {
            receiver: UplinkReceiver::new(),
            config,
            store,
            source,
            replies_dropped: 0,
        }
    }

    pub fn config(&self) -> &ProbeConfig {
        &self.config
    }

    /// Where the configuration in use at boot came from.
    pub fn source(&self) -> ConfigSource {
        self.source
    }

    pub fn stats(&self) -> &UplinkStats {
        self.receiver.stats()
    }

    /// Replies the transmit queue had no room for (the host sends again).
    pub fn replies_dropped(&self) -> u32 {
        self.replies_dropped
    }

    /// Takes at most `max_bytes` from the inbox, answering each command
    /// they complete (the survey commands carried out on `navigator`);
    /// returns the first action a board must carry out (the rest of the
    /// bytes wait for the next call).
    #[inline(never)]
    pub fn serve<G, A, T: Transmitter>(
        &mut self,
        probe: &SharedProbe<G, A, T>,
        navigator: &mut Navigator,
        inbox: &mut InboxReader,
        max_bytes: usize,
    ) -> Option<BoardAction> {
        let start = self.receiver.stats().bytes;
        loop {
            let (room, samples) = probe.with(|s| {
                (
                    TX_QUEUE_LEN - s.probe().queue().len(),
                    s.probe().cycle().samples(),
                )
            });
            let taken = self.receiver.stats().bytes.wrapping_sub(start) as usize;
            if room < NAV_ROOM_BYTES || taken >= max_bytes {
                return None;
            }
            let decoded = self.receiver.poll(inbox, max_bytes - taken)?;
            let store = &mut self.store;
            let outcome = apply(
                &decoded,
                &mut self.config,
                sample_time_us(samples),
                true,
                |c| {
                    store
                        .as_mut()
                        .ok_or(())
                        .and_then(|s| s.save(c).map(|_slot| ()).map_err(|_| ()))
                },
            );
            let Some(mut outcome) = outcome else {
                continue;
            };
            let mut station = None;
            let done = match outcome.action {
                Some(Action::StartSurveying) => navigator.start_surveying(),
                Some(Action::TakeStation) => navigator.take_station_now().map(|s| {
                    station = Some(s);
                }),
                Some(Action::IndexToolface(p)) => navigator.index_toolface(p),
                _ => Ok(()),
            };
            if let Err(refusal) = done {
                outcome.reply.status = ReplyStatus::Nak(nak_reason(refusal));
            }
            #[cfg(feature = "defmt")]
            if let ReplyStatus::Nak(reason) = outcome.reply.status {
                let s = self.receiver.stats();
                defmt::warn!(
                    "uplink NAK, reason {=u8}; refused so far: {=u32} CRC, {=u32} malformed, \
                     {=u32} oversized, {=u32} unknown, {=u32} out of range",
                    reason.to_byte(),
                    s.crc_failures,
                    s.malformed,
                    s.oversized,
                    s.unknown,
                    s.out_of_range
                );
            }
            let action = match outcome.action {
                Some(Action::Realign) => Some(BoardAction::Realign),
                Some(Action::Reboot) => Some(BoardAction::Reboot),
                _ => None,
            };
            self.send(probe, &outcome.reply, station);
            if action.is_some() {
                return action;
            }
        }
    }
}

impl<F> UplinkService<F> {
    /// Queues a reply and the station it answered with, if any (the queue
    /// had the room of a navigation step, which holds both).
    fn send<G, A, T: Transmitter>(
        &mut self,
        probe: &SharedProbe<G, A, T>,
        reply: &mwd_core::protocol::uplink::Reply,
        station: Option<StationSurvey>,
    ) {
        if !probe.with(|s| s.push_reply(reply)) {
            self.replies_dropped = self.replies_dropped.saturating_add(1);
        }
        if let Some(station) = station {
            probe.push(&Payload::Station(station));
        }
    }
}

/// The NAK reason of the navigator's refusal.
fn nak_reason(refusal: Refusal) -> NakReason {
    match refusal {
        Refusal::NotReady => NakReason::NotReady,
        Refusal::NotStill => NakReason::NotStill,
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::app::ram_flash::{RamNorFlash, RAM_FLASH_ERASE_SIZE};
    use crate::app::uplink_rx::UplinkInbox;
    use crate::app::FrameQueue;
    use mwd_core::earth::Position;
    use mwd_core::protocol::frame::{raw_flags, station_flags};
    use mwd_core::protocol::uplink::reply::decode_reply_body;
    use mwd_core::protocol::uplink::{
        encode_command, Command, IndexingProcedure, Reply, MAX_COMMAND_WIRE_LEN,
    };
    use mwd_core::protocol::{Decoder, RawPart, RawSample};
    use mwd_core::sensor_units::{
        m_s2_to_accel_count, rad_s_to_gyro_count, PART_MOUNTINGS, STANDARD_GRAVITY_M_S2,
    };
    use std::vec::Vec;

    /// A UART that sends at once everything queued.
    #[derive(Default)]
    struct Wire(Vec<u8>);

    impl Transmitter for Wire {
        fn kick(&mut self, queue: &mut FrameQueue<TX_QUEUE_LEN>) {
            while let Some(b) = queue.pop() {
                self.0.push(b);
            }
        }
        fn ready(&mut self, queue: &mut FrameQueue<TX_QUEUE_LEN>) {
            self.kick(queue);
        }
    }

    fn replies(probe: &SharedProbe<(), (), Wire>) -> Vec<Reply> {
        downlink(probe)
            .into_iter()
            .filter_map(|f| match f {
                Sent::Reply(r) => Some(r),
                Sent::Station(_) => None,
            })
            .collect()
    }

    /// What the probe sent: replies and station frames, in order.
    #[derive(Debug)]
    enum Sent {
        Reply(Reply),
        Station(StationSurvey),
    }

    fn downlink(probe: &SharedProbe<(), (), Wire>) -> Vec<Sent> {
        let wire = probe.with(|s| core::mem::take(&mut s.transmitter_mut().0));
        let mut decoder = Decoder::new();
        let mut out = Vec::new();
        for b in wire {
            if let Some(Payload::Station(s)) = decoder.push(b).map(|f| f.payload) {
                out.push(Sent::Station(s));
            }
            if let Some(Ok((_, reply))) = decoder.unknown_body().map(decode_reply_body) {
                out.push(Sent::Reply(reply));
            }
        }
        out
    }

    fn navigator() -> Navigator {
        Navigator::new(Position::paper_site())
    }

    /// A level probe's sample `n` (no earth rate), turning about the
    /// vertical at `rate` (rad/s).
    fn level(n: u32, rate: f32) -> RawSample {
        let force = [0.0, 0.0, STANDARD_GRAVITY_M_S2];
        let parts = PART_MOUNTINGS.map(|mounting| RawPart {
            accel: mounting.body_to_sensor(force).map(m_s2_to_accel_count),
            gyro_rate: rad_s_to_gyro_count(mounting.gyro_rate_from_body([0.0, 0.0, rate])),
            flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID,
            ..RawPart::default()
        });
        RawSample {
            time_us: u64::from(n) * 50_000,
            sample_counter: n,
            parts,
        }
    }

    /// A still, level probe's sample `n`.
    fn still(n: u32) -> RawSample {
        level(n, 0.0)
    }

    fn command(seq: u16, command: &Command) -> Vec<u8> {
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq, command, &mut wire).unwrap();
        wire[..n].to_vec()
    }

    #[test]
    fn a_setting_is_stored_acknowledged_and_loaded_after_a_reset() {
        let mut memory = [0u8; 2 * RAM_FLASH_ERASE_SIZE];
        let mut inbox = UplinkInbox::new();
        let (mut writer, mut reader) = inbox.split();
        let probe = SharedProbe::<(), (), Wire>::new(Wire::default());
        let mut service = UplinkService::load(RamNorFlash::new(&mut memory), 0);
        assert_eq!(service.source(), ConfigSource::Defaults);

        let site = Position::new(0.5, 1.0, 300.0);
        let mut bytes = command(7, &Command::SetSite(site));
        bytes.extend([0x13, 0x37, 0x00]); // garbage between commands
        bytes.extend(command(8, &Command::ReportConfig));
        bytes.extend(command(9, &Command::TakeStation));
        bytes.extend(command(10, &Command::Reboot));
        bytes.iter().for_each(|b| writer.push(*b));
        assert_eq!(
            service.serve(&probe, &mut navigator(), &mut reader, 1024),
            Some(BoardAction::Reboot)
        );
        let got: Vec<(u16, ReplyStatus, u32)> = replies(&probe)
            .iter()
            .map(|r| (r.command_seq, r.status, r.config_version))
            .collect();
        // A station before the probe has even levelled itself.
        let nak = ReplyStatus::Nak(NakReason::NotReady);
        assert_eq!(
            got,
            [
                (7, ReplyStatus::Ack, 1),
                (8, ReplyStatus::Ack, 1),
                (9, nak, 1),
                (10, ReplyStatus::Ack, 1)
            ]
        );
        assert_eq!(service.stats().malformed, 1);
        // A reset: the first service is done with the memory.

        let service = UplinkService::load(RamNorFlash::new(&mut memory), 0);
        assert_eq!(service.source(), ConfigSource::Flash);
        assert_eq!((service.config().version, service.config().site), (1, site));
    }

    #[test]
    fn bytes_are_taken_no_faster_than_the_budget() {
        let mut memory = [0u8; 2 * RAM_FLASH_ERASE_SIZE];
        let mut inbox = UplinkInbox::new();
        let (mut writer, mut reader) = inbox.split();
        let probe = SharedProbe::<(), (), Wire>::new(Wire::default());
        let mut service = UplinkService::load(RamNorFlash::new(&mut memory), 0);
        (0..300).for_each(|i| writer.push(i as u8 | 1));
        assert_eq!(
            service.serve(&probe, &mut navigator(), &mut reader, 100),
            None
        );
        assert_eq!((service.stats().bytes, reader.pending()), (100, 200));
    }

    /// The survey commands through the service: refused with the
    /// navigator's reason, acknowledged when they took effect, and a
    /// requested station right after its ACK.
    #[test]
    fn survey_commands_are_answered_by_what_the_navigator_did() {
        let mut memory = [0u8; 2 * RAM_FLASH_ERASE_SIZE];
        let mut inbox = UplinkInbox::new();
        let (mut writer, mut reader) = inbox.split();
        let probe = SharedProbe::<(), (), Wire>::new(Wire::default());
        let mut service = UplinkService::load(RamNorFlash::new(&mut memory), 0);
        let mut navigator = navigator();
        let mut send = |seq, c: &Command, navigator: &mut Navigator| {
            command(seq, c).iter().for_each(|b| writer.push(*b));
            assert_eq!(service.serve(&probe, navigator, &mut reader, 1024), None);
            downlink(&probe)
        };
        let status = |sent: &[Sent]| match sent {
            [Sent::Reply(r)] => r.status,
            other => panic!("{other:?}"),
        };
        let nak = |reason| ReplyStatus::Nak(reason);
        let indexing = Command::IndexToolface(IndexingProcedure {
            positions: 4,
            dwell_s: 10,
        });
        for (seq, c) in [(1, Command::StartSurveying), (2, indexing)] {
            let sent = send(seq, &c, &mut navigator);
            assert_eq!(status(&sent), nak(NakReason::NotReady));
        }
        // Into the fine alignment, long enough to end it.
        let mut n = 0;
        while !navigator.is_aligned() || n < 200 {
            navigator.step(&still(n));
            n += 1;
        }
        let sent = send(3, &Command::StartSurveying, &mut navigator);
        assert_eq!(status(&sent), ReplyStatus::Ack);
        assert!(navigator.is_navigating());
        // Navigating and still from its first cycle (the still detector
        // ran through the fine alignment); then turning: not still.
        navigator.step(&still(n));
        navigator.step(&level(n + 1, 0.05));
        n += 2;
        let sent = send(4, &Command::TakeStation, &mut navigator);
        assert_eq!(status(&sent), nak(NakReason::NotStill));
        for _ in 0..100 {
            navigator.step(&still(n));
            n += 1;
        }
        let sent = send(5, &Command::TakeStation, &mut navigator);
        match sent.as_slice() {
            [Sent::Reply(r), Sent::Station(s)] => {
                assert_eq!((r.command_seq, r.status), (5, ReplyStatus::Ack));
                // (station 1: the one still cycle before the turn, not
                // taken from the navigator here: not this still period's)
                assert_eq!(s.station, 2);
                assert_ne!(s.flags & station_flags::REQUESTED, 0, "{s:?}");
            }
            other => panic!("{other:?}"),
        }
        let sent = send(6, &indexing, &mut navigator);
        assert_eq!(status(&sent), ReplyStatus::Ack);
        assert!(navigator.indexing().is_some());
    }
}
