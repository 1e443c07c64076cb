//! `host-sim survey`: positions of a survey's stations by minimum curvature
//! and, with `--error-model`, their ISCWSA position uncertainty and error
//! ellipse; a listing on the terminal and CSV, JSON, WITSML exports.
use super::limits::number_in;
use super::site::SiteArgs;
use anyhow::{bail, Context, Result};
use host_sim::survey::iscwsa::Site;
use host_sim::survey::job::{Job, SurveyJob};
use host_sim::survey::listing::separation as sep;
use host_sim::survey::listing::{
    self as listing, ellipse::scale_2d, plot, AzimuthReference, KnownModel, LengthUnit, Row,
    StationFile, TieOnInput,
};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::config::default_still_settings;
use mwd_core::earth::Position;
use mwd_core::probe::TieIn;
use mwd_core::protocol::uplink::StillSettings;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// North reference of the file's azimuths.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Reference {
    True,
    Grid,
}

/// Tie-on numbers, in the file's length unit.
fn tie_on(text: &str) -> Result<f64, String> {
    number_in(text, "a tie-on value", (-1e6, 1e6), "(file's length unit)")
}
fn convergence_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the grid convergence", (-90.0, 90.0), "deg")
}
fn b_total_nt(text: &str) -> Result<f64, String> {
    number_in(text, "the total field", (1.0, 100_000.0), "nT")
}
fn dip_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the dip", (-90.0, 90.0), "deg")
}
fn declination_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the declination", (-180.0, 180.0), "deg")
}
fn azimuth_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the vertical-section azimuth", (0.0, 360.0), "deg")
}
fn radius_m(text: &str) -> Result<f64, String> {
    number_in(text, "a hole radius", (0.0, 10.0), "m")
}
fn margin_m(text: &str) -> Result<f64, String> {
    number_in(text, "the margin", (0.0, 100.0), "m")
}
fn confidence(text: &str) -> Result<f64, String> {
    let p = number_in(text, "the confidence", (0.0, 1.0), "(probability)")?;
    if p == 0.0 || p == 1.0 {
        return Err("the confidence must be between 0 and 1, exclusive".into());
    }
    Ok(p)
}

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Station CSV: header with md_m (or md_ft), inc_deg, azi_deg; optional
    /// toolface_deg, time_s. With --depth: a probe capture (.bin) whose
    /// station surveys are listed (docs/drilling-survey.md).
    pub stations: PathBuf,
    /// The capture's options (boxed, as `sep`).
    #[command(flatten)]
    pub capture: Box<super::survey_capture::CaptureArgs>,
    #[command(flatten)]
    pub site: SiteArgs,
    /// The site as three numbers, the same as --lat --lon --height (and
    /// the way to override a job's site).
    #[arg(long = "site", num_args = 3, value_names = ["LAT", "LON", "HEIGHT"],
          allow_negative_numbers = true, conflicts_with_all = ["lat", "lon", "height"])]
    pub site_numbers: Option<Vec<f64>>,
    /// A job file (host-sim/src/job.rs): its site, survey tie-on (in its
    /// length unit, converted to the file's) and error model; the flags
    /// given override it (its site: with --site, not --lat/--lon/--height).
    #[arg(long, value_name = "JOB.json", conflicts_with_all = ["lat", "lon", "height"])]
    pub job: Option<PathBuf>,
    /// North reference of the azimuths (grid: give --convergence-deg).
    #[arg(long, value_enum, default_value_t = Reference::True)]
    pub azimuth_reference: Reference,
    /// Grid convergence, deg: true azimuth = grid azimuth + convergence.
    #[arg(long, allow_hyphen_values = true, value_parser = convergence_deg)]
    pub convergence_deg: Option<f64>,
    /// MD of the tie-on (file's unit): must be the first station's MD.
    #[arg(long, allow_hyphen_values = true, value_parser = tie_on)]
    pub tie_on_md: Option<f64>,
    /// TVD of the tie-on (file's unit).
    #[arg(long, allow_hyphen_values = true, value_parser = tie_on)]
    pub tie_on_tvd: Option<f64>,
    /// North of the tie-on (file's unit, true north).
    #[arg(long, allow_hyphen_values = true, value_parser = tie_on)]
    pub tie_on_north: Option<f64>,
    /// East of the tie-on (file's unit, true north).
    #[arg(long, allow_hyphen_values = true, value_parser = tie_on)]
    pub tie_on_east: Option<f64>,
    /// Error model: "ISCWSA MWD Rev5" (Rev 5.10), "GYRO-MWD", "GYRO-NS",
    /// "PROBE-SCC1300" (this probe, through 90 deg; at the SCC1300's noise
    /// every station is beyond its first-order limit: docs/probe-tool-model.md).
    #[arg(long)]
    pub error_model: Option<String>,
    /// Error model from a term table (CSV in the format of host-sim/data/,
    /// e.g. the probe's table with another gyro's magnitudes). Validity:
    /// the probe's rule (azimuth sensitivity and first-order azimuth sigma
    /// limit, docs/probe-tool-model.md) if it has PRB-G* gyro terms, 89 deg
    /// inclination if it has GXY-* terms, else none. Not with --error-model.
    #[arg(long, conflicts_with = "error_model")]
    pub error_model_file: Option<PathBuf>,
    /// Total magnetic field, nT (magnetic models).
    #[arg(long, value_parser = b_total_nt)]
    pub b_total_nt: Option<f64>,
    /// Magnetic dip, deg (magnetic models).
    #[arg(long, allow_hyphen_values = true, value_parser = dip_deg)]
    pub dip_deg: Option<f64>,
    /// Magnetic declination, deg (magnetic models).
    #[arg(long, allow_hyphen_values = true, value_parser = declination_deg)]
    pub declination_deg: Option<f64>,
    /// Probability held by the scaled horizontal ellipse (2-D normal).
    #[arg(long, default_value_t = 0.95, value_parser = confidence)]
    pub confidence: f64,
    /// Vertical-section azimuth, deg (default: closure of the last station).
    #[arg(long, value_parser = azimuth_deg)]
    pub vsec_azimuth_deg: Option<f64>,
    /// Write one row per station here (CSV).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write the survey here (JSON).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write a WITSML 1.4.1.1 trajectory here (XML).
    #[arg(long)]
    pub witsml: Option<PathBuf>,
    /// Write plan.svg/.png and section.svg/.png (path and 2-sigma error
    /// ellipses) into this directory (created if missing).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// The offset well and the separation rule's inputs (boxed: they
    /// would make every command's argument enum as large as this one).
    #[command(flatten)]
    pub sep: Box<OffsetArgs>,
}

/// Anti-collision options.
#[derive(clap::Args, Debug)]
pub struct OffsetArgs {
    /// Offset well (same CSV format and length unit): closest point,
    /// centre-to-centre distance and ISCWSA separation factor per station.
    #[arg(long)]
    pub offset: Option<PathBuf>,
    /// MD of the offset's tie-on (file's unit): its first station's MD.
    #[arg(long, allow_hyphen_values = true, value_parser = tie_on)]
    pub offset_tie_on_md: Option<f64>,
    /// TVD of the offset's tie-on (file's unit).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = tie_on)]
    pub offset_tie_on_tvd: f64,
    /// North of the offset's tie-on (file's unit, true north).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = tie_on)]
    pub offset_tie_on_north: f64,
    /// East of the offset's tie-on (file's unit, true north).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = tie_on)]
    pub offset_tie_on_east: f64,
    /// Error model of the offset well (default: --error-model or
    /// --error-model-file).
    #[arg(long)]
    pub offset_error_model: Option<String>,
    /// Open-hole radius of the reference well, m (needed with --offset).
    #[arg(long, allow_hyphen_values = true, value_parser = radius_m)]
    pub hole_radius_m: Option<f64>,
    /// Open-hole radius of the offset well, m (needed with --offset).
    #[arg(long, allow_hyphen_values = true, value_parser = radius_m)]
    pub offset_hole_radius_m: Option<f64>,
    /// Surface margin S_m of the separation rule, m.
    #[arg(long, default_value_t = sep::SURFACE_MARGIN_M, allow_hyphen_values = true, value_parser = margin_m)]
    pub surface_margin_m: f64,
    /// Project-ahead 1-sigma uncertainty sigma_pa of the separation rule, m.
    #[arg(long, default_value_t = sep::SIGMA_PA_M, allow_hyphen_values = true, value_parser = margin_m)]
    pub sigma_pa_m: f64,
}

/// The offset well's separation from the reference stations.
struct Offset {
    name: String,
    model: Option<&'static KnownModel>,
    rule: sep::Rule,
    seps: Vec<sep::Separation>,
    /// The offset's file name (figures' legend) and its rows.
    short_name: String,
    rows: Vec<Row>,
}

/// What the outputs need besides the rows.
struct Survey {
    rows: Vec<Row>,
    vsec_azimuth_deg: f64,
    model: Option<&'static KnownModel>,
    /// First station the model is not valid at.
    invalid_from: Option<listing::Invalid>,
    confidence: f64,
    /// Length unit of the station file (the figures use it).
    unit: LengthUnit,
    offset: Option<Offset>,
}

/// The survey's inputs that a job file may give (flags override it).
pub struct Resolved {
    /// Latitude of the site, rad.
    pub latitude: f64,
    pub job: SurveyJob,
    /// The probe's configuration for a capture's replay (`survey_capture`):
    /// the site, the job's calibration, still settings and tie-in (else
    /// none, the probe's defaults, none).
    pub probe: ProbeSetup,
}

/// What a capture's replay needs of the probe's configuration.
pub struct ProbeSetup {
    pub site: Position,
    pub calibration: ProbeCalibration,
    pub still: StillSettings,
    pub tie_in: Option<TieIn>,
}

impl Resolved {
    fn new(args: &Args) -> Result<Self> {
        let job = args.job.as_deref().map(Job::load).transpose()?;
        let site = match (args.site_numbers.as_deref(), &job) {
            (Some(&[lat, lon, height]), _) => super::site::checked_position(lat, lon, height)?,
            (_, Some(job)) => job.site,
            _ => args.site.position(),
        };
        let probe = ProbeSetup {
            site,
            calibration: job
                .as_ref()
                .and_then(|j| j.calibration.as_ref())
                .map_or_else(ProbeCalibration::default, |(_, c)| *c),
            still: job
                .as_ref()
                .and_then(|j| j.still)
                .unwrap_or_else(default_still_settings),
            tie_in: job.as_ref().and_then(|j| j.tie_in),
        };
        Ok(Self {
            latitude: site.lat,
            job: job.map(|j| j.survey).unwrap_or_default(),
            probe,
        })
    }

    /// The tie-on in `unit` (the input file's): each flag given, else the
    /// job's (converted to `unit`), else the surface (MD: the first
    /// station's).
    pub fn tie_on(&self, args: &Args, unit: LengthUnit) -> TieOnInput {
        let job = self.job.tie_on.in_unit(unit);
        TieOnInput {
            md: args.tie_on_md.or(job.md),
            tvd: args.tie_on_tvd.or(job.tvd).unwrap_or(0.0),
            north: args.tie_on_north.or(job.north).unwrap_or(0.0),
            east: args.tie_on_east.or(job.east).unwrap_or(0.0),
        }
    }

    /// `--error-model`, else the job's (not with `--error-model-file`).
    fn error_model<'a>(&'a self, args: &'a Args) -> Option<&'a str> {
        match (&args.error_model, &args.error_model_file) {
            (Some(name), _) => Some(name),
            (None, Some(_)) => None,
            (None, None) => self.job.error_model.as_deref(),
        }
    }
}

pub fn run(args: Args) -> Result<()> {
    let resolved = Resolved::new(&args)?;
    let o = &args.sep;
    if o.offset.is_none() {
        let given = [
            ("--offset-tie-on-md", o.offset_tie_on_md.is_some()),
            ("--offset-error-model", o.offset_error_model.is_some()),
            ("--hole-radius-m", o.hole_radius_m.is_some()),
            ("--offset-hole-radius-m", o.offset_hole_radius_m.is_some()),
        ];
        if let Some((flag, _)) = given.iter().find(|g| g.1) {
            bail!("{flag} needs --offset (an offset well)");
        }
    }
    if args.capture.depth.is_some() {
        return super::survey_capture::run(&args, &resolved);
    }
    if let Some(dir) = &args.plot {
        // refused before any work: a file in the way is the user's mistake
        host_sim::formats::figure::prepare_dir(dir)?;
    }
    let file = read(&args.stations)?;
    let mut survey = compute(&args, &resolved, &file)?;
    if let Some(path) = &args.sep.offset {
        survey.offset = Some(offset(&args, &resolved, path, &file, &survey)?);
    }
    report(&survey);
    write_outputs(&args, &survey)
}

fn read(path: &Path) -> Result<StationFile> {
    let input = std::fs::File::open(path).with_context(|| format!("{}", path.display()))?;
    listing::read_stations(input).with_context(|| format!("{}", path.display()))
}

fn compute(args: &Args, resolved: &Resolved, file: &StationFile) -> Result<Survey> {
    let reference = match (args.azimuth_reference, args.convergence_deg) {
        (Reference::True, None) => AzimuthReference::True,
        (Reference::True, Some(_)) => {
            bail!("--convergence-deg needs --azimuth-reference grid")
        }
        (Reference::Grid, Some(c)) => AzimuthReference::Grid(c.to_radians()),
        (Reference::Grid, None) => bail!("--azimuth-reference grid needs --convergence-deg"),
    };
    let tie = resolved.tie_on(args, file.unit);
    let vsec = args.vsec_azimuth_deg.map(f64::to_radians);
    let (mut rows, direction) = listing::compute(file, reference, tie, vsec)?;
    let model = match &args.error_model_file {
        Some(path) => Some(listing::model_from_file(path)?),
        None => resolved.error_model(args).map(listing::model).transpose()?,
    };
    let mut invalid_from = None;
    if let Some(m) = model {
        let terms = listing::terms(m)?;
        let site = model_site(args, resolved, m)?;
        invalid_from = listing::apply_model(&mut rows, m, &terms, &site)?;
    }
    Ok(Survey {
        rows,
        vsec_azimuth_deg: direction.to_degrees(),
        model,
        invalid_from,
        confidence: args.confidence,
        unit: file.unit,
        offset: None,
    })
}

/// The offset well positioned and given its covariance, and its separation
/// from every reference station.
fn offset(
    args: &Args,
    resolved: &Resolved,
    path: &Path,
    reference: &StationFile,
    s: &Survey,
) -> Result<Offset> {
    let (Some(ref_radius_m), Some(offset_radius_m)) =
        (args.sep.hole_radius_m, args.sep.offset_hole_radius_m)
    else {
        bail!("--offset needs --hole-radius-m and --offset-hole-radius-m (open-hole radii, m)");
    };
    let file = read(path).context("the offset well")?;
    if file.unit != reference.unit {
        bail!(
            "{}: the offset well's length unit differs from the reference well's (give both in m or both in ft)",
            path.display()
        );
    }
    let reference_azimuths = match (args.azimuth_reference, args.convergence_deg) {
        (Reference::Grid, Some(c)) => AzimuthReference::Grid(c.to_radians()),
        _ => AzimuthReference::True,
    };
    let tie = TieOnInput {
        md: args.sep.offset_tie_on_md,
        tvd: args.sep.offset_tie_on_tvd,
        north: args.sep.offset_tie_on_north,
        east: args.sep.offset_tie_on_east,
    };
    let (mut rows, _) = listing::compute(&file, reference_azimuths, tie, None)
        .with_context(|| format!("offset well {}", path.display()))?;
    // default: the reference well's model (named or from a file)
    let model = match args.sep.offset_error_model.as_deref() {
        Some(name) => Some(listing::model(name)?),
        None => s.model,
    };
    if let Some(m) = model {
        let terms = listing::terms(m)?;
        listing::apply_model(&mut rows, m, &terms, &model_site(args, resolved, m)?)
            .with_context(|| format!("offset well {}", path.display()))?;
    }
    let rule = sep::Rule {
        k: sep::K,
        surface_margin_m: args.sep.surface_margin_m,
        sigma_pa_m: args.sep.sigma_pa_m,
        ref_radius_m,
        offset_radius_m,
    };
    let seps = sep::separations(&s.rows, &rows, &rule)?;
    Ok(Offset {
        name: path.display().to_string(),
        model,
        rule,
        seps,
        short_name: path
            .file_name()
            .map_or_else(|| "offset".into(), |n| n.to_string_lossy().into_owned()),
        rows,
    })
}

fn sf_status(x: &sep::Separation) -> &'static str {
    match x.sf {
        None => "undetermined",
        Some(f) if f < 1.0 => "violation",
        Some(_) => "ok",
    }
}

/// The minimum SF and the violations, as lines of text.
fn separation_summary(s: &Survey) -> Vec<String> {
    let Some(o) = &s.offset else {
        return Vec::new();
    };
    let mut out = vec![format!(
        "offset {}: model {}; ISCWSA separation rule (Sawaryn et al. 2019, SPE-187073-PA): k {}, S_m {} m, sigma_pa {} m, hole radii {} m / {} m",
        o.name,
        o.model.map_or("none", |m| m.name),
        o.rule.k,
        o.rule.surface_margin_m,
        o.rule.sigma_pa_m,
        o.rule.ref_radius_m,
        o.rule.offset_radius_m
    )];
    match sep::minimum(&o.seps) {
        Some((i, f)) => out.push(format!(
            "minimum SF {:.3} at MD {:.2} m (offset MD {:.2} m, centre to centre {:.2} m +- {:.2} m 1-sigma)",
            f,
            s.rows[i].md_m,
            o.seps[i].closest.md_m,
            o.seps[i].ctc_m,
            o.seps[i].sigma_s_m.unwrap_or(f64::NAN)
        )),
        None => out.push("minimum SF undetermined: no station has both wells' covariance".into()),
    }
    let bad: Vec<usize> = (0..o.seps.len())
        .filter(|&i| sf_status(&o.seps[i]) == "violation")
        .collect();
    if let (Some(&a), Some(&b)) = (bad.first(), bad.last()) {
        out.push(format!(
            "VIOLATION of the separation rule (SF < 1) at {} stations, MD {:.2} to {:.2} m",
            bad.len(),
            s.rows[a].md_m,
            s.rows[b].md_m
        ));
    }
    let undetermined = o.seps.iter().filter(|x| x.sf.is_none()).count();
    if undetermined > 0 {
        out.push(format!(
            "SF undetermined at {undetermined} stations (a covariance missing: no model, or beyond its validity)"
        ));
    }
    out
}

fn model_site(args: &Args, resolved: &Resolved, model: &KnownModel) -> Result<Site> {
    let magnetic = |v: Option<f64>, flag: &str| match v {
        Some(v) => Ok(v),
        None if model.magnetic => bail!("--error-model {} needs {flag}", model.name),
        None => Ok(0.0),
    };
    Ok(Site {
        gravity: 9.806_65,
        b_total: magnetic(args.b_total_nt, "--b-total-nt")?,
        dip: magnetic(args.dip_deg, "--dip-deg")?.to_radians(),
        declination: magnetic(args.declination_deg, "--declination-deg")?.to_radians(),
        vertical_limit: 0.0001_f64.to_radians(),
        latitude: resolved.latitude,
        gyro_noise_reduction: 1.0,
    })
}

fn validity_note(s: &Survey) -> Option<String> {
    let (m, inv) = (s.model?, s.invalid_from.as_ref()?);
    Some(format!(
        "{} {}: no uncertainty from MD {:.2} m (station {}) on, not extrapolated",
        m.name, inv.reason, s.rows[inv.station].md_m, inv.station
    ))
}

fn report(s: &Survey) {
    outln!(
        "{} stations; N/E along true north, m; vertical section along {:.2} deg",
        s.rows.len(),
        s.vsec_azimuth_deg
    );
    if let Some(m) = s.model {
        outln!(
            "error model {}; ellipse at {:.1} % (2-D normal, k = {:.4} x 1-sigma)",
            m.name,
            100.0 * s.confidence,
            scale_2d(s.confidence)
        );
    }
    let mut head = format!(
        "{:>9} {:>7} {:>7} {:>9} {:>9} {:>9} {:>6} {:>9}",
        "MD m", "inc", "azi", "TVD m", "N m", "E m", "DLS", "VS m"
    );
    if s.model.is_some() {
        head += &format!(
            " {:>7} {:>7} {:>7} {:>8} {:>8} {:>6}",
            "sN m", "sE m", "sV m", "major m", "minor m", "az"
        );
    }
    if s.offset.is_some() {
        head += &format!(" {:>9} {:>7} {:>8}", "ctc m", "sS m", "SF");
    }
    outln!("{head}");
    for (k, r) in s.rows.iter().enumerate() {
        let mut line = format!(
            "{:>9.2} {:>7.2} {:>7.2} {:>9.2} {:>9.2} {:>9.2} {:>6.2} {:>9.2}",
            r.md_m, r.inc_deg, r.azi_deg, r.tvd_m, r.north_m, r.east_m, r.dls_deg_per_30m, r.vsec_m
        );
        if s.model.is_some() {
            match (r.cov, r.ellipse()) {
                (Some(c), Some(e)) => {
                    let (a, b) = e.scaled(s.confidence);
                    let _ = write!(
                        line,
                        " {:>7.2} {:>7.2} {:>7.2} {:>8.2} {:>8.2} {:>6.1}",
                        c[0].max(0.0).sqrt(),
                        c[1].max(0.0).sqrt(),
                        e.sigma_vert,
                        a,
                        b,
                        e.azimuth_deg
                    );
                }
                _ => line += "  (outside the model's validity)",
            }
        }
        if let Some(x) = s.offset.as_ref().map(|o| &o.seps[k]) {
            let _ = write!(line, " {:>9.2}", x.ctc_m);
            match (x.sigma_s_m, x.sf) {
                (Some(sig), Some(f)) => {
                    let flag = if f < 1.0 { " SF<1" } else { "" };
                    let _ = write!(line, " {sig:>7.2} {f:>8.3}{flag}");
                }
                _ => line += "  SF undetermined",
            }
        }
        outln!("{line}");
    }
    if let Some(note) = validity_note(s) {
        outln!("note: {note}");
    }
    for l in separation_summary(s) {
        outln!("{l}");
    }
}

fn write_outputs(args: &Args, s: &Survey) -> Result<()> {
    let write = |path: &Path, text: String| {
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
    };
    if let Some(p) = &args.csv {
        write(p, csv_text(s))?;
    }
    if let Some(p) = &args.json {
        write(p, json_text(s)?)?;
    }
    if let Some(p) = &args.witsml {
        write(p, witsml_text(s))?;
    }
    if let Some(dir) = &args.plot {
        let well = args
            .stations
            .file_stem()
            .map_or_else(|| "survey".into(), |n| n.to_string_lossy());
        let figures = plot::SurveyPlot {
            rows: &s.rows,
            unit: s.unit,
            vsec_azimuth: s.vsec_azimuth_deg.to_radians(),
            well: &well,
            model: s.model.map(|m| m.name),
            offset: s
                .offset
                .as_ref()
                .map(|o| (o.short_name.as_str(), o.rows.as_slice())),
        };
        let files = figures.write(dir)?;
        for f in files {
            outln!("wrote {}", f.display());
        }
    }
    Ok(())
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |v| v.to_string())
}

fn csv_text(s: &Survey) -> String {
    let mut out = String::from(
        "md_m,inc_deg,azi_deg,tvd_m,north_m,east_m,dls_deg_per_30m,vsec_m,toolface_deg,time_s",
    );
    if s.model.is_some() {
        out += ",sigma_north_m,sigma_east_m,sigma_vert_m,ellipse_semi_major_m,ellipse_semi_minor_m,ellipse_azimuth_deg,confidence,error_model_valid";
    }
    if s.offset.is_some() {
        out += ",offset_md_m,ctc_m,sigma_s_m,sf,sf_status";
    }
    out += "\n";
    for (k, r) in s.rows.iter().enumerate() {
        let _ = write!(
            out,
            "{},{},{},{},{},{},{},{},{},{}",
            r.md_m,
            r.inc_deg,
            r.azi_deg,
            r.tvd_m,
            r.north_m,
            r.east_m,
            r.dls_deg_per_30m,
            r.vsec_m,
            opt(r.input.toolface_deg),
            opt(r.input.time_s)
        );
        if s.model.is_some() {
            match (r.cov, r.ellipse()) {
                (Some(c), Some(e)) => {
                    let (a, b) = e.scaled(s.confidence);
                    let _ = write!(
                        out,
                        ",{},{},{},{a},{b},{},{},true",
                        c[0].max(0.0).sqrt(),
                        c[1].max(0.0).sqrt(),
                        e.sigma_vert,
                        e.azimuth_deg,
                        s.confidence
                    );
                }
                _ => {
                    let _ = write!(out, ",,,,,,,{},false", s.confidence);
                }
            }
        }
        if let Some(x) = s.offset.as_ref().map(|o| &o.seps[k]) {
            let _ = write!(
                out,
                ",{},{},{},{},{}",
                x.closest.md_m,
                x.ctc_m,
                opt(x.sigma_s_m),
                opt(x.sf),
                sf_status(x)
            );
        }
        out += "\n";
    }
    out
}

fn json_text(s: &Survey) -> Result<String> {
    let stations: Vec<serde_json::Value> = s
        .rows
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let mut v = serde_json::json!({
                "md_m": r.md_m, "inc_deg": r.inc_deg, "azi_deg": r.azi_deg,
                "tvd_m": r.tvd_m, "north_m": r.north_m, "east_m": r.east_m,
                "dls_deg_per_30m": r.dls_deg_per_30m, "vsec_m": r.vsec_m,
                "toolface_deg": r.input.toolface_deg, "time_s": r.input.time_s,
            });
            if s.model.is_some() {
                let e = r.ellipse();
                let scaled = e.map(|e| e.scaled(s.confidence));
                v["nev_covariance_m2"] = serde_json::json!(r.cov);
                v["sigma_north_m"] = serde_json::json!(r.cov.map(|c| c[0].max(0.0).sqrt()));
                v["sigma_east_m"] = serde_json::json!(r.cov.map(|c| c[1].max(0.0).sqrt()));
                v["sigma_vert_m"] = serde_json::json!(e.map(|e| e.sigma_vert));
                v["ellipse_semi_major_m"] = serde_json::json!(scaled.map(|x| x.0));
                v["ellipse_semi_minor_m"] = serde_json::json!(scaled.map(|x| x.1));
                v["ellipse_azimuth_deg"] = serde_json::json!(e.map(|e| e.azimuth_deg));
                v["error_model_valid"] = serde_json::json!(r.cov.is_some());
            }
            if let Some(x) = s.offset.as_ref().map(|o| &o.seps[k]) {
                let c = &x.closest;
                v["offset_md_m"] = serde_json::json!(c.md_m);
                v["offset_nev_m"] = serde_json::json!([c.nev.x, c.nev.y, c.nev.z]);
                v["offset_nev_covariance_m2"] = serde_json::json!(c.cov);
                v["ctc_m"] = serde_json::json!(x.ctc_m);
                v["sigma_s_m"] = serde_json::json!(x.sigma_s_m);
                v["sf"] = serde_json::json!(x.sf);
                v["sf_status"] = serde_json::json!(sf_status(x));
            }
            v
        })
        .collect();
    let doc = serde_json::json!({
        "north_reference": "true",
        "length_unit": "m",
        "vsec_azimuth_deg": s.vsec_azimuth_deg,
        "error_model": s.model.map(|m| m.name),
        "confidence": s.model.map(|_| s.confidence),
        "ellipse_convention": s.model.map(|_| "semi-axes: 1-sigma of the NE covariance times sqrt(-2 ln(1 - confidence)); azimuth of the major axis in [0, 180) deg; covariance [nn, ee, vv, ne, nv, ev] m^2"),
        "note": validity_note(s),
        "stations": stations,
    });
    let mut doc = doc;
    if let Some(o) = &s.offset {
        let min = sep::minimum(&o.seps);
        doc["separation"] = serde_json::json!({
            "offset": o.name,
            "offset_error_model": o.model.map(|m| m.name),
            "rule": "ISCWSA separation rule, Sawaryn et al. 2019 (SPE-187073-PA): SF = (D - R_ref - R_off - S_m) / (k sqrt(sigma_S^2 + sigma_pa^2)); offset covariance interpolated linearly in MD at the closest point",
            "k": o.rule.k,
            "surface_margin_m": o.rule.surface_margin_m,
            "sigma_pa_m": o.rule.sigma_pa_m,
            "hole_radius_m": o.rule.ref_radius_m,
            "offset_hole_radius_m": o.rule.offset_radius_m,
            "min_sf": min.map(|m| m.1),
            "min_sf_md_m": min.map(|m| s.rows[m.0].md_m),
            "violation": o.seps.iter().any(|x| x.sf.is_some_and(|f| f < 1.0)),
            "summary": separation_summary(s),
        });
    }
    Ok(serde_json::to_string_pretty(&doc)? + "\n")
}

fn witsml_text(s: &Survey) -> String {
    let mut x = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <trajectorys xmlns=\"http://www.witsml.org/schemas/1series\" version=\"1.4.1.1\">\n\
         \x20 <trajectory uidWell=\"well\" uidWellbore=\"wellbore\" uid=\"survey\">\n\
         \x20   <nameWell>well</nameWell>\n\
         \x20   <nameWellbore>wellbore</nameWellbore>\n\
         \x20   <name>host-sim survey</name>\n",
    );
    if let (Some(first), Some(last)) = (s.rows.first(), s.rows.last()) {
        let _ = writeln!(x, "    <mdMn uom=\"m\">{}</mdMn>", first.md_m);
        let _ = writeln!(x, "    <mdMx uom=\"m\">{}</mdMx>", last.md_m);
    }
    let _ = writeln!(
        x,
        "    <aziVertSect uom=\"dega\">{}</aziVertSect>",
        s.vsec_azimuth_deg
    );
    x += "    <aziRef>true north</aziRef>\n";
    for (k, r) in s.rows.iter().enumerate() {
        let kind = if k == 0 { "tie in point" } else { "unknown" };
        let _ = write!(
            x,
            "    <trajectoryStation uid=\"st{k}\">\n\
             \x20     <typeTrajStation>{kind}</typeTrajStation>\n\
             \x20     <md uom=\"m\">{}</md>\n\
             \x20     <tvd uom=\"m\">{}</tvd>\n\
             \x20     <incl uom=\"dega\">{}</incl>\n\
             \x20     <azi uom=\"dega\">{}</azi>\n\
             \x20     <dispNs uom=\"m\">{}</dispNs>\n\
             \x20     <dispEw uom=\"m\">{}</dispEw>\n\
             \x20     <vertSect uom=\"m\">{}</vertSect>\n\
             \x20     <dls uom=\"dega/30m\">{}</dls>\n\
             \x20   </trajectoryStation>\n",
            r.md_m, r.tvd_m, r.inc_deg, r.azi_deg, r.north_m, r.east_m, r.vsec_m, r.dls_deg_per_30m
        );
    }
    x += "  </trajectory>\n</trajectorys>\n";
    x
}
