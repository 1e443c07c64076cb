//! The drilling of a plan ([`Drilling`]): its schedule (a still period at
//! the tie-on; per stand, drilling at the rate of penetration, a still
//! period at the connection and an orienter turn; a final still period;
//! the sliding toolface steps and the shocks drawn from the seed) and the
//! truth at any instant ([`Truth`]): MD from the schedule, direction and
//! position at that MD on the hole as drilled (the plan's minimum-curvature
//! arcs with the run's tortuosity drawn around them,
//! [`DrilledPath`]), the gravity toolface the plan's section's plus the
//! orienter's steps, and C_b^n from them. Also the surface depth log over
//! the run.
use super::phase::{toward_section, Connection, DrillState, Phase, PhaseKind, Ramp};
use crate::sim::plan::{BuiltPlan, DrilledPath, PathPoint};
use core::f64::consts::FRAC_PI_2;
use mwd_core::conventions::{dcm_from_euler, euler_from_dcm, wrap_pi, Euler, DEG};
use mwd_core::earth::Position;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Exp};

/// The truth at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    pub time: f64,
    pub md: f64,
    /// Speed along the hole (m/s) and its rate (m/s^2).
    pub speed: f64,
    pub accel_along: f64,
    pub point: PathPoint,
    /// Gravity toolface (rad, wrapped to [-pi, pi)).
    pub toolface: f64,
    /// C_b^n.
    pub c_bn: Matrix3<f64>,
    pub state: DrillState,
    /// Geodetic position (the site moved by north, east, TVD).
    pub position: Position,
}

impl Truth {
    pub fn euler(&self) -> Euler {
        euler_from_dcm(&self.c_bn)
    }

    /// Unit direction of the hole, NED.
    pub fn tangent(&self) -> Vector3<f64> {
        mwd_core::survey::tangent(self.point.inclination, self.point.azimuth)
    }

    /// Velocity over the earth, NED (m/s).
    pub fn velocity(&self) -> Vector3<f64> {
        self.tangent() * self.speed
    }
}

/// The drilling of a plan: schedule and truth.
#[derive(Clone, Debug)]
pub struct Drilling {
    plan: BuiltPlan,
    /// The hole as drilled; `None`: the plan's own arcs (no tortuosity).
    hole: Option<DrilledPath>,
    phases: Vec<Phase>,
    /// Orienter steps (connections and sliding), and the offset before
    /// each.
    steps: Vec<Ramp>,
    offsets: Vec<f64>,
    /// Turns to a new section's toolface: (the time the boundary is
    /// reached, the ramp that ends there).
    boundary_turns: Vec<Ramp>,
    connections: Vec<Connection>,
    /// Shock times (s) while drilling.
    shocks: Vec<f64>,
    duration: f64,
}

impl Drilling {
    /// The schedule of `plan`; `seed` draws the toolface steps' signs, the
    /// sliding steps' and the shocks' times, and (from a stream of its
    /// own) the hole's tortuosity.
    pub fn new(plan: BuiltPlan, seed: u64) -> Self {
        let p = plan.drilling;
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5EED_D811_0000_0001);
        let speed = p.rop_m_per_h / 3600.0;
        let turn_rate = p.toolface_turn_rate_deg_s * DEG;
        let mut phases = Vec::new();
        let mut steps = Vec::new();
        let mut connections = Vec::new();
        // The orienter's offset from the section's toolface, and its value
        // before each step (for lookups without summing).
        let mut offset = 0.0;
        let mut offsets = Vec::new();
        // Whole turns of the connections' indexing, apart from `offset`.
        let mut revolutions = 0.0;
        let push = |phases: &mut Vec<Phase>, t0: f64, length: f64, md0: f64, kind| {
            if length > 0.0 {
                phases.push(Phase {
                    t0,
                    t1: t0 + length,
                    md0,
                    kind,
                });
            }
            t0 + length.max(0.0)
        };
        let mut md = plan.start_md();
        let end = plan.end_md();
        let mut t = push(&mut phases, 0.0, p.initial_still_s, md, PhaseKind::Still);
        // Stands counted from the tie-on; the MD lost to rounding is below
        // 1e-9 m per stand.
        while end - md > 1e-9 {
            let length = p.stand_length_m.min(end - md);
            let ramp = p.rop_ramp_s;
            let (peak, duration) = if ramp <= 0.0 {
                (speed, length / speed)
            } else if length >= speed * ramp {
                (speed, length / speed + ramp)
            } else {
                (length / ramp, 2.0 * ramp)
            };
            let t_drill = t;
            t = push(
                &mut phases,
                t,
                duration,
                md,
                PhaseKind::Drill {
                    length,
                    peak,
                    ramp: ramp.max(0.0),
                },
            );
            // Toolface steps while sliding: Poisson, away from the ramps,
            // one at a time.
            let rate = p.sliding_toolface_steps_per_hour / 3600.0;
            let step = p.sliding_toolface_step_deg * DEG;
            if rate > 0.0 && step > 0.0 {
                if let Ok(exp) = Exp::new(rate) {
                    let turn = step / turn_rate;
                    let mut te = t_drill + ramp;
                    loop {
                        te += exp.sample(&mut rng);
                        if te + turn > t - ramp {
                            break;
                        }
                        let delta = toward_section(offset, step, &mut rng);
                        steps.push(Ramp {
                            t0: te,
                            t1: te + turn,
                            delta,
                        });
                        offsets.push(revolutions + offset);
                        offset += delta;
                        te += turn;
                    }
                }
            }
            md += length;
            let still_start = t;
            // Indexed: the dwells 360 deg / n apart, the orienter turning
            // the same way between them; `offset` leaves out the whole turn
            // they make with the last turn below (the toolface is an angle).
            let dwells = p.connection_dwells.max(1);
            let dwell = p.connection_still_s / f64::from(dwells);
            let index_step = core::f64::consts::TAU / f64::from(dwells);
            let mut indexed = 0.0;
            for k in 0..dwells {
                if k > 0 {
                    let turn = index_step / turn_rate;
                    steps.push(Ramp {
                        t0: t,
                        t1: t + turn,
                        delta: index_step,
                    });
                    offsets.push(revolutions + offset + indexed);
                    indexed += index_step;
                    t = push(&mut phases, t, turn, md, PhaseKind::Turn);
                }
                t = push(&mut phases, t, dwell, md, PhaseKind::Still);
            }
            connections.push(Connection {
                still_start,
                still_end: t,
                md,
            });
            let change = p.toolface_change_per_connection_deg * DEG;
            let index_rest = if dwells > 1 { index_step } else { 0.0 };
            if end - md > 1e-9 && (change > 0.0 || index_rest > 0.0) {
                let delta = if change > 0.0 {
                    toward_section(offset, change, &mut rng)
                } else {
                    0.0
                };
                let turn = (change + index_rest) / turn_rate;
                steps.push(Ramp {
                    t0: t,
                    t1: t + turn,
                    delta: index_rest + delta,
                });
                offsets.push(revolutions + offset + indexed);
                offset += delta;
                if dwells > 1 {
                    revolutions += core::f64::consts::TAU;
                }
                t = push(&mut phases, t, turn, md, PhaseKind::Turn);
            }
        }
        let duration = t;
        let hole = DrilledPath::draw(&plan, seed);
        let mut sim = Self {
            plan,
            hole,
            phases,
            steps,
            offsets,
            boundary_turns: Vec::new(),
            connections,
            shocks: Vec::new(),
            duration,
        };
        sim.boundary_turns = sim.section_boundary_turns(turn_rate);
        sim.shocks = sim.shock_times(&mut rng);
        sim
    }

    /// At each section boundary where the section toolface jumps by D, the
    /// orienter turns by D (at its turn rate) so as to reach the new
    /// toolface as the bit reaches the boundary: the toolface stays
    /// continuous.
    fn section_boundary_turns(&self, turn_rate: f64) -> Vec<Ramp> {
        let mut turns = Vec::new();
        for k in 1..self.plan.sections.len() {
            let md_b = self.plan.sections[k].start_md;
            let before = self.plan.at_in_section(md_b, k - 1);
            let after = self.plan.at_in_section(md_b, k);
            let delta =
                wrap_pi(self.plan.section_toolface(&after) - self.plan.section_toolface(&before));
            if delta.abs() < 1e-12 {
                continue;
            }
            let tb = self.time_at_md(md_b);
            let length = delta.abs() / turn_rate;
            turns.push(Ramp {
                t0: tb - length,
                t1: tb,
                delta,
            });
        }
        turns
    }

    /// The first time the bit reaches `md` (bisection in its drill phase;
    /// the end of the run beyond the plan).
    pub fn time_at_md(&self, md: f64) -> f64 {
        for ph in &self.phases {
            if let PhaseKind::Drill { length, .. } = ph.kind {
                if md <= ph.md0 + length {
                    let (mut lo, mut hi) = (ph.t0, ph.t1);
                    for _ in 0..80 {
                        let mid = 0.5 * (lo + hi);
                        if ph.kinematics(mid).0 < md {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    return hi;
                }
            }
        }
        self.duration
    }

    fn shock_times(&self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        let v = &self.plan.drilling.vibration;
        let rate = v.shocks_per_hour / 3600.0;
        let mut shocks = Vec::new();
        let Ok(exp) = Exp::new(rate) else {
            return shocks;
        };
        if rate <= 0.0 || v.shock_peak_g <= 0.0 {
            return shocks;
        }
        for ph in &self.phases {
            if matches!(ph.kind, PhaseKind::Drill { .. }) {
                let mut t = ph.t0;
                loop {
                    t += exp.sample(rng);
                    if t >= ph.t1 {
                        break;
                    }
                    shocks.push(t);
                }
            }
        }
        shocks
    }

    pub fn plan(&self) -> &BuiltPlan {
        &self.plan
    }

    /// The hole as drilled at `md` (clamped to the plan's MD range): the
    /// plan's arcs with this run's tortuosity; the plan's section there.
    pub fn hole_at(&self, md: f64) -> PathPoint {
        match &self.hole {
            Some(hole) => hole.at(md),
            None => self.plan.at(md),
        }
    }

    /// Length of the whole run (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    pub fn connections(&self) -> &[Connection] {
        &self.connections
    }

    /// Shock times (s).
    pub fn shocks(&self) -> &[f64] {
        &self.shocks
    }

    fn phase_index(&self, t: f64) -> Option<usize> {
        let k = self.phases.partition_point(|p| p.t0 <= t);
        k.checked_sub(1)
    }

    /// (MD, speed, acceleration, state) at t.
    fn kinematics(&self, t: f64) -> (f64, f64, f64, DrillState) {
        match self.phase_index(t) {
            Some(k) if t <= self.phases[k].t1 => {
                let ph = &self.phases[k];
                let (md, v, a) = ph.kinematics(t);
                (md, v, a, ph.state())
            }
            Some(k) => {
                let ph = &self.phases[k];
                (ph.kinematics(ph.t1).0, 0.0, 0.0, DrillState::Still)
            }
            None => (self.plan.start_md(), 0.0, 0.0, DrillState::Still),
        }
    }

    /// The orienter's toolface offset at t (rad).
    fn toolface_offset(&self, t: f64) -> f64 {
        // Steps are sorted by start and do not overlap: the last one begun
        // sets the offset.
        let k = self.steps.partition_point(|r| r.t0 <= t);
        let steps = k
            .checked_sub(1)
            .map_or(0.0, |i| self.offsets[i] + self.steps[i].value(t));
        // Boundary turns: in progress until the boundary, then absorbed by
        // the new section's toolface.
        let boundary: f64 = self
            .boundary_turns
            .iter()
            .filter(|r| t < r.t1)
            .map(|r| r.value(t))
            .sum();
        steps + boundary
    }

    /// The truth at time t.
    pub fn truth(&self, t: f64) -> Truth {
        let (md, speed, accel_along, mut state) = self.kinematics(t);
        if state == DrillState::Still && self.boundary_turning(t, t) {
            state = DrillState::Connection;
        }
        // the driller sets the plan's toolface; the hole wanders around
        // the plan whatever it is (docs/drilling-simulation.md)
        let planned = self.plan.at(md);
        let point = self.hole.as_ref().map_or(planned, |hole| hole.at(md));
        let toolface = wrap_pi(self.plan.section_toolface(&planned) + self.toolface_offset(t));
        let c_bn = dcm_from_euler(&Euler::new(
            toolface,
            point.inclination - FRAC_PI_2,
            point.azimuth,
        ));
        Truth {
            time: t,
            md,
            speed,
            accel_along,
            point,
            toolface,
            c_bn,
            state,
            position: self.plan.site.displaced(&point.nev),
        }
    }

    /// Whether a turn to a new section's toolface is under way in (t0, t1)
    /// (it may begin in the still period before the stand that reaches the
    /// boundary).
    fn boundary_turning(&self, t0: f64, t1: f64) -> bool {
        self.boundary_turns.iter().any(|r| r.t0 < t1 && r.t1 > t0)
    }

    /// Whether [t0, t1] lies in one still phase with nothing moving.
    pub(super) fn still_interval(&self, t0: f64, t1: f64) -> Option<usize> {
        let k = self.phase_index(t0)?;
        let ph = &self.phases[k];
        (ph.kind == PhaseKind::Still
            && t1 <= ph.t1
            && t0 >= ph.t0
            && !self.boundary_turning(t0, t1))
        .then_some(k)
    }

    /// Whether the bit is on bottom (vibration, shocks) at t.
    pub(super) fn on_bottom(&self, t: f64) -> bool {
        self.phase_index(t).is_some_and(|k| {
            matches!(self.phases[k].kind, PhaseKind::Drill { .. }) && t <= self.phases[k].t1
        })
    }

    /// The surface depth log's MD for a true MD and TVD: md (1 + scale)
    /// + stretch md TVD (ISCWSA DSF and DST).
    pub fn logged_md(&self, md: f64, tvd: f64) -> f64 {
        self.plan.logged_md(md, tvd)
    }

    /// The depth log: (time, logged MD) every `depth_log_interval_s`.
    pub fn depth_log(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        let step = self.plan.drilling.depth_log_interval_s;
        let n = (self.duration / step).floor() as usize;
        (0..=n).map(move |i| {
            let t = i as f64 * step;
            let (md, ..) = self.kinematics(t);
            let tvd = self.hole_at(md).nev.z;
            (t, self.logged_md(md, tvd))
        })
    }

    /// Number of 20 Hz samples of the run.
    pub fn sample_count(&self, dt: f64) -> usize {
        // The last sample ends at or after the run's end (a duration on the
        // grid up to rounding gives no extra sample).
        (self.duration / dt - 1e-6).ceil().max(0.0) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::plan::{DrillingParams, Plan, Section, Site, TieOnSpec, Vibration};

    /// A hold to `hold_end_md_m` at `hold_toolface_deg`, then a 6 deg/30 m
    /// curve to 92 deg inclination and `curve_azimuth_deg`, in stands of
    /// 9 m with 60 s still at each connection.
    fn hold_then_curve(hold_end_md_m: f64, hold_toolface_deg: f64, curve_azimuth_deg: f64) -> Plan {
        Plan {
            site: Site::default(),
            tie_on: TieOnSpec {
                md_m: 3000.0,
                tvd_m: 2000.0,
                north_m: 0.0,
                east_m: 0.0,
                inclination_deg: 90.0,
                azimuth_deg: 10.0,
            },
            sections: vec![
                Section::Hold {
                    end_md_m: hold_end_md_m,
                    toolface_deg: hold_toolface_deg,
                },
                Section::Curve {
                    dls_deg_per_30m: 6.0,
                    inclination_deg: 92.0,
                    azimuth_deg: curve_azimuth_deg,
                },
            ],
            drilling: DrillingParams {
                stand_length_m: 9.0,
                connection_still_s: 60.0,
                initial_still_s: 30.0,
                vibration: Vibration::NONE,
                ..DrillingParams::default()
            },
        }
    }

    fn plan() -> BuiltPlan {
        hold_then_curve(3010.0, 20.0, 14.0)
            .build()
            .expect("valid plan")
    }

    #[test]
    fn toolface_is_continuous_across_sections_and_connections() {
        let sim = Drilling::new(plan(), 3);
        let dt = 0.05;
        let mut prev = sim.truth(0.0);
        let mut t = dt;
        while t < sim.duration() {
            let now = sim.truth(t);
            let jump = wrap_pi(now.toolface - prev.toolface).abs();
            // At most the turn rate (10 deg/s) plus the arc's own change.
            assert!(
                jump < 0.6 * DEG,
                "toolface jumps {} deg at {t} s",
                jump / DEG
            );
            // The orienter's steps stay around the section's toolface.
            if !sim.boundary_turning(t, t) {
                let planned = sim.plan().at(now.md);
                let off = wrap_pi(now.toolface - sim.plan().section_toolface(&planned));
                assert!(off.abs() <= 30.0 * DEG + 1e-9, "{} deg off", off / DEG);
            }
            prev = now;
            t += dt;
        }
    }

    #[test]
    fn a_turn_to_a_new_section_toolface_before_drilling_is_not_still() {
        // The boundary 0.01 m into the second stand: the turn from
        // toolface 150 deg to the build's 0 deg (15 s) starts at the
        // connection, before drilling resumes.
        let mut plan = hold_then_curve(3009.01, 150.0, 10.0);
        plan.drilling.toolface_change_per_connection_deg = 0.0;
        plan.drilling.sliding_toolface_steps_per_hour = 0.0;
        let sim = Drilling::new(plan.build().expect("valid"), 1);
        let dt = 0.05;
        let mut prev = sim.truth(0.0);
        let mut turning_at_rest = 0;
        let mut t = dt;
        while t < sim.duration() {
            let now = sim.truth(t);
            if (now.toolface - prev.toolface).abs() > 1e-9 && now.md == prev.md {
                turning_at_rest += 1;
                assert_eq!(now.state, DrillState::Connection, "at {t} s");
            }
            prev = now;
            t += dt;
        }
        assert!(turning_at_rest > 10, "{turning_at_rest}");
    }

    #[test]
    fn zero_tortuosity_drills_the_plan_exactly_and_two_seeds_two_holes() {
        let mut straight = hold_then_curve(3010.0, 20.0, 14.0);
        straight.drilling.tortuosity = crate::sim::plan::Tortuosity::NONE;
        let sim = Drilling::new(straight.build().expect("valid"), 3);
        let mut t = 0.0;
        while t < sim.duration() {
            let truth = sim.truth(t);
            assert_eq!(truth.point, sim.plan().at(truth.md), "at {t} s");
            t += 7.3;
        }
        // the default tortuosity: each seed its own hole, the same MD and
        // schedule, the toolface the plan's section's
        let (a, b) = (Drilling::new(plan(), 3), Drilling::new(plan(), 4));
        let end = a.duration();
        let (ta, tb) = (a.truth(end), b.truth(end));
        assert_eq!(ta.md, tb.md);
        assert!((ta.point.nev - tb.point.nev).norm() > 1e-3);
        assert!((ta.point.nev - a.plan().at(ta.md).nev).norm() > 1e-3);
        assert_eq!(ta, Drilling::new(plan(), 3).truth(end));
        // the depth log follows the drilled hole's TVD
        let (_, logged) = a.depth_log().last().expect("a log");
        assert_eq!(logged, a.logged_md(ta.md, ta.point.nev.z));
    }

    /// Four dwells: the still time in four equal still periods at the
    /// connection's MD, the toolface 90 deg apart in them (the orienter
    /// turning one way), and the drilling toolface after the connection
    /// as without indexing (a whole turn more).
    #[test]
    fn an_indexed_connection_dwells_at_toolfaces_a_quarter_turn_apart() {
        let mut indexed = hold_then_curve(3010.0, 20.0, 14.0);
        indexed.drilling.connection_dwells = 4;
        let sim = Drilling::new(indexed.build().expect("valid"), 3);
        let plain = Drilling::new(plan(), 3);
        let c = sim.connections()[1];
        assert_eq!(c.md, plain.connections()[1].md);
        // four dwells of 15 s, three 9-s turns of 90 deg between them
        let dwell = 15.0;
        let turn = 90.0 / 10.0;
        assert!((c.still_end - c.still_start - (4.0 * dwell + 3.0 * turn)).abs() < 1e-9);
        let mut toolfaces = Vec::new();
        for k in 0..4 {
            let t0 = c.still_start + k as f64 * (dwell + turn);
            let (a, b) = (sim.truth(t0 + 0.1), sim.truth(t0 + dwell - 0.1));
            assert_eq!((a.state, b.state), (DrillState::Still, DrillState::Still));
            assert_eq!((a.md, a.toolface), (c.md, b.toolface));
            assert!(sim.still_interval(t0 + 0.1, t0 + dwell - 0.1).is_some());
            toolfaces.push(a.toolface);
            if k < 3 {
                assert_eq!(
                    sim.truth(t0 + dwell + 0.5 * turn).state,
                    DrillState::Connection
                );
            }
        }
        for pair in toolfaces.windows(2) {
            let step = wrap_pi(pair[1] - pair[0]);
            assert!((step - 90.0 * DEG).abs() < 1e-9, "{} deg", step / DEG);
        }
        // drilling again: the toolface as the plain schedule's (the same
        // steps drawn), a whole turn on
        let md = c.md + 4.5;
        let (ti, tp) = (sim.time_at_md(md), plain.time_at_md(md));
        let step = wrap_pi(sim.truth(ti).toolface - plain.truth(tp).toolface);
        assert!(step.abs() < 1e-9, "{} deg", step / DEG);
    }

    #[test]
    fn the_run_reaches_the_plan_end_and_stops() {
        let sim = Drilling::new(plan(), 3);
        let end = sim.truth(sim.duration());
        assert!((end.md - sim.plan().end_md()).abs() < 1e-9);
        assert_eq!(end.state, DrillState::Still);
        // Stands of 9 m; the last, shorter one ends with a still period too.
        let length = sim.plan().end_md() - sim.plan().start_md();
        assert!(length > 27.0 && length < 36.0, "{length}");
        assert_eq!(sim.connections().len(), 4);
        for (i, c) in sim.connections().iter().enumerate() {
            let md = (sim.plan().start_md() + 9.0 * (i + 1) as f64).min(sim.plan().end_md());
            assert!((c.md - md).abs() < 1e-9);
            assert!((c.still_end - c.still_start - 60.0).abs() < 1e-9);
        }
    }
}
