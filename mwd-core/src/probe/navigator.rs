//! The probe's navigation, run by its main loop (lower priority than
//! acquisition):
//! raw samples in, navigation-solution frames out. The probe must first be
//! still:
//! 1. coarse alignment: the first 5 s of samples are averaged, levelled and
//!    gyrocompassed (`crate::alignment`);
//! 2. fine alignment: the 39-state filter (33 AR-augmented states of the
//!    paper plus six sensor biases) with zero-velocity and zero-position
//!    updates, closed loop, until 60 s (the paper's test length), with the
//!    settings scaled to the SCC1300's error budget
//!    (`FineAlignmentConfig::physical`, the same the host's `paper mgwd`
//!    runs);
//! 3. navigation: the same filter without the zero updates, so the
//!    mechanization runs on (bias estimates still compensated through the
//!    filter's dynamics) and the reported uncertainties grow honestly;
//! 4. station surveys, within navigation: whenever the still detector
//!    (`super::still`, thresholds from the noise budget) finds the probe
//!    at rest (the string in the slips at a connection), each cycle gets a
//!    zero-velocity update (the filter re-levels through it: the velocity
//!    error is driven by the tilt error times g, derivation section 3),
//!    every block of [`SURVEY_SETTLE_EPOCHS`] still cycles gets a rate
//!    gyrocompass (the x and z gyros' block means against the earth rate
//!    at the filter's attitude: heading, tilt and both rate biases,
//!    `aid_sources::EarthRate`, derivation section 4e), and when motion
//!    resumes (or after [`MAX_STATION_SAMPLES`]) the
//!    navigator hands out a station survey ([`Navigator::take_station`]):
//!    inclination, azimuth and toolface of the last still cycle with their
//!    covariance (`super::station`). No zero-position update: the probe's
//!    position while drilling is not known. The station's cycle is in
//!    `navigator_station.rs`.
//!
//! What the frames say besides the solution (docs/protocol.md, Kind 2;
//! docs/filter-derivation.md section 5b): during the coarse alignment the
//! attitude and velocity are NaN placeholders; after it the covariance
//! is health-checked every cycle (an invalid one is latched, its sigmas
//! sent as NaN), a tilt sigma beyond [`TILT_SIGMA_LIMIT_RAD`] marks the
//! solution invalid, a sample with no valid part is propagated on the held
//! sample (coasting), and with one part out the other carries on alone
//! (single part; azimuth not determined).
//!
//! Every sample first goes through the probe's calibration (the host's
//! six-position result, [`crate::calibration`]). The host replays the same
//! raw frames through this same code and must get the probe's solutions
//! bit for bit.

#[path = "commands.rs"]
pub mod commands;

#[path = "navigator_station.rs"]
mod station_cycle;

use super::raw::{reading, Reading};
use super::station::angles_and_jacobian;
use super::station_link::StationLink;
use super::still::{Hysteresis, StillDetector};
use super::tie_in::{TieIn, TieInTilt};
use crate::aid_sources::{
    AxialSpeed, DrillingToolface, ForceBlock, NonHolonomic, AXIAL_SPEED_VARIANCE,
    DRILLING_VARIANCE, TOOLFACE_BLOCK_SAMPLES,
};
use crate::alignment::{
    gyrocompass, level_segment, AlignmentConfig, HeadingEstimate, SegmentSums, StaticSegment,
};
use crate::attitude::ToolAxisRate;
use crate::calibration::ProbeCalibration;
use crate::conventions::{
    dcm_from_quat, euler_from_quat, quat_from_euler, DrillingAngles, Euler, DEG,
};
use crate::earth::{normal_gravity, Position};
use crate::error_model::{AugmentedModel, POS, STATES_WITH_BIASES, VEL};
use crate::fine_alignment::{
    AccelBiasSnapshot, FineAlignment, FineAlignmentConfig, StepNoise, TiltPrior,
};
use crate::kalman::{FilterScalar, Stacked, UpdateReport};
use crate::mechanization::{ImuSample, NavState, ProbeInput, ToolAxisSource};
use crate::probe_sample::{ProbeSample, GYRO_AXES};
use crate::protocol::frame::nav_flags;
use crate::protocol::frame::nav_mode;
use crate::protocol::uplink::StillSettings;
use crate::protocol::{NavSolution, RawSample, StationSurvey};
use crate::sensor_noise::{ImuNoise, SCC1300_NOISE};
use crate::timing::{ALIGNMENT_SAMPLES, FINE_ALIGNMENT_SAMPLES, SAMPLE_INTERVAL_S};
use commands::Refusal;
use nalgebra::UnitQuaternion;
use nalgebra::{Matrix3, Vector3};

/// The navigator's filter, 39 states, in scalar `T`: f32 on the probe
/// (the M4F's FPU is single precision; the host's replay takes f32 too, to
/// reproduce the probe bit for bit), f64 in the host's Monte Carlo
/// studies, where it is faster on x86 and gives the same figures.
type Filter<T> = FineAlignment<T, STATES_WITH_BIASES>;

/// The largest roll or pitch 1-sigma (rad) for which the solution is
/// valid: the error model's limit (`crate::error_model`), re-exported
/// here where the frames and stations apply it.
pub use crate::error_model::TILT_SIGMA_LIMIT_RAD;

/// The covariance health check's bound on every variance, in the states'
/// own units squared (rad^2, (m/s)^2, m^2, and the sensor-error states'):
/// 1e16 is a position sigma of 1e8 m (100,000 km), far past any meaning.
/// The f32 covariance also holds variances down to ~1e-11 (the gyro-bias
/// states); with a spread of much more than 1e21 its Phi P Phi^T would
/// lose the small entries to the rounding of the large ones (f32: 24-bit
/// mantissa; docs/filter-derivation.md section 5b), so
/// the check stops it before that rather than report what the roundings
/// made. An f64 filter is held to the same bound, so it stops where the
/// probe would.
pub const VARIANCE_LIMIT: f32 = 1e16;

/// The rate (rad/s) a sample the probe did not measure may be off by: a
/// gap's held rate, or the missing gyro's stand-in in single-part mode.
/// 1 deg/s: the rate changes of a still or slowly turning tool over the
/// ~1-2 s a driver recovery takes; its variance goes into the attitude
/// process noise (docs/filter-derivation.md, "Sensor gaps").
pub const UNMEASURED_RATE_SIGMA: f64 = 1.0 * DEG;

/// The specific force (m/s^2) a held sample may be off by: 0.1 m/s^2,
/// about 10 mg, ten times the accelerometers' per-sample noise.
pub const UNMEASURED_FORCE_SIGMA: f64 = 0.1;

/// Zero-velocity update noise variance during a station, (m/s)^2: 1 cm/s,
/// ten times the fine alignment's 1 mm/s, for a string held in the slips
/// that may still sway and creep a little (the still detector cannot see a
/// steady creep: `super::still`).
pub const STATION_ZUPT_VARIANCE: f64 = 1e-4;

/// A station's zero-velocity update variance from the uplink's 1-sigma
/// (f32, m/s). The default's f32 stands for [`STATION_ZUPT_VARIANCE`]
/// itself (`still::widened_setting`: its square in f64 would not be the
/// constant to the bit).
fn station_zupt_variance(sigma: f32) -> f64 {
    // `config::default_still_settings`'s sigma (probe does not import
    // config: config builds on probe's constants).
    let default = libm::sqrt(STATION_ZUPT_VARIANCE) as f32;
    if sigma == default {
        STATION_ZUPT_VARIANCE
    } else {
        square(f64::from(sigma))
    }
}

/// The longest station (samples): 5 minutes, longer than a connection
/// usually takes. A station still going on then is sent (flag
/// `MAX_DURATION`) so the surface need not wait for motion, and the
/// zero-velocity updates stop until the probe has moved: the filter's
/// position sigma is not consistent under hours of them (the 24 h still
/// run, `tests/tests/navigator_long_run.rs`, saw the down position drift
/// ~0.33 m/h, linearly, while its sigma grew as a random walk: a residual
/// velocity bias the model does not hold), so they are kept to station
/// lengths, where the drift (~3 cm in 5 min) stays within the sigma.
pub const MAX_STATION_SAMPLES: u32 = 6000;

/// The largest azimuth 1-sigma (rad) a station or frame reports as
/// determined: 10 deg, the first-order limit measured for the probe's tool
/// model (docs/probe-tool-model.md): beyond it the small-angle azimuth
/// sigma no longer covers the error, so the azimuth is flagged
/// undetermined and its sigma sent as infinite; in navigation it stays so
/// until the next tie-in (`Navigator::note_heading_loss`).
pub const AZIMUTH_SIGMA_LIMIT_RAD: f64 = 10.0 * DEG;

/// The lateral force jitter (m/s^2, `StillStatistics::lateral_jitter`)
/// above which the probe is taken as drilling (on bottom, vibrating):
/// g sin(1 deg). Above it a single sample's accelerometer roll is off by
/// more than 1 deg, and the roll-derived tool-axis rate (paper eq. 1-2)
/// would put that noise into the attitude every sample (and rectify it into
/// a vertical force: the force is rolled onto the vertical); the roll is
/// then held (`ToolAxisSource::AtRest`) and its possible change is process
/// noise ([`DRILLING_TOOLFACE_VARIANCE_PER_S`]). The SCC1300's own noise
/// is ~0.06 m/s^2 per sample; a 10 deg/s toolface turn adds 0.085 m/s^2
/// per sample to the differences; the moderate simulated vibration is
/// ~7 m/s^2 (docs/filter-derivation.md section 4d).
pub const DRILLING_JITTER_LIMIT_M_S2: f64 = 9.80665 * 0.017_452_406;

/// Angular vibration reaching a gyro sample while drilling (rad/s, 1-sigma
/// per sample, white): the drilling simulator's moderate level, 1 deg/s RMS
/// over 5-500 Hz through the part's assumed 50 Hz first-order low-pass,
/// which passes 0.1385 of the power (docs/drilling-simulation.md): 0.372
/// deg/s, an attitude random walk of 5.0 deg/sqrt(h) about the gyro axes.
pub const DRILLING_ANGULAR_SIGMA_RAD_S: f64 = 0.372 * DEG;

/// Variance rate (rad^2/s) of the toolface while the roll is held: the
/// orienter's steps while sliding, 10 deg once an hour (the simulator's
/// `sliding_toolface_step_deg`, `sliding_toolface_steps_per_hour`), taken
/// as a random walk of 100 deg^2/h about the tool axis.
pub const DRILLING_TOOLFACE_VARIANCE_PER_S: f64 = 100.0 * DEG * DEG / 3600.0;

/// Still cycles per block of the station's survey checkpoints: a station
/// sends the survey of the older of its last two checkpoints, 40 to 80
/// cycles (2-4 s) before its last still cycle (or its last still cycle
/// when it was shorter than 80). The still detector ends a station only
/// when the motion exceeds its stay threshold, and the orienter's turn
/// begins slowly: in the drilling simulator the toolface had moved by up
/// to 1.5 deg between 40 samples before the last still cycle and it,
/// twenty times the station's toolface sigma.
pub const SURVEY_SETTLE_EPOCHS: u32 = 40;

/// One still sample's accelerometer roll noise (rad): the SCC1300's x
/// accelerometer noise, 0.058 m/s^2 per sample (paper Table 4), over g.
pub const SINGLE_SAMPLE_ROLL_SIGMA_RAD: f64 = 0.058 / 9.80665;

/// The fewest still cycles with both gyros in a block of
/// [`SURVEY_SETTLE_EPOCHS`] whose means make a rate-gyrocompass update
/// (`aid_sources::EarthRate`): three quarters of the block.
pub const MIN_BIAS_UPDATE_SAMPLES: u32 = SURVEY_SETTLE_EPOCHS * 3 / 4;

/// The rate gyrocompass's consistency gate: the largest normalised
/// innovation squared of a block's two scalars (x and z gyro, each against
/// the filter's covariance before either is used) a still tool passes,
/// `Z_STAY^2` (`super::still`: two-sided 2e-7 per gyro and block, about
/// 2e-3 over the 5,500 blocks of a 1000 m lateral's 37 stations). A block beyond it is a tool that
/// turns while the still detector sees no motion: a smooth slide at the
/// rate of penetration has no acceleration and turns at the build and walk
/// rates, 5-15 deg/h, which the detector cannot see against the SCC1300's
/// per-sample noise, but a block mean reads as earth rate (15 deg/h at
/// most). Unchecked, a quiet slide became an hour of stations whose
/// gyrocompass turned the heading by tens of degrees under 0.05 deg sigmas
/// (docs/lateral-study.md, "A slide without vibration"). The block is not
/// used, and the station ends there (station flag
/// [`MOTION_SEEN`](crate::protocol::frame::station_flags::MOTION_SEEN)).
/// Gyros too noisy to see the turn (a block mean's noise is ~40 deg/h for
/// the SCC1300, ~5 deg/h for the high-end MEMS grade, whose bias
/// instability enters as rate noise) pass it, and their gyrocompass weighs
/// it as little as the noise says.
pub const EARTH_RATE_GATE: f64 = super::still::Z_STAY * super::still::Z_STAY;

/// The filter's settings for a still probe at `position` whose coarse
/// alignment has 1-sigma `coarse_sigma` (roll, pitch, heading; rad), with
/// the sensors' error budget `noise`.
fn filter_config(
    position: &Position,
    coarse_sigma: &[f64; 3],
    noise: &ImuNoise,
) -> FineAlignmentConfig<STATES_WITH_BIASES> {
    FineAlignmentConfig::physical(
        AugmentedModel::from_noise(noise),
        noise,
        coarse_sigma,
        position.lat,
    )
}

enum Phase {
    /// Summing still samples.
    Coarse(SegmentSums),
    /// The filter with zero updates; `samples` taken so far.
    Fine { samples: u32 },
    /// The filter without zero updates, but for station surveys.
    Navigating,
}

/// A station in progress.
struct Station {
    /// Zero-velocity updates so far.
    epochs: u32,
    /// Sum of the still detector's largest normalised statistic.
    quality_sum: f32,
    /// The survey as of the last still cycle.
    survey: StationSurvey,
    /// The survey at the last multiple of [`SURVEY_SETTLE_EPOCHS`] still
    /// cycles, and the one before it: what the station sends.
    checkpoint: Option<StationSurvey>,
    settled: Option<StationSurvey>,
    /// Their links to the previous station (`station_link`; `None` where
    /// the covariance was not valid).
    link: Option<StationLink>,
    checkpoint_link: Option<StationLink>,
    settled_link: Option<StationLink>,
    /// Sums of the x and z gyros' readings over the block's still cycles
    /// for the rate gyrocompass (`aid_sources::EarthRate`).
    gyro_sum: [f64; 2],
    /// Still cycles in those sums.
    gyro_epochs: u32,
}

/// The probe's navigation, one raw sample at a time, with its filter in
/// scalar `T`: the probe's f32 unless told otherwise (see `Filter`).
pub struct Navigator<T: FilterScalar = f32> {
    position: Position,
    calibration: ProbeCalibration,
    /// The sensors' error budget the filter and the aiding sources model
    /// (default the SCC1300's; a reference, 4 bytes on the probe).
    noise: &'static ImuNoise,
    phase: Phase,
    /// Idle until the coarse alignment ends, then restarted in place from
    /// it: the filter is the probe's largest object (6 KiB of covariance),
    /// and every move of it would be another copy on the stack.
    filter: Filter<T>,
    /// The mechanization's input (the tool-axis rate's estimator).
    input: ProbeInput,
    /// 1-sigma of roll, pitch, heading from the coarse alignment (rad),
    /// reported until the filter has its own. An infinite heading sigma
    /// (no heading found) stays in the frames afterwards: the filter then
    /// runs from its best guess with its largest prior, but its small-angle
    /// azimuth sigma would not cover the error. A heading lost in
    /// navigation (its sigma past [`AZIMUTH_SIGMA_LIMIT_RAD`]) is set
    /// infinite here too, until the next tie-in (`note_heading_loss`).
    /// Set only through [`set_heading_source`](Self::set_heading_source).
    coarse_std: [f32; 3],
    /// The heading was determined and then lost in navigation (its sigma
    /// past [`AZIMUTH_SIGMA_LIMIT_RAD`]) since the last tie-in or
    /// alignment: the frames' and stations' `HEADING_LOST` bit.
    heading_lost: bool,
    /// The last sample the filter took, held through a gap.
    held: Option<ImuSample>,
    /// Samples missed in a row (the current gap).
    missed: u32,
    /// Propagated through a gap and not aided since.
    coasting: bool,
    /// The covariance failed its health check (latched until the next
    /// alignment: a covariance that lost its meaning does not regain it).
    covariance_invalid: bool,
    /// A coarse-alignment sample came from one part: the heading cannot be
    /// gyrocompassed from these sums.
    coarse_single_part: bool,
    flags: u16,
    /// The still detector (navigation only).
    still: StillDetector,
    station: Option<Station>,
    /// Stations started since boot.
    stations: u16,
    /// The current still period is no station any more: it reached
    /// `max_station_samples`, or its gyros saw the tool turn
    /// ([`EARTH_RATE_GATE`]). No zero-velocity updates until the detector
    /// sees motion; the moving tool's constraints instead.
    station_capped: bool,
    /// The longest station (samples; default [`MAX_STATION_SAMPLES`]).
    max_station_samples: u32,
    /// A station's zero-velocity update noise variance, (m/s)^2 (default
    /// [`STATION_ZUPT_VARIANCE`]).
    station_zupt_variance: f64,
    /// A finished station, until taken.
    finished_station: Option<StationSurvey>,
    /// The link of the last station finished, and the station whose sent
    /// survey the filter's `station_link::PREVIOUS` snapshot is of.
    finished_link: Option<StationLink>,
    linked_station: u16,
    /// [`track_station_links`](Self::track_station_links).
    station_links: bool,
    /// This still cycle's x and z gyro readings, for the rate gyrocompass
    /// (a zero-velocity cycle with both parts).
    still_gyro: Option<[f64; 2]>,
    /// The roll was held for drilling since the last still cycle.
    drilled_since_station: bool,
    /// The last navigation cycle was still (its roll held).
    was_still: bool,
    /// Consecutive drilling cycles up to this one.
    drilling_cycles: u32,
    /// The turn about the tool axis (rad) in the last navigation cycle when
    /// it followed the accelerometer roll; `None` when the roll was held.
    last_roll_turn: Option<f64>,
    /// The accelerometer-bias estimate and covariance at the last still
    /// cycle of the last station: put back at the next station after
    /// drilling
    /// (`FineAlignment::restore_accel_bias`).
    rest_accel_bias: Option<AccelBiasSnapshot>,
    /// The drilling samples' force since the last toolface update
    /// (`aid_sources::DrillingToolface`).
    toolface_block: ForceBlock,
    /// The raw sample being processed.
    time_us: u64,
    sample_counter: u32,
    /// The surface's survey commands' state (`commands`).
    commands: commands::CommandState,
}

/// The navigator's public entry points that run its filter. Each forwards
/// to [`NavigatorScalar`], whose implementations below are compiled in this
/// crate (see there).
impl<T: NavigatorScalar> Navigator<T> {
    /// Takes one raw sample and returns the solution after it.
    pub fn step(&mut self, raw: &RawSample) -> NavSolution {
        T::step(self, raw)
    }

    /// Takes one calibrated body-frame sample of both parts (the host's
    /// studies of gyros other than the SCC1300, whose readings do not fit
    /// the SCC1300's raw counts: 18 LSB per deg/s would round a
    /// navigation-grade gyro's earth rate away) and returns the solution.
    pub fn step_sample(
        &mut self,
        time_us: u64,
        sample_counter: u32,
        sample: &ProbeSample,
    ) -> NavSolution {
        T::step_sample(self, time_us, sample_counter, sample)
    }

    /// Ties the navigation in to the parent well's survey at the window
    /// (`super::tie_in`, derivation section 4c).
    ///
    /// A probe that has levelled itself (navigating: called between steps
    /// as soon as [`is_navigating`](Self::is_navigating) first returns true)
    /// keeps its filter: the azimuth is replaced by the tie-in's (a turn
    /// about the vertical; the heading error is then the tie-in's alone),
    /// and the tie-in's inclination and toolface are fused with its own
    /// levelling as measurements ([`TieInTilt`]), so the levelled tilt keeps
    /// its correlation with the accelerometer biases it was levelled with.
    /// (Putting the tie-in's tilt in place of that, as independent, left the
    /// window station's toolface 4 times outside its sigma in the coverage
    /// study: the accelerometer bias went into the toolface unseen.)
    /// Before that (or with an invalid covariance) the filter starts again
    /// from the tie-in's attitude and sigmas, independent of the sensor
    /// states, with no zero updates. Drilling mode and stations start
    /// afresh.
    pub fn start_from_tie_in(&mut self, tie_in: &TieIn) {
        T::start_from_tie_in(self, tie_in)
    }

    /// Uplink "start surveying": ends the fine alignment now (see
    /// `commands`' notes). `Ok` when the probe navigates after it.
    pub fn start_surveying(&mut self) -> Result<(), Refusal> {
        T::start_surveying(self)
    }
}

/// A scalar the navigator's filter runs in: f32 on the probe, f64 in the
/// host's studies (`FilterScalar`). Its functions are the navigator's
/// entry points that run the filter, implemented below for each scalar:
/// Rust compiles a generic function in the crate that calls it, and the
/// firmware's own build of the f32 filter came out 27 KB larger and 3 %
/// slower per cycle than this crate's (docs/budgets.md). Implemented
/// (concretely, not generically) here, their code is this crate's.
/// Sealed: only f32 and f64.
pub trait NavigatorScalar: FilterScalar + sealed::Sealed {
    /// [`Navigator::step`].
    fn step(navigator: &mut Navigator<Self>, raw: &RawSample) -> NavSolution;
    /// [`Navigator::step_sample`].
    fn step_sample(
        navigator: &mut Navigator<Self>,
        time_us: u64,
        sample_counter: u32,
        sample: &ProbeSample,
    ) -> NavSolution;
    /// [`Navigator::start_from_tie_in`].
    fn start_from_tie_in(navigator: &mut Navigator<Self>, tie_in: &TieIn);
    /// [`Navigator::start_surveying`].
    fn start_surveying(navigator: &mut Navigator<Self>) -> Result<(), Refusal>;
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

macro_rules! navigator_scalar {
    ($($scalar:ty),+) => {$(
        impl NavigatorScalar for $scalar {
            fn step(navigator: &mut Navigator<Self>, raw: &RawSample) -> NavSolution {
                navigator.step_raw(raw)
            }
            fn step_sample(
                navigator: &mut Navigator<Self>,
                time_us: u64,
                sample_counter: u32,
                sample: &ProbeSample,
            ) -> NavSolution {
                navigator.step_calibrated(time_us, sample_counter, sample)
            }
            fn start_from_tie_in(navigator: &mut Navigator<Self>, tie_in: &TieIn) {
                navigator.tie_in(tie_in)
            }
            fn start_surveying(navigator: &mut Navigator<Self>) -> Result<(), Refusal> {
                navigator.start_surveying_now()
            }
        }
    )+};
}

navigator_scalar!(f32, f64);

/// The probe's constructors, f32: on the default type itself, so that
/// `Navigator::new(..)` needs no annotation (a default type parameter does
/// not steer inference); another scalar's navigator comes from
/// [`Navigator::calibrated`].
impl Navigator {
    /// A navigator for a probe at `position` with uncalibrated sensors.
    pub fn new(position: Position) -> Self {
        Self::with_calibration(position, ProbeCalibration::default())
    }

    /// The same with the still detector's and the station's `settings`
    /// (the uplink's, range-checked when decoded).
    pub fn with_settings(
        position: Position,
        calibration: ProbeCalibration,
        settings: &StillSettings,
    ) -> Self {
        let mut navigator = Self::with_calibration(position, calibration);
        navigator.apply_still_settings(settings);
        navigator
    }

    /// A navigator that corrects every sample with `calibration`, with the
    /// default still settings.
    pub fn with_calibration(position: Position, calibration: ProbeCalibration) -> Self {
        Self::calibrated(position, calibration)
    }
}

impl<T: FilterScalar> Navigator<T> {
    /// Takes the still detector's and the station's `settings` (the
    /// uplink's, range-checked when decoded): the detector's thresholds are
    /// derived here, once, not per sample. For a navigator that has not
    /// started (the probe's boot and re-align). In place, because the
    /// probe's navigator is ~9 KiB: a constructor that took the settings
    /// kept a second one in its frame (16 KiB) on top of `main`'s.
    pub fn apply_still_settings(&mut self, settings: &StillSettings) {
        let gravity = normal_gravity(self.position.lat, self.position.height);
        self.still = StillDetector::scc1300_with(gravity, &Hysteresis::from_settings(settings));
        self.max_station_samples = settings.max_station_samples;
        self.station_zupt_variance = station_zupt_variance(settings.zupt_velocity_sigma);
    }

    /// [`Navigator::with_calibration`] in filter scalar `T`, e.g.
    /// `Navigator::<f64>::calibrated(..)` for the host's studies.
    pub fn calibrated(position: Position, calibration: ProbeCalibration) -> Self {
        let idle = NavState::at_rest(UnitQuaternion::identity(), position);
        let noise = &SCC1300_NOISE;
        Self {
            position,
            calibration,
            noise,
            phase: Phase::Coarse(SegmentSums::default()),
            filter: Filter::new(idle, position, filter_config(&position, &[0.0; 3], noise)),
            input: ProbeInput::new(),
            coarse_std: [f32::NAN; 3],
            heading_lost: false,
            held: None,
            missed: 0,
            coasting: false,
            covariance_invalid: false,
            coarse_single_part: false,
            flags: 0,
            still: StillDetector::scc1300(normal_gravity(position.lat, position.height)),
            station: None,
            stations: 0,
            station_capped: false,
            max_station_samples: MAX_STATION_SAMPLES,
            station_zupt_variance: STATION_ZUPT_VARIANCE,
            finished_station: None,
            finished_link: None,
            linked_station: 0,
            station_links: false,
            still_gyro: None,
            drilled_since_station: false,
            was_still: false,
            drilling_cycles: 0,
            last_roll_turn: None,
            rest_accel_bias: None,
            toolface_block: ForceBlock::default(),
            time_us: 0,
            sample_counter: 0,
            commands: commands::CommandState::default(),
        }
    }

    /// Models the sensors with the error budget `noise` instead of the
    /// SCC1300's: the filter's AR and bias models, its process noise and
    /// the aiding sources' variances. The still detector keeps the
    /// SCC1300's thresholds (a quieter gyro passes them too). For a
    /// navigator that has not started; the host's studies of other gyro
    /// grades use it (the probe flies the SCC1300).
    pub fn set_noise_budget(&mut self, noise: &'static ImuNoise) {
        self.noise = noise;
    }

    /// Whether the filter keeps the station links (`station_link`): off by
    /// default. No frame carries them yet, and on the probe they cost a
    /// drilling cycle ~14,500 instructions (the QEMU drilling run's worst
    /// cycle 405,120, over the 10 % budget: docs/budgets.md); the host's
    /// studies turn them on. Off, the snapshots already kept are dropped.
    pub fn track_station_links(&mut self, on: bool) {
        self.station_links = on;
        if !on {
            self.filter.snapshots_mut().1.clear_all();
            self.finished_link = None;
        }
    }

    /// The sensors' error budget the navigator models.
    pub fn noise_budget(&self) -> &'static ImuNoise {
        self.noise
    }

    fn step_raw(&mut self, raw: &RawSample) -> NavSolution {
        let reading = reading(raw, &self.calibration);
        self.step_reading(raw.time_us, raw.sample_counter, reading)
    }

    fn step_calibrated(
        &mut self,
        time_us: u64,
        sample_counter: u32,
        sample: &ProbeSample,
    ) -> NavSolution {
        self.step_reading(time_us, sample_counter, Reading::Both(*sample))
    }

    fn step_reading(&mut self, time_us: u64, sample_counter: u32, reading: Reading) -> NavSolution {
        self.flags = 0;
        self.time_us = time_us;
        self.sample_counter = sample_counter;
        let still = match reading {
            Reading::Both(sample) => self.use_sample(&sample, None),
            Reading::Single {
                sample,
                missing_gyro,
            } => {
                self.flags |= nav_flags::SENSOR_DEGRADED | nav_flags::SINGLE_PART;
                self.use_sample(&sample, Some(missing_gyro))
            }
            // No valid data: the alignment waits, the filter coasts.
            Reading::Neither => {
                self.flags |= nav_flags::SENSOR_DEGRADED;
                self.coast();
                self.is_navigating().then_some(false)
            }
        };
        if self.is_aligned() && !self.covariance_invalid {
            let limit = T::of(f64::from(VARIANCE_LIMIT));
            self.covariance_invalid = !self.filter.filter().covariance_is_healthy(limit);
        }
        if let Some(still) = still {
            self.track_station(still);
            self.follow_commands(still);
        }
        // After the station's updates, which the frame reports; a station
        // finished above judges its own sigma against the limit.
        let attitude_std = self.attitude_std();
        if let Some(std) = &attitude_std {
            self.note_heading_loss(std.z);
        }
        self.solution(time_us, sample_counter, attitude_std)
    }

    /// The filter's roll, pitch and heading sigmas (rad), once it has a
    /// solution with a valid covariance: computed once per cycle, for the
    /// frame and the heading-loss check.
    fn attitude_std(&self) -> Option<Vector3<f64>> {
        let has_solution = !matches!(self.phase, Phase::Coarse(_));
        (has_solution && !self.covariance_invalid).then(|| self.filter.euler_std())
    }

    /// Once the navigating filter's azimuth sigma passes the first-order
    /// limit ([`AZIMUTH_SIGMA_LIMIT_RAD`]), the heading stays undetermined
    /// until the next tie-in, even when the sigma comes back under it.
    /// Past the limit the small-angle model no longer holds, and the rate
    /// gyrocompass's heading information, taken at an estimate that may
    /// be tens of degrees off (a cross-axis gyro sees the earth rate as
    /// the cosine of the heading), makes the sigma shrink by what the
    /// estimate believes, not by what the data tell. On the simulated
    /// 1000 m lateral (40 runs) the SCC1300's 666 station azimuths that
    /// came back under the limit were 87 % within 2 sigma, their error
    /// over sigma 1.67 RMS, one 92 deg off under a 9.3 deg sigma
    /// (docs/lateral-study.md, "A heading once lost stays lost"). A NaN
    /// sigma counts as past.
    /// A heading never found (an infinite sigma already) is not "lost".
    fn note_heading_loss(&mut self, heading_std: f64) {
        let navigating = matches!(self.phase, Phase::Navigating);
        if navigating && self.loses_heading(heading_std) {
            self.coarse_std[2] = f32::INFINITY;
            self.heading_lost = true;
        }
    }

    /// Whether a heading sigma (rad, the filter's Euler heading) loses a
    /// heading that was found: past the limit, or NaN.
    pub(super) fn loses_heading(&self, heading_std: f64) -> bool {
        let within = heading_std <= AZIMUTH_SIGMA_LIMIT_RAD; // false for NaN
        self.coarse_std[2].is_finite() && !within
    }

    /// The roll, pitch and heading sigmas of a new source of the attitude
    /// (the coarse alignment, a tie-in): a heading lost before is
    /// forgotten.
    fn set_heading_source(&mut self, sigma: [f64; 3]) {
        self.coarse_std = sigma.map(|s| s as f32);
        self.heading_lost = false;
    }

    /// The station survey finished by the last [`step`](Self::step), if
    /// any: the probe sends it after that step's navigation frame.
    pub fn take_station(&mut self) -> Option<StationSurvey> {
        self.finished_station.take()
    }

    /// The link to the previous station of the last station the station
    /// tracking finished (`station_link`), once it is taken: `None` when
    /// its covariance was not valid or it was too short to have two
    /// checkpoints. A station sent on request or as an indexing dwell has
    /// none; match on `StationLink::station`.
    pub fn station_link(&self) -> Option<&StationLink> {
        self.finished_link.as_ref()
    }

    /// Stations started since boot.
    pub fn stations(&self) -> u16 {
        self.stations
    }

    /// `sample`, with the gyro of index `missing_gyro` (in `GYRO_AXES`)
    /// out when one part is. Returns, when navigating, whether the probe
    /// was still (a zero-velocity update was made).
    fn use_sample(&mut self, sample: &ProbeSample, missing_gyro: Option<usize>) -> Option<bool> {
        let mut sample = *sample;
        let mut coarse_done = None;
        let mut fine_done = false;
        let mut navigating_still = None;
        let gap_ended = self.missed > 0;
        self.missed = 0;
        if gap_ended {
            // The roll-derived tool-axis rate would difference rolls a gap
            // apart and count the held rate's turn twice: it starts again.
            self.input = ProbeInput::new();
        }
        // Judged on the sample as measured (before the missing gyro's
        // stand-in): with one part out a turn about its axis would not be
        // seen, so stillness is judged on full samples only. Judged in the
        // fine alignment too, so a probe still at its end navigates on as
        // still from the first cycle: before, the detector's 1.95 s delay
        // made those cycles "moving", whose roll follows the accelerometer
        // roll (~0.3 deg of noise per sample) while its sigma stayed the
        // levelling's 0.06 deg; the rate gyrocompass then read the
        // unmodelled roll error (a tilt of the vertical earth rate into
        // the x and z gyros) as heading and inclination: the window
        // station's inclination came out 0.085 deg RMS against a 0.047 deg
        // sigma with a navigation-grade gyro (docs/lateral-study.md).
        let still = match (&self.phase, missing_gyro) {
            (Phase::Fine { .. } | Phase::Navigating, None) => self.still.update(&sample),
            _ => {
                self.still.reset();
                false
            }
        };
        let filter = &mut self.filter;
        // The missing gyro's stand-in: the rate of a tool turning with the
        // navigation frame (a still tool), uncertain by
        // `UNMEASURED_RATE_SIGMA` each step.
        let extra = match missing_gyro {
            None => StepNoise::NONE,
            Some(k) => {
                let frame_rate = filter.frame_rate_in_body();
                sample.gyro[k] = frame_rate[GYRO_AXES[k]];
                StepNoise {
                    attitude: square(UNMEASURED_RATE_SIGMA * SAMPLE_INTERVAL_S),
                    velocity: 0.0,
                    skip_updates: false,
                }
            }
        };
        match &mut self.phase {
            Phase::Coarse(sums) => {
                self.coarse_single_part |= missing_gyro.is_some();
                sums.add(&sample);
                if sums.samples() >= ALIGNMENT_SAMPLES as usize {
                    coarse_done = Some(sums.segment());
                }
            }
            Phase::Fine { samples } => {
                let (imu, _) = self.input.imu_sample(
                    &filter.frame_rate_in_body(),
                    &sample,
                    ToolAxisSource::AtRest,
                    SAMPLE_INTERVAL_S,
                );
                let report = filter.step_with(&imu, &extra);
                self.held = Some(imu);
                if report.zero_velocity.accepted > 0 {
                    self.flags |= nav_flags::ZUPT_APPLIED;
                    self.coasting = false;
                }
                *samples += 1;
                fine_done = *samples >= FINE_ALIGNMENT_SAMPLES;
            }
            Phase::Navigating => {
                let jitter = f64::from(self.still.statistics().lateral_jitter);
                let drilling = !still && jitter > DRILLING_JITTER_LIMIT_M_S2;
                // Drilling: the roll is held (the accelerometer roll is
                // vibration), and the roll estimator starts again after it:
                // a difference across the drilling would add the roll
                // change a second time on top of what the filter already
                // corrected through the constraints. Still: held too, as in
                // the fine alignment (`ToolAxisSource::AtRest`: a single
                // sample's roll carries its 0.3 deg of noise).
                if drilling {
                    self.input = ProbeInput::new();
                }
                let source = if drilling || still {
                    ToolAxisSource::AtRest
                } else {
                    ToolAxisSource::AccelerometerRoll
                };
                let frame_rate = filter.frame_rate_in_body();
                let (imu, tool_axis) =
                    self.input
                        .imu_sample(&frame_rate, &sample, source, SAMPLE_INTERVAL_S);
                filter.hold_tool_axis(source == ToolAxisSource::AtRest);
                if tool_axis == ToolAxisRate::Unavailable || drilling {
                    self.flags |= nav_flags::TOOL_AXIS_RATE_INVALID;
                }
                // No updates past the longest station (see
                // `MAX_STATION_SAMPLES`): free navigation until it moves.
                let update = still && !self.station_capped;
                filter.set_zero_velocity(update.then_some(self.station_zupt_variance));
                let mut extra = extra;
                self.drilling_cycles = if drilling {
                    self.drilling_cycles.saturating_add(1)
                } else {
                    0
                };
                if drilling {
                    // The measured lateral jitter is the vibration's force
                    // noise per sample: white, a velocity random walk.
                    let onset = vibration_onset_factor(self.drilling_cycles);
                    extra.velocity += square(jitter * SAMPLE_INTERVAL_S) * onset;
                }
                filter.linearize_at_gravity(drilling || still);
                // A still tool's attitude does not change: once the
                // station's first block has re-levelled it, the error model
                // stays linearised there instead of following each ZUPT's
                // correction (derivation section 4i).
                let settled = still
                    && self
                        .station
                        .as_ref()
                        .is_some_and(|s| s.epochs >= SURVEY_SETTLE_EPOCHS);
                filter.fix_linearization(settled);
                let report = filter.step_with(&imu, &extra);
                if drilling {
                    filter.add_attitude_noise(&drilling_attitude_noise(filter.state()));
                }
                if report.sample_used && !update && !self.covariance_invalid {
                    // Drilling or moving in the hole: the tool moves along
                    // its axis (derivation sections 4b, 4d). Also still
                    // past the station's end (the longest station, or the
                    // gyros saw it turn): the detector cannot tell a tool
                    // at rest from one sliding smoothly, and these hold
                    // for both; free inertial navigation there grew
                    // velocity errors of tens of m/s in an hour of a quiet
                    // slide, far outside the error model's linear range.
                    // The rows' attitude terms (v_n x r_a) are dropped:
                    // linearised at the computed velocity, which while
                    // drilling is mostly vibration noise (the true speed,
                    // the rate of penetration, is < 0.01 m/s), they would
                    // read that noise as azimuth and tilt errors; the true
                    // speed's leak through an attitude error is in the
                    // constraint's noise (the misalignment part, 0.5 m/s x
                    // 1 deg; derivation section 4d).
                    let state = filter.state();
                    let mut cross = NonHolonomic::at(state, T::of(DRILLING_VARIANCE));
                    cross.attitude_row = [[T::zero(); 3]; 2];
                    let mut axial = AxialSpeed::at(state, T::of(AXIAL_SPEED_VARIANCE));
                    axial.attitude_row = [T::zero(); 3];
                    // One update: the axial bound's value was computed
                    // at the solution before the cross-axis correction,
                    // which a feedback between two updates would have
                    // moved under it (`kalman::Stacked`).
                    filter.aid(&Stacked(cross, axial));
                }
                if drilling && report.sample_used && !self.covariance_invalid {
                    self.toolface_block.add(&sample.specific_force);
                    if self.toolface_block.samples() >= TOOLFACE_BLOCK_SAMPLES {
                        aid_drilling_toolface(filter, &self.toolface_block, self.noise);
                        self.toolface_block.clear();
                    }
                } else {
                    self.toolface_block.clear();
                }
                if still && self.drilled_since_station {
                    // The first still cycle after drilling: the roll was
                    // held through it, so the orienter's steps were not
                    // sensed. The accelerometer roll shows how far off the
                    // held roll is; that, with the sample's own roll noise,
                    // goes into the variance about the tool axis, and the
                    // station's zero-velocity updates re-level it.
                    let offset = roll_offset(filter.state(), &sample);
                    let variance = square(offset) + square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
                    add_tool_axis_variance(filter, variance);
                    // The accelerometer biases as the last station (at rest)
                    // left them: while drilling the filter read the
                    // vibration's rectified force as bias, and at rest
                    // that bias is inseparable from the tilt the station
                    // measures, so it would go straight into the toolface
                    // (seen in the simulated lateral: 0.10-0.15 deg of
                    // toolface error, the same sign in every seed, against
                    // 0.035-deg sigmas).
                    if let Some(snapshot) = &self.rest_accel_bias {
                        filter.restore_accel_bias(snapshot);
                    }
                    self.drilled_since_station = false;
                }
                if !still && !drilling && self.was_still && report.sample_used {
                    // The first moving cycle after a still period: the
                    // roll was held through the still detector's delay
                    // while the orienter may already have been turning the
                    // tool (0.5 deg in the simulated connections, 15 times
                    // the station's roll sigma), and from here the roll
                    // follows the accelerometer roll's differences, so its
                    // error stays that offset plus the difference of two
                    // samples' roll noise. Unmodelled, the velocity it
                    // makes went through the non-holonomic updates into
                    // the heading (up to 8 deg per connection in the
                    // drilling study; derivation section 4h).
                    let offset = roll_offset(filter.state(), &sample);
                    let variance = square(offset) + 2.0 * square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
                    add_tool_axis_variance(filter, variance);
                }
                if let (true, Some(turn)) = (drilling, self.last_roll_turn) {
                    // The first drilling cycle after the roll followed the
                    // accelerometers: the roll is held from here, and the
                    // vibration that made this a drilling cycle may have
                    // begun before the orienter's turn ended. The turn of
                    // one cycle is estimated by the last one's (noisy by
                    // the two samples' roll noise, which is added too).
                    let variance = square(turn) + 2.0 * square(SINGLE_SAMPLE_ROLL_SIGMA_RAD);
                    add_tool_axis_variance(filter, variance);
                }
                self.last_roll_turn = match (source, tool_axis) {
                    (ToolAxisSource::AccelerometerRoll, ToolAxisRate::Valid(rate)) => {
                        Some((rate - frame_rate.y) * SAMPLE_INTERVAL_S)
                    }
                    _ => None,
                };
                self.was_still = still;
                self.drilled_since_station |= drilling;
                if still && !self.drilled_since_station {
                    self.rest_accel_bias = filter.accel_bias();
                }
                self.still_gyro = (update && missing_gyro.is_none()).then_some(sample.gyro);
                self.held = Some(imu);
                if still {
                    self.flags |= nav_flags::STILL;
                }
                if report.zero_velocity.accepted > 0 {
                    self.flags |= nav_flags::ZUPT_APPLIED;
                    self.coasting = false;
                }
                navigating_still = Some(still && report.sample_used);
            }
        }
        if let Some(segment) = coarse_done {
            // A single part in the coarse alignment: its gyro alone cannot
            // gyrocompass.
            self.finish_coarse_alignment(&segment, !self.coarse_single_part);
        }
        if fine_done {
            self.enter_navigation();
        }
        navigating_still
    }

    /// A sample with no valid data: after the coarse alignment the filter
    /// propagates the last sample it took (held rates and force: exact for
    /// a steady turn), with the held values' possible error as process
    /// noise, fully correlated over the gap (the same held value every
    /// step: the k-th missed step adds (2k - 1) sigma^2 dt^2, so k steps
    /// hold (k sigma dt)^2), and no zero update.
    fn coast(&mut self) {
        let Some(held) = self.held else {
            return;
        };
        if matches!(self.phase, Phase::Coarse(_)) {
            return;
        }
        self.missed = self.missed.saturating_add(1);
        // A gap ends any still period: stillness was not seen (and the
        // step below makes no zero update).
        self.still.reset();
        let growth = f64::from(2 * self.missed.min(1 << 20) - 1);
        let extra = StepNoise {
            attitude: growth * square(UNMEASURED_RATE_SIGMA * SAMPLE_INTERVAL_S),
            velocity: growth * square(UNMEASURED_FORCE_SIGMA * SAMPLE_INTERVAL_S),
            skip_updates: true,
        };
        self.filter.step_with(&held, &extra);
        self.coasting = true;
    }

    fn finish_coarse_alignment(&mut self, segment: &StaticSegment, gyrocompass_possible: bool) {
        let mut config = AlignmentConfig::probe(self.position.lat);
        config.noise = *self.noise;
        let (roll, pitch, roll_pitch_std) = match level_segment(segment, &config) {
            Ok(l) => (l.roll.value, l.pitch.value, [l.roll.sigma, l.pitch.sigma]),
            Err(_) => (0.0, 0.0, [f64::NAN; 2]),
        };
        // Without a usable heading the solution runs on with heading 0 and
        // says so through its (infinite) standard deviation; the filter
        // starts it with its largest prior (30 deg, see `physical`).
        // One part's gyro alone cannot gyrocompass: not even tried.
        let estimate =
            gyrocompass_possible.then(|| gyrocompass(core::slice::from_ref(segment), &config));
        // A heading whose mirror candidate explains the data as well is
        // undetermined however small its sigma unless a prior chose it
        // (`ambiguous` stays set when one did); the probe has none
        // (`AlignmentConfig::probe`), so the lower misfit is a coin toss.
        // A horizontal tool's cross-axis gyros see only the sine of its
        // heading, and a quiet grade's 1 deg sigma once went out on the
        // mirror 60 deg away; the tie-in brings the heading.
        let unchosen = |h: &HeadingEstimate| h.ambiguous && config.heading_prior.is_none();
        let (heading, heading_std) = match estimate {
            Some(Ok(h)) if h.determined && !unchosen(&h) => (h.heading.value, h.heading.sigma),
            Some(Ok(h)) => (h.heading.value, f64::INFINITY),
            Some(Err(_)) | None => (0.0, f64::INFINITY),
        };
        let sigma = [roll_pitch_std[0], roll_pitch_std[1], heading_std];
        self.set_heading_source(sigma);
        // A levelling that failed leaves no tilt sigma: the filter then
        // starts from a 10 deg one.
        let filter_sigma = sigma.map(|s| if s.is_nan() { 10f64.to_radians() } else { s });
        let attitude = quat_from_euler(&Euler::new(roll, pitch, heading));
        self.filter.restart(
            NavState::at_rest(attitude, self.position),
            self.position,
            filter_config(&self.position, &filter_sigma, self.noise),
        );
        self.covariance_invalid = false;
        self.coasting = false;
        self.drilled_since_station = false;
        self.was_still = false;
        self.drilling_cycles = 0;
        self.last_roll_turn = None;
        self.rest_accel_bias = None;
        self.toolface_block.clear();
        self.phase = Phase::Fine { samples: 0 };
    }

    /// The cycle's frame; `attitude_std` from [`attitude_std`](Self::attitude_std).
    fn solution(
        &self,
        time_us: u64,
        sample_counter: u32,
        attitude_std: Option<Vector3<f64>>,
    ) -> NavSolution {
        let mut solution = NavSolution {
            time_us,
            sample_counter,
            mode: nav_mode::COARSE_ALIGNMENT,
            flags: self.flags,
            // Placeholders while there is no solution: NaN, never a
            // number that could be read (docs/protocol.md, Kind 2).
            attitude: [f32::NAN; 3],
            velocity_ned: [f32::NAN; 3],
            latitude: self.position.lat,
            longitude: self.position.lon,
            height: self.position.height as f32,
            attitude_std: self.coarse_std,
            // No filter yet: velocity and position uncertainty unknown.
            velocity_std: [f32::NAN; 3],
            position_std_ned: [f32::NAN; 3],
        };
        solution.mode = match self.phase {
            Phase::Coarse(_) => return solution,
            Phase::Fine { .. } => nav_mode::FINE_ALIGNMENT,
            Phase::Navigating => nav_mode::NAVIGATING,
        };
        let filter = &self.filter;
        let state = filter.state();
        let e = euler_from_quat(&state.attitude);
        solution.attitude = [e.roll, e.pitch, e.heading].map(|a| a as f32);
        let v = state.velocity;
        solution.velocity_ned = [v.x, v.y, v.z].map(|v| v as f32);
        solution.latitude = state.position.lat;
        solution.longitude = state.position.lon;
        solution.height = state.position.height as f32;
        if self.coasting {
            solution.flags |= nav_flags::COASTING;
        }
        if self.heading_lost {
            solution.flags |= nav_flags::HEADING_LOST;
        }
        let Some(std) = attitude_std.filter(|_| !self.covariance_invalid) else {
            solution.flags |= nav_flags::COVARIANCE_INVALID | nav_flags::SOLUTION_INVALID;
            solution.attitude_std = [f32::NAN; 3];
            return solution;
        };
        // The azimuth's sigma: infinite while the heading is undetermined
        // (coarse alignment, or lost in navigation) or rests on one gyro
        // (single part).
        let heading_std = if self.coarse_std[2].is_finite()
            && solution.flags & nav_flags::SINGLE_PART == 0
            && std.z <= AZIMUTH_SIGMA_LIMIT_RAD
        {
            std.z as f32
        } else {
            f32::INFINITY
        };
        solution.attitude_std = [std.x as f32, std.y as f32, heading_std];
        // Beyond the tilt limit (or with a tilt sigma that is not even a
        // number) the small-angle error model no longer holds.
        let tilt_valid = std.x <= TILT_SIGMA_LIMIT_RAD && std.y <= TILT_SIGMA_LIMIT_RAD;
        if !tilt_valid {
            solution.flags |= nav_flags::SOLUTION_INVALID;
        }
        let kalman = filter.filter();
        // The frames' sigmas are f32 whatever the filter's scalar (the wire
        // protocol's type).
        let std_dev = |i: usize| kalman.std_dev(i).as_f64() as f32;
        solution.velocity_std = core::array::from_fn(|i| std_dev(VEL + i));
        solution.position_std_ned = core::array::from_fn(|i| std_dev(POS + i));
        solution
    }

    fn tie_in(&mut self, tie_in: &TieIn) {
        if !matches!(self.phase, Phase::Navigating) || self.covariance_invalid {
            self.restart_from_tie_in(tie_in);
            return;
        }
        // The filter starts again at the probe's own levelled tilt and the
        // tie-in's azimuth: what it learned in the fine alignment rested on
        // a heading that may have been tens of degrees off (its gyro-bias
        // estimates absorbed the misplaced earth rate: kept, the window's
        // azimuths came out 11 deg RMS instead of 6). The tilt starts as a
        // levelling with these accelerometers (`TiltPrior` default: its
        // error holds their biases) from the coarse levelling's noise; the
        // heading error is the tie-in's alone.
        let (own, _) = angles_and_jacobian(&dcm_from_quat(&self.filter.state().attitude));
        let given = tie_in.angles();
        let sigma = tie_in.sigma();
        let start = DrillingAngles {
            azimuth: given.azimuth,
            ..own
        };
        let levelling = [self.coarse_std[0], self.coarse_std[1]].map(|s| {
            if s.is_finite() {
                f64::from(s)
            } else {
                10f64.to_radians()
            }
        });
        let config = filter_config(
            &self.position,
            &[levelling[0], levelling[1], sigma.azimuth],
            self.noise,
        );
        let state = NavState::at_rest(quat_from_euler(&start.to_euler()), self.position);
        self.filter.restart(state, self.position, config);
        self.filter.set_heading(0.0, square(sigma.azimuth));
        self.filter.start_navigation();
        // Inclination and toolface are fused with the probe's levelling.
        let (angles, jacobian) = angles_and_jacobian(&dcm_from_quat(&self.filter.state().attitude));
        let row = |i: usize| [0, 1, 2].map(|k| T::of(jacobian[(i, k)]));
        let tilt = TieInTilt {
            rows: [row(0), row(2)],
            innovation: [
                T::of(angles.inclination - given.inclination),
                T::of(crate::conventions::wrap_pi(
                    angles.toolface - given.toolface,
                )),
            ],
            variance: [
                T::of(square(sigma.inclination)),
                T::of(square(sigma.toolface)),
            ],
        };
        self.filter.aid(&tilt);
        let euler_std = self.filter.euler_std();
        self.set_heading_source([euler_std.x, euler_std.y, sigma.azimuth]);
        self.input = ProbeInput::new();
        self.coasting = false;
        self.coarse_single_part = false;
        self.drilled_since_station = false;
        // `was_still` is kept: the roll is the levelling's, held as at the
        // end of the fine alignment (`enter_navigation`).
        self.drilling_cycles = 0;
        self.last_roll_turn = None;
        self.rest_accel_bias = None;
        self.toolface_block.clear();
    }

    /// [`start_from_tie_in`](Self::start_from_tie_in) before the probe
    /// has levelled itself (or with a covariance that lost its meaning):
    /// the filter starts again from the tie-in's attitude and sigmas.
    fn restart_from_tie_in(&mut self, tie_in: &TieIn) {
        let sigma = tie_in.euler_sigma();
        let mut config = filter_config(&self.position, &sigma, self.noise);
        config.tilt_prior = TiltPrior::Independent;
        let start = NavState::at_rest(tie_in.attitude(), self.position);
        self.filter.restart(start, self.position, config);
        self.filter
            .set_attitude_error_covariance(&tie_in.attitude_error_covariance());
        self.filter.start_navigation();
        self.set_heading_source(sigma);
        self.input = ProbeInput::new();
        self.held = None;
        self.missed = 0;
        self.coasting = false;
        self.covariance_invalid = false;
        self.coarse_single_part = false;
        self.drilled_since_station = false;
        self.was_still = false;
        self.drilling_cycles = 0;
        self.last_roll_turn = None;
        self.rest_accel_bias = None;
        self.toolface_block.clear();
        self.phase = Phase::Navigating;
    }

    /// One non-holonomic update at the current solution (no velocity
    /// across the tool axis, `aid_sources::NonHolonomic`, with the drilling
    /// BHA's noise [`DRILLING_VARIANCE`]), for the caller that knows the
    /// tool is drilling; call it between steps (the next frame shows it).
    /// Only while navigating with a valid covariance; `None` otherwise.
    pub fn apply_non_holonomic(&mut self) -> Option<UpdateReport> {
        if !self.is_navigating() || self.covariance_invalid {
            return None;
        }
        let constraint = NonHolonomic::at(self.filter.state(), T::of(DRILLING_VARIANCE));
        Some(self.filter.aid(&constraint))
    }

    /// The filter (idle during the coarse alignment): for analysis, e.g.
    /// the covariance behind the frames' sigmas.
    pub fn filter(&self) -> &FineAlignment<T, STATES_WITH_BIASES> {
        &self.filter
    }

    /// True once the coarse alignment is done.
    pub fn is_aligned(&self) -> bool {
        !matches!(self.phase, Phase::Coarse(_))
    }

    /// True once the fine alignment is done too.
    pub fn is_navigating(&self) -> bool {
        matches!(self.phase, Phase::Navigating)
    }

    /// One reference-azimuth update (rad, true north; 1-sigma `sigma` rad)
    /// at the current solution (`aid_sources::HeadingReference`: the probe
    /// as the backup of a reference heading, docs/redundant-rins.md); call
    /// it between steps. Only while navigating with a valid covariance;
    /// `None` then, or for a reference the source refuses. A heading lost
    /// past the first-order limit stays undetermined after it: unlike a
    /// tie-in, a reference does not restart the filter, whose gyro-bias
    /// estimates were learned at the lost heading (`note_heading_loss`).
    pub fn aid_heading(&mut self, azimuth: f64, sigma: f64) -> Option<UpdateReport> {
        if !self.is_navigating() || self.covariance_invalid {
            return None;
        }
        let reference =
            crate::aid_sources::HeadingReference::<T>::at(self.filter.state(), azimuth, sigma)
                .ok()?;
        Some(self.filter.aid(&reference))
    }
}

/// How much the still detector's jitter (the RMS of the successive force
/// differences over its window, `StillStatistics::lateral_jitter`)
/// understates the vibration in the `k`-th drilling cycle after it began:
/// the window's WINDOW - 1 differences then hold k - 1 between vibrating
/// samples and one half-vibrating (the first one), k - 1/2 in all; the
/// variance is scaled up by their share. Unscaled, the first drilling
/// samples' vibration (0.36 m/s per sample at the moderate level) went
/// into the velocity with a twentieth of its variance, and the
/// non-holonomic updates turned it into heading through the velocity's
/// correlation with it (1.3 deg in 0.3 s in the simulated lateral;
/// derivation section 4h).
fn vibration_onset_factor(k: u32) -> f64 {
    let differences = (super::still::WINDOW - 1) as f64;
    let vibrating = f64::from(k.max(1)) - 0.5;
    (differences / vibrating).max(1.0)
}

fn square(v: f64) -> f64 {
    v * v
}

/// The drilling environment's attitude noise for one step, nav frame
/// (derivation section 4d): the angular vibration about the gyro axes
/// (body x and z: (I - t t^T) sigma^2 dt^2, t the tool axis) and the
/// orienter's unsensed toolface steps about the tool axis (t t^T q dt).
fn drilling_attitude_noise(state: &NavState) -> Matrix3<f64> {
    let c_bn = dcm_from_quat(&state.attitude);
    let t: Vector3<f64> = c_bn.column(1).into_owned();
    let tt = t * t.transpose();
    let vibration = square(DRILLING_ANGULAR_SIGMA_RAD_S * SAMPLE_INTERVAL_S);
    (Matrix3::identity() - tt) * vibration
        + tt * (DRILLING_TOOLFACE_VARIANCE_PER_S * SAMPLE_INTERVAL_S)
}

/// A drilling toolface innovation beyond this many sigma (squared) is not
/// a small-angle error: the driller turned the toolface on bottom, and the
/// roll is set to the block's instead of updated towards it.
const GROSS_TOOLFACE_CHI2: f64 = 16.0;

/// The toolface of one block of drilling samples against the held roll
/// (`aid_sources::DrillingToolface`, derivation section 4g): an update, or
/// when the roll is grossly off (a toolface turned on bottom) the block's
/// roll with its variance about the tool axis.
fn aid_drilling_toolface<T: FilterScalar>(
    filter: &mut Filter<T>,
    block: &ForceBlock,
    noise: &ImuNoise,
) {
    let budget = noise.accel[0];
    let bias_variance = square(budget.residual_bias) + square(budget.bias_instability);
    let Some(m) = DrillingToolface::<T>::at(filter.state(), block, bias_variance) else {
        return;
    };
    let h = Vector3::from(m.attitude_row.map(T::as_f64));
    let variance = m.variance.as_f64();
    let innovation_variance = h.dot(&(filter.attitude_error_covariance() * h)) + variance;
    if square(m.toolface_residual.as_f64()) > GROSS_TOOLFACE_CHI2 * innovation_variance {
        filter.set_roll(m.block_toolface);
        add_tool_axis_variance(filter, variance);
    } else {
        filter.aid(&m);
    }
}

/// Adds `variance` (rad^2) to the attitude error about the tool axis (the
/// roll): the roll the filter holds or follows may be off by more than its
/// covariance says (an orienter's turn not sensed, a re-roll).
fn add_tool_axis_variance<T: FilterScalar>(filter: &mut Filter<T>, variance: f64) {
    let c_bn = dcm_from_quat(&filter.state().attitude);
    let t: Vector3<f64> = c_bn.column(1).into_owned();
    filter.add_attitude_noise(&(t * t.transpose() * variance));
}

/// The accelerometer roll of `sample` less the solution's roll (rad,
/// wrapped; 0 where the roll is not defined: tool near vertical).
fn roll_offset(state: &NavState, sample: &ProbeSample) -> f64 {
    let levelling = crate::attitude::level(&sample.specific_force);
    if !levelling.roll_valid {
        return 0.0;
    }
    let roll = euler_from_quat(&state.attitude).roll;
    crate::conventions::wrap_pi(levelling.roll - roll)
}

#[cfg(test)]
#[path = "navigator_settings_tests.rs"]
mod settings_tests;

#[cfg(test)]
#[path = "navigator_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "navigator_slide_tests.rs"]
mod slide_tests;

#[cfg(test)]
#[path = "navigator_heading_tests.rs"]
mod heading_tests;
