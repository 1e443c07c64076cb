//! The 20 Hz sample stream of a drilling run ([`DrillingSimulator`]):
//! the ideal sensor outputs over each 50 ms interval from the truth at its
//! start, middle and end (Simpson's rule), the vibration and shocks as the
//! samples see them while the bit is on bottom, then the SCC1300's error
//! model ([`SensorErrors`]) and its range flags.
use super::schedule::{Drilling, Truth};
use crate::sim::sensor::{SensorErrors, SensorModel, SimSample};
use mwd_core::conventions::DEG;
use mwd_core::earth::LocalEarth;
use mwd_core::sensor_units::STANDARD_GRAVITY;
use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

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
        let v = drilling.plan().drilling.vibration;
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
        while self.next_shock < d.shocks().len() && d.shocks()[self.next_shock] < t1 {
            let ts = d.shocks()[self.next_shock];
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
}
