//! Gyro grades as data files (`host-sim/data/grades/*.json`):
//! a gyro's figures in datasheet units with the documents they come from
//! (`sources`) and what those documents do not say (`assumptions`). The
//! four files of the repository are built in, so the binary works from
//! any directory; `study lateral --grade-file F` adds or replaces one.
//!
//! Only the gyros (body x and z) change with the grade. Every grade keeps
//! the SCC1300-D04's accelerometers and the tool-axis (y) "rate" derived
//! from their roll (paper eq. 1-2): the question the study answers is
//! which gyro meets the requirement, so the file must say
//! `"accelerometers": "scc1300"`.
//!
//! A grade gives the simulator its sensors ([`Grade::sensor_model`]) and
//! the navigator the same figures as its error budget
//! ([`Grade::noise_budget`], `Navigator::set_noise_budget`), so the filter
//! models the gyro it is given. `"scc1300_part": true` says the gyro is
//! the probe's own part: the simulator then adds the part's deterministic
//! errors (paper Table 3) and rounds to its LSB, and the navigator reads
//! the probe's raw frames and removes those errors by its calibration
//! (exactly today's `study drilling-coverage`). Other parts are read at
//! full resolution as calibrated samples: the SCC1300's 18 LSB per deg/s
//! (0.056 deg/s) would round a navigation-grade gyro's earth rate
//! (15 deg/h = 0.004 deg/s) away.
//!
//! The residual bias after calibration: `gyro.residual_bias_deg_per_h`
//! when the file gives it, else equal to the bias instability (the
//! figure datasheets give; nothing better is known of a part calibrated
//! in the well). [`Grade::with_gyro`] (a sweep over bias and ARW) keeps
//! the file's ratio of residual bias to instability (1 when the file
//! gives no residual), and scales the file's coloured (AR) noise with the
//! ARW (both are the part's short-term noise).

use crate::analysis::ar_file::{check_ar, ArQuantity};
use crate::formats::ranges::Range;
use crate::formats::text_records::excerpt;
use crate::sim::model_file::Ar4File;
use crate::sim::{DeterministicErrors, SensorModel};
use anyhow::{bail, ensure, Context, Result};
use mwd_core::ar::Ar4;
use mwd_core::conventions::DEG;
use mwd_core::sensor_noise::{
    arw_from_deg_per_sqrt_hour, rate_from_deg_per_hour, AxisNoise, ImuNoise, SCC1300_NOISE,
};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The built-in grade files, in the study's default order.
pub const BUILTIN: [(&str, &str); 4] = [
    ("scc1300", include_str!("../../data/grades/scc1300.json")),
    (
        "high-end-mems",
        include_str!("../../data/grades/high-end-mems.json"),
    ),
    (
        "ge-mwd-2020",
        include_str!("../../data/grades/ge-mwd-2020.json"),
    ),
    (
        "navigation",
        include_str!("../../data/grades/navigation.json"),
    ),
];

/// A document a grade's figures come from.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Source {
    pub document: String,
    /// Revision, edition or year.
    pub revision: String,
    /// The figures taken from it, as it states them.
    pub figures: Vec<String>,
}

/// The gyros' figures (body x and z alike), datasheet units.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GyroFigures {
    pub arw_deg_per_sqrt_h: f64,
    /// 1-sigma of the first-order Gauss-Markov bias instability.
    pub bias_instability_deg_per_h: f64,
    pub correlation_time_s: f64,
    /// 1-sigma bias left after calibration; absent: the bias instability.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residual_bias_deg_per_h: Option<f64>,
    /// AR(4) noise on top of the white noise (the paper's sign
    /// convention; variance in (deg/s)^2); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coloured_noise_x: Option<Ar4File>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coloured_noise_z: Option<Ar4File>,
}

/// A grade file as written.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GradeFile {
    /// What `--grades` calls it: lower-case letters, digits and '-'.
    pub name: String,
    pub title: String,
    /// The gyro is the probe's SCC1300 (deterministic errors, LSB, raw
    /// frames: module docs).
    pub scc1300_part: bool,
    /// Must be "scc1300" (module docs).
    pub accelerometers: String,
    pub gyro: GyroFigures,
    pub sources: Vec<Source>,
    pub assumptions: Vec<String>,
}

/// The range of every figure of a grade file: a value outside is a unit
/// mistake. Zero ARW or instability is refused: no gyro has none, and the
/// filter needs a positive variance in every state.
pub mod limits {
    use crate::formats::ranges::Range;

    pub const ARW_DEG_PER_SQRT_H: Range = Range::new(1e-6, 10.0, "deg/sqrt(h)");
    pub const BIAS_INSTABILITY_DEG_PER_H: Range = Range::new(1e-6, 1000.0, "deg/h");
    pub const RESIDUAL_BIAS_DEG_PER_H: Range = Range::new(0.0, 1000.0, "deg/h");
    /// As the sensor model file's (`sim::model_file::limits`).
    pub const CORRELATION_TIME_S: Range = crate::sim::model_file::limits::CORRELATION_TIME_S;
    /// AR innovation variance: positive, at most the full scale (300 deg/s)
    /// squared.
    pub const AR_VARIANCE_DEG2_PER_S2: Range = Range::new(1e-30, 9e4, "(deg/s)^2");
    pub const NAME_LENGTH: usize = 40;
}

/// A checked grade: the file and the error budget made from it.
#[derive(Clone, Debug)]
pub struct Grade {
    pub file: GradeFile,
    /// The budget, `'static` for `Navigator::set_noise_budget`: the
    /// SCC1300's own static when it is that, else leaked once per grade
    /// (a few hundred bytes; a study makes a handful).
    budget: &'static ImuNoise,
}

impl PartialEq for Grade {
    fn eq(&self, other: &Self) -> bool {
        self.file == other.file && self.budget == other.budget
    }
}

/// The AR(4) model of a file entry in SI: variance v (deg/s)^2 times
/// DEG^2 in the order `mwd_core::ar` computes it, so the SCC1300's file
/// gives its models to the bit.
fn coloured(entry: &Option<Ar4File>) -> Option<Ar4> {
    entry
        .as_ref()
        .map(|f| Ar4::new(f.a, f.noise_variance * (DEG * DEG)))
}

impl GradeFile {
    /// Checks every field (ranges, names, sources).
    pub fn check(&self) -> Result<()> {
        let n = &self.name;
        ensure!(
            !n.is_empty()
                && n.len() <= limits::NAME_LENGTH
                && n.bytes()
                    .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-'),
            "`name` \"{}\" must be 1 to {} lower-case letters, digits or '-' (it is what \
             --grades calls the grade)",
            excerpt(n),
            limits::NAME_LENGTH
        );
        ensure!(
            self.accelerometers == "scc1300",
            "`accelerometers` is \"{}\": only \"scc1300\" is modelled (every grade keeps the \
             SCC1300-D04's accelerometers; the study is of the gyro)",
            excerpt(&self.accelerometers)
        );
        let g = &self.gyro;
        limits::ARW_DEG_PER_SQRT_H.check("gyro.arw_deg_per_sqrt_h", g.arw_deg_per_sqrt_h)?;
        limits::BIAS_INSTABILITY_DEG_PER_H.check(
            "gyro.bias_instability_deg_per_h",
            g.bias_instability_deg_per_h,
        )?;
        limits::CORRELATION_TIME_S.check("gyro.correlation_time_s", g.correlation_time_s)?;
        if let Some(r) = g.residual_bias_deg_per_h {
            limits::RESIDUAL_BIAS_DEG_PER_H.check("gyro.residual_bias_deg_per_h", r)?;
        }
        for (field, entry) in [
            ("gyro.coloured_noise_x", &g.coloured_noise_x),
            ("gyro.coloured_noise_z", &g.coloured_noise_z),
        ] {
            if let Some(f) = entry {
                limits::AR_VARIANCE_DEG2_PER_S2
                    .check(&format!("{field}.noise_variance"), f.noise_variance)?;
                check_ar(&f.a, f.noise_variance, ArQuantity::Other)
                    .with_context(|| format!("`{field}`"))?;
            }
        }
        ensure!(
            !self.sources.is_empty(),
            "`sources` is empty: a grade names the documents its figures come from"
        );
        for (i, s) in self.sources.iter().enumerate() {
            ensure!(
                !s.document.trim().is_empty() && !s.figures.is_empty(),
                "`sources[{i}]` needs a `document` and the `figures` taken from it"
            );
        }
        Ok(())
    }

    /// The error budget: the SCC1300's accelerometers and tool-axis rate,
    /// the file's gyros on body x and z.
    fn budget(&self) -> ImuNoise {
        let g = &self.gyro;
        let scc = ImuNoise::scc1300();
        let instability = rate_from_deg_per_hour(g.bias_instability_deg_per_h);
        let gyro = |entry: &Option<Ar4File>| AxisNoise {
            white_density: arw_from_deg_per_sqrt_hour(g.arw_deg_per_sqrt_h),
            coloured: coloured(entry),
            bias_instability: instability,
            correlation_time: g.correlation_time_s,
            residual_bias: g
                .residual_bias_deg_per_h
                .map_or(instability, rate_from_deg_per_hour),
        };
        ImuNoise {
            accel: scc.accel,
            gyro: [
                gyro(&g.coloured_noise_x),
                scc.gyro[1],
                gyro(&g.coloured_noise_z),
            ],
        }
    }
}

impl Grade {
    /// A grade from a checked file.
    pub fn new(file: GradeFile) -> Result<Self> {
        file.check()?;
        let noise = file.budget();
        let budget: &'static ImuNoise = if noise == SCC1300_NOISE {
            &SCC1300_NOISE
        } else {
            Box::leak(Box::new(noise))
        };
        Ok(Self { file, budget })
    }

    /// A grade from JSON text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let file: GradeFile = serde_json::from_str(text)
            .with_context(|| format!("{origin} is not a gyro grade file (JSON)"))?;
        Self::new(file).with_context(|| format!("gyro grade in {origin}"))
    }

    /// A grade file from disk.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::formats::text_records::read_small_file(path)
            .with_context(|| format!("reading the grade file {}", path.display()))?;
        Self::parse(&text, &path.display().to_string())
    }

    /// The four built-in grades, in [`BUILTIN`]'s order.
    pub fn builtin() -> Result<Vec<Self>> {
        BUILTIN
            .iter()
            .map(|(name, text)| Self::parse(text, &format!("the built-in grade {name}")))
            .collect()
    }

    /// The built-in SCC1300 grade (the drilling-coverage study's).
    pub fn scc1300() -> Result<Self> {
        Self::parse(BUILTIN[0].1, "the built-in grade scc1300")
    }

    pub fn name(&self) -> &str {
        &self.file.name
    }

    /// Whether the gyro is the probe's SCC1300 (raw frames, LSB,
    /// deterministic errors calibrated away).
    pub fn is_scc1300_part(&self) -> bool {
        self.file.scc1300_part
    }

    /// The navigator's error budget (module docs).
    pub fn noise_budget(&self) -> ImuNoise {
        *self.budget
    }

    /// The same for `Navigator::set_noise_budget`.
    pub fn budget_ref(&self) -> &'static ImuNoise {
        self.budget
    }

    /// The simulator's sensors, seeded: the budget's noise, and for the
    /// SCC1300 part its deterministic errors and LSB
    /// (`SensorModel::scc1300`); other parts calibrated, unrounded.
    pub fn sensor_model(&self, seed: u64) -> SensorModel {
        let scc = self.is_scc1300_part();
        SensorModel {
            deterministic: if scc {
                DeterministicErrors::paper_table3()
            } else {
                DeterministicErrors::none()
            },
            noise: *self.budget,
            quantize: scc,
            seed,
        }
    }

    /// This grade with the gyros' bias instability (deg/h) and ARW
    /// (deg/sqrt(h)) replaced, for a sweep: the residual bias keeps the
    /// file's ratio to the instability, the coloured noise scales with
    /// the ARW (module docs). Named `<name>@<bias>deg/h,<arw>deg/rt-h`.
    pub fn with_gyro(
        &self,
        bias_instability_deg_per_h: f64,
        arw_deg_per_sqrt_h: f64,
    ) -> Result<Self> {
        let mut file = self.file.clone();
        let old = file.gyro.clone();
        limits::BIAS_INSTABILITY_DEG_PER_H
            .check("the sweep's bias instability", bias_instability_deg_per_h)?;
        limits::ARW_DEG_PER_SQRT_H.check("the sweep's ARW", arw_deg_per_sqrt_h)?;
        let bias_ratio = bias_instability_deg_per_h / old.bias_instability_deg_per_h;
        let arw_ratio = arw_deg_per_sqrt_h / old.arw_deg_per_sqrt_h;
        file.gyro.bias_instability_deg_per_h = bias_instability_deg_per_h;
        file.gyro.arw_deg_per_sqrt_h = arw_deg_per_sqrt_h;
        file.gyro.residual_bias_deg_per_h = old.residual_bias_deg_per_h.map(|r| r * bias_ratio);
        for ar in [
            &mut file.gyro.coloured_noise_x,
            &mut file.gyro.coloured_noise_z,
        ]
        .into_iter()
        .flatten()
        {
            ar.noise_variance *= arw_ratio * arw_ratio;
        }
        file.title = format!(
            "{} with bias instability {} deg/h and ARW {} deg/sqrt(h)",
            file.title,
            crate::formats::ranges::number(bias_instability_deg_per_h),
            crate::formats::ranges::number(arw_deg_per_sqrt_h)
        );
        Self::new(file).context("the swept grade")
    }
}

/// The grades named in `names` (all built-in ones when empty) with the
/// files' grades added or replacing a built-in of the same name.
pub fn select(names: &[String], files: &[std::path::PathBuf]) -> Result<Vec<Grade>> {
    let from_files = files
        .iter()
        .map(|path| Grade::load(path))
        .collect::<Result<Vec<_>>>()?;
    select_parsed(names, from_files)
}

/// [`select`] with the grade files already read, in their order.
pub fn select_parsed(names: &[String], from_files: Vec<Grade>) -> Result<Vec<Grade>> {
    let mut all = Grade::builtin()?;
    for grade in from_files {
        match all.iter_mut().find(|g| g.name() == grade.name()) {
            Some(slot) => *slot = grade,
            None => all.push(grade),
        }
    }
    if names.is_empty() {
        return Ok(all);
    }
    let mut chosen = Vec::new();
    for name in names {
        let Some(g) = all.iter().find(|g| g.name() == name) else {
            let known: Vec<&str> = all.iter().map(|g| g.name()).collect();
            bail!(
                "no gyro grade \"{}\": the grades are {} (a --grade-file adds one)",
                excerpt(name),
                known.join(", ")
            );
        };
        if !chosen.iter().any(|c: &Grade| c.name() == name) {
            chosen.push(g.clone());
        }
    }
    Ok(chosen)
}

/// Ranges, for the docs: `(field, range)`.
pub fn ranges() -> [(&'static str, Range); 5] {
    [
        ("gyro.arw_deg_per_sqrt_h", limits::ARW_DEG_PER_SQRT_H),
        (
            "gyro.bias_instability_deg_per_h",
            limits::BIAS_INSTABILITY_DEG_PER_H,
        ),
        ("gyro.correlation_time_s", limits::CORRELATION_TIME_S),
        (
            "gyro.residual_bias_deg_per_h",
            limits::RESIDUAL_BIAS_DEG_PER_H,
        ),
        (
            "gyro.coloured_noise_*.noise_variance",
            limits::AR_VARIANCE_DEG2_PER_S2,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scc1300_file_is_the_built_in_model_to_the_bit() {
        let g = Grade::scc1300().expect("the built-in file");
        assert_eq!(g.noise_budget(), ImuNoise::scc1300());
        assert!(std::ptr::eq(g.budget_ref(), &SCC1300_NOISE));
        assert_eq!(g.sensor_model(7), SensorModel::scc1300(7));
        assert!(g.is_scc1300_part());
    }

    #[test]
    fn every_built_in_grade_parses_with_sources_and_the_scc1300_accelerometers() {
        let all = Grade::builtin().expect("the built-in files");
        let names: Vec<&str> = all.iter().map(Grade::name).collect();
        assert_eq!(
            names,
            ["scc1300", "high-end-mems", "ge-mwd-2020", "navigation"]
        );
        let scc = ImuNoise::scc1300();
        for g in &all {
            let b = g.noise_budget();
            assert_eq!(b.accel, scc.accel, "{}", g.name());
            assert_eq!(b.gyro[1], scc.gyro[1], "{}", g.name());
            assert!(!g.file.sources.is_empty() && !g.file.assumptions.is_empty());
            if g.name() != "scc1300" {
                assert!(!g.is_scc1300_part());
                let m = g.sensor_model(1);
                assert!(!m.quantize);
                assert_eq!(m.deterministic, DeterministicErrors::none());
                // better than the SCC1300 on both figures
                assert!(b.gyro[0].white_density < scc.gyro[0].white_density / 10.0);
                assert!(b.gyro[2].bias_instability < scc.gyro[2].bias_instability);
                assert_eq!(b.gyro[0].residual_bias, b.gyro[0].bias_instability);
            }
        }
        // the GE figures as Lin et al. (GE Research, 2020) report them
        let ge = &all[2].noise_budget().gyro[0];
        assert!((ge.white_density - arw_from_deg_per_sqrt_hour(0.003)).abs() < 1e-18);
        assert!((ge.bias_instability - rate_from_deg_per_hour(0.01)).abs() < 1e-18);
    }

    #[test]
    fn bad_files_are_refused_with_the_field_named() {
        let base: serde_json::Value =
            serde_json::from_str(BUILTIN[3].1).expect("the navigation file");
        let refused = |edit: &dyn Fn(&mut serde_json::Value), needle: &str| {
            let mut v = base.clone();
            edit(&mut v);
            let e = format!(
                "{:#}",
                Grade::parse(&v.to_string(), "test.json").unwrap_err()
            );
            assert!(e.contains(needle), "{needle:?} not in {e}");
            assert!(e.contains("test.json"), "{e}");
        };
        refused(
            &|v| v["gyro"]["arw_deg_per_sqrt_h"] = (-1.0).into(),
            "`gyro.arw_deg_per_sqrt_h` is -1 deg/sqrt(h), outside its range",
        );
        refused(
            &|v| v["gyro"]["bias_instability_deg_per_h"] = 1e9.into(),
            "`gyro.bias_instability_deg_per_h` is 1e9 deg/h",
        );
        refused(
            &|v| v["gyro"]["correlation_time_s"] = 0.0.into(),
            "`gyro.correlation_time_s` is 0 s",
        );
        refused(
            &|v| v["accelerometers"] = "stim300".into(),
            "only \"scc1300\"",
        );
        refused(
            &|v| v["sources"] = serde_json::json!([]),
            "`sources` is empty",
        );
        refused(&|v| v["name"] = "Nav Grade".into(), "lower-case letters");
        refused(&|v| v["gyro"]["arw"] = 1.0.into(), "unknown field `arw`");
        refused(
            &|v| {
                v["gyro"]["coloured_noise_x"] =
                    serde_json::json!({"a": [-2.0, 1.0, 0.0, 0.0], "noise_variance": 1e-7})
            },
            "`gyro.coloured_noise_x`",
        );
        assert!(format!("{:#}", Grade::parse("{", "x.json").unwrap_err())
            .contains("x.json is not a gyro grade file"));
    }

    #[test]
    fn a_sweep_point_follows_the_rule_for_the_residual_and_the_coloured_noise() {
        let scc = Grade::scc1300().expect("built in");
        let swept = scc.with_gyro(0.021, 0.0086).expect("in range");
        let b = swept.noise_budget();
        assert!((b.gyro[0].bias_instability - rate_from_deg_per_hour(0.021)).abs() < 1e-18);
        // the SCC1300 file's residual equals its instability: so does the sweep's
        assert!((b.gyro[2].residual_bias / b.gyro[2].bias_instability - 1.0).abs() < 1e-12);
        let ar0 = ImuNoise::scc1300().gyro[0]
            .coloured
            .expect("paper AR")
            .noise_variance;
        let ar = b.gyro[0].coloured.expect("kept").noise_variance;
        assert!((ar / ar0 - 1e-4).abs() < 1e-12, "{ar} {ar0}");
        assert_eq!(b.gyro[1], ImuNoise::scc1300().gyro[1]);
        assert!(!std::ptr::eq(swept.budget_ref(), &SCC1300_NOISE));
        // a file without a residual: the sweep's residual is its instability
        let nav = &Grade::builtin().expect("built in")[3];
        let n = nav.with_gyro(1.0, 0.1).expect("in range").noise_budget();
        assert_eq!(n.gyro[0].residual_bias, n.gyro[0].bias_instability);
        assert!(scc.with_gyro(0.0, 0.1).is_err());
    }

    #[test]
    fn selection_by_name_and_file() {
        let dir = std::env::temp_dir().join(format!("grade-select-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("mine.json");
        let mut v: serde_json::Value = serde_json::from_str(BUILTIN[1].1).expect("json");
        v["name"] = "mine".into();
        std::fs::write(&path, v.to_string()).expect("write");
        let all = select(&[], std::slice::from_ref(&path)).expect("select");
        assert_eq!(all.len(), 5);
        let two = select(&["mine".into(), "scc1300".into()], &[path]).expect("select");
        assert_eq!(two[0].name(), "mine");
        assert_eq!(two[1].name(), "scc1300");
        let e = select(&["tactical".into()], &[]).unwrap_err().to_string();
        assert!(
            e.contains("no gyro grade \"tactical\"") && e.contains("navigation"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(dir);
    }
}
