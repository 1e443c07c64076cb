//! Limits of the numbers the commands take on the command line, checked
//! when the arguments are parsed so that a bad number is refused with a
//! sentence naming the flag and the range, before any work is done.
//! The ranges are listed in the README's host-tool section.
use mwd_core::sensor_units::GYRO_RANGE_DEG_S;
use std::fmt;
use std::ops::Deref;

/// Longest simulated run (48 h): twice the 24 h runs the tests make; a
/// CSV of it is ~0.6 GB (3.3 kB per simulated second), a capture ~0.3 GB.
/// Beyond it a typo such as `--duration 1e9` would fill the disk.
pub const MAX_DURATION_S: f64 = 48.0 * 3600.0;

/// A number from the command line: finite and inside `range` (inclusive).
pub fn number_in(text: &str, what: &str, range: (f64, f64), unit: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{}` is not a number ({what})", excerpt(text)))?;
    if !(value.is_finite() && value >= range.0 && value <= range.1) {
        return Err(format!(
            "{what} must be a finite number from {} to {} {unit}, not {value}",
            range.0, range.1
        ));
    }
    Ok(value)
}

/// `--duration`: seconds, more than 0 and at most [`MAX_DURATION_S`].
pub fn duration_s(text: &str) -> Result<f64, String> {
    let value = number_in(text, "the duration", (0.0, MAX_DURATION_S), "s")?;
    if value == 0.0 {
        return Err("the duration must be more than 0 s".into());
    }
    Ok(value)
}

/// `--tie-in-azimuth-sigma-deg` (the studies): 1-sigma of the parent
/// well's azimuth at the tie-in, 0.001 to 30 deg.
pub fn azimuth_sigma_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the tie-in azimuth sigma", (0.001, 30.0), "deg")
}

/// A body rate `x,y,z` in deg/s, each within the SCC1300's measurement
/// range (+-300 deg/s: beyond it the simulated gyros would saturate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyRate(pub [f64; 3]);

impl BodyRate {
    /// Parses `x,y,z` (degrees per second).
    pub fn parse(text: &str) -> Result<Self, String> {
        let parts: Vec<&str> = text.split(',').collect();
        let [x, y, z] = parts.as_slice() else {
            return Err(format!(
                "the body rate is three numbers x,y,z in deg/s, not `{}`",
                excerpt(text)
            ));
        };
        let range = (-f64::from(GYRO_RANGE_DEG_S), f64::from(GYRO_RANGE_DEG_S));
        let axis = |t: &str, name: &str| number_in(t, name, range, "deg/s");
        Ok(Self([
            axis(x, "the body rate's x")?,
            axis(y, "the body rate's y")?,
            axis(z, "the body rate's z")?,
        ]))
    }
}

/// The rates as a slice, x, y, z.
impl Deref for BodyRate {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.0
    }
}

impl fmt::Display for BodyRate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.0;
        write!(f, "{x},{y},{z}")
    }
}

/// At most the first 40 characters of what a person typed or a file held,
/// with control characters escaped: enough to find it, never the whole of
/// a long or binary input.
pub fn excerpt(text: &str) -> String {
    host_sim::analysis::csv_input::excerpt(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations() {
        assert_eq!(duration_s("60"), Ok(60.0));
        assert_eq!(duration_s("172800"), Ok(MAX_DURATION_S));
        for bad in ["1e9", "0", "-1", "nan", "inf", "x"] {
            let e = duration_s(bad).unwrap_err();
            assert!(e.contains("duration") || e.contains("not a number"), "{e}");
        }
        assert!(duration_s("1e9").unwrap_err().contains("172800 s"));
    }

    #[test]
    fn body_rates() {
        assert_eq!(BodyRate::parse("0,0,3"), Ok(BodyRate([0.0, 0.0, 3.0])));
        assert_eq!(BodyRate::parse("-1,2.5,3").unwrap()[1], 2.5);
        assert!(BodyRate::parse("0,3")
            .unwrap_err()
            .contains("three numbers"));
        assert!(BodyRate::parse("0,nan,3").unwrap_err().contains("y"));
        assert!(BodyRate::parse("0,0,301").unwrap_err().contains("300"));
        assert_eq!(BodyRate([0.0, 1.0, 0.0]).to_string(), "0,1,0");
    }
}
