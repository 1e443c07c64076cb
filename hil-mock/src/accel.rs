//! The accelerometer slave's frames [TN92]: MOSI byte 1 = `A5..A0, RW, P`
//! (odd parity), then data; MISO byte 1 = status
//! `[-, FRME, PORST, ST, SAT, 0, 1, dPAR]`, then the in-frame data, read
//! registers decrementing from the address (burst).
//!
//! The status byte is the state before this frame's command takes effect;
//! FRME speaks about the previous frame [spec, "Accelerometer part": FRME
//! flags an error in it]. dPAR is the odd-parity bit over the data bytes of the
//! previous frame or of this frame, as [`Scc1300::dpar_scope`] says: the spec
//! does not tell which (see [`DparScope`] and the driver's
//! `datasheet::ACCEL_DPAR_SCOPE`).
//!
//! Start-up [TN92 step 3: "write CTRL = 0x00 (clears PORST), wait 10 ms"]:
//! a CTRL write clears PORST and starts [`ACCEL_SETTLE_NS`] of settling,
//! during which the output registers (axes, temperature) read 0 with no
//! status bit to say so (what the real part shows then is unknown); every
//! frame that reads them early is counted in
//! [`crate::MockStats::accel_output_reads_while_settling`].

use mwd_core::sensor_units::{self, ACCEL_RANGE_G, ACCEL_TEMPERATURE, STANDARD_GRAVITY_M_S2};

use crate::clock::TimeSource;
use crate::part::{DparScope, Scc1300, MOCK_ACCEL_ID, MOCK_ACCEL_REVID};
use crate::source::SampleSource;

const FRME: u8 = 1 << 6;
const PORST: u8 = 1 << 5;
const ST: u8 = 1 << 4;
const SAT: u8 = 1 << 3;
const FIXED: u8 = 1 << 1;
const DPAR: u8 = 1 << 0;

const REVID: u8 = 0x00;
const CTRL: u8 = 0x01;
const X_LSB: u8 = 0x04;
const TEMP_LSB: u8 = 0x12;
const TEMP_MSB: u8 = 0x13;
const INT_STATUS: u8 = 0x16;
const ID: u8 = 0x27;

/// Settling of the accelerometer after a CTRL write, before its outputs are
/// valid: the 10 ms TN92 step 3 waits after CTRL = 0x00 (spec "Start-up and
/// supervision", item 3).
pub const ACCEL_SETTLE_NS: u64 = 10_000_000;

/// The output registers at the instant of a frame.
struct Outputs {
    axes: [u16; 3],
    temp: u16,
}

/// Odd-parity bit over bytes.
pub(crate) fn odd_parity_bit(bytes: &[u8]) -> bool {
    bytes.iter().map(|b| b.count_ones()).sum::<u32>() % 2 == 0
}

/// One accelerometer frame: `mosi` as received, `miso` filled (same length).
pub(crate) fn frame<T: TimeSource, S: SampleSource>(
    part: &mut Scc1300<T, S>,
    mosi: &[u8],
    miso: &mut [u8],
) {
    let now = part.advance();
    part.stats.accel_frames += 1;
    let sample = part.physics(now);
    let limit = ACCEL_RANGE_G * STANDARD_GRAVITY_M_S2;
    if part.faults.accel_saturated || sample.accel_m_s2.iter().any(|a| a.abs() > limit) {
        part.accel.sat_latched = true;
    }
    let settling = part.accel.settle_until_ns.is_some_and(|t| now < t);
    let outputs = if settling {
        Outputs {
            axes: [0; 3],
            temp: 0,
        }
    } else {
        Outputs {
            axes: sample
                .accel_m_s2
                .map(|a| sensor_units::count_to_word(sensor_units::m_s2_to_accel_count(a))),
            temp: sensor_units::count_to_word(
                ACCEL_TEMPERATURE.degc_to_count(sample.temperature_degc),
            ),
        }
    };
    let st = &part.accel;
    let mut status = FIXED;
    for (on, bit) in [
        (st.frame_error_pending, FRME),
        (st.porst, PORST),
        (part.faults.accel_self_test_failed, ST),
        (st.sat_latched, SAT),
    ] {
        if on {
            status |= bit;
        }
    }
    let (status_out, data_out) = match miso.split_first_mut() {
        Some(split) => split,
        None => return,
    };
    part.accel.frame_error_pending = false;
    let accepted = match mosi.split_first() {
        Some((cmd, tx)) if cmd.count_ones() % 2 == 1 => {
            execute(part, now, *cmd, tx, data_out, &outputs, settling);
            true
        }
        _ => false,
    };
    if !accepted {
        data_out.fill(0);
        part.accel.frame_error_pending = true;
        part.stats.accel_mosi_errors += 1;
    }
    let this_frame = odd_parity_bit(data_out);
    let dpar = match part.dpar_scope {
        DparScope::PreviousFrame => {
            let previous = part.accel.next_dpar;
            part.accel.next_dpar = this_frame;
            previous
        }
        DparScope::SameFrame => this_frame,
    };
    if dpar {
        status |= DPAR;
    }
    *status_out = status;
}

fn execute<T: TimeSource, S: SampleSource>(
    part: &mut Scc1300<T, S>,
    now: u64,
    cmd: u8,
    tx: &[u8],
    data_out: &mut [u8],
    outputs: &Outputs,
    settling: bool,
) {
    let addr = cmd >> 2;
    if cmd & (1 << 1) != 0 {
        if let (CTRL, Some(value)) = (addr, tx.first()) {
            part.accel.ctrl = *value;
            // Writing CTRL clears PORST [TN92 step 3], and the outputs
            // settle for the 10 ms TN92 waits next.
            part.accel.porst = false;
            part.accel.settle_until_ns = Some(now.saturating_add(ACCEL_SETTLE_NS));
        }
        data_out.fill(0);
        return;
    }
    let mut reg = addr;
    let mut early = false;
    for out in data_out.iter_mut() {
        early |= settling && is_output(reg);
        *out = register(part, reg, outputs);
        reg = reg.wrapping_sub(1) & 0x3F;
    }
    if early {
        part.stats.accel_output_reads_while_settling += 1;
    }
}

/// The registers that hold measurements (axes and temperature).
fn is_output(reg: u8) -> bool {
    matches!(reg, X_LSB..=0x09 | TEMP_LSB | TEMP_MSB)
}

fn register<T: TimeSource, S: SampleSource>(
    part: &mut Scc1300<T, S>,
    reg: u8,
    outputs: &Outputs,
) -> u8 {
    let half = |word: u16, msb: bool| word.to_be_bytes()[usize::from(!msb)];
    match reg {
        X_LSB..=0x09 => {
            let axis = usize::from((reg - X_LSB) / 2);
            let msb = (reg - X_LSB) % 2 == 1;
            outputs.axes.get(axis).map_or(0, |w| half(*w, msb))
        }
        TEMP_LSB => half(outputs.temp, false),
        TEMP_MSB => half(outputs.temp, true),
        INT_STATUS => {
            // Reading INT_STATUS acknowledges SAT (SCA3100 behaviour, spec).
            let was = u8::from(part.accel.sat_latched);
            part.accel.sat_latched = false;
            part.stats.sat_acknowledged += 1;
            was
        }
        CTRL => part.accel.ctrl,
        REVID => MOCK_ACCEL_REVID,
        ID => MOCK_ACCEL_ID,
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clock::SimClock;
    use crate::source::{Constant, PhysicalSample};

    fn part(clock: &SimClock, accel: [f32; 3]) -> Scc1300<&SimClock, Constant> {
        let truth = PhysicalSample {
            accel_m_s2: accel,
            ..Default::default()
        };
        Scc1300::new(clock, Constant(truth), 3)
    }

    #[test]
    fn burst_from_z_msb_and_delayed_parity() {
        let clock = SimClock::new();
        let g = STANDARD_GRAVITY_M_S2;
        let mut p = part(&clock, [g, -g, 0.0]);
        let mut miso = [0u8; 2];
        frame(&mut p, &[0x07, 0x00], &mut miso); // CTRL = 0
        assert_eq!(miso[0], PORST | FIXED | DPAR, "power-up status");
        clock.advance_ns(ACCEL_SETTLE_NS);
        let mut burst = [0u8; 7];
        frame(&mut p, &[0x25, 0, 0, 0, 0, 0, 0], &mut burst);
        // No PORST any more; dPAR = parity of the CTRL frame's data (0x00).
        assert_eq!(burst[0], FIXED | DPAR);
        // Z = 0; Y = -650 = 0xF5D8; X = 650 = 0x0A28 (left-aligned).
        assert_eq!(&burst[1..], &[0x00, 0x00, 0xF5, 0xD8, 0x0A, 0x28]);
        frame(&mut p, &[0x08, 0], &mut miso);
        let dpar = u8::from(odd_parity_bit(&burst[1..]));
        assert_eq!(miso[0], FIXED | dpar);
        assert_eq!(p.stats().accel_mosi_errors, 0);
        assert_eq!(p.stats().accel_output_reads_while_settling, 0);
    }

    #[test]
    fn same_frame_parity_covers_the_frame_it_is_in() {
        let clock = SimClock::new();
        let g = STANDARD_GRAVITY_M_S2;
        let mut p = part(&clock, [g, -g, 0.0]);
        p.dpar_scope = DparScope::SameFrame;
        let mut miso = [0u8; 2];
        frame(&mut p, &[0x07, 0x00], &mut miso); // CTRL = 0: data 0x00
        assert_eq!(miso[0], PORST | FIXED | DPAR);
        clock.advance_ns(ACCEL_SETTLE_NS);
        let mut burst = [0u8; 7];
        frame(&mut p, &[0x25, 0, 0, 0, 0, 0, 0], &mut burst);
        assert_eq!(&burst[1..], &[0x00, 0x00, 0xF5, 0xD8, 0x0A, 0x28]);
        // 0xF5D8 and 0x0A28 hold 10 + 4 ones: even, so dPAR = 1.
        assert_eq!(burst[0], FIXED | u8::from(odd_parity_bit(&burst[1..])));
        assert_eq!(burst[0], FIXED | DPAR);
        // REVID 0x01: one 1, odd, so dPAR = 0 in this very frame, whatever
        // the burst before held.
        frame(&mut p, &[0x01, 0], &mut miso);
        assert_eq!(miso, [FIXED, MOCK_ACCEL_REVID]);
    }

    #[test]
    fn outputs_settle_for_10_ms_after_ctrl() {
        let clock = SimClock::new();
        let g = STANDARD_GRAVITY_M_S2;
        let mut p = part(&clock, [g, 0.0, 0.0]);
        let mut burst = [0u8; 7];
        // Before any CTRL write the outputs run (PORST tells the driver).
        frame(&mut p, &[0x25, 0, 0, 0, 0, 0, 0], &mut burst);
        assert_eq!(&burst[5..], &[0x0A, 0x28]);
        let mut miso = [0u8; 2];
        frame(&mut p, &[0x07, 0x00], &mut miso); // CTRL = 0
        clock.advance_ns(ACCEL_SETTLE_NS - 1);
        frame(&mut p, &[0x25, 0, 0, 0, 0, 0, 0], &mut burst);
        assert_eq!(&burst[1..], &[0; 6], "not settled yet");
        assert_eq!(burst[0] & PORST, 0, "no status bit tells");
        // Registers other than the outputs are not counted.
        frame(&mut p, &[0x08, 0], &mut miso);
        assert_eq!(p.stats().accel_output_reads_while_settling, 1);
        clock.advance_ns(1);
        frame(&mut p, &[0x25, 0, 0, 0, 0, 0, 0], &mut burst);
        assert_eq!(&burst[5..], &[0x0A, 0x28]);
        assert_eq!(p.stats().accel_output_reads_while_settling, 1);
    }

    #[test]
    fn saturation_latches_until_int_status_and_bad_parity_sets_frme() {
        let clock = SimClock::new();
        let mut p = part(&clock, [0.0, 0.0, 7.0 * STANDARD_GRAVITY_M_S2]);
        let mut miso = [0u8; 2];
        frame(&mut p, &[0x58, 0], &mut miso);
        assert_ne!(miso[0] & SAT, 0);
        assert_eq!(miso[1], 1, "INT_STATUS shows what it acknowledges");
        p.source_mut().0.accel_m_s2 = [0.0; 3];
        frame(&mut p, &[0x58, 0], &mut miso);
        assert_eq!(miso[0] & SAT, 0, "cleared by the previous INT_STATUS read");
        frame(&mut p, &[0x24, 0], &mut miso); // even parity
        assert_eq!(p.stats().accel_mosi_errors, 1);
        frame(&mut p, &[0x08, 0], &mut miso);
        assert_ne!(miso[0] & FRME, 0);
    }
}
