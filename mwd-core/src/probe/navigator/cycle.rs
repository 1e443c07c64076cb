//! One cycle: the navigator's entry points (through [`NavigatorScalar`],
//! compiled in this crate), a raw sample's calibration, its way to the
//! phase the navigator is in, and a gap's coasting (module docs of
//! `navigator`: what the frames say).

use super::commands::Refusal;
use super::frame::VARIANCE_LIMIT;
use super::state::{square, Navigator, Phase};
use crate::conventions::DEG;
use crate::fine_alignment::StepNoise;
use crate::kalman::FilterScalar;
use crate::mechanization::ProbeInput;
use crate::probe::raw::{reading, Reading};
use crate::probe::tie_in::TieIn;
use crate::probe_sample::{ProbeSample, GYRO_AXES};
use crate::protocol::frame::nav_flags;
use crate::protocol::{NavSolution, RawSample};
use crate::timing::SAMPLE_INTERVAL_S;

/// The rate (rad/s) a sample the probe did not measure may be off by: a
/// gap's held rate, or the missing gyro's stand-in in single-part mode.
/// 1 deg/s: the rate changes of a still or slowly turning tool over the
/// ~1-2 s a driver recovery takes; its variance goes into the attitude
/// process noise (docs/filter-derivation.md, "Sensor gaps").
pub const UNMEASURED_RATE_SIGMA: f64 = 1.0 * DEG;

/// The specific force (m/s^2) a held sample may be off by: 0.1 m/s^2,
/// about 10 mg, ten times the accelerometers' per-sample noise.
pub const UNMEASURED_FORCE_SIGMA: f64 = 0.1;

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
    /// (`crate::probe::tie_in`, derivation section 4c).
    ///
    /// A probe that has levelled itself (navigating: called between steps
    /// as soon as [`is_navigating`](Self::is_navigating) first returns true)
    /// keeps its filter: the azimuth is replaced by the tie-in's (a turn
    /// about the vertical; the heading error is then the tie-in's alone),
    /// and the tie-in's inclination and toolface are fused with its own
    /// levelling as measurements
    /// ([`TieInTilt`](crate::probe::tie_in::TieInTilt)), so the levelled tilt keeps
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

impl<T: FilterScalar> Navigator<T> {
    pub(super) fn step_raw(&mut self, raw: &RawSample) -> NavSolution {
        let reading = reading(raw, &self.calibration);
        self.step_reading(raw.time_us, raw.sample_counter, reading)
    }

    pub(super) fn step_calibrated(
        &mut self,
        time_us: u64,
        sample_counter: u32,
        sample: &ProbeSample,
    ) -> NavSolution {
        self.step_reading(time_us, sample_counter, Reading::Both(*sample))
    }

    fn step_reading(&mut self, time_us: u64, sample_counter: u32, reading: Reading) -> NavSolution {
        self.flags = if self.is_uncalibrated() {
            nav_flags::UNCALIBRATED
        } else {
            0
        };
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
        let readout = self.solution_readout();
        if let Some(readout) = readout.filter(|_| !self.covariance_invalid) {
            self.note_heading_loss(readout.euler_std().z);
        }
        self.solution(time_us, sample_counter, readout)
    }

    /// `sample`, with the gyro of index `missing_gyro` (in `GYRO_AXES`)
    /// out when one part is, through the phase the navigator is in.
    /// Returns, when navigating, whether the probe was still (a
    /// zero-velocity update was made).
    fn use_sample(&mut self, sample: &ProbeSample, missing_gyro: Option<usize>) -> Option<bool> {
        let mut sample = *sample;
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
        let extra = self.stand_in_missing_gyro(&mut sample, missing_gyro);
        match self.phase {
            Phase::Coarse(_) => {
                self.coarse_sample(&sample, missing_gyro.is_some());
                None
            }
            Phase::Fine { .. } => {
                self.fine_sample(&sample, &extra);
                None
            }
            Phase::Navigating => Some(self.navigation_sample(&sample, missing_gyro, still, extra)),
        }
    }

    /// The missing gyro's stand-in, put in `sample`: the rate of a tool
    /// turning with the navigation frame (a still tool), uncertain by
    /// `UNMEASURED_RATE_SIGMA` each step. Returns the step's extra noise
    /// (none with both parts).
    fn stand_in_missing_gyro(
        &mut self,
        sample: &mut ProbeSample,
        missing_gyro: Option<usize>,
    ) -> StepNoise {
        match missing_gyro {
            None => StepNoise::NONE,
            Some(k) => {
                let frame_rate = self.filter.frame_rate_in_body();
                sample.gyro[k] = frame_rate[GYRO_AXES[k]];
                StepNoise {
                    attitude: square(UNMEASURED_RATE_SIGMA * SAMPLE_INTERVAL_S),
                    velocity: 0.0,
                    skip_updates: false,
                }
            }
        }
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
}
