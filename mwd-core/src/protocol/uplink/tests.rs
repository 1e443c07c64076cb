use super::super::crc::crc32c;
use super::super::decoder::Decoder;
use super::super::wire::FrameEncoder;
use super::*;
use crate::calibration::{GyroCalibration, TriadCalibration};

fn still() -> StillSettings {
    StillSettings {
        z_enter: 3.09,
        z_stay: 5.199,
        enter_epochs: 20,
        max_station_samples: 6000,
        zupt_velocity_sigma: 0.01,
    }
}

fn one_of_each() -> [Command; 11] {
    let angles = DrillingAngles {
        inclination: 1.5,
        azimuth: 4.0,
        toolface: 0.3,
    };
    let sigma = DrillingAngles {
        inclination: 0.001,
        azimuth: 0.02,
        toolface: 0.002,
    };
    let mut accel = TriadCalibration::IDENTITY;
    accel.bias = [0.01, -0.02, 0.03];
    accel.correction[0][1] = 0.001;
    [
        Command::SetSite(Position::paper_site()),
        Command::SetTieIn { angles, sigma },
        Command::ClearTieIn,
        Command::SetCalibration {
            part: 1,
            accel,
            gyro: GyroCalibration {
                bias: 1e-4,
                scale: 1.001,
            },
        },
        Command::SetStillSettings(still()),
        Command::Realign,
        Command::StartSurveying,
        Command::TakeStation,
        Command::IndexToolface(IndexingProcedure {
            positions: 8,
            dwell_s: 20,
        }),
        Command::ReportConfig,
        Command::Reboot,
    ]
}

fn body(seq: u16, command: &Command) -> ([u8; MAX_COMMAND_BODY_LEN], usize) {
    let mut buf = [0u8; MAX_COMMAND_BODY_LEN];
    let n = encode_command_body(seq, command, &mut buf).unwrap();
    (buf, n)
}

/// Rewrites a body's CRC after a test changed its bytes.
fn reseal(bytes: &mut [u8]) {
    let n = bytes.len() - CRC_LEN;
    let crc = crc32c(&bytes[..n]).to_le_bytes();
    bytes[n..].copy_from_slice(&crc);
}

#[test]
fn every_command_round_trips_at_its_length() {
    for (i, command) in one_of_each().iter().enumerate() {
        let (buf, n) = body(i as u16, command);
        assert_eq!(n, command.kind().body_len(), "{command:?}");
        let got = decode_command(&buf[..n]).unwrap();
        assert_eq!((got.seq, got.command), (i as u16, *command));
    }
    assert_eq!(MAX_COMMAND_BODY_LEN, 121);
    assert!(CommandKind::ALL
        .iter()
        .all(|k| k.body_len() <= MAX_COMMAND_BODY_LEN));
    for byte in 0..=255u8 {
        if let Some(kind) = CommandKind::from_byte(byte) {
            assert_eq!(kind as u8, byte);
            assert!(
                (0x40..=0x4A).contains(&byte),
                "apart from the downlink kinds"
            );
        }
    }
}

#[test]
fn every_bit_flip_is_a_crc_error_and_carries_no_address() {
    let (buf, n) = body(3, &Command::SetSite(Position::paper_site()));
    for bit in 0..n * 8 {
        let mut copy = buf;
        copy[bit / 8] ^= 1 << (bit % 8);
        let err = decode_command(&copy[..n]).unwrap_err();
        assert_eq!(err, UplinkError::BadCrc);
        assert_eq!(err.addressed(), None);
        assert_eq!(Reply::for_error(&err, 0, 1), None);
    }
    assert_eq!(decode_command(&buf[..7]), Err(UplinkError::TooShort));
}

#[test]
fn header_errors_name_the_command() {
    let (buf, n) = body(9, &Command::Realign);
    let mut v = buf;
    v[0] = 2;
    reseal(&mut v[..n]);
    let err = decode_command(&v[..n]).unwrap_err();
    assert_eq!(
        err,
        UplinkError::UnsupportedVersion {
            version: 2,
            seq: 9,
            kind: 0x45
        }
    );
    let mut k = buf;
    k[1] = 0x4B;
    reseal(&mut k[..n]);
    assert_eq!(
        decode_command(&k[..n]),
        Err(UplinkError::UnknownCommand { seq: 9, kind: 0x4B })
    );
    let mut l = buf;
    l[1] = CommandKind::SetSite as u8;
    reseal(&mut l[..n]);
    assert_eq!(
        decode_command(&l[..n]),
        Err(UplinkError::BadLength { seq: 9, kind: 0x40 })
    );
}

/// Encodes `command`, overwrites the f64 at payload offset `at` with
/// `value` and decodes.
fn with_f64(command: &Command, at: usize, value: f64) -> Result<Received, UplinkError> {
    let (mut buf, n) = body(5, command);
    buf[HEADER_LEN + at..HEADER_LEN + at + 8].copy_from_slice(&value.to_le_bytes());
    reseal(&mut buf[..n]);
    decode_command(&buf[..n])
}

fn out_of_range(kind: CommandKind, field: Field) -> Result<Received, UplinkError> {
    Err(UplinkError::OutOfRange {
        seq: 5,
        kind: kind as u8,
        field,
    })
}

#[test]
fn each_out_of_range_field_is_named() {
    let [site, tie_in, _, calibration, ..] = one_of_each();
    use CommandKind as K;
    let cases = [
        (site, 0, f64::NAN, K::SetSite, Field::Latitude),
        (site, 0, 1.6, K::SetSite, Field::Latitude),
        (site, 8, -3.2, K::SetSite, Field::Longitude),
        (site, 16, 9_500.0, K::SetSite, Field::Height),
        (site, 16, f64::INFINITY, K::SetSite, Field::Height),
        (tie_in, 0, -0.1, K::SetTieIn, Field::Inclination),
        (
            tie_in,
            8,
            core::f64::consts::TAU,
            K::SetTieIn,
            Field::Azimuth,
        ),
        (tie_in, 16, f64::NAN, K::SetTieIn, Field::Toolface),
        (tie_in, 24, 0.0, K::SetTieIn, Field::InclinationSigma),
        (tie_in, 32, -1.0, K::SetTieIn, Field::AzimuthSigma),
        (tie_in, 40, 4.0, K::SetTieIn, Field::ToolfaceSigma),
        (calibration, 1, 10.0, K::SetCalibration, Field::AccelBias),
        (
            calibration,
            25,
            0.4,
            K::SetCalibration,
            Field::AccelCorrection,
        ),
        (
            calibration,
            33,
            0.25,
            K::SetCalibration,
            Field::AccelCorrection,
        ),
        (calibration, 97, 0.2, K::SetCalibration, Field::GyroBias),
        (calibration, 105, 0.0, K::SetCalibration, Field::GyroScale),
    ];
    for (command, at, value, kind, field) in cases {
        assert_eq!(
            with_f64(&command, at, value),
            out_of_range(kind, field),
            "{field:?} = {value}"
        );
    }
    // The edges of the ranges are in.
    assert!(with_f64(&site, 0, -core::f64::consts::FRAC_PI_2).is_ok());
    assert!(with_f64(&site, 16, -1_000.0).is_ok());
    assert!(with_f64(&tie_in, 0, core::f64::consts::PI).is_ok());
}

#[test]
fn integer_and_cross_field_ranges() {
    let (mut buf, n) = body(
        5,
        &Command::SetCalibration {
            part: 0,
            accel: TriadCalibration::IDENTITY,
            gyro: GyroCalibration::IDENTITY,
        },
    );
    buf[HEADER_LEN] = 2;
    reseal(&mut buf[..n]);
    assert_eq!(
        decode_command(&buf[..n]),
        out_of_range(CommandKind::SetCalibration, Field::Part)
    );
    let set = |s: StillSettings| {
        let (buf, n) = body(5, &Command::SetStillSettings(s));
        decode_command(&buf[..n])
    };
    let kind = CommandKind::SetStillSettings;
    let cases = [
        (
            StillSettings {
                z_stay: 3.0,
                ..still()
            },
            Field::ZStay,
        ),
        (
            StillSettings {
                z_enter: 1.9,
                ..still()
            },
            Field::ZEnter,
        ),
        (
            StillSettings {
                enter_epochs: 0,
                ..still()
            },
            Field::EnterEpochs,
        ),
        (
            StillSettings {
                max_station_samples: 72_001,
                ..still()
            },
            Field::MaxStationSamples,
        ),
        (
            StillSettings {
                zupt_velocity_sigma: f32::NAN,
                ..still()
            },
            Field::ZuptVelocitySigma,
        ),
    ];
    for (settings, field) in cases {
        assert_eq!(set(settings), out_of_range(kind, field), "{field:?}");
    }
    let index = |positions, dwell_s| {
        let (buf, n) = body(
            5,
            &Command::IndexToolface(IndexingProcedure { positions, dwell_s }),
        );
        decode_command(&buf[..n])
    };
    let kind = CommandKind::IndexToolface;
    assert_eq!(index(1, 10), out_of_range(kind, Field::IndexPositions));
    assert_eq!(index(37, 10), out_of_range(kind, Field::IndexPositions));
    assert_eq!(index(4, 2), out_of_range(kind, Field::IndexDwell));
    assert!(index(36, 600).is_ok());
}

#[test]
fn field_codes_are_one_to_twenty_one() {
    for (i, field) in Field::ALL.iter().enumerate() {
        assert_eq!(*field as usize, i + 1);
        assert_eq!(Field::from_byte(i as u8 + 1), Some(*field));
    }
    assert_eq!(Field::from_byte(0), None);
    assert_eq!(Field::from_byte(22), None);
}

#[test]
fn a_nak_quotes_the_command_and_the_field() {
    let err = UplinkError::OutOfRange {
        seq: 8,
        kind: 0x44,
        field: Field::ZStay,
    };
    let nak = Reply::for_error(&err, 2_550_000, 3).unwrap();
    assert_eq!(nak, super::super::example::nak_reply());
    let unknown = UplinkError::UnknownCommand { seq: 1, kind: 0x99 };
    let nak = Reply::for_error(&unknown, 0, 0).unwrap();
    assert_eq!(
        (nak.status, nak.command_kind, nak.detail),
        (ReplyStatus::Nak(NakReason::UnknownCommand), 0x99, 0)
    );
}

#[test]
fn replies_round_trip_and_old_decoders_skip_them() {
    let replies = [
        super::super::example::ack_reply(),
        super::super::example::nak_reply(),
    ];
    let mut enc = FrameEncoder::new();
    let mut dec = Decoder::new();
    for reply in replies {
        let mut body = [0u8; reply::REPLY_BODY_LEN];
        let n = reply::encode_reply_body(enc.next_seq(), &reply, &mut body).unwrap();
        assert_eq!(n, 25);
        assert_eq!(
            reply::decode_reply_body(&body[..n]),
            Ok((enc.next_seq(), reply))
        );
        let mut wire = [0u8; 32];
        let seq = enc.next_seq();
        assert!(enc.encode_reply(&reply, &mut wire[..20]).is_err());
        assert_eq!(enc.next_seq(), seq, "not used up on error");
        let w = enc.encode_reply(&reply, &mut wire).unwrap();
        assert_eq!((w, enc.next_seq()), (28, seq.wrapping_add(1)));
        let mut read_back = None;
        for b in &wire[..w] {
            assert_eq!(dec.push(*b), None, "not a telemetry frame");
            if let Some(body) = dec.unknown_body() {
                read_back = Some(reply::decode_reply_body(body));
            }
        }
        assert_eq!(read_back, Some(Ok((seq, reply))));
    }
    // Numbered in the downlink's one sequence: a telemetry frame after
    // the replies is not counted as a loss.
    let mut wire = [0u8; 64];
    let w = enc
        .encode(&super::super::example::boot_event(), &mut wire)
        .unwrap();
    dec.feed(&wire[..w], |_| {});
    let s = dec.stats();
    assert_eq!((s.unknown_kind, s.corrupt(), s.lost), (2, 0, 0));
    // Every status byte survives (unknown NAK reasons are kept).
    for b in 0..=255u8 {
        let status = NakReason::from_byte(b).map_or(0, NakReason::to_byte);
        assert_eq!(status, b);
    }
}

#[test]
fn errors_read_as_sentences_with_their_numbers() {
    extern crate std;
    use std::string::ToString;
    let text = UplinkError::OutOfRange {
        seq: 8,
        kind: 0x44,
        field: Field::ZStay,
    }
    .to_string();
    assert!(
        text.contains("command 8") && text.contains("staying"),
        "{text}"
    );
    let text = UplinkError::UnknownCommand { seq: 2, kind: 0x99 }.to_string();
    assert!(text.contains("0x99"), "{text}");
}

#[test]
fn the_survey_commands_refusals_have_their_own_codes() {
    // Codes 1-6 keep their meaning (worked examples, older hosts read 7
    // and 8 as unknown reasons and keep them).
    assert_eq!(NakReason::from_byte(7), Some(NakReason::NotReady));
    assert_eq!(NakReason::from_byte(8), Some(NakReason::NotStill));
    assert_eq!(NakReason::Busy.to_byte(), 5);
    assert_eq!(NakReason::StorageFailed.to_byte(), 6);
    assert_eq!(NakReason::from_byte(9), Some(NakReason::Other(9)));
}
