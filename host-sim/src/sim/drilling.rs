//! The drilling simulator: a lateral drilled along a [`BuiltPlan`] with an
//! orienter on coiled tubing or a sliding motor (no string rotation).
//!
//! * Schedule: a still period at the tie-on, then per stand: drilling at
//!   the rate of penetration (linear speed ramps at both ends), a still
//!   period at the connection, an orienter toolface turn; a final still
//!   period. While sliding, occasional toolface steps (Poisson).
//! * Truth: MD(t) from the schedule; direction and position at MD from the
//!   plan's minimum-curvature arcs (`mwd_core::survey::Segment::at`);
//!   gravity toolface = the section's toolface (a hold's setting, a curve's
//!   arc direction) + the orienter's steps. C_b^n from (toolface,
//!   inclination - 90 deg, azimuth) by `conventions::dcm_from_euler`.
//! * Ideal sensor outputs over each 50 ms interval: omega_ib^b = the exact
//!   rotation vector of C_b^n(t0)^T C_b^n(t1) / dt (omega_nb^b) + the mean
//!   of C_n^b (omega_ie^n + omega_en^n) (Simpson, 3 points); specific force
//!   f^b = mean of C_n^b (a^n + (2 omega_ie^n + omega_en^n) x v^n - g^n)
//!   (Simpson), with a^n = ROP' t + ROP^2 kappa (k x t) along the arc.
//! * Then the vibration as the 20 Hz samples see it (white, the in-band
//!   power the sensor's low-pass lets through; shocks), and the SCC1300's
//!   error model ([`SensorErrors`]).
use super::plan::{BuiltPlan, PathPoint};
use super::sensor::{SensorErrors, SensorModel, SimSample};
use core::f64::consts::FRAC_PI_2;
use mwd_core::conventions::{dcm_from_euler, euler_from_dcm, wrap_pi, Euler, DEG};
use mwd_core::earth::{LocalEarth, Position};
use mwd_core::sensor_units::STANDARD_GRAVITY;
use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Exp, StandardNormal};

/// What the rig is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrillState {
    /// On bottom, the hole getting deeper (speed ramps included).
    Drilling,
    /// At a connection, the orienter turning the toolface.
    Connection,
    /// At rest (pumps off, connection or tie-on).
    Still,
}

impl DrillState {
    pub fn name(self) -> &'static str {
        match self {
            Self::Drilling => "drilling",
            Self::Connection => "connection",
            Self::Still => "still",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum PhaseKind {
    Still,
    Turn,
    /// Drilling `length` m from the phase's MD, peak speed (m/s), ramp (s).
    Drill {
        length: f64,
        peak: f64,
        ramp: f64,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Phase {
    t0: f64,
    t1: f64,
    md0: f64,
    kind: PhaseKind,
}

impl Phase {
    /// (MD, speed, acceleration along the hole) at t in the phase.
    fn kinematics(&self, t: f64) -> (f64, f64, f64) {
        let PhaseKind::Drill { length, peak, ramp } = self.kind else {
            return (self.md0, 0.0, 0.0);
        };
        let u = (t - self.t0).clamp(0.0, self.t1 - self.t0);
        let total = self.t1 - self.t0;
        if ramp <= 0.0 {
            return (self.md0 + peak * u, peak, 0.0);
        }
        if u < ramp {
            (
                self.md0 + peak * u * u / (2.0 * ramp),
                peak * u / ramp,
                peak / ramp,
            )
        } else if u < total - ramp {
            (self.md0 + peak * (0.5 * ramp + u - ramp), peak, 0.0)
        } else {
            let w = total - u;
            (
                self.md0 + length - peak * w * w / (2.0 * ramp),
                peak * w / ramp,
                -peak / ramp,
            )
        }
    }

    fn state(&self) -> DrillState {
        match self.kind {
            PhaseKind::Still => DrillState::Still,
            PhaseKind::Turn => DrillState::Connection,
            PhaseKind::Drill { .. } => DrillState::Drilling,
        }
    }
}

/// A linear change of the toolface offset by `delta` over [t0, t1].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Ramp {
    t0: f64,
    t1: f64,
    delta: f64,
}

impl Ramp {
    fn value(&self, t: f64) -> f64 {
        if t <= self.t0 {
            0.0
        } else if t >= self.t1 {
            self.delta
        } else {
            self.delta * (t - self.t0) / (self.t1 - self.t0)
        }
    }
}

/// An orienter step of `size` (rad) from the offset `offset` to the
/// section's toolface: back towards it when off it, either way at random
/// when on it. The driller holds the toolface the section needs; the steps
/// stay within +-(the larger step size) of it.
fn toward_section(offset: f64, size: f64, rng: &mut ChaCha8Rng) -> f64 {
    let direction = if offset.abs() > 1e-12 {
        -offset.signum()
    } else if rng.random::<bool>() {
        1.0
    } else {
        -1.0
    };
    size * direction
}

/// A connection: the still period's times and the MD there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Connection {
    pub still_start: f64,
    pub still_end: f64,
    pub md: f64,
}

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
    /// sliding steps' and the shocks' times.
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
                        offsets.push(offset);
                        offset += delta;
                        te += turn;
                    }
                }
            }
            md += length;
            connections.push(Connection {
                still_start: t,
                still_end: t + p.connection_still_s,
                md,
            });
            t = push(&mut phases, t, p.connection_still_s, md, PhaseKind::Still);
            let change = p.toolface_change_per_connection_deg * DEG;
            if end - md > 1e-9 && change > 0.0 {
                let delta = toward_section(offset, change, &mut rng);
                let turn = change / turn_rate;
                steps.push(Ramp {
                    t0: t,
                    t1: t + turn,
                    delta,
                });
                offsets.push(offset);
                offset += delta;
                t = push(&mut phases, t, turn, md, PhaseKind::Turn);
            }
        }
        let duration = t;
        let mut sim = Self {
            plan,
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
        let point = self.plan.at(md);
        let toolface = wrap_pi(self.plan.section_toolface(&point) + self.toolface_offset(t));
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
    fn still_interval(&self, t0: f64, t1: f64) -> Option<usize> {
        let k = self.phase_index(t0)?;
        let ph = &self.phases[k];
        (ph.kind == PhaseKind::Still
            && t1 <= ph.t1
            && t0 >= ph.t0
            && !self.boundary_turning(t0, t1))
        .then_some(k)
    }

    /// Whether the bit is on bottom (vibration, shocks) at t.
    fn on_bottom(&self, t: f64) -> bool {
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
            let tvd = self.plan.at(md).nev.z;
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

/// The rotation vector of a rotation matrix (its exact logarithm):
/// sin(theta) k from the skew part, theta from atan2, which keeps full
/// precision at the tiny angles of drilling (acos would not).
pub fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) * 0.5;
    let s = v.norm();
    let c = 0.5 * (r.trace() - 1.0);
    let theta = libm::atan2(s, c);
    if s < 1e-300 {
        return Vector3::zeros();
    }
    v * (theta / s)
}

/// Interval means of omega_ib^b (rad/s) and the specific force (m/s^2).
type IdealMeans = (Vector3<f64>, Vector3<f64>);

/// One simulated sample with the truth at its end and what clipped.
#[derive(Clone, Debug)]
pub struct DrillSample {
    pub sample: SimSample,
    pub truth: Truth,
    /// An accelerometer axis beyond 6 g or a gyro beyond 300 deg/s in the
    /// measured sample (what the part flags).
    pub accel_over_range: bool,
    pub gyro_over_range: bool,
}

/// The 20 Hz sample stream of a drilling run.
pub struct DrillingSimulator<'a> {
    drilling: &'a Drilling,
    dt: f64,
    index: usize,
    count: usize,
    errors: SensorErrors,
    vibration_rng: ChaCha8Rng,
    previous: Truth,
    /// Still phase index and ideal means of the last still interval.
    still_cache: Option<(usize, IdealMeans)>,
    next_shock: usize,
    /// Per-sample vibration sigmas: accel (m/s^2) x, y, z and gyro (rad/s).
    accel_sigma: Vector3<f64>,
    gyro_sigma: f64,
    /// A shock's area (m/s) and the low-pass time constant (s).
    shock_area: f64,
    tau: f64,
}

impl<'a> DrillingSimulator<'a> {
    pub fn new(drilling: &'a Drilling, model: SensorModel, dt: f64) -> Self {
        let v = drilling.plan.drilling.vibration;
        let seed = model.seed;
        let frac = libm::sqrt(v.passed_power_fraction());
        let g = STANDARD_GRAVITY;
        Self {
            drilling,
            dt,
            index: 0,
            count: drilling.sample_count(dt),
            errors: SensorErrors::new(model),
            vibration_rng: ChaCha8Rng::seed_from_u64(seed ^ 0x0B1B_0000_0000_0002),
            previous: drilling.truth(0.0),
            still_cache: None,
            next_shock: 0,
            accel_sigma: Vector3::new(v.lateral_rms_g, v.axial_rms_g, v.lateral_rms_g) * g * frac,
            gyro_sigma: v.angular_rms_deg_s * DEG * frac,
            // Half-sine of peak A and duration T: area 2 A T / pi.
            shock_area: 2.0 * v.shock_peak_g * g * v.shock_duration_ms * 1e-3
                / core::f64::consts::PI,
            tau: 1.0 / (2.0 * core::f64::consts::PI * v.sensor_lowpass_hz),
        }
    }

    /// Ideal interval means (omega_ib^b, f^b) over [prev.time, end.time].
    fn ideal_means(&self, start: &Truth, mid: &Truth, end: &Truth) -> IdealMeans {
        let earth = LocalEarth::at(&mid.position);
        let w_ie = earth.earth_rate_n();
        let g = earth.gravity_n();
        let nav_terms = |s: &Truth| {
            let v = s.velocity();
            let w_en = earth.transport_rate_n(&v);
            let t = s.tangent();
            // Along the arc: d(v t)/dt = v' t + v^2 kappa (k x t).
            let a = t * s.accel_along
                + s.point.axis.cross(&t) * (s.speed * s.speed * s.point.curvature);
            let c_nb = s.c_bn.transpose();
            (
                c_nb * (w_ie + w_en),
                c_nb * (a + (w_ie * 2.0 + w_en).cross(&v) - g),
            )
        };
        let (w0, f0) = nav_terms(start);
        let (wm, fm) = nav_terms(mid);
        let (w1, f1) = nav_terms(end);
        let w_nb = rotation_vector(&(start.c_bn.transpose() * end.c_bn)) / self.dt;
        (
            w_nb + (w0 + wm * 4.0 + w1) / 6.0,
            (f0 + fm * 4.0 + f1) / 6.0,
        )
    }

    fn normal(&mut self) -> f64 {
        StandardNormal.sample(&mut self.vibration_rng)
    }
}

impl Iterator for DrillingSimulator<'_> {
    type Item = DrillSample;

    fn next(&mut self) -> Option<DrillSample> {
        if self.index >= self.count {
            return None;
        }
        let d = self.drilling;
        let t0 = self.index as f64 * self.dt;
        self.index += 1;
        let t1 = self.index as f64 * self.dt;
        let end = d.truth(t1);
        let (true_rate, true_accel) = match (d.still_interval(t0, t1), self.still_cache) {
            (Some(k), Some((cached, means))) if k == cached => means,
            (still, _) => {
                let mid = d.truth(0.5 * (t0 + t1));
                let means = self.ideal_means(&self.previous, &mid, &end);
                self.still_cache = still.map(|k| (k, means));
                means
            }
        };
        // Vibration as the samples see it, only on bottom.
        let (mut rate_in, mut accel_in) = (true_rate, true_accel);
        if d.on_bottom(t1) {
            for axis in 0..3 {
                accel_in[axis] += self.accel_sigma[axis] * self.normal();
            }
            for axis in [0, 2] {
                rate_in[axis] += self.gyro_sigma * self.normal();
            }
        }
        // Shocks in this interval: the low-passed impulse area/tau
        // exp(-lag/tau), read at the interval's end, in a random lateral
        // direction.
        while self.next_shock < d.shocks.len() && d.shocks[self.next_shock] < t1 {
            let ts = d.shocks[self.next_shock];
            self.next_shock += 1;
            if ts < t0 {
                continue;
            }
            let angle: f64 = self.vibration_rng.random::<f64>() * core::f64::consts::TAU;
            let size = self.shock_area / self.tau * libm::exp(-(t1 - ts) / self.tau);
            accel_in.x += size * libm::cos(angle);
            accel_in.z += size * libm::sin(angle);
        }
        let (gyro, accel) = self.errors.measure(self.dt, &rate_in, &accel_in);
        let accel_limit = f64::from(mwd_core::sensor_units::ACCEL_RANGE_G) * STANDARD_GRAVITY;
        let gyro_limit = f64::from(mwd_core::sensor_units::GYRO_RANGE_DEG_S) * DEG;
        let accel_over_range = accel.iter().any(|a| a.abs() > accel_limit);
        let gyro_over_range = gyro.x.abs() > gyro_limit || gyro.z.abs() > gyro_limit;
        let truth = end;
        self.previous = end;
        Some(DrillSample {
            sample: SimSample {
                time: t1,
                gyro,
                accel,
                true_rate,
                true_accel,
                truth: truth.euler(),
                position_code: None,
            },
            truth,
            accel_over_range,
            gyro_over_range,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::plan::{DrillingParams, Plan, Section, Site, TieOnSpec, Vibration};

    fn plan() -> BuiltPlan {
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
                    end_md_m: 3010.0,
                    toolface_deg: 20.0,
                },
                Section::Curve {
                    dls_deg_per_30m: 6.0,
                    inclination_deg: 92.0,
                    azimuth_deg: 14.0,
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
        .build()
        .expect("valid plan")
    }

    #[test]
    fn rotation_vector_inverts_the_exponential() {
        for v in [
            Vector3::new(1e-7, -2e-7, 3e-8),
            Vector3::new(0.3, -0.2, 0.1),
            Vector3::new(0.0, 2.5, 0.0),
        ] {
            let r = mwd_core::attitude::dcm_from_rotation_vector(&v);
            assert!((rotation_vector(&r) - v).norm() < 1e-15 * (1.0 + v.norm() * 10.0));
        }
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
                let off = wrap_pi(now.toolface - sim.plan().section_toolface(&now.point));
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
        let p = plan();
        let mut plan = Plan {
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
                    end_md_m: 3009.01,
                    toolface_deg: 150.0,
                },
                Section::Curve {
                    dls_deg_per_30m: 6.0,
                    inclination_deg: 92.0,
                    azimuth_deg: 10.0,
                },
            ],
            drilling: p.drilling,
        };
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
