//! Fault injection, in the spirit of smoltcp's fault injector: a plain
//! configuration struct the test (or the QEMU firmware) sets, with
//! deterministic pseudo-random chances, so every fault run repeats exactly.

/// How often a per-frame fault fires: always for the next `next_frames`
/// frames, then with probability `per_million` / 1e6 per frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Chance {
    pub next_frames: u32,
    pub per_million: u32,
}

impl Chance {
    pub const NEVER: Chance = Chance {
        next_frames: 0,
        per_million: 0,
    };

    /// The next `n` frames.
    pub const fn next(n: u32) -> Self {
        Self {
            next_frames: n,
            per_million: 0,
        }
    }

    /// A random share of frames.
    pub const fn per_million(p: u32) -> Self {
        Self {
            next_frames: 0,
            per_million: p,
        }
    }

    /// Decides for one frame (consumes a forced frame or one random draw).
    pub fn fires(&mut self, rng: &mut Rng) -> bool {
        if self.next_frames > 0 {
            self.next_frames -= 1;
            return true;
        }
        self.per_million > 0 && rng.below(1_000_000) < self.per_million
    }
}

/// What a dead chip select makes MISO read: the line floats to a pull-up or
/// a pull-down, and the part never sees the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeadLevel {
    Low,
    High,
}

/// Faults of one slave's SPI link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LinkFaults {
    /// Flip a parity bit the part sends (gyro: bit 0 of a word; accel: dPAR).
    pub miso_parity: Chance,
    /// Flip one random bit of the parity-protected MOSI words (gyro: both
    /// words; accelerometer: the command byte) before the part decodes
    /// them, so the part sees a parity error on its side.
    pub mosi_bit_flip: Chance,
    /// Flip one random bit of the MISO frame (line noise); on the
    /// accelerometer never dPAR, which `miso_parity` covers (see spi.rs).
    pub miso_bit_flip: Chance,
    /// Stuck MISO bits over the first 32 bits of a frame, first bit
    /// clocked out = bit 31 (gyro: status word in bits 31..16, data word in
    /// 15..0; accelerometer: status byte in bits 31..24). Forced to 1 / 0.
    pub miso_stuck_high: u32,
    pub miso_stuck_low: u32,
    /// The chip select is dead.
    pub dead: Option<DeadLevel>,
}

/// A time window in ns since power-up, `[start, end)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    pub start_ns: u64,
    pub end_ns: u64,
}

impl Window {
    pub fn contains(&self, t: u64) -> bool {
        self.start_ns <= t && t < self.end_ns
    }
}

/// The part's temperature forced to `degc` during `window` (both slaves'
/// temperature outputs; whole degrees are enough to cross the operating
/// range or clip the count: 200 degC reads as the count limit 8191).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TemperatureExcursion {
    pub window: Window,
    pub degc: i16,
}

/// Everything that can be injected into one part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Faults {
    pub gyro: LinkFaults,
    pub accel: LinkFaults,
    /// Gyro S_OK drops (LOOPF_OK stays set): a transient.
    pub s_ok_drop: Option<Window>,
    /// From this time the gyro's drive loop fails (S_OK and LOOPF_OK clear)
    /// until a soft reset. One-shot.
    pub loop_failure_at_ns: Option<u64>,
    /// The part power-cycles at this time (both slaves restart). One-shot.
    pub reset_at_ns: Option<u64>,
    /// Gyro output pinned at full scale.
    pub gyro_saturated: bool,
    /// Accelerometer SAT raised on every conversion.
    pub accel_saturated: bool,
    /// Accelerometer ST (self-test/checksum failure) raised.
    pub accel_self_test_failed: bool,
    /// The part runs hot or cold for a while.
    pub temperature: Option<TemperatureExcursion>,
}

/// xorshift32: tiny, deterministic, no_std; quality is plenty for fault dice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rng(u32);

impl Rng {
    pub const fn new(seed: u32) -> Self {
        Self(if seed == 0 { 0x9E37_79B9 } else { seed })
    }

    pub fn next_u32(&mut self) -> u32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        x
    }

    /// Uniform-ish in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: u32) -> u32 {
        self.next_u32().checked_rem(n).unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chance_forced_then_random() {
        let mut rng = Rng::new(1);
        let mut c = Chance::next(2);
        assert!(c.fires(&mut rng) && c.fires(&mut rng));
        assert!(!c.fires(&mut rng));
        let mut half = Chance::per_million(500_000);
        let hits = (0..10_000).filter(|_| half.fires(&mut rng)).count();
        assert!((4_500..5_500).contains(&hits), "{hits}");
        let mut never = Chance::NEVER;
        assert!(!never.fires(&mut rng));
    }

    #[test]
    fn rng_is_deterministic() {
        let mut a = Rng::new(42);
        let mut b = Rng::new(42);
        assert!((0..100).all(|_| a.next_u32() == b.next_u32()));
        assert_eq!(Rng::new(0).below(0), 0);
        assert!(Window {
            start_ns: 1,
            end_ns: 3
        }
        .contains(2));
        assert!(!Window {
            start_ns: 1,
            end_ns: 3
        }
        .contains(3));
    }
}
