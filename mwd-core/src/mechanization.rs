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
use crate::conventions::skew;
use crate::earth::{earth_rate_n, gravity_n, radii, transport_rate_n, Position};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

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
}

impl Strapdown {
    /// `dt` is the sample interval (s), 0.05 on the probe.
    pub fn new(state: NavState, dt: f64) -> Self {
        Self {
            state,
            dt,
            previous: None,
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
    }

    /// Advances the solution by one sample interval.
    pub fn step(&mut self, sample: &ImuSample) {
        let dt = self.dt;
        let s = &mut self.state;
        let dtheta = sample.rate * dt;
        let dv = sample.specific_force * dt;
        // With no history (first sample) the increments are taken as
        // constant over the last two intervals: the corrections vanish.
        let (prev_dtheta, prev_dv) = self.previous.unwrap_or((dtheta, dv));
        self.previous = Some((dtheta, dv));

        let omega_ie = earth_rate_n(s.position.lat);
        let omega_en = transport_rate_n(&s.position, &s.velocity);
        let zeta = (omega_ie + omega_en) * dt; // eq. 5, rates held over the interval
        let c_bn = s.attitude.to_rotation_matrix().into_inner();

        // Attitude, eq. 3-7.
        let body_rotation =
            quat_from_rotation_vector(&coning_rotation_vector(&prev_dtheta, &dtheta));
        let nav_rotation = quat_from_rotation_vector(&-zeta);
        let mut attitude = nav_rotation * s.attitude * body_rotation;
        attitude.renormalize();

        // Velocity: the specific-force increment with the rotation and
        // two-sample sculling corrections, resolved at the start of the
        // interval and rotated by half the frame's turn.
        let dv_body =
            dv + dtheta.cross(&dv) * 0.5 + (prev_dtheta.cross(&dv) + prev_dv.cross(&dtheta)) / 12.0;
        let dv_nav = (Matrix3::identity() - skew(&zeta) * 0.5) * c_bn * dv_body;
        let coriolis = (omega_ie * 2.0 + omega_en).cross(&s.velocity);
        let velocity = s.velocity + dv_nav + (gravity_n(&s.position) - coriolis) * dt;

        // Position by the trapezoidal rule in f64.
        let mean_v = (s.velocity + velocity) * 0.5;
        let r = radii(s.position.lat);
        let lat = s.position.lat + mean_v.x / (r.meridian + s.position.height) * dt;
        let cos_lat = libm::cos(0.5 * (lat + s.position.lat));
        let lon = s.position.lon + mean_v.y / ((r.transverse + s.position.height) * cos_lat) * dt;
        let height = s.position.height - mean_v.z * dt;

        *s = NavState {
            attitude,
            velocity,
            position: Position::new(lat, lon, height),
        };
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
        s.attitude = quat_from_rotation_vector(attitude_error_n) * s.attitude;
        s.attitude.renormalize();
        s.velocity -= velocity_error_n;
        s.position = s.position.displaced(&-position_error_ned_m);
    }
}

/// Builds the mechanization's input from the probe's sensors: the x and z
/// gyros, the accelerometers, and the tool-axis rate derived from
/// accelerometer roll (eq. 1-2). Where that rate is unavailable (first
/// sample, tool near vertical) the tool is taken as not turning about its
/// axis relative to the navigation frame, and the caller is told.
#[derive(Clone, Copy, Debug, Default)]
pub struct ProbeInput {
    tool_axis: ToolAxisRateEstimator,
}

impl ProbeInput {
    pub fn new() -> Self {
        Self::default()
    }

    /// The sample for the next mechanization step, from calibrated sensor
    /// readings, given the current solution (for the navigation frame's
    /// rate in body axes).
    pub fn sample(
        &mut self,
        state: &NavState,
        gyro_x: f64,
        gyro_z: f64,
        specific_force: &Vector3<f64>,
        dt: f64,
    ) -> (ImuSample, ToolAxisRate) {
        let omega_in_n =
            earth_rate_n(state.position.lat) + transport_rate_n(&state.position, &state.velocity);
        let omega_in_b = state.attitude.inverse_transform_vector(&omega_in_n);
        let derived = self
            .tool_axis
            .update(specific_force, gyro_x, gyro_z, &omega_in_b, dt);
        let rate_y = match derived {
            ToolAxisRate::Valid(rate) => rate,
            ToolAxisRate::Unavailable => omega_in_b.y,
        };
        let sample = ImuSample {
            rate: Vector3::new(gyro_x, rate_y, gyro_z),
            specific_force: *specific_force,
        };
        (sample, derived)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{dcm_from_quat, quat_from_euler, Euler};
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
            let mut nav = Strapdown::new(start, 0.05);
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
    fn free_fall_over_one_second() {
        // No specific force: the probe falls with gravity (Coriolis deflects
        // it eastward by micrometres only over one second).
        let pos = Position::paper_site();
        let start = NavState::at_rest(quat_from_euler(&Euler::default()), pos);
        let mut nav = Strapdown::new(start, 0.05);
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
        let drop = pos.height - nav.state().position.height;
        assert!((drop - 0.5 * g).abs() < 1e-3, "drop {drop}");
    }

    #[test]
    fn constant_northward_velocity_moves_the_latitude() {
        // Moving north at 1 m/s with the matching specific force: after
        // 100 s the probe is 100 m north.
        let pos = Position::paper_site();
        let attitude = quat_from_euler(&Euler::default());
        let mut state = NavState::at_rest(attitude, pos);
        state.velocity = Vector3::new(1.0, 0.0, 0.0);
        let mut nav = Strapdown::new(state, 0.05);
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
        let mut nav = Strapdown::new(computed, 0.05);
        nav.apply_correction(&phi, &dv, &dp);
        let s = nav.state();
        assert!(s.attitude.angle_to(&truth.attitude) < 1e-12);
        assert!((s.velocity - truth.velocity).norm() < 1e-12);
        assert!(s.position.ned_from(&truth.position).norm() < 1e-6);
    }
}
