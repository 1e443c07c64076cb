//! The probe's clock: one sample every 50 ms (20 Hz, the paper's rate),
//! and how its navigation phases are counted in samples.

/// Sample period of the probe (us): 20 Hz.
pub const SAMPLE_PERIOD_US: u64 = 50_000;
/// Sample interval of the probe (s), the same 50 ms.
pub const SAMPLE_INTERVAL_S: f64 = SAMPLE_PERIOD_US as f64 / 1e6;
/// Samples per second.
pub const SAMPLE_RATE_HZ: f64 = 1e6 / SAMPLE_PERIOD_US as f64;
/// Still samples averaged for the coarse alignment: 5 s, as in the paper.
pub const ALIGNMENT_SAMPLES: u32 = 100;
/// Samples of fine alignment after the coarse one: to 60 s in all, the
/// paper's static test.
pub const FINE_ALIGNMENT_SAMPLES: u32 = 1100;

/// The time stamp of sample `n` (us): sample 0 is taken at time 0.
pub const fn sample_time_us(n: u32) -> u64 {
    n as u64 * SAMPLE_PERIOD_US
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_interval_is_fifty_milliseconds_exactly() {
        // The filter's dt was the literal 0.05 before it was derived here;
        // the probe's replay parity needs the very same bits.
        assert_eq!(SAMPLE_INTERVAL_S, 0.05);
        assert_eq!(SAMPLE_RATE_HZ, 20.0);
        assert_eq!(sample_time_us(3), 150_000);
    }
}
