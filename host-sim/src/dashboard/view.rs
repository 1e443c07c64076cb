//! What the dashboard shows of each frame, as JSON for the page: sensor
//! readings in physical units, the attitude as drilling angles with their
//! 1-sigma, flags and events in words. The people-facing rules (azimuth
//! "undetermined", "n/a" for placeholders) are `crate::formats::display`'s.

use mwd_core::conventions::{DrillingAngles, Euler};
use mwd_core::protocol::frame::{nav_flags, EventKind, NO_PART};
use mwd_core::protocol::{Event, NavSolution, RawSample};
use mwd_core::sensor_units::{
    accel_count_to_m_s2, gyro_count_to_rad_s, ACCEL_TEMPERATURE, GYRO_TEMPERATURE, PART_MOUNTINGS,
};
use serde_json::{json, Value};

use crate::formats::display;
use crate::formats::display::mode_name;

/// Sensor channels of one sample: both parts' gyro rate (deg/s), both
/// parts' accelerometer triads in body axes (m/s^2, so that the two parts'
/// curves overlay), and the four temperatures (degC: gyro and accelerometer
/// of part 1, then of part 2). Uncalibrated: the counts as sent, in SI.
pub const SENSOR_CHANNELS: usize = 12;

pub fn sensor_channels(raw: &RawSample) -> [f32; SENSOR_CHANNELS] {
    let [p1, p2] = raw.parts;
    let accel = |i: usize, part: &mwd_core::protocol::RawPart| {
        PART_MOUNTINGS[i].sensor_to_body(part.accel.map(accel_count_to_m_s2))
    };
    let (a1, a2) = (accel(0, &p1), accel(1, &p2));
    [
        gyro_count_to_rad_s(p1.gyro_rate).to_degrees(),
        gyro_count_to_rad_s(p2.gyro_rate).to_degrees(),
        a1[0],
        a1[1],
        a1[2],
        a2[0],
        a2[1],
        a2[2],
        GYRO_TEMPERATURE.count_to_degc(p1.gyro_temp),
        ACCEL_TEMPERATURE.count_to_degc(p1.accel_temp),
        GYRO_TEMPERATURE.count_to_degc(p2.gyro_temp),
        ACCEL_TEMPERATURE.count_to_degc(p2.accel_temp),
    ]
}

/// Attitude channels of one solution, deg: inclination, its sigma,
/// azimuth, its sigma, toolface, its sigma. An azimuth that is not
/// determined is NaN with its sigma (sent as null: the page draws no
/// number). The frame's sigmas are those of roll, pitch and heading; the
/// drilling angles are inclination = 90 deg + pitch, azimuth = heading,
/// toolface = roll (`mwd_core::conventions`), so each sigma carries over
/// unchanged.
pub const ATTITUDE_CHANNELS: usize = 6;

pub fn attitude_channels(nav: &NavSolution) -> [f32; ATTITUDE_CHANNELS] {
    let [roll, pitch, heading] = nav.attitude.map(f64::from);
    let [s_roll, s_pitch, s_heading] = nav.attitude_std.map(f64::from);
    let drilling = DrillingAngles::from_euler(&Euler::new(roll, pitch, heading));
    let determined = heading.is_finite() && display::azimuth_is_determined(s_heading);
    let (azimuth, s_azimuth) = if determined {
        (display::deg_0_360(heading), s_heading.to_degrees())
    } else {
        (f64::NAN, f64::NAN)
    };
    let toolface = if roll.is_finite() {
        display::deg_0_360(roll)
    } else {
        f64::NAN
    };
    [
        drilling.inclination.to_degrees(),
        s_pitch.to_degrees(),
        azimuth,
        s_azimuth,
        toolface,
        s_roll.to_degrees(),
    ]
    .map(|v| v as f32)
}

const NAV_FLAG_NAMES: [(u16, &str); 10] = [
    (nav_flags::ZUPT_APPLIED, "zero-velocity update"),
    (nav_flags::TOOL_AXIS_RATE_INVALID, "near vertical"),
    (nav_flags::SENSOR_DEGRADED, "sensor degraded"),
    (nav_flags::COVARIANCE_INVALID, "COVARIANCE INVALID"),
    (nav_flags::SOLUTION_INVALID, "SOLUTION INVALID"),
    (nav_flags::COASTING, "coasting"),
    (nav_flags::SINGLE_PART, "single part"),
    (nav_flags::STILL, "still (station)"),
    (nav_flags::HEADING_LOST, "heading lost: needs a tie-in"),
    (
        nav_flags::UNCALIBRATED,
        "UNCALIBRATED: sigmas leave out the parts' turn-on errors",
    ),
];

/// The latest solution for people: each angle with its 1-sigma.
pub fn latest_json(nav: &NavSolution) -> Value {
    let [roll, pitch, _] = nav.attitude.map(f64::from);
    let [s_roll, s_pitch, _] = nav.attitude_std.map(f64::from);
    let [inc, _, _, _, tf, _] = attitude_channels(nav).map(f64::from);
    let flags: Vec<&str> = NAV_FLAG_NAMES
        .iter()
        .filter(|(bit, _)| nav.flags & bit != 0)
        .map(|(_, name)| *name)
        .collect();
    json!({
        "time_s": nav.time_us as f64 * 1e-6,
        "mode": mode_name(nav.mode).trim(),
        "flags": flags,
        "roll": display::angle_with_sigma(roll.to_degrees(), s_roll),
        "pitch": display::angle_with_sigma(pitch.to_degrees(), s_pitch),
        "inclination": display::angle_with_sigma(inc, s_pitch),
        "azimuth": display::nav_azimuth_text(nav, 3),
        "azimuth_status": display::AzimuthStatus::of_nav(nav).word(),
        "toolface": display::angle_with_sigma(tf, s_roll),
    })
}

/// An event for people.
pub fn event_text(e: &Event) -> String {
    let what = match e.kind {
        EventKind::Boot => format!("boot, firmware {}, reset cause {}", e.code, e.value),
        EventKind::SensorFault => format!("sensor fault code {}, count {}", e.code, e.value),
        EventKind::SensorReset => format!("sensor reset, reason {}", e.code),
        EventKind::Resync => format!("sampling resynchronised, {} samples skipped", e.value),
        EventKind::SamplesDropped => format!("{} samples dropped by the navigation", e.value),
        EventKind::Temperature => {
            let side = match e.code {
                0 => "below its range",
                1 => "above its range",
                _ => "back in range",
            };
            format!("temperature {side} (count {})", e.value as i32 as i16)
        }
        EventKind::Other(k) => format!("event kind {k}, code {}, value {}", e.code, e.value),
    };
    let part = if e.part == NO_PART {
        String::new()
    } else {
        format!("part {}: ", u16::from(e.part) + 1)
    };
    format!("{:.2} s {part}{what}", e.time_us as f64 * 1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::protocol::{example, Payload};

    #[test]
    fn an_undetermined_azimuth_is_no_number_and_sigmas_carry_over() {
        let mut nav = NavSolution {
            attitude: [0.1, -0.2, 1.0],
            attitude_std: [0.01, 0.02, f32::INFINITY],
            ..NavSolution::default()
        };
        let ch = attitude_channels(&nav);
        assert!((ch[0] - (90.0 - 0.2f32.to_degrees())).abs() < 1e-4);
        assert!((ch[1] - 0.02f32.to_degrees()).abs() < 1e-5);
        assert!(ch[2].is_nan() && ch[3].is_nan());
        let latest = latest_json(&nav);
        assert_eq!(latest["azimuth"], "undetermined");
        assert_eq!(latest["azimuth_status"], "undetermined");
        // Lost since the last tie-in: said so, still no number.
        nav.flags = nav_flags::HEADING_LOST;
        let latest = latest_json(&nav);
        assert_eq!(latest["azimuth"], display::HEADING_LOST_TEXT);
        assert_eq!(latest["azimuth_status"], "lost");
        assert_eq!(latest["flags"][0], "heading lost: needs a tie-in");
        nav.flags = 0;
        nav.attitude_std[2] = 0.02;
        let latest = latest_json(&nav);
        assert_eq!(latest["azimuth"], "57.296 +- 1.146 deg (1 sigma)");
        assert_eq!(attitude_channels(&nav)[2], 57.29578);
        // An invalid covariance: no sigma shown as 0.
        nav.attitude_std = [f32::NAN; 3];
        let latest = latest_json(&nav);
        assert_eq!(latest["roll"], "n/a");
        assert_eq!(latest["azimuth"], "n/a");
    }

    #[test]
    fn sensors_read_in_physical_units() {
        let Payload::Raw(raw) = example::raw_sample() else {
            unreachable!()
        };
        let ch = sensor_channels(&raw);
        let g: f32 = ch[2..5].iter().map(|a| a * a).sum::<f32>().sqrt();
        assert!((g - 9.8).abs() < 0.3, "{g}");
        assert!(ch[8] > -60.0 && ch[8] < 150.0, "{}", ch[8]);
    }
}
