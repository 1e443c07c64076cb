//! The weighting functions of the ISCWSA model, looked up by the table's
//! `Wt.Fn.` name: `(dD, dI, dA)` per unit of the source at a station, and
//! the NEV singularity vector where the azimuth weighting is singular at
//! vertical (the MWD Rev 4 / Rev 5.10 set, the OWSG gyro functions, this
//! probe's `PRB-*` in [`probe_weighting`](super::probe_weighting)); and
//! the long-course-length terms XCLA/XCLH (SPE 187249), which give the
//! error vector directly in the tangential form.
use super::probe_weighting;
use super::stations::{Site, SiteTerms, Station, StationTrig};
use super::term_table::ErrorTerm;

/// The weighting function of a source at a station: `(dD, dI, dA)` per unit
/// of the source, and the NEV singularity vector where the azimuth weighting
/// is singular at vertical.
pub(super) struct Weight {
    pub(super) w: [f64; 3],
    pub(super) singular: Option<[f64; 3]>,
}

/// `None`: weighting function not implemented.
#[inline(always)]
pub(super) fn weighting(
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
    // the XY misalignments: dI = f |cos I| c, dA = f |cos I| d / sin I
    // (0 at vertical, where `singular` stands in)
    let xy_misalignment = |f: f64, c: f64, d: f64, singular: [f64; 3]| Weight {
        w: [
            0.0,
            f * ci.abs() * c,
            if vertical { 0.0 } else { f * ci.abs() * d / si },
        ],
        singular: Some(singular),
    };
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
        // XYM4 is XYM3 with the azimuth turned by 90 deg (cos A -> sin A,
        // -sin A -> cos A) and the other horizontal singularity
        "XYM3" | "XYM3L" | "XYM3E" => {
            let f = enhanced(name, course);
            xy_misalignment(f, cat, -sat, [f, 0.0, 0.0])
        }
        "XYM4" | "XYM4L" | "XYM4E" => {
            let f = enhanced(name, course);
            xy_misalignment(f, sat, cat, [0.0, f, 0.0])
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

/// The azimuth change XCLA weighs: `|dA|` in the workbook diagnostic
/// block (before Rev 5.10), `sin |dA|` from Rev 5.10 on (the "sine term";
/// HPT Rev 5.1 diagnostics, OWSG tool models).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum XclAzimuth {
    Angle,
    Sine,
}

/// Default tortuosity of the XCL terms (1 deg / 100 ft), rad/m.
pub const XCL_TORTUOSITY: f64 = 0.000_572_615;

/// Error vector of the long-course-length terms (SPE 187249), which use the
/// tangential form: the station's angle error acts over the leg before it
/// only, `e_k = sigma * (D_k - D_{k-1}) * dt_k/dp * w`.
#[inline]
pub(super) fn xcl_vector(
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
pub(super) fn horizontal_earth_rate(site: &SiteTerms) -> f64 {
    site.horizontal_earth_rate
}

/// Whether a source's weighting function is implemented: the dispatch is
/// by name only, so asking at the tie-on answers for every station.
pub(super) fn implemented(
    term: &ErrorTerm,
    s: &Station,
    trig: &StationTrig,
    site: &SiteTerms,
) -> bool {
    if term.weighting.starts_with("XCL") {
        xcl_vector(&term.weighting, s, s, trig, 0.0, site, XclAzimuth::Angle).is_some()
    } else {
        weighting(&term.weighting, s, trig, 0.0, site).is_some()
    }
}
