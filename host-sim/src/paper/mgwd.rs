//! The MGWD paper's experiment (section 4): 60 s of static data at the
//! paper's site, coarse alignment on the first 5 s, then fine alignment with
//! the 33-state AR-augmented filter (39 states with sensor biases for the
//! physically scaled settings), ZUPT and zero-position updates.
//! The CLI (`host-sim paper mgwd`) prints and plots what this computes.

use crate::alignment::coarse;
use crate::formats::samples_csv::Record;
use crate::sim::{DeterministicErrors, SensorModel, SensorSimulator, Trajectory};
use anyhow::Result;
use mwd_core::alignment::AlignmentConfig;
use mwd_core::conventions::{dcm_from_quat, euler_from_quat, quat_from_euler, wrap_pi, Euler, DEG};
use mwd_core::earth::Position;
use mwd_core::error_model::{
    AugmentedModel, Coupling, ProcessNoise, NAV_STATES, STATES, STATES_WITH_BIASES, VEL,
};
use mwd_core::fine_alignment::{FineAlignment, FineAlignmentConfig};
use mwd_core::mechanization::NavState;
use mwd_core::mechanization::{ProbeInput, ToolAxisSource};
use mwd_core::sensor_noise::ImuNoise;
use mwd_core::timing::SAMPLE_INTERVAL_S;
use nalgebra::Vector3;

/// Samples of the paper's test and of its coarse-alignment window.
pub const SAMPLES: usize = 1200;
pub const COARSE_SAMPLES: usize = 100;

/// The paper's published figures (section 4), degrees and m/s.
pub struct Published {
    pub coarse_deg: [f64; 3],
    pub roll_sigma_deg: f64,
    pub pitch_sigma_deg: f64,
    pub velocity_sigma: [f64; 3],
    pub trace_after_2s: f64,
}

pub const PUBLISHED: Published = Published {
    coarse_deg: [-0.8061, 0.5371, -150.9636],
    roll_sigma_deg: 0.0348,
    pitch_sigma_deg: 0.0104,
    velocity_sigma: [0.0277, 0.0292, 0.0270],
    trace_after_2s: 0.2,
};

/// Which filter settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Settings {
    /// P0 = 0.01 I, Q = I, R = 0.1 I, AR blocks decoupled (eq. 43 as printed).
    PaperAsPublished,
    /// The paper's P0, Q, R with the AR noise coupled into the navigation errors.
    PaperCoupled,
    /// P0 from the coarse alignment, AR blocks stationary, process noise from
    /// the datasheet's random walks, tight R (the tool really is at rest),
    /// and the six sensor-bias states (39 states) with the tilt-bias
    /// correlation of levelling.
    Physical,
    /// The same without bias states (33 states): shows what they change.
    PhysicalWithoutBiases,
}

impl Settings {
    pub const ALL: [Settings; 3] = [
        Settings::PaperAsPublished,
        Settings::PaperCoupled,
        Settings::Physical,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            Settings::PaperAsPublished => "paper, as published",
            Settings::PaperCoupled => "paper P0/Q/R, coupled",
            Settings::Physical => "physically scaled",
            Settings::PhysicalWithoutBiases => "physical, 33 states",
        }
    }

    /// The setting's tag in the plots' file names.
    pub fn file_tag(&self) -> &'static str {
        match self {
            Settings::PaperAsPublished => "published",
            Settings::PaperCoupled => "paper",
            Settings::Physical => "physical",
            Settings::PhysicalWithoutBiases => "physical-33",
        }
    }

    /// Filter states: 39 with the sensor biases, else the paper's 33.
    pub fn states(&self) -> usize {
        match self {
            Settings::Physical => STATES_WITH_BIASES,
            _ => STATES,
        }
    }

    /// The filter settings on `model`'s AR and bias models (the paper's:
    /// [`AugmentedModel::paper`]; `--ar-models` loads fitted ones).
    fn config<const N: usize>(
        &self,
        model: &AugmentedModel,
        coarse_sigma: &[f64; 3],
    ) -> FineAlignmentConfig<N> {
        let mut model = *model;
        match self {
            Settings::PaperAsPublished => {
                model.coupling = Coupling::BlockDiagonalAsPublished;
                FineAlignmentConfig::paper(model)
            }
            Settings::PaperCoupled => FineAlignmentConfig::paper(model),
            Settings::Physical | Settings::PhysicalWithoutBiases => FineAlignmentConfig::physical(
                model,
                &ImuNoise::scc1300(),
                coarse_sigma,
                Position::paper_site().lat,
            ),
        }
    }
}

/// The truth of the simulated test: the paper's coarse result as attitude.
pub fn truth() -> Euler {
    let [r, p, h] = PUBLISHED.coarse_deg;
    Euler::new(r * DEG, p * DEG, h * DEG)
}

/// 60 s of calibrated static samples. `full_model`: the SCC1300 model with
/// residual biases, bias instability, white noise and quantisation;
/// otherwise the paper's AR(4) noise alone (what the filter assumes).
pub fn simulate(seed: u64, full_model: bool) -> Vec<Record> {
    let mut model = SensorModel::scc1300(seed);
    if !full_model {
        model.deterministic = DeterministicErrors::none();
        model.quantize = false;
        for axis in model
            .noise
            .accel
            .iter_mut()
            .chain(model.noise.gyro.iter_mut())
        {
            axis.white_density = 0.0;
            axis.bias_instability = 0.0;
            axis.residual_bias = 0.0;
        }
    }
    let cal = model.deterministic.calibration();
    SensorSimulator::new(Trajectory::paper_static(truth()), model, SAMPLE_INTERVAL_S)
        .take(SAMPLES)
        .map(|s| coarse::calibrated(&Record::from(&s), &cal))
        .collect()
}

/// Coarse alignment on the first 5 s: attitude and 1-sigma (rad).
pub fn coarse_align(records: &[Record]) -> Result<(Euler, [f64; 3])> {
    // South-westerly prior from the parent well resolves north/south.
    let config = AlignmentConfig::probe(Position::paper_site().lat)
        .with_heading_prior(Some(truth().heading + 30.0 * DEG));
    let window = &records[..COARSE_SAMPLES.min(records.len())];
    let whole = 0..window.len();
    let report = coarse::align(window, std::slice::from_ref(&whole), &config)?;
    let lev = report.levels[0];
    let h = report.heading.heading;
    Ok((
        Euler::new(lev.roll.value, lev.pitch.value, h.value),
        [lev.roll.sigma, lev.pitch.sigma, h.sigma],
    ))
}

/// One fine alignment's history, one entry per sample.
#[derive(Clone, Debug, Default)]
pub struct History {
    pub time: Vec<f64>,
    /// Computed minus true roll, pitch, azimuth (deg).
    pub euler_error_deg: Vec<[f64; 3]>,
    /// Filter 1-sigma of roll, pitch, azimuth (deg).
    pub euler_sigma_deg: Vec<[f64; 3]>,
    /// Filter 1-sigma of the NED velocity errors (m/s).
    pub velocity_sigma: Vec<[f64; 3]>,
    /// trace(P) of the whole covariance (33 or 39 states).
    pub trace: Vec<f64>,
}

/// Fine alignment of `records` from a coarse attitude, in f32 (the probe's
/// precision), with `model`'s AR noise models.
pub fn fine_align(
    records: &[Record],
    coarse: &Euler,
    coarse_sigma: &[f64; 3],
    settings: Settings,
    model: &AugmentedModel,
) -> History {
    if settings.states() == STATES_WITH_BIASES {
        fine_align_with::<STATES_WITH_BIASES>(records, coarse, settings.config(model, coarse_sigma))
    } else {
        fine_align_with::<STATES>(records, coarse, settings.config(model, coarse_sigma))
    }
}

fn fine_align_with<const N: usize>(
    records: &[Record],
    coarse: &Euler,
    config: FineAlignmentConfig<N>,
) -> History {
    let position = Position::paper_site();
    let start = NavState::at_rest(quat_from_euler(coarse), position);
    let mut fa = FineAlignment::<f32, N>::new(start, position, config);
    let t = truth();
    let mut h = History::default();
    let mut input = ProbeInput::new();
    let dt = SAMPLE_INTERVAL_S;
    for r in records {
        // The tool is at rest: its rate about the tool axis is the frame's.
        let frame_rate = fa.frame_rate_in_body();
        let (imu, _) = input.imu_sample(&frame_rate, &r.sample, ToolAxisSource::AtRest, dt);
        fa.step(&imu);
        let e = euler_from_quat(&fa.state().attitude);
        let sigma = fa.euler_std() / DEG;
        let p = &fa.filter().p;
        h.time.push(r.time);
        h.euler_error_deg.push([
            wrap_pi(e.roll - t.roll) / DEG,
            wrap_pi(e.pitch - t.pitch) / DEG,
            wrap_pi(e.heading - t.heading) / DEG,
        ]);
        h.euler_sigma_deg.push([sigma.x, sigma.y, sigma.z]);
        h.velocity_sigma.push(std::array::from_fn(|i| {
            (p[(VEL + i, VEL + i)] as f64).max(0.0).sqrt()
        }));
        h.trace.push((0..N).map(|i| p[(i, i)] as f64).sum());
    }
    h
}

/// The static test on one seed: the coarse alignment of its first 5 s,
/// then the fine alignment under each of [`Settings::ALL`].
pub struct StaticTest {
    /// The coarse alignment's roll, pitch and azimuth.
    pub coarse: Euler,
    /// Their 1-sigma (rad).
    pub coarse_sigma: [f64; 3],
    /// The fine alignment under each setting.
    pub runs: Vec<(Settings, History)>,
}

/// The static test on `seed` with the full sensor model; `model` is the
/// filter's.
pub fn static_test(seed: u64, model: &AugmentedModel) -> Result<StaticTest> {
    let records = simulate(seed, true);
    let (coarse, coarse_sigma) = coarse_align(&records)?;
    let runs = Settings::ALL
        .iter()
        .map(|s| (*s, fine_align(&records, &coarse, &coarse_sigma, *s, model)))
        .collect();
    Ok(StaticTest {
        coarse,
        coarse_sigma,
        runs,
    })
}

/// Seeded runs: how often the final roll and pitch errors are both inside
/// the filter's 3 sigma, and the RMS of the final errors (deg).
pub struct MonteCarlo {
    pub runs: usize,
    pub inside: usize,
    pub rms_error_deg: [f64; 3],
    pub mean_sigma_deg: [f64; 3],
}

/// `full_model` as in [`simulate`]; `model` is the filter's.
pub fn monte_carlo(
    runs: usize,
    settings: Settings,
    full_model: bool,
    model: &AugmentedModel,
) -> Result<MonteCarlo> {
    let mut mc = MonteCarlo {
        runs,
        inside: 0,
        rms_error_deg: [0.0; 3],
        mean_sigma_deg: [0.0; 3],
    };
    for seed in 1..=runs as u64 {
        let records = simulate(seed, full_model);
        let (coarse, sigma) = coarse_align(&records)?;
        let h = fine_align(&records, &coarse, &sigma, settings, model);
        let (Some(e), Some(s)) = (h.euler_error_deg.last(), h.euler_sigma_deg.last()) else {
            continue;
        };
        if e[0].abs() <= 3.0 * s[0] && e[1].abs() <= 3.0 * s[1] {
            mc.inside += 1;
        }
        for i in 0..3 {
            mc.rms_error_deg[i] += e[i] * e[i] / runs as f64;
            mc.mean_sigma_deg[i] += s[i] / runs as f64;
        }
    }
    mc.rms_error_deg = mc.rms_error_deg.map(f64::sqrt);
    Ok(mc)
}

/// The settings of the consistency check, in report order.
pub const CONSISTENCY_SETTINGS: [Settings; 3] = [
    Settings::PaperCoupled,
    Settings::PhysicalWithoutBiases,
    Settings::Physical,
];

/// One line of the consistency check: seeded runs of one setting on the
/// filter's own noise model or on the full sensor model.
pub struct Consistency {
    pub settings: Settings,
    /// As in [`simulate`]: the full SCC1300 model rather than the filter's.
    pub full_model: bool,
    pub result: MonteCarlo,
}

/// [`monte_carlo`] of `runs` seeds for each of [`CONSISTENCY_SETTINGS`],
/// first on the filter's own noise model, then on the full sensor model.
pub fn consistency(runs: usize, model: &AugmentedModel) -> Result<Vec<Consistency>> {
    let mut lines = Vec::new();
    for full_model in [false, true] {
        for settings in CONSISTENCY_SETTINGS {
            lines.push(Consistency {
                settings,
                full_model,
                result: monte_carlo(runs, settings, full_model, model)?,
            });
        }
    }
    Ok(lines)
}

/// Ranks of section 2.4's matrices for the static problem (33 states,
/// discrete pair (Phi, Gamma) with Gamma = diag(sqrt q), H of eq. 48).
pub struct Ranks {
    pub coupling: Coupling,
    pub controllability: usize,
    pub observability: usize,
    /// Azimuth sigma the 60 s of measurements alone could reach (deg),
    /// 9-state model, 0.01 m/s and 0.01 m measurement noise.
    pub azimuth_sigma_from_data_deg: f64,
}

pub fn ranks(coupling: Coupling) -> Ranks {
    use crate::alignment::observability::matrices::{
        controllability_matrix, dynamic, observability_matrix, observability_matrix_discrete, rank,
        ObservabilityReport,
    };
    use mwd_core::error_model::{navigation_error_dynamics, LinearizationPoint, POS};
    use nalgebra::DMatrix;
    let position = Position::paper_site();
    let lp = LinearizationPoint {
        c_bn: dcm_from_quat(&quat_from_euler(&truth())),
        velocity_n: Vector3::zeros(),
        position,
        specific_force_n: -mwd_core::earth::gravity_n(&position),
    };
    let model = AugmentedModel {
        coupling,
        ..AugmentedModel::paper()
    };
    let phi = dynamic(&model.transition::<f64, STATES>(&lp).to_dense());
    let q = model.process_noise::<f64, STATES>(&ProcessNoise {
        nav_per_step: [model.dt * model.dt; NAV_STATES],
    });
    let gamma = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        STATES,
        q.iter().map(|v| v.sqrt()),
    ));
    let mut h = DMatrix::zeros(6, STATES);
    for i in 0..3 {
        h[(i, VEL + i)] = 1.0;
        h[(3 + i, POS + i)] = 1.0;
    }
    let f9 = dynamic(&navigation_error_dynamics::<f64>(&lp));
    let phi9 = DMatrix::identity(NAV_STATES, NAV_STATES) + &f9 * model.dt;
    let h9 = h.columns(0, NAV_STATES).into_owned() / 0.01;
    let scale = [1.0; NAV_STATES];
    let report = ObservabilityReport::new(
        &observability_matrix_discrete(&phi9, &h9, SAMPLES),
        &scale,
        1e-12,
    );
    Ranks {
        coupling,
        controllability: rank(&controllability_matrix(&phi, &gamma)),
        observability: rank(&observability_matrix(&phi, &h)),
        azimuth_sigma_from_data_deg: report.std_from_measurements[2] / DEG,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Seed 3 of the full sensor model, coarse- then fine-aligned.
    fn seed_3_history(settings: Settings) -> History {
        let records = simulate(3, true);
        let (coarse, sigma) = coarse_align(&records).expect("coarse alignment");
        fine_align(
            &records,
            &coarse,
            &sigma,
            settings,
            &AugmentedModel::paper(),
        )
    }

    #[test]
    fn paper_settings_azimuth_sigma_grows_while_tilt_sigmas_settle() {
        let h = seed_3_history(Settings::PaperCoupled);
        let (early, late) = (h.euler_sigma_deg[100], h.euler_sigma_deg[SAMPLES - 1]);
        assert!(late[2] > 2.0 * early[2], "{early:?} -> {late:?}");
        // Tilt sigmas are pinned by the ZUPT: they stop changing.
        let before = h.euler_sigma_deg[SAMPLES - 200];
        assert!((late[0] - before[0]).abs() < 0.01 * late[0]);
    }

    #[test]
    fn physical_settings_are_consistent_in_tilt_on_the_filters_own_noise_model() {
        let mc =
            monte_carlo(10, Settings::Physical, false, &AugmentedModel::paper()).expect("runs");
        assert!(mc.inside >= 9, "{} of 10", mc.inside);
        assert!(mc.mean_sigma_deg[0] < 0.1 && mc.mean_sigma_deg[1] < 0.1);
    }

    #[test]
    fn bias_state_settings_are_consistent_in_tilt_on_the_full_sensor_model() {
        // Residual biases, bias instability, white noise, quantisation: the
        // 33-state physical filter is inside 3 sigma in ~61 % of such runs.
        let mc = monte_carlo(20, Settings::Physical, true, &AugmentedModel::paper()).expect("runs");
        assert!(mc.inside >= 19, "{} of 20", mc.inside);
    }

    #[test]
    fn bias_state_settings_keep_an_honest_azimuth_sigma() {
        // Rate biases and azimuth are one east tilt drift at rest: the
        // azimuth sigma must not collapse, the tilt sigmas settle.
        let h = seed_3_history(Settings::Physical);
        let (early, late) = (h.euler_sigma_deg[100], h.euler_sigma_deg[SAMPLES - 1]);
        assert!(late[2] > 0.5 * early[2], "{early:?} -> {late:?}");
        let before = h.euler_sigma_deg[SAMPLES - 200];
        for i in 0..2 {
            assert!(
                (late[i] - before[i]).abs() < 0.02 * late[i],
                "{before:?} {late:?}"
            );
        }
    }

    #[test]
    fn the_published_block_diagonal_model_cannot_see_its_ar_states() {
        assert_eq!(
            ranks(Coupling::BlockDiagonalAsPublished).observability,
            NAV_STATES
        );
        assert_eq!(
            ranks(Coupling::SensorErrorsDriveNavigation).observability,
            STATES
        );
    }
}
