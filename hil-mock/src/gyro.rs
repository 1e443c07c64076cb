//! The gyro slave's frames [TN92]: 32 bits with CSB_G low, MOSI
//! `cmd, data` and MISO `status, data`, odd parity in bit 0 of every word.
//! The answer is in-frame: word 2 carries the register that word 1 named,
//! which the part has decoded by the time word 2 is clocked out.

use mwd_core::sensor_units::{self, COUNT_MAX, GYRO_TEMPERATURE};

use crate::clock::TimeSource;
use crate::part::{Scc1300, MOCK_GYRO_IC_ID};
use crate::source::SampleSource;

const RATE_X: u16 = 0x00;
const IC_ID: u16 = 0x07;
const STATUS: u16 = 0x08;
const TEMP: u16 = 0x0A;
const S_OK: u16 = 1 << 1;
const LOOPF_OK: u16 = 1 << 2;
/// Data bit 1 written to IC_ID soft-resets the gyro.
const SOFT_RESET: u16 = 1 << 1;

/// Sets bit 0 so the word has odd parity.
pub(crate) fn with_odd_parity(word: u16) -> u16 {
    let word = word & !1;
    if word.count_ones() % 2 == 0 {
        word | 1
    } else {
        word
    }
}

/// One gyro frame: `mosi` as the part received it, `miso` filled with the
/// part's answer (same length).
pub(crate) fn frame<T: TimeSource, S: SampleSource>(
    part: &mut Scc1300<T, S>,
    mosi: &[u8],
    miso: &mut [u8],
) {
    let now = part.advance();
    part.stats.gyro_frames += 1;
    let s_ok = part.s_ok(now);
    if !s_ok {
        part.gyro.latched_fault = true;
    }
    let status = with_odd_parity(if s_ok { S_OK } else { 0 });
    let data = match mosi {
        [c1, c0, d1, d0] => {
            let cmd = u16::from_be_bytes([*c1, *c0]);
            let word2 = u16::from_be_bytes([*d1, *d0]);
            answer(part, now, cmd, word2)
        }
        _ => None,
    };
    let data = data.unwrap_or_else(|| {
        // A frame the part rejects (parity, length): it answers an all-zero
        // word, whose even parity tells the master.
        part.stats.gyro_mosi_errors += 1;
        0
    });
    let answer = [status.to_be_bytes(), data.to_be_bytes()];
    for (out, byte) in miso.iter_mut().zip(answer.iter().flatten()) {
        *out = *byte;
    }
}

/// Decodes a command; `None` when its parity is wrong.
fn answer<T: TimeSource, S: SampleSource>(
    part: &mut Scc1300<T, S>,
    now: u64,
    cmd: u16,
    word2: u16,
) -> Option<u16> {
    if cmd.count_ones() % 2 == 0 || word2.count_ones() % 2 == 0 {
        return None;
    }
    let addr = cmd >> 3;
    let write = cmd & (1 << 2) != 0;
    if write {
        if addr == IC_ID && (word2 >> 1) & SOFT_RESET != 0 {
            part.gyro_soft_reset(now);
        }
        return Some(with_odd_parity(0));
    }
    let value = match addr {
        RATE_X => {
            let count = if part.faults.gyro_saturated {
                COUNT_MAX
            } else {
                sensor_units::rad_s_to_gyro_count(part.physics(now).rate_rad_s)
            };
            sensor_units::count_to_word(count)
        }
        TEMP => {
            let t = part.physics(now).temperature_degc;
            sensor_units::count_to_word(GYRO_TEMPERATURE.degc_to_count(t))
        }
        STATUS => {
            // Latched: reports a fault seen since the last read, then
            // clears to the live state [TN92 step 2: read twice].
            let live = part.s_ok(now);
            let s_ok = live && !part.gyro.latched_fault;
            part.gyro.latched_fault = !live;
            let loop_ok = part.loop_ok(now);
            (if s_ok { S_OK } else { 0 }) | (if loop_ok { LOOPF_OK } else { 0 })
        }
        IC_ID => MOCK_GYRO_IC_ID << 1,
        _ => 0,
    };
    Some(with_odd_parity(value))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clock::SimClock;
    use crate::source::{Constant, PhysicalSample};

    fn part(clock: &SimClock) -> Scc1300<&SimClock, Constant> {
        let truth = PhysicalSample {
            rate_rad_s: 1.0f32.to_radians(),
            accel_m_s2: [0.0; 3],
            temperature_degc: 0.0,
        };
        Scc1300::new(clock, Constant(truth), 7)
    }

    fn exchange(p: &mut Scc1300<&SimClock, Constant>, mosi: [u8; 4]) -> [u16; 2] {
        let mut miso = [0u8; 4];
        frame(p, &mosi, &mut miso);
        [
            u16::from_be_bytes([miso[0], miso[1]]),
            u16::from_be_bytes([miso[2], miso[3]]),
        ]
    }

    #[test]
    fn answers_rate_status_and_temperature_with_odd_parity() {
        let clock = SimClock::new();
        let mut p = part(&clock);
        // During start-up: S_OK clear, STATUS latched.
        assert_eq!(exchange(&mut p, [0, 0x40, 0, 1]), [0x0001, 0x0001]);
        clock.advance_ms(800);
        // First STATUS read after start-up still shows the latch; LOOPF_OK set.
        assert_eq!(exchange(&mut p, [0, 0x40, 0, 1]), [0x0002, 0x0004]);
        assert_eq!(exchange(&mut p, [0, 0x40, 0, 1]), [0x0002, 0x0007]);
        // 1 deg/s = 18 counts = 0x0048, two ones -> P = 1.
        assert_eq!(exchange(&mut p, [0, 0x01, 0, 1]), [0x0002, 0x0049]);
        // 0 degC = count -3250 = 0xCD38 left-aligned.
        let temp = exchange(&mut p, [0, 0x51, 0, 1])[1];
        assert_eq!(temp & !1, 0xCD38);
        assert_eq!(p.stats().gyro_mosi_errors, 0);
    }

    #[test]
    fn a_temperature_excursion_clips_the_count_during_its_window() {
        use crate::faults::{TemperatureExcursion, Window};
        let clock = SimClock::new();
        let mut p = part(&clock);
        clock.advance_ms(800);
        p.faults.temperature = Some(TemperatureExcursion {
            window: Window {
                start_ns: 900_000_000,
                end_ns: 1_000_000_000,
            },
            degc: 200,
        });
        let temp = |p: &mut Scc1300<&SimClock, Constant>| {
            sensor_units::word_to_count(exchange(p, [0, 0x51, 0, 1])[1])
        };
        assert_eq!(temp(&mut p), -3250, "0 degC before the window");
        clock.advance_ms(100);
        // 200 degC is count 9750, beyond the 14-bit limit.
        assert_eq!(temp(&mut p), sensor_units::COUNT_MAX);
        assert_eq!(p.truth().temperature_degc, 200.0);
        clock.advance_ms(100);
        assert_eq!(temp(&mut p), -3250, "back after it");
    }

    #[test]
    fn rejects_bad_parity_and_soft_resets() {
        let clock = SimClock::new();
        let mut p = part(&clock);
        clock.advance_ms(800);
        assert_eq!(exchange(&mut p, [0, 0x00, 0, 1])[1], 0);
        assert_eq!(p.stats().gyro_mosi_errors, 1);
        exchange(&mut p, [0, 0x3D, 0, 0x04]);
        assert_eq!(p.stats().soft_resets, 1);
        assert_eq!(exchange(&mut p, [0, 0x01, 0, 1])[0], 0x0001, "restarting");
    }
}
