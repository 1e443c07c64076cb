//! `host-sim dashboard --port DEV [--baud B] [--save FILE]` or
//! `host-sim dashboard --file CAPTURE.bin [--speed X]`: the probe's live
//! display as a local web page (docs/dashboard.md). Prints its URL and
//! serves until stopped (Ctrl-C).

use std::fs::File;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use anyhow::{Context, Result};
use host_sim::dashboard::server::{self, App};
use host_sim::dashboard::source::{self, Shared};
use host_sim::dashboard::state::{DashboardState, SourceInfo, LIMITS};
use host_sim::formats::depth_log::DepthLog;
use host_sim::survey::job::Job;
use host_sim::survey::stations::{job_tie_on, SurveySetup};
use mwd_core::calibration::ProbeCalibration;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The probe's serial port (e.g. /dev/ttyUSB0, or QEMU's pty).
    #[arg(
        long,
        value_name = "DEV",
        required_unless_present = "file",
        conflicts_with = "file"
    )]
    pub port: Option<String>,
    /// Baud rate of the serial port (the probe sends at 115200).
    #[arg(long, default_value_t = 115_200, requires = "port")]
    pub baud: u32,
    /// Record the port's raw bytes here as they arrive (a capture that
    /// `decode`, `replay` and `dashboard --file` read).
    #[arg(long, value_name = "FILE", requires = "port")]
    pub save: Option<PathBuf>,
    /// Replay this capture (`.bin`) instead of a port; the probe's
    /// commands are then disabled.
    #[arg(long, value_name = "CAPTURE.bin")]
    pub file: Option<PathBuf>,
    /// Replay pace: times the probe's own (1 = as recorded).
    #[arg(long, default_value_t = 1.0, requires = "file", value_parser = speed)]
    pub speed: f64,
    /// The surface depth log (CSV: time_s, md_m) that pairs the stations
    /// with MD for their positions (as `host-sim survey --depth`).
    #[arg(long, value_name = "DEPTH.csv")]
    pub depth: Option<PathBuf>,
    /// The job file the page's "configure" button sends (site, tie-in,
    /// calibration: `host-sim probe configure`); its calibration is shown
    /// as the one in use.
    #[arg(long, value_name = "JOB.json")]
    pub job: Option<PathBuf>,
    /// Address to serve on (default: this machine only).
    #[arg(long, default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    pub bind: IpAddr,
    /// TCP port to serve on (0: any free port; the URL printed tells).
    #[arg(long, default_value_t = 8080)]
    pub http_port: u16,
}

fn speed(text: &str) -> Result<f64, String> {
    let v: f64 = text
        .parse()
        .map_err(|_| format!("the speed must be a number, not {text:?}"))?;
    if !(v.is_finite() && v > 0.0 && v <= 1e6) {
        return Err(format!(
            "the speed must be above 0 and at most 1e6, not {v}"
        ));
    }
    Ok(v)
}

/// The calibration in use, for people: the job's, or what is known.
fn calibration_lines(job: Option<&Job>) -> Vec<String> {
    let Some(job) = job else {
        return vec![
            "not known to the host: no job file (--job); the probe's configuration \
                     version shows after its first reply"
                .into(),
        ];
    };
    let Some((path, c)) = &job.calibration else {
        return vec!["none: the job file gives no calibration (no correction)".into()];
    };
    calibration_text(&path.display().to_string(), c)
}

fn calibration_text(source: &str, c: &ProbeCalibration) -> Vec<String> {
    let mut lines = vec![format!("from {source}")];
    for part in 0..2 {
        let (a, g) = (&c.accel[part], &c.gyro[part]);
        let diag = [0, 1, 2].map(|i| a.correction[i][i]);
        lines.push(format!(
            "part {}: gyro bias {:.4} deg/s, scale {:.6}; accel bias [{:.4}, {:.4}, {:.4}] m/s^2, \
             correction diagonal [{:.6}, {:.6}, {:.6}]",
            part + 1,
            g.bias.to_degrees(),
            g.scale,
            a.bias[0],
            a.bias[1],
            a.bias[2],
            diag[0],
            diag[1],
            diag[2]
        ));
    }
    lines
}

pub fn run(args: Args) -> Result<()> {
    let job = args.job.as_deref().map(Job::load).transpose()?;
    let depth = args
        .depth
        .as_deref()
        .map(|path| {
            let file = File::open(path).with_context(|| format!("reading {}", path.display()))?;
            DepthLog::read(file).with_context(|| format!("{}", path.display()))
        })
        .transpose()?;
    let latitude_deg = job
        .as_ref()
        .map_or(mwd_core::earth::Position::paper_site().lat, |j| j.site.lat)
        .to_degrees();
    let mut info = SourceInfo {
        description: String::new(),
        controls_disabled: None,
        calibration: calibration_lines(job.as_ref()),
        job: args.job.as_ref().map(|p| p.display().to_string()),
        depth,
        survey: SurveySetup::probe(job_tie_on(job.as_ref()), latitude_deg.to_radians())?,
    };
    let session = rand::random::<u64>() >> 12;
    let (state, commands): (Shared, _) = match (&args.port, &args.file) {
        (Some(port), _) => {
            let save = args
                .save
                .as_deref()
                .map(|p| File::create(p).with_context(|| format!("creating {}", p.display())))
                .transpose()?;
            info.description = format!("port {port} at {} baud", args.baud);
            if let Some(path) = &args.save {
                info.description += &format!(", recording to {}", path.display());
            }
            let state = Arc::new(Mutex::new(DashboardState::new(info, session, LIMITS)));
            let sender = source::run_port(port, args.baud, save, Arc::clone(&state))?;
            (state, Ok(Arc::new(Mutex::new(sender))))
        }
        (None, Some(file)) => {
            source::check_capture(file)?;
            let reason = "replaying a capture: there is no probe to command".to_string();
            info.description = format!("capture {} at {}x", file.display(), args.speed);
            info.controls_disabled = Some(reason.clone());
            let state = Arc::new(Mutex::new(DashboardState::new(info, session, LIMITS)));
            source::replay_file(file.clone(), args.speed, Arc::clone(&state));
            (state, Err(reason))
        }
        (None, None) => anyhow::bail!("give --port DEV or --file CAPTURE.bin"),
    };
    let app = App {
        state,
        commands,
        job: job.map(Arc::new),
    };
    server::serve(SocketAddr::new(args.bind, args.http_port), app, |addr| {
        // Scripts wait for this line to find the URL.
        outln!("dashboard at http://{addr}/ (Ctrl-C to stop)");
    })
}
