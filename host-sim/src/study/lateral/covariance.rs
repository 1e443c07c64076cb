//! The lateral study's fast path: covariance analysis. One run per grade
//! and well with error-free sensors
//! ([`covariance_analysis`](crate::study::drilling_run::covariance_analysis)) gives the sigmas the probe and
//! the survey would report; no noise is drawn, so one run answers what the
//! Monte Carlo answers with hundreds, and the Monte Carlo checks it: the
//! predicted TD horizontal 1-sigma against the RMS of the runs' TD errors,
//! the predicted station azimuth sigmas against the RMS azimuth error.
//! Also the sweep over gyro bias instability and ARW.

use super::summary::GradeWellSummary;
use crate::study::drilling_run::{covariance_analysis, RunConfig, RunOutcome};
use crate::study::grade::Grade;
use crate::study::stats::rms;
use crate::survey::listing::drilling::station_valid;
use mwd_core::protocol::frame::station_flags;
use serde::Serialize;

/// One grade and well by covariance analysis.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CovariancePrediction {
    pub grade: String,
    pub well: String,
    pub lateral_length_m: f64,
    /// Predicted TD horizontal 1-sigma: sqrt of the NE covariance's trace.
    pub td_horizontal_1_sigma_m: Option<f64>,
    pub td_semi_major_1_sigma_m: Option<f64>,
    pub td_semi_major_1_sigma_per_1000_m: Option<f64>,
    /// RMS of the determined stations' predicted azimuth sigmas (the RMS
    /// error a consistent Monte Carlo shows over the same stations).
    pub rms_station_azimuth_sigma_deg: Option<f64>,
    pub rms_station_inclination_sigma_deg: Option<f64>,
    /// Stations whose azimuth the probe flags undetermined.
    pub azimuth_undetermined_stations: usize,
    /// Along MD: truth MD, azimuth sigma (deg), horizontal 1-sigma (m).
    pub along_md: Vec<(f64, Option<f64>, Option<f64>)>,
    /// The survey method's own TD horizontal error on this well (m):
    /// minimum curvature through the true angles at the stations against
    /// the drilled path ([`RunOutcome::method_td_error_m`]); the XCLA and
    /// XCLH terms' predicted 1-sigma, and the TD 1-sigma without them.
    pub method_td_error_m: Option<f64>,
    pub td_method_1_sigma_m: Option<f64>,
    pub td_without_method_1_sigma_m: Option<f64>,
    /// Why there is no TD figure, if there is none.
    pub td_note: Option<String>,
    pub cpu_s: Option<f64>,
    pub wall_s: f64,
}

impl CovariancePrediction {
    /// The prediction from the error-free run `o`.
    pub fn of(grade: &str, well: &str, lateral_length_m: f64, o: &RunOutcome) -> Self {
        let (mut azi, mut inc, mut undetermined) = (Vec::new(), Vec::new(), 0);
        let mut along_md = Vec::new();
        for st in &o.stations {
            let sd = st.survey.angles_std.map(f64::from);
            if !station_valid(&st.survey) || !sd[0].is_finite() {
                continue;
            }
            inc.push(sd[0].to_degrees());
            let azimuth = (st.survey.flags & station_flags::AZIMUTH_UNDETERMINED == 0
                && sd[1].is_finite())
            .then(|| sd[1].to_degrees());
            match azimuth {
                Some(a) => azi.push(a),
                None => undetermined += 1,
            }
            let position = st.position.map(|p| p.sigma_horizontal());
            along_md.push((st.truth_md, azimuth, position));
        }
        let td = o.td.map(|t| t.position());
        Self {
            grade: grade.into(),
            well: well.into(),
            lateral_length_m,
            td_horizontal_1_sigma_m: td.map(|p| p.sigma_horizontal()),
            td_semi_major_1_sigma_m: td.map(|p| p.semi_major()),
            td_semi_major_1_sigma_per_1000_m: td
                .map(|p| p.semi_major() * 1000.0 / lateral_length_m),
            rms_station_azimuth_sigma_deg: rms(&azi),
            rms_station_inclination_sigma_deg: rms(&inc),
            azimuth_undetermined_stations: undetermined,
            along_md,
            method_td_error_m: o.method_td_error_m(),
            td_method_1_sigma_m: o.td.map(|t| t.method_only([0.0; 2]).sigma_horizontal()),
            td_without_method_1_sigma_m: o
                .td
                .map(|t| t.without_method([0.0; 2]).sigma_horizontal()),
            td_note: o.td_note.clone(),
            cpu_s: o.cpu_s,
            wall_s: o.elapsed_s,
        }
    }
}

/// The covariance analysis against the Monte Carlo of the same grade and
/// well: each ratio is predicted / observed, 1 for a filter that is
/// neither optimistic nor pessimistic; the check asks for
/// |ratio - 1| <= 10 % ([`AGREEMENT_TOLERANCE`]).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Agreement {
    pub grade: String,
    pub well: String,
    /// Predicted TD horizontal 1-sigma / RMS of the runs' TD errors.
    pub td_ratio: Option<f64>,
    /// RMS predicted station azimuth sigma / RMS station azimuth error.
    pub azimuth_ratio: Option<f64>,
    /// The same as `td_ratio` without the survey method on either side
    /// ([`TdSummary::without_method`](super::summary::TdSummary)).
    pub td_without_method_ratio: Option<f64>,
    pub within_10_percent: Option<bool>,
}

/// Tolerance of the agreement check: the predicted 1-sigma within 10 % of
/// the Monte Carlo's RMS error.
pub const AGREEMENT_TOLERANCE: f64 = 0.10;

pub fn agreement(c: &CovariancePrediction, m: &GradeWellSummary) -> Agreement {
    let ratio = |p: Option<f64>, o: Option<f64>| match (p, o) {
        (Some(p), Some(o)) if o > 0.0 => Some(p / o),
        _ => None,
    };
    let td_ratio = ratio(c.td_horizontal_1_sigma_m, m.td.rms_horizontal_error_m);
    let azimuth_ratio = ratio(c.rms_station_azimuth_sigma_deg, m.rms_station_azimuth_deg);
    let td_without_method_ratio = ratio(
        c.td_without_method_1_sigma_m,
        m.td.without_method.rms_horizontal_error_m,
    );
    Agreement {
        grade: c.grade.clone(),
        well: c.well.clone(),
        td_ratio,
        azimuth_ratio,
        td_without_method_ratio,
        within_10_percent: td_ratio.map(|r| (r - 1.0).abs() <= AGREEMENT_TOLERANCE),
    }
}

/// The covariance analysis of `grade` on `config`'s well (seed `seed`:
/// the vibration and orienter steps of that run).
pub fn predict(
    config: &RunConfig,
    grade: &Grade,
    well: &str,
    lateral_length_m: f64,
    seed: u64,
) -> Result<CovariancePrediction, String> {
    let config = RunConfig {
        grade: grade.clone(),
        ..config.clone()
    };
    covariance_analysis(&config, seed)
        .map(|o| CovariancePrediction::of(grade.name(), well, lateral_length_m, &o))
        .map_err(|e| format!("{}, {well}: {e:#}", grade.name()))
}

/// A sweep's grid: the gyros' bias instability (deg/h) and ARW
/// (deg/sqrt(h)), log-spaced.
#[derive(Clone, Debug, Serialize)]
pub struct SweepGrid {
    pub bias_deg_per_h: Vec<f64>,
    pub arw_deg_per_sqrt_h: Vec<f64>,
}

impl SweepGrid {
    /// `n` log-spaced values from `lo` to `hi` (both > 0, n >= 2).
    pub fn log_spaced(lo: f64, hi: f64, n: usize) -> Vec<f64> {
        let n = n.max(2);
        let (a, b) = (lo.ln(), hi.ln());
        (0..n)
            .map(|k| (a + (b - a) * k as f64 / (n - 1) as f64).exp())
            .collect()
    }

    /// Four decades of bias (0.001-10 deg/h) and three and a half of ARW
    /// (0.001-3 deg/sqrt(h)): navigation grade to below the SCC1300.
    pub fn default_grid(points: usize) -> Self {
        Self {
            bias_deg_per_h: Self::log_spaced(0.001, 10.0, points),
            arw_deg_per_sqrt_h: Self::log_spaced(0.001, 3.0, points),
        }
    }
}

/// The sweep's result on one well: [bias index][arw index].
#[derive(Clone, Debug, Serialize)]
pub struct SweepResult {
    pub base_grade: String,
    pub well: String,
    pub grid: SweepGrid,
    /// Predicted TD horizontal 1-sigma per 1000 m of lateral (m).
    pub td_sigma_per_1000_m: Vec<Vec<Option<f64>>>,
    /// RMS predicted station azimuth sigma (deg).
    pub azimuth_sigma_deg: Vec<Vec<Option<f64>>>,
    pub failures: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_spacing_hits_both_ends() {
        let v = SweepGrid::log_spaced(0.001, 10.0, 5);
        assert_eq!(v.len(), 5);
        assert!((v[0] - 0.001).abs() < 1e-15 && (v[4] - 10.0).abs() < 1e-12);
        assert!((v[1] / v[0] - 10.0).abs() < 1e-9);
    }

    #[test]
    fn agreement_is_prediction_over_observation() {
        let c = CovariancePrediction {
            td_horizontal_1_sigma_m: Some(1.05),
            rms_station_azimuth_sigma_deg: Some(0.2),
            ..Default::default()
        };
        let mut m = GradeWellSummary::default();
        m.td.rms_horizontal_error_m = Some(1.0);
        m.rms_station_azimuth_deg = Some(0.25);
        let a = agreement(&c, &m);
        assert!((a.td_ratio.unwrap() - 1.05).abs() < 1e-12);
        assert!((a.azimuth_ratio.unwrap() - 0.8).abs() < 1e-12);
        assert_eq!(a.within_10_percent, Some(true));
        // no Monte Carlo TD: undetermined, not a pass
        m.td.rms_horizontal_error_m = None;
        assert_eq!(agreement(&c, &m).within_10_percent, None);
    }
}
