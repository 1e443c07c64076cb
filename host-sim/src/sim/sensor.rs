//! The probe's sensors: ideal outputs of a trajectory (earth rate and WGS-84
//! gravity included), then the SCC1300 errors: deterministic bias, scale
//! factor and misalignment (what calibration removes), residual bias, white
//! noise, Gauss-Markov bias instability and AR(4) coloured noise (what it
//! cannot), and quantisation to the part's LSB. Seeded and reproducible.
use super::trajectory::Trajectory;
use mwd_core::ar::Ar4;
use mwd_core::calibration::{GyroCalibration, ProbeCalibration, TriadCalibration};
use mwd_core::conventions::DEG;
use mwd_core::earth::{earth_rate_n, gravity_n};
use mwd_core::sensor_noise::{AxisNoise, ImuNoise};
use mwd_core::sensor_units::STANDARD_GRAVITY;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Gyro LSB (rad/s): the D04's 18 LSB per deg/s (`mwd_core::sensor_units`).
pub const GYRO_LSB: f64 = DEG / mwd_core::sensor_units::GYRO_LSB_PER_DEG_S as f64;
/// Accelerometer LSB (m/s^2): 650 LSB per g.
pub const ACCEL_LSB: f64 = STANDARD_GRAVITY / mwd_core::sensor_units::ACCEL_LSB_PER_G as f64;

/// Deterministic errors, found and removed by calibration. Body axes.
#[derive(Clone, Debug, PartialEq)]
pub struct DeterministicErrors {
    /// Accelerometer bias (m/s^2).
    pub accel_bias: Vector3<f64>,
    /// Accelerometer scale factor and misalignment K (raw = K true + bias).
    pub accel_matrix: Matrix3<f64>,
    /// Gyro bias (rad/s), body x and z used.
    pub gyro_bias: Vector3<f64>,
    /// Gyro scale-factor error (fraction), body x and z used.
    pub gyro_scale: Vector3<f64>,
}

impl DeterministicErrors {
    pub fn none() -> Self {
        Self {
            accel_bias: Vector3::zeros(),
            accel_matrix: Matrix3::identity(),
            gyro_bias: Vector3::zeros(),
            gyro_scale: Vector3::zeros(),
        }
    }

    /// The paper's Table 3 (six-position calibration). Accelerometer rows
    /// X, Y, Z map to body x, y, z; gyro rows with the project's mapping of
    /// the paper's gyro labels (see `mwd_core::ar`): body x <- "Y", body z
    /// <- "Z". Scale factor and misalignment: the paper gives none.
    pub fn paper_table3() -> Self {
        Self {
            accel_bias: Vector3::new(
                -0.007_083_371_298_406,
                -0.020_187_699_316_629,
                0.002_405_466_970_394,
            ),
            accel_matrix: Matrix3::identity(),
            gyro_bias: Vector3::new(-0.002_242_990_654_206, 0.0, -0.016_448_598_130_841) * DEG,
            gyro_scale: Vector3::zeros(),
        }
    }

    /// The errors a calibration describes (the simulated probe then has
    /// exactly what `host-sim calibrate` found): accelerometer bias and
    /// K = M^-1 of the first triad, gyro biases and scales. `None` if the
    /// accelerometer correction is not invertible or a gyro scale is zero.
    pub fn from_calibration(cal: &ProbeCalibration) -> Option<Self> {
        let triad = &cal.accel[0];
        let m = Matrix3::from_fn(|r, c| triad.correction[r][c]);
        let k = m.try_inverse()?;
        let [gx, gz] = cal.gyro;
        let valid =
            |g: &GyroCalibration| g.scale.is_finite() && g.scale != 0.0 && g.bias.is_finite();
        if !(valid(&gx) && valid(&gz) && k.iter().all(|v| v.is_finite())) {
            return None;
        }
        Some(Self {
            accel_bias: Vector3::from(triad.bias),
            accel_matrix: k,
            gyro_bias: Vector3::new(gx.bias, 0.0, gz.bias),
            gyro_scale: Vector3::new(gx.scale - 1.0, 0.0, gz.scale - 1.0),
        })
    }

    /// The calibration that removes exactly these errors (what a perfect
    /// six-position calibration would find), in the probe's format. Both
    /// accelerometer triads get the body-frame correction.
    pub fn calibration(&self) -> ProbeCalibration {
        let m = self
            .accel_matrix
            .try_inverse()
            .unwrap_or_else(Matrix3::identity);
        let triad = TriadCalibration {
            bias: [self.accel_bias.x, self.accel_bias.y, self.accel_bias.z],
            correction: [
                [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
                [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
                [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
            ],
        };
        let gyro = |axis: usize| GyroCalibration {
            bias: self.gyro_bias[axis],
            scale: 1.0 + self.gyro_scale[axis],
        };
        ProbeCalibration {
            accel: [triad, triad],
            gyro: [gyro(0), gyro(2)],
        }
    }
}

/// The whole sensor model.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorModel {
    pub deterministic: DeterministicErrors,
    pub noise: ImuNoise,
    /// Round outputs to the part's LSB, as the real part does.
    pub quantize: bool,
    pub seed: u64,
}

impl SensorModel {
    /// A perfect probe.
    pub fn ideal() -> Self {
        Self {
            deterministic: DeterministicErrors::none(),
            noise: ImuNoise::NONE,
            quantize: false,
            seed: 0,
        }
    }

    /// The SCC1300-D04 with the paper's figures.
    pub fn scc1300(seed: u64) -> Self {
        Self {
            deterministic: DeterministicErrors::paper_table3(),
            noise: ImuNoise::scc1300(),
            quantize: true,
            seed,
        }
    }
}

/// Random error state of one axis.
#[derive(Clone, Debug)]
struct AxisErrors {
    noise: AxisNoise,
    residual_bias: f64,
    gauss_markov: f64,
    ar_history: [f64; 4],
}

impl AxisErrors {
    fn new(noise: AxisNoise, rng: &mut ChaCha8Rng) -> Self {
        let mut axis = Self {
            noise,
            residual_bias: noise.residual_bias * normal(rng),
            gauss_markov: noise.bias_instability * normal(rng),
            ar_history: [0.0; 4],
        };
        // Start the coloured noise in its stationary regime: the slowest
        // of the paper's models forgets its start within a few hundred steps.
        if let Some(ar) = noise.coloured {
            for _ in 0..1000 {
                axis.coloured(&ar, rng);
            }
        }
        axis
    }

    fn coloured(&mut self, ar: &Ar4, rng: &mut ChaCha8Rng) -> f64 {
        let e = libm::sqrt(ar.noise_variance.max(0.0)) * normal(rng);
        ar.step(&mut self.ar_history, e)
    }

    /// The random error of the next sample.
    fn next(&mut self, dt: f64, rng: &mut ChaCha8Rng) -> f64 {
        let n = self.noise;
        let white = n.white_density / libm::sqrt(dt) * normal(rng);
        let coloured = match n.coloured {
            Some(ar) => self.coloured(&ar, rng),
            None => 0.0,
        };
        if n.bias_instability > 0.0 && n.correlation_time > 0.0 {
            let a = libm::exp(-dt / n.correlation_time);
            self.gauss_markov =
                a * self.gauss_markov + libm::sqrt(1.0 - a * a) * n.bias_instability * normal(rng);
        }
        self.residual_bias + self.gauss_markov + white + coloured
    }
}

pub use crate::formats::samples_csv::SimSample;

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

/// Interval means of the ideal rate and specific force.
type IdealMeans = (Vector3<f64>, Vector3<f64>);

/// The probe's sensor errors applied to ideal interval means: what any
/// trajectory generator (the scripted motions here, the drilling simulator)
/// feeds its ideal outputs through. Seeded by the model's seed.
pub struct SensorErrors {
    model: SensorModel,
    rng: ChaCha8Rng,
    accel: [AxisErrors; 3],
    gyro: [AxisErrors; 3],
}

impl SensorErrors {
    pub fn new(model: SensorModel) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(model.seed);
        let accel = model.noise.accel.map(|n| AxisErrors::new(n, &mut rng));
        let gyro = model.noise.gyro.map(|n| AxisErrors::new(n, &mut rng));
        Self {
            model,
            rng,
            accel,
            gyro,
        }
    }

    pub fn model(&self) -> &SensorModel {
        &self.model
    }

    /// The measured (gyro, accel) of one sample of length `dt` whose true
    /// interval means are `true_rate` (omega_ib^b) and `true_accel`: the
    /// deterministic errors, the random errors, then the part's LSB. Only
    /// the x and z gyros exist; the y gyro is NaN.
    pub fn measure(
        &mut self,
        dt: f64,
        true_rate: &Vector3<f64>,
        true_accel: &Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let d = &self.model.deterministic;
        let mut accel = d.accel_matrix * true_accel + d.accel_bias;
        let mut gyro = Vector3::new(f64::NAN, f64::NAN, f64::NAN);
        for axis in 0..3 {
            accel[axis] += self.accel[axis].next(dt, &mut self.rng);
        }
        for axis in [0, 2] {
            gyro[axis] = (1.0 + d.gyro_scale[axis]) * true_rate[axis]
                + d.gyro_bias[axis]
                + self.gyro[axis].next(dt, &mut self.rng);
        }
        if self.model.quantize {
            accel = accel.map(|v| libm::round(v / ACCEL_LSB) * ACCEL_LSB);
            gyro = gyro.map(|v| libm::round(v / GYRO_LSB) * GYRO_LSB);
        }
        (gyro, accel)
    }
}

/// Generates the sample stream of a trajectory.
pub struct SensorSimulator {
    trajectory: Trajectory,
    dt: f64,
    index: u64,
    errors: SensorErrors,
    /// Attitude and ideal means of the last interval at rest.
    rest_cache: Option<(Matrix3<f64>, IdealMeans)>,
}

impl SensorSimulator {
    pub fn new(trajectory: Trajectory, model: SensorModel, dt: f64) -> Self {
        Self {
            trajectory,
            dt,
            index: 0,
            errors: SensorErrors::new(model),
            rest_cache: None,
        }
    }

    /// The ideal interval-mean rate and specific force over [t0, t0 + dt],
    /// by Simpson's rule on 8 sub-intervals (exact for a static tool). An
    /// interval at rest with the same attitude as the previous one reuses
    /// its means: long static runs cost no trigonometry.
    fn ideal_means(&mut self, t0: f64) -> IdealMeans {
        let (c0, c1) = (
            self.trajectory.attitude(t0),
            self.trajectory.attitude(t0 + self.dt),
        );
        let at_rest = self.trajectory.body_rate(t0) == Vector3::zeros()
            && self.trajectory.body_rate(t0 + self.dt) == Vector3::zeros()
            && c0 == c1;
        if let Some((c, means)) = &self.rest_cache {
            if at_rest && *c == c0 {
                return *means;
            }
        }
        let means = self.integrate_means(t0);
        self.rest_cache = at_rest.then_some((c0, means));
        means
    }

    fn integrate_means(&self, t0: f64) -> IdealMeans {
        let pos = self.trajectory.position;
        let w_ie = earth_rate_n(pos.lat);
        let g = gravity_n(&pos);
        let at = |t: f64| {
            let c_nb = self.trajectory.attitude(t).transpose();
            (self.trajectory.body_rate(t) + c_nb * w_ie, c_nb * -g)
        };
        let n = 8;
        let h = self.dt / n as f64;
        let (mut w, mut f) = (Vector3::zeros(), Vector3::zeros());
        for i in 0..=n {
            let weight = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let (wi, fi) = at(t0 + i as f64 * h);
            w += wi * weight;
            f += fi * weight;
        }
        (w * (h / 3.0 / self.dt), f * (h / 3.0 / self.dt))
    }

    pub fn dt(&self) -> f64 {
        self.dt
    }
}

impl Iterator for SensorSimulator {
    type Item = SimSample;

    fn next(&mut self) -> Option<SimSample> {
        let t0 = self.index as f64 * self.dt;
        self.index += 1;
        let time = self.index as f64 * self.dt;
        let (true_rate, true_accel) = self.ideal_means(t0);
        let (gyro, accel) = self.errors.measure(self.dt, &true_rate, &true_accel);
        Some(SimSample {
            time,
            gyro,
            accel,
            true_rate,
            true_accel,
            truth: self.trajectory.euler(time),
            position_code: self.trajectory.position_code(time),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::conventions::Euler;
    use mwd_core::timing::SAMPLE_INTERVAL_S;

    #[test]
    fn calibration_round_trips_to_the_same_errors() {
        let mut errors = DeterministicErrors::paper_table3();
        errors.accel_matrix[(0, 1)] = 1e-3;
        errors.accel_matrix[(2, 2)] = 1.002;
        errors.gyro_scale = Vector3::new(3e-4, 0.0, -2e-4);
        let back =
            DeterministicErrors::from_calibration(&errors.calibration()).expect("invertible");
        assert!((back.accel_matrix - errors.accel_matrix).abs().max() < 1e-12);
        assert!((back.accel_bias - errors.accel_bias).norm() < 1e-15);
        assert!((back.gyro_bias - errors.gyro_bias).norm() < 1e-18);
        assert!((back.gyro_scale - errors.gyro_scale).norm() < 1e-15);
        let mut broken = errors.calibration();
        broken.accel[0].correction = [[0.0; 3]; 3];
        assert!(DeterministicErrors::from_calibration(&broken).is_none());
    }

    #[test]
    fn ideal_static_outputs_are_earth_rate_and_gravity() {
        let e = Euler::new(0.1, -0.3, 2.0);
        let traj = Trajectory::paper_static(e);
        let pos = traj.position;
        let mut sim = SensorSimulator::new(traj, SensorModel::ideal(), SAMPLE_INTERVAL_S);
        let s = sim.next().expect("a sample");
        let c_nb = mwd_core::conventions::dcm_from_euler(&e).transpose();
        assert!((s.accel - c_nb * -gravity_n(&pos)).norm() < 1e-12);
        assert!((s.gyro.x - (c_nb * earth_rate_n(pos.lat)).x).abs() < 1e-18);
        assert!(s.gyro.y.is_nan());
    }

    #[test]
    fn same_seed_same_stream_other_seed_other_stream() {
        let traj = Trajectory::paper_static(Euler::default());
        // The measured values (the absent y gyro is NaN, which never
        // compares equal, so it is left out).
        let stream = |seed| -> Vec<[f64; 5]> {
            SensorSimulator::new(traj.clone(), SensorModel::scc1300(seed), SAMPLE_INTERVAL_S)
                .take(50)
                .map(|s| [s.gyro.x, s.gyro.z, s.accel.x, s.accel.y, s.accel.z])
                .collect()
        };
        assert!(stream(7) == stream(7), "same seed, different stream");
        assert!(stream(7) != stream(8), "different seeds, same stream");
    }

    #[test]
    fn quantised_outputs_sit_on_the_lsb_grid() {
        let traj = Trajectory::paper_static(Euler::default());
        for s in SensorSimulator::new(traj, SensorModel::scc1300(1), SAMPLE_INTERVAL_S).take(20) {
            let counts = s.gyro.x / GYRO_LSB;
            assert!((counts - counts.round()).abs() < 1e-9);
            let counts = s.accel.z / ACCEL_LSB;
            assert!((counts - counts.round()).abs() < 1e-9);
        }
    }

    #[test]
    fn white_noise_has_the_stated_density() {
        // Gyro white noise only: per-sample sigma = ARW / sqrt(dt).
        let mut model = SensorModel::ideal();
        model.noise.gyro[0].white_density = 1e-3;
        model.seed = 3;
        let traj = Trajectory::paper_static(Euler::default());
        let truth = SensorSimulator::new(traj.clone(), SensorModel::ideal(), SAMPLE_INTERVAL_S)
            .next()
            .expect("a sample")
            .gyro
            .x;
        let n = 20_000;
        let var: f64 = SensorSimulator::new(traj, model, SAMPLE_INTERVAL_S)
            .take(n)
            .map(|s| (s.gyro.x - truth).powi(2))
            .sum::<f64>()
            / n as f64;
        let expected = 1e-6 / SAMPLE_INTERVAL_S;
        assert!((var / expected - 1.0).abs() < 0.05, "{var} vs {expected}");
    }
}
