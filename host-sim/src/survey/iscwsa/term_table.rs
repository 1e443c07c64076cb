//! The ISCWSA term table: the error sources of a tool model as data, one
//! row each (code, weighting-function name, magnitude and unit,
//! propagation mode), read from the CSV of the workbooks' `Model` sheet
//! (`host-sim/data/`, `tests/data/iscwsa/`), magnitudes converted to the
//! units the weighting functions use.
use std::fmt;
use std::path::Path;

/// Propagation mode of an error source.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Propagation {
    Random,
    Systematic,
    PerWell,
    Global,
}

impl Propagation {
    fn parse(s: &str) -> Result<Self, String> {
        match s.trim() {
            "R" => Ok(Self::Random),
            "S" => Ok(Self::Systematic),
            "W" => Ok(Self::PerWell),
            "G" => Ok(Self::Global),
            other => Err(format!("unknown propagation mode {other:?}")),
        }
    }
}

/// One error source (a row of the term table).
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorTerm {
    pub code: String,
    /// Weighting-function name (`Wt.Fn.` column), e.g. `DSF`, `ABXY-TI1`.
    pub weighting: String,
    /// Magnitude as published, in `unit`.
    pub magnitude: f64,
    pub unit: String,
    /// Magnitude in the units the weighting functions use (degree terms in
    /// radians): the table's "converted" column.
    pub magnitude_si: f64,
    pub propagation: Propagation,
}

/// Error loading a term table or a data file.
#[derive(Debug)]
pub struct DataError(pub String);

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DataError {}

fn col(headers: &csv::StringRecord, name: &str) -> Result<usize, DataError> {
    headers
        .iter()
        .position(|h| h.trim() == name)
        .ok_or_else(|| DataError(format!("term table: no column {name:?}")))
}

fn num(field: Option<&str>, what: &str, line: u64) -> Result<f64, DataError> {
    let s = field.ok_or_else(|| DataError(format!("line {line}: missing {what}")))?;
    s.trim()
        .parse::<f64>()
        .map_err(|e| DataError(format!("line {line}: {what} {s:?}: {e}")))
}

/// Reads an ISCWSA term table (`Model` sheet as CSV, as in
/// `tests/data/iscwsa/mwd_rev5_04_model_terms.csv`).
pub fn load_term_table(path: &Path) -> Result<Vec<ErrorTerm>, DataError> {
    let rdr =
        csv::Reader::from_path(path).map_err(|e| DataError(format!("{}: {e}", path.display())))?;
    read_term_table(rdr, &path.display().to_string())
}

/// Reads a term table from text (an embedded table); `name` labels errors.
pub fn parse_term_table(text: &str, name: &str) -> Result<Vec<ErrorTerm>, DataError> {
    read_term_table(csv::Reader::from_reader(text.as_bytes()), name)
}

fn read_term_table<R: std::io::Read>(
    mut rdr: csv::Reader<R>,
    name: &str,
) -> Result<Vec<ErrorTerm>, DataError> {
    let headers = rdr
        .headers()
        .map_err(|e| DataError(format!("{}: {e}", name)))?
        .clone();
    let c_code = col(&headers, "Code")?;
    let c_wt = col(&headers, "Wt.Fn.")?;
    let c_mag = col(&headers, "Magnitude")?;
    let c_unit = col(&headers, "Units")?;
    let c_prop = col(&headers, "Prop.")?;
    // the MWD tables carry the converted magnitude; the OWSG sheets do not
    let c_si = col(&headers, "Convert Magnitudes Degrees to Radians").ok();
    let mut terms = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| DataError(format!("{}: {e}", name)))?;
        let line = rec.position().map_or(0, |p| p.line());
        let text = |c: usize, what: &str| {
            rec.get(c)
                .map(|s| s.trim().to_string())
                .ok_or_else(|| DataError(format!("line {line}: missing {what}")))
        };
        let code = text(c_code, "Code")?;
        let magnitude = num(rec.get(c_mag), "Magnitude", line)?;
        let unit = text(c_unit, "Units")?;
        let magnitude_si = match c_si {
            Some(c) => num(rec.get(c), "converted magnitude", line)?,
            None => to_model_units(magnitude, &unit).ok_or_else(|| {
                DataError(format!("line {line}: unknown unit {unit:?} of {code}"))
            })?,
        };
        if code.is_empty() {
            return Err(DataError(format!("line {line}: empty Code")));
        }
        terms.push(ErrorTerm {
            code,
            weighting: text(c_wt, "Wt.Fn.")?,
            magnitude,
            unit,
            magnitude_si,
            propagation: Propagation::parse(&text(c_prop, "Prop.")?)
                .map_err(|e| DataError(format!("line {line}: {e}")))?,
        });
    }
    if terms.is_empty() {
        return Err(DataError(format!("{}: no terms", name)));
    }
    Ok(terms)
}

/// A magnitude in the units the weighting functions use: angles in
/// radians, angular rates in rad/s, the rest as tabulated.
pub(super) fn to_model_units(magnitude: f64, unit: &str) -> Option<f64> {
    let deg = std::f64::consts::PI / 180.0;
    Some(match unit {
        "deg" => magnitude * deg,
        "deg/hr" => magnitude * deg / 3600.0,
        "deg.nT" => magnitude * deg,
        "m" | "-" | "1/m" | "m/s2" | "nT" => magnitude,
        _ => return None,
    })
}
