//! `host-sim study indexing`'s command line ([`host_sim::study::indexing`]).

use super::limits::number_in;
use super::runs::{
    print_and_write_json, progress_bar, stop_on_ctrl_c, GradeChoice, SeedsAndThreads,
};
use anyhow::{bail, Result};
use host_sim::study::indexing::{indexed_station, summarize, table, IndexingSetup};
use mwd_core::conventions::DEG;
use mwd_core::earth::Position;
use std::path::PathBuf;
use std::sync::atomic::Ordering;

fn still_s(text: &str) -> Result<f64, String> {
    number_in(text, "the connection's still time", (10.0, 3600.0), "s")
}

fn inclination_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the inclination", (0.0, 180.0), "deg")
}

fn prior_sigma_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the prior azimuth's sigma", (0.0, 90.0), "deg")
}

fn turn_rate_deg_s(text: &str) -> Result<f64, String> {
    number_in(text, "the orienter's turn rate", (0.1, 360.0), "deg/s")
}

#[derive(clap::Args, Debug)]
pub struct IndexingArgs {
    #[command(flatten)]
    pub grade_choice: GradeChoice,
    /// Dwells per connection, each a study (1: no indexing; 2: 180 deg
    /// apart; 4: 90 deg apart).
    #[arg(long, value_delimiter = ',', default_values_t = [1, 2, 4],
          value_parser = clap::value_parser!(u32).range(1..=6))]
    pub dwells: Vec<u32>,
    /// The connection's still time, all dwells together (s; the drilling
    /// simulation's default connection).
    #[arg(long, default_value_t = 300.0, value_parser = still_s)]
    pub still_s: f64,
    /// The orienter's turn rate between dwells (deg/s).
    #[arg(long, default_value_t = 10.0, value_parser = turn_rate_deg_s)]
    pub turn_rate_deg_s: f64,
    /// The hole's inclination (deg); azimuth and toolface are drawn per run.
    #[arg(long, default_value_t = 90.0, value_parser = inclination_deg)]
    pub inclination_deg: f64,
    /// 1-sigma of the azimuth known beforehand (deg: the plan's or the
    /// last station's), which chooses between a horizontal tool's two
    /// mirror headings when the gyros cannot.
    #[arg(long, default_value_t = 5.0, value_parser = prior_sigma_deg)]
    pub prior_sigma_deg: f64,
    /// Site latitude (deg; default the paper's site, 45.78 N).
    #[arg(long, value_parser = super::site::latitude_deg)]
    pub latitude_deg: Option<f64>,
    /// Runs per grade and number of dwells (seeds first-seed, ...).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub runs: u64,
    #[command(flatten)]
    pub seeds: SeedsAndThreads,
    /// Write the summaries here (JSON).
    #[arg(long)]
    pub json: Option<PathBuf>,
}

pub fn run(args: IndexingArgs) -> Result<()> {
    let grades = args.grade_choice.select()?;
    let mut site = Position::paper_site();
    if let Some(lat) = args.latitude_deg {
        site.lat = lat * DEG;
    }
    let setup = IndexingSetup {
        still_s: args.still_s,
        turn_rate: args.turn_rate_deg_s * DEG,
        inclination: args.inclination_deg * DEG,
        site,
        prior_sigma: args.prior_sigma_deg * DEG,
    };
    let bar = progress_bar(
        args.runs * (grades.len() * args.dwells.len()) as u64,
        "{bar:40} {pos}/{len} stations, {elapsed} (eta {eta})",
    )?;
    let stop = stop_on_ctrl_c(Some(&bar))?;
    let mut summaries = Vec::new();
    let progress = || bar.inc(1);
    for grade in &grades {
        for &dwells in &args.dwells {
            let runs = args.seeds.runs(args.runs, &progress, &stop);
            let stations = runs.run(|seed| indexed_station(grade, dwells, &setup, seed));
            summaries.push(summarize(grade.name(), dwells, &stations));
        }
    }
    bar.finish_and_clear();
    outln!(
        "indexing study: a still probe at inclination {} deg, latitude {:.2} deg, random azimuth and toolface, the azimuth known beforehand to {} deg (1 sigma); {} s of still time per connection in 1 to {} dwells, the toolface turned between them at {} deg/s; {} runs each from seed {}",
        args.inclination_deg,
        site.lat / DEG,
        args.prior_sigma_deg,
        args.still_s,
        args.dwells.iter().max().copied().unwrap_or(1),
        args.turn_rate_deg_s,
        args.runs,
        args.seeds.first_seed,
    );
    print_and_write_json(&table(&summaries), args.json.as_deref(), &summaries)?;
    if stop.load(Ordering::Relaxed) {
        bail!("interrupted: the outputs above hold the runs done");
    }
    let failed: usize = summaries.iter().map(|s| s.failed).sum();
    if let Some(first) = summaries.iter().find_map(|s| s.first_failure.clone()) {
        bail!("{failed} runs failed; the first: {first}");
    }
    Ok(())
}
