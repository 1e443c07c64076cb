//! Numeric column files (CSV, semicolon, tab or whitespace separated) as
//! the analysis commands read them: an optional header line, `#` comments,
//! every data field a finite number. Errors name the file, the line and
//! the field, so a bad export is found without a debugger; they quote at
//! most a short excerpt of the input.

use super::units::InputUnit;
use crate::formats::samples_csv::{Record, MEASURED_COLUMNS};
use crate::formats::text_records::for_each_record;
pub use crate::formats::text_records::{excerpt, name_list};
use anyhow::{bail, Context, Result};
use mwd_core::calibration::ProbeCalibration;
use std::io::Read;
use std::path::Path;

/// A table of finite numbers, one `Vec` per column.
#[derive(Debug, Clone, PartialEq)]
pub struct Columns {
    /// Column names from the header, or `col1`, `col2`, ... without one.
    pub names: Vec<String>,
    /// `data[c][r]`: column `c`, data row `r`.
    pub data: Vec<Vec<f64>>,
}

impl Columns {
    /// Number of data rows.
    pub fn rows(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    /// Index of a column by its header name (case-insensitive).
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n.eq_ignore_ascii_case(name))
    }

    /// The column called `name`, or an error listing the names there are.
    pub fn column(&self, name: &str) -> Result<&[f64]> {
        match self.index_of(name) {
            Some(i) => Ok(&self.data[i]),
            None => bail!(
                "no column named `{name}` (columns: {})",
                name_list(&self.names)
            ),
        }
    }
}

/// The columns an analysis command works on, with their units: `columns`
/// (comma-separated header names) or every column but time and the
/// simulator's truth (`true_*`) columns;
/// `units` one unit for all, one per selected column, or `auto` (from the
/// column names' suffixes, `raw` where there is none).
pub fn select_columns(
    table: &Columns,
    columns: Option<&str>,
    units: &str,
) -> Result<Vec<(usize, InputUnit)>> {
    let selected: Vec<usize> = match columns {
        Some(list) => list
            .split(',')
            .map(|n| {
                table.index_of(n.trim()).ok_or_else(|| {
                    anyhow::anyhow!(
                        "no column `{}` (columns: {})",
                        n.trim(),
                        name_list(&table.names)
                    )
                })
            })
            .collect::<Result<_>>()?,
        None => (0..table.names.len())
            .filter(|&i| {
                let name = table.names[i].to_ascii_lowercase();
                !(matches!(name.as_str(), "time" | "time_s" | "t") || name.starts_with("true_"))
            })
            .collect(),
    };
    if selected.is_empty() {
        bail!("no data columns selected");
    }
    if units.trim().eq_ignore_ascii_case("auto") {
        return Ok(selected
            .into_iter()
            .map(|i| {
                (
                    i,
                    InputUnit::from_column_name(&table.names[i]).unwrap_or(InputUnit::Raw),
                )
            })
            .collect());
    }
    let parsed: Vec<InputUnit> = units
        .split(',')
        .map(InputUnit::parse)
        .collect::<Result<_>>()?;
    match parsed.len() {
        1 => Ok(selected.into_iter().map(|i| (i, parsed[0])).collect()),
        n if n == selected.len() => Ok(selected.into_iter().zip(parsed).collect()),
        n => bail!("{n} units given for {} columns", selected.len()),
    }
}

/// The input of an analysis command: a record sampled at `rate_hz`, read
/// from `path` (column file or capture), with the selected columns and
/// their units (see [`select_columns`]).
pub struct AnalysisInput {
    pub table: Columns,
    pub selected: Vec<usize>,
    pub units: Vec<InputUnit>,
}

impl AnalysisInput {
    /// The selected columns converted to SI: name, input unit, samples.
    pub fn si_columns(&self) -> impl Iterator<Item = (&str, InputUnit, Vec<f64>)> + '_ {
        self.selected.iter().zip(&self.units).map(|(&col, &unit)| {
            let si = unit.to_si();
            let samples = self.table.data[col].iter().map(|v| v * si).collect();
            (self.table.names[col].as_str(), unit, samples)
        })
    }
}

/// Checks the sample rate, reads the file and selects the columns: the
/// common start of `allan` and `arfit`.
pub fn read_analysis_input(
    path: &Path,
    rate_hz: f64,
    columns: Option<&str>,
    units: &str,
) -> Result<AnalysisInput> {
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        bail!("--rate must be a positive number of Hz, got {rate_hz}");
    }
    let table = read_columns(path)?;
    let chosen =
        select_columns(&table, columns, units).with_context(|| format!("{}", path.display()))?;
    let (selected, units) = chosen.into_iter().unzip();
    Ok(AnalysisInput {
        table,
        selected,
        units,
    })
}

/// Reads a numeric column file from disk, or a probe capture (`.bin`, the
/// UART bytes of `docs/protocol.md`) as SI body-frame columns.
pub fn read_columns(path: &Path) -> Result<Columns> {
    if is_capture(path) {
        return capture_columns(path);
    }
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    read_table(file).with_context(|| format!("in {}", path.display()))
}

/// Whether `path` names a probe capture (`.bin`) rather than a text table.
pub fn is_capture(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("bin"))
}

/// The raw-sample frames of a capture as samples, converted to SI in body
/// axes by the probe's own conversion (`mwd_core::probe::body_sample`),
/// uncalibrated (the tools apply their own calibration, as they do to a
/// simulated CSV). Samples with a faulty part are left out (and counted on
/// standard error), as are CRC failures and other corrupt frames.
pub fn capture_records(path: &Path) -> Result<Vec<Record>> {
    use crate::formats::capture::{FrameStream, Item};
    use mwd_core::protocol::Payload;
    let context = || format!("cannot read capture {}", path.display());
    let file = std::fs::File::open(path).with_context(context)?;
    let mut stream = FrameStream::new(std::io::BufReader::new(file));
    let mut records = Vec::new();
    let (mut frames, mut skipped) = (0usize, 0usize);
    while let Some(item) = stream.next_item().with_context(context)? {
        let Item::Frame(frame) = item else {
            continue;
        };
        frames += 1;
        let Payload::Raw(raw) = frame.payload else {
            continue;
        };
        let Some(sample) = mwd_core::probe::body_sample(&raw, &ProbeCalibration::default()) else {
            skipped += 1;
            continue;
        };
        records.push(Record {
            time: raw.time_us as f64 * 1e-6,
            sample,
            truth: None,
        });
    }
    if records.is_empty() {
        bail!(
            "{}: no valid raw-sample frame ({frames} frames decoded, {} CRC failures)",
            path.display(),
            stream.stats().crc_errors
        );
    }
    if skipped > 0 {
        eprintln!(
            "{}: {skipped} raw samples with a faulty part left out",
            path.display()
        );
    }
    Ok(records)
}

/// A capture's samples ([`capture_records`]) as SI columns named with their
/// units: time_s, gyro_x_rad_s, gyro_z_rad_s, accel_{x,y,z}_m_s2.
fn capture_columns(path: &Path) -> Result<Columns> {
    let mut data = vec![Vec::new(); 6];
    for r in capture_records(path)? {
        let f = r.sample.specific_force;
        let row = [r.time, r.sample.rate_x(), r.sample.rate_z(), f.x, f.y, f.z];
        for (column, value) in data.iter_mut().zip(row) {
            column.push(value);
        }
    }
    Ok(Columns {
        names: MEASURED_COLUMNS.iter().map(|n| n.to_string()).collect(),
        data,
    })
}

/// Parses the text of a numeric column file (see [`read_table`]).
pub fn parse_columns(text: &str) -> Result<Columns> {
    read_table(text.as_bytes())
}

/// Reads a numeric column file as it streams in (see
/// [`text_records`](super::text_records) for the separators and limits).
/// The first record is a header when any of its fields is not a number.
pub fn read_table<R: Read>(input: R) -> Result<Columns> {
    let mut names: Option<Vec<String>> = None;
    let mut data: Vec<Vec<f64>> = Vec::new();
    for_each_record(input, |line_no, fields| {
        let first_record = names.is_none() && data.is_empty();
        if first_record && fields.iter().any(|f| f.parse::<f64>().is_err()) {
            names = Some(fields.iter().map(|f| f.to_string()).collect());
            data = vec![Vec::new(); fields.len()];
            return Ok(());
        }
        if data.is_empty() {
            data = vec![Vec::new(); fields.len()];
        }
        if fields.len() != data.len() {
            bail!(
                "line {line_no}: {} fields where {} were expected",
                fields.len(),
                data.len()
            );
        }
        for (col, field) in fields.iter().enumerate() {
            let value: f64 = field.parse().map_err(|_| {
                anyhow::anyhow!(
                    "line {line_no}, column {}: `{}` is not a number",
                    col + 1,
                    excerpt(field)
                )
            })?;
            if !value.is_finite() {
                bail!(
                    "line {line_no}, column {}: `{}` is not finite",
                    col + 1,
                    excerpt(field)
                );
            }
            data[col].push(value);
        }
        Ok(())
    })?;
    if data.first().is_none_or(Vec::is_empty) {
        bail!("no data rows");
    }
    let names = names.unwrap_or_else(|| (1..=data.len()).map(|i| format!("col{i}")).collect());
    Ok(Columns { names, data })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_comments_and_separators() {
        let c = parse_columns("# run 3\ngx, gz\n1.0, 2\n\n3e-3, -4\n").unwrap();
        assert_eq!(c.names, vec!["gx", "gz"]);
        assert_eq!(c.data, vec![vec![1.0, 3e-3], vec![2.0, -4.0]]);
        assert_eq!(c.column("GZ").unwrap(), &[2.0, -4.0]);
        let w = parse_columns("1 2\n3\t4\n").unwrap();
        assert_eq!(w.names, vec!["col1", "col2"]);
        assert_eq!(w.rows(), 2);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse_columns("a,b\n1,2\n3,x\n").unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("`x`"), "{e}");
        let e = parse_columns("1,2\n3\n").unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
        let e = parse_columns("1,NaN\n").unwrap_err().to_string();
        assert!(e.contains("not finite"), "{e}");
        assert!(parse_columns("a,b\n").is_err());
        assert!(parse_columns("x\n1\n").unwrap().column("y").is_err());
    }

    #[test]
    fn selection_and_units() {
        let c = parse_columns("time_s,gyro_x_rad_s,ax,true_roll_rad\n0,1,2,3\n").unwrap();
        let auto = select_columns(&c, None, "auto").unwrap();
        assert_eq!(auto, vec![(1, InputUnit::RadPerS), (2, InputUnit::Raw)]);
        let two = select_columns(&c, Some("ax,time_s"), "g,raw").unwrap();
        assert_eq!(two, vec![(2, InputUnit::G), (0, InputUnit::Raw)]);
        assert!(select_columns(&c, None, "g,g,g").is_err());
        assert!(select_columns(&c, Some("nope"), "auto").is_err());
    }
}
