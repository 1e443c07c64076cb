//! Where the simulated part's physical readings come from: any
//! [`SampleSource`] (in the part's own axes), e.g. a body-frame source seen
//! through a part's mounting ([`MountedSource`]), the built-in deterministic
//! [`Generator`], or recorded/simulated streams ([`SliceSource`]).

use mwd_core::sensor_units::{Mounting, STANDARD_GRAVITY_M_S2};

/// What one part senses, in its own axes and SI units.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PhysicalSample {
    /// Rate about the part's X axis (rad/s).
    pub rate_rad_s: f32,
    /// Specific force along the part's X, Y, Z (m/s^2).
    pub accel_m_s2: [f32; 3],
    pub temperature_degc: f32,
}

/// A part's readings as a function of time (ns since power-up).
pub trait SampleSource {
    fn sample(&mut self, time_ns: u64) -> PhysicalSample;
}

/// What the probe's body undergoes, in body axes (x right, y forward, z up).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodySample {
    pub rate_rad_s: [f32; 3],
    pub specific_force_m_s2: [f32; 3],
    pub temperature_degc: f32,
}

/// A body-frame motion as a function of time.
pub trait BodySource {
    fn body_sample(&mut self, time_ns: u64) -> BodySample;
}

/// A body source seen by one part through its mounting
/// (`mwd_core::sensor_units::PART_MOUNTINGS`).
#[derive(Debug, Clone)]
pub struct MountedSource<B> {
    pub body: B,
    pub mounting: Mounting,
}

impl<B: BodySource> SampleSource for MountedSource<B> {
    fn sample(&mut self, time_ns: u64) -> PhysicalSample {
        let b = self.body.body_sample(time_ns);
        PhysicalSample {
            rate_rad_s: self.mounting.gyro_rate_from_body(b.rate_rad_s),
            accel_m_s2: self.mounting.body_to_sensor(b.specific_force_m_s2),
            temperature_degc: b.temperature_degc,
        }
    }
}

/// The same reading at every instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Constant(pub PhysicalSample);

impl SampleSource for Constant {
    fn sample(&mut self, _time_ns: u64) -> PhysicalSample {
        self.0
    }
}

/// Recorded or simulated samples at a fixed period: sample `k` holds for
/// `k * period <= t < (k + 1) * period`; the last one holds afterwards.
#[derive(Debug, Clone)]
pub struct SliceSource<'a> {
    pub samples: &'a [PhysicalSample],
    pub period_ns: u64,
}

impl SampleSource for SliceSource<'_> {
    fn sample(&mut self, time_ns: u64) -> PhysicalSample {
        let k = time_ns.checked_div(self.period_ns).unwrap_or(0);
        let k = usize::try_from(k).unwrap_or(usize::MAX);
        self.samples
            .get(k)
            .or(self.samples.last())
            .copied()
            .unwrap_or_default()
    }
}

/// Deterministic body motion for the QEMU firmware and tests: the tool
/// rolls slowly about its axis (y) while a small wobble drives the x and z
/// rates, gravity turns with the roll, and the temperature creeps up. Pure
/// function of time (libm), identical on host and target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Generator {
    /// Roll rate about the tool axis (rad/s).
    pub roll_rate_rad_s: f32,
    /// Amplitude of the x/z wobble rate (rad/s) and its frequency (Hz).
    pub wobble_rad_s: f32,
    pub wobble_hz: f32,
    pub start_degc: f32,
    pub degc_per_s: f32,
}

impl Default for Generator {
    fn default() -> Self {
        Self {
            roll_rate_rad_s: 0.05,
            wobble_rad_s: 0.02,
            wobble_hz: 0.5,
            start_degc: 25.0,
            degc_per_s: 0.01,
        }
    }
}

impl BodySource for Generator {
    fn body_sample(&mut self, time_ns: u64) -> BodySample {
        // f64 for the time so that hours of run keep sub-microsecond steps.
        let t = time_ns as f64 * 1e-9;
        let roll = libm::fmod(f64::from(self.roll_rate_rad_s) * t, core::f64::consts::TAU) as f32;
        let phase = libm::fmod(f64::from(self.wobble_hz) * t, 1.0) as f32 * core::f32::consts::TAU;
        let wobble = self.wobble_rad_s * libm::sinf(phase);
        let g = STANDARD_GRAVITY_M_S2;
        BodySample {
            rate_rad_s: [wobble, self.roll_rate_rad_s, -wobble],
            // Tool horizontal, rolled by `roll` about y: gravity's reaction
            // moves from +z towards x.
            specific_force_m_s2: [g * libm::sinf(roll), 0.0, g * libm::cosf(roll)],
            temperature_degc: self.start_degc + self.degc_per_s * t as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::sensor_units::PART_MOUNTINGS;

    #[test]
    fn mounted_source_applies_the_mounting() {
        let mut part2 = MountedSource {
            body: Generator::default(),
            mounting: PART_MOUNTINGS[1],
        };
        let body = Generator::default().body_sample(3_000_000_000);
        let s = part2.sample(3_000_000_000);
        assert_eq!(s.rate_rad_s, body.rate_rad_s[2]);
        assert_eq!(s.accel_m_s2[0], body.specific_force_m_s2[2]);
        assert_eq!(s.accel_m_s2[2], -body.specific_force_m_s2[0]);
    }

    #[test]
    fn generator_is_deterministic_and_physical() {
        let mut a = Generator::default();
        let mut b = Generator::default();
        for t in [0u64, 1, 50_000_000, 3_600_000_000_000] {
            let s = a.body_sample(t);
            assert_eq!(s, b.body_sample(t));
            let f = s.specific_force_m_s2;
            let norm = libm::sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            assert!((norm - STANDARD_GRAVITY_M_S2).abs() < 1e-4);
        }
    }

    #[test]
    fn slice_source_holds_samples() {
        let samples = [
            PhysicalSample {
                rate_rad_s: 1.0,
                ..Default::default()
            },
            PhysicalSample {
                rate_rad_s: 2.0,
                ..Default::default()
            },
        ];
        let mut src = SliceSource {
            samples: &samples,
            period_ns: 10,
        };
        assert_eq!(src.sample(9).rate_rad_s, 1.0);
        assert_eq!(src.sample(10).rate_rad_s, 2.0);
        assert_eq!(src.sample(1000).rate_rad_s, 2.0);
        let mut empty = SliceSource {
            samples: &[],
            period_ns: 0,
        };
        assert_eq!(empty.sample(5), PhysicalSample::default());
    }
}
