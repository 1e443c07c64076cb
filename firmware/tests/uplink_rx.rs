//! The uplink receiver cannot be hurt: 100,000 seeded random byte strings
//! (pure garbage, and commands with random kinds, lengths and fields under
//! a good CRC) go through the interrupt's inbox and the main loop's
//! receiver and `apply`; none panics, a valid command after each is still
//! accepted, and every chunk lands in exactly one counter.

use firmware::app::uplink_rx::{
    apply, Action, Decoded, UplinkInbox, UplinkReceiver, MAX_CHUNK_LEN, UPLINK_QUEUE_LEN,
};
use mwd_core::config::ProbeConfig;
use mwd_core::earth::Position;
use mwd_core::protocol::crc::crc32c;
use mwd_core::protocol::uplink::{
    encode_command, Command, CommandKind, Field, NakReason, Received, ReplyStatus,
    MAX_COMMAND_WIRE_LEN,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn wire(seq: u16, command: &Command) -> Vec<u8> {
    let mut out = [0u8; MAX_COMMAND_WIRE_LEN];
    let n = encode_command(seq, command, &mut out).unwrap();
    out[..n].to_vec()
}

/// Non-empty runs between zeros: the chunks a receiver must count.
fn chunks_in(bytes: &[u8]) -> u64 {
    bytes.split(|b| *b == 0).filter(|c| !c.is_empty()).count() as u64
}

/// A random string: garbage with some zeros, or a body with a good CRC
/// and random kind, length and bytes, COBS-framed (the deeper paths).
fn random_string(rng: &mut ChaCha8Rng) -> Vec<u8> {
    if rng.random_bool(0.5) {
        let len = rng.random_range(0..300);
        (0..len)
            .map(|_| {
                if rng.random_bool(0.05) {
                    0
                } else {
                    rng.random()
                }
            })
            .collect()
    } else {
        let kind = rng.random_range(0x3E..0x4D);
        // Mostly the kind's own length, so its fields are read.
        let len = match CommandKind::from_byte(kind) {
            Some(k) if rng.random_bool(0.7) => k.body_len(),
            _ => rng.random_range(0..130),
        };
        let mut body: Vec<u8> = (0..len).map(|_| rng.random()).collect();
        if len >= 2 {
            body[0] = if rng.random_bool(0.9) {
                1
            } else {
                rng.random()
            };
            body[1] = kind;
        }
        if len >= 8 && rng.random_bool(0.9) {
            let crc = crc32c(&body[..len - 4]).to_le_bytes();
            body[len - 4..].copy_from_slice(&crc);
        }
        let mut out = vec![0u8; len + len / 254 + 3];
        let n = cobs::try_encode(&body, &mut out[1..]).unwrap();
        out.truncate(n + 2);
        out[n + 1] = 0;
        out
    }
}

#[test]
fn a_hundred_thousand_random_strings_neither_crash_nor_wedge_it() {
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let mut inbox = UplinkInbox::new();
    let (mut isr, mut main_loop) = inbox.split();
    let mut rx = UplinkReceiver::new();
    let mut config = ProbeConfig::default();
    let mut expected_chunks = 0u64;
    let (mut answered, mut oversized_strings) = (0u32, 0u32);
    for i in 0..100_000u32 {
        let garbage = random_string(&mut rng);
        let seq = i as u16;
        let probe = wire(seq, &Command::ReportConfig);
        // The garbage is closed by a delimiter before the valid command.
        let mut stream = garbage.clone();
        stream.push(0);
        stream.extend_from_slice(&probe);
        expected_chunks += chunks_in(&stream);
        oversized_strings += u32::from(garbage.split(|b| *b == 0).any(|c| c.len() > MAX_CHUNK_LEN));
        for b in &stream {
            isr.push(*b);
        }
        let mut last: Option<Decoded> = None;
        // Main-loop cycles of at most 64 bytes each until all is read.
        while main_loop.pending() > 0 {
            let Some(decoded) = rx.poll(&mut main_loop, 64) else {
                continue;
            };
            let version = config.version;
            let outcome = apply(&decoded, &mut config, 0, true, |_| Ok::<(), ()>(()));
            assert!(outcome.is_some(), "everything returned is answered");
            assert!(config.version >= version);
            answered += 1;
            last = Some(decoded);
        }
        let expected = Received {
            seq,
            command: Command::ReportConfig,
        };
        assert_eq!(last, Some(Ok(expected)), "string {i} wedged the receiver");
    }
    let s = *rx.stats();
    assert_eq!(s.chunks(), expected_chunks, "{s:?}");
    assert_eq!(s.overflowed_bytes, 0);
    assert!(s.frames_ok >= 100_000 && answered >= 100_000);
    // Each path was taken many times (the random kinds and lengths).
    for (name, count) in [
        ("crc", s.crc_failures),
        ("malformed", s.malformed),
        ("unknown", s.unknown),
        ("out of range", s.out_of_range),
    ] {
        assert!(count > 1_000, "{name}: {s:?}");
    }
    assert_eq!(s.oversized, oversized_strings);
    println!("100000 strings: {s:?}");
}

#[test]
fn a_full_inbox_drops_and_counts_bytes_and_recovers() {
    let mut inbox = UplinkInbox::new();
    let (mut isr, mut main_loop) = inbox.split();
    let mut rx = UplinkReceiver::new();
    for _ in 0..3_000 {
        isr.push(0x55);
    }
    assert_eq!(rx.poll(&mut main_loop, 10_000), None);
    assert_eq!(
        rx.stats().overflowed_bytes,
        3_000 - (UPLINK_QUEUE_LEN as u32 - 1)
    );
    for b in wire(9, &Command::Reboot) {
        isr.push(b);
    }
    let got = rx.poll(&mut main_loop, 10_000);
    assert_eq!(
        got,
        Some(Ok(Received {
            seq: 9,
            command: Command::Reboot
        }))
    );
    // The 1023 bytes of 0x55 were one oversized chunk.
    assert_eq!((rx.stats().oversized, rx.stats().chunks()), (1, 2));
}

#[test]
fn the_main_loop_takes_no_more_bytes_than_it_allows() {
    let mut inbox = UplinkInbox::new();
    let (mut isr, mut main_loop) = inbox.split();
    let mut rx = UplinkReceiver::new();
    for _ in 0..500 {
        isr.push(0x11);
    }
    rx.poll(&mut main_loop, 64);
    assert_eq!(rx.stats().bytes, 64);
}

fn decoded(seq: u16, command: Command) -> Decoded {
    Ok(Received { seq, command })
}

#[test]
fn apply_acks_stores_refuses_and_requests() {
    let mut config = ProbeConfig::default();
    let site = Command::SetSite(Position::from_degrees(10.0, 20.0, 30.0));
    let mut stored = Vec::new();
    let ack = apply(&decoded(1, site), &mut config, 5, true, |c| {
        stored.push(*c);
        Ok::<(), ()>(())
    })
    .unwrap();
    assert_eq!(ack.reply.status, ReplyStatus::Ack);
    assert_eq!((ack.reply.command_seq, ack.reply.config_version), (1, 1));
    assert_eq!((stored.len(), stored[0]), (1, config));
    // Surveying: settings are refused, actions are not.
    let busy = apply(&decoded(2, site), &mut config, 5, false, |_| {
        Ok::<(), ()>(())
    })
    .unwrap();
    assert_eq!(busy.reply.status, ReplyStatus::Nak(NakReason::Busy));
    let station = apply(
        &decoded(3, Command::TakeStation),
        &mut config,
        5,
        false,
        |_| Err(()),
    )
    .unwrap();
    assert_eq!(
        (station.reply.status, station.action),
        (ReplyStatus::Ack, Some(Action::TakeStation))
    );
    // A failed store keeps the previous configuration.
    let other = Command::SetSite(Position::from_degrees(11.0, 20.0, 30.0));
    let before = config;
    let failed = apply(&decoded(4, other), &mut config, 5, true, |_| Err(())).unwrap();
    assert_eq!(
        failed.reply.status,
        ReplyStatus::Nak(NakReason::StorageFailed)
    );
    assert_eq!((config, failed.reply.config_version), (before, 1));
    // The navigator's tie-in limits: near vertical is out of range.
    let near_vertical = Command::SetTieIn {
        angles: mwd_core::conventions::DrillingAngles {
            inclination: 0.001,
            azimuth: 1.0,
            toolface: 1.0,
        },
        sigma: mwd_core::conventions::DrillingAngles {
            inclination: 0.001,
            azimuth: 0.01,
            toolface: 0.001,
        },
    };
    let nak = apply(&decoded(5, near_vertical), &mut config, 5, true, |_| {
        Ok::<(), ()>(())
    })
    .unwrap();
    assert_eq!(
        (nak.reply.status, nak.reply.detail),
        (
            ReplyStatus::Nak(NakReason::OutOfRange),
            Field::Inclination as u8
        )
    );
}
