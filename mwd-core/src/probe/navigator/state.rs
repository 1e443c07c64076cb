//! The navigator's state: the [`Navigator`] itself, its phases and a
//! station in progress, its constructors and settings (the still
//! detector's and the station's, the noise budget, the station links), and
//! what it tells about itself.

use super::commands::CommandState;
use super::readout::AttitudeReadout;
use crate::aid_sources::ForceBlock;
use crate::alignment::SegmentSums;
use crate::calibration::ProbeCalibration;
use crate::earth::{normal_gravity, Position};
use crate::error_model::{AugmentedModel, STATES_WITH_BIASES};
use crate::fine_alignment::{FineAlignment, FineAlignmentConfig};
use crate::kalman::FilterScalar;
use crate::mechanization::{ImuSample, NavState, ProbeInput};
use crate::probe::station_link::StationLink;
use crate::probe::still::{Hysteresis, StillDetector};
use crate::protocol::uplink::StillSettings;
use crate::protocol::StationSurvey;
use crate::sensor_noise::{ImuNoise, SCC1300_NOISE};
use nalgebra::UnitQuaternion;

/// The navigator's filter, 39 states, in scalar `T`: f32 on the probe
/// (the M4F's FPU is single precision; the host's replay takes f32 too, to
/// reproduce the probe bit for bit), f64 in the host's Monte Carlo
/// studies, where it is faster on x86 and gives the same figures.
pub(super) type Filter<T> = FineAlignment<T, STATES_WITH_BIASES>;

/// Zero-velocity update noise variance during a station, (m/s)^2: 1 cm/s,
/// ten times the fine alignment's 1 mm/s, for a string held in the slips
/// that may still sway and creep a little (the still detector cannot see a
/// steady creep: `crate::probe::still`).
pub const STATION_ZUPT_VARIANCE: f64 = 1e-4;

/// A station's zero-velocity update variance from the uplink's 1-sigma
/// (f32, m/s). The default's f32 stands for [`STATION_ZUPT_VARIANCE`]
/// itself (`still::widened_setting`: its square in f64 would not be the
/// constant to the bit).
pub(super) fn station_zupt_variance(sigma: f32) -> f64 {
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

/// The filter's settings for a still probe at `position` whose coarse
/// alignment has 1-sigma `coarse_sigma` (roll, pitch, heading; rad), with
/// the sensors' error budget `noise`.
pub(super) fn filter_config(
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

/// Where the navigator is: the three phases of the module's notes.
pub(super) enum Phase {
    /// Summing still samples.
    Coarse(SegmentSums),
    /// The filter with zero updates; `samples` taken so far.
    Fine { samples: u32 },
    /// The filter without zero updates, but for station surveys.
    Navigating,
}

/// A station in progress.
pub(super) struct Station {
    /// Zero-velocity updates so far.
    pub(super) epochs: u32,
    /// Sum of the still detector's largest normalised statistic.
    pub(super) quality_sum: f32,
    /// The survey as of the last still cycle.
    pub(super) survey: StationSurvey,
    /// The survey at the last multiple of
    /// [`SURVEY_SETTLE_EPOCHS`](super::SURVEY_SETTLE_EPOCHS) still cycles,
    /// and the one before it: what the station sends.
    pub(super) checkpoint: Option<StationSurvey>,
    pub(super) settled: Option<StationSurvey>,
    /// Their links to the previous station (`station_link`; `None` where
    /// the covariance was not valid).
    pub(super) link: Option<StationLink>,
    pub(super) checkpoint_link: Option<StationLink>,
    pub(super) settled_link: Option<StationLink>,
    /// Sums of the x and z gyros' readings over the block's still cycles
    /// for the rate gyrocompass (`aid_sources::EarthRate`).
    pub(super) gyro_sum: [f64; 2],
    /// Still cycles in those sums.
    pub(super) gyro_epochs: u32,
}

impl Station {
    /// The survey a station sends: the older of its last two checkpoints,
    /// or its last still cycle when it has fewer (`SURVEY_SETTLE_EPOCHS`).
    pub(super) fn to_send(&self) -> StationSurvey {
        self.settled.unwrap_or(self.survey)
    }
}

/// The probe's navigation, one raw sample at a time, with its filter in
/// scalar `T`: the probe's f32 unless told otherwise (see `Filter`).
pub struct Navigator<T: FilterScalar = f32> {
    pub(super) position: Position,
    pub(super) calibration: ProbeCalibration,
    /// The sensors' error budget the filter and the aiding sources model
    /// (default the SCC1300's; a reference, 4 bytes on the probe).
    pub(super) noise: &'static ImuNoise,
    pub(super) phase: Phase,
    /// Idle until the coarse alignment ends, then restarted in place from
    /// it: the filter is the probe's largest object (6 KiB of covariance),
    /// and every move of it would be another copy on the stack.
    pub(super) filter: Filter<T>,
    /// The mechanization's input (the tool-axis rate's estimator).
    pub(super) input: ProbeInput,
    /// 1-sigma of roll, pitch, heading from the coarse alignment (rad),
    /// reported until the filter has its own. An infinite heading sigma
    /// (no heading found) stays in the frames afterwards: the filter then
    /// runs from its best guess with its largest prior, but its small-angle
    /// azimuth sigma would not cover the error. A heading lost in
    /// navigation (its sigma past
    /// [`AZIMUTH_SIGMA_LIMIT_RAD`](super::AZIMUTH_SIGMA_LIMIT_RAD)) is set
    /// infinite here too, until the next tie-in (`note_heading_loss`).
    /// Set only through [`set_heading_source`](Self::set_heading_source).
    pub(super) coarse_std: [f32; 3],
    /// The heading was determined and then lost in navigation (its sigma
    /// past [`AZIMUTH_SIGMA_LIMIT_RAD`](super::AZIMUTH_SIGMA_LIMIT_RAD))
    /// since the last tie-in or alignment: the frames' and stations'
    /// `HEADING_LOST` bit.
    pub(super) heading_lost: bool,
    /// The last sample the filter took, held through a gap.
    pub(super) held: Option<ImuSample>,
    /// Samples missed in a row (the current gap).
    pub(super) missed: u32,
    /// Propagated through a gap and not aided since.
    pub(super) coasting: bool,
    /// The covariance failed its health check (latched until the next
    /// alignment: a covariance that lost its meaning does not regain it).
    pub(super) covariance_invalid: bool,
    /// A coarse-alignment sample came from one part: the heading cannot be
    /// gyrocompassed from these sums.
    pub(super) coarse_single_part: bool,
    pub(super) flags: u16,
    /// The still detector (navigation only).
    pub(super) still: StillDetector,
    pub(super) station: Option<Station>,
    /// Stations started since boot.
    pub(super) stations: u16,
    /// The current still period is no station any more: it reached
    /// `max_station_samples`, or its gyros saw the tool turn
    /// ([`EARTH_RATE_GATE`](super::EARTH_RATE_GATE)). No zero-velocity
    /// updates until the detector sees motion; the moving tool's
    /// constraints instead.
    pub(super) station_capped: bool,
    /// The longest station (samples; default [`MAX_STATION_SAMPLES`]).
    pub(super) max_station_samples: u32,
    /// A station's zero-velocity update noise variance, (m/s)^2 (default
    /// [`STATION_ZUPT_VARIANCE`]).
    pub(super) station_zupt_variance: f64,
    /// A finished station, until taken.
    pub(super) finished_station: Option<StationSurvey>,
    /// The link of the last station finished, and the station whose sent
    /// survey the filter's `station_link::PREVIOUS` snapshot is of.
    pub(super) finished_link: Option<StationLink>,
    pub(super) linked_station: u16,
    /// [`track_station_links`](Self::track_station_links).
    pub(super) station_links: bool,
    /// This still cycle's x and z gyro readings, for the rate gyrocompass
    /// (a zero-velocity cycle with both parts).
    pub(super) still_gyro: Option<[f64; 2]>,
    /// The last navigation cycle was still (its roll held).
    pub(super) was_still: bool,
    /// Consecutive drilling cycles up to this one.
    pub(super) drilling_cycles: u32,
    /// The turn about the tool axis (rad) in the last navigation cycle when
    /// it followed the accelerometer roll; `None` when the roll was held.
    pub(super) last_roll_turn: Option<f64>,
    /// The drilling samples' force since the last toolface update
    /// (`aid_sources::DrillingToolface`).
    pub(super) toolface_block: ForceBlock,
    /// The raw sample being processed.
    pub(super) time_us: u64,
    pub(super) sample_counter: u32,
    /// The surface's survey commands' state (`commands`).
    pub(super) commands: CommandState,
    /// The attitude's readout last made (`readout`).
    pub(super) readout: Option<AttitudeReadout>,
}

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
            was_still: false,
            drilling_cycles: 0,
            last_roll_turn: None,
            toolface_block: ForceBlock::default(),
            time_us: 0,
            sample_counter: 0,
            commands: CommandState::default(),
            readout: None,
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

    /// True while the probe corrects its samples with the identity (no
    /// calibration configured): its error budget is a calibrated part's,
    /// so every frame says its sigmas leave the parts' turn-on errors out
    /// (navigation and station bit 9).
    pub fn is_uncalibrated(&self) -> bool {
        self.calibration == ProbeCalibration::default()
    }
}

/// `v` squared (the navigator's files share it).
pub(super) fn square(v: f64) -> f64 {
    v * v
}
