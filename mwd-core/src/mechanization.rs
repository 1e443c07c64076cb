//! Strapdown mechanization in the NED frame at the probe's sample rate
//! (paper section 2.2, eq. 3-8): attitude quaternion, velocity with Coriolis,
//! transport rate and gravity, and geodetic position in f64.
//!
//! The attitude update is paper eq. 3,
//! q(n_k <- b_k) = q(n_k <- n_{k-1}) q(n_{k-1} <- b_{k-1}) q(b_{k-1} <- b_k),
//! with the body part from the gyro increments omega_ib^b dt corrected for
//! coning (eq. 6-7) and the navigation part from zeta = omega_in^n dt
//! (eq. 4-5). Paper eq. 8 subtracts omega_in^b in the body part as well;
//! with the navigation-frame part applied too, that would count the earth
//! and transport rate twice, so the body part uses omega_ib^b alone.
use crate::attitude::{
    coning_rotation_vector, quat_from_rotation_vector, ToolAxisRate, ToolAxisRateEstimator,
};
use crate::earth::{displaced_with_trig, LocalEarth, Position};
use crate::probe_sample::ProbeSample;
use nalgebra::{UnitQuaternion, Vector3};

/// One sample of the probe's inertial sensors in the body frame, averaged
/// over the sample interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSample {
    /// Angular rate omega_ib^b (rad/s); the y (tool-axis) component is the
    /// accelerometer-derived rate on the probe.
    pub rate: Vector3<f64>,
    /// Specific force f_ib^b (m/s^2).
    pub specific_force: Vector3<f64>,
}

/// The navigation solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavState {
    /// Body-to-NED rotation (C_b^n as a quaternion).
    pub attitude: UnitQuaternion<f64>,
    /// Velocity over the earth in NED (m/s).
    pub velocity: Vector3<f64>,
    pub position: Position,
}

impl NavState {
    /// At rest at a place with a given attitude.
    pub fn at_rest(attitude: UnitQuaternion<f64>, position: Position) -> Self {
        Self {
            attitude,
            velocity: Vector3::zeros(),
            position,
        }
    }
}

/// The strapdown integrator. Keeps the previous increments for the
/// two-sample coning and sculling corrections.
#[derive(Clone, Copy, Debug)]
pub struct Strapdown {
    state: NavState,
    dt: f64,
    previous: Option<(Vector3<f64>, Vector3<f64>)>,
    /// Sine and cosine of the latitude the last step ended at, and that
    /// latitude: they spare `apply_correction` its trigonometry.
    latitude_trig: Option<(f64, LatitudeTrig)>,
    /// The local earth at `state`, once asked for: the input of a step
    /// (the navigation frame's rate) and the step itself share it.
    earth: Option<LocalEarth>,
}

impl Strapdown {
    /// `dt` is the sample interval (s): `timing::SAMPLE_INTERVAL_S` on the
    /// probe.
    pub fn new(state: NavState, dt: f64) -> Self {
        Self {
            state,
            dt,
            previous: None,
            latitude_trig: None,
            earth: None,
        }
    }

    pub fn state(&self) -> &NavState {
        &self.state
    }

    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Replaces the state (e.g. after alignment) and forgets the previous
    /// increments.
    pub fn reset(&mut self, state: NavState) {
        self.state = state;
        self.previous = None;
        self.latitude_trig = None;
        self.earth = None;
    }

    /// The local earth at the current solution (computed once per state).
    pub fn local_earth(&mut self) -> LocalEarth {
        *self
            .earth
            .get_or_insert_with(|| LocalEarth::at(&self.state.position))
    }

    /// The navigation frame's rate in body axes at the current solution
    /// ([`frame_rate_in_body`], with the local earth the next step uses).
    pub fn frame_rate_in_body(&mut self) -> Vector3<f64> {
        let earth = self.local_earth();
        frame_rate_in_body_with(&self.state, &earth)
    }

    /// Advances the solution by one sample interval.
    ///
    /// The latitude's sine and cosine are computed once (`libm::sincos`)
    /// and give the earth rate, the transport rate, gravity and the radii;
    /// the cosine at the interval's mid-latitude and the sine and cosine at
    /// the new latitude (kept for [`apply_correction`](Self::apply_correction))
    /// follow from them by the angle-sum formulas with series in the
    /// latitude increment, exact to f64 rounding.
    pub fn step(&mut self, sample: &ImuSample) {
        let dt = self.dt;
        let earth = self.local_earth();
        self.earth = None;
        let s = &mut self.state;
        let dtheta = sample.rate * dt;
        let dv = sample.specific_force * dt;
        // With no history (first sample) the increments are taken as
        // constant over the last two intervals: the corrections vanish.
        let (prev_dtheta, prev_dv) = self.previous.unwrap_or((dtheta, dv));
        self.previous = Some((dtheta, dv));

        let pos = s.position;
        let trig = LatitudeTrig {
            sin: earth.sin_lat,
            cos: earth.cos_lat,
        };
        let omega_ie = earth.earth_rate_n();
        let omega_en = earth.transport_rate_n(&s.velocity);
        let zeta = (omega_ie + omega_en) * dt; // eq. 5, rates held over the interval

        // Velocity: the specific-force increment with the rotation and
        // two-sample sculling corrections, resolved at the start of the
        // interval and rotated by half the frame's turn,
        // (I - 0.5 [zeta x]) C_b^n dv_body.
        let dv_body =
            dv + dtheta.cross(&dv) * 0.5 + (prev_dtheta.cross(&dv) + prev_dv.cross(&dtheta)) / 12.0;
        let dv_start = s.attitude.transform_vector(&dv_body);
        let dv_nav = dv_start - zeta.cross(&dv_start) * 0.5;
        let coriolis = (omega_ie * 2.0 + omega_en).cross(&s.velocity);
        let velocity = s.velocity + dv_nav + (earth.gravity_n() - coriolis) * dt;

        // Attitude, eq. 3-7.
        let body_rotation =
            quat_from_rotation_vector(&coning_rotation_vector(&prev_dtheta, &dtheta));
        let nav_rotation = quat_from_rotation_vector(&-zeta);
        let attitude = renormalized(nav_rotation * s.attitude * body_rotation);

        // Position in f64 with the interval's starting velocity, the
        // longitude with the cosine of the mid-latitude. Not the trapezoid:
        // the filter's transition is first order (eq. 15, dp' = v dt), the
        // exact linearisation of this step, while the trapezoid's extra
        // (v_end - v_start) dt / 2 per step is a position change the
        // filter never models. Under a zero-velocity update every cycle it
        // is an uncorrected vertical accelerometer bias b times dt^2 / 2
        // per step: the height crept by b dt / 2 (0.88 m/h per mg) outside
        // its sigma (docs/filter-derivation.md section 5c). From rest to
        // rest the two rules place the tool alike within dt/2 of the
        // velocity change (a quarter of a millimetre at 1 cm/s).
        let mean_v = s.velocity;
        let lat = pos.lat + mean_v.x / earth.meridian * dt;
        let half_step = 0.5 * (lat - pos.lat);
        let cos_mid = match shifted_trig(&trig, half_step) {
            Some(t) => t.cos,
            None => libm::cos(pos.lat + half_step),
        };
        let lon = pos.lon + mean_v.y / (earth.transverse * cos_mid) * dt;
        let height = pos.height - mean_v.z * dt;

        *s = NavState {
            attitude,
            velocity,
            position: Position::new(lat, lon, height),
        };
        // For the feedback that usually follows (`apply_correction`).
        self.latitude_trig = shifted_trig(&trig, lat - pos.lat).map(|t| (lat, t));
    }

    /// Closed-loop feedback of estimated errors (error = computed - true):
    /// the attitude error phi (nav frame, C_computed = (I - [phi x]) C_true),
    /// the velocity error (NED, m/s) and the position error (NED, m).
    pub fn apply_correction(
        &mut self,
        attitude_error_n: &Vector3<f64>,
        velocity_error_n: &Vector3<f64>,
        position_error_ned_m: &Vector3<f64>,
    ) {
        let s = &mut self.state;
        s.attitude = renormalized(quat_from_rotation_vector(attitude_error_n) * s.attitude);
        s.velocity -= velocity_error_n;
        // The sine and cosine of the latitude from the last step, if the
        // latitude has not been changed since.
        let (sin_lat, cos_lat) = match self.latitude_trig {
            Some((lat, trig)) if lat == s.position.lat => (trig.sin, trig.cos),
            _ => libm::sincos(s.position.lat),
        };
        s.position = displaced_with_trig(&s.position, sin_lat, cos_lat, &-position_error_ned_m);
        self.earth = None;
        self.latitude_trig = None;
    }
}

/// Sine and cosine of a latitude.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LatitudeTrig {
    sin: f64,
    cos: f64,
}

/// Largest latitude shift (rad) that [`shifted_trig`] takes by series:
/// 6 m of latitude, 120 m/s over a 50 ms step.
const SERIES_SHIFT: f64 = 1e-6;

/// Sine and cosine of `lat + d` from those of `lat`, by the angle-sum
/// formulas with cos d = 1 - d^2/2 and sin d = d - d^3/6. For |d| <=
/// [`SERIES_SHIFT`] the truncation is below d^4/24 = 4.2e-26 absolute,
/// under half an ulp of the cosine anywhere but within 1e-9 rad of a pole:
/// the result is libm's to rounding. `None` for a larger (or non-finite)
/// shift.
fn shifted_trig(trig: &LatitudeTrig, d: f64) -> Option<LatitudeTrig> {
    if d.abs() > SERIES_SHIFT || d.is_nan() {
        return None;
    }
    let d2 = d * d;
    let cos_d = 1.0 - 0.5 * d2;
    let sin_d = d - d * d2 * (1.0 / 6.0);
    Some(LatitudeTrig {
        sin: trig.sin * cos_d + trig.cos * sin_d,
        cos: trig.cos * cos_d - trig.sin * sin_d,
    })
}

/// `q / |q|` for a quaternion that is a product of unit quaternions, so
/// |q|^2 = 1 + e with e at rounding level: 1/|q| = 1 - e/2 + 3 e^2/8 with a
/// truncation below 5 |e|^3 / 16 (3e-19 for |e| <= 1e-6, under f64's
/// resolution). Larger departures take the square root.
fn renormalized(q: UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    let q = q.into_inner();
    let e = q.norm_squared() - 1.0;
    let scale = if e.abs() <= 1e-6 {
        1.0 - e * (0.5 - 0.375 * e)
    } else {
        1.0 / libm::sqrt(1.0 + e)
    };
    UnitQuaternion::new_unchecked(q * scale)
}

/// The rate the navigation frame turns at (earth rate plus transport
/// rate), in body axes at the solution `state`: what a tool at rest senses,
/// and the reference of the accelerometer-derived tool-axis rate.
pub fn frame_rate_in_body(state: &NavState) -> Vector3<f64> {
    frame_rate_in_body_with(state, &LocalEarth::at(&state.position))
}

/// [`frame_rate_in_body`] with the local earth at `state` at hand.
fn frame_rate_in_body_with(state: &NavState, earth: &LocalEarth) -> Vector3<f64> {
    let omega_in_n = earth.earth_rate_n() + earth.transport_rate_n(&state.velocity);
    state.attitude.inverse_transform_vector(&omega_in_n)
}

/// Where the mechanization's tool-axis (y) rate comes from: no gyro senses
/// it on the probe.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolAxisSource {
    /// The tool is still: it turns with the navigation frame (earth and
    /// transport rate in body axes at the current solution). The rate
    /// derived from accelerometer roll (eq. 1-2) differences two
    /// single-sample rolls: with Table 4's accelerometer noise (0.058 m/s^2
    /// on x) that is ~0.17 rad/s per sample, far above Table 5's model, and
    /// its sum is the last sample's roll noise; a static alignment does
    /// better without it.
    AtRest,
    /// The tool may move: the rate derived from successive accelerometer
    /// rolls (eq. 1-2); where that is unavailable (first sample, tool near
    /// vertical) the tool is taken as not turning about its axis relative
    /// to the navigation frame, and the caller is told.
    AccelerometerRoll,
}

/// Builds the mechanization's input from the probe's samples: the x and z
/// gyros and the accelerometers as they are, and the tool-axis rate from
/// the chosen [`ToolAxisSource`].
#[derive(Clone, Copy, Debug, Default)]
pub struct ProbeInput {
    tool_axis: ToolAxisRateEstimator,
}

impl ProbeInput {
    pub fn new() -> Self {
        Self::default()
    }

    /// The sample for the next mechanization step from a calibrated probe
    /// sample, given the navigation frame's rate in body axes at the
    /// current solution ([`frame_rate_in_body`], or the
    /// [`Strapdown::frame_rate_in_body`] of the filter that will take the
    /// sample), and the tool-axis rate used: `Unavailable` when the
    /// accelerometer roll gave none and the frame's rate stood in. At rest
    /// the estimator of the roll-derived rate is left as it is.
    pub fn imu_sample(
        &mut self,
        frame_rate_in_body: &Vector3<f64>,
        sample: &ProbeSample,
        source: ToolAxisSource,
        dt: f64,
    ) -> (ImuSample, ToolAxisRate) {
        let omega_in_b = frame_rate_in_body;
        let (rate_y, used) = match source {
            ToolAxisSource::AtRest => (omega_in_b.y, ToolAxisRate::Valid(omega_in_b.y)),
            ToolAxisSource::AccelerometerRoll => {
                match self.tool_axis.update(sample, omega_in_b, dt) {
                    ToolAxisRate::Valid(rate) => (rate, ToolAxisRate::Valid(rate)),
                    ToolAxisRate::Unavailable => (omega_in_b.y, ToolAxisRate::Unavailable),
                }
            }
        };
        let imu = ImuSample {
            rate: sample.rate_with_tool_axis(rate_y),
            specific_force: sample.specific_force,
        };
        (imu, used)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{dcm_from_quat, quat_from_euler, Euler};
    use crate::earth::{earth_rate_n, gravity_n, transport_rate_n};
    use crate::timing::SAMPLE_INTERVAL_S;
    use nalgebra::Matrix3;
    use proptest::prelude::*;

    /// The exact outputs of a perfect probe at rest.
    fn ideal_static_sample(state: &NavState) -> ImuSample {
        let c_nb = dcm_from_quat(&state.attitude).transpose();
        ImuSample {
            rate: c_nb * earth_rate_n(state.position.lat),
            specific_force: c_nb * -gravity_n(&state.position),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]
        /// A stationary noise-free probe stays put: over 60 s at 20 Hz the
        /// position drifts less than 1 mm and the velocity stays below
        /// 1e-6 m/s, for any attitude and latitude away from the poles.
        #[test]
        fn stationary_probe_stays_put(
            roll in -3.1f64..3.1, pitch in -1.5f64..1.5, heading in -3.1f64..3.1,
            lat_deg in -80.0f64..80.0, height in -3000.0f64..3000.0,
        ) {
            let start = NavState::at_rest(
                quat_from_euler(&Euler::new(roll, pitch, heading)),
                Position::from_degrees(lat_deg, 126.7, height),
            );
            let sample = ideal_static_sample(&start);
            let mut nav = Strapdown::new(start, SAMPLE_INTERVAL_S);
            for _ in 0..1200 {
                nav.step(&sample);
            }
            let end = nav.state();
            prop_assert!(end.position.ned_from(&start.position).norm() < 1e-3);
            prop_assert!(end.velocity.norm() < 1e-6);
            let turn = (dcm_from_quat(&end.attitude).transpose() * dcm_from_quat(&start.attitude)
                - Matrix3::identity()).abs().max();
            prop_assert!(turn < 1e-9);
        }
    }

    #[test]
    fn small_angle_quaternion_series_are_libm_to_rounding() {
        // Below SMALL_ANGLE (1e-4 rad) the series' truncation is < 2.2e-29
        // (scalar part) and < 5.2e-20 relative (vector part): what is left
        // is the rounding of a few operations.
        for (i, angle) in [1e-12, 3e-9, 4.4e-6, 1e-5, 3.3e-5, 7.7e-5, 9.99e-5]
            .into_iter()
            .enumerate()
        {
            let axis = Vector3::new(0.3, -0.5 + 0.1 * i as f64, 0.8).normalize();
            let v = axis * angle;
            let q = quat_from_rotation_vector(&v);
            let half = 0.5 * v.norm();
            assert!((q.w - libm::cos(half)).abs() <= 2.3e-16, "{angle}: {}", q.w);
            let k = libm::sin(half) / v.norm();
            for j in 0..3 {
                let (got, want) = (q.imag()[j], k * v[j]);
                assert!((got - want).abs() <= 4.5e-16 * want.abs(), "{angle} {j}");
            }
        }
    }

    fn latitude_trig(lat: f64) -> LatitudeTrig {
        let (sin, cos) = libm::sincos(lat);
        LatitudeTrig { sin, cos }
    }

    #[test]
    fn shifted_latitude_trig_is_libm_to_rounding() {
        for lat in [-1.4, -0.8, 0.0, 0.3, 0.798_968, 1.2, 1.55] {
            let trig = latitude_trig(lat);
            for d in [-1e-6, -3.1e-7, -2e-9, 0.0, 5e-12, 8.8e-9, 4.4e-7, 1e-6] {
                let shifted = shifted_trig(&trig, d).unwrap();
                let exact = latitude_trig(lat + d);
                // lat + d itself is rounded: half an ulp of lat.
                let tol = 4.5e-16;
                assert!((shifted.sin - exact.sin).abs() <= tol, "{lat} {d}");
                assert!((shifted.cos - exact.cos).abs() <= tol, "{lat} {d}");
            }
        }
        assert!(shifted_trig(&latitude_trig(0.5), 1.1e-6).is_none());
        assert!(shifted_trig(&latitude_trig(0.5), f64::NAN).is_none());
    }

    #[test]
    fn renormalization_is_the_division_by_the_norm_to_rounding() {
        let a = quat_from_euler(&Euler::new(0.3, -1.2, 2.9));
        let b = quat_from_rotation_vector(&Vector3::new(1e-5, -3e-6, 2e-5));
        let q = a * b * a * b;
        let fast = renormalized(q);
        let exact = q.into_inner().normalize();
        assert!((fast.into_inner() - exact).coords.amax() <= 2.3e-16);
        assert!((fast.norm() - 1.0).abs() <= 2.3e-16);
        // Far from unit: the square root.
        let far = UnitQuaternion::new_unchecked(q.into_inner() * 1.5);
        assert!((renormalized(far).into_inner() - exact).coords.amax() <= 2.3e-16);
    }

    #[test]
    fn correction_after_a_step_uses_the_step_latitude_terms() {
        // With and without the latitude terms kept from the step, the
        // corrected position is the same to rounding.
        let start = NavState::at_rest(
            quat_from_euler(&Euler::new(0.1, -0.2, 2.0)),
            Position::paper_site(),
        );
        let mut moving = start;
        moving.velocity = Vector3::new(3.0, -2.0, 0.5);
        let mut nav = Strapdown::new(moving, SAMPLE_INTERVAL_S);
        nav.step(&ideal_static_sample(&start));
        let mut fresh = Strapdown::new(*nav.state(), SAMPLE_INTERVAL_S);
        let dp = Vector3::new(0.02, -0.03, 0.01);
        nav.apply_correction(&Vector3::zeros(), &Vector3::zeros(), &dp);
        fresh.apply_correction(&Vector3::zeros(), &Vector3::zeros(), &dp);
        let (a, b) = (nav.state().position, fresh.state().position);
        assert!((a.lat - b.lat).abs() <= 2.3e-16 && (a.lon - b.lon).abs() <= 4.5e-16);
        assert_eq!(a.height, b.height);
    }

    #[test]
    fn free_fall_over_one_second() {
        // No specific force: the probe falls with gravity (Coriolis deflects
        // it eastward by micrometres only over one second).
        let pos = Position::paper_site();
        let start = NavState::at_rest(quat_from_euler(&Euler::default()), pos);
        let mut nav = Strapdown::new(start, SAMPLE_INTERVAL_S);
        let sample = ImuSample {
            rate: dcm_from_quat(&start.attitude).transpose() * earth_rate_n(pos.lat),
            specific_force: Vector3::zeros(),
        };
        for _ in 0..20 {
            nav.step(&sample);
        }
        let g = gravity_n(&pos).z;
        let v = nav.state().velocity;
        assert!((v.z - g).abs() < 1e-6 * g, "vz {}", v.z);
        // Each step moves the tool by its starting velocity (the filter's
        // first-order transition linearises exactly that): the drop lags
        // g t^2 / 2 by the velocity change times dt / 2, 20 steps of
        // g dt^2 k for k = 0..19.
        let drop = pos.height - nav.state().position.height;
        let lagged = g * SAMPLE_INTERVAL_S * SAMPLE_INTERVAL_S * 190.0;
        assert!((drop - lagged).abs() < 1e-3, "drop {drop}");
        assert!((0.5 * g - drop - g * SAMPLE_INTERVAL_S / 2.0).abs() < 1e-3);
    }

    #[test]
    fn constant_northward_velocity_moves_the_latitude() {
        // Moving north at 1 m/s with the matching specific force: after
        // 100 s the probe is 100 m north.
        let pos = Position::paper_site();
        let attitude = quat_from_euler(&Euler::default());
        let mut state = NavState::at_rest(attitude, pos);
        state.velocity = Vector3::new(1.0, 0.0, 0.0);
        let mut nav = Strapdown::new(state, SAMPLE_INTERVAL_S);
        for _ in 0..2000 {
            let s = *nav.state();
            let omega_ie = earth_rate_n(s.position.lat);
            let omega_en = transport_rate_n(&s.position, &s.velocity);
            let c_nb = dcm_from_quat(&s.attitude).transpose();
            // The frame turns with the transport rate; the body follows it.
            let f_n = (omega_ie * 2.0 + omega_en).cross(&s.velocity) - gravity_n(&s.position);
            nav.step(&ImuSample {
                rate: c_nb * (omega_ie + omega_en),
                specific_force: c_nb * f_n,
            });
        }
        let moved = nav.state().position.ned_from(&pos);
        assert!((moved.x - 100.0).abs() < 0.01, "{moved:?}");
        assert!(moved.y.abs() < 0.01 && moved.z.abs() < 0.01, "{moved:?}");
    }

    #[test]
    fn correction_removes_the_stated_errors() {
        let truth = NavState::at_rest(
            quat_from_euler(&Euler::new(0.1, 0.2, 0.3)),
            Position::paper_site(),
        );
        let phi = Vector3::new(1e-3, -2e-3, 3e-3);
        let dv = Vector3::new(0.1, -0.2, 0.05);
        let dp = Vector3::new(1.0, 2.0, -3.0);
        // Build the erroneous solution with the same definitions.
        let computed = NavState {
            attitude: quat_from_rotation_vector(&-phi) * truth.attitude,
            velocity: truth.velocity + dv,
            position: truth.position.displaced(&dp),
        };
        let mut nav = Strapdown::new(computed, SAMPLE_INTERVAL_S);
        nav.apply_correction(&phi, &dv, &dp);
        let s = nav.state();
        assert!(s.attitude.angle_to(&truth.attitude) < 1e-12);
        assert!((s.velocity - truth.velocity).norm() < 1e-12);
        assert!(s.position.ned_from(&truth.position).norm() < 1e-6);
    }
}
