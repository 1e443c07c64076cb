//! Survey computation on a long well: 10,001 stations 1 m apart (10 km MD:
//! vertical to 500 m, build at 3 deg/30 m to 60 deg, then a slow turn),
//! ISCWSA MWD Rev 5 (`host-sim/data/mwd_rev5_model_terms.csv`, 22
//! sources) at the ISCWSA #1 site. `positions`: minimum curvature
//! (`mwd_core::survey::positions`); `covariance`: the error model's per-source
//! and total NEV covariance at every station (`survey_error::run`);
//! `positions_and_covariance`: both, as a survey command would. Run with
//! `cargo bench -p host-sim --bench survey` (figures:
//! docs/survey-benchmarks.md).
//!
//! Two groups: `survey_10001` in wall time (criterion's default) and
//! `survey_10001_cpu` in the benchmark thread's own on-CPU time (Linux
//! `/proc/thread-self/schedstat`), which other processes on a shared,
//! loaded machine inflate far less than the wall time (they still share the
//! caches). Whether the 11 MB of results land on fresh pages each iteration
//! depends on glibc's heap; `GLIBC_TUNABLES=glibc.malloc.mmap_threshold=131072`
//! makes them always fresh, as in a one-shot CLI run (see the doc).

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{criterion_group, criterion_main, Criterion};
use host_sim::survey::iscwsa::{self, Site, Station as ErrStation};
use mwd_core::survey::{positions, TieOn, TrueNorth, TrueStation};
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

const STATIONS: usize = 10_001;

fn well() -> Vec<TrueStation> {
    (0..STATIONS)
        .map(|k| {
            let md = k as f64;
            let inc = ((md - 500.0).max(0.0) * 3.0 / 30.0).min(60.0);
            let azi = 30.0 + (md - 1100.0).max(0.0) * 0.01;
            TrueStation::new(md, inc.to_radians(), (azi % 360.0).to_radians())
                .expect("valid station")
        })
        .collect()
}

fn site() -> Site {
    Site {
        gravity: 9.80665,
        b_total: 50_000.0,
        dip: 72_f64.to_radians(),
        declination: -4_f64.to_radians(),
        vertical_limit: 1e-4_f64.to_radians(),
        latitude: 60_f64.to_radians(),
        gyro_noise_reduction: 1.0,
    }
}

fn with_tvd(stations: &[TrueStation]) -> Vec<ErrStation> {
    positions(&TieOn::<TrueNorth>::origin(), stations)
        .map(|p| {
            let p = p.expect("valid survey");
            ErrStation {
                md: p.station.md(),
                inc: p.station.inclination(),
                azi: p.station.azimuth(),
                tvd: p.tvd(),
                toolface: None,
            }
        })
        .collect()
}

/// The calling thread's on-CPU time, ns: the first field of
/// `/proc/thread-self/schedstat` (the scheduler's runtime of the task).
/// `None` where that file is not there (not Linux).
fn thread_cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Criterion measurement in on-CPU time (values in ns, shown as times).
struct CpuTime;

impl Measurement for CpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns().expect("/proc/thread-self/schedstat")
    }
    fn end(&self, start: u64) -> u64 {
        thread_cpu_ns().expect("/proc/thread-self/schedstat") - start
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        // values are ns, as WallTime's: its formatter prints them as times
        static WALL: WallTime = WallTime;
        WALL.formatter()
    }
}

fn bench_survey(c: &mut Criterion) {
    let terms = iscwsa::load_term_table(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/mwd_rev5_model_terms.csv"),
    )
    .expect("term table");
    let stations = well();
    let err_stations = with_tvd(&stations);
    iscwsa::check_stations(&err_stations).expect("valid survey");
    let site = site();
    assert!(iscwsa::run(&terms, &err_stations, &site).missing.is_empty());
    let mut group = c.benchmark_group("survey_10001");
    group.sample_size(20);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(5));
    group.bench_function("positions", |b| {
        b.iter(|| {
            positions(&TieOn::<TrueNorth>::origin(), black_box(&stations))
                .map(|p| p.expect("valid").tvd())
                .sum::<f64>()
        })
    });
    group.bench_function("covariance", |b| {
        b.iter(|| iscwsa::run(black_box(&terms), black_box(&err_stations), &site))
    });
    group.bench_function("positions_and_covariance", |b| {
        b.iter(|| {
            let s = with_tvd(black_box(&stations));
            iscwsa::run(black_box(&terms), &s, &site)
        })
    });
    group.finish();
}

/// The same covariance benches in on-CPU time.
fn bench_survey_cpu(c: &mut Criterion<CpuTime>) {
    let terms = iscwsa::load_term_table(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/mwd_rev5_model_terms.csv"),
    )
    .expect("term table");
    let stations = well();
    let err_stations = with_tvd(&stations);
    let site = site();
    let mut group = c.benchmark_group("survey_10001_cpu");
    group.sample_size(20);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(5));
    group.bench_function("covariance", |b| {
        b.iter(|| iscwsa::run(black_box(&terms), black_box(&err_stations), &site))
    });
    group.bench_function("positions_and_covariance", |b| {
        b.iter(|| {
            let s = with_tvd(black_box(&stations));
            iscwsa::run(black_box(&terms), &s, &site)
        })
    });
    group.finish();
}

criterion_group!(benches, bench_survey);
criterion_group! {
    name = benches_cpu;
    config = Criterion::default().with_measurement(CpuTime);
    targets = bench_survey_cpu
}
criterion_main!(benches, benches_cpu);
