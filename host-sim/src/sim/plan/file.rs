//! The plan file (JSON, serde; every field documented in
//! `docs/drilling-simulation.md`): the site, the tie-on in the parent well
//! and the sections by measured depth (holds, and build/turn curves at a
//! dogleg severity to a target direction). [`Plan::build`] checks every
//! field and turns the sections into stations, one at each section's end.
use super::built::{BuiltPlan, BuiltSection};
use super::drilling_params::DrillingParams;
use anyhow::{bail, ensure, Context, Result};
use mwd_core::conventions::{wrap_two_pi, DEG};
use mwd_core::earth::Position;
use mwd_core::survey::{dogleg, TieOn, TrueNorth, TrueStation};
use nalgebra::Matrix3;
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

impl Plan {
    /// Reads and checks a plan file.
    pub fn load(path: &Path) -> Result<BuiltPlan> {
        Self::read(path)?
            .build()
            .with_context(|| format!("{}: invalid plan", path.display()))
    }

    /// Checks a plan file's text, `name` (its path) in the errors as
    /// [`Self::load`] names it: a plan that travels as text (a study's
    /// shard file).
    pub fn parse(text: &str, name: &str) -> Result<BuiltPlan> {
        let plan: Self =
            serde_json::from_str(text).with_context(|| format!("{name}: not a well plan"))?;
        plan.build()
            .with_context(|| format!("{name}: invalid plan"))
    }

    /// Reads a plan file without building it.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading the plan {}", path.display()))?;
        serde_json::from_str(&text).with_context(|| format!("{}: not a well plan", path.display()))
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
        BuiltPlan::new(
            Position::from_degrees(s.latitude_deg, s.longitude_deg, s.height_m),
            tie_on,
            stations,
            sections,
            self.drilling,
        )
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
