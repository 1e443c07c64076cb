//! A well plan for the drilling simulator: the tie-on in the parent well,
//! then sections by measured depth (holds, and build/turn curves at a
//! dogleg severity to a target direction), with the drilling parameters.
//! Read from JSON (serde); every field documented in
//! `docs/drilling-simulation.md`. [`Plan::build`] checks it and turns it
//! into stations whose minimum-curvature path (`mwd_core::survey`) is the
//! simulated hole.
use anyhow::{bail, ensure, Context, Result};
use mwd_core::conventions::{wrap_two_pi, DEG};
use mwd_core::earth::Position;
use mwd_core::survey::{
    dogleg, interpolate, positions, Segment, SurveyPoint, TieOn, TrueNorth, TrueStation,
};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Highest dogleg severity a plan may ask for (deg/30 m). Short-radius
/// motors reach some 20-30 deg/30 m; beyond that no sliding motor drills.
pub const MAX_DLS_DEG_PER_30M: f64 = 30.0;
/// Longest plan (m of MD from the tie-on) accepted: 20 km.
pub const MAX_PLAN_LENGTH_M: f64 = 20_000.0;

/// The plan file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// Geodetic position of the origin of north, east and TVD (the
    /// wellhead); the paper's site by default.
    #[serde(default)]
    pub site: Site,
    pub tie_on: TieOnSpec,
    pub sections: Vec<Section>,
    #[serde(default)]
    pub drilling: DrillingParams,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Site {
    pub latitude_deg: f64,
    pub longitude_deg: f64,
    pub height_m: f64,
}

impl Default for Site {
    fn default() -> Self {
        let p = Position::paper_site();
        Self {
            latitude_deg: p.lat / DEG,
            longitude_deg: p.lon / DEG,
            height_m: p.height,
        }
    }
}

/// The parent well's survey at the window: where the lateral starts.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TieOnSpec {
    pub md_m: f64,
    pub tvd_m: f64,
    pub north_m: f64,
    pub east_m: f64,
    pub inclination_deg: f64,
    /// From true north, clockwise.
    pub azimuth_deg: f64,
}

/// One section of the plan.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Section {
    /// Straight on at the current direction to `end_md_m`, the orienter set
    /// to `toolface_deg` (gravity toolface, deg; sliding straight with a
    /// bent motor is idealised as a hold at any toolface).
    Hold { end_md_m: f64, toolface_deg: f64 },
    /// Build and/or turn along a circular arc at `dls_deg_per_30m` until
    /// the hole points at `inclination_deg`, `azimuth_deg`. Its length is
    /// dogleg / DLS; the toolface the driller must set is the arc's (from
    /// the high side to the direction the hole turns), computed.
    Curve {
        dls_deg_per_30m: f64,
        inclination_deg: f64,
        azimuth_deg: f64,
    },
}

/// The random vibration and shocks while drilling (on bottom). Levels are
/// the environment's (before the sensor), flat over [band_low_hz,
/// band_high_hz]; what the 20 Hz samples see follows from the sensor's
/// low-pass (see `docs/drilling-simulation.md`, "Vibration").
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Vibration {
    /// Across the tool (body x and z), each axis, g RMS over the band.
    pub lateral_rms_g: f64,
    /// Along the tool (body y), g RMS over the band.
    pub axial_rms_g: f64,
    pub band_low_hz: f64,
    pub band_high_hz: f64,
    /// The sensor's internal low-pass, taken as first order, -3 dB here
    /// (Hz). The datasheet available to the project does not give it.
    pub sensor_lowpass_hz: f64,
    /// Angular vibration about body x and z, each, deg/s RMS over the band.
    pub angular_rms_deg_s: f64,
    /// Shocks while drilling: mean rate (per hour), half-sine peak (g) and
    /// duration (ms), lateral direction at random.
    pub shocks_per_hour: f64,
    pub shock_peak_g: f64,
    pub shock_duration_ms: f64,
}

impl Vibration {
    /// The default: a moderate sliding environment, 2 g RMS lateral and
    /// 1 g axial over 5-500 Hz, 1 deg/s angular, 6 shocks of 30 g per hour.
    pub const MODERATE: Self = Self {
        lateral_rms_g: 2.0,
        axial_rms_g: 1.0,
        band_low_hz: 5.0,
        band_high_hz: 500.0,
        sensor_lowpass_hz: 50.0,
        angular_rms_deg_s: 1.0,
        shocks_per_hour: 6.0,
        shock_peak_g: 30.0,
        shock_duration_ms: 1.0,
    };
    /// The paper's environment: 15 g RMS over 5-500 Hz on every axis,
    /// 30 deg/s angular, 60 shocks of 100 g per hour.
    pub const HARSH: Self = Self {
        lateral_rms_g: 15.0,
        axial_rms_g: 15.0,
        band_low_hz: 5.0,
        band_high_hz: 500.0,
        sensor_lowpass_hz: 50.0,
        angular_rms_deg_s: 30.0,
        shocks_per_hour: 60.0,
        shock_peak_g: 100.0,
        shock_duration_ms: 1.0,
    };
    /// No vibration.
    pub const NONE: Self = Self {
        lateral_rms_g: 0.0,
        axial_rms_g: 0.0,
        band_low_hz: 5.0,
        band_high_hz: 500.0,
        sensor_lowpass_hz: 50.0,
        angular_rms_deg_s: 0.0,
        shocks_per_hour: 0.0,
        shock_peak_g: 0.0,
        shock_duration_ms: 1.0,
    };

    /// The fraction of a flat band's power a first-order low-pass at fc
    /// lets through: (1 / (hi - lo)) int_lo^hi df / (1 + (f/fc)^2)
    /// = fc (atan(hi/fc) - atan(lo/fc)) / (hi - lo).
    pub fn passed_power_fraction(&self) -> f64 {
        let (lo, hi, fc) = (self.band_low_hz, self.band_high_hz, self.sensor_lowpass_hz);
        fc * (libm::atan(hi / fc) - libm::atan(lo / fc)) / (hi - lo)
    }

    fn check(&self) -> Result<()> {
        let nonneg = [
            ("lateral_rms_g", self.lateral_rms_g),
            ("axial_rms_g", self.axial_rms_g),
            ("angular_rms_deg_s", self.angular_rms_deg_s),
            ("shocks_per_hour", self.shocks_per_hour),
            ("shock_peak_g", self.shock_peak_g),
        ];
        for (name, v) in nonneg {
            ensure!(
                v.is_finite() && (0.0..=1000.0).contains(&v),
                "drilling.vibration.{name} must be a number from 0 to 1000 (got {v})"
            );
        }
        ensure!(
            self.band_low_hz.is_finite()
                && self.band_low_hz >= 0.0
                && self.band_high_hz.is_finite()
                && self.band_high_hz > self.band_low_hz
                && self.band_high_hz <= 100_000.0,
            "drilling.vibration: the band must satisfy 0 <= band_low_hz < band_high_hz <= 100000 Hz"
        );
        ensure!(
            self.sensor_lowpass_hz.is_finite()
                && self.sensor_lowpass_hz > 0.0
                && self.sensor_lowpass_hz <= 100_000.0,
            "drilling.vibration.sensor_lowpass_hz must be a number of Hz above 0, at most 100000"
        );
        ensure!(
            self.shock_duration_ms.is_finite()
                && self.shock_duration_ms > 0.0
                && self.shock_duration_ms <= 50.0,
            "drilling.vibration.shock_duration_ms must be above 0 and at most 50 ms"
        );
        Ok(())
    }
}

impl Default for Vibration {
    fn default() -> Self {
        Self::MODERATE
    }
}

/// Errors of the surface depth measurement (the ISCWSA depth terms):
/// md_log = md (1 + scale) + stretch md TVD.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DepthErrors {
    /// Scale-factor error, ppm of MD (ISCWSA DSF, 1 sigma 560 ppm in MWD Rev 5).
    pub scale_ppm: f64,
    /// Stretch, 1/m: error = stretch x MD x TVD (ISCWSA DST, 2.5e-7 /m).
    pub stretch_per_m: f64,
}

impl Default for DepthErrors {
    fn default() -> Self {
        Self {
            scale_ppm: 560.0,
            stretch_per_m: 2.5e-7,
        }
    }
}

/// Drilling parameters, each with a default.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct DrillingParams {
    /// Rate of penetration while drilling (m/h).
    pub rop_m_per_h: f64,
    /// Time to reach ROP from rest and to stop again (s): linear ramps.
    pub rop_ramp_s: f64,
    /// MD drilled between connections (m).
    pub stand_length_m: f64,
    /// Still time at each connection (s): pumps off, the probe at rest.
    pub connection_still_s: f64,
    /// Still time at the tie-on before drilling starts (s): alignment.
    pub initial_still_s: f64,
    /// Toolface change at each connection (deg; back towards the section's
    /// toolface, or either way at random from it).
    pub toolface_change_per_connection_deg: f64,
    /// Rate of the orienter's toolface turns (deg/s).
    pub toolface_turn_rate_deg_s: f64,
    /// Toolface steps while sliding (reactive torque, driller's
    /// corrections): mean rate (per hour of drilling) and size (deg,
    /// directed as the connection steps).
    pub sliding_toolface_steps_per_hour: f64,
    pub sliding_toolface_step_deg: f64,
    pub vibration: Vibration,
    pub depth_errors: DepthErrors,
    /// Interval of the surface depth log (s).
    pub depth_log_interval_s: f64,
}

impl Default for DrillingParams {
    fn default() -> Self {
        Self {
            rop_m_per_h: 30.0,
            rop_ramp_s: 10.0,
            stand_length_m: 28.0,
            connection_still_s: 300.0,
            initial_still_s: 600.0,
            toolface_change_per_connection_deg: 30.0,
            toolface_turn_rate_deg_s: 10.0,
            sliding_toolface_steps_per_hour: 1.0,
            sliding_toolface_step_deg: 10.0,
            vibration: Vibration::default(),
            depth_errors: DepthErrors::default(),
            depth_log_interval_s: 1.0,
        }
    }
}

impl DrillingParams {
    fn check(&self) -> Result<()> {
        let ranges = [
            ("rop_m_per_h", self.rop_m_per_h, 0.1, 500.0),
            ("rop_ramp_s", self.rop_ramp_s, 0.0, 600.0),
            ("stand_length_m", self.stand_length_m, 1.0, 1000.0),
            ("connection_still_s", self.connection_still_s, 0.0, 86_400.0),
            ("initial_still_s", self.initial_still_s, 0.0, 86_400.0),
            (
                "toolface_change_per_connection_deg",
                self.toolface_change_per_connection_deg,
                0.0,
                360.0,
            ),
            (
                "toolface_turn_rate_deg_s",
                self.toolface_turn_rate_deg_s,
                0.1,
                300.0,
            ),
            (
                "sliding_toolface_steps_per_hour",
                self.sliding_toolface_steps_per_hour,
                0.0,
                3600.0,
            ),
            (
                "sliding_toolface_step_deg",
                self.sliding_toolface_step_deg,
                0.0,
                360.0,
            ),
            (
                "depth_log_interval_s",
                self.depth_log_interval_s,
                0.05,
                3600.0,
            ),
        ];
        for (name, v, lo, hi) in ranges {
            ensure!(
                v.is_finite() && (lo..=hi).contains(&v),
                "drilling.{name} must be a number from {lo} to {hi} (got {v})"
            );
        }
        self.vibration.check()?;
        let d = &self.depth_errors;
        ensure!(
            d.scale_ppm.is_finite() && d.scale_ppm.abs() <= 10_000.0,
            "drilling.depth_errors.scale_ppm must be a number from -10000 to 10000 ppm"
        );
        ensure!(
            d.stretch_per_m.is_finite() && d.stretch_per_m.abs() <= 1e-5,
            "drilling.depth_errors.stretch_per_m must be a number from -1e-5 to 1e-5 per m"
        );
        Ok(())
    }
}

/// One section as built: its MD range, stations, and toolface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuiltSection {
    pub start_md: f64,
    pub end_md: f64,
    /// Hold: the orienter's toolface (rad); curve: None (the arc's).
    pub hold_toolface: Option<f64>,
    /// Curve: dogleg severity (deg/30 m).
    pub dls_deg_per_30m: f64,
}

/// A checked plan: the stations at every section end (the first at the
/// tie-on) and their minimum-curvature positions.
#[derive(Clone, Debug)]
pub struct BuiltPlan {
    pub site: Position,
    pub tie_on: TieOn<TrueNorth>,
    pub stations: Vec<TrueStation>,
    pub points: Vec<SurveyPoint<TrueNorth>>,
    pub sections: Vec<BuiltSection>,
    pub drilling: DrillingParams,
    /// Each section's arc, computed once from `stations` by `build`.
    arcs: Vec<SectionArc>,
}

/// A section's minimum-curvature arc with its curvature (rad/m) and unit
/// bending axis (NED; zero on a straight hold): computed once per plan, as
/// a simulated run reads the plan twice per sample (each arc's dogleg and
/// tangents cost a dozen transcendental calls).
#[derive(Clone, Copy, Debug)]
struct SectionArc {
    /// `None` if the stations form no segment (`build` rules it out).
    segment: Option<Segment<TrueNorth>>,
    curvature: f64,
    axis: Vector3<f64>,
}

impl SectionArc {
    fn new(from: TrueStation, to: TrueStation) -> Self {
        match Segment::new(from, to) {
            Ok(segment) => {
                let cross = segment.start_tangent().cross(&segment.end_tangent());
                let axis = if cross.norm() > 0.0 {
                    cross / cross.norm()
                } else {
                    Vector3::zeros()
                };
                SectionArc {
                    segment: Some(segment),
                    curvature: segment.dogleg() / segment.length(),
                    axis,
                }
            }
            Err(_) => SectionArc {
                segment: None,
                curvature: 0.0,
                axis: Vector3::zeros(),
            },
        }
    }
}

/// A point of the planned hole at some MD: direction, position, the arc's
/// curvature (rad/m) and bending axis (unit, NED), and the section index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathPoint {
    pub md: f64,
    pub inclination: f64,
    pub azimuth: f64,
    /// (north, east, TVD), m.
    pub nev: Vector3<f64>,
    pub curvature: f64,
    pub axis: Vector3<f64>,
    pub section: usize,
}

impl Plan {
    /// Reads and checks a plan file.
    pub fn load(path: &Path) -> Result<BuiltPlan> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading the plan {}", path.display()))?;
        let plan: Plan = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a well plan", path.display()))?;
        plan.build()
            .with_context(|| format!("{}: invalid plan", path.display()))
    }

    /// Checks the plan and builds its stations.
    pub fn build(&self) -> Result<BuiltPlan> {
        let s = &self.site;
        ensure!(
            s.latitude_deg.is_finite() && s.latitude_deg.abs() <= 89.0,
            "site.latitude_deg must be a number from -89 to 89"
        );
        ensure!(
            s.longitude_deg.is_finite() && s.longitude_deg.abs() <= 180.0,
            "site.longitude_deg must be a number from -180 to 180"
        );
        ensure!(
            s.height_m.is_finite() && s.height_m.abs() <= 10_000.0,
            "site.height_m must be a number from -10000 to 10000"
        );
        let t = &self.tie_on;
        ensure!(
            t.md_m.is_finite() && (0.0..=1e5).contains(&t.md_m),
            "tie_on.md_m must be a number from 0 to 100000 m"
        );
        for (name, v) in [
            ("tvd_m", t.tvd_m),
            ("north_m", t.north_m),
            ("east_m", t.east_m),
        ] {
            ensure!(
                v.is_finite() && v.abs() <= 1e5,
                "tie_on.{name} must be a number from -100000 to 100000 m"
            );
        }
        ensure!(
            t.tvd_m <= t.md_m + 1e-9,
            "tie_on.tvd_m ({}) cannot exceed tie_on.md_m ({})",
            t.tvd_m,
            t.md_m
        );
        check_direction("tie_on", t.inclination_deg, t.azimuth_deg)?;
        self.drilling.check()?;
        ensure!(!self.sections.is_empty(), "the plan has no sections");

        let tie_on =
            TieOn::<TrueNorth>::new(t.md_m, t.tvd_m, t.north_m, t.east_m, Matrix3::zeros())
                .map_err(|e| anyhow::anyhow!("tie_on: {e}"))?;
        let first = TrueStation::new(t.md_m, t.inclination_deg * DEG, t.azimuth_deg * DEG)
            .map_err(|e| anyhow::anyhow!("tie_on: {e}"))?;
        let mut stations = vec![first];
        let mut sections = Vec::with_capacity(self.sections.len());
        for (i, section) in self.sections.iter().enumerate() {
            let n = i + 1;
            let last = stations[stations.len() - 1];
            let (end, built) = match *section {
                Section::Hold {
                    end_md_m,
                    toolface_deg,
                } => {
                    ensure!(
                        end_md_m.is_finite() && end_md_m > last.md(),
                        "section {n} (hold): end_md_m ({end_md_m}) must be a number greater than \
                         the MD where it starts ({} m)",
                        last.md()
                    );
                    ensure!(
                        toolface_deg.is_finite(),
                        "section {n} (hold): toolface_deg must be a number"
                    );
                    let end = TrueStation::new(end_md_m, last.inclination(), last.azimuth())
                        .map_err(|e| anyhow::anyhow!("section {n}: {e}"))?;
                    (
                        end,
                        BuiltSection {
                            start_md: last.md(),
                            end_md: end_md_m,
                            hold_toolface: Some(toolface_deg * DEG),
                            dls_deg_per_30m: 0.0,
                        },
                    )
                }
                Section::Curve {
                    dls_deg_per_30m,
                    inclination_deg,
                    azimuth_deg,
                } => {
                    ensure!(
                        dls_deg_per_30m.is_finite()
                            && dls_deg_per_30m > 0.0
                            && dls_deg_per_30m <= MAX_DLS_DEG_PER_30M,
                        "section {n} (curve): dls_deg_per_30m ({dls_deg_per_30m}) must be above 0 \
                         and at most {MAX_DLS_DEG_PER_30M} deg/30 m (no motor drills more)"
                    );
                    check_direction(
                        &format!("section {n} (curve)"),
                        inclination_deg,
                        azimuth_deg,
                    )?;
                    let (inc, azi) = (inclination_deg * DEG, wrap_two_pi(azimuth_deg * DEG));
                    let beta = dogleg(last.inclination(), last.azimuth(), inc, azi);
                    ensure!(
                        beta > 1e-6,
                        "section {n} (curve): the hole already points at inclination \
                         {inclination_deg} deg, azimuth {azimuth_deg} deg: nothing to build or turn"
                    );
                    ensure!(
                        beta < 179.0 * DEG,
                        "section {n} (curve): a dogleg of {:.1} deg cannot be one arc",
                        beta / DEG
                    );
                    let length = beta / (dls_deg_per_30m * DEG) * 30.0;
                    let end_md = last.md() + length;
                    let end = TrueStation::new(end_md, inc, azi)
                        .map_err(|e| anyhow::anyhow!("section {n}: {e}"))?;
                    (
                        end,
                        BuiltSection {
                            start_md: last.md(),
                            end_md,
                            hold_toolface: None,
                            dls_deg_per_30m,
                        },
                    )
                }
            };
            stations.push(end);
            sections.push(built);
        }
        let length = stations[stations.len() - 1].md() - t.md_m;
        ensure!(
            length <= MAX_PLAN_LENGTH_M,
            "the plan is {length:.0} m long; at most {MAX_PLAN_LENGTH_M} m are simulated"
        );
        let points = positions(&tie_on, &stations)
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| anyhow::anyhow!("the plan's stations: {e}"))?;
        let arcs = stations
            .windows(2)
            .map(|pair| SectionArc::new(pair[0], pair[1]))
            .collect();
        let built = BuiltPlan {
            site: Position::from_degrees(s.latitude_deg, s.longitude_deg, s.height_m),
            tie_on,
            stations,
            points,
            sections,
            drilling: self.drilling,
            arcs,
        };
        built.check_depth_log_monotone()?;
        Ok(built)
    }
}

fn check_direction(what: &str, inclination_deg: f64, azimuth_deg: f64) -> Result<()> {
    // Within 5 deg of vertical the tool's toolface and azimuth lose their
    // meaning (conventions::euler_from_dcm): a lateral never goes there.
    if !(inclination_deg.is_finite() && (5.0..=175.0).contains(&inclination_deg)) {
        bail!("{what}: inclination_deg must be a number from 5 to 175 (got {inclination_deg})");
    }
    if !azimuth_deg.is_finite() {
        bail!("{what}: azimuth_deg must be a number (got {azimuth_deg})");
    }
    Ok(())
}

impl BuiltPlan {
    /// The surface's MD for a true MD and TVD: md (1 + scale) + stretch md
    /// TVD (ISCWSA DSF and DST).
    pub fn logged_md(&self, md: f64, tvd: f64) -> f64 {
        let d = &self.drilling.depth_errors;
        md * (1.0 + d.scale_ppm * 1e-6) + d.stretch_per_m * md * tvd
    }

    /// The depth errors must keep the logged MD increasing with MD (a
    /// stretch term of a hole climbing steeply could make it fall):
    /// checked every metre and at the stations.
    fn check_depth_log_monotone(&self) -> Result<()> {
        let (start, end) = (self.start_md(), self.end_md());
        let steps = (end - start).ceil().max(1.0) as usize;
        let mut previous = self.logged_md(start, self.points[0].tvd());
        for i in 1..=steps {
            let md = (start + i as f64).min(end);
            let logged = self.logged_md(md, self.at(md).nev.z);
            ensure!(
                logged > previous,
                "drilling.depth_errors: the logged MD would decrease near MD {md:.0} m \
                 (stretch x (TVD + MD cos I) below -(1 + scale))"
            );
            previous = logged;
        }
        Ok(())
    }

    pub fn start_md(&self) -> f64 {
        self.stations[0].md()
    }

    pub fn end_md(&self) -> f64 {
        self.stations[self.stations.len() - 1].md()
    }

    /// The planned hole at `md` (clamped to the plan): minimum curvature
    /// between the stations, interpolated along the arc
    /// ([`mwd_core::survey::Segment::at`]).
    pub fn at(&self, md: f64) -> PathPoint {
        let md = md.clamp(self.start_md(), self.end_md());
        // The section holding md (the last one whose start is <= md).
        let k = self
            .sections
            .partition_point(|s| s.start_md <= md)
            .saturating_sub(1)
            .min(self.sections.len() - 1);
        self.at_in_section(md, k)
    }

    /// The hole at `md` on section `k`'s arc (`md` within it or at its
    /// ends; `k` a valid index).
    pub fn at_in_section(&self, md: f64, k: usize) -> PathPoint {
        let k = k.min(self.sections.len() - 1);
        let md = md.clamp(self.sections[k].start_md, self.sections[k].end_md);
        let from = self.stations[k];
        let base = self.points[k].nev;
        let arc = &self.arcs[k];
        let (station, chord) = arc
            .segment
            .and_then(|seg| seg.at(md).ok())
            .unwrap_or((from, Vector3::zeros()));
        let (curvature, axis) = (arc.curvature, arc.axis);
        PathPoint {
            md,
            inclination: station.inclination(),
            azimuth: station.azimuth(),
            nev: base + chord,
            curvature,
            axis,
            section: k,
        }
    }

    /// The plan's own interpolation (`mwd_core::survey::interpolate`), for
    /// checks against [`Self::at`].
    pub fn interpolate(&self, md: f64) -> Result<SurveyPoint<TrueNorth>> {
        interpolate(&self.tie_on, &self.stations, md).map_err(|e| anyhow::anyhow!("{e}"))
    }

    /// The toolface the driller sets in the section at `p` (rad): a hold's
    /// given toolface; on a curve, the gravity toolface of the direction the
    /// hole turns to (d = axis x t): atan2(d . right, d . high side).
    pub fn section_toolface(&self, p: &PathPoint) -> f64 {
        if let Some(tf) = self.sections[p.section].hold_toolface {
            return tf;
        }
        let (si, ci) = (libm::sin(p.inclination), libm::cos(p.inclination));
        let (sa, ca) = (libm::sin(p.azimuth), libm::cos(p.azimuth));
        let t = Vector3::new(si * ca, si * sa, ci);
        let high = Vector3::new(ci * ca, ci * sa, -si);
        let right = Vector3::new(-sa, ca, 0.0);
        let d = p.axis.cross(&t);
        libm::atan2(d.dot(&right), d.dot(&high))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(sections: Vec<Section>) -> Plan {
        Plan {
            site: Site::default(),
            tie_on: TieOnSpec {
                md_m: 3000.0,
                tvd_m: 2000.0,
                north_m: 100.0,
                east_m: 50.0,
                inclination_deg: 90.0,
                azimuth_deg: 30.0,
            },
            sections,
            drilling: DrillingParams::default(),
        }
    }

    #[test]
    fn a_curve_ends_at_its_target_after_dogleg_over_dls() {
        let built = plan(vec![Section::Curve {
            dls_deg_per_30m: 6.0,
            inclination_deg: 93.0,
            azimuth_deg: 30.0,
        }])
        .build()
        .expect("valid");
        // 3 deg at 6 deg/30 m: 15 m.
        assert!((built.end_md() - 3015.0).abs() < 1e-9);
        let end = built.at(3015.0);
        assert!((end.inclination - 93.0 * DEG).abs() < 1e-12);
        // A pure build (inclination up past 90 = towards the high side).
        let tf = built.section_toolface(&built.at(3007.0));
        assert!(tf.abs() < 1e-9, "build toolface {tf}");
    }

    #[test]
    fn a_right_turn_needs_toolface_90() {
        let built = plan(vec![Section::Curve {
            dls_deg_per_30m: 3.0,
            inclination_deg: 90.0,
            azimuth_deg: 40.0,
        }])
        .build()
        .expect("valid");
        let tf = built.section_toolface(&built.at(3010.0));
        assert!((tf - 90.0 * DEG).abs() < 1e-6, "turn toolface {}", tf / DEG);
    }

    #[test]
    fn bad_plans_are_refused_with_the_field_named() {
        let cases: Vec<(Plan, &str)> = vec![
            (
                plan(vec![Section::Hold {
                    end_md_m: 2999.0,
                    toolface_deg: 0.0,
                }]),
                "end_md_m",
            ),
            (
                plan(vec![Section::Curve {
                    dls_deg_per_30m: 45.0,
                    inclination_deg: 95.0,
                    azimuth_deg: 30.0,
                }]),
                "dls_deg_per_30m",
            ),
            (
                plan(vec![Section::Curve {
                    dls_deg_per_30m: f64::NAN,
                    inclination_deg: 95.0,
                    azimuth_deg: 30.0,
                }]),
                "dls_deg_per_30m",
            ),
            (
                plan(vec![Section::Curve {
                    dls_deg_per_30m: 5.0,
                    inclination_deg: 90.0,
                    azimuth_deg: 30.0,
                }]),
                "nothing to build",
            ),
            (plan(vec![]), "no sections"),
        ];
        for (p, needle) in cases {
            let err = format!("{:#}", p.build().expect_err("invalid"));
            assert!(err.contains(needle), "{err}");
        }
        let mut p = plan(vec![Section::Hold {
            end_md_m: 3100.0,
            toolface_deg: 0.0,
        }]);
        p.drilling.rop_m_per_h = 0.0;
        assert!(format!("{:#}", p.build().expect_err("rop")).contains("rop_m_per_h"));
        p.drilling.rop_m_per_h = 30.0;
        p.tie_on.inclination_deg = f64::NAN;
        assert!(format!("{:#}", p.build().expect_err("nan")).contains("inclination_deg"));
    }
}
