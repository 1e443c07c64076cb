//! The worked examples of `docs/protocol.md`: fixed frames whose bytes the
//! document prints and a test compares, so the document cannot go stale
//! (`cargo run -p mwd-core --example protocol_example` prints them).

use super::frame::{
    nav_flags, nav_mode, raw_flags, station_flags, Event, EventKind, NavSolution, Payload, RawPart,
    RawSample, StationSurvey, NO_PART,
};
use crate::earth::Position;

/// Sequence number of the worked raw-sample example.
pub const EXAMPLE_SEQ: u16 = 0x0102;

const GOOD: u16 = raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID | raw_flags::GYRO_S_OK;

/// Tool horizontal, at rest, 25 degC: part 1 senses 1 deg/s about body x
/// (18 counts) and gravity on its Z (+650 counts = 1 g); part 2 (X along
/// body z) senses gravity on its X. Sample 1234 at t = 61.7 s.
pub fn raw_sample() -> Payload {
    let temp = -1625; // 25 degC with the (unverified) gyro formula
    Payload::Raw(RawSample {
        time_us: 61_700_000,
        sample_counter: 1234,
        parts: [
            RawPart {
                gyro_rate: 18,
                gyro_temp: temp,
                accel: [0, -3, 650],
                accel_temp: temp,
                flags: GOOD,
            },
            RawPart {
                gyro_rate: -2,
                gyro_temp: temp,
                accel: [650, 1, 0],
                accel_temp: temp,
                flags: GOOD,
            },
        ],
    })
}

/// A navigation solution at the paper's start position (45.77755 N,
/// 126.687898 E, 124 m), fine alignment, ZUPT applied.
pub fn nav_solution() -> Payload {
    Payload::Nav(NavSolution {
        time_us: 61_700_000,
        sample_counter: 1234,
        mode: nav_mode::FINE_ALIGNMENT,
        flags: nav_flags::ZUPT_APPLIED,
        attitude: [-0.014_069, 0.009_374, -2.634_808],
        velocity_ned: [0.001, -0.002, 0.0],
        latitude: Position::paper_site().lat,
        longitude: Position::paper_site().lon,
        height: 124.0,
        attitude_std: [0.000_607, 0.000_182, 0.1],
        velocity_std: [0.0277, 0.0292, 0.027],
        position_std_ned: [0.05, 0.05, 0.05],
    })
}

/// The boot event: firmware version 1, reset cause 0.
pub fn boot_event() -> Payload {
    Payload::Event(Event {
        time_us: 0,
        kind: EventKind::Boot,
        part: NO_PART,
        code: 1,
        value: 0,
    })
}

/// Station 3, still from sample 24000 to 27599 (20 min to 23 min after
/// boot, 3 min of zero-velocity updates): inclination 45 deg +- 0.05,
/// azimuth 120 deg +- 1.2, toolface 300 deg +- 0.07 (1 sigma),
/// magnetic-free, still quality 1.02.
pub fn station_survey() -> Payload {
    Payload::Station(StationSurvey {
        time_us: 1_379_950_000,
        station: 3,
        flags: station_flags::MAGNETIC_FREE,
        start_sample: 24_000,
        end_sample: 27_599,
        angles: [
            core::f32::consts::FRAC_PI_4,
            2.0 * core::f32::consts::FRAC_PI_3,
            5.0 * core::f32::consts::FRAC_PI_3,
        ],
        angles_std: [0.000_872_7, 0.020_944, 0.001_221_7],
        correlations: [0.12, -0.35, 0.05],
        still_quality: 1.02,
    })
}

/// The uplink's worked example: set the site to the paper's (45.77755 N,
/// 126.687898 E, 124 m), command number 7.
pub fn set_site_command() -> super::uplink::Command {
    super::uplink::Command::SetSite(Position::paper_site())
}

/// Command number of the uplink's worked examples.
pub const EXAMPLE_COMMAND_SEQ: u16 = 7;

/// The probe's ACK of command 7 at t = 2.5 s, the configuration now at
/// version 3.
pub fn ack_reply() -> super::uplink::Reply {
    super::uplink::Reply::ack(2_500_000, EXAMPLE_COMMAND_SEQ, 0x40, 3)
}

/// The NAK of a still-settings command 8 whose staying quantile is below
/// its entering one (field 16), configuration still at version 3.
pub fn nak_reply() -> super::uplink::Reply {
    use super::uplink::{Field, NakReason, Reply, ReplyStatus};
    Reply {
        time_us: 2_550_000,
        command_seq: 8,
        command_kind: 0x44,
        status: ReplyStatus::Nak(NakReason::OutOfRange),
        detail: Field::ZStay as u8,
        config_version: 3,
    }
}
