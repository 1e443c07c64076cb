//! A checked plan as built ([`BuiltPlan`]): the stations at every section
//! end, their minimum-curvature positions (`mwd_core::survey`) and each
//! section's arc, computed once; the planned hole at any MD along them
//! ([`PathPoint`]), the toolface the driller sets there, and the surface's
//! logged MD.
use super::drilling_params::DrillingParams;
use anyhow::{ensure, Result};
use mwd_core::earth::Position;
use mwd_core::survey::{
    interpolate, positions, Segment, SurveyPoint, TieOn, TrueNorth, TrueStation,
};
use nalgebra::Vector3;

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
pub(super) struct SectionArc {
    /// `None` if the stations form no segment (`build` rules it out).
    segment: Option<Segment<TrueNorth>>,
    curvature: f64,
    axis: Vector3<f64>,
}

impl SectionArc {
    pub(super) fn new(from: TrueStation, to: TrueStation) -> Self {
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

    /// The hole at `md` (within the arc) on this arc from `from`, whose
    /// position is `base`; `section` the plan's section there.
    pub(super) fn point(
        &self,
        from: TrueStation,
        base: Vector3<f64>,
        md: f64,
        section: usize,
    ) -> PathPoint {
        let (station, chord) = self
            .segment
            .and_then(|seg| seg.at(md).ok())
            .unwrap_or((from, Vector3::zeros()));
        PathPoint {
            md,
            inclination: station.inclination(),
            azimuth: station.azimuth(),
            nev: base + chord,
            curvature: self.curvature,
            axis: self.axis,
            section,
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

impl BuiltPlan {
    /// The plan of checked stations (the first at the tie-on, then one at
    /// each section's end; [`Plan::build`](super::Plan::build)): their
    /// minimum-curvature positions and each section's arc. Fails if a
    /// station cannot be positioned or the depth errors would make the
    /// logged MD fall.
    pub(super) fn new(
        site: Position,
        tie_on: TieOn<TrueNorth>,
        stations: Vec<TrueStation>,
        sections: Vec<BuiltSection>,
        drilling: DrillingParams,
    ) -> Result<Self> {
        let points = positions(&tie_on, &stations)
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| anyhow::anyhow!("the plan's stations: {e}"))?;
        let arcs = stations
            .windows(2)
            .map(|pair| SectionArc::new(pair[0], pair[1]))
            .collect();
        let built = BuiltPlan {
            site,
            tie_on,
            stations,
            points,
            sections,
            drilling,
            arcs,
        };
        built.check_depth_log_monotone()?;
        Ok(built)
    }

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
        self.arcs[k].point(self.stations[k], self.points[k].nev, md, k)
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
