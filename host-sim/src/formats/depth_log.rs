//! The surface depth log (`time_s,md_m`, as `host-sim simulate --depth-log`
//! writes it): read, checked, and interpolated in time.

use crate::formats::ranges::number;
use crate::formats::station_csv::MAX_MD_M;
use crate::formats::text_records::{excerpt, for_each_record};
use anyhow::{anyhow, bail, Result};
use std::io::Read;

/// Times (s, strictly increasing) and MD (m) of a depth log.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthLog {
    times: Vec<f64>,
    mds: Vec<f64>,
}

impl DepthLog {
    /// A log from (time, MD) points: at least two, every value finite, time
    /// strictly increasing.
    pub fn new(points: impl IntoIterator<Item = (f64, f64)>) -> Result<Self> {
        let (times, mds): (Vec<f64>, Vec<f64>) = points.into_iter().unzip();
        if times.len() < 2 {
            bail!("a depth log needs at least two rows (time_s, md_m)");
        }
        for k in 0..times.len() {
            if !(times[k].is_finite() && mds[k].is_finite()) {
                bail!("depth log row {}: a value is not a finite number", k + 1);
            }
            if k > 0 && times[k] <= times[k - 1] {
                bail!(
                    "depth log row {}: time {} s not after the previous {} s (time must increase)",
                    k + 1,
                    times[k],
                    times[k - 1]
                );
            }
        }
        Ok(Self { times, mds })
    }

    /// Reads a CSV with the columns `time_s` and `md_m` (any order, others
    /// ignored).
    pub fn read<R: Read>(input: R) -> Result<Self> {
        let mut cols: Option<(usize, usize)> = None;
        let mut points = Vec::new();
        for_each_record(input, |line, fields| {
            let Some((t, m)) = cols else {
                let find = |name: &str| fields.iter().position(|h| h.eq_ignore_ascii_case(name));
                match (find("time_s"), find("md_m")) {
                    (Some(t), Some(m)) => cols = Some((t, m)),
                    _ => bail!(
                        "not a depth log: the header `{}` lacks time_s and md_m",
                        excerpt(&fields.join(","))
                    ),
                }
                return Ok(());
            };
            let value = |c: usize, name: &str| -> Result<f64> {
                let text = fields
                    .get(c)
                    .ok_or_else(|| anyhow!("line {line}: no {name}"))?;
                text.parse::<f64>()
                    .map_err(|_| anyhow!("line {line}: {name} `{}` is not a number", excerpt(text)))
            };
            let (time, md) = (value(t, "time_s")?, value(m, "md_m")?);
            if !(time.is_finite() && time >= 0.0) {
                bail!(
                    "line {line}: time_s {} is not a finite time of 0 s or more",
                    number(time)
                );
            }
            if !(0.0..=MAX_MD_M).contains(&md) {
                bail!("line {line}: md_m {} outside 0..{MAX_MD_M} m", number(md));
            }
            if let Some(&(previous, _)) = points.last() {
                if time <= previous {
                    bail!(
                        "line {line}: time {time} s not after the previous row's {previous} s \
                         (time must increase)"
                    );
                }
            }
            points.push((time, md));
            Ok(())
        })?;
        if cols.is_none() {
            bail!("not a depth log: empty (expected a header time_s,md_m and rows)");
        }
        Self::new(points)
    }

    /// First and last time, s.
    pub fn span(&self) -> (f64, f64) {
        (self.times[0], self.times[self.times.len() - 1])
    }

    /// The first row at or after time `t`; `None` outside the log.
    fn row_at_or_after(&self, t: f64) -> Option<usize> {
        let (first, last) = self.span();
        (first..=last)
            .contains(&t)
            .then(|| self.times.partition_point(|&x| x < t))
    }

    /// The length of the log's interval `t` falls in, s: 0 at a row's own
    /// time, `None` outside the log. An MD interpolated across a long one
    /// is a guess at what the string did in between.
    pub fn interpolation_span(&self, t: f64) -> Option<f64> {
        let i = self.row_at_or_after(t)?;
        // At a row (the first row included: t is not before it).
        if i == 0 || self.times[i] == t {
            return Some(0.0);
        }
        Some(self.times[i] - self.times[i - 1])
    }

    /// MD at time `t` by linear interpolation; `None` outside the log.
    pub fn md_at(&self, t: f64) -> Option<f64> {
        let i = self.row_at_or_after(t)?;
        if i == 0 {
            return Some(self.mds[0]);
        }
        let (t0, t1) = (self.times[i - 1], self.times[i]);
        let (m0, m1) = (self.mds[i - 1], self.mds[i]);
        Some(m0 + (m1 - m0) * (t - t0) / (t1 - t0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_inside_and_refuses_outside() {
        let log = DepthLog::read("time_s,md_m\n0,100\n10,110\n20,110\n".as_bytes()).unwrap();
        assert_eq!(log.md_at(5.0), Some(105.0));
        assert_eq!(log.md_at(15.0), Some(110.0));
        assert_eq!(log.md_at(0.0), Some(100.0));
        assert_eq!(log.md_at(20.0), Some(110.0));
        assert_eq!(log.md_at(20.5), None);
        assert_eq!(log.md_at(-1.0), None);
    }

    #[test]
    fn what_is_not_a_depth_log_is_refused() {
        for bad in [
            "",
            "md_m,inc_deg,azi_deg\n0,0,0\n",
            "time_s,md_m\n0,1\n",
            "time_s,md_m\n0,1\n0,2\n",
            "time_s,md_m\n0,1\n1,x\n",
            "time_s,md_m\n0,1\n1,inf\n",
        ] {
            assert!(DepthLog::read(bad.as_bytes()).is_err(), "{bad:?}");
        }
        for (bad, needle) in [
            (
                "time_s,md_m\n0,1\n1,1e300\n",
                "line 3: md_m 1e300 outside 0..20000 m",
            ),
            ("time_s,md_m\n0,1\n1,-5\n", "line 3: md_m -5 outside"),
            ("time_s,md_m\n-1,1\n1,2\n", "line 2: time_s -1"),
        ] {
            let e = format!("{:#}", DepthLog::read(bad.as_bytes()).unwrap_err());
            assert!(e.contains(needle), "{bad:?}: {e}");
        }
    }
}
