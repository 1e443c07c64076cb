//! A station file's survey in constant memory: `host-sim survey` of a file
//! of any length when only the listing and the CSV are asked for. The file
//! is read twice, one station at a time: first to check every line (so
//! nothing is written from a file that turns out bad) and to find the last
//! station's closure (the default vertical-section direction); then to
//! position each station (`mwd_core::survey::Walker`), give it the error
//! model's covariance ([`listing::ModelRun`], the sources' running sums)
//! and write its listing line and CSV row. Held at any time: two stations
//! and the sources' sums, so a million stations take the memory of ten.
//!
//! The rows are those of the survey held in memory
//! ([`WellSurvey::compute`]) number for number, and the tables the same
//! bytes ([`crate::survey::outputs::table`]).

use crate::formats::station_csv::{for_each_station, InputStation, LengthUnit, StationReading};
use crate::survey::listing::{
    self, closure_azimuth, plus_tie_on, row, tie_on_m, true_station, ModelRun, Row,
};
use crate::survey::outputs::{csv_head, csv_row, listing_head, listing_row, Head};
use crate::survey::well_survey::{validity_note, ModelChoice, SiteFor, SurveyInputs};
use anyhow::{anyhow, Context, Result};
use mwd_core::survey::{SurveyPoint, TrueNorth, Walker};
use std::io::Write;
use std::path::Path;

/// Where the streamed tables go.
pub struct StreamOutputs<'a> {
    /// The listing (standard output).
    pub listing: &'a mut dyn Write,
    /// The CSV, if asked for.
    pub csv: Option<&'a mut dyn Write>,
}

/// What the streamed survey found, besides what it wrote.
#[derive(Clone, Debug)]
pub struct StreamedSurvey {
    pub stations: usize,
    /// The model's validity note, if it stops being valid.
    pub validity_note: Option<String>,
}

/// Surveys the station file at `path` (read as `reading` says: its MD
/// unit if the header names none, azimuths to wrap), writing the listing and the CSV row by row in
/// `unit` (metres if `None`).
pub fn survey_streamed(
    path: &Path,
    reading: StationReading,
    inputs: &SurveyInputs,
    site_for: SiteFor,
    unit: Option<LengthUnit>,
    out: StreamOutputs,
) -> Result<StreamedSurvey> {
    let named = |e: anyhow::Error| e.context(path.display().to_string());
    let open = || std::fs::File::open(path).with_context(|| format!("{}", path.display()));
    // Pass 1: every line checked, the count and the last position.
    let mut walker = None;
    let mut last = None;
    let mut stations = 0usize;
    let file_unit = for_each_station(open()?, reading, |file_unit, s| {
        stations += 1;
        last = Some(walk(&mut walker, file_unit, s, inputs)?);
        Ok(())
    })
    .map_err(named)?;
    let last = last.context("no stations")?;
    let direction = inputs
        .vsec_azimuth
        .unwrap_or_else(|| closure_azimuth(&last));
    let model = match inputs.model {
        ModelChoice::File(p) => Some(listing::model_from_file(p)?),
        ModelChoice::Named(name) => Some(listing::model(name)?),
        ModelChoice::None => None,
    };
    let tie_on_cov_m2 = inputs.tie.covariance_m2(file_unit);
    let head = Head {
        stations,
        vsec_azimuth_deg: direction.to_degrees(),
        model,
        confidence: inputs.confidence,
        tie_on_cov_m2,
        unit: unit.unwrap_or(LengthUnit::Metre),
        offset: false,
        // a station file says nothing of the probe's calibration
        uncalibrated: false,
    };
    let terms = model.map(listing::terms).transpose()?.unwrap_or_default();
    let mut run = model
        .map(|m| Ok::<_, anyhow::Error>(ModelRun::new(m, &terms, site_for(m)?)))
        .transpose()?;
    // the tie-on's covariance in each station's, as `WellSurvey::compute`
    // adds it
    let with_tie_on = |mut r: Row| {
        r.cov = r.cov.map(|c| plus_tie_on(c, tie_on_cov_m2.as_ref()));
        r
    };
    // Pass 2: the rows, one behind the file where a model runs (a
    // station's covariance needs the station after it).
    let mut table = Tables::new(&head, out)?;
    let mut walker = None;
    for_each_station(open()?, reading, |file_unit, s| {
        let r = row(s, &walk(&mut walker, file_unit, s, inputs)?, direction);
        match run.as_mut() {
            None => table.write(&r),
            Some(run) => run
                .push(r)?
                .into_iter()
                .try_for_each(|r| table.write(&with_tie_on(r))),
        }
    })
    .map_err(named)?;
    let mut note = None;
    if let (Some(mut run), Some(m)) = (run, model) {
        run.finish()?
            .into_iter()
            .try_for_each(|r| table.write(&with_tie_on(r)))?;
        note = run
            .invalid
            .map(|(invalid, md_m)| validity_note(m, &invalid, md_m, head.unit));
    }
    if let Some(note) = &note {
        writeln!(table.out.listing, "note: {note}")?;
    }
    table.flush()?;
    Ok(StreamedSurvey {
        stations,
        validity_note: note,
    })
}

/// The next station's position by minimum curvature (the first station
/// starts the walk at the tie-on), as `listing::compute` places it.
fn walk(
    walker: &mut Option<Walker<TrueNorth>>,
    unit: LengthUnit,
    s: &InputStation,
    inputs: &SurveyInputs,
) -> Result<SurveyPoint<TrueNorth>> {
    let walker = match walker {
        Some(w) => w,
        None => walker.insert(Walker::new(&tie_on_m(&inputs.tie, unit, s.md)?)),
    };
    walker
        .step(true_station(s, unit, inputs.reference)?)
        .map_err(|e| anyhow!("minimum curvature: {e:?}"))
}

/// The two tables being written.
struct Tables<'h, 'o> {
    head: &'h Head,
    out: StreamOutputs<'o>,
}

impl<'h, 'o> Tables<'h, 'o> {
    fn new(head: &'h Head, mut out: StreamOutputs<'o>) -> Result<Self> {
        out.listing.write_all(listing_head(head).as_bytes())?;
        if let Some(csv) = out.csv.as_mut() {
            csv.write_all(csv_head(head).as_bytes())?;
        }
        Ok(Self { head, out })
    }

    fn write(&mut self, r: &Row) -> Result<()> {
        self.out
            .listing
            .write_all(listing_row(self.head, r, None).as_bytes())?;
        if let Some(csv) = self.out.csv.as_mut() {
            csv.write_all(csv_row(self.head, r, None).as_bytes())?;
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<()> {
        self.out.listing.flush()?;
        if let Some(csv) = self.out.csv.as_mut() {
            csv.flush()?;
        }
        Ok(())
    }
}
