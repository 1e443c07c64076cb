//! ISCWSA wellbore position-uncertainty model (SPE 67616, Williamson 2000)
//! on the host: error sources as data (a term table read from CSV), the
//! weighting functions of the ISCWSA MWD Rev 5 model, and the propagation
//! of each source's error vectors to the NEV covariance at every station.
//!
//! Conventions (as in the ISCWSA example workbooks and SPE 67616):
//! * stations are (MD, inclination, true azimuth, TVD), MD/TVD in metres,
//!   angles in radians; the first station is the tie-on;
//! * the position change over the leg k-1 -> k is taken, for the
//!   derivatives, as the balanced-tangential
//!   `dr_k = (D_k - D_{k-1})/2 * (t_{k-1} + t_k)` with `t` the unit tangent;
//! * a source's error at station k is `e_k = sigma * (d dr_k/dp_k +
//!   d dr_{k+1}/dp_k) * w_k` with `w = (dD, dI, dA)/d eps` the weighting
//!   function; at the station of interest K only the leg before it counts;
//! * the tie-on's own inclination/azimuth error is carried by station 1
//!   (its leg-before weight covers the whole first course length), its depth
//!   error is not counted — this is what the published Rev 5 diagnostics
//!   show (e.g. the random XYM3E of well #1 at 1200 m); the Rev 4
//!   diagnostics take the tie-on as exact instead ([`TieOn`]);
//! * random sources: sum over stations of `e e^T`; systematic, per-well and
//!   global sources: the outer product of the summed vector (the same
//!   thing on a single well);
//! * at a station closer to vertical than the model's limit, a source
//!   whose azimuth weighting is singular uses its tabulated NEV
//!   "singularity" vector in place of `dr/dp * w`;
//! * the long-course-length terms XCLA/XCLH (SPE 187249) use the
//!   tangential form instead (see `xcl_vector`).
//!
//! Where the workbook's documentation formulas and its published numbers
//! disagree, the numbers win (each case checked against the diagnostic
//! block of the three test wells, `host-sim/tests/iscwsa_error_model.rs`):
//! XYM3E's azimuth weight is `-|cos I| sin A / sin I` (the 5.10 Model sheet
//! prints it without the minus sign), and an azimuth change out of a
//! vertical station does not count in XCLA.
//!
//! Weighting functions are looked up by the table's `Wt.Fn.` name; a name
//! not implemented here is reported in [`ModelResult::missing`], never
//! treated as zero. Implemented: DREF, DSF, DST, ABXY-TI1/2, ABZ,
//! ASXY-TI1/2/3, ASZ, MBXY-TI1/2, MBZ, MSXY-TI1/2/3, MSZ, AZ, DBH, AMIL,
//! SAGE, XYM1, XYM2, XYM3L/XYM3E, XYM4L/XYM4E, XCLA, XCLH (the Rev 5.10
//! MWD set; XCLA in both its pre-5.10 and 5.10 forms, [`XclAzimuth`]), and
//! SAG, XYM3, XYM4 (Rev 4), and the OWSG GYRO-MWD / GYRO-NS gyro and
//! accelerometer functions AXYZ-MIS/SF/ZB, GXY-B1/B2/G1/G4/RN (no
//! published covariances to check them against: tested only by closed
//! forms; the OWSG models are stated for inclinations up to 89 deg, and
//! GXY-B1/G4/RN grow without bound towards 90 deg); and this probe's own
//! PRB-GXB/GZB/GN ([`probe_weighting`]), valid through 90 deg. Not
//! implemented: the Rev 5.04 single `XCL` function.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

/// Propagation mode of an error source.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Propagation {
    Random,
    Systematic,
    PerWell,
    Global,
}

impl Propagation {
    fn parse(s: &str) -> Result<Self, String> {
        match s.trim() {
            "R" => Ok(Self::Random),
            "S" => Ok(Self::Systematic),
            "W" => Ok(Self::PerWell),
            "G" => Ok(Self::Global),
            other => Err(format!("unknown propagation mode {other:?}")),
        }
    }
}

/// One error source (a row of the term table).
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorTerm {
    pub code: String,
    /// Weighting-function name (`Wt.Fn.` column), e.g. `DSF`, `ABXY-TI1`.
    pub weighting: String,
    /// Magnitude as published, in `unit`.
    pub magnitude: f64,
    pub unit: String,
    /// Magnitude in the units the weighting functions use (degree terms in
    /// radians): the table's "converted" column.
    pub magnitude_si: f64,
    pub propagation: Propagation,
}

mod link_chain;
pub mod probe_model;
pub mod probe_station;
pub mod probe_weighting;
#[cfg(test)]
mod tests;

/// Error loading a term table or a data file.
#[derive(Debug)]
pub struct DataError(pub String);

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DataError {}

fn col(headers: &csv::StringRecord, name: &str) -> Result<usize, DataError> {
    headers
        .iter()
        .position(|h| h.trim() == name)
        .ok_or_else(|| DataError(format!("term table: no column {name:?}")))
}

fn num(field: Option<&str>, what: &str, line: u64) -> Result<f64, DataError> {
    let s = field.ok_or_else(|| DataError(format!("line {line}: missing {what}")))?;
    s.trim()
        .parse::<f64>()
        .map_err(|e| DataError(format!("line {line}: {what} {s:?}: {e}")))
}

/// Reads an ISCWSA term table (`Model` sheet as CSV, as in
/// `tests/data/iscwsa/mwd_rev5_04_model_terms.csv`).
pub fn load_term_table(path: &Path) -> Result<Vec<ErrorTerm>, DataError> {
    let rdr =
        csv::Reader::from_path(path).map_err(|e| DataError(format!("{}: {e}", path.display())))?;
    read_term_table(rdr, &path.display().to_string())
}

/// Reads a term table from text (an embedded table); `name` labels errors.
pub fn parse_term_table(text: &str, name: &str) -> Result<Vec<ErrorTerm>, DataError> {
    read_term_table(csv::Reader::from_reader(text.as_bytes()), name)
}

fn read_term_table<R: std::io::Read>(
    mut rdr: csv::Reader<R>,
    name: &str,
) -> Result<Vec<ErrorTerm>, DataError> {
    let headers = rdr
        .headers()
        .map_err(|e| DataError(format!("{}: {e}", name)))?
        .clone();
    let c_code = col(&headers, "Code")?;
    let c_wt = col(&headers, "Wt.Fn.")?;
    let c_mag = col(&headers, "Magnitude")?;
    let c_unit = col(&headers, "Units")?;
    let c_prop = col(&headers, "Prop.")?;
    // the MWD tables carry the converted magnitude; the OWSG sheets do not
    let c_si = col(&headers, "Convert Magnitudes Degrees to Radians").ok();
    let mut terms = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| DataError(format!("{}: {e}", name)))?;
        let line = rec.position().map_or(0, |p| p.line());
        let text = |c: usize, what: &str| {
            rec.get(c)
                .map(|s| s.trim().to_string())
                .ok_or_else(|| DataError(format!("line {line}: missing {what}")))
        };
        let code = text(c_code, "Code")?;
        let magnitude = num(rec.get(c_mag), "Magnitude", line)?;
        let unit = text(c_unit, "Units")?;
        let magnitude_si = match c_si {
            Some(c) => num(rec.get(c), "converted magnitude", line)?,
            None => to_model_units(magnitude, &unit).ok_or_else(|| {
                DataError(format!("line {line}: unknown unit {unit:?} of {code}"))
            })?,
        };
        if code.is_empty() {
            return Err(DataError(format!("line {line}: empty Code")));
        }
        terms.push(ErrorTerm {
            code,
            weighting: text(c_wt, "Wt.Fn.")?,
            magnitude,
            unit,
            magnitude_si,
            propagation: Propagation::parse(&text(c_prop, "Prop.")?)
                .map_err(|e| DataError(format!("line {line}: {e}")))?,
        });
    }
    if terms.is_empty() {
        return Err(DataError(format!("{}: no terms", name)));
    }
    Ok(terms)
}

/// A magnitude in the units the weighting functions use: angles in
/// radians, angular rates in rad/s, the rest as tabulated.
fn to_model_units(magnitude: f64, unit: &str) -> Option<f64> {
    let deg = std::f64::consts::PI / 180.0;
    Some(match unit {
        "deg" => magnitude * deg,
        "deg/hr" => magnitude * deg / 3600.0,
        "deg.nT" => magnitude * deg,
        "m" | "-" | "1/m" | "m/s2" | "nT" => magnitude,
        _ => return None,
    })
}

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
    /// `PRB-GXB`/`PRB-GZB` weights ([`probe_weighting`]) use it.
    pub toolface: Option<f64>,
}

/// Checks a survey before [`run`]: at least a tie-on, every value finite,
/// MD strictly increasing, inclination within 0..=180 deg. `run` itself
/// assumes this (a repeated MD would make a zero-length leg; a non-finite
/// value would spread NaN through every later station).
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

/// NEV covariance, m^2: `[nn, ee, vv, ne, nv, ev]`.
pub type Cov6 = [f64; 6];

fn outer(v: [f64; 3]) -> Cov6 {
    [
        v[0] * v[0],
        v[1] * v[1],
        v[2] * v[2],
        v[0] * v[1],
        v[0] * v[2],
        v[1] * v[2],
    ]
}

/// The weighting function of a source at a station: `(dD, dI, dA)` per unit
/// of the source, and the NEV singularity vector where the azimuth weighting
/// is singular at vertical.
struct Weight {
    w: [f64; 3],
    singular: Option<[f64; 3]>,
}

/// Sines and cosines of a station's inclination, true azimuth and magnetic
/// azimuth, computed once per station: every error source's weighting, the
/// leg tangents and their derivatives all read them (a profile of the
/// 10,001-station bench had most of its time in `sincos` while each source
/// recomputed them).
#[derive(Clone, Copy, Debug)]
struct StationTrig {
    sin_inc: f64,
    cos_inc: f64,
    sin_azi: f64,
    cos_azi: f64,
    /// Of the magnetic azimuth `azi - declination`.
    sin_mag_azi: f64,
    cos_mag_azi: f64,
}

impl StationTrig {
    fn of(s: &Station, site: &Site) -> Self {
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
struct SiteTerms {
    site: Site,
    /// tan(dip).
    tan_dip: f64,
    /// Horizontal field B cos(dip), nT.
    b_horizontal: f64,
    /// Horizontal earth rate Omega cos(latitude), rad/s.
    horizontal_earth_rate: f64,
}

impl SiteTerms {
    fn of(site: &Site) -> Self {
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

/// `None`: weighting function not implemented.
#[inline(always)]
fn weighting(
    name: &str,
    s: &Station,
    trig: &StationTrig,
    course: f64,
    site: &SiteTerms,
) -> Option<Weight> {
    let (si, ci) = (trig.sin_inc, trig.cos_inc);
    let (sam, cam) = (trig.sin_mag_azi, trig.cos_mag_azi);
    let (sat, cat) = (trig.sin_azi, trig.cos_azi);
    let g = site.gravity;
    let td = site.tan_dip;
    let bh = site.b_horizontal;
    let r2 = std::f64::consts::SQRT_2;
    let w = |d: f64, i: f64, a: f64| Weight {
        w: [d, i, a],
        singular: None,
    };
    let vertical = s.inc < site.vertical_limit;
    Some(match name {
        "DREF" => w(1.0, 0.0, 0.0),
        "DSF" => w(s.md, 0.0, 0.0),
        "DST" => w(s.md * s.tvd, 0.0, 0.0),
        "ABXY-TI1" => w(0.0, -ci / g, td * ci * sam / g),
        "ABXY-TI2" => Weight {
            w: [
                0.0,
                0.0,
                if vertical {
                    0.0
                } else {
                    // tan(pi/2 - I) = cot I, without a tan per station
                    (ci / si - td * cam) / g
                },
            ],
            singular: Some([-sat / g, cat / g, 0.0]),
        },
        "ABZ" => w(0.0, -si / g, td * si * sam / g),
        "ASXY-TI1" => w(0.0, si * ci / r2, -td * si * ci * sam / r2),
        "ASXY-TI2" => w(0.0, si * ci / 2.0, -td * si * ci * sam / 2.0),
        "ASXY-TI3" => w(0.0, 0.0, (td * si * cam - ci) / 2.0),
        "ASZ" => w(0.0, -si * ci, td * si * ci * sam),
        "MBXY-TI1" => w(0.0, 0.0, -ci * sam / bh),
        "MBXY-TI2" => w(0.0, 0.0, cam / bh),
        "MBZ" => w(0.0, 0.0, -si * sam / bh),
        "MSXY-TI1" => w(0.0, 0.0, si * sam * (td * ci + si * cam) / r2),
        "MSXY-TI2" => w(0.0, 0.0, sam * (td * si * ci - ci * ci * cam - cam) / 2.0),
        "MSXY-TI3" => w(
            0.0,
            0.0,
            (ci * cam * cam - ci * sam * sam - td * si * cam) / 2.0,
        ),
        "MSZ" => w(0.0, 0.0, -(si * cam + td * ci) * si * sam),
        "AZ" => w(0.0, 0.0, 1.0),
        "DBH" => w(0.0, 0.0, 1.0 / bh),
        "AMIL" => w(0.0, 0.0, si * sam / bh),
        "SAGE" => w(0.0, si.powf(0.25), 0.0),
        "SAG" => w(0.0, si, 0.0),
        // OWSG gyro models (SPE 90408 Tables 1 and 4): 3-axis
        // accelerometer, 2-axis (XY) stationary gyro
        "AXYZ-MIS" => w(0.0, 1.0, 0.0),
        "AXYZ-SF" => w(0.0, 1.3 * si * ci, 0.0),
        "AXYZ-ZB" => w(0.0, si / g, 0.0),
        "GXY-B1" => w(0.0, 0.0, sat / (horizontal_earth_rate(site) * ci)),
        "GXY-B2" => w(0.0, 0.0, cat / horizontal_earth_rate(site)),
        "GXY-G1" => w(0.0, 0.0, cat * si / horizontal_earth_rate(site)),
        "GXY-G4" => w(0.0, 0.0, sat * si / ci / horizontal_earth_rate(site)),
        "GXY-RN" => w(
            0.0,
            0.0,
            site.gyro_noise_reduction * (1.0 - (cat * si).powi(2)).sqrt()
                / (horizontal_earth_rate(site) * ci),
        ),
        "XYM1" => w(0.0, si.abs(), 0.0),
        "XYM2" => w(0.0, 0.0, -1.0),
        "XYM3" | "XYM3L" | "XYM3E" => {
            let f = enhanced(name, course);
            Weight {
                w: [
                    0.0,
                    f * ci.abs() * cat,
                    if vertical {
                        0.0
                    } else {
                        -f * ci.abs() * sat / si
                    },
                ],
                singular: Some([f, 0.0, 0.0]),
            }
        }
        "XYM4" | "XYM4L" | "XYM4E" => {
            let f = enhanced(name, course);
            Weight {
                w: [
                    0.0,
                    f * ci.abs() * sat,
                    if vertical {
                        0.0
                    } else {
                        f * ci.abs() * cat / si
                    },
                ],
                singular: Some([0.0, f, 0.0]),
            }
        }
        // this probe's gyrocompass, valid through 90 deg (probe_weighting.rs)
        p if p.starts_with("PRB-") => Weight {
            w: probe_weighting::weighting(p, s, trig, site)?,
            singular: None,
        },
        _ => return None,
    })
}

/// Minimum course length of the "enhanced" misalignment terms (XYM3E,
/// XYM4E of Rev 5.10), m: below it the weight grows as sqrt(10 m / course).
const MISALIGNMENT_MIN_COURSE: f64 = 10.0;

fn enhanced(name: &str, course: f64) -> f64 {
    if name.ends_with('E') && course > 0.0 {
        (MISALIGNMENT_MIN_COURSE / course).sqrt().max(1.0)
    } else {
        1.0
    }
}

/// Default tortuosity of the XCL terms (1 deg / 100 ft), rad/m.
pub const XCL_TORTUOSITY: f64 = 0.000_572_615;

/// Error vector of the long-course-length terms (SPE 187249), which use the
/// tangential form: the station's angle error acts over the leg before it
/// only, `e_k = sigma * (D_k - D_{k-1}) * dt_k/dp * w`.
#[inline]
fn xcl_vector(
    name: &str,
    s: &Station,
    prev: &Station,
    trig: &StationTrig,
    sig: f64,
    site: &Site,
    xcl: XclAzimuth,
) -> Option<[f64; 3]> {
    let len = s.md - prev.md;
    let (si, ci) = (trig.sin_inc, trig.cos_inc);
    let (sa, ca) = (trig.sin_azi, trig.cos_azi);
    match name {
        "XCLH" => {
            let w = (s.inc - prev.inc).abs().max(XCL_TORTUOSITY * len);
            Some([
                sig * len * w * ci * ca,
                sig * len * w * ci * sa,
                -sig * len * w * si,
            ])
        }
        "XCLA" => {
            let mut da = (s.azi - prev.azi).rem_euclid(std::f64::consts::TAU);
            if da > std::f64::consts::PI {
                da = std::f64::consts::TAU - da;
            }
            // the azimuth of a vertical station is no measurement: no
            // azimuth change out of it
            if prev.inc < site.vertical_limit {
                da = 0.0;
            }
            // sin(I) * max(|dA|, tau * L / sin(I)) = max(sin(I) |dA|, tau * L):
            // finite at vertical
            let change = match xcl {
                XclAzimuth::Angle => da,
                XclAzimuth::Sine => da.sin(),
            };
            let ws = (si * change).max(XCL_TORTUOSITY * len);
            Some([-sig * len * ws * sa, sig * len * ws * ca, 0.0])
        }
        _ => None,
    }
}

/// Omega cos(latitude), computed once per run ([`SiteTerms`]).
fn horizontal_earth_rate(site: &SiteTerms) -> f64 {
    site.horizontal_earth_rate
}

fn tangent(t: &StationTrig) -> [f64; 3] {
    [t.sin_inc * t.cos_azi, t.sin_inc * t.sin_azi, t.cos_inc]
}

/// What every source's error vector at a station needs from the well's
/// geometry, computed once per station for all sources. In the
/// balanced-tangential form (SPE 67616, the derivatives of
/// `dr_k = (D_k - D_{k-1})/2 (t_{k-1} + t_k)`):
/// * depth: `d dr_k/dD_k = (t_{k-1} + t_k)/2`,
///   `d dr_{k+1}/dD_k = -(t_k + t_{k+1})/2`;
/// * inclination and azimuth: `d dr/dI = L/2 (cos I cos A, cos I sin A,
///   -sin I)`, `d dr/dA = L/2 (-sin I sin A, sin I cos A, 0)`, the same at
///   either end of a leg of length L.
///
/// "interior": station k with the legs before and after it; "last": k as
/// the station of interest, the leg before it only.
#[derive(Clone, Copy, Debug)]
struct Leg {
    /// Depth derivative, interior and last.
    dd_interior: [f64; 3],
    dd_last: [f64; 3],
    /// Half the course lengths the angle errors act over, interior and last.
    h_interior: f64,
    h_last: f64,
    /// d t/dI and d t/dA (per unit length, times 2: `h` carries the 1/2).
    di: [f64; 3],
    da: [f64; 3],
    /// MD from the previous station, m.
    course: f64,
}

impl Leg {
    /// Station `k` (>= 1) of `stations`, from the trigonometry of stations
    /// k-1, k and k+1 (`next`: `None` at the last station).
    fn at(
        stations: &[Station],
        k: usize,
        prev: &StationTrig,
        cur: &StationTrig,
        next: Option<&StationTrig>,
        opts: Options,
    ) -> Self {
        let s = &stations[k];
        let course = s.md - stations[k - 1].md;
        let len_b = if k == 1 && opts.tie_on == TieOn::CarriedByFirstStation {
            // the tie-on's inclination/azimuth error is carried here
            2.0 * (s.md - stations[0].md)
        } else {
            course
        };
        let len_a = stations.get(k + 1).map_or(0.0, |n| n.md - s.md);
        let t = tangent(cur);
        let tp = tangent(prev);
        let tn = next.map_or(t, tangent);
        let dd_b: [f64; 3] = std::array::from_fn(|j| 0.5 * (tp[j] + t[j]));
        let (si, ci) = (cur.sin_inc, cur.cos_inc);
        let (sa, ca) = (cur.sin_azi, cur.cos_azi);
        Leg {
            dd_interior: std::array::from_fn(|j| dd_b[j] - 0.5 * (t[j] + tn[j])),
            dd_last: dd_b,
            h_interior: len_b / 2.0 + len_a / 2.0,
            h_last: len_b / 2.0,
            di: [ci * ca, ci * sa, -si],
            da: [-si * sa, si * ca, 0.0],
            course,
        }
    }
}

/// Per-source and total covariances at every station.
#[derive(Clone, Debug)]
pub struct ModelResult {
    /// Per implemented source code: covariance at each station.
    pub per_source: BTreeMap<String, Vec<Cov6>>,
    /// Sum of the implemented sources at each station.
    pub total: Vec<Cov6>,
    /// Codes of sources whose weighting function is not implemented (not
    /// included in `total`).
    pub missing: Vec<String>,
}

/// How the tie-on's own inclination/azimuth error is counted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TieOn {
    /// Rev 5 workbooks: station 1 carries it (its leg-before weight covers
    /// the whole first course length).
    CarriedByFirstStation,
    /// Rev 4 workbook: the tie-on is exact; station 1's leg-before weight
    /// is half the first course length, as at every other station.
    Exact,
}

/// The azimuth change XCLA weighs: `|dA|` in the workbook diagnostic
/// block (before Rev 5.10), `sin |dA|` from Rev 5.10 on (the "sine term";
/// HPT Rev 5.1 diagnostics, OWSG tool models).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum XclAzimuth {
    Angle,
    Sine,
}

/// Conventions that differ between model revisions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    pub tie_on: TieOn,
    pub xcl_azimuth: XclAzimuth,
}

impl Options {
    /// Rev 5.10 (HPT Rev 5.1 diagnostics, WB5.10 calculation sheets).
    pub const REV5_10: Self = Self {
        tie_on: TieOn::CarriedByFirstStation,
        xcl_azimuth: XclAzimuth::Sine,
    };
    /// The workbook diagnostic block (Rev 5 before the 5.10 XCLA change).
    pub const REV5_DIAGNOSTIC: Self = Self {
        tie_on: TieOn::CarriedByFirstStation,
        xcl_azimuth: XclAzimuth::Angle,
    };
    /// Rev 4 (no XCL terms).
    pub const REV4: Self = Self {
        tie_on: TieOn::Exact,
        xcl_azimuth: XclAzimuth::Angle,
    };
}

/// Error vectors of one source at station `k` (>= 1): (as an interior
/// station, as the station of interest); `None`: weighting function not
/// implemented.
#[inline]
fn error_vector(
    term: &ErrorTerm,
    stations: &[Station],
    trig: &StationTrig,
    leg: &Leg,
    k: usize,
    site: &SiteTerms,
    opts: Options,
) -> Option<([f64; 3], [f64; 3])> {
    let sig = term.magnitude_si;
    let s = &stations[k];
    if term.weighting.starts_with("XCL") {
        let v = xcl_vector(
            &term.weighting,
            s,
            &stations[k - 1],
            trig,
            sig,
            site,
            opts.xcl_azimuth,
        )?;
        return Some((v, v));
    }
    let wt = weighting(&term.weighting, s, trig, leg.course, site)?;
    // the angle part: d dr/dI w_I + d dr/dA w_A per unit half-length, or at
    // a vertical station the tabulated singularity vector
    let u: [f64; 3] = match (wt.singular, s.inc < site.vertical_limit) {
        (Some(sv), true) => sv,
        _ => std::array::from_fn(|j| leg.di[j] * wt.w[1] + leg.da[j] * wt.w[2]),
    };
    Some((
        std::array::from_fn(|j| sig * (leg.dd_interior[j] * wt.w[0] + leg.h_interior * u[j])),
        std::array::from_fn(|j| sig * (leg.dd_last[j] * wt.w[0] + leg.h_last * u[j])),
    ))
}

/// Whether a source's weighting function is implemented: the dispatch is
/// by name only, so asking at the tie-on answers for every station.
fn implemented(term: &ErrorTerm, s: &Station, trig: &StationTrig, site: &SiteTerms) -> bool {
    if term.weighting.starts_with("XCL") {
        xcl_vector(&term.weighting, s, s, trig, 0.0, site, XclAzimuth::Angle).is_some()
    } else {
        weighting(&term.weighting, s, trig, 0.0, site).is_some()
    }
}

/// One implemented source while the stations are walked: its running sum
/// (SPE 67616: random sources add their covariances, the others their
/// error vectors) and its covariance at the stations so far.
struct Source<'a> {
    term: &'a ErrorTerm,
    random: bool,
    /// Random: the covariance sum `[nn, ee, vv, ne, nv, ev]`; otherwise the
    /// vector sum in the first three.
    sum: [f64; 6],
    covs: Vec<Cov6>,
}

/// Runs the model over a survey (first station = tie-on), with the Rev
/// 5.10 conventions.
pub fn run(terms: &[ErrorTerm], stations: &[Station], site: &Site) -> ModelResult {
    run_with(terms, stations, site, Options::REV5_10)
}

/// Runs the model with explicit conventions.
pub fn run_with(
    terms: &[ErrorTerm],
    stations: &[Station],
    site: &Site,
    opts: Options,
) -> ModelResult {
    let n = stations.len();
    let mut per_source = BTreeMap::new();
    let mut missing = Vec::new();
    if n == 0 {
        return ModelResult {
            per_source,
            total: Vec::new(),
            missing,
        };
    }
    let site = &SiteTerms::of(site);
    // Stations outside, sources inside: each station's trigonometry and leg
    // geometry is computed once for all sources and kept only while it is
    // needed (no per-station tables), and the sources' running sums lie
    // together in one small array.
    let mut prev = StationTrig::of(&stations[0], site);
    let mut sources: Vec<Source> = Vec::with_capacity(terms.len());
    for term in terms {
        if !implemented(term, &stations[0], &prev, site) {
            missing.push(term.code.clone());
            continue;
        }
        let mut covs = Vec::with_capacity(n);
        // the tie-on carries no error
        covs.push([0.0; 6]);
        sources.push(Source {
            term,
            random: term.propagation == Propagation::Random,
            sum: [0.0; 6],
            covs,
        });
    }
    let mut total = Vec::with_capacity(n);
    total.push([0.0; 6]);
    let mut cur = stations.get(1).map(|s| StationTrig::of(s, site));
    for k in 1..n {
        let Some(trig) = cur else { break };
        let next = stations.get(k + 1).map(|s| StationTrig::of(s, site));
        let leg = Leg::at(stations, k, &prev, &trig, next.as_ref(), opts);
        let mut tot = [0.0; 6];
        for src in &mut sources {
            // `implemented` said the name is known: a station cannot change
            // that (the dispatch is by name)
            let (interior, last) = error_vector(src.term, stations, &trig, &leg, k, site, opts)
                .unwrap_or(([0.0; 3], [0.0; 3]));
            let c = if src.random {
                let c = outer(last);
                let c: Cov6 = std::array::from_fn(|j| src.sum[j] + c[j]);
                for (a, e) in src.sum.iter_mut().zip(outer(interior)) {
                    *a += e;
                }
                c
            } else {
                let c = outer(std::array::from_fn(|j| src.sum[j] + last[j]));
                for (a, e) in src.sum.iter_mut().zip(interior) {
                    *a += e;
                }
                c
            };
            src.covs.push(c);
            for j in 0..6 {
                tot[j] += c[j];
            }
        }
        total.push(tot);
        prev = trig;
        cur = next;
    }
    for src in sources {
        per_source.insert(src.term.code.clone(), src.covs);
    }
    ModelResult {
        per_source,
        total,
        missing,
    }
}
