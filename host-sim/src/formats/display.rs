//! How the host shows angles and their uncertainty to people, in one
//! place: azimuth and toolface in [0, 360) deg; an azimuth whose sigma is
//! beyond what the alignment calls determined is shown as "undetermined",
//! never as a number; a placeholder (NaN, e.g. no solution yet) as "n/a".

use mwd_core::alignment::MAX_DETERMINED_SIGMA;
use mwd_core::conventions::wrap_two_pi;
use mwd_core::protocol::frame::{nav_flags, nav_mode, station_flags};
use mwd_core::protocol::uplink::{Field, NakReason, Reply, ReplyStatus};
use mwd_core::protocol::{NavSolution, StationSurvey};
use mwd_core::timing::SAMPLE_INTERVAL_S;

/// An angle (rad) in degrees in [0, 360): azimuth and toolface.
pub fn deg_0_360(angle_rad: f64) -> f64 {
    let deg = wrap_two_pi(angle_rad).to_degrees();
    // wrap_two_pi can round up to exactly 2 pi.
    if deg >= 360.0 {
        0.0
    } else {
        deg
    }
}

/// Whether an azimuth with this 1-sigma (rad) is determined: finite and
/// within [`MAX_DETERMINED_SIGMA`] (the alignment's own rule).
pub fn azimuth_is_determined(sigma_rad: f64) -> bool {
    sigma_rad.is_finite() && sigma_rad <= MAX_DETERMINED_SIGMA
}

/// An azimuth for people: "123.46 +- 1.23 deg (1 sigma)" with `decimals`
/// decimals, "undetermined" when its sigma says so, "n/a" for a
/// placeholder.
pub fn azimuth_text(azimuth_rad: f64, sigma_rad: f64, decimals: usize) -> String {
    AzimuthStatus::of_sigma(azimuth_rad, sigma_rad).text(azimuth_rad, sigma_rad, decimals)
}

/// "12.345 +- 0.050" (deg), "n/a" for a NaN value or sigma.
pub fn angle_with_sigma(value_deg: f64, sigma_rad: f64) -> String {
    if !value_deg.is_finite() || sigma_rad.is_nan() {
        "n/a".to_string()
    } else {
        format!("{value_deg:.3} +- {:.3} deg", sigma_rad.to_degrees())
    }
}

/// A station's azimuth for people: "undetermined" when its flag or its
/// sigma says so (`azimuth_text`'s rule plus the flag), with the reason
/// when the heading was lost since the last tie-in (only a new one brings
/// it back, unlike a heading the alignment has not found yet).
pub fn station_azimuth_text(s: &StationSurvey) -> String {
    let (azimuth, sigma) = (f64::from(s.angles[1]), f64::from(s.angles_std[1]));
    AzimuthStatus::of_station(s).text(azimuth, sigma, 3)
}

/// An azimuth whose heading was lost since the last tie-in (station and
/// navigation bit 8).
pub const HEADING_LOST_TEXT: &str = "undetermined (heading lost: needs a tie-in)";

/// A navigation frame's azimuth for people: [`azimuth_text`], with the
/// reason when it is undetermined because the heading was lost since the
/// last tie-in (navigation bit 8).
pub fn nav_azimuth_text(nav: &NavSolution, decimals: usize) -> String {
    let (azimuth, sigma) = (f64::from(nav.attitude[2]), f64::from(nav.attitude_std[2]));
    AzimuthStatus::of_nav(nav).text(azimuth, sigma, decimals)
}

/// What an azimuth is, as the CSV exports and the dashboard say beside it
/// ([`word`](Self::word)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AzimuthStatus {
    /// A placeholder (NaN: no solution yet): "n/a".
    Placeholder,
    Determined,
    /// Lost since the last tie-in (navigation and station bit 8): only a
    /// new tie-in brings it back.
    Lost,
    /// Not found yet (or its station's flag says so).
    Undetermined,
}

impl AzimuthStatus {
    /// From the azimuth and its 1-sigma alone (rad): a placeholder (NaN),
    /// determined ([`azimuth_is_determined`]) or undetermined.
    pub fn of_sigma(azimuth_rad: f64, sigma_rad: f64) -> Self {
        if !azimuth_rad.is_finite() || sigma_rad.is_nan() {
            Self::Placeholder
        } else if azimuth_is_determined(sigma_rad) {
            Self::Determined
        } else {
            Self::Undetermined
        }
    }

    /// A navigation frame's: undetermined after a heading lost since the
    /// last tie-in is lost.
    pub fn of_nav(nav: &NavSolution) -> Self {
        let (azimuth, sigma) = (f64::from(nav.attitude[2]), f64::from(nav.attitude_std[2]));
        match Self::of_sigma(azimuth, sigma) {
            Self::Undetermined if nav.flags & nav_flags::HEADING_LOST != 0 => Self::Lost,
            status => status,
        }
    }

    /// A station survey's: its flags call an azimuth lost or undetermined
    /// whatever its sigma.
    pub fn of_station(s: &StationSurvey) -> Self {
        if s.flags & station_flags::HEADING_LOST != 0 {
            Self::Lost
        } else if s.flags & station_flags::AZIMUTH_UNDETERMINED != 0 {
            Self::Undetermined
        } else {
            Self::of_sigma(f64::from(s.angles[1]), f64::from(s.angles_std[1]))
        }
    }

    /// The azimuth for people in this status: "123.46 +- 1.23 deg (1
    /// sigma)" with `decimals` decimals when determined, else "n/a",
    /// "undetermined" or [`HEADING_LOST_TEXT`], never a number.
    fn text(self, azimuth_rad: f64, sigma_rad: f64, decimals: usize) -> String {
        match self {
            Self::Determined => format!(
                "{:.decimals$} +- {:.decimals$} deg (1 sigma)",
                deg_0_360(azimuth_rad),
                sigma_rad.to_degrees()
            ),
            Self::Lost => HEADING_LOST_TEXT.to_string(),
            status => status.word().to_string(),
        }
    }

    /// "n/a", "determined", "lost" or "undetermined".
    pub fn word(self) -> &'static str {
        match self {
            Self::Placeholder => "n/a",
            Self::Determined => "determined",
            Self::Lost => "lost",
            Self::Undetermined => "undetermined",
        }
    }
}

/// One station survey for people: number, span, the three drilling angles
/// with their 1-sigma (azimuth "undetermined" when its sigma or flag says
/// so), correlations, still quality and flags.
pub fn station_text(s: &StationSurvey) -> String {
    let [inc, _, tf] = s.angles.map(f64::from);
    let [s_inc, _, s_tf] = s.angles_std.map(f64::from);
    let azimuth = station_azimuth_text(s);
    let span_s = f64::from(s.end_sample.wrapping_sub(s.start_sample)) * SAMPLE_INTERVAL_S;
    let names = [
        (station_flags::MAGNETIC_FREE, "magnetic-free"),
        (station_flags::AZIMUTH_UNDETERMINED, "azimuth undetermined"),
        (station_flags::MAX_DURATION, "longest station reached"),
        (station_flags::NEAR_VERTICAL, "near vertical"),
        (station_flags::SOLUTION_INVALID, "INVALID"),
        (station_flags::REQUESTED, "requested"),
        (station_flags::INDEXING_DWELL, "indexing dwell"),
        (station_flags::MOTION_SEEN, "gyros saw it turn"),
        (station_flags::HEADING_LOST, "heading lost"),
        (station_flags::UNCALIBRATED, "uncalibrated"),
    ];
    let flags: Vec<&str> = names
        .iter()
        .filter(|(bit, _)| s.flags & bit != 0)
        .map(|(_, name)| *name)
        .collect();
    let corr = |r: f32| {
        if r.is_nan() {
            "n/a".to_string()
        } else {
            format!("{r:.3}")
        }
    };
    format!(
        "station {} samples {}..{} ({span_s:.2} s still): inclination {}, azimuth {azimuth}, \
         toolface {} (1 sigma); correlations inc-azi {} inc-tf {} azi-tf {}; \
         still quality {:.2}; {}",
        s.station,
        s.start_sample,
        s.end_sample,
        angle_with_sigma(inc.to_degrees(), s_inc),
        angle_with_sigma(
            if tf.is_finite() {
                deg_0_360(tf)
            } else {
                f64::NAN
            },
            s_tf
        ),
        corr(s.correlations[0]),
        corr(s.correlations[1]),
        corr(s.correlations[2]),
        s.still_quality,
        flags.join(", ")
    )
}

/// The probe's ACK or NAK to a command as a person reads it
/// (`host-sim probe`, the dashboard).
pub fn reply_text(reply: &Reply) -> String {
    let version = match reply.config_version {
        0 => "defaults (never stored)".to_string(),
        v => format!("version {v}"),
    };
    let why = match reply.status {
        ReplyStatus::Ack => return format!("ACK, configuration {version}"),
        ReplyStatus::Nak(NakReason::OutOfRange) => {
            let field = Field::from_byte(reply.detail)
                .map_or_else(|| format!("field {}", reply.detail), |f| f.name().into());
            format!("out of range ({field})")
        }
        ReplyStatus::Nak(NakReason::Busy) => "busy (not while surveying)".into(),
        ReplyStatus::Nak(NakReason::NotReady) => "not ready (still aligning)".into(),
        ReplyStatus::Nak(NakReason::NotStill) => "not still (no station in progress)".into(),
        ReplyStatus::Nak(NakReason::StorageFailed) => {
            "the probe could not store it (previous configuration kept)".into()
        }
        ReplyStatus::Nak(reason) => format!("{reason:?}"),
    };
    format!("NAK {why}, configuration {version}")
}

/// The navigation mode as a short word for the display, padded to six
/// characters (the live status line's column; trim it elsewhere).
pub fn mode_name(mode: u8) -> &'static str {
    match mode {
        nav_mode::INITIALISING => "init  ",
        nav_mode::COARSE_ALIGNMENT => "coarse",
        nav_mode::FINE_ALIGNMENT => "fine  ",
        nav_mode::NAVIGATING => "nav   ",
        _ => "?     ",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::conventions::DEG;
    use mwd_core::protocol::Payload;

    #[test]
    fn azimuths_read_in_0_to_360() {
        assert_eq!(deg_0_360(-90.0 * DEG), 270.0);
        assert!((deg_0_360(725.0 * DEG) - 5.0).abs() < 1e-9);
        assert_eq!(deg_0_360(-1e-18), 0.0);
        assert!(deg_0_360(-1e-18) < 360.0);
    }

    #[test]
    fn an_undetermined_azimuth_is_never_a_number() {
        assert_eq!(azimuth_text(1.0, f64::INFINITY, 2), "undetermined");
        assert_eq!(azimuth_text(1.0, 25.0 * DEG, 2), "undetermined");
        assert_eq!(azimuth_text(f64::NAN, 0.1, 2), "n/a");
        assert_eq!(azimuth_text(1.0, f64::NAN, 2), "n/a");
        assert_eq!(
            azimuth_text(-30.0 * DEG, 1.5 * DEG, 2),
            "330.00 +- 1.50 deg (1 sigma)"
        );
    }

    #[test]
    fn a_station_reads_with_its_sigmas_and_never_an_undetermined_azimuth() {
        let Payload::Station(mut s) = mwd_core::protocol::example::station_survey() else {
            unreachable!()
        };
        let text = station_text(&s);
        assert!(
            text.contains("station 3 samples 24000..27599 (179.95 s still)"),
            "{text}"
        );
        assert!(text.contains("inclination 45.000 +- 0.050 deg"), "{text}");
        assert!(text.contains("azimuth 120.000 +- 1.200 deg"), "{text}");
        assert!(text.contains("toolface 300.000 +- 0.070 deg"), "{text}");
        assert!(text.contains("magnetic-free"), "{text}");
        s.flags |= station_flags::AZIMUTH_UNDETERMINED;
        s.angles_std[1] = f32::INFINITY;
        s.correlations[0] = f32::NAN;
        let text = station_text(&s);
        assert!(
            text.contains("azimuth undetermined") && !text.contains("120.0"),
            "{text}"
        );
        assert!(text.contains("inc-azi n/a"), "{text}");
        assert!(!text.contains("heading lost"), "{text}");
        // Lost since the last tie-in: the reason comes with the word.
        s.flags |= station_flags::HEADING_LOST;
        let text = station_text(&s);
        assert!(
            text.contains(&format!("azimuth {HEADING_LOST_TEXT}")) && !text.contains("120.0"),
            "{text}"
        );
        assert!(
            text.contains("; magnetic-free, azimuth undetermined"),
            "{text}"
        );
        assert!(text.ends_with(", heading lost"), "{text}");
    }
}
