//! Units at the edges of the analysis commands: input columns are converted
//! to SI on reading, results are converted to the units engineers quote
//! (deg/sqrt(h), deg/h; m/s/sqrt(h), m/s^2) only when printed.

use anyhow::{bail, Result};
use mwd_core::conventions::DEG;
// Inputs given in g or mg are in standard gravities (ISO 80000-3).
use mwd_core::sensor_units::STANDARD_GRAVITY;

/// Unit of an input column (`allan --json` writes its variant name).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum InputUnit {
    /// rad/s (SI angular rate).
    RadPerS,
    /// deg/s.
    DegPerS,
    /// deg/h.
    DegPerH,
    /// m/s^2 (SI specific force).
    MPerS2,
    /// Standard gravities.
    G,
    /// Milli-g.
    MilliG,
    /// Anything else: analysed as given, reported in the same unit.
    Raw,
}

/// What a column measures, which decides the report units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Angular rate (SI rad/s).
    AngularRate,
    /// Specific force (SI m/s^2).
    SpecificForce,
    /// Unknown: no conversion.
    Other,
}

impl InputUnit {
    /// Parses `rad/s`, `deg/s`, `deg/h`, `m/s2` (or `m/s^2`), `g`, `mg`, `raw`.
    pub fn parse(text: &str) -> Result<Self> {
        Ok(match text.trim().to_ascii_lowercase().as_str() {
            "rad/s" => Self::RadPerS,
            "deg/s" | "dps" => Self::DegPerS,
            "deg/h" | "dph" => Self::DegPerH,
            "m/s2" | "m/s^2" => Self::MPerS2,
            "g" => Self::G,
            "mg" => Self::MilliG,
            "raw" | "1" => Self::Raw,
            other => bail!("unknown unit `{other}` (use rad/s, deg/s, deg/h, m/s2, g, mg or raw)"),
        })
    }

    /// The unit a column name announces by its suffix, as the simulator's
    /// sample CSV writes them (`gyro_x_rad_s`, `accel_y_m_s2`, ...).
    pub fn from_column_name(name: &str) -> Option<Self> {
        let n = name.to_ascii_lowercase();
        [
            ("_rad_s", Self::RadPerS),
            ("_deg_s", Self::DegPerS),
            ("_deg_h", Self::DegPerH),
            ("_m_s2", Self::MPerS2),
            ("_mg", Self::MilliG),
            ("_g", Self::G),
        ]
        .into_iter()
        .find(|(suffix, _)| n.ends_with(suffix))
        .map(|(_, unit)| unit)
    }

    /// Factor from this unit to SI.
    pub fn to_si(self) -> f64 {
        match self {
            Self::RadPerS | Self::MPerS2 | Self::Raw => 1.0,
            Self::DegPerS => DEG,
            Self::DegPerH => DEG / 3600.0,
            Self::G => STANDARD_GRAVITY,
            Self::MilliG => STANDARD_GRAVITY * 1e-3,
        }
    }

    /// The quantity measured.
    pub fn quantity(self) -> Quantity {
        match self {
            Self::RadPerS | Self::DegPerS | Self::DegPerH => Quantity::AngularRate,
            Self::MPerS2 | Self::G | Self::MilliG => Quantity::SpecificForce,
            Self::Raw => Quantity::Other,
        }
    }
}

/// A value in report units.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Reported {
    /// The number.
    pub value: f64,
    /// Its unit.
    pub unit: &'static str,
}

/// Report units of the Allan noise coefficients of an SI series: random
/// walk (SI unit * sqrt(s)), bias instability (SI unit), rate random walk
/// (SI unit / sqrt(s)) and the deviation itself.
pub fn report_noise(q: Quantity, random_walk: f64, bias: f64, rrw: f64) -> [Reported; 3] {
    // sqrt(3600 s) = 60 sqrt(s): x / sqrt(s) = 60 x / sqrt(h).
    match q {
        Quantity::AngularRate => [
            Reported {
                value: random_walk.to_degrees() * 60.0,
                unit: "deg/sqrt(h)",
            },
            Reported {
                value: bias.to_degrees() * 3600.0,
                unit: "deg/h",
            },
            Reported {
                value: rrw.to_degrees() * 3600.0 * 60.0,
                unit: "deg/h/sqrt(h)",
            },
        ],
        Quantity::SpecificForce => [
            Reported {
                value: random_walk * 60.0,
                unit: "m/s/sqrt(h)",
            },
            Reported {
                value: bias,
                unit: "m/s^2",
            },
            Reported {
                value: rrw * 60.0,
                unit: "m/s^2/sqrt(h)",
            },
        ],
        Quantity::Other => [
            Reported {
                value: random_walk,
                unit: "u*sqrt(s)",
            },
            Reported {
                value: bias,
                unit: "u",
            },
            Reported {
                value: rrw,
                unit: "u/sqrt(s)",
            },
        ],
    }
}

/// Unit of the Allan deviation itself in reports, and the factor from SI.
pub fn deviation_unit(q: Quantity) -> (&'static str, f64) {
    match q {
        Quantity::AngularRate => ("deg/h", 3600.0 / DEG),
        Quantity::SpecificForce => ("m/s^2", 1.0),
        Quantity::Other => ("u", 1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions() {
        assert_eq!(InputUnit::parse("DEG/S").unwrap(), InputUnit::DegPerS);
        assert!(InputUnit::parse("furlong").is_err());
        // 1 deg/sqrt(h) = (pi/180) / 60 rad/sqrt(s).
        let n = DEG / 60.0;
        let r = report_noise(Quantity::AngularRate, n, 0.0, 0.0);
        assert!((r[0].value - 1.0).abs() < 1e-12);
        assert!((InputUnit::MilliG.to_si() - 9.80665e-3).abs() < 1e-15);
        assert_eq!(
            InputUnit::from_column_name("gyro_z_rad_s"),
            Some(InputUnit::RadPerS)
        );
        assert_eq!(
            InputUnit::from_column_name("accel_x_m_s2"),
            Some(InputUnit::MPerS2)
        );
        assert_eq!(InputUnit::from_column_name("col1"), None);
    }
}
