//! One drilling run's survey against its truth: a station's horizontal
//! position ([`PositionCheck`]), a station's angles ([`StationCheck`]) and
//! the run's TD ([`TdCheck`]), as the drilling studies count them.

use crate::survey::listing::ellipse::ne_mahalanobis2;
use mwd_core::probe::StationLink;
use mwd_core::protocol::StationSurvey;

/// A station's surveyed horizontal position against the truth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionCheck {
    /// North and east error, m.
    pub error_ne: [f64; 2],
    /// Predicted NE covariance (m^2): north-north, east-east, north-east.
    pub cov_ne: [f64; 3],
}

impl PositionCheck {
    /// The predicted horizontal 1-sigma: sqrt of the covariance's trace
    /// (the RMS radial error a covariance predicts).
    pub fn sigma_horizontal(&self) -> f64 {
        (self.cov_ne[0] + self.cov_ne[1]).max(0.0).sqrt()
    }

    /// The 1-sigma semi-major axis of the NE ellipse: the square root of
    /// the covariance's larger eigenvalue.
    pub fn semi_major(&self) -> f64 {
        let [nn, ee, ne] = self.cov_ne;
        let half_trace = 0.5 * (nn + ee);
        let root = (0.25 * (nn - ee) * (nn - ee) + ne * ne).sqrt();
        (half_trace + root).max(0.0).sqrt()
    }

    pub fn error_horizontal(&self) -> f64 {
        self.error_ne[0].hypot(self.error_ne[1])
    }

    /// The error's squared Mahalanobis distance in the covariance;
    /// `None` where the covariance is singular or not a number.
    pub fn mahalanobis2(&self) -> Option<f64> {
        ne_mahalanobis2(self.cov_ne, self.error_ne)
    }
}

/// A station survey and the truth at its last still sample.
#[derive(Clone, Copy, Debug)]
pub struct StationCheck {
    pub survey: StationSurvey,
    /// Errors of inclination, azimuth, toolface (rad, wrapped).
    pub error: [f64; 3],
    pub truth_md: f64,
    /// The azimuth sigma (rad) just before the station's first
    /// zero-velocity update, as the survey's azimuth chain takes it
    /// ([`StationCollector::push_station`]).
    pub azimuth_sigma_before: Option<f64>,
    /// The azimuth error (rad, wrapped) of the same solution: with its
    /// sigma, where the station starts from (`super::lateral::consistency`).
    pub azimuth_error_before: Option<f64>,
    /// The probe's link of this station's errors to the previous
    /// station's (`mwd_core::probe::station_link`), as the survey takes it.
    pub link: Option<StationLink>,
    /// The survey's position here; `None` where the station is not in
    /// the survey (skipped) or its position is undetermined.
    pub position: Option<PositionCheck>,
}

/// The run's TD: the last station's horizontal position against the truth.
#[derive(Clone, Copy, Debug)]
pub struct TdCheck {
    /// North and east error, m.
    pub error_ne: [f64; 2],
    /// Squared Mahalanobis distance in the predicted NE covariance.
    pub d2: f64,
    /// That covariance (m^2): north-north, east-east, north-east.
    pub cov_ne: [f64; 3],
    /// The survey method's part of it (XCLA, XCLH), same layout.
    pub method_cov_ne: [f64; 3],
}

impl TdCheck {
    pub fn position(&self) -> PositionCheck {
        PositionCheck {
            error_ne: self.error_ne,
            cov_ne: self.cov_ne,
        }
    }

    /// The TD without the survey method: the error less the method's own
    /// (`method_error_ne`, [`RunOutcome::method_td_error_ne`]) against the
    /// covariance less the method's terms. What the sensors and the depth
    /// log did, against what the probe and the depth terms predict.
    pub fn without_method(&self, method_error_ne: [f64; 2]) -> PositionCheck {
        PositionCheck {
            error_ne: std::array::from_fn(|j| self.error_ne[j] - method_error_ne[j]),
            cov_ne: std::array::from_fn(|j| self.cov_ne[j] - self.method_cov_ne[j]),
        }
    }

    /// The survey method's part alone: its own error against its terms.
    pub fn method_only(&self, method_error_ne: [f64; 2]) -> PositionCheck {
        PositionCheck {
            error_ne: method_error_ne,
            cov_ne: self.method_cov_ne,
        }
    }
}
