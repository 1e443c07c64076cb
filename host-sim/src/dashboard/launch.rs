//! A dashboard started from its source: the calibration in use as the
//! page shows it, the state described by its source, and the source's
//! reader started (a serial port, recorded raw as it arrives, or a capture
//! replayed at a chosen pace; the probe's commands only with a port).

use crate::dashboard::server::App;
use crate::dashboard::source::{self, Shared};
use crate::dashboard::state::{DashboardState, SourceInfo, LIMITS};
use crate::sim::plan::Plan;
use crate::survey::job::Job;
use anyhow::{Context, Result};
use mwd_core::calibration::ProbeCalibration;
use std::fs::File;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Where the dashboard's frames come from.
#[derive(Clone, Copy, Debug)]
pub enum Source<'a> {
    /// A serial port, its raw bytes recorded to `save` as they arrive.
    Port {
        port: &'a str,
        baud: u32,
        save: Option<&'a Path>,
    },
    /// A capture replayed at `speed` times the probe's pace.
    Capture { path: &'a Path, speed: f64 },
}

/// Starts reading `source` into a new dashboard state (`info` gets the
/// source's description), and gives the app to serve with `job` for its
/// "configure" button.
pub fn start(source: Source, mut info: SourceInfo, job: Option<Job>) -> Result<App> {
    let session = rand::random::<u64>() >> 12;
    let (state, commands): (Shared, _) = match source {
        Source::Port { port, baud, save } => {
            let file = save
                .map(|p| File::create(p).with_context(|| format!("creating {}", p.display())))
                .transpose()?;
            info.description = format!("port {port} at {baud} baud");
            if let Some(path) = save {
                info.description += &format!(", recording to {}", path.display());
            }
            let state = Arc::new(Mutex::new(DashboardState::new(info, session, LIMITS)));
            let sender = source::run_port(port, baud, file, Arc::clone(&state))?;
            (state, Ok(Arc::new(Mutex::new(sender))))
        }
        Source::Capture { path, speed } => {
            source::check_capture(path)?;
            let reason = "replaying a capture: there is no probe to command".to_string();
            info.description = format!("capture {} at {}x", path.display(), speed);
            info.controls_disabled = Some(reason.clone());
            let state = Arc::new(Mutex::new(DashboardState::new(info, session, LIMITS)));
            source::replay_file(path.to_path_buf(), speed, Arc::clone(&state));
            (state, Err(reason))
        }
    };
    Ok(App {
        state,
        commands,
        job: job.map(Arc::new),
    })
}

/// Points drawn along a well plan: enough for its curves to look round.
const PLAN_POINTS: usize = 400;

/// The job's well plan (its `plan` key), as (north, east, TVD) m at
/// [`PLAN_POINTS`] + 1 MDs evenly along it; `None` without a job or plan.
pub fn well_plan_path(job: Option<&Job>) -> Result<Option<Vec<[f64; 3]>>> {
    let Some(path) = job.and_then(|j| j.plan.as_deref()) else {
        return Ok(None);
    };
    let plan = Plan::load(path)?;
    let (start, end) = (plan.start_md(), plan.end_md());
    let points = (0..=PLAN_POINTS)
        .map(|i| {
            let md = start + (end - start) * i as f64 / PLAN_POINTS as f64;
            let p = plan.at(md);
            [p.nev[0], p.nev[1], p.nev[2]]
        })
        .collect();
    Ok(Some(points))
}

/// The calibration in use, for people: the job's, or what is known.
pub fn calibration_lines(job: Option<&Job>) -> Vec<String> {
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
