//! What the model runs on: the survey's stations, the site and model
//! parameters, and the check of a survey before a run; with what is
//! computed once from them (each station's sines and cosines, the site's
//! derived terms) and read by every source's weighting function.
use super::term_table::DataError;

/// Earth rate, rad/s (the gyro weighting functions' `EarthRate`).
pub const EARTH_RATE: f64 = 7.292_115e-5;

/// Site and model parameters the weighting functions need.
#[derive(Clone, Copy, Debug)]
pub struct Site {
    /// Gravity, m/s^2.
    pub gravity: f64,
    /// Total field, nT.
    pub b_total: f64,
    /// Dip, rad.
    pub dip: f64,
    /// Declination, rad: magnetic azimuth = true azimuth - declination
    /// (grid convergence is not modelled; it is zero for the test wells).
    pub declination: f64,
    /// Inclination below which a station counts as vertical, rad.
    pub vertical_limit: f64,
    /// Latitude, rad (gyro terms).
    pub latitude: f64,
    /// `NoiseReductionFactor` of the gyro random-noise term GXY-RN (1: one
    /// measurement per station).
    pub gyro_noise_reduction: f64,
}

/// A survey station: MD and TVD in metres, angles in radians.
#[derive(Clone, Copy, Debug)]
pub struct Station {
    pub md: f64,
    pub inc: f64,
    pub azi: f64,
    pub tvd: f64,
    /// Gravity toolface (rad), when the survey gives it: the probe's
    /// `PRB-GXB`/`PRB-GZB` weights
    /// ([`probe_weighting`](super::probe_weighting)) use it.
    pub toolface: Option<f64>,
}

/// Checks a survey before [`run`](super::run): at least a tie-on, every
/// value finite, MD strictly increasing, inclination within 0..=180 deg.
/// `run` itself assumes this (a repeated MD would make a zero-length leg;
/// a non-finite value would spread NaN through every later station).
pub fn check_stations(stations: &[Station]) -> Result<(), DataError> {
    if stations.is_empty() {
        return Err(DataError("survey: no stations".into()));
    }
    for (k, s) in stations.iter().enumerate() {
        if ![s.md, s.inc, s.azi, s.tvd].iter().all(|x| x.is_finite()) {
            return Err(DataError(format!("survey station {k}: non-finite value")));
        }
        if !(0.0..=std::f64::consts::PI).contains(&s.inc) {
            return Err(DataError(format!(
                "survey station {k}: inclination {} deg outside 0..180",
                s.inc.to_degrees()
            )));
        }
        if k > 0 && s.md <= stations[k - 1].md {
            return Err(DataError(format!(
                "survey station {k}: MD {} m not beyond the previous {} m",
                s.md,
                stations[k - 1].md
            )));
        }
    }
    Ok(())
}

/// Sines and cosines of a station's inclination, true azimuth and magnetic
/// azimuth, computed once per station: every error source's weighting, the
/// leg tangents and their derivatives all read them (a profile of the
/// 10,001-station bench had most of its time in `sincos` while each source
/// recomputed them).
#[derive(Clone, Copy, Debug)]
pub(super) struct StationTrig {
    pub(super) sin_inc: f64,
    pub(super) cos_inc: f64,
    pub(super) sin_azi: f64,
    pub(super) cos_azi: f64,
    /// Of the magnetic azimuth `azi - declination`.
    pub(super) sin_mag_azi: f64,
    pub(super) cos_mag_azi: f64,
}

impl StationTrig {
    pub(super) fn of(s: &Station, site: &Site) -> Self {
        let (sin_inc, cos_inc) = s.inc.sin_cos();
        let (sin_azi, cos_azi) = s.azi.sin_cos();
        let (sin_mag_azi, cos_mag_azi) = (s.azi - site.declination).sin_cos();
        Self {
            sin_inc,
            cos_inc,
            sin_azi,
            cos_azi,
            sin_mag_azi,
            cos_mag_azi,
        }
    }
}

/// The site with the quantities the weighting functions derive from it,
/// computed once per run instead of per source and station (`tan` of the
/// dip was 16 % of the bench's profile). Reads as a [`Site`] (`Deref`).
#[derive(Clone, Copy, Debug)]
pub(super) struct SiteTerms {
    site: Site,
    /// tan(dip).
    pub(super) tan_dip: f64,
    /// Horizontal field B cos(dip), nT.
    pub(super) b_horizontal: f64,
    /// Horizontal earth rate Omega cos(latitude), rad/s.
    pub(super) horizontal_earth_rate: f64,
}

impl SiteTerms {
    pub(super) fn of(site: &Site) -> Self {
        Self {
            site: *site,
            tan_dip: site.dip.tan(),
            b_horizontal: site.b_total * site.dip.cos(),
            horizontal_earth_rate: EARTH_RATE * site.latitude.cos(),
        }
    }
}

impl std::ops::Deref for SiteTerms {
    type Target = Site;
    fn deref(&self) -> &Site {
        &self.site
    }
}
