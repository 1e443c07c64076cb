use super::*;
use crate::protocol::example::boot_event;
use crate::protocol::frame::{Event, EventKind, Payload, NO_PART};
use crate::protocol::wire::{FrameEncoder, MAX_WIRE_LEN};

extern crate std;
use std::vec::Vec;

fn event(n: u32) -> Payload {
    Payload::Event(Event {
        time_us: u64::from(n) * 50_000,
        kind: EventKind::SensorFault,
        part: NO_PART,
        code: 3,
        value: n,
    })
}

fn encode_all(enc: &mut FrameEncoder, count: u32, out: &mut [u8]) -> usize {
    let mut n = 0;
    for i in 0..count {
        n += enc.encode(&event(i), &mut out[n..]).unwrap();
    }
    n
}

#[test]
fn decodes_back_to_back_frames_in_any_chunking() {
    let mut stream = [0u8; 8 * MAX_WIRE_LEN];
    let n = encode_all(&mut FrameEncoder::new(), 8, &mut stream);
    for chunk in [1, 3, 7, 64, n] {
        let mut dec = Decoder::new();
        let mut seen = 0u32;
        for piece in stream[..n].chunks(chunk) {
            dec.feed(piece, |f| {
                assert_eq!(f.payload, event(seen));
                seen += 1;
            });
        }
        assert_eq!(seen, 8);
        assert_eq!(dec.stats().frames, [0, 0, 8, 0]);
        assert_eq!(dec.stats().corrupt(), 0);
        assert_eq!(dec.stats().lost, 0);
    }
}

#[test]
fn resynchronises_after_garbage_and_truncation() {
    let mut stream = [0u8; 8 * MAX_WIRE_LEN];
    let n = encode_all(&mut FrameEncoder::new(), 3, &mut stream);
    let mut dec = Decoder::new();
    let mut got = 0;
    // Garbage first (no delimiter), then a frame cut after 10 bytes.
    dec.feed(&[0x55; 300], |_| got += 1);
    dec.feed(&stream[1..11], |_| got += 1);
    dec.feed(&stream[..n], |_| got += 1);
    assert_eq!(got, 3);
    let s = dec.stats();
    assert_eq!(
        s.malformed + s.crc_errors,
        1,
        "one chunk: garbage + cut frame"
    );
    assert_eq!(s.garbage_bytes, 310);
}

#[test]
fn counts_sequence_gaps_and_restarts() {
    let mut buf = [0u8; MAX_WIRE_LEN];
    let mut dec = Decoder::new();
    for seq in [10u16, 11, 14, 15, 2, 3] {
        let n = crate::protocol::wire::encode_frame(seq, &event(0), &mut buf).unwrap();
        dec.feed(&buf[..n], |_| {});
    }
    assert_eq!(dec.stats().lost, 2);
    assert_eq!(dec.stats().sequence_restarts, 1);
    assert_eq!(dec.stats().good_frames(), 6);
}

fn raw(counter: u32) -> Payload {
    Payload::Raw(crate::protocol::frame::RawSample {
        sample_counter: counter,
        time_us: crate::timing::sample_time_us(counter),
        ..Default::default()
    })
}

/// Decodes frames given as (sequence number, payload).
fn stats_of(frames: impl IntoIterator<Item = (u16, Payload)>) -> DecoderStats {
    let mut buf = [0u8; MAX_WIRE_LEN];
    let mut dec = Decoder::new();
    for (seq, payload) in frames {
        let n = crate::protocol::wire::encode_frame(seq, &payload, &mut buf).unwrap();
        dec.feed(&buf[..n], |_| {});
    }
    *dec.stats()
}

/// A probe run: its boot event, then `samples` raw and navigation
/// frames (the navigation ones stand in as events here), from `from`.
fn run(samples: u32) -> impl Iterator<Item = (u16, Payload)> {
    core::iter::once((0, boot_event())).chain((0..samples).flat_map(|n| {
        let seq = (1 + 2 * n) as u16;
        [(seq, raw(n)), (seq.wrapping_add(1), event(n))]
    }))
}

#[test]
fn a_reboot_after_a_long_run_is_a_restart_not_a_loss() {
    // 18000 samples (15 min, 36001 frames) twice, as `cat a.bin a.bin`.
    let stats = stats_of(run(18_000).chain(run(18_000)));
    assert_eq!((stats.lost, stats.sequence_restarts), (0, 1), "{stats:?}");
}

#[test]
fn a_reboot_whose_boot_event_was_lost_is_found_by_the_sample_counter() {
    let stats = stats_of(run(18_000).chain(run(100).skip(1)));
    assert_eq!(stats.sequence_restarts, 1, "{stats:?}");
    assert_eq!(stats.lost, 0, "{stats:?}");
}

#[test]
fn an_outage_longer_than_the_sequence_is_counted_from_the_sample_counter() {
    // 40000 samples (80000 frames, more than the 16-bit sequence) lost
    // after sample 100, then 5 % more lost in small gaps.
    let frames = run(50_000).filter(|(_, p)| match p {
        Payload::Raw(r) => !(101..40_101).contains(&r.sample_counter),
        Payload::Event(e) if e.kind != EventKind::Boot => !(101..40_101).contains(&e.value),
        _ => true,
    });
    let stats = stats_of(frames);
    assert_eq!(
        (stats.lost, stats.sequence_restarts),
        (80_000, 0),
        "{stats:?}"
    );
    // Small gaps stay exact without any raw frame to check them.
    let stats = stats_of(run(100).filter(|(seq, _)| seq % 20 != 7));
    assert_eq!((stats.lost, stats.sequence_restarts), (10, 0), "{stats:?}");
}

/// A kind this decoder does not know (a newer probe's) is skipped, not
/// counted as corrupt, and its sequence number keeps the loss count
/// exact: the rule that lets a version-1 decoder that predates kind 4
/// (station survey) read a capture that holds them.
#[test]
fn an_unknown_kind_is_skipped_and_its_sequence_number_counted() {
    use crate::protocol::crc::crc32c;
    let mut buf = [0u8; MAX_WIRE_LEN];
    let mut dec = Decoder::new();
    let mut seen = 0;
    for seq in 0..3u16 {
        let mut body = [0u8; MAX_BODY_LEN];
        let n = crate::protocol::codec::encode_body(seq, &event(0), &mut body).unwrap();
        if seq == 1 {
            body[1] = 0x77;
            let crc = crc32c(&body[..n - 4]).to_le_bytes();
            body[n - 4..n].copy_from_slice(&crc);
        }
        buf[0] = 0;
        let len = cobs::try_encode(&body[..n], &mut buf[1..]).unwrap();
        buf[len + 1] = 0;
        dec.feed(&buf[..len + 2], |_| seen += 1);
    }
    let s = dec.stats();
    assert_eq!((seen, s.unknown_kind, s.lost, s.corrupt()), (2, 1, 0, 0));
}

#[test]
fn a_station_survey_decodes_and_is_counted() {
    let mut buf = [0u8; MAX_WIRE_LEN];
    let station = crate::protocol::example::station_survey();
    let n = crate::protocol::wire::encode_frame(5, &station, &mut buf).unwrap();
    let mut dec = Decoder::new();
    let mut got = None;
    dec.feed(&buf[..n], |f| got = Some(f.payload));
    assert_eq!(got, Some(station));
    assert_eq!(dec.stats().frames, [0, 0, 0, 1]);
}

#[test]
fn open_chunk_at_end_counts_as_garbage() {
    let mut dec = Decoder::new();
    dec.feed(&[1, 2, 3], |_| {});
    dec.finish();
    assert_eq!(dec.stats().garbage_bytes, 3);
    assert_eq!(dec.stats().malformed, 1);
}

fn nav(counter: u32) -> Payload {
    Payload::Nav(crate::protocol::frame::NavSolution {
        sample_counter: counter,
        time_us: crate::timing::sample_time_us(counter),
        ..Default::default()
    })
}

/// Frame `index` of a probe run as the probe numbers it: the boot event
/// at 0, then per sample a raw frame and a navigation frame (or, with
/// `events`, an event standing in for it: the raw frames alone carry a
/// sample counter).
fn run_frame(index: u64, events: bool) -> (u16, Payload) {
    let seq = index as u16;
    if index == 0 {
        return (seq, boot_event());
    }
    let sample = ((index - 1) / 2) as u32;
    let payload = match (index % 2 == 1, events) {
        (true, _) => raw(sample),
        (false, false) => nav(sample),
        (false, true) => event(sample),
    };
    (seq, payload)
}

/// A run's frames `kept` (by index), in that order.
fn run_frames(
    kept: impl IntoIterator<Item = u64>,
    events: bool,
) -> impl Iterator<Item = (u16, Payload)> {
    kept.into_iter().map(move |i| run_frame(i, events))
}

/// Decodes frames given as (sequence number, payload); what it handed on
/// (numbers) and its counts.
fn decoded(frames: impl IntoIterator<Item = (u16, Payload)>) -> (Vec<u16>, DecoderStats) {
    let mut buf = [0u8; MAX_WIRE_LEN];
    let mut dec = Decoder::new();
    let mut seqs = Vec::new();
    for (seq, payload) in frames {
        let n = crate::protocol::wire::encode_frame(seq, &payload, &mut buf).unwrap();
        dec.feed(&buf[..n], |f| seqs.push(f.seq));
    }
    (seqs, *dec.stats())
}

/// Frames handed on, and [lost, reordered, duplicated, restarts], of a
/// run's frames received in `order` (by index).
fn counted(order: impl IntoIterator<Item = u64>) -> (usize, [u64; 4]) {
    let (seqs, s) = decoded(run_frames(order, false));
    let counts = [s.lost, s.reordered, s.duplicated, s.sequence_restarts];
    (seqs.len(), counts)
}

#[test]
fn outages_of_65536_k_plus_m_frames_are_counted_in_full() {
    for k in 0..=3u64 {
        for m in [
            0, 1, 2, 63, 64, 65, 1_000, 32_767, 32_768, 32_769, 50_000, 65_535,
        ] {
            let outage = 0x1_0000 * k + m;
            if outage == 0 {
                continue;
            }
            // from a raw frame or a navigation frame on, with navigation
            // frames or events beside the raw frames
            for first_lost in [1_001, 1_002] {
                for events in [false, true] {
                    let resume = first_lost + outage;
                    let kept = (0..first_lost).chain(resume..resume + 1_000);
                    let (_, stats) = decoded(run_frames(kept, events));
                    assert_eq!(
                        (stats.lost, stats.sequence_restarts, stats.reordered),
                        (outage, 0, 0),
                        "k {k} m {m} from {first_lost} events {events}: {stats:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn counters_that_jump_with_no_gap_and_times_that_disagree_are_no_outage() {
    // Sample counters 40000 apart on consecutive frames say the sequence
    // wrapped, but their time stamps do not: believed neither (a probe
    // never does it; random payloads do).
    let mut jumped = raw(50_000);
    if let Payload::Raw(r) = &mut jumped {
        r.time_us = crate::timing::sample_time_us(10_001);
    }
    let frames = run_frames(0..20_002, false).chain([(20_002, jumped)]);
    let (_, stats) = decoded(frames);
    assert_eq!((stats.lost, stats.sequence_restarts), (0, 0), "{stats:?}");
}

#[test]
fn an_outage_across_the_wrap_between_navigation_frames_is_counted() {
    // The sequence wraps at frame 65536; the outage runs from a navigation
    // frame's successor to the one before a navigation frame, and the raw
    // frames around it were lost too: only navigation frames border it.
    for outage in [
        10,
        64,
        1_000,
        40_000,
        0x1_0000,
        0x1_0000 + 7,
        0x2_0000 + 100,
    ] {
        let first_lost = 65_500u64; // even: frame 65499 before it is a raw frame
        let resume = first_lost + outage + (outage % 2); // a navigation frame (even)
        let lost_around: Vec<u64> = (first_lost - 20..first_lost)
            .chain(resume..resume + 20)
            .filter(|i| i % 2 == 1)
            .collect();
        let kept = (0..first_lost - 20)
            .chain((first_lost - 20..first_lost).filter(|i| i % 2 == 0))
            .chain((resume..resume + 20).filter(|i| i % 2 == 0))
            .chain(resume + 20..resume + 200);
        let (_, stats) = decoded(run_frames(kept, false));
        let expected = (resume - first_lost) + lost_around.len() as u64;
        assert_eq!(
            (stats.lost, stats.sequence_restarts),
            (expected, 0),
            "outage {outage}: {stats:?}"
        );
    }
}

#[test]
fn frames_lost_before_the_first_or_after_the_last_received_are_not_counted() {
    // The capture starts mid-run (no boot event) or stops before the run
    // ends: nothing says what was sent outside it.
    let (_, stats) = decoded(run_frames(70_000..71_000, false));
    assert_eq!((stats.lost, stats.sequence_restarts), (0, 0), "{stats:?}");
    let (_, stats) = decoded(run_frames(0..1_000, false));
    assert_eq!((stats.lost, stats.sequence_restarts), (0, 0), "{stats:?}");
    // After the boot event the run's first frames are known to be missing.
    let (_, stats) = decoded(run_frames((0..1).chain(101..1_000), false));
    assert_eq!((stats.lost, stats.sequence_restarts), (100, 0), "{stats:?}");
}

#[test]
fn a_frame_received_again_is_a_duplicate_dropped_not_a_restart() {
    // frame 10 again at once, frame 20 after two more
    let order = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 10, 11, 12, 13, 14, 15, 16]
        .into_iter()
        .chain([17, 18, 19, 20, 21, 22, 20, 23, 24, 25]);
    let (seqs, stats) = decoded(run_frames(order, false));
    assert_eq!(seqs, (0..=25).collect::<Vec<u16>>(), "handed on once each");
    assert_eq!(
        (stats.duplicated, stats.lost, stats.sequence_restarts),
        (2, 0, 0),
        "{stats:?}"
    );
    assert_eq!(
        stats.good_frames(),
        26,
        "duplicates are not counted as frames"
    );
    // A boot event again soon after is a probe that booted again (the
    // same bytes): a restart, handed on, never a duplicate.
    let order = [0, 1, 2, 0, 1, 2].into_iter();
    let (seqs, stats) = decoded(run_frames(order, false));
    assert_eq!(seqs, [0, 1, 2, 0, 1, 2]);
    assert_eq!(
        (stats.duplicated, stats.sequence_restarts),
        (0, 1),
        "{stats:?}"
    );
    // The same number just received with other bytes is not a duplicate:
    // the sequence went backwards, as before.
    let frames = run_frames(0..12, true).chain([(10, event(99))]);
    let (seqs, stats) = decoded(frames);
    assert_eq!(seqs.len(), 13);
    assert_eq!(
        (stats.duplicated, stats.sequence_restarts),
        (0, 1),
        "{stats:?}"
    );
}

#[test]
fn a_frame_that_comes_late_is_reordered_not_lost() {
    // 10 and 11 swapped; 20 seven frames late (the furthest the window
    // holds); 40 eight frames late: taken as the sequence going backwards
    let order = (0..10)
        .chain([11, 10])
        .chain(12..20)
        .chain(21..28)
        .chain([20])
        .chain(28..40)
        .chain(41..49)
        .chain([40])
        .chain(49..60);
    let (seqs, stats) = decoded(run_frames(order, false));
    assert_eq!(seqs.len(), 60, "every frame handed on: {seqs:?}");
    assert_eq!(&seqs[10..12], &[11, 10]);
    assert_eq!(stats.reordered, 2, "{stats:?}");
    assert_eq!(stats.duplicated, 0, "{stats:?}");
    // the frame beyond the window: a raw frame whose counter went back
    assert_eq!(stats.sequence_restarts, 1, "{stats:?}");
    assert_eq!(stats.good_frames(), 60);

    // Within the window and nothing else: no loss, no restart.
    let order = (0..10)
        .chain([11, 10])
        .chain(12..20)
        .chain(21..28)
        .chain([20])
        .chain(28..40);
    assert_eq!(counted(order), (40, [0, 2, 0, 0]));
    // A late frame received twice: reordered once, then a duplicate.
    let order = (0..10).chain([11, 12, 10, 10]).chain(13..20);
    assert_eq!(counted(order), (20, [0, 1, 1, 0]));
}

#[test]
fn a_late_frame_after_a_long_outage_takes_its_loss_back() {
    // 100 frames lost from frame 1001, but frame 1095 came after 1101 and
    // 1102: 99 lost, counted by the sample counters across the outage.
    let order = (0..1_001).chain([1_101, 1_102, 1_095]).chain(1_103..1_500);
    assert_eq!(counted(order), (1_401, [99, 1, 0, 0]));
    // and late across the wrap of the sequence (65535 after 0 and 1)
    let order = (0..65_535)
        .chain([65_536, 65_537, 65_535])
        .chain(65_538..65_600);
    assert_eq!(counted(order), (65_600, [0, 1, 0, 0]));
}

#[test]
fn the_decoder_stays_small() {
    // The probe holds one: its state beyond the chunk buffer stays within
    // a few dozen bytes of what it was (on the host 164 bytes before
    // duplicates and late frames were told apart; the window adds 36, the
    // two counts 16, the anchor's time stamp 16 with its padding).
    let state = core::mem::size_of::<Decoder>() - MAX_CHUNK_LEN;
    assert!(state <= 232, "{state} bytes");
}
