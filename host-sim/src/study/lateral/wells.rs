//! The lateral study's wells: the repository's two laterals built in, or
//! a plan file, with the drilling parameters the command line gives
//! instead of the plan's ([`DrillingOverrides`]).

use crate::sim::{BuiltPlan, Plan};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::path::Path;

/// The repository's two laterals (docs/drilling-simulation.md), built in
/// so the binary works from any directory.
pub const BUILTIN_WELLS: [(&str, &str); 2] = [
    (
        "100m",
        include_str!("../../../data/plans/lateral-100m.json"),
    ),
    (
        "1000m",
        include_str!("../../../data/plans/lateral-1000m.json"),
    ),
];

/// Drilling parameters given on the command line instead of the plan's
/// (checked with the plan's own ranges when it is built).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct DrillingOverrides {
    pub rop_m_per_h: Option<f64>,
    pub stand_length_m: Option<f64>,
    pub connection_still_s: Option<f64>,
    /// The connection's still time in this many dwells, the toolface
    /// indexed between them (`DrillingParams::connection_dwells`).
    pub connection_dwells: Option<u32>,
    /// The hole's tortuosity: RMS (deg/30 m) and correlation length (m).
    pub tortuosity_deg_per_30m: Option<f64>,
    pub tortuosity_length_m: Option<f64>,
}

/// A well of the study.
#[derive(Clone, Debug)]
pub struct Well {
    /// "100m", "1000m" or the plan file's path.
    pub label: String,
    pub plan: BuiltPlan,
}

impl Well {
    /// MD drilled from the tie-on to TD (m).
    pub fn lateral_length_m(&self) -> f64 {
        self.plan.end_md() - self.plan.tie_on.md()
    }

    /// A plan from its JSON text with `overrides` applied.
    pub fn parse(label: &str, text: &str, overrides: &DrillingOverrides) -> Result<Self> {
        let mut plan: Plan =
            serde_json::from_str(text).with_context(|| format!("{label}: not a well plan"))?;
        let d = &mut plan.drilling;
        if let Some(v) = overrides.rop_m_per_h {
            d.rop_m_per_h = v;
        }
        if let Some(v) = overrides.stand_length_m {
            d.stand_length_m = v;
        }
        if let Some(v) = overrides.connection_still_s {
            d.connection_still_s = v;
        }
        if let Some(n) = overrides.connection_dwells {
            d.connection_dwells = n;
        }
        d.tortuosity = d.tortuosity.overridden(
            overrides.tortuosity_deg_per_30m,
            overrides.tortuosity_length_m,
        );
        let plan = plan.build().with_context(|| {
            format!("{label}: invalid plan (with the command line's drilling parameters)")
        })?;
        Ok(Self {
            label: label.to_string(),
            plan,
        })
    }

    /// A built-in well: "100m" or "1000m".
    pub fn builtin(name: &str, overrides: &DrillingOverrides) -> Result<Self> {
        let Some((label, text)) = BUILTIN_WELLS.iter().find(|(n, _)| *n == name) else {
            bail!("no built-in well {name:?}: 100m or 1000m");
        };
        Self::parse(label, text, overrides)
    }

    /// A plan file.
    pub fn load(path: &Path, overrides: &DrillingOverrides) -> Result<Self> {
        let text = crate::formats::text_records::read_small_file(path)
            .with_context(|| format!("reading the plan {}", path.display()))?;
        Self::parse(&path.display().to_string(), &text, overrides)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_wells_build_and_overrides_are_checked() {
        let none = DrillingOverrides::default();
        let short = Well::builtin("100m", &none).expect("built in");
        assert!((short.lateral_length_m() - 100.0).abs() < 1e-6);
        let long = Well::builtin("1000m", &none).expect("built in");
        assert!(long.lateral_length_m() > 900.0);
        let fast = DrillingOverrides {
            rop_m_per_h: Some(60.0),
            ..none
        };
        assert_eq!(
            Well::builtin("100m", &fast)
                .expect("ok")
                .plan
                .drilling
                .rop_m_per_h,
            60.0
        );
        let bad = DrillingOverrides {
            stand_length_m: Some(0.0),
            ..none
        };
        let e = format!("{:#}", Well::builtin("100m", &bad).unwrap_err());
        assert!(e.contains("drilling.stand_length_m"), "{e}");
        let indexed = DrillingOverrides {
            connection_dwells: Some(4),
            ..none
        };
        let plan = Well::builtin("1000m", &indexed).expect("ok").plan;
        assert_eq!(plan.drilling.connection_dwells, 4);
        let bad = DrillingOverrides {
            connection_dwells: Some(0),
            ..none
        };
        let e = format!("{:#}", Well::builtin("100m", &bad).unwrap_err());
        assert!(e.contains("drilling.connection_dwells"), "{e}");
        let straight = DrillingOverrides {
            tortuosity_deg_per_30m: Some(0.0),
            ..none
        };
        let plan = Well::builtin("100m", &straight).expect("ok").plan;
        assert_eq!(plan.drilling.tortuosity.rms_deg_per_30m, 0.0);
        let bad = DrillingOverrides {
            tortuosity_length_m: Some(0.0),
            ..none
        };
        let e = format!("{:#}", Well::builtin("100m", &bad).unwrap_err());
        assert!(
            e.contains("drilling.tortuosity.correlation_length_m"),
            "{e}"
        );
        assert!(Well::builtin("10km", &none).is_err());
    }
}
