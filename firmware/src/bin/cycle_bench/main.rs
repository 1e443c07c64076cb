//! One 20 Hz filter cycle (mechanization, time update, ZUPT and
//! zero-position updates, feedback) counted in SysTick ticks on QEMU's
//! mps2-an386 with `-icount shift=0`, fast vs dense, f32 vs f64, 33 states
//! and (fast f32) 39 states with the sensor biases; and one survey
//! station's minimum-curvature step (f64, docs/survey-benchmarks.md).
//!
//! Under `-icount shift=0` every instruction advances virtual time by 1 ns;
//! SysTick runs from the 25 MHz board clock, so it ticks every 40
//! instructions. The loop calibration below measures that ratio instead of
//! trusting it.
//!
//! Run it with `scripts/qemu-cycle-bench.sh` (feature `qemu-cycle-bench`,
//! profile `cycle-bench`); the figures are in docs/filter-benchmarks.md.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use core::panic::PanicInfo;
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use mwd_core::conventions::{dcm_from_quat, quat_from_euler, Euler};
use mwd_core::earth::{earth_rate_n, gravity_n, LocalEarth, Position};
use mwd_core::error_model::{
    AugmentedModel, LinearizationPoint, ProcessNoise, POS, STATES, STATES_WITH_BIASES, VEL,
};
use mwd_core::fine_alignment::{FineAlignment, FineAlignmentConfig};
use mwd_core::kalman::{dense, FilterScalar};
use mwd_core::mechanization::{ImuSample, NavState, Strapdown};
use mwd_core::survey::{Segment, TrueStation};
use nalgebra::{SMatrix, SVector, Vector3};

const RELOAD: u32 = 0x00ff_ffff;
const CYCLES: u32 = 10;

fn ticks(start: u32) -> u32 {
    // SysTick counts down and wraps at RELOAD; runs here stay well below.
    start.wrapping_sub(SYST::get_current()) & RELOAD
}

fn setup() -> (NavState, ImuSample) {
    let state = NavState::at_rest(
        quat_from_euler(&Euler::new(-0.014, 0.0094, -2.635)),
        Position::paper_site(),
    );
    let c_nb = dcm_from_quat(&state.attitude).transpose();
    let sample = ImuSample {
        rate: c_nb * earth_rate_n(state.position.lat) + Vector3::new(1e-5, -2e-5, 3e-5),
        specific_force: c_nb * -gravity_n(&state.position) + Vector3::new(1e-3, 2e-3, -1e-3),
    };
    (state, sample)
}

/// The error model linearised at the strapdown's solution `s`, with the
/// sample's measured specific force (as the fast cycle's filter does).
/// Inlined, so that the measured loops compile as when it was written out
/// in each (the figures in docs/filter-benchmarks.md stay comparable).
#[inline(always)]
fn linearization_point(s: &NavState, sample: &ImuSample) -> LinearizationPoint {
    let c_bn = s.attitude.to_rotation_matrix().into_inner();
    LinearizationPoint {
        c_bn,
        velocity_n: s.velocity,
        position: s.position,
        specific_force_n: c_bn * sample.specific_force,
    }
}

fn fast<T: FilterScalar, const N: usize>() -> u32 {
    let (state, sample) = setup();
    let mut fa = FineAlignment::<T, N>::new(
        state,
        state.position,
        FineAlignmentConfig::paper(AugmentedModel::paper()),
    );
    fa.step(&sample);
    let start = SYST::get_current();
    for _ in 0..CYCLES {
        core::hint::black_box(fa.step(core::hint::black_box(&sample)));
    }
    ticks(start) / CYCLES
}

fn dense_cycle<T: FilterScalar>() -> u32 {
    let (state, sample) = setup();
    let model = AugmentedModel::paper();
    let mut sd = Strapdown::new(state, model.dt);
    let mut x = SVector::<T, STATES>::zeros();
    let mut p = SMatrix::<T, STATES, STATES>::identity() * T::of(0.01);
    let q = SMatrix::from_diagonal(&model.process_noise::<T, STATES>(&ProcessNoise {
        nav_per_step: [1e-6; 9],
    }));
    let mut h = SMatrix::<T, 6, STATES>::zeros();
    for i in 0..3 {
        h[(i, VEL + i)] = T::one();
        h[(3 + i, POS + i)] = T::one();
    }
    let r = SMatrix::<T, 6, 6>::identity() * T::of(0.1);
    // Geodetic terms cached as in the fast cycle: compare filters, not caches.
    let earth = LocalEarth::at(&state.position);
    let start = SYST::get_current();
    for _ in 0..CYCLES {
        sd.step(core::hint::black_box(&sample));
        let s = *sd.state();
        let lp = linearization_point(&s, &sample);
        let phi = model.transition_with::<T, STATES>(&earth, &lp).to_dense();
        dense::predict(&mut x, &mut p, &phi, &q);
        let dp = s.position.ned_from(&state.position);
        let z =
            SVector::<T, 6>::from_fn(|i, _| T::of(if i < 3 { s.velocity[i] } else { dp[i - 3] }));
        dense::update(&mut x, &mut p, &z, &h, &r);
        let v = |i: usize| Vector3::new(x[i].as_f64(), x[i + 1].as_f64(), x[i + 2].as_f64());
        sd.apply_correction(&v(0), &v(3), &v(6));
        x.fixed_rows_mut::<9>(0).fill(T::zero());
    }
    core::hint::black_box(&p);
    ticks(start) / CYCLES
}

/// The fast cycle's parts, to see where the instructions go.
fn parts<T: FilterScalar, const N: usize>() -> [(&'static str, u32); 5] {
    let (state, sample) = setup();
    let model = AugmentedModel::paper();
    let mut sd = Strapdown::new(state, model.dt);
    let start = SYST::get_current();
    for _ in 0..CYCLES {
        sd.step(core::hint::black_box(&sample));
    }
    let mech = ticks(start) / CYCLES;
    // Feedback after each step, as in the cycle (corrections of the size
    // the fine alignment feeds back at rest).
    let (phi, dv, dp) = (
        Vector3::new(2e-7, -1e-7, 3e-6),
        Vector3::new(1e-4, -2e-4, 5e-5),
        Vector3::new(1e-3, 2e-3, -1e-3),
    );
    let mut feedback = 0;
    for _ in 0..CYCLES {
        sd.step(core::hint::black_box(&sample));
        let start = SYST::get_current();
        sd.apply_correction(
            core::hint::black_box(&phi),
            core::hint::black_box(&dv),
            core::hint::black_box(&dp),
        );
        feedback += ticks(start);
    }
    let feedback = feedback / CYCLES;
    let s = *sd.state();
    let lp = linearization_point(&s, &sample);
    let earth = LocalEarth::at(&s.position);
    let start = SYST::get_current();
    for _ in 0..CYCLES {
        core::hint::black_box(model.transition_with::<T, N>(&earth, core::hint::black_box(&lp)));
    }
    let build = ticks(start) / CYCLES;
    let phi = model.transition::<T, N>(&lp);
    let q = model.process_noise::<T, N>(&ProcessNoise {
        nav_per_step: [1e-6; 9],
    });
    let mut f = mwd_core::kalman::KalmanFilter::<T, N>::new(SMatrix::identity() * T::of(0.01));
    let start = SYST::get_current();
    for _ in 0..CYCLES {
        f.predict(core::hint::black_box(&phi), &q);
    }
    let predict = ticks(start) / CYCLES;
    let zv = mwd_core::aid_sources::ZeroVelocity {
        velocity_n: [T::of(0.01); 3],
        variance: T::of(0.1),
    };
    let zp = mwd_core::aid_sources::ZeroPosition {
        position_error_ned_m: [T::of(0.01); 3],
        variance: T::of(0.1),
    };
    let start = SYST::get_current();
    for _ in 0..CYCLES {
        core::hint::black_box(f.update(core::hint::black_box(&zv)));
        core::hint::black_box(f.update(core::hint::black_box(&zp)));
    }
    let update = ticks(start) / CYCLES;
    [
        ("mechanization (f64)", mech),
        ("transition build (cached geodetic terms)", build),
        ("time update", predict),
        ("6 scalar updates", update),
        ("feedback (apply_correction, f64)", feedback),
    ]
}

/// One survey station's minimum-curvature step in f64: the segment from
/// the previous station (dogleg, checks) and its chord (ratio factor,
/// north/east/TVD increment) added to the position, with the dogleg
/// severity, as `mwd_core::survey::positions` does per station. A
/// 30 m course with a 3 deg/30 m build and a turn; the stations are
/// validated outside the loop.
fn min_curvature_step() -> u32 {
    let (Ok(from), Ok(to)) = (
        TrueStation::new(1000.0, 0.52, 1.10),
        TrueStation::new(1030.0, 0.5724, 1.13),
    ) else {
        return 0;
    };
    let mut nev = Vector3::new(100.0, 200.0, 900.0);
    let start = SYST::get_current();
    for _ in 0..CYCLES {
        if let Ok(seg) = Segment::new(core::hint::black_box(from), core::hint::black_box(to)) {
            nev += seg.increment();
            core::hint::black_box(seg.dogleg_severity_deg_per_30m());
        }
        core::hint::black_box(&nev);
    }
    ticks(start) / CYCLES
}

/// Ticks of a loop of known length: 1 nop + subs + bne per iteration.
fn calibration() -> (u32, u32) {
    let n: u32 = 300_000;
    let start = SYST::get_current();
    for _ in 0..n {
        cortex_m::asm::nop();
    }
    (ticks(start), 3 * n)
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        debug::exit(debug::EXIT_FAILURE);
        loop {
            cortex_m::asm::wfi();
        }
    };
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(RELOAD);
    cp.SYST.clear_current();
    cp.SYST.enable_counter();
    let (cal_ticks, cal_instr) = calibration();
    let per_tick = cal_instr as f32 / cal_ticks.max(1) as f32;
    hprintln!(
        "calibration: {} ticks for ~{} instructions ({:.1} instructions/tick)",
        cal_ticks,
        cal_instr,
        per_tick
    );
    let rows = [
        ("fast  f32", fast::<f32, STATES>()),
        ("fast  f32, 39 states", fast::<f32, STATES_WITH_BIASES>()),
        ("fast  f64", fast::<f64, STATES>()),
        ("dense f32", dense_cycle::<f32>()),
        ("dense f64", dense_cycle::<f64>()),
    ];
    for (name, t) in rows {
        let instr = t as f32 * per_tick;
        // 80 MHz probe at about one instruction per cycle: share of 50 ms.
        hprintln!(
            "{}: {} ticks/cycle = ~{:.0} instructions, {:.2} % of the 50 ms frame at 80 MHz",
            name,
            t,
            instr,
            instr / 80e6 / 0.05 * 100.0
        );
    }
    for (name, t) in parts::<f32, STATES>() {
        hprintln!(
            "  f32 part {}: ~{:.0} instructions",
            name,
            t as f32 * per_tick
        );
    }
    for (name, t) in parts::<f32, STATES_WITH_BIASES>() {
        hprintln!(
            "  f32 39-state part {}: ~{:.0} instructions",
            name,
            t as f32 * per_tick
        );
    }
    let mc = min_curvature_step();
    hprintln!(
        "survey: one station's minimum-curvature step (f64): {} ticks = ~{:.0} instructions",
        mc,
        mc as f32 * per_tick
    );
    debug::exit(debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}
