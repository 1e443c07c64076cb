//! The state one SCC1300 part shares between its gyro and accelerometer
//! slaves: power-up time, start-up states, latched flags, injected faults.
//! The slaves' frame handling is in `gyro.rs` and `accel.rs`.

use crate::clock::TimeSource;
use crate::faults::{Faults, Rng};
use crate::source::{PhysicalSample, SampleSource};

/// Start-up time of both slaves after power-up or a gyro soft reset
/// [TN92 step 1: the host waits 800 ms].
pub const START_UP_NS: u64 = 800_000_000;
/// The values the mock's ID registers answer. UNVERIFIED on the real part
/// (`docs/scc1300.md`: ID and REVID unknown); the driver does not check them.
pub const MOCK_GYRO_IC_ID: u16 = 0x0130;
pub const MOCK_ACCEL_ID: u8 = 0x13;
pub const MOCK_ACCEL_REVID: u8 = 0x01;

/// Which frame's data the accelerometer's dPAR status bit covers. The spec
/// (`docs/scc1300.md`, "Accelerometer part") names the bit but not
/// its coverage, so the mock can model either; the driver's single switch
/// is `firmware::scc1300::datasheet::ACCEL_DPAR_SCOPE`, and the firmware
/// tests check that [`DEFAULT_DPAR_SCOPE`] agrees with it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DparScope {
    /// Odd parity over the data bytes of the previous accelerometer frame.
    PreviousFrame,
    /// Odd parity over the data bytes of the same frame.
    SameFrame,
}

/// UNVERIFIED: the dPAR coverage a new part models (keep it equal to the
/// driver's `datasheet::ACCEL_DPAR_SCOPE`).
pub const DEFAULT_DPAR_SCOPE: DparScope = DparScope::PreviousFrame;

/// What the mock has seen: lets tests prove that the driver built every
/// word's parity right (`mosi_parity_errors` stays 0 without injection).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MockStats {
    pub gyro_frames: u32,
    pub accel_frames: u32,
    /// Frames whose MOSI parity (or length) the part rejected.
    pub gyro_mosi_errors: u32,
    pub accel_mosi_errors: u32,
    pub soft_resets: u32,
    pub power_on_resets: u32,
    /// INT_STATUS reads (SAT acknowledgements).
    pub sat_acknowledged: u32,
    /// Accelerometer frames that read an output register (axes or
    /// temperature) within [`crate::ACCEL_SETTLE_NS`] of a CTRL write,
    /// i.e. before the outputs were valid: a driver that honours TN92's
    /// 10 ms wait keeps this at 0.
    pub accel_output_reads_while_settling: u32,
}

/// Gyro-side state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct GyroState {
    /// Power-up or last soft reset: start-up runs from here.
    pub started_ns: u64,
    /// STATUS latch: S_OK was seen low since the last STATUS read.
    pub latched_fault: bool,
    pub loop_failed: bool,
}

/// Accelerometer-side state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct AccelState {
    pub porst: bool,
    pub frame_error_pending: bool,
    pub sat_latched: bool,
    /// dPAR for the next status byte: parity of the last frame's data.
    pub next_dpar: bool,
    pub ctrl: u8,
    /// Outputs invalid until this time (set by a CTRL write).
    pub settle_until_ns: Option<u64>,
}

/// One simulated SCC1300. Share it between its two slaves by putting it in
/// a `RefCell` and handing `&RefCell` to [`crate::GyroSpi`] and
/// [`crate::AccelSpi`].
pub struct Scc1300<T, S> {
    pub(crate) time: T,
    pub(crate) source: S,
    /// The faults to inject; change them at any time.
    pub faults: Faults,
    /// What the accelerometer's dPAR bit covers (a model choice, see
    /// [`DparScope`]); [`DEFAULT_DPAR_SCOPE`] unless changed.
    pub dpar_scope: DparScope,
    pub(crate) rng: Rng,
    pub(crate) gyro: GyroState,
    pub(crate) accel: AccelState,
    pub(crate) stats: MockStats,
}

impl<T: TimeSource, S: SampleSource> Scc1300<T, S> {
    /// A part powered up at `time`'s current instant.
    pub fn new(time: T, source: S, seed: u32) -> Self {
        let now = time.now_ns();
        Self {
            time,
            source,
            faults: Faults::default(),
            dpar_scope: DEFAULT_DPAR_SCOPE,
            rng: Rng::new(seed),
            gyro: power_on_gyro(now),
            accel: power_on_accel(),
            stats: MockStats::default(),
        }
    }

    pub fn stats(&self) -> MockStats {
        self.stats
    }

    pub fn source_mut(&mut self) -> &mut S {
        &mut self.source
    }

    /// What the source says now (what a perfect driver would read).
    pub fn truth(&mut self) -> PhysicalSample {
        let now = self.time.now_ns();
        self.physics(now)
    }

    /// What the part senses at `now`: its source, with an injected
    /// temperature excursion applied.
    pub(crate) fn physics(&mut self, now: u64) -> PhysicalSample {
        let mut sample = self.source.sample(now);
        if let Some(excursion) = self.faults.temperature {
            if excursion.window.contains(now) {
                sample.temperature_degc = f32::from(excursion.degc);
            }
        }
        sample
    }

    /// Applies time-triggered faults; returns the current time.
    pub(crate) fn advance(&mut self) -> u64 {
        let now = self.time.now_ns();
        if self.faults.reset_at_ns.is_some_and(|t| now >= t) {
            self.faults.reset_at_ns = None;
            self.power_cycle(now);
        }
        if self.faults.loop_failure_at_ns.is_some_and(|t| now >= t) {
            self.faults.loop_failure_at_ns = None;
            self.gyro.loop_failed = true;
        }
        now
    }

    /// Both slaves restart as after power-up.
    pub fn power_cycle(&mut self, now: u64) {
        self.gyro = power_on_gyro(now);
        self.accel = power_on_accel();
        self.stats.power_on_resets += 1;
    }

    pub(crate) fn gyro_soft_reset(&mut self, now: u64) {
        self.gyro = power_on_gyro(now);
        self.stats.soft_resets += 1;
    }

    /// Start-up finished (gyro counted from its last soft reset).
    pub(crate) fn gyro_started(&self, now: u64) -> bool {
        now.saturating_sub(self.gyro.started_ns) >= START_UP_NS
    }

    /// LOOPF_OK: the drive loop runs (not during start-up, not failed).
    pub(crate) fn loop_ok(&self, now: u64) -> bool {
        self.gyro_started(now) && !self.gyro.loop_failed
    }

    /// S_OK right now.
    pub(crate) fn s_ok(&self, now: u64) -> bool {
        self.loop_ok(now) && !self.faults.s_ok_drop.is_some_and(|w| w.contains(now))
    }
}

fn power_on_gyro(now: u64) -> GyroState {
    GyroState {
        started_ns: now,
        latched_fault: true,
        loop_failed: false,
    }
}

fn power_on_accel() -> AccelState {
    AccelState {
        porst: true,
        frame_error_pending: false,
        sat_latched: false,
        // Odd parity over "no previous data".
        next_dpar: true,
        ctrl: 0,
        settle_until_ns: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clock::SimClock;
    use crate::faults::Window;
    use crate::source::Constant;

    #[test]
    fn walks_start_up_with_time_and_faults() {
        let clock = SimClock::new();
        let mut part = Scc1300::new(&clock, Constant::default(), 1);
        let now = part.advance();
        assert!(!part.s_ok(now));
        clock.advance_ms(800);
        let now = part.advance();
        assert!(part.s_ok(now) && part.loop_ok(now));
        part.faults.s_ok_drop = Some(Window {
            start_ns: now,
            end_ns: now + 10,
        });
        assert!(!part.s_ok(now));
        assert!(part.loop_ok(now));
        part.faults.loop_failure_at_ns = Some(now + 100);
        clock.advance_ns(100);
        let now = part.advance();
        assert!(!part.loop_ok(now));
        part.gyro_soft_reset(now);
        clock.advance_ms(800);
        let now = part.advance();
        assert!(part.loop_ok(now));
        part.faults.reset_at_ns = Some(0);
        let now = part.advance();
        assert!(!part.s_ok(now));
        assert!(part.accel.porst);
        assert_eq!(part.stats().power_on_resets, 1);
        assert_eq!(part.stats().soft_resets, 1);
    }
}
