//! Fine alignment on simulated static data with the paper's AR(4) sensor
//! noise (Tables 4-5) and no other sensor error: tilt errors converge and
//! are consistent with the filter's covariance; azimuth converges far more
//! slowly (only through earth rate: there is no gyro bias here to hide it).
//!
//! The coarse azimuth error is drawn with sigma 2 deg. With 5 deg the
//! psi-angle model's second-order terms (azimuth error times tilt error
//! times g) bias the azimuth estimate and only 14 of 50 runs stay inside
//! 3 sigma in azimuth (48 of 50 in tilt): a large-azimuth-error model is
//! future work.

mod common;
use common::Normal;
use mwd_core::ar::{Ar4, ACCEL_DEFAULTS, GYRO_DEFAULTS};
use mwd_core::attitude::quat_from_rotation_vector;
use mwd_core::conventions::{dcm_from_quat, quat_from_euler, Euler};
use mwd_core::earth::{earth_rate_n, gravity_n, Position};
use mwd_core::error_model::{AugmentedModel, ProcessNoise, NAV_STATES, POS, STATES, VEL};
use mwd_core::fine_alignment::{
    ArInitialCovariance, FineAlignment, FineAlignmentConfig, SpecificForceInModel, TiltPrior,
};
use mwd_core::kalman::FilterScalar;
use mwd_core::mechanization::{ImuSample, NavState};
use nalgebra::Vector3;

/// Static tool with AR(4) errors on all six channels.
struct StaticSensors {
    ideal: ImuSample,
    rng: Normal,
    history: [[f64; 4]; 6],
}

impl StaticSensors {
    fn new(truth: &NavState, seed: u64) -> Self {
        let c_nb = dcm_from_quat(&truth.attitude).transpose();
        let mut s = Self {
            ideal: ImuSample {
                rate: c_nb * earth_rate_n(truth.position.lat),
                specific_force: c_nb * -gravity_n(&truth.position),
            },
            rng: Normal(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1),
            history: [[0.0; 4]; 6],
        };
        // Warm up so the noise starts in its stationary state.
        for _ in 0..200 {
            s.next();
        }
        s
    }

    fn next(&mut self) -> ImuSample {
        let models: [Ar4; 6] = [
            ACCEL_DEFAULTS[0],
            ACCEL_DEFAULTS[1],
            ACCEL_DEFAULTS[2],
            GYRO_DEFAULTS[0],
            GYRO_DEFAULTS[1],
            GYRO_DEFAULTS[2],
        ];
        let mut err = [0.0; 6];
        for (i, m) in models.iter().enumerate() {
            let e = self.rng.sample() * libm::sqrt(m.noise_variance);
            err[i] = m.step(&mut self.history[i], e);
        }
        ImuSample {
            specific_force: self.ideal.specific_force + Vector3::new(err[0], err[1], err[2]),
            rate: self.ideal.rate + Vector3::new(err[3], err[4], err[5]),
        }
    }
}

fn truth() -> NavState {
    NavState::at_rest(
        quat_from_euler(&Euler::new(-0.014, 0.0094, -2.635)),
        Position::paper_site(),
    )
}

/// Physically scaled settings: P0 from a coarse alignment's errors, the AR
/// blocks at their stationary covariance, small white noise, tight R.
fn physical<const N: usize>() -> FineAlignmentConfig<N> {
    let model = AugmentedModel::paper();
    let mut p0 = [0.0; NAV_STATES];
    p0[..3].copy_from_slice(&[
        (0.5f64.to_radians()).powi(2),
        (0.5f64.to_radians()).powi(2),
        (2f64.to_radians()).powi(2),
    ]);
    p0[3..6].copy_from_slice(&[1e-4; 3]);
    p0[6..].copy_from_slice(&[1e-4; 3]);
    FineAlignmentConfig {
        model,
        process_noise: ProcessNoise::from_densities(1e-10, 1e-8, 0.0, model.dt),
        initial_nav_variance: p0,
        initial_ar: ArInitialCovariance::Stationary,
        zero_velocity_variance: Some(1e-6),
        zero_position_variance: Some(1e-6),
        gate: None,
        ar_noise_scale: 1.0,
        tilt_prior: TiltPrior::Independent,
        specific_force: SpecificForceInModel::MeasuredSample,
    }
}

/// Runs 60 s from a coarse attitude off by `phi0` (nav frame) and returns
/// (actual attitude error, its 1-sigma, start sigma) at the end.
fn run<T: FilterScalar>(
    seed: u64,
    phi0: Vector3<f64>,
    config: FineAlignmentConfig,
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let (_, phi, sigma, sigma0) = align::<T>(seed, phi0, config, 1200);
    (phi, sigma, sigma0)
}

/// [`run`] for `steps` samples, also returning the alignment itself (its
/// solution and covariance) at the end.
fn align<T: FilterScalar>(
    seed: u64,
    phi0: Vector3<f64>,
    config: FineAlignmentConfig,
    steps: usize,
) -> (FineAlignment<T>, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let t = truth();
    let coarse = NavState {
        attitude: quat_from_rotation_vector(&-phi0) * t.attitude,
        ..t
    };
    let mut sensors = StaticSensors::new(&t, seed);
    let mut fa = FineAlignment::<T>::new(coarse, t.position, config);
    let sigma0 = fa.attitude_error_covariance().diagonal().map(libm::sqrt);
    for _ in 0..steps {
        let report = fa.step(&sensors.next());
        assert!(report.zero_velocity.all_accepted() && report.zero_position.all_accepted());
        // Three scalars from each enabled update, none from a disabled one.
        let expected = |enabled: Option<f64>| if enabled.is_some() { 3 } else { 0 };
        assert_eq!(
            report.zero_velocity.accepted,
            expected(config.zero_velocity_variance)
        );
        assert_eq!(
            report.zero_position.accepted,
            expected(config.zero_position_variance)
        );
    }
    let phi = (t.attitude * fa.state().attitude.inverse()).scaled_axis();
    let sigma = fa.attitude_error_covariance().diagonal().map(libm::sqrt);
    (fa, phi, sigma, sigma0)
}

#[test]
fn tilt_converges_and_azimuth_lags_far_behind_in_60_s() {
    let phi0 = Vector3::new(
        0.3f64.to_radians(),
        -0.4f64.to_radians(),
        1.5f64.to_radians(),
    );
    let (phi, sigma, sigma0) = run::<f32>(1, phi0, physical());
    // Tilt sigmas shrink by more than 10x and the tilt errors with them.
    for i in 0..2 {
        assert!(sigma[i] < 0.1 * sigma0[i], "axis {i}: {sigma} vs {sigma0}");
        assert!(phi[i].abs() < 0.1 * phi0[i].abs(), "axis {i}: {phi}");
    }
    // Azimuth keeps a far larger share of its start sigma than the tilts.
    let tilt_share = (sigma[0] / sigma0[0]).max(sigma[1] / sigma0[1]);
    assert!(
        sigma[2] / sigma0[2] > 5.0 * tilt_share,
        "{sigma} vs {sigma0}"
    );
}

#[test]
fn tilt_errors_are_within_three_sigma_in_95_percent_of_seeded_runs() {
    let runs = 20;
    let mut inside = 0;
    for seed in 0..runs {
        // Coarse errors drawn from P0 itself, so the filter's prior is true.
        let mut rng = Normal(1000 + seed);
        let p0 = physical::<STATES>().initial_nav_variance;
        let phi0 = Vector3::new(
            rng.sample() * p0[0].sqrt(),
            rng.sample() * p0[1].sqrt(),
            rng.sample() * p0[2].sqrt(),
        );
        let (phi, sigma, _) = run::<f32>(seed, phi0, physical());
        if phi[0].abs() <= 3.0 * sigma[0] && phi[1].abs() <= 3.0 * sigma[1] {
            inside += 1;
        }
    }
    assert!(
        inside * 100 >= 95 * runs,
        "{inside} of {runs} runs inside 3 sigma"
    );
}

#[test]
fn f32_and_f64_alignments_agree() {
    let phi0 = Vector3::new(0.2f64.to_radians(), 0.1f64.to_radians(), -2f64.to_radians());
    let (a, sa, _) = run::<f32>(7, phi0, physical());
    let (b, sb, _) = run::<f64>(7, phi0, physical());
    for i in 0..3 {
        assert!(
            (sa[i] - sb[i]).abs() < 0.01 * sb[i],
            "sigma {i}: {sa} vs {sb}"
        );
    }
    assert!((a - b).norm() < 1e-5, "{a} vs {b}");
}

#[test]
fn non_finite_samples_are_skipped_without_touching_the_solution() {
    let t = truth();
    let mut sensors = StaticSensors::new(&t, 5);
    let mut fa = FineAlignment::<f32>::new(t, t.position, physical());
    for _ in 0..20 {
        fa.step(&sensors.next());
    }
    let (state, p) = (*fa.state(), fa.filter().p);
    let mut bad = sensors.next();
    bad.rate.y = f64::NAN;
    let report = fa.step(&bad);
    assert!(!report.sample_used);
    assert_eq!((*fa.state(), fa.filter().p), (state, p));
    assert_eq!((fa.rejected_samples(), fa.steps()), (1, 20));
    assert!(fa.step(&sensors.next()).sample_used);
}

/// [`physical`] with only the updates given (variances in (m/s)^2 and m^2).
fn aided_by(zero_velocity: Option<f64>, zero_position: Option<f64>) -> FineAlignmentConfig {
    FineAlignmentConfig {
        zero_velocity_variance: zero_velocity,
        zero_position_variance: zero_position,
        ..physical()
    }
}

/// Diagonal of the velocity (or position) block of the filter's covariance.
fn block_variances<T: FilterScalar>(fa: &FineAlignment<T>, first: usize) -> Vector3<f64> {
    let p = &fa.filter().p;
    Vector3::from_fn(|i, _| p[(first + i, first + i)].as_f64())
}

/// The tilts converge as in `tilt_converges_and_azimuth_lags_far_behind_in_60_s`.
fn assert_tilt_converged(
    name: &str,
    phi: &Vector3<f64>,
    phi0: &Vector3<f64>,
    sigma: &Vector3<f64>,
    sigma0: &Vector3<f64>,
) {
    for i in 0..2 {
        assert!(
            sigma[i] < 0.1 * sigma0[i],
            "{name}, axis {i}: {sigma} vs {sigma0}"
        );
        assert!(
            phi[i].abs() < 0.1 * phi0[i].abs(),
            "{name}, axis {i}: {phi}"
        );
    }
}

const PHI0_DEG: [f64; 3] = [0.3, -0.4, 1.5];

/// ZUPT alone (no zero-position update): every step applies the three
/// velocity scalars and nothing else; roll and pitch converge as with both
/// updates (the ZUPT sees g x tilt); the velocity stays held near the ZUPT
/// noise (variance < 1e-5 (m/s)^2 with R = 1e-6); the position is
/// unaided: its variance never falls below P0 (1e-4 m^2), grows from 20 s
/// to 60 s, and ends over 100 times the variance with both updates.
#[test]
fn zupt_alone_converges_the_tilt_and_leaves_position_unaided() {
    let phi0 = Vector3::from(PHI0_DEG).map(f64::to_radians);
    let config = aided_by(Some(1e-6), None);
    let (early, ..) = align::<f32>(1, phi0, config, 400);
    let (fa, phi, sigma, sigma0) = align::<f32>(1, phi0, config, 1200);
    let (both, ..) = align::<f32>(1, phi0, physical(), 1200);
    assert_tilt_converged("ZUPT only", &phi, &phi0, &sigma, &sigma0);
    let velocity = block_variances(&fa, VEL);
    assert!(velocity.max() < 1e-5, "velocity variance {velocity}");
    let (p_early, p_end, p_both) = (
        block_variances(&early, POS),
        block_variances(&fa, POS),
        block_variances(&both, POS),
    );
    let p0 = physical::<STATES>().initial_nav_variance[POS];
    for i in 0..3 {
        assert!(
            p_end[i] >= p0,
            "axis {i}: position variance {p_end} below P0"
        );
        assert!(
            p_end[i] > p_early[i],
            "axis {i}: {p_early} -> {p_end} not growing"
        );
        assert!(
            p_end[i] > 100.0 * p_both[i],
            "axis {i}: {p_end} vs {p_both} with both"
        );
    }
}

/// Zero-position update alone (no ZUPT): every step applies the three
/// position scalars and nothing else; roll and pitch converge; and the
/// position measurement still bounds the velocity: its variance stays
/// below P0 (1e-4 (m/s)^2) and does not grow from 20 s to 60 s (10 %
/// slack), and the velocity itself stays below 1 cm/s, where the same run
/// with neither update drifts to metres per second (variance > 1).
#[test]
fn zero_position_alone_converges_the_tilt_and_bounds_velocity() {
    let phi0 = Vector3::from(PHI0_DEG).map(f64::to_radians);
    let config = aided_by(None, Some(1e-6));
    let (early, ..) = align::<f32>(1, phi0, config, 400);
    let (fa, phi, sigma, sigma0) = align::<f32>(1, phi0, config, 1200);
    let (unaided, ..) = align::<f32>(1, phi0, aided_by(None, None), 1200);
    assert_tilt_converged("zero position only", &phi, &phi0, &sigma, &sigma0);
    let (v_early, v_end) = (block_variances(&early, VEL), block_variances(&fa, VEL));
    let p0 = physical::<STATES>().initial_nav_variance[VEL];
    for i in 0..3 {
        assert!(v_end[i] < p0, "axis {i}: velocity variance {v_end}");
        assert!(
            v_end[i] <= 1.1 * v_early[i],
            "axis {i}: {v_early} -> {v_end} growing"
        );
    }
    let speed = fa.state().velocity.norm();
    assert!(speed < 0.01, "velocity {} m/s", speed);
    let drift = block_variances(&unaided, VEL);
    assert!(
        drift.x > 1.0 && drift.y > 1.0,
        "unaided velocity variance {drift}"
    );
    let position = block_variances(&fa, POS);
    assert!(position.max() < 1e-6, "position variance {position}");
}

/// `restart` (the probe's in-place start after its coarse alignment) is
/// `new`: a filter that has run, restarted, then fed the same samples as a
/// fresh one, ends bit for bit where the fresh one does, in the 33- and the
/// 39-state form with the settings the probe uses.
#[test]
fn restart_in_place_is_the_same_filter_as_a_new_one() {
    use mwd_core::error_model::STATES_WITH_BIASES;
    use mwd_core::sensor_noise::ImuNoise;
    fn check<const N: usize>(config: FineAlignmentConfig<N>) {
        let start = truth();
        let mut used = FineAlignment::<f32, N>::new(start, start.position, physical());
        let mut sensors = StaticSensors::new(&start, 7);
        for _ in 0..40 {
            used.step(&sensors.next());
        }
        used.restart(start, start.position, config);
        let mut fresh = FineAlignment::<f32, N>::new(start, start.position, config);
        for _ in 0..40 {
            let sample = sensors.next();
            used.step(&sample);
            fresh.step(&sample);
        }
        assert_eq!(used.filter(), fresh.filter());
        assert_eq!(used.state(), fresh.state());
        assert_eq!(used.steps(), fresh.steps());
    }
    let sigma = [1e-3, 1e-3, 0.5];
    let lat = truth().position.lat;
    let noise = ImuNoise::scc1300();
    check::<STATES>(FineAlignmentConfig::physical(
        AugmentedModel::paper(),
        &noise,
        &sigma,
        lat,
    ));
    check::<STATES_WITH_BIASES>(FineAlignmentConfig::physical(
        AugmentedModel::paper(),
        &noise,
        &sigma,
        lat,
    ));
}
