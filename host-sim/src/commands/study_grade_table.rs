//! `host-sim study grade-table`: the lateral study of every grade on the
//! built-in wells, its deciding figures put into README.md between the
//! grade-table markers and into a CSV
//! ([`host_sim::study::lateral::grade_table`]). Nothing is written unless
//! every run of every study succeeded: a failed or interrupted study, or
//! README without its markers, leaves both files as they were.

use super::runs::{progress_bar, stop_on_ctrl_c, SeedsAndThreads};
use super::study_lateral::{connection_still, rop, WellChoice};
use anyhow::{bail, Context, Result};
use host_sim::formats::files::OutputSet;
use host_sim::formats::text_records::read_small_file;
use host_sim::study::drilling_run::Scalar;
use host_sim::study::lateral::grade_table::{self, Provenance};
use host_sim::study::lateral::shard::{exact_text, SourceText, StudySpec};
use host_sim::study::lateral::summary::GradeWellSummary;
use host_sim::study::lateral::{study, LateralStudy, BUILTIN_WELLS};
use std::path::{Path, PathBuf};

/// The tie-in azimuth sigma of every study of the table (deg), the lateral
/// study's default.
const TIE_IN_AZIMUTH_SIGMA_DEG: f64 = 0.5;

#[derive(clap::Args, Debug)]
pub struct GradeTableArgs {
    /// Runs per grade on each well (seeds first-seed, first-seed + 1, ...).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub runs: u64,
    /// Runs per grade on the 1000 m well instead (each costs about ten
    /// times a 100 m run).
    #[arg(long = "runs-1000m", value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub runs_1000m: Option<u64>,
    /// The built-in laterals.
    #[arg(long, value_enum, default_value = "both")]
    pub well: WellChoice,
    /// Gyro grades by name (default: all built-in ones).
    #[arg(long, value_delimiter = ',')]
    pub grades: Vec<String>,
    #[command(flatten)]
    pub seeds: SeedsAndThreads,
    /// Rate of penetration, m/h (default: the plans').
    #[arg(long = "rop", value_parser = rop)]
    pub rop_m_per_h: Option<f64>,
    /// Still time at each connection, s (default: the plans').
    #[arg(long = "connection-still", value_parser = connection_still)]
    pub connection_still_s: Option<f64>,
    /// The navigator filter's scalar (f64: the probe's figures, faster).
    #[arg(long, value_enum, default_value = "f64")]
    pub scalar: Scalar,
    /// The README whose grade-table block is replaced.
    #[arg(long, default_value = "README.md")]
    pub readme: PathBuf,
    /// The table as CSV.
    #[arg(long, default_value = "docs/results/grade-table.csv")]
    pub csv: PathBuf,
}

impl GradeTableArgs {
    /// (well, runs per grade) of each study, the longest well first (the
    /// table lists it second).
    fn studies(&self) -> Vec<(&'static str, usize)> {
        let long = self.runs_1000m.unwrap_or(self.runs) as usize;
        let short = ("100m", self.runs as usize);
        match self.well {
            WellChoice::Short => vec![short],
            WellChoice::Long => vec![("1000m", long)],
            WellChoice::Both => vec![short, ("1000m", long)],
        }
    }

    /// The command line that makes this table (threads aside: they change
    /// no figure).
    fn command(&self) -> String {
        let mut c = format!("host-sim study grade-table --runs {}", self.runs);
        if let Some(n) = self.runs_1000m {
            c.push_str(&format!(" --runs-1000m {n}"));
        }
        match self.well {
            WellChoice::Short => c.push_str(" --well 100m"),
            WellChoice::Long => c.push_str(" --well 1000m"),
            WellChoice::Both => {}
        }
        if !self.grades.is_empty() {
            c.push_str(&format!(" --grades {}", self.grades.join(",")));
        }
        if self.seeds.first_seed != 1 {
            c.push_str(&format!(" --first-seed {}", self.seeds.first_seed));
        }
        if let Some(v) = self.rop_m_per_h {
            c.push_str(&format!(" --rop {v}"));
        }
        if let Some(v) = self.connection_still_s {
            c.push_str(&format!(" --connection-still {v}"));
        }
        if self.scalar != Scalar::F64 {
            c.push_str(&format!(" --scalar {}", self.scalar.name()));
        }
        c
    }

    /// The lateral study of one built-in well, as `study lateral` makes it.
    fn spec(&self, well: &str, runs: usize) -> Result<StudySpec> {
        let (label, text) = BUILTIN_WELLS
            .iter()
            .find(|(n, _)| *n == well)
            .with_context(|| format!("no built-in well {well:?}"))?;
        Ok(StudySpec {
            grades: self.grades.clone(),
            grade_files: Vec::new(),
            wells: vec![SourceText {
                name: label.to_string(),
                text: text.to_string(),
            }],
            rop_m_per_h: self.rop_m_per_h.map(exact_text),
            stand_length_m: None,
            connection_still_s: self.connection_still_s.map(exact_text),
            connection_dwells: None,
            // the wells' own (each run drills its own hole around the plan)
            tortuosity_deg_per_30m: None,
            tortuosity_length_m: None,
            tie_in_azimuth_sigma_deg: exact_text(TIE_IN_AZIMUTH_SIGMA_DEG),
            runs,
            first_seed: self.seeds.first_seed,
            monte_carlo: true,
            sweep: None,
            scalar: self.scalar,
        })
    }
}

pub fn run(args: GradeTableArgs) -> Result<()> {
    let readme_name = args.readme.display().to_string();
    // the markers checked before the long work, and again after it
    grade_table::block_span(&read_readme(&args.readme)?, &readme_name)?;
    let threads = args.seeds.threads();
    let configs = args
        .studies()
        .into_iter()
        .map(|(well, runs)| args.spec(well, runs)?.config(threads))
        .collect::<Result<Vec<_>>>()?;
    let jobs: u64 = configs
        .iter()
        .map(|c| (c.grades.len() * c.wells.len() * (c.runs + 1)) as u64)
        .sum();
    let bar = progress_bar(
        jobs,
        "{bar:40} {pos}/{len} jobs (Monte Carlo, covariance analysis), {elapsed} (eta {eta})",
    )?;
    let stop = stop_on_ctrl_c(Some(&bar))?;
    let mut studies = Vec::new();
    for config in &configs {
        let result = study(config, &|| bar.inc(1), &stop)?;
        refuse_incomplete(&result)?;
        studies.push(result);
    }
    bar.finish_and_clear();
    let summaries = grade_major(&studies);
    let provenance = Provenance {
        command: args.command(),
        runs: args
            .studies()
            .into_iter()
            .map(|(w, n)| (w.to_string(), n))
            .collect(),
        first_seed: args.seeds.first_seed,
        filter: args.scalar.name().to_string(),
        threads,
        wall_s: studies.iter().map(|s| s.wall_s).sum(),
        csv: args.csv.display().to_string(),
    };
    let block = grade_table::markdown(&summaries, &provenance);
    let readme = grade_table::replace_block(&read_readme(&args.readme)?, &readme_name, &block)?;
    let mut outputs = OutputSet::default();
    outputs.stage(&args.csv, &grade_table::csv(&summaries))?;
    outputs.stage(&args.readme, &readme)?;
    outputs.commit()?;
    out!("{block}\n");
    outln!(
        "wrote the grade table into {readme_name} and {}",
        args.csv.display()
    );
    Ok(())
}

fn read_readme(path: &Path) -> Result<String> {
    read_small_file(path).with_context(|| format!("reading {}", path.display()))
}

/// A study with a failed or missing run makes no table.
fn refuse_incomplete(result: &LateralStudy) -> Result<()> {
    let unwritten = "the grade table was not written";
    if let Some(i) = result.interrupted {
        bail!(
            "interrupted after {} of {} jobs: {unwritten}",
            i.jobs_done,
            i.jobs
        );
    }
    let mut errors = result.errors.clone();
    for s in &result.summaries {
        errors.extend(
            s.failed_runs
                .iter()
                .map(|e| format!("{} {}: {e}", s.grade, s.well)),
        );
    }
    if let Some(first) = errors.first() {
        bail!("{} failed ({first}): {unwritten}", errors.len());
    }
    Ok(())
}

/// The studies' summaries (one well each) grade by grade, each grade's
/// wells in the studies' order.
fn grade_major(studies: &[LateralStudy]) -> Vec<GradeWellSummary> {
    let grades = studies.first().map_or(0, |s| s.summaries.len());
    (0..grades)
        .flat_map(|g| studies.iter().filter_map(move |s| s.summaries.get(g)))
        .cloned()
        .collect()
}
