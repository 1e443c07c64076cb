//! `host-sim survey`: positions of a survey's stations by minimum curvature
//! and, with `--error-model`, their ISCWSA position uncertainty and error
//! ellipse; a listing on the terminal and CSV, JSON, WITSML exports. The
//! survey is `host_sim::survey::well_survey`'s, its outputs
//! `host_sim::survey::outputs`'; this module reads the options (and the
//! job file they may name) and prints. With `--depth`, the capture survey
//! (`survey_capture`).
use super::limits::number_in;
use super::output::StdoutStream;
use super::site::SiteArgs;
use anyhow::{bail, Context, Result};
use host_sim::formats::files::create_buffered;
use host_sim::formats::station_csv::file_unit;
use host_sim::survey::capture::{CaptureSurveyInputs, ProbeSetup};
use host_sim::survey::iscwsa::Site;
use host_sim::survey::job::{Job, SurveyJob, WellNames};
use host_sim::survey::listing::separation as sep;
use host_sim::survey::listing::{
    self as listing, drilling, AzimuthReference, KnownModel, LengthUnit, StationReading, TieOnInput,
};
use host_sim::survey::outputs::{listing_text, write_outputs, OutputPaths};
use host_sim::survey::streamed::{survey_streamed, StreamOutputs};
use host_sim::survey::well_survey::{
    read_station_file, ModelChoice, OffsetInputs, SiteFor, SurveyInputs, WellSurvey,
};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::config::default_still_settings;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// A length unit on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Units {
    M,
    Ft,
}

impl Units {
    fn unit(self) -> LengthUnit {
        match self {
            Self::M => LengthUnit::Metre,
            Self::Ft => LengthUnit::Foot,
        }
    }
}

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
fn tie_on_sigma(text: &str) -> Result<f64, String> {
    number_in(text, "a tie-on sigma", (0.0, 1e3), "(file's length unit)")
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
    /// A job file (examples/lateral-100m/job.json is one): its site, survey tie-on (in its
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
    /// 1-sigma of the tie-on's position, north, east and TVD (file's
    /// unit): the parent well's uncertainty where this well leaves it,
    /// added to every station's covariance (a job gives it, or a full
    /// covariance, as survey.tie_on.sigma / .covariance).
    #[arg(long, num_args = 3, value_names = ["NORTH", "EAST", "TVD"], value_parser = tie_on_sigma)]
    pub tie_on_sigma: Option<Vec<f64>>,
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
    /// Length unit of the outputs (listing, CSV, JSON, WITSML, figures;
    /// DLS per 30 m or per 100 ft), and of a station file's MD column that
    /// names no unit (a header's own unit stands). Default: metres, the
    /// figures in the file's unit.
    #[arg(long, value_enum)]
    pub units: Option<Units>,
    /// Wrap station azimuths within one turn of 0..360 (-360..720 deg: -30
    /// is read as 330, 400 as 40) instead of refusing them.
    #[arg(long)]
    pub wrap_azimuth: bool,
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

/// The survey's inputs that a job file may give (flags override it).
struct Resolved {
    /// Latitude of the site, rad.
    latitude: f64,
    job: SurveyJob,
    /// The well's and wellbore's names and uids (the WITSML output's):
    /// the job's, else placeholders.
    well: WellNames,
    /// The probe's configuration for a capture's replay (`survey_capture`):
    /// the site, the job's calibration, still settings and tie-in (else
    /// none, the probe's defaults, none).
    probe: ProbeSetup,
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
        let (job, well) = job.map_or_else(Default::default, |j| (j.survey, j.well));
        Ok(Self {
            latitude: site.lat,
            job,
            well,
            probe,
        })
    }

    /// The tie-on in `unit` (the input file's): each flag given, else the
    /// job's (converted to `unit`), else the surface (MD: the first
    /// station's).
    fn tie_on(&self, args: &Args, unit: LengthUnit) -> TieOnInput {
        let job = self.job.tie_on.in_unit(unit);
        let flag = args.tie_on_sigma.as_deref().and_then(|s| match *s {
            [n, e, v] => Some([n * n, e * e, v * v, 0.0, 0.0, 0.0]),
            _ => None,
        });
        TieOnInput {
            md: args.tie_on_md.or(job.md),
            tvd: args.tie_on_tvd.or(job.tvd).unwrap_or(0.0),
            north: args.tie_on_north.or(job.north).unwrap_or(0.0),
            east: args.tie_on_east.or(job.east).unwrap_or(0.0),
            covariance: flag.or(job.covariance),
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

pub fn run(args: Args) -> Result<ExitCode> {
    let resolved = Resolved::new(&args)?;
    check_offset_flags(&args.sep)?;
    if let Some(dir) = &args.plot {
        // refused before any work: a file in the way is the user's mistake
        host_sim::formats::figure::prepare_dir(dir)?;
    }
    let site_for = |model: &KnownModel| model_site(&args, &resolved, model);
    let paths = OutputPaths {
        csv: args.csv.as_deref(),
        json: args.json.as_deref(),
        witsml: args.witsml.as_deref(),
        plot: args.plot.as_deref(),
    };
    if args.capture.depth.is_some() {
        if args.units == Some(Units::Ft) {
            bail!(
                "--units ft: a capture's survey is listed in metres, the depth log's unit (its \
                 --json and --witsml carry their units); survey its stations CSV with --units ft \
                 for feet"
            );
        }
        let inputs = capture_inputs(&args, &resolved)?;
        let offset = args.sep.offset.as_deref();
        let outputs = super::survey_capture::CaptureOutputs {
            paths,
            confidence: args.confidence,
            vsec_azimuth: args.vsec_azimuth_deg.map(f64::to_radians),
            offset: offset.map(|p| offset_inputs(&args, p)).transpose()?,
            well: &resolved.well,
        };
        return super::survey_capture::run(&args.capture, &inputs, &outputs, &site_for);
    }
    let units = args.units.map(Units::unit);
    let reading = station_reading(&args);
    let whole_survey_outputs = [&args.json, &args.witsml, &args.plot, &args.sep.offset];
    if whole_survey_outputs.iter().all(|o| o.is_none()) {
        // the listing and the CSV only: row by row, in constant memory
        run_streamed(&args, &resolved, reading, &site_for)?;
        return Ok(ExitCode::from(super::status::COMPLETE));
    }
    let file = read_station_file(&args.stations, reading)?;
    let inputs = SurveyInputs {
        reference: azimuth_reference(&args)?,
        tie: resolved.tie_on(&args, file.unit),
        vsec_azimuth: args.vsec_azimuth_deg.map(f64::to_radians),
        model: model_choice(&args, &resolved),
        confidence: args.confidence,
    };
    let mut survey = WellSurvey::compute(&file, &inputs, &site_for)?;
    survey.well = resolved.well.clone();
    if let Some(path) = &args.sep.offset {
        survey.add_offset(&offset_inputs(&args, path)?, &site_for)?;
    }
    if let Some(unit) = units {
        // the figures too (by default in the file's unit)
        survey.output_unit = unit;
        survey.unit = unit;
    }
    out!("{}", listing_text(&survey));
    let well = args
        .stations
        .file_stem()
        .map_or_else(|| "survey".into(), |n| n.to_string_lossy());
    for f in write_outputs(&survey, &paths, &well)? {
        outln!("wrote {}", f.display());
    }
    Ok(ExitCode::from(super::status::COMPLETE))
}

/// How the station files are read: `--units` for an MD column that names
/// none, `--wrap-azimuth`.
fn station_reading(args: &Args) -> StationReading {
    StationReading {
        unit: args.units.map(Units::unit),
        wrap_azimuth: args.wrap_azimuth,
    }
}

/// The survey of a station file of any length, its listing and CSV
/// written as the stations are read (`survey::streamed`); a CSV left
/// incomplete by an error is removed.
fn run_streamed(
    args: &Args,
    resolved: &Resolved,
    reading: StationReading,
    site_for: SiteFor,
) -> Result<()> {
    let path = &args.stations;
    let input = std::fs::File::open(path).with_context(|| format!("{}", path.display()))?;
    let file_unit = file_unit(input, reading).with_context(|| format!("{}", path.display()))?;
    let inputs = SurveyInputs {
        reference: azimuth_reference(args)?,
        tie: resolved.tie_on(args, file_unit),
        vsec_azimuth: args.vsec_azimuth_deg.map(f64::to_radians),
        model: model_choice(args, resolved),
        confidence: args.confidence,
    };
    let mut listing = StdoutStream::default();
    let mut csv = args.csv.as_deref().map(create_buffered).transpose()?;
    let outputs = StreamOutputs {
        listing: &mut listing,
        csv: csv.as_mut().map(|w| w as &mut dyn std::io::Write),
    };
    // An error drops the CSV unfinished: no partial file, the error says why.
    survey_streamed(path, reading, &inputs, site_for, reading.unit, outputs)?;
    if let Some(csv) = csv {
        csv.finish()?;
    }
    Ok(())
}

/// The offset well's options are refused without `--offset`.
fn check_offset_flags(o: &OffsetArgs) -> Result<()> {
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
    Ok(())
}

/// A capture survey's inputs (`--depth`), once the options it does not
/// take are refused.
fn capture_inputs(args: &Args, resolved: &Resolved) -> Result<CaptureSurveyInputs> {
    let own_model = [
        ("--error-model", args.error_model.is_some()),
        ("--error-model-file", args.error_model_file.is_some()),
    ];
    if let Some((flag, _)) = own_model.iter().find(|u| u.1) {
        bail!(
            "{flag} is not available for a capture survey (--depth): its uncertainty is the \
             probe's own (docs/drilling-survey.md)"
        );
    }
    if args.convergence_deg.is_some() || args.azimuth_reference != Reference::True {
        bail!(
            "--azimuth-reference grid and --convergence-deg are not available for a capture \
             survey (--depth): the probe gyrocompasses, its azimuths are true north"
        );
    }
    // The capture's uncertainty is the probe's own model: a job naming
    // another is a job for another tool.
    if let Some(name) = &resolved.job.error_model {
        let probe = drilling::MODEL_NAME;
        if listing::model(name)?.name != probe {
            bail!(
                "the job's error model {name} is not the probe's ({probe}): a capture survey \
                 (--depth) has the probe's own uncertainty"
            );
        }
    }
    let Some(depth) = &args.capture.depth else {
        bail!("a capture survey needs --depth");
    };
    Ok(CaptureSurveyInputs {
        capture: args.stations.clone(),
        depth: depth.clone(),
        // The depth log is in metres.
        tie: resolved.tie_on(args, LengthUnit::Metre),
        latitude: resolved.latitude,
        probe: resolved.probe,
        sensor_to_bit_m: resolved
            .job
            .sensor_to_bit
            .map(|d| d * resolved.job.tie_on.unit.to_m()),
        depth_gap_limit_s: args.capture.depth_gap_limit,
    })
}

/// `--azimuth-reference` with `--convergence-deg`.
fn azimuth_reference(args: &Args) -> Result<AzimuthReference> {
    Ok(match (args.azimuth_reference, args.convergence_deg) {
        (Reference::True, None) => AzimuthReference::True,
        (Reference::True, Some(_)) => {
            bail!("--convergence-deg needs --azimuth-reference grid")
        }
        (Reference::Grid, Some(c)) => AzimuthReference::Grid(c.to_radians()),
        (Reference::Grid, None) => bail!("--azimuth-reference grid needs --convergence-deg"),
    })
}

/// `--error-model-file`, else `--error-model` or the job's.
fn model_choice<'a>(args: &'a Args, resolved: &'a Resolved) -> ModelChoice<'a> {
    match (&args.error_model_file, resolved.error_model(args)) {
        (Some(path), _) => ModelChoice::File(path),
        (None, Some(name)) => ModelChoice::Named(name),
        (None, None) => ModelChoice::None,
    }
}

/// The offset well's inputs: its tie-on, model and the separation rule
/// (the open-hole radii are needed).
fn offset_inputs<'a>(args: &'a Args, path: &'a Path) -> Result<OffsetInputs<'a>> {
    let (Some(ref_radius_m), Some(offset_radius_m)) =
        (args.sep.hole_radius_m, args.sep.offset_hole_radius_m)
    else {
        bail!("--offset needs --hole-radius-m and --offset-hole-radius-m (open-hole radii, m)");
    };
    let reference = match (args.azimuth_reference, args.convergence_deg) {
        (Reference::Grid, Some(c)) => AzimuthReference::Grid(c.to_radians()),
        _ => AzimuthReference::True,
    };
    Ok(OffsetInputs {
        path,
        reference,
        tie: TieOnInput {
            md: args.sep.offset_tie_on_md,
            tvd: args.sep.offset_tie_on_tvd,
            north: args.sep.offset_tie_on_north,
            east: args.sep.offset_tie_on_east,
            covariance: None,
        },
        model_name: args.sep.offset_error_model.as_deref(),
        reading: station_reading(args),
        rule: sep::Rule {
            k: sep::K,
            surface_margin_m: args.sep.surface_margin_m,
            sigma_pa_m: args.sep.sigma_pa_m,
            ref_radius_m,
            offset_radius_m,
        },
    })
}

/// The site an error model runs at: the magnetic field from the options
/// (a magnetic model refuses to go without it), the site's latitude.
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
