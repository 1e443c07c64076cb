//! The uplink's commands and replies: every valid command round-trips
//! through its body and the wire, every field drawn across and beyond its
//! range decodes or is named, and random bytes never panic.

use mwd_core::calibration::{GyroCalibration, TriadCalibration};
use mwd_core::conventions::DrillingAngles;
use mwd_core::earth::Position;
use mwd_core::protocol::uplink::reply::{decode_reply_body, encode_reply_body, REPLY_BODY_LEN};
use mwd_core::protocol::uplink::{
    decode_command, encode_command, encode_command_body, fields, Command, IndexingProcedure,
    NakReason, Reply, ReplyStatus, StillSettings, UplinkError, MAX_COMMAND_BODY_LEN,
    MAX_COMMAND_WIRE_LEN,
};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

fn site() -> impl Strategy<Value = Position> {
    (-FRAC_PI_2..=FRAC_PI_2, -PI..=PI, -1_000.0..=9_000.0f64)
        .prop_map(|(lat, lon, height)| Position { lat, lon, height })
}

fn angles(max_sigma: f64) -> impl Strategy<Value = (DrillingAngles, DrillingAngles)> {
    (
        0.0..=PI,
        0.0..TAU,
        0.0..TAU,
        [1e-9..=max_sigma, 1e-9..=max_sigma, 1e-9..=max_sigma],
    )
        .prop_map(|(inclination, azimuth, toolface, s)| {
            (
                DrillingAngles {
                    inclination,
                    azimuth,
                    toolface,
                },
                DrillingAngles {
                    inclination: s[0],
                    azimuth: s[1],
                    toolface: s[2],
                },
            )
        })
}

fn part_calibration() -> impl Strategy<Value = (TriadCalibration, GyroCalibration)> {
    let b = fields::MAX_ACCEL_BIAS_M_S2;
    let m = fields::MAX_ACCEL_CORRECTION_OFF_DIAGONAL;
    let (dlo, dhi) = fields::ACCEL_CORRECTION_DIAGONAL;
    let g = fields::MAX_GYRO_BIAS_RAD_S;
    (
        [-b..=b, -b..=b, -b..=b],
        [dlo..=dhi, dlo..=dhi, dlo..=dhi],
        [-m..=m, -m..=m, -m..=m, -m..=m, -m..=m, -m..=m],
        -g..=g,
        fields::GYRO_SCALE.0..=fields::GYRO_SCALE.1,
    )
        .prop_map(|(bias, d, o, gyro_bias, scale)| {
            (
                TriadCalibration {
                    bias,
                    correction: [[d[0], o[0], o[1]], [o[2], d[1], o[3]], [o[4], o[5], d[2]]],
                },
                GyroCalibration {
                    bias: gyro_bias,
                    scale,
                },
            )
        })
}

fn still_settings() -> impl Strategy<Value = StillSettings> {
    (
        fields::Z_ENTER.0..=fields::Z_ENTER.1,
        0.0..=1.0f32,
        fields::ENTER_EPOCHS.0..=fields::ENTER_EPOCHS.1,
        fields::MAX_STATION_SAMPLES.0..=fields::MAX_STATION_SAMPLES.1,
        fields::ZUPT_VELOCITY_SIGMA.0..=fields::ZUPT_VELOCITY_SIGMA.1,
    )
        .prop_map(|(z_enter, t, enter_epochs, longest, sigma)| {
            // z_stay anywhere in [z_enter, 8] (f32 rounding kept inside).
            let z_stay = (z_enter + t * (fields::MAX_Z_STAY - z_enter)).max(z_enter);
            StillSettings {
                z_enter,
                z_stay,
                enter_epochs,
                max_station_samples: longest,
                zupt_velocity_sigma: sigma,
            }
        })
}

fn command() -> impl Strategy<Value = Command> {
    prop_oneof![
        site().prop_map(Command::SetSite),
        angles(PI).prop_map(|(angles, sigma)| Command::SetTieIn { angles, sigma }),
        Just(Command::ClearTieIn),
        (0..=1u8, part_calibration()).prop_map(|(part, (accel, gyro))| Command::SetCalibration {
            part,
            accel,
            gyro
        }),
        still_settings().prop_map(Command::SetStillSettings),
        Just(Command::Realign),
        Just(Command::StartSurveying),
        Just(Command::TakeStation),
        (2..=36u8, 3..=600u16).prop_map(|(positions, dwell_s)| Command::IndexToolface(
            IndexingProcedure { positions, dwell_s }
        )),
        Just(Command::ReportConfig),
        Just(Command::Reboot),
    ]
}

/// The commands made of f64 fields.
fn f64_command() -> impl Strategy<Value = Command> {
    prop_oneof![
        site().prop_map(Command::SetSite),
        angles(PI).prop_map(|(angles, sigma)| Command::SetTieIn { angles, sigma }),
        (0..=1u8, part_calibration()).prop_map(|(part, (accel, gyro))| Command::SetCalibration {
            part,
            accel,
            gyro
        }),
    ]
}

fn wire_to_body(wire: &[u8]) -> Vec<u8> {
    assert_eq!((wire[0], wire[wire.len() - 1]), (0, 0));
    let mut inner = wire[1..wire.len() - 1].to_vec();
    assert!(inner.iter().all(|b| *b != 0));
    let n = cobs::decode_in_place(&mut inner).expect("COBS");
    inner.truncate(n);
    inner
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn every_valid_command_round_trips(seq in any::<u16>(), command in command()) {
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq, &command, &mut wire).unwrap();
        let got = decode_command(&wire_to_body(&wire[..n])).unwrap();
        prop_assert_eq!(got.seq, seq);
        prop_assert_eq!(got.command, command);
    }

    /// Any f64 bit pattern in any f64 field: decodes to exactly it, or is
    /// refused as out of range, never anything else.
    #[test]
    fn any_f64_in_a_field_is_kept_or_named(
        command in f64_command(),
        slot in any::<usize>(),
        bits in any::<u64>(),
    ) {
        let mut body = [0u8; MAX_COMMAND_BODY_LEN];
        let n = encode_command_body(1, &command, &mut body).unwrap();
        // The calibration's part byte comes before its f64 fields.
        let skip = usize::from(matches!(command, Command::SetCalibration { .. }));
        let at = 4 + skip + 8 * (slot % ((n - 8 - skip) / 8));
        body[at..at + 8].copy_from_slice(&bits.to_le_bytes());
        let crc = crc32c::crc32c_of(&body[..n - 4]);
        body[n - 4..n].copy_from_slice(&crc.to_le_bytes());
        match decode_command(&body[..n]) {
            Ok(got) => {
                let mut again = [0u8; MAX_COMMAND_BODY_LEN];
                let m = encode_command_body(1, &got.command, &mut again).unwrap();
                prop_assert_eq!(&again[..m], &body[..n]);
            }
            Err(UplinkError::OutOfRange { seq: 1, .. }) => {}
            Err(e) => prop_assert!(false, "{e:?}"),
        }
    }

    #[test]
    fn random_bytes_never_panic(soup in proptest::collection::vec(any::<u8>(), 0..300)) {
        let _ = decode_command(&soup);
        let _ = decode_reply_body(&soup);
    }

    #[test]
    fn replies_round_trip(
        seq in any::<u16>(),
        time_us in any::<u64>(),
        command_seq in any::<u16>(),
        command_kind in any::<u8>(),
        status in any::<u8>(),
        detail in any::<u8>(),
        config_version in any::<u32>(),
    ) {
        let reply = Reply {
            time_us,
            command_seq,
            command_kind,
            status: NakReason::from_byte(status).map_or(ReplyStatus::Ack, ReplyStatus::Nak),
            detail,
            config_version,
        };
        let mut body = [0u8; REPLY_BODY_LEN];
        let n = encode_reply_body(seq, &reply, &mut body).unwrap();
        prop_assert_eq!(decode_reply_body(&body[..n]), Ok((seq, reply)));
    }
}

/// The CRC the protocol uses, from the library (the test's own copy would
/// only check itself).
mod crc32c {
    pub fn crc32c_of(data: &[u8]) -> u32 {
        mwd_core::protocol::crc::crc32c(data)
    }
}

#[test]
fn the_longest_command_fits_its_buffer() {
    assert_eq!(MAX_COMMAND_BODY_LEN, 121);
    assert_eq!(MAX_COMMAND_WIRE_LEN, 124);
}

fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `docs/protocol.md`'s uplink examples are the bytes this code makes, and
/// decode to what the document says they are.
#[test]
fn the_document_shows_the_current_uplink_bytes() {
    use mwd_core::protocol::example;
    use mwd_core::protocol::uplink::reply::encode_reply;
    use mwd_core::protocol::uplink::{CommandKind, Field, Received};
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/protocol.md"))
        .expect("docs/protocol.md");
    let uplink = &doc[doc.find("## Uplink").expect("an Uplink section")..];
    let seq = example::EXAMPLE_COMMAND_SEQ;
    let command = example::set_site_command();
    let mut body = [0u8; MAX_COMMAND_BODY_LEN];
    let n = encode_command_body(seq, &command, &mut body).unwrap();
    let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
    let w = encode_command(seq, &command, &mut wire).unwrap();
    for text in [hex(&body[..n]), hex(&wire[..w])] {
        assert!(uplink.contains(&text), "docs/protocol.md lacks {text}");
    }
    assert_eq!(
        decode_command(&wire_to_body(&wire[..w])),
        Ok(Received {
            seq: 7,
            command: Command::SetSite(Position::from_degrees(45.777_55, 126.687_898, 124.0))
        })
    );
    for reply in [example::ack_reply(), example::nak_reply()] {
        let mut body = [0u8; REPLY_BODY_LEN];
        let n = encode_reply_body(example::EXAMPLE_SEQ, &reply, &mut body).unwrap();
        let mut wire = [0u8; 32];
        let w = encode_reply(example::EXAMPLE_SEQ, &reply, &mut wire).unwrap();
        for text in [hex(&body[..n]), hex(&wire[..w])] {
            assert!(uplink.contains(&text), "docs/protocol.md lacks {text}");
        }
    }
    // The tables name every kind and the codes the examples use.
    for kind in CommandKind::ALL {
        let row = format!("| {:#04x} |", kind as u8);
        assert!(uplink.contains(&row), "no row for kind {row}");
    }
    assert_eq!(Field::ZStay as u8, 0x10);
    assert!(uplink.contains("detail 0x10 (field 16, z_stay)"));
    assert!(uplink.contains("16 z_stay"));
    assert_eq!(NakReason::OutOfRange.to_byte(), 4);
    assert!(uplink.contains("4 out of range"));
}
