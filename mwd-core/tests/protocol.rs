//! Wire protocol properties: round trips of every frame kind, a byte-soup
//! decoder that never panics, exact loss accounting under random
//! corruption, the bandwidth budget, and the document's worked example.

use mwd_core::protocol::frame::{MAX_BODY_LEN, NO_PART};
use mwd_core::protocol::{
    cyclic_bytes_per_s, decode_body, encode_body, encode_frame, example, wire_len, Decoder, Event,
    EventKind, Frame, FrameEncoder, FrameKind, NavSolution, Payload, RawPart, RawSample,
    StationSurvey, MAX_WIRE_LEN, UART_BYTES_PER_S,
};
use proptest::prelude::*;

fn f32_bits() -> impl Strategy<Value = f32> {
    any::<u32>().prop_map(f32::from_bits)
}

fn f32x3() -> impl Strategy<Value = [f32; 3]> {
    [f32_bits(), f32_bits(), f32_bits()]
}

fn raw_part() -> impl Strategy<Value = RawPart> {
    (any::<[i16; 6]>(), any::<u16>()).prop_map(|(v, flags)| RawPart {
        gyro_rate: v[0],
        gyro_temp: v[1],
        accel: [v[2], v[3], v[4]],
        accel_temp: v[5],
        flags,
    })
}

fn payload() -> impl Strategy<Value = Payload> {
    let raw = (any::<u64>(), any::<u32>(), raw_part(), raw_part()).prop_map(|(t, n, a, b)| {
        Payload::Raw(RawSample {
            time_us: t,
            sample_counter: n,
            parts: [a, b],
        })
    });
    let nav = (
        (any::<u64>(), any::<u32>(), any::<u8>(), any::<u16>()),
        (f32x3(), f32x3(), any::<u64>(), any::<u64>(), f32_bits()),
        (f32x3(), f32x3(), f32x3()),
    )
        .prop_map(
            |((t, n, mode, flags), (att, vel, lat, lon, h), (sa, sv, sp))| {
                Payload::Nav(NavSolution {
                    time_us: t,
                    sample_counter: n,
                    mode,
                    flags,
                    attitude: att,
                    velocity_ned: vel,
                    latitude: f64::from_bits(lat),
                    longitude: f64::from_bits(lon),
                    height: h,
                    attitude_std: sa,
                    velocity_std: sv,
                    position_std_ned: sp,
                })
            },
        );
    let event = (
        any::<u64>(),
        any::<u8>(),
        any::<u8>(),
        any::<u16>(),
        any::<u32>(),
    )
        .prop_map(|(t, kind, part, code, value)| {
            Payload::Event(Event {
                time_us: t,
                kind: EventKind::from_byte(kind),
                part,
                code,
                value,
            })
        });
    let station = (
        any::<(u64, u16, u16, u32, u32)>(),
        f32x3(),
        f32x3(),
        f32x3(),
        f32_bits(),
    )
        .prop_map(|((t, station, flags, start, end), a, s, c, q)| {
            Payload::Station(StationSurvey {
                time_us: t,
                station,
                flags,
                start_sample: start,
                end_sample: end,
                angles: a,
                angles_std: s,
                correlations: c,
                still_quality: q,
            })
        });
    prop_oneof![raw, nav, event, station]
}

fn body_bytes(seq: u16, payload: &Payload) -> Vec<u8> {
    let mut buf = [0u8; MAX_BODY_LEN];
    let n = encode_body(seq, payload, &mut buf).unwrap();
    buf[..n].to_vec()
}

fn wire_bytes(seq: u16, payload: &Payload) -> Vec<u8> {
    let mut buf = [0u8; MAX_WIRE_LEN];
    let n = encode_frame(seq, payload, &mut buf).unwrap();
    buf[..n].to_vec()
}

fn decode_all(bytes: &[u8]) -> (Vec<Frame>, Decoder) {
    let mut dec = Decoder::new();
    let mut frames = vec![];
    dec.feed(bytes, |f| frames.push(f));
    dec.finish();
    (frames, dec)
}

proptest! {
    #[test]
    fn every_kind_round_trips(seq in any::<u16>(), payload in payload()) {
        // Bit-exact: NaNs included, so compare re-encoded bytes.
        let body = body_bytes(seq, &payload);
        prop_assert_eq!(body.len(), payload.kind().body_len());
        let frame = decode_body(&body).unwrap();
        prop_assert_eq!(frame.seq, seq);
        prop_assert_eq!(body_bytes(seq, &frame.payload), body);
        // And through the streaming decoder from the wire.
        let (frames, dec) = decode_all(&wire_bytes(seq, &payload));
        prop_assert_eq!(frames.len(), 1);
        prop_assert_eq!(body_bytes(seq, &frames[0].payload), body_bytes(seq, &payload));
        prop_assert_eq!(dec.stats().frames[payload.kind().index()], 1);
    }

    #[test]
    fn byte_soup_never_panics(soup in proptest::collection::vec(any::<u8>(), 0..3000)) {
        let (frames, dec) = decode_all(&soup);
        let s = dec.stats();
        prop_assert_eq!(s.bytes, soup.len() as u64);
        prop_assert!(s.garbage_bytes <= s.bytes);
        prop_assert_eq!(frames.len() as u64, s.frames.iter().sum::<u64>());
    }

    #[test]
    fn garbage_between_frames_costs_no_frame(
        payloads in proptest::collection::vec(payload(), 1..20),
        garbage in proptest::collection::vec(proptest::collection::vec(any::<u8>(), 0..200), 20),
    ) {
        let mut stream = vec![];
        for (i, p) in payloads.iter().enumerate() {
            stream.extend(&garbage[i]);
            stream.extend(wire_bytes(i as u16, p));
        }
        let (frames, dec) = decode_all(&stream);
        prop_assert_eq!(frames.len(), payloads.len());
        for (i, f) in frames.iter().enumerate() {
            prop_assert_eq!(f.seq, i as u16);
        }
        prop_assert_eq!(dec.stats().lost, 0);
    }

    #[test]
    fn corruption_loses_exactly_the_frames_hit(
        seed_payloads in proptest::collection::vec(payload(), 1..8),
        hits in proptest::collection::vec((any::<prop::sample::Index>(), 0u8..8), 1..40),
    ) {
        // A long capture: 1500 frames cycling through the given payloads.
        let count = 1500;
        let mut enc = FrameEncoder::starting_at(0xFF00); // crosses the wrap
        let mut stream = vec![];
        let mut ranges = vec![];
        let mut buf = [0u8; MAX_WIRE_LEN];
        for i in 0..count {
            let n = enc.encode(&seed_payloads[i % seed_payloads.len()], &mut buf).unwrap();
            ranges.push(stream.len()..stream.len() + n);
            stream.extend_from_slice(&buf[..n]);
        }
        // Flip bits anywhere except in the first and last frame, whose loss
        // no sequence gap can show.
        let lo = ranges[1].start;
        let hi = ranges[count - 2].end;
        // Two flips of the same bit cancel: apply them first, then see
        // which bytes really changed.
        let mut masks = std::collections::BTreeMap::<usize, u8>::new();
        for (index, bit) in &hits {
            *masks.entry(lo + index.index(hi - lo)).or_default() ^= 1 << bit;
        }
        let mut hit = vec![false; count];
        for (pos, mask) in masks.into_iter().filter(|(_, m)| *m != 0) {
            stream[pos] ^= mask;
            let frame = ranges.iter().position(|r| r.contains(&pos)).unwrap();
            hit[frame] = true;
        }
        let (frames, dec) = decode_all(&stream);
        let expected: Vec<u16> = (0..count)
            .filter(|i| !hit[*i])
            .map(|i| 0xFF00u16.wrapping_add(i as u16))
            .collect();
        let got: Vec<u16> = frames.iter().map(|f| f.seq).collect();
        // (Compared by count first to keep a failure message short.)
        prop_assert_eq!(got.len(), expected.len());
        prop_assert!(got == expected, "decoded sequence numbers differ");
        let n_hit = hit.iter().filter(|h| **h).count() as u64;
        prop_assert_eq!(dec.stats().lost, n_hit);
        prop_assert!(dec.stats().corrupt() >= u64::from(n_hit > 0));
        prop_assert_eq!(dec.stats().sequence_restarts, 0);
        // The frames that survived are the ones that were sent.
        for f in &frames {
            let i = f.seq.wrapping_sub(0xFF00) as usize;
            let sent = &seed_payloads[i % seed_payloads.len()];
            prop_assert_eq!(body_bytes(f.seq, &f.payload), body_bytes(f.seq, sent));
        }
    }
}

#[test]
fn bandwidth_budget() {
    let raw = wire_len(FrameKind::RawSample.body_len());
    let nav = wire_len(FrameKind::NavSolution.body_len());
    let event = wire_len(FrameKind::Event.body_len());
    let station = wire_len(FrameKind::StationSurvey.body_len());
    assert_eq!((raw, nav, event, station), (51, 106, 27, 71));
    // Measured, not just computed: encode real frames.
    for payload in [
        example::raw_sample(),
        example::nav_solution(),
        example::boot_event(),
        example::station_survey(),
    ] {
        assert_eq!(
            wire_bytes(1, &payload).len(),
            wire_len(payload.kind().body_len())
        );
    }
    let per_s = cyclic_bytes_per_s();
    assert_eq!(per_s, 20 * (51 + 106));
    // At most 50 % of 11520 B/s (115200 baud, 8N1 = 10 bits per byte).
    assert!(per_s * 2 <= UART_BYTES_PER_S, "{per_s} B/s");
    assert_eq!(UART_BYTES_PER_S, 11_520);
}

fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn the_document_shows_the_current_bytes() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/protocol.md"))
        .expect("docs/protocol.md");
    let seq = example::EXAMPLE_SEQ;
    for payload in [
        example::raw_sample(),
        example::nav_solution(),
        example::boot_event(),
        example::station_survey(),
    ] {
        let body = hex(&body_bytes(seq, &payload));
        let wire = hex(&wire_bytes(seq, &payload));
        assert!(doc.contains(&body), "docs/protocol.md lacks body {body}");
        assert!(
            doc.contains(&wire),
            "docs/protocol.md lacks wire bytes {wire}"
        );
    }
    for figure in ["51 + 106 = 157", "3140 B/s", "27.3 %"] {
        assert!(doc.contains(figure), "docs/protocol.md lacks {figure}");
    }
    // The example decodes to what it claims.
    let (frames, _) = decode_all(&wire_bytes(seq, &example::boot_event()));
    assert_eq!(
        frames[0].payload,
        Payload::Event(Event {
            time_us: 0,
            kind: EventKind::Boot,
            part: NO_PART,
            code: 1,
            value: 0
        })
    );
}
