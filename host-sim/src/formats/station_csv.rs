//! The station file of `host-sim survey` (CSV): a header line, then one
//! station a line. Columns (any order): `md_m` or `md_ft` (one of them:
//! feet and metres are never mixed, and every length column of the file
//! must be in the same unit), `inc_deg`, `azi_deg` required;
//! `toolface_deg`, `time_s` optional (carried to the outputs). Read and
//! checked here (finite numbers, MD increasing, inclination in 0..=180
//! deg, at least one station), lengths left in the file's unit.

use crate::formats::text_records::{excerpt, for_each_record};
use anyhow::{anyhow, bail, Result};
use std::io::Read;

/// Metres per international foot.
pub const FOOT_M: f64 = 0.3048;

/// Length unit of a station file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LengthUnit {
    Metre,
    Foot,
}

impl LengthUnit {
    pub fn to_m(self) -> f64 {
        match self {
            Self::Metre => 1.0,
            Self::Foot => FOOT_M,
        }
    }
}

/// One row of a station file, as read (lengths in the file's unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputStation {
    pub md: f64,
    pub inc_deg: f64,
    pub azi_deg: f64,
    pub toolface_deg: Option<f64>,
    pub time_s: Option<f64>,
}

/// A station file: its unit and rows, checked (finite, MD increasing,
/// inclination in 0..=180 deg, at least one station).
#[derive(Clone, Debug)]
pub struct StationFile {
    pub unit: LengthUnit,
    pub stations: Vec<InputStation>,
}

struct Columns {
    md: usize,
    inc: usize,
    azi: usize,
    toolface: Option<usize>,
    time: Option<usize>,
    unit: LengthUnit,
}

fn columns(header: &[&str]) -> Result<Columns> {
    let find = |name: &str| header.iter().position(|h| h.eq_ignore_ascii_case(name));
    let metres: Vec<&str> = header
        .iter()
        .copied()
        .filter(|h| h.ends_with("_m"))
        .collect();
    let feet: Vec<&str> = header
        .iter()
        .copied()
        .filter(|h| h.ends_with("_ft"))
        .collect();
    if !metres.is_empty() && !feet.is_empty() {
        bail!(
            "the header mixes feet and metres ({} and {}): give every length in one unit",
            metres.join(", "),
            feet.join(", ")
        );
    }
    let (md, unit) = match (find("md_m"), find("md_ft")) {
        (Some(c), None) => (c, LengthUnit::Metre),
        (None, Some(c)) => (c, LengthUnit::Foot),
        _ => bail!(
            "no column md_m or md_ft in the header `{}` (required: md_m or md_ft, inc_deg, azi_deg)",
            excerpt(&header.join(","))
        ),
    };
    let need = |name: &str| {
        find(name).ok_or_else(|| {
            anyhow!(
                "no column {name} in the header `{}` (required: md_m or md_ft, inc_deg, azi_deg)",
                excerpt(&header.join(","))
            )
        })
    };
    Ok(Columns {
        md,
        inc: need("inc_deg")?,
        azi: need("azi_deg")?,
        toolface: find("toolface_deg"),
        time: find("time_s"),
        unit,
    })
}

fn number(fields: &[&str], col: usize, name: &str, line: u64) -> Result<f64> {
    let text = fields
        .get(col)
        .ok_or_else(|| anyhow!("line {line}: no {name} (too few fields)"))?;
    let value: f64 = text
        .parse()
        .map_err(|_| anyhow!("line {line}: {name} `{}` is not a number", excerpt(text)))?;
    if !value.is_finite() {
        bail!("line {line}: {name} is {value}, not a finite number");
    }
    Ok(value)
}

fn optional(fields: &[&str], col: Option<usize>, name: &str, line: u64) -> Result<Option<f64>> {
    match col {
        Some(c) if fields.get(c).is_some_and(|f| !f.is_empty()) => {
            number(fields, c, name, line).map(Some)
        }
        _ => Ok(None),
    }
}

/// Reads and checks a station file.
pub fn read_stations<R: Read>(input: R) -> Result<StationFile> {
    let mut cols: Option<Columns> = None;
    let mut stations: Vec<InputStation> = Vec::new();
    for_each_record(input, |line, fields| {
        let Some(c) = &cols else {
            cols = Some(columns(fields)?);
            return Ok(());
        };
        let unit = if c.unit == LengthUnit::Metre {
            "md_m"
        } else {
            "md_ft"
        };
        let s = InputStation {
            md: number(fields, c.md, unit, line)?,
            inc_deg: number(fields, c.inc, "inc_deg", line)?,
            azi_deg: number(fields, c.azi, "azi_deg", line)?,
            toolface_deg: optional(fields, c.toolface, "toolface_deg", line)?,
            time_s: optional(fields, c.time, "time_s", line)?,
        };
        if !(0.0..=180.0).contains(&s.inc_deg) {
            bail!("line {line}: inclination {} deg outside 0..180", s.inc_deg);
        }
        if let Some(prev) = stations.last() {
            if s.md <= prev.md {
                bail!(
                    "line {line}: MD {} is not beyond the previous station's {} (MD must increase)",
                    s.md,
                    prev.md
                );
            }
        }
        stations.push(s);
        Ok(())
    })?;
    let Some(c) = cols else {
        bail!(
            "the file is empty: expected a header (md_m or md_ft, inc_deg, azi_deg) and stations"
        );
    };
    if stations.is_empty() {
        bail!("no stations after the header");
    }
    Ok(StationFile {
        unit: c.unit,
        stations,
    })
}
