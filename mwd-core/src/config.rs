//! The probe's configuration: everything the host sets over the uplink
//! (site, tie-in, both parts' calibrations, still-detection settings), its
//! defaults, how a setting command changes it, and its record in flash
//! ([`record`]: fixed size, versioned, CRC-protected).
//!
//! The defaults are what the probe did before it could be configured: the
//! paper's Harbin site, no tie-in (static alignment), no calibration
//! correction, and the still detector's and navigator's constants. A
//! `version` of 0 means "the defaults, never stored"; every change the
//! probe accepts raises it, and the record's version is this number, so
//! the newest slot in flash is the one with the highest.

pub mod record;

use crate::calibration::ProbeCalibration;
use crate::earth::Position;
use crate::probe::navigator::{MAX_STATION_SAMPLES, STATION_ZUPT_VARIANCE};
use crate::probe::still::{ENTER_EPOCHS, Z_ENTER, Z_STAY};
use crate::probe::{TieIn, TieInAngle, TieInError};
use crate::protocol::uplink::{Command, Field, StillSettings};

/// Everything the probe is told before it goes in the hole.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeConfig {
    /// 0 for the defaults; raised by each accepted change.
    pub version: u32,
    pub site: Position,
    /// `None`: the static alignment.
    pub tie_in: Option<TieIn>,
    pub calibration: ProbeCalibration,
    pub still: StillSettings,
}

impl Default for ProbeConfig {
    fn default() -> Self {
        Self {
            version: 0,
            site: Position::paper_site(),
            tie_in: None,
            calibration: ProbeCalibration::default(),
            still: default_still_settings(),
        }
    }
}

/// The still detector's and navigator's constants as settings.
pub fn default_still_settings() -> StillSettings {
    StillSettings {
        z_enter: Z_ENTER as f32,
        z_stay: Z_STAY as f32,
        enter_epochs: ENTER_EPOCHS as u16,
        max_station_samples: MAX_STATION_SAMPLES,
        zupt_velocity_sigma: libm::sqrt(STATION_ZUPT_VARIANCE) as f32,
    }
}

/// What a command did to the configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Applied {
    /// A setting changed; the version was raised: store it.
    Changed,
    /// A setting command that set what was already there: nothing to
    /// store (no flash wear).
    Unchanged,
    /// Not a setting (an action such as re-align or reboot).
    NotASetting,
}

/// The uplink field the navigator's tie-in check names.
pub fn tie_in_field(error: TieInError) -> Field {
    let angle = |a| match a {
        TieInAngle::Inclination => Field::Inclination,
        TieInAngle::Azimuth => Field::Azimuth,
        TieInAngle::Toolface => Field::Toolface,
    };
    let sigma = |a| match a {
        TieInAngle::Inclination => Field::InclinationSigma,
        TieInAngle::Azimuth => Field::AzimuthSigma,
        TieInAngle::Toolface => Field::ToolfaceSigma,
    };
    match error {
        TieInError::AngleNotFinite(a) | TieInError::AngleOutOfRange(a) => angle(a),
        TieInError::NearVertical => Field::Inclination,
        TieInError::SigmaNotPositive(a) | TieInError::SigmaTooLarge(a) => sigma(a),
    }
}

impl ProbeConfig {
    /// Applies a decoded command. A setting the wire accepted can still be
    /// refused here: a tie-in the navigator cannot start from
    /// (`TieIn::new`), named by its field. The configuration is unchanged
    /// on error.
    pub fn apply(&mut self, command: &Command) -> Result<Applied, Field> {
        let mut next = *self;
        match command {
            Command::SetSite(site) => next.site = *site,
            Command::SetTieIn { angles, sigma } => {
                next.tie_in = Some(TieIn::new(*angles, *sigma).map_err(tie_in_field)?);
            }
            Command::ClearTieIn => next.tie_in = None,
            Command::SetCalibration { part, accel, gyro } => {
                let part = usize::from(*part);
                let (Some(a), Some(g)) = (
                    next.calibration.accel.get_mut(part),
                    next.calibration.gyro.get_mut(part),
                ) else {
                    return Err(Field::Part);
                };
                (*a, *g) = (*accel, *gyro);
            }
            Command::SetStillSettings(s) => next.still = *s,
            Command::Realign
            | Command::StartSurveying
            | Command::TakeStation
            | Command::IndexToolface(_)
            | Command::ReportConfig
            | Command::Reboot => return Ok(Applied::NotASetting),
        }
        if next == *self {
            return Ok(Applied::Unchanged);
        }
        // Saturating: 4e9 changes would wear the flash out long before.
        next.version = self.version.saturating_add(1);
        *self = next;
        Ok(Applied::Changed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{DrillingAngles, DEG};
    use crate::protocol::uplink::fields;

    #[test]
    fn the_defaults_are_the_constants_and_within_the_wire_ranges() {
        let c = ProbeConfig::default();
        assert_eq!((c.version, c.tie_in), (0, None));
        assert_eq!(c.site, Position::paper_site());
        let s = c.still;
        assert!((fields::Z_ENTER.0..=fields::Z_ENTER.1).contains(&s.z_enter));
        assert!(s.z_stay >= s.z_enter && s.z_stay <= fields::MAX_Z_STAY);
        assert_eq!((s.enter_epochs, s.max_station_samples), (20, 6000));
        assert!((s.zupt_velocity_sigma - 0.01).abs() < 1e-9);
    }

    #[test]
    fn settings_raise_the_version_actions_and_repeats_do_not() {
        let mut c = ProbeConfig::default();
        let site = Command::SetSite(Position::from_degrees(30.0, 50.0, 10.0));
        assert_eq!(c.apply(&site), Ok(Applied::Changed));
        assert_eq!(c.version, 1);
        assert_eq!(c.apply(&site), Ok(Applied::Unchanged));
        assert_eq!(c.apply(&Command::Reboot), Ok(Applied::NotASetting));
        assert_eq!(c.apply(&Command::ClearTieIn), Ok(Applied::Unchanged));
        assert_eq!(c.version, 1);
        assert_eq!(c.site.lat, 30.0 * DEG);
    }

    #[test]
    fn the_navigators_tie_in_limits_name_their_field() {
        let mut c = ProbeConfig::default();
        let angles = DrillingAngles {
            inclination: 90.0 * DEG,
            azimuth: 10.0 * DEG,
            toolface: 0.0,
        };
        let sigma = DrillingAngles {
            inclination: 0.1 * DEG,
            azimuth: 1.0 * DEG,
            toolface: 0.2 * DEG,
        };
        let ok = Command::SetTieIn { angles, sigma };
        assert_eq!(c.apply(&ok), Ok(Applied::Changed));
        let before = c;
        let near_vertical = Command::SetTieIn {
            angles: DrillingAngles {
                inclination: 0.5 * DEG,
                ..angles
            },
            sigma,
        };
        assert_eq!(c.apply(&near_vertical), Err(Field::Inclination));
        let loose = Command::SetTieIn {
            angles,
            sigma: DrillingAngles {
                azimuth: 40.0 * DEG,
                ..sigma
            },
        };
        assert_eq!(c.apply(&loose), Err(Field::AzimuthSigma));
        assert_eq!(c, before, "unchanged on error");
        assert_eq!(c.tie_in.map(|t| t.angles()), Some(angles));
    }
}
