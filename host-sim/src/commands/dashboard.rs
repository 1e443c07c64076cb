//! `host-sim dashboard --port DEV [--baud B] [--save FILE]` or
//! `host-sim dashboard --file CAPTURE.bin [--speed X]`: the probe's live
//! display as a local web page (docs/dashboard.md). Prints its URL and
//! serves until stopped (Ctrl-C). Loopback only unless `--allow-remote`.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;

use anyhow::Result;
use host_sim::dashboard::launch::{calibration_lines, start, well_plan_path, Source};
use host_sim::dashboard::server;
use host_sim::dashboard::state::SourceInfo;
use host_sim::formats::files::read_depth_log;
use host_sim::survey::job::Job;
use host_sim::survey::stations::{job_tie_on, SurveySetup};

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
    /// as the one in use, its survey tie-on places the stations, and its
    /// well plan (`plan`) is drawn under them in the plan view and the
    /// vertical section.
    #[arg(long, value_name = "JOB.json")]
    pub job: Option<PathBuf>,
    /// Address to serve on (default: this machine only). On a loopback
    /// address the dashboard answers only to localhost, 127.0.0.1 and
    /// [::1] with its port (not to another site's name rebound to this
    /// machine), refuses requests from other sites' pages (Origin), and
    /// takes the probe's commands only with the random token of this run
    /// that the page it serves holds. Any other address needs
    /// --allow-remote.
    #[arg(long, default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    pub bind: IpAddr,
    /// Let other machines connect (to serve on a non-loopback --bind, such
    /// as 0.0.0.0). Plain HTTP, not encrypted: use it on a network you
    /// trust. The dashboard then takes any Host name, but every request
    /// (the page, the data, the commands; not its public scripts) needs
    /// the access token printed at start: open the printed URL, which
    /// carries it (?token=...).
    #[arg(long)]
    pub allow_remote: bool,
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

pub fn run(args: Args) -> Result<()> {
    let remote = !args.bind.is_loopback();
    anyhow::ensure!(
        !remote || args.allow_remote,
        "--bind {} lets other machines reach the dashboard and command the probe: give \
         --allow-remote to serve there (every request then needs the printed access token), \
         or bind 127.0.0.1 (the default) to serve this machine only",
        args.bind
    );
    let job = args.job.as_deref().map(Job::load).transpose()?;
    let depth = args.depth.as_deref().map(read_depth_log).transpose()?;
    let latitude_deg = job
        .as_ref()
        .map_or(mwd_core::earth::Position::paper_site().lat, |j| j.site.lat)
        .to_degrees();
    let info = SourceInfo {
        description: String::new(),
        controls_disabled: None,
        calibration: calibration_lines(job.as_ref()),
        job: args.job.as_ref().map(|p| p.display().to_string()),
        depth,
        survey: SurveySetup::probe(job_tie_on(job.as_ref()), latitude_deg.to_radians())?,
        well_plan: well_plan_path(job.as_ref())?,
    };
    let source = match (&args.port, &args.file) {
        (Some(port), _) => Source::Port {
            port,
            baud: args.baud,
            save: args.save.as_deref(),
        },
        (None, Some(file)) => Source::Capture {
            path: file,
            speed: args.speed,
        },
        (None, None) => anyhow::bail!("give --port DEV or --file CAPTURE.bin"),
    };
    let app = start(source, info, job)?;
    let bind = SocketAddr::new(args.bind, args.http_port);
    server::serve(bind, remote, app, |addr, access| {
        if remote {
            eprintln!(
                "warning: serving on {addr}: other machines can reach the dashboard over plain \
                 HTTP (not encrypted) and command the probe with its access token; every \
                 request needs the token, as in the URL below: {}",
                access.token()
            );
            // Scripts wait for this line to find the URL.
            outln!(
                "dashboard at http://{addr}/?token={} (Ctrl-C to stop)",
                access.token()
            );
        } else {
            outln!("dashboard at http://{addr}/ (Ctrl-C to stop)");
        }
    })
}
