//! The 39-state filter (33 + six sensor biases) on static data WITH
//! residual constant biases drawn from the project's error budget
//! (`sensor_noise::ImuNoise::scc1300`: 1 mg, 2.1 deg/h, plus the
//! Gauss-Markov bias instability) on top of the paper's AR(4) noise.
//!
//! The coarse tilt comes from levelling the first 5 s of the same biased
//! accelerometers (`attitude::level`), so its error holds the bias, as on
//! the probe; the coarse azimuth is off by a drawn error of 2 deg sigma.
//! The 33-state filter cannot say that a 1 mg bias looks like 0.057 deg of
//! tilt at rest and is overconfident on such data (`host-sim paper mgwd`:
//! 61 of 100 inside 3 sigma).

mod common;
use common::{Channel, Normal};
use mwd_core::ar::{ACCEL_DEFAULTS, GYRO_DEFAULTS};
use mwd_core::attitude::level;
use mwd_core::conventions::DEG;
use mwd_core::conventions::{dcm_from_quat, euler_from_quat, quat_from_euler, Euler};
use mwd_core::earth::{earth_rate_n, gravity_n, normal_gravity, Position};
use mwd_core::error_model::{AugmentedModel, ProcessNoise, NAV_STATES, STATES_WITH_BIASES};
use mwd_core::fine_alignment::{
    ArInitialCovariance, FineAlignment, FineAlignmentConfig, SpecificForceInModel, TiltPrior,
};
use mwd_core::mechanization::{ImuSample, NavState};
use mwd_core::sensor_noise::ImuNoise;
use mwd_core::sensor_units::STANDARD_GRAVITY;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use nalgebra::Vector3;

const DT: f64 = SAMPLE_INTERVAL_S;
const SAMPLES: usize = 1200; // the paper's 60 s
const COARSE_SAMPLES: usize = 100; // its 5 s of coarse alignment
const AZIMUTH_SIGMA: f64 = 2.0 * DEG;

/// A static tool: accelerometers x, y, z then rates x, y, z.
struct BiasedStaticSensors {
    ideal: ImuSample,
    rng: Normal,
    channels: Vec<Channel>,
}

impl BiasedStaticSensors {
    fn new(truth: &NavState, seed: u64) -> Self {
        let c_nb = dcm_from_quat(&truth.attitude).transpose();
        let budget = ImuNoise::scc1300();
        let mut rng = Normal(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
        let accel = ACCEL_DEFAULTS.iter().zip(budget.accel.iter());
        let gyro = GYRO_DEFAULTS.iter().zip(budget.gyro.iter());
        let channels = accel
            .chain(gyro)
            .map(|(ar, axis)| Channel::new(*ar, *axis, &mut rng))
            .collect();
        Self {
            ideal: ImuSample {
                rate: c_nb * earth_rate_n(truth.position.lat),
                specific_force: c_nb * -gravity_n(&truth.position),
            },
            rng,
            channels,
        }
    }

    fn next(&mut self) -> ImuSample {
        let e: Vec<f64> = self
            .channels
            .iter_mut()
            .map(|c| c.next(&mut self.rng))
            .collect();
        ImuSample {
            specific_force: self.ideal.specific_force + Vector3::new(e[0], e[1], e[2]),
            rate: self.ideal.rate + Vector3::new(e[3], e[4], e[5]),
        }
    }
}

fn truth() -> NavState {
    NavState::at_rest(
        quat_from_euler(&Euler::new(-0.014, 0.0094, -2.635)),
        Position::paper_site(),
    )
}

/// Physically scaled 39-state settings. `levelling_sigma`: 1-sigma of the
/// coarse tilt without the bias share (the filter adds that share and its
/// correlation, `TiltPrior::LevelledWithSameAccelerometers`).
fn config(levelling_sigma: [f64; 2]) -> FineAlignmentConfig<STATES_WITH_BIASES> {
    let model = AugmentedModel::paper();
    let mut p0 = [1e-4; NAV_STATES];
    p0[0] = levelling_sigma[0].powi(2);
    p0[1] = levelling_sigma[1].powi(2);
    p0[2] = AZIMUTH_SIGMA.powi(2);
    let arw = (0.86f64.to_radians() / 60.0).powi(2);
    let vrw = (0.052f64 / 60.0).powi(2);
    FineAlignmentConfig {
        model,
        process_noise: ProcessNoise::from_densities(arw, vrw, 0.0, model.dt),
        initial_nav_variance: p0,
        initial_ar: ArInitialCovariance::Stationary,
        zero_velocity_variance: Some(1e-6),
        zero_position_variance: Some(1e-6),
        gate: None,
        ar_noise_scale: 1.0,
        tilt_prior: TiltPrior::LevelledWithSameAccelerometers,
        specific_force: SpecificForceInModel::GravityAtRest,
    }
}

/// Sigma of the 5 s mean of the budget's varying accelerometer errors
/// (AR, white, Gauss-Markov) as tilt: roll from body x, pitch from body y.
fn levelling_noise_sigma() -> [f64; 2] {
    let budget = ImuNoise::scc1300();
    let g = normal_gravity(truth().position.lat, truth().position.height);
    [0, 1].map(|axis| budget.accel[axis].mean_sigma(COARSE_SAMPLES, DT) / g)
}

/// Euler roll, pitch, heading errors (rad) of `attitude` against the truth.
fn euler_error(attitude: &nalgebra::UnitQuaternion<f64>) -> Vector3<f64> {
    let (e, t) = (
        euler_from_quat(attitude),
        euler_from_quat(&truth().attitude),
    );
    let wrap = mwd_core::conventions::wrap_pi;
    Vector3::new(
        wrap(e.roll - t.roll),
        wrap(e.pitch - t.pitch),
        wrap(e.heading - t.heading),
    )
}

struct Run {
    /// Final Euler errors (rad).
    error: Vector3<f64>,
    /// Euler 1-sigma (rad) after each sample.
    sigma: Vec<Vector3<f64>>,
}

/// Coarse-levels on the first 5 s, then fine-aligns on all 60 s in f32.
fn run(seed: u64, levelling_sigma: [f64; 2]) -> Run {
    let t = truth();
    let mut sensors = BiasedStaticSensors::new(&t, seed);
    let samples: Vec<ImuSample> = (0..SAMPLES).map(|_| sensors.next()).collect();
    let mean_force = samples[..COARSE_SAMPLES]
        .iter()
        .fold(Vector3::zeros(), |acc, s| acc + s.specific_force)
        / COARSE_SAMPLES as f64;
    let levelled = level(&mean_force);
    let heading_error = AZIMUTH_SIGMA * Normal(7919 + seed).sample();
    let heading = euler_from_quat(&t.attitude).heading + heading_error;
    let coarse = NavState {
        attitude: quat_from_euler(&Euler::new(levelled.roll, levelled.pitch, heading)),
        ..t
    };
    let mut fa =
        FineAlignment::<f32, STATES_WITH_BIASES>::new(coarse, t.position, config(levelling_sigma));
    let mut sigma = vec![fa.euler_std()];
    for s in &samples {
        let report = fa.step(s);
        assert!(report.zero_velocity.all_accepted() && report.zero_position.all_accepted());
        sigma.push(fa.euler_std());
    }
    Run {
        error: euler_error(&fa.state().attitude),
        sigma,
    }
}

#[test]
fn tilt_errors_with_residual_biases_are_within_three_sigma_in_95_of_100_runs() {
    let runs = 100;
    let noise = levelling_noise_sigma();
    let mut inside = 0;
    for seed in 0..runs {
        let r = run(seed, noise);
        let s = r.sigma.last().expect("sigma history");
        if r.error[0].abs() <= 3.0 * s[0] && r.error[1].abs() <= 3.0 * s[1] {
            inside += 1;
        }
    }
    assert!(inside >= 95, "{inside} of {runs} runs inside 3 sigma");
}

#[test]
fn tilt_sigma_converges_and_azimuth_sigma_does_not() {
    // A poor coarse tilt (0.5 deg levelling noise claimed) so that the
    // convergence is visible: the tilt sigmas fall to the bias floor
    // sigma_b / g (~0.057 deg) and stay there; the azimuth sigma barely
    // moves, because east gyro bias and azimuth x earth rate are one and
    // the same east tilt drift (derivation section 3b).
    let r = run(3, [0.5f64.to_radians(); 2]);
    let (start, end) = (r.sigma[0], r.sigma[SAMPLES]);
    let ten_s_before = r.sigma[SAMPLES - 200];
    let floor = 1e-3 * STANDARD_GRAVITY / normal_gravity(truth().position.lat, 0.0);
    for i in 0..2 {
        assert!(end[i] < 0.2 * start[i], "axis {i}: {start} -> {end}");
        assert!(end[i] > 0.9 * floor, "axis {i}: {end} below the bias floor");
        let change = (end[i] - ten_s_before[i]).abs() / end[i];
        assert!(change < 0.02, "axis {i} still moving: {change}");
    }
    assert!(end[2] > 0.8 * start[2], "azimuth {start} -> {end}");
}
