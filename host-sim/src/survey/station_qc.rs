//! Station quality control as gyro-survey practice checks a station: what
//! the sensors measured while the probe was still, against what the earth
//! gives at the site.
//!
//! - **Total gravity**: the magnitude of the mean calibrated specific
//!   force over the station's samples against the normal gravity at the
//!   site's latitude and height (`mwd_core::earth::normal_gravity`).
//! - **Earth rate**: the two cross-axis gyros' mean rates against the
//!   earth rate the station's own inclination, azimuth and toolface put on
//!   those axes (`omega_b = C_n^b Omega_n`, `conventions::dcm_from_euler`,
//!   `earth::earth_rate_n`). With gyros only across the tool axis the
//!   horizontal earth rate's magnitude cannot be formed in a lateral (the
//!   tool axis's share is not measured), so the check is the residual of
//!   the measured rates against the station's attitude: a wrong azimuth,
//!   an uncalibrated bias or a moving probe show in it.
//!
//! Tolerances come from the tool model's own terms (the PROBE-SCC1300
//! table): gravity 3 sigma of the accelerometers' residual bias, station
//! noise and scale factor (AXYZ-ZB, AXYZ-ZN, AXYZ-SF) along gravity; the
//! earth-rate residual the 99.73 % radius of a 2-D normal with each axis's
//! sigma from the gyro bias and station noise (PRB-GXB, PRB-GZB, PRB-GN)
//! and the station azimuth's own sigma. A model without those terms gives
//! no tolerance, and the check is not made.

use crate::survey::iscwsa::ErrorTerm;
use mwd_core::calibration::ProbeCalibration;
use mwd_core::conventions::{dcm_from_euler, DrillingAngles};
use mwd_core::earth::{earth_rate_n, normal_gravity, Position, EARTH_RATE};
use mwd_core::probe::raw::body_sample;
use mwd_core::protocol::{RawSample, StationSurvey};
use mwd_core::sensor_units::STANDARD_GRAVITY;
use nalgebra::Vector3;
use std::collections::VecDeque;

/// The radius holding 99.73 % of a 2-D standard normal: sqrt(-2 ln(0.0027)).
const RADIUS_2D_9973: f64 = 3.4393;

/// The most samples kept while waiting for a station's frame (which comes
/// after its samples): 20 minutes at 20 Hz, four times the longest station
/// the still settings' default allows.
const KEPT_SAMPLES: usize = 24_000;

/// The checks' tolerances (SI), from the tool model's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QcTolerances {
    /// |measured - theoretical| total gravity, m/s^2.
    pub gravity_m_s2: f64,
    /// Per-axis 1-sigma of a station's mean cross-axis rate, rad/s.
    pub gyro_sigma_rad_s: f64,
}

impl QcTolerances {
    /// The per-axis gyro sigma in deg/h.
    pub fn gyro_sigma_deg_h(&self) -> f64 {
        deg_per_h(self.gyro_sigma_rad_s)
    }

    /// From a model's terms; `None` if it lacks the accelerometer or gyro
    /// terms (gravity is then not checked either: one rule for both).
    pub fn from_terms(terms: &[ErrorTerm], gravity: f64) -> Option<Self> {
        let si = |code: &str| {
            terms
                .iter()
                .find(|t| t.code == code)
                .map(|t| t.magnitude_si)
        };
        let (bias, noise, scale) = (si("AXYZ-ZB")?, si("AXYZ-ZN")?, si("AXYZ-SF")?);
        let gyro_bias = si("PRB-GXB")?.max(si("PRB-GZB")?);
        let gyro_noise = si("PRB-GN")?;
        Some(Self {
            gravity_m_s2: 3.0 * (bias.powi(2) + noise.powi(2) + (scale * gravity).powi(2)).sqrt(),
            // (the table's deg/hr, converted to rad/s)
            gyro_sigma_rad_s: gyro_bias.hypot(gyro_noise),
        })
    }
}

/// The checks of the stations of a capture: (station number, its last
/// sample, checks).
pub type CheckedStations = Vec<(u16, u32, StationQc)>;

/// One station's checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StationQc {
    /// Samples averaged.
    pub samples: u32,
    /// Measured total gravity, m/s^2, and its difference from the site's.
    pub gravity_m_s2: f64,
    pub gravity_error_m_s2: f64,
    pub gravity_tolerance_m_s2: f64,
    /// The cross-axis rates' residual against the earth rate the station's
    /// attitude predicts (its norm, rad/s), and the tolerance; `None` where
    /// the station's azimuth is undetermined.
    pub earth_rate_residual: Option<(f64, f64)>,
}

/// A rate in rad/s in deg/h, as gyro tolerances are quoted.
fn deg_per_h(rate_rad_s: f64) -> f64 {
    rate_rad_s.to_degrees() * 3600.0
}

impl StationQc {
    /// The gravity error in mg (of standard gravity).
    pub fn gravity_error_mg(&self) -> f64 {
        self.gravity_error_m_s2 / (STANDARD_GRAVITY * 1e-3)
    }

    /// The earth-rate residual and its tolerance in deg/h, where checked.
    pub fn earth_rate_deg_h(&self) -> Option<(f64, f64)> {
        self.earth_rate_residual
            .map(|(r, tol)| (deg_per_h(r), deg_per_h(tol)))
    }

    pub fn gravity_ok(&self) -> bool {
        self.gravity_error_m_s2.abs() <= self.gravity_tolerance_m_s2
    }

    pub fn earth_rate_ok(&self) -> Option<bool> {
        self.earth_rate_residual.map(|(r, tol)| r <= tol)
    }

    /// Whether every check made passed.
    pub fn ok(&self) -> bool {
        self.gravity_ok() && self.earth_rate_ok() != Some(false)
    }

    /// One word for a table: "ok", or what is out ("gravity", "earth-rate",
    /// "gravity+earth-rate").
    pub fn word(&self) -> &'static str {
        match (self.gravity_ok(), self.earth_rate_ok() != Some(false)) {
            (true, true) => "ok",
            (false, true) => "gravity",
            (true, false) => "earth-rate",
            (false, false) => "gravity+earth-rate",
        }
    }
}

/// Collects the calibrated samples of a capture and checks each station
/// as its frame arrives.
pub struct QcCollector {
    calibration: ProbeCalibration,
    site: Position,
    gravity: f64,
    tolerances: QcTolerances,
    /// (sample counter, cross-axis rates, specific force) since the last
    /// station, at most [`KEPT_SAMPLES`].
    samples: VecDeque<(u32, [f64; 2], Vector3<f64>)>,
    checked: CheckedStations,
}

impl QcCollector {
    pub fn new(calibration: ProbeCalibration, site: Position, tolerances: QcTolerances) -> Self {
        Self {
            calibration,
            site,
            gravity: normal_gravity(site.lat, site.height),
            tolerances,
            samples: VecDeque::new(),
            checked: Vec::new(),
        }
    }

    /// The site's normal gravity, m/s^2.
    pub fn gravity(&self) -> f64 {
        self.gravity
    }

    pub fn tolerances(&self) -> QcTolerances {
        self.tolerances
    }

    pub fn push_raw(&mut self, raw: &RawSample) {
        let Some(s) = body_sample(raw, &self.calibration) else {
            return;
        };
        if self.samples.len() == KEPT_SAMPLES {
            self.samples.pop_front();
        }
        self.samples
            .push_back((raw.sample_counter, s.gyro, s.specific_force));
    }

    /// Checks a station from its samples (if they were all received).
    pub fn push_station(&mut self, s: &StationSurvey) {
        let span = s.start_sample..=s.end_sample;
        let inside: Vec<_> = self
            .samples
            .iter()
            .filter(|(counter, ..)| span.contains(counter))
            .collect();
        let expected = s.end_sample.wrapping_sub(s.start_sample).wrapping_add(1);
        let complete = u32::try_from(inside.len()).ok() == Some(expected);
        if complete && !inside.is_empty() {
            let n = inside.len() as f64;
            let rates = inside
                .iter()
                .fold([0.0; 2], |a, (_, g, _)| [a[0] + g[0], a[1] + g[1]])
                .map(|v| v / n);
            let force = inside
                .iter()
                .fold(Vector3::zeros(), |a: Vector3<f64>, (_, _, f)| a + f)
                / n;
            let qc = self.check(s, rates, &force, expected);
            self.checked.push((s.station, s.end_sample, qc));
        }
        // the next station's samples come after this one's
        while self
            .samples
            .front()
            .is_some_and(|(counter, ..)| *counter <= s.end_sample)
        {
            self.samples.pop_front();
        }
    }

    fn check(&self, s: &StationSurvey, rates: [f64; 2], force: &Vector3<f64>, n: u32) -> StationQc {
        let t = &self.tolerances;
        let measured = force.norm();
        let [inc, azi, tf] = s.angles.map(f64::from);
        let azi_sigma = f64::from(s.angles_std[1]);
        let earth_rate_residual = azi_sigma.is_finite().then(|| {
            let angles = DrillingAngles {
                inclination: inc,
                azimuth: azi,
                toolface: tf,
            };
            let c_bn = dcm_from_euler(&angles.to_euler());
            let predicted = c_bn.transpose() * earth_rate_n(self.site.lat);
            let residual = (rates[0] - predicted.x).hypot(rates[1] - predicted.z);
            // the station's azimuth error turns the predicted horizontal
            // earth rate by as much
            let horizontal = EARTH_RATE * self.site.lat.cos();
            let sigma = t.gyro_sigma_rad_s.hypot(horizontal * azi_sigma);
            (residual, RADIUS_2D_9973 * sigma)
        });
        StationQc {
            samples: n,
            gravity_m_s2: measured,
            gravity_error_m_s2: measured - self.gravity,
            gravity_tolerance_m_s2: t.gravity_m_s2,
            earth_rate_residual,
        }
    }

    /// The stations checked: (station number, its last sample, checks).
    pub fn into_checked(self) -> CheckedStations {
        self.checked
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::conventions::Euler;

    fn tolerances() -> QcTolerances {
        QcTolerances {
            gravity_m_s2: 0.03,
            gyro_sigma_rad_s: (5.5f64).to_radians() / 3600.0,
        }
    }

    fn station(angles: [f64; 3], azi_sigma: f64) -> StationSurvey {
        StationSurvey {
            station: 3,
            start_sample: 100,
            end_sample: 199,
            angles: angles.map(|a| a as f32),
            angles_std: [0.001, azi_sigma as f32, 0.001],
            ..Default::default()
        }
    }

    /// A collector fed the exact rates and force of a still tool at `e`.
    fn check_at(e: &Euler, rate_bias: f64, force_scale: f64, s: &StationSurvey) -> StationQc {
        let site = Position::from_degrees(45.8, 126.7, 124.0);
        let qc = QcCollector::new(ProbeCalibration::default(), site, tolerances());
        let c_bn = dcm_from_euler(e);
        let w = c_bn.transpose() * earth_rate_n(site.lat);
        let f = c_bn.transpose() * Vector3::new(0.0, 0.0, -qc.gravity()) * force_scale;
        qc.check(s, [w.x + rate_bias, w.z], &f, 100)
    }

    #[test]
    fn a_still_tool_where_its_station_says_passes_and_a_wrong_one_fails() {
        let angles = DrillingAngles {
            inclination: 90f64.to_radians(),
            azimuth: 120f64.to_radians(),
            toolface: 30f64.to_radians(),
        };
        let e = angles.to_euler();
        let s = station([angles.inclination, angles.azimuth, angles.toolface], 0.01);
        let good = check_at(&e, 0.0, 1.0, &s);
        assert!(good.ok(), "{good:?}");
        assert!(good.gravity_error_m_s2.abs() < 1e-9);
        assert!(good.earth_rate_residual.unwrap().0 < 1e-12);
        // 5 mg more gravity than the site's: out
        let heavy = check_at(&e, 0.0, 1.005, &s);
        assert_eq!(heavy.word(), "gravity");
        // a gyro bias of 100 deg/h: out
        let biased = check_at(&e, 100f64.to_radians() / 3600.0, 1.0, &s);
        assert_eq!(biased.word(), "earth-rate");
        // the station says azimuth 300 deg, the tool points at 120: the
        // horizontal earth rate's share flips
        let wrong = station(
            [angles.inclination, 300f64.to_radians(), angles.toolface],
            0.01,
        );
        let flipped = check_at(&e, 0.0, 1.0, &wrong);
        assert!(flipped.earth_rate_residual.unwrap().0 > 15f64.to_radians() / 3600.0);
        // an undetermined azimuth: no earth-rate check, gravity still made
        let open = station(
            [angles.inclination, angles.azimuth, angles.toolface],
            f64::INFINITY,
        );
        let q = check_at(&e, 0.0, 1.0, &open);
        assert_eq!((q.earth_rate_ok(), q.ok()), (None, true));
    }

    #[test]
    fn the_probes_tool_model_gives_tolerances() {
        let model = crate::survey::listing::model("PROBE-SCC1300").unwrap();
        let terms = crate::survey::listing::terms(model).unwrap();
        let t = QcTolerances::from_terms(&terms, 9.806).unwrap();
        // 3 sigma of a 1 mg residual bias (AXYZ-ZB) and the rest: about 3 mg
        assert!((0.029..0.031).contains(&t.gravity_m_s2), "{t:?}");
        // hypot(2.1, 5.04) deg/h
        let deg_h = t.gyro_sigma_deg_h();
        assert!((deg_h - 2.1f64.hypot(5.038)).abs() < 0.01, "{deg_h}");
        let mwd = crate::survey::listing::model("ISCWSA MWD Rev5").unwrap();
        let none = crate::survey::listing::terms(mwd).unwrap();
        assert_eq!(QcTolerances::from_terms(&none, 9.806), None);
    }
}
