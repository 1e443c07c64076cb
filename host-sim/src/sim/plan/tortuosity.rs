//! The hole as drilled around the plan: tortuosity. A real hole never
//! follows its plan's arcs; its curvature wanders around the planned one
//! on length scales shorter than the stands between surveys, which is what
//! minimum curvature cannot follow between stations (the ISCWSA's
//! long-course-length terms XCLA and XCLH are its envelope, SPE 187249).
//!
//! The model (docs/drilling-simulation.md, "Tortuosity"): the curvature's
//! deviation from the plan's, in its two components across the hole (u_h
//! towards the high side, a build; u_r towards the right, a walk), is a
//! first-order Gauss-Markov process along MD with RMS `sigma` and
//! correlation length `L`: E[u(s) u(s + l)] = sigma^2 exp(-|l| / L). The
//! hole's direction deviation d (the same two components, rad) is its
//! integral, steered back by the driller over `steering_length_m` (L_s):
//! d' = u - d / L_s. Without steering d would be a random walk growing
//! without bound (sqrt(2 sigma^2 L s)); with it its RMS per component is
//! sigma L_s sqrt(L / (L + L_s)).
//!
//! Drawn per run from its seed (its own stream: the schedule's draws do
//! not move), at a step of min(1 m, L / 4) in MD; the hole is the
//! minimum-curvature chain through the drawn directions at those steps (a
//! circular arc each, so the simulator's curvature and acceleration terms
//! hold on every step).
use super::built::{BuiltPlan, PathPoint, SectionArc};
use super::drilling_params::Tortuosity;
use mwd_core::conventions::wrap_two_pi;
use mwd_core::survey::TrueStation;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// The curvature deviation (rad/m, build and walk components) drawn step
/// by step: the exact discretisation of the first-order Gauss-Markov
/// process at step h, u_(k+1) = phi u_k + sqrt(1 - phi^2) sigma w_k with
/// phi = exp(-h / L), started from its stationary distribution, so every
/// u_k has RMS sigma and u_k, u_(k+j) correlate by exp(-j h / L). The
/// hole's curvature over a step is the value at its start.
pub struct CurvatureWalk {
    phi: f64,
    drive: f64,
    state: [f64; 2],
    rng: ChaCha8Rng,
}

impl CurvatureWalk {
    pub fn new(tortuosity: &Tortuosity, step_m: f64, seed: u64) -> Self {
        let sigma = tortuosity.sigma_rad_per_m();
        let phi = libm::exp(-step_m / tortuosity.correlation_length_m);
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7047_7051_7100_0003);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let state = [sigma * normal(), sigma * normal()];
        Self {
            phi,
            drive: sigma * libm::sqrt(1.0 - phi * phi),
            state,
            rng,
        }
    }

    /// This step's curvature deviation; the walk moves on one step.
    pub fn next_step(&mut self) -> [f64; 2] {
        let now = self.state;
        for u in &mut self.state {
            let w: f64 = StandardNormal.sample(&mut self.rng);
            *u = self.phi * *u + self.drive * w;
        }
        now
    }
}

/// The hole as drilled: minimum-curvature arcs through the drawn
/// directions every [`Tortuosity::step_m`] of MD, from the plan's tie-on
/// (where the hole starts in the plan's direction: the parent well's).
#[derive(Clone, Debug)]
pub struct DrilledPath {
    nodes: Vec<TrueStation>,
    /// (north, east, TVD) of each node (m).
    positions: Vec<Vector3<f64>>,
    arcs: Vec<SectionArc>,
    /// The plan's section at the start of each step (its toolface).
    sections: Vec<usize>,
}

impl DrilledPath {
    /// The hole `plan.drilling.tortuosity` drills around `plan` in the
    /// run of `seed`; `None` when the tortuosity is 0 (the plan itself is
    /// the hole) or a drawn direction is no number (the plan's checks
    /// rule that out).
    pub fn draw(plan: &BuiltPlan, seed: u64) -> Option<Self> {
        let t = plan.drilling.tortuosity;
        if t.rms_deg_per_30m <= 0.0 {
            return None;
        }
        let step = t.step_m();
        let (start, end) = (plan.start_md(), plan.end_md());
        let steps = ((end - start) / step).ceil().max(1.0) as usize;
        let mut walk = CurvatureWalk::new(&t, step, seed);
        let mut deviation = [0.0f64; 2];
        let mut nodes = Vec::with_capacity(steps + 1);
        let mut sections = Vec::with_capacity(steps);
        let mut md = start;
        for k in 0..=steps {
            let planned = plan.at(md);
            let inclination =
                (planned.inclination + deviation[0]).clamp(0.0, core::f64::consts::PI);
            // a sideways angle d_r turns the azimuth by d_r / sin I
            let azimuth = planned.azimuth + deviation[1] / libm::sin(planned.inclination);
            nodes.push(TrueStation::new(md, inclination, wrap_two_pi(azimuth)).ok()?);
            if k == steps {
                break;
            }
            sections.push(planned.section);
            let next = (start + (k + 1) as f64 * step).min(end);
            let h = next - md;
            let u = walk.next_step();
            for (d, u) in deviation.iter_mut().zip(u) {
                *d += h * (u - *d / t.steering_length_m);
            }
            md = next;
        }
        let arcs: Vec<SectionArc> = nodes
            .windows(2)
            .map(|pair| SectionArc::new(pair[0], pair[1]))
            .collect();
        let mut positions = Vec::with_capacity(nodes.len());
        positions.push(plan.points[0].nev);
        for (k, arc) in arcs.iter().enumerate() {
            let end = arc.point(nodes[k], positions[k], nodes[k + 1].md(), 0);
            positions.push(end.nev);
        }
        Some(Self {
            nodes,
            positions,
            arcs,
            sections,
        })
    }

    /// The drilled hole at `md` (clamped to it): direction, position, the
    /// step's curvature and bending axis, and the plan's section there.
    pub fn at(&self, md: f64) -> PathPoint {
        let first = self.nodes[0].md();
        let last = self.nodes[self.nodes.len() - 1].md();
        let md = md.clamp(first, last);
        let k = self
            .nodes
            .partition_point(|n| n.md() <= md)
            .saturating_sub(1)
            .min(self.arcs.len() - 1);
        self.arcs[k].point(self.nodes[k], self.positions[k], md, self.sections[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::plan::{Plan, Section, Site, TieOnSpec};
    use mwd_core::conventions::DEG;

    fn hold(length_m: f64, tortuosity: Tortuosity) -> BuiltPlan {
        let mut plan = Plan {
            site: Site::default(),
            tie_on: TieOnSpec {
                md_m: 3000.0,
                tvd_m: 2000.0,
                north_m: 0.0,
                east_m: 0.0,
                inclination_deg: 90.0,
                azimuth_deg: 120.0,
            },
            sections: vec![
                Section::Hold {
                    end_md_m: 3000.0 + 0.5 * length_m,
                    toolface_deg: 0.0,
                },
                Section::Curve {
                    dls_deg_per_30m: 3.0,
                    inclination_deg: 90.0,
                    azimuth_deg: 120.0 + 0.05 * length_m,
                },
            ],
            drilling: Default::default(),
        };
        plan.drilling.tortuosity = tortuosity;
        plan.build().expect("valid plan")
    }

    /// The drawn walk has the RMS and correlation asked for: 200,000
    /// steps of 1 m at L = 10 m are ~10,000 independent samples per
    /// component, so the RMS is known to ~0.7 % and the correlation to
    /// ~0.01 (1 sigma); the tolerances are 4 sigma.
    #[test]
    fn the_curvature_walk_has_the_requested_rms_and_correlation() {
        let t = Tortuosity {
            rms_deg_per_30m: 2.0,
            correlation_length_m: 10.0,
            steering_length_m: 60.0,
        };
        let n = 200_000;
        let mut walk = CurvatureWalk::new(&t, 1.0, 11);
        let u: Vec<[f64; 2]> = (0..n).map(|_| walk.next_step()).collect();
        let sigma = t.sigma_rad_per_m();
        for c in 0..2 {
            let x: Vec<f64> = u.iter().map(|v| v[c]).collect();
            let rms = (x.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
            assert!(
                (rms / sigma - 1.0).abs() < 0.03,
                "component {c}: RMS {rms} against {sigma}"
            );
            for lag in [5usize, 10, 20] {
                let r = x.iter().zip(&x[lag..]).map(|(a, b)| a * b).sum::<f64>()
                    / (n - lag) as f64
                    / (rms * rms);
                let expected = (-(lag as f64) / 10.0).exp();
                assert!(
                    (r - expected).abs() < 0.04,
                    "component {c}, lag {lag} m: correlation {r} against {expected}"
                );
            }
        }
        // the two components are independent
        let cross = u.iter().map(|v| v[0] * v[1]).sum::<f64>() / n as f64 / (sigma * sigma);
        assert!(cross.abs() < 0.04, "cross-correlation {cross}");
    }

    #[test]
    fn two_seeds_drill_two_paths_around_the_plan_and_one_seed_the_same() {
        let plan = hold(300.0, Tortuosity::default());
        let a = DrilledPath::draw(&plan, 1).expect("tortuous");
        let b = DrilledPath::draw(&plan, 2).expect("tortuous");
        let again = DrilledPath::draw(&plan, 1).expect("tortuous");
        let end = plan.end_md();
        let (pa, pb) = (a.at(end), b.at(end));
        assert_eq!(pa, again.at(end));
        let apart = (pa.nev - pb.nev).norm();
        assert!(apart > 0.05, "two seeds end {apart} m apart");
        // around the plan: within a few RMS of the steered deviation
        // (sigma L_s sqrt(L / (L + L_s)) = 0.74 deg per component)
        let planned = plan.at(end);
        for p in [pa, pb] {
            let turn = (p.inclination - planned.inclination)
                .abs()
                .max((p.azimuth - planned.azimuth).abs());
            assert!(turn < 3.0 * DEG, "{} deg off the plan", turn / DEG);
            assert!((p.nev - planned.nev).norm() < 15.0);
        }
        // the hole starts where and as the plan does
        let (s, ps) = (a.at(plan.start_md()), plan.at(plan.start_md()));
        assert!((s.nev - ps.nev).norm() < 1e-12);
        assert!((s.inclination - ps.inclination).abs() < 1e-12);
        assert!((s.azimuth - ps.azimuth).abs() < 1e-12);
    }

    /// Minimum curvature through the drilled hole's own directions every
    /// 28 m misses it by what the curvature did inside each leg: across
    /// the hole, e = int (s - D/2) u(s) ds over a leg of length D, whose
    /// variance for the walk alone is sigma^2 int int (s - D/2)(s' - D/2)
    /// exp(-|s - s'| / L) ds ds' = (0.058 m)^2 at the defaults (the
    /// steering adds a little). 400 legs: the RMS known to ~4 %.
    #[test]
    fn minimum_curvature_misses_the_drilled_hole_by_the_walk_inside_each_leg() {
        let t = Tortuosity::default();
        let leg = 28.0;
        let plan = hold(56.0, Tortuosity::default());
        let (mut sum2, mut n) = (0.0, 0);
        for seed in 0..200 {
            let path = DrilledPath::draw(&plan, seed).expect("tortuous");
            for k in 0..2 {
                let (a, b) = (
                    path.at(3000.0 + k as f64 * leg),
                    path.at(3000.0 + (k + 1) as f64 * leg),
                );
                let from = TrueStation::new(a.md, a.inclination, a.azimuth).expect("station");
                let to = TrueStation::new(b.md, b.inclination, b.azimuth).expect("station");
                let chord = mwd_core::survey::Segment::new(from, to)
                    .expect("arc")
                    .increment();
                let miss = a.nev + chord - b.nev;
                // across the hole, horizontally (the walk's plane at 90 deg)
                let right = Vector3::new(-libm::sin(a.azimuth), libm::cos(a.azimuth), 0.0);
                sum2 += miss.dot(&right).powi(2);
                n += 1;
            }
        }
        let rms = (sum2 / n as f64).sqrt();
        let n_int = 400;
        let h = leg / n_int as f64;
        let sigma = t.sigma_rad_per_m();
        let mut variance = 0.0;
        for i in 0..n_int {
            for j in 0..n_int {
                let (a, b) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                variance += (a - leg / 2.0)
                    * (b - leg / 2.0)
                    * (-(a - b).abs() / t.correlation_length_m).exp();
            }
        }
        let expected = sigma * h * variance.sqrt();
        assert!(
            (rms / expected - 1.0).abs() < 0.2,
            "minimum curvature misses by {rms} m RMS across, expected {expected} m"
        );
    }

    #[test]
    fn the_path_is_continuous_and_its_steps_are_arcs() {
        let plan = hold(100.0, Tortuosity::default());
        let path = DrilledPath::draw(&plan, 5).expect("tortuous");
        let mut previous = path.at(plan.start_md());
        let mut md = plan.start_md();
        while md < plan.end_md() {
            md += 0.1;
            let p = path.at(md);
            let ds = p.md - previous.md;
            // position moves by the MD step, direction by less than 1 deg/m
            assert!(((p.nev - previous.nev).norm() - ds).abs() < 1e-6 * (1.0 + ds));
            let t0 = mwd_core::survey::tangent(previous.inclination, previous.azimuth);
            let t1 = mwd_core::survey::tangent(p.inclination, p.azimuth);
            assert!(
                t0.dot(&t1).min(1.0).acos() <= ds * DEG + 1e-7,
                "kink at MD {md}"
            );
            previous = p;
        }
    }

    #[test]
    fn zero_tortuosity_draws_no_path_and_bad_values_are_refused() {
        assert!(DrilledPath::draw(&hold(100.0, Tortuosity::NONE), 1).is_none());
        for (field, t) in [
            (
                "rms_deg_per_30m",
                Tortuosity {
                    rms_deg_per_30m: f64::NAN,
                    ..Tortuosity::default()
                },
            ),
            (
                "correlation_length_m",
                Tortuosity {
                    correlation_length_m: 0.0,
                    ..Tortuosity::default()
                },
            ),
            (
                "steering_length_m",
                Tortuosity {
                    steering_length_m: -1.0,
                    ..Tortuosity::default()
                },
            ),
        ] {
            let e = format!("{:#}", t.check().expect_err("refused"));
            assert!(e.contains(field), "{e}");
        }
    }
}
