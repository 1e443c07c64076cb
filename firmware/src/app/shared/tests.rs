//! The shared glue on the host: hil-mock parts, a UART that takes one byte
//! per interrupt, and the probe's own navigator, as a board runs them.

extern crate std;

use super::*;
use crate::app::sensor_wire::fault_code;
use crate::app::test_support::{
    assert_navigated_in_order, drain, events_of, sent_frames, take_wire, TestUart,
};
use crate::scc1300::Part;
use hil_mock::{
    AccelSpi, Constant, GyroSpi, Scc1300, SimClock, SimDelay, TimeSource, Window, SAMPLE_PERIOD_NS,
};
use mwd_core::earth::Position;
use mwd_core::protocol::{Decoder, Frame};
use std::vec::Vec;

#[test]
fn boot_streaming_recovery_and_navigation_reach_the_uart_in_order() {
    let clock = SimClock::new();
    let mocks = [0, 1].map(|i| RefCell::new(Scc1300::new(&clock, Constant::default(), i)));
    let parts = [0, 1].map(|i| Part::new(GyroSpi::new(&mocks[i]), AccelSpi::new(&mocks[i])));
    let mut delay = SimDelay::new(&clock);
    let probe = SharedProbe::new(TestUart::default());
    probe.announce_boot();
    assert_eq!(
        probe.start_streaming(parts, &mut delay, &mut || {}),
        [None, None]
    );

    let mut navigator = Navigator::new(Position::paper_site());
    let mut resets = Vec::new();
    let mut solutions = 0;
    for n in 0..12 {
        if n == 4 {
            // Part 1's gyro loses S_OK for 100 ms: the next sample asks for
            // recovery, which the main loop runs (a transient).
            let now = clock.now_ns();
            mocks[1].borrow_mut().faults.s_ok_drop = Some(Window {
                start_ns: now,
                end_ns: now + 100_000_000,
            });
        }
        clock.advance_ns(SAMPLE_PERIOD_NS);
        probe.with(|shared| shared.acquire());
        probe.main_loop_pass(
            &mut delay,
            &mut navigator,
            &mut || {},
            |part, code| resets.push((part, code)),
            |_| solutions += 1,
        );
        drain(&probe);
    }
    assert_eq!(resets, [(1, 0)]);
    assert_eq!(solutions, 12);

    let frames = sent_frames(&probe);
    let events = events_of(&frames);
    let kinds: Vec<(EventKind, u8, u16)> =
        events.iter().map(|e| (e.kind, e.part, e.code)).collect();
    assert_eq!(
        kinds,
        [
            (EventKind::Boot, NO_PART, FIRMWARE_VERSION),
            (EventKind::SensorFault, 1, fault_code(&Error::NotReady)),
            (EventKind::SensorReset, 1, 0),
            (EventKind::Resync, NO_PART, 0),
        ]
    );

    assert_navigated_in_order(&frames, 12);
}

/// A still probe (the mock's constant level sample) past its alignment: it
/// navigates, finds itself still, and at the longest station sends one
/// station survey right after that cycle's navigation frame; a fresh
/// navigator on the raw frames finishes the same station, bit for bit.
#[test]
fn a_station_survey_follows_its_navigation_frame_and_replays_identically() {
    use mwd_core::probe::navigator::{MAX_STATION_SAMPLES, SURVEY_SETTLE_EPOCHS};
    use mwd_core::probe::still::DETECTION_DELAY_SAMPLES;
    use mwd_core::protocol::frame::MAX_BODY_LEN;
    use mwd_core::protocol::{encode_body, StationSurvey};
    use mwd_core::timing::{ALIGNMENT_SAMPLES, FINE_ALIGNMENT_SAMPLES};

    use hil_mock::{MountedSource, StillProbe};
    use mwd_core::sensor_units::PART_MOUNTINGS;

    // The QEMU board's mock: a still probe with the budget's white noise
    // and biases, each part its own noise stream.
    let clock = SimClock::new();
    let mocks = [0, 1].map(|i| {
        let source = MountedSource {
            body: StillProbe::paper_test(1 + i as u64),
            mounting: PART_MOUNTINGS[i],
        };
        RefCell::new(Scc1300::new(&clock, source, 1 + i as u32))
    });
    let parts = [0, 1].map(|i| Part::new(GyroSpi::new(&mocks[i]), AccelSpi::new(&mocks[i])));
    let mut delay = SimDelay::new(&clock);
    let probe = SharedProbe::new(TestUart::default());
    probe.announce_boot();
    probe.start_streaming(parts, &mut delay, &mut || {});
    let mut navigator = Navigator::new(Position::paper_site());
    let samples = ALIGNMENT_SAMPLES
        + FINE_ALIGNMENT_SAMPLES
        + DETECTION_DELAY_SAMPLES
        + MAX_STATION_SAMPLES
        + 10;
    let mut frames: Vec<Frame> = Vec::new();
    let mut decoder = Decoder::new();
    for _ in 0..samples {
        clock.advance_ns(SAMPLE_PERIOD_NS);
        probe.with(|shared| shared.acquire());
        probe.main_loop_pass(&mut delay, &mut navigator, &mut || {}, |_, _| {}, |_| {});
        drain(&probe);
        let wire = take_wire(&probe);
        decoder.feed(&wire, |f| frames.push(f));
    }
    assert_eq!((decoder.stats().corrupt(), decoder.stats().lost), (0, 0));
    assert_eq!(decoder.stats().frames[3], 1, "{:?}", decoder.stats());
    let at = frames
        .iter()
        .position(|f| matches!(f.payload, Payload::Station(_)))
        .unwrap();
    let (Payload::Nav(nav), Payload::Station(station)) =
        (frames[at - 1].payload, frames[at].payload)
    else {
        panic!(
            "the station follows a navigation frame: {:?}",
            &frames[at - 2..=at]
        );
    };
    // The station is sent right after the cycle that finished it; its
    // survey is the settled one, 40 to 80 still cycles before that cycle
    // (`SURVEY_SETTLE_EPOCHS`), or that cycle's for a shorter station.
    let before = nav.sample_counter - station.end_sample;
    assert!(
        (SURVEY_SETTLE_EPOCHS..=2 * SURVEY_SETTLE_EPOCHS).contains(&before),
        "survey {before} cycles before the frame it follows"
    );
    assert_eq!(station.station, 1);

    let body = |s: &StationSurvey| {
        let mut buf = [0u8; MAX_BODY_LEN];
        let n = encode_body(0, &Payload::Station(*s), &mut buf).unwrap();
        buf[..n].to_vec()
    };
    let mut replay = Navigator::new(Position::paper_site());
    let mut replayed = Vec::new();
    for f in &frames {
        if let Payload::Raw(raw) = f.payload {
            replay.step(&raw);
            replayed.extend(replay.take_station());
        }
    }
    assert_eq!(replayed.len(), 1);
    assert_eq!(body(&replayed[0]), body(&station));
}
