//! The station file of `host-sim survey` (CSV): a header line, then one
//! station a line. Columns (any order, names matched case-insensitively,
//! blanks around them ignored):
//!
//! - MD, required: `md`, `depth` or `measured depth` with its length unit
//!   (`md_m`, `MD (m)`, `Depth [ft]`, `md ft`...; metres: `m`; feet: `ft`,
//!   `feet`, `usft`). US survey feet are read as international feet: the
//!   two differ by 2 ppm (6 mm in 3000 m), far below any survey's
//!   uncertainty. A MD column without a unit is refused: the tool does not
//!   guess between feet and metres.
//! - inclination, required: `inc`, `incl`, `inclination`; azimuth,
//!   required: `azi`, `az`, `azimuth` (also `azi_true`: the azimuths' north
//!   is the command line's `--azimuth-reference`); toolface, optional:
//!   `toolface`, `tf`, `tool face`. Angles are in degrees: no unit, or
//!   `_deg`, `(deg)`, `[deg]`; any other unit is refused.
//! - time, optional: `time_s`, `time (s)`.
//!
//! Other columns (TVD, N, E, DLS of another tool's listing) are ignored;
//! two columns giving the same quantity are refused, and so is a header
//! with lengths in both feet and metres. Separators: comma, semicolon or
//! tab (else runs of spaces), from the header line. A row whose `station`
//! column holds `bit` (the bit's projection ending a capture survey's
//! stations CSV) is skipped: it repeats the last station's angles at the
//! bit's depth, it is no survey station. Read and checked here (finite
//! numbers, MD increasing and within 0..=20,000 m, inclination in 0..=180
//! deg, azimuth in 0..=360 deg, toolface within +-360 deg, at least one
//! station), lengths left in the file's unit.

use crate::formats::ranges::number as shown;
use crate::formats::text_records::{excerpt, for_each_record_tab_aware};
use anyhow::{anyhow, bail, Result};
use std::io::Read;

/// Metres per international foot.
pub const FOOT_M: f64 = 0.3048;

/// The deepest MD a station or depth file may hold, m: beyond the deepest
/// wells drilled (about 12,300 m), so a value past it is a mistake (a unit,
/// a column, a corrupted number), not a well.
pub const MAX_MD_M: f64 = 20_000.0;

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

    /// The unit's symbol in headers, column names and WITSML `uom`s.
    pub fn symbol(self) -> &'static str {
        match self {
            Self::Metre => "m",
            Self::Foot => "ft",
        }
    }

    /// A length given in metres, in this unit.
    pub fn from_m(self, metres: f64) -> f64 {
        match self {
            Self::Metre => metres,
            Self::Foot => metres / FOOT_M,
        }
    }

    /// A variance or covariance given in m^2, in this unit squared.
    pub fn from_m2(self, square_metres: f64) -> f64 {
        match self {
            Self::Metre => square_metres,
            Self::Foot => square_metres / (FOOT_M * FOOT_M),
        }
    }

    /// The dogleg-severity course length of this unit's practice: 30 m,
    /// or 100 ft.
    pub fn dls_course(self) -> (f64, &'static str) {
        match self {
            Self::Metre => (30.0, "30m"),
            Self::Foot => (100.0, "100ft"),
        }
    }

    /// A dogleg severity per 30 m, per this unit's course length.
    pub fn dls_from_per_30m(self, per_30m: f64) -> f64 {
        match self {
            Self::Metre => per_30m,
            // 100 ft is 30.48 m
            Self::Foot => per_30m * (100.0 * FOOT_M / 30.0),
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

/// How a station file is read: the unit of an MD column that names none
/// (`--units`), and whether azimuths outside 0..360 are wrapped into it
/// (`--wrap-azimuth`: those within one turn of it, -360..720) rather than
/// refused.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StationReading {
    pub unit: Option<LengthUnit>,
    pub wrap_azimuth: bool,
}

impl StationReading {
    /// Read with `unit` for an MD column that names none.
    pub fn in_unit(unit: Option<LengthUnit>) -> Self {
        Self {
            unit,
            ..Self::default()
        }
    }
}

/// What a column gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Quantity {
    Md,
    Inc,
    Azi,
    Toolface,
    Time,
}

impl Quantity {
    /// Its name in the errors (that of the tool's own header).
    fn name(self) -> &'static str {
        match self {
            Self::Md => "MD",
            Self::Inc => "inclination",
            Self::Azi => "azimuth",
            Self::Toolface => "toolface",
            Self::Time => "time",
        }
    }
}

/// A header name cut into its quantity's name and its unit, both lower
/// case: `MD (m)`, `md_m`, `Md [m]` and `md m` all give ("md", "m").
/// The name's underscores and runs of blanks become one space.
fn name_and_unit(header: &str) -> (String, Option<String>) {
    let lower = header.trim().to_ascii_lowercase();
    let normal = |s: &str| {
        s.split([' ', '_', '\t'])
            .filter(|w| !w.is_empty())
            .collect::<Vec<_>>()
            .join(" ")
    };
    for (open, close) in [('(', ')'), ('[', ']')] {
        if let Some(inner) = lower.strip_suffix(close) {
            if let Some(at) = inner.rfind(open) {
                let unit = inner[at + 1..].trim().to_string();
                return (normal(&inner[..at]), Some(unit));
            }
        }
    }
    let name = normal(&lower);
    if let Some((head, tail)) = name.rsplit_once(' ') {
        if is_unit(tail) {
            return (head.to_string(), Some(tail.to_string()));
        }
    }
    (name, None)
}

const METRE_UNITS: [&str; 5] = ["m", "metre", "metres", "meter", "meters"];
/// US survey feet are taken as international feet (see the module's doc).
const FOOT_UNITS: [&str; 4] = ["ft", "feet", "foot", "usft"];
const DEGREE_UNITS: [&str; 4] = ["deg", "degree", "degrees", "°"];
/// Angle units refused by name rather than left as part of a name.
const OTHER_ANGLE_UNITS: [&str; 6] = ["rad", "radian", "radians", "mrad", "grad", "gon"];
const SECOND_UNITS: [&str; 2] = ["s", "sec"];

/// Whether a name's last word is a unit (`md_m`, `inc_deg`), not part
/// of the name (`measured depth`).
fn is_unit(word: &str) -> bool {
    [
        &METRE_UNITS[..],
        &FOOT_UNITS,
        &DEGREE_UNITS,
        &OTHER_ANGLE_UNITS,
        &SECOND_UNITS,
    ]
    .iter()
    .any(|units| units.contains(&word))
}

fn length_unit(unit: &str) -> Option<LengthUnit> {
    if METRE_UNITS.contains(&unit) {
        Some(LengthUnit::Metre)
    } else if FOOT_UNITS.contains(&unit) {
        Some(LengthUnit::Foot)
    } else {
        None
    }
}

/// The quantity a column's name gives, if any of the five.
fn quantity(name: &str, unit: Option<&str>) -> Option<Quantity> {
    let q = match name {
        "md" | "depth" | "measured depth" => Quantity::Md,
        "inc" | "incl" | "inclination" => Quantity::Inc,
        "azi" | "az" | "azimuth" | "azi true" | "az true" | "azimuth true" => Quantity::Azi,
        "toolface" | "tf" | "tool face" => Quantity::Toolface,
        // a time without a unit may be a clock time: left alone
        "time" if unit.is_some_and(|u| SECOND_UNITS.contains(&u)) => Quantity::Time,
        _ => return None,
    };
    Some(q)
}

/// The required columns, for the errors.
const REQUIRED: &str = "required: md_m or md_ft, inc_deg, azi_deg";

struct Columns {
    md: usize,
    inc: usize,
    azi: usize,
    toolface: Option<usize>,
    time: Option<usize>,
    /// Of the `station` column, if any: its `bit` row is skipped.
    station: Option<usize>,
    unit: LengthUnit,
    /// The header's names of the MD, inclination... columns, for the errors.
    names: [String; 5],
}

fn columns(header: &[&str], line: u64, declared: Option<LengthUnit>) -> Result<Columns> {
    let parsed: Vec<(String, Option<String>)> = header.iter().map(|h| name_and_unit(h)).collect();
    let with_unit = |unit: LengthUnit| -> Vec<&str> {
        header
            .iter()
            .zip(&parsed)
            .filter(|(_, (_, u))| u.as_deref().and_then(length_unit) == Some(unit))
            .map(|(h, _)| *h)
            .collect()
    };
    let (metres, feet) = (with_unit(LengthUnit::Metre), with_unit(LengthUnit::Foot));
    if !metres.is_empty() && !feet.is_empty() {
        bail!(
            "the header mixes feet and metres ({} and {}): give every length in one unit",
            metres.join(", "),
            feet.join(", ")
        );
    }
    let mut found: [Option<usize>; 5] = [None; 5];
    let all = [
        Quantity::Md,
        Quantity::Inc,
        Quantity::Azi,
        Quantity::Toolface,
        Quantity::Time,
    ];
    for (col, (name, unit)) in parsed.iter().enumerate() {
        let Some(q) = quantity(name, unit.as_deref()) else {
            continue;
        };
        let slot = &mut found[q as usize];
        if let Some(first) = *slot {
            bail!(
                "line {line}: columns `{}` and `{}` both give the {}: keep one",
                excerpt(header[first]),
                excerpt(header[col]),
                q.name()
            );
        }
        *slot = Some(col);
        let angle = matches!(q, Quantity::Inc | Quantity::Azi | Quantity::Toolface);
        if let (true, Some(u)) = (angle, unit.as_deref()) {
            if !DEGREE_UNITS.contains(&u) {
                bail!(
                    "line {line}: column `{}`: the {} is in `{}`, not degrees: give angles in degrees",
                    excerpt(header[col]),
                    q.name(),
                    excerpt(u)
                );
            }
        }
    }
    let header_text = || excerpt(&header.join(","));
    let Some(md) = found[Quantity::Md as usize] else {
        bail!(
            "no column md_m or md_ft in the header `{}` ({REQUIRED})",
            header_text()
        );
    };
    let unit = match (parsed[md].1.as_deref(), declared) {
        (None, Some(unit)) => {
            let others = if unit == LengthUnit::Metre { &feet } else { &metres };
            if let Some(other) = others.first() {
                bail!(
                    "line {line}: the MD column `{}` has no unit and is taken in {} (--units), \
                     but `{}` is in the other unit: name the MD column with its unit",
                    excerpt(header[md]),
                    unit.symbol(),
                    excerpt(other)
                );
            }
            unit
        }
        (None, None) => bail!(
            "line {line}: the MD column `{}` has no unit: name it with one, e.g. \"MD (m)\" or \"md_ft\", \
             or give the file's unit with --units",
            excerpt(header[md])
        ),
        (Some(u), _) => length_unit(u).ok_or_else(|| {
            anyhow!(
                "line {line}: the MD column `{}` is in `{}`: give MD in m or ft",
                excerpt(header[md]),
                excerpt(u)
            )
        })?,
    };
    let need = |q: Quantity, name: &str| {
        found[q as usize].ok_or_else(|| {
            anyhow!(
                "no column {name} in the header `{}` ({REQUIRED})",
                header_text()
            )
        })
    };
    let names = all.map(|q| found[q as usize].map_or_else(String::new, |c| excerpt(header[c])));
    Ok(Columns {
        md,
        inc: need(Quantity::Inc, "inc_deg")?,
        azi: need(Quantity::Azi, "azi_deg")?,
        toolface: found[Quantity::Toolface as usize],
        time: found[Quantity::Time as usize],
        station: parsed
            .iter()
            .position(|(n, u)| n == "station" && u.is_none()),
        unit,
        names,
    })
}

fn number(fields: &[&str], col: usize, name: &str, line: u64) -> Result<f64> {
    let text = fields
        .get(col)
        .ok_or_else(|| anyhow!("line {line}: no {name} (too few fields)"))?;
    if text.trim().is_empty() {
        // a capture's stations CSV leaves an undetermined azimuth empty
        bail!(
            "line {line}: no {name} (an empty cell: undetermined at this station); a survey needs \
             every station's {name}: survey the stations before it"
        );
    }
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

/// Reads and checks a station file; its MD column names its unit.
pub fn read_stations<R: Read>(input: R) -> Result<StationFile> {
    read_stations_in(input, StationReading::default())
}

/// Reads and checks a station file whose MD column may leave its unit to
/// `reading.unit` (a header's own unit stands).
pub fn read_stations_in<R: Read>(input: R, reading: StationReading) -> Result<StationFile> {
    let mut stations: Vec<InputStation> = Vec::new();
    let unit = for_each_station(input, reading, |_, s| {
        stations.push(*s);
        Ok(())
    })?;
    Ok(StationFile { unit, stations })
}

/// The length unit of a station file, from its header (and its first
/// station, checked): what a caller needs before the stations.
pub fn file_unit<R: Read>(input: R, reading: StationReading) -> Result<LengthUnit> {
    /// Stops the reading at the first station.
    #[derive(Debug)]
    struct Found(LengthUnit);
    impl std::fmt::Display for Found {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "unit found")
        }
    }
    impl std::error::Error for Found {}
    match for_each_station(input, reading, |unit, _| Err(Found(unit).into())) {
        Ok(unit) => Ok(unit),
        Err(e) => e.downcast_ref::<Found>().map(|f| f.0).ok_or(e),
    }
}

/// Reads and checks a station file one station at a time, as
/// [`read_stations_in`] does, handing each to `take` with the file's
/// length unit; returns that unit. Holds one station, whatever the file's
/// length.
pub fn for_each_station<R: Read>(
    input: R,
    reading: StationReading,
    mut take: impl FnMut(LengthUnit, &InputStation) -> Result<()>,
) -> Result<LengthUnit> {
    let mut cols: Option<Columns> = None;
    let mut previous: Option<InputStation> = None;
    for_each_record_tab_aware(input, |line, fields| {
        let Some(c) = &cols else {
            cols = Some(columns(fields, line, reading.unit)?);
            return Ok(());
        };
        if c.station
            .is_some_and(|k| fields.get(k).is_some_and(|f| f.eq_ignore_ascii_case("bit")))
        {
            return Ok(());
        }
        let [md, inc, azi, toolface, time] = &c.names;
        let azi_deg = number(fields, c.azi, azi, line)?;
        let s = InputStation {
            md: number(fields, c.md, md, line)?,
            inc_deg: number(fields, c.inc, inc, line)?,
            // Wrapped only when asked (400 read as 40 may hide a typing
            // error), and only one turn either side: 1e300 stays refused.
            azi_deg: if reading.wrap_azimuth && (-360.0..720.0).contains(&azi_deg) {
                azi_deg.rem_euclid(360.0)
            } else {
                azi_deg
            },
            toolface_deg: optional(fields, c.toolface, toolface, line)?,
            time_s: optional(fields, c.time, time, line)?,
        };
        if !(0.0..=180.0).contains(&s.inc_deg) {
            bail!("line {line}: inclination {} deg outside 0..180", s.inc_deg);
        }
        if !(0.0..=360.0).contains(&s.azi_deg) {
            bail!(
                "line {line}: azimuth {} deg outside 0..360 (give azimuths from north, clockwise, \
                 in 0..360, or survey with --wrap-azimuth to wrap them into it)",
                shown(s.azi_deg)
            );
        }
        let md_limit = MAX_MD_M / c.unit.to_m();
        if !(0.0..=md_limit).contains(&s.md) {
            bail!(
                "line {line}: MD {} {} outside 0..{} (the deepest wells are about 12,000 m)",
                shown(s.md),
                c.unit.symbol(),
                md_limit.floor()
            );
        }
        if let Some(tf) = s.toolface_deg.filter(|tf| !(-360.0..=360.0).contains(tf)) {
            bail!("line {line}: toolface {} deg outside -360..360", shown(tf));
        }
        if let Some(prev) = previous {
            if s.md <= prev.md {
                bail!(
                    "line {line}: MD {} is not beyond the previous station's {} (MD must increase)",
                    s.md,
                    prev.md
                );
            }
        }
        previous = Some(s);
        take(c.unit, &s)
    })?;
    let Some(c) = cols else {
        bail!(
            "the file is empty: expected a header (md_m or md_ft, inc_deg, azi_deg) and stations"
        );
    };
    if previous.is_none() {
        bail!("no stations after the header");
    }
    Ok(c.unit)
}

#[cfg(test)]
mod tests;
