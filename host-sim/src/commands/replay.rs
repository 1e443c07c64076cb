//! `host-sim replay FILE [--csv OUT]`: runs the probe's navigation on the
//! raw frames of a capture (for example QEMU's `-serial file:` output) and
//! checks the replayed solutions against the probe's own navigation frames.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;

use anyhow::Context;
use host_sim::{capture, replay};
use mwd_core::earth::Position;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Capture of the probe's UART bytes (`.bin`).
    pub file: PathBuf,
    /// Write the replayed navigation solutions as CSV here.
    #[arg(long, value_name = "OUT")]
    pub csv: Option<PathBuf>,
    /// The probe's site: latitude and longitude (deg), height (m); the
    /// QEMU probe uses the MGWD paper's site.
    #[arg(long, num_args = 3, value_names = ["LAT", "LON", "HEIGHT"], allow_negative_numbers = true)]
    pub site: Option<Vec<f64>>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let cap = capture::read_capture(&args.file)
        .with_context(|| format!("reading {}", args.file.display()))?;
    let site = match args.site.as_deref() {
        Some([lat, lon, height]) => Position::from_degrees(*lat, *lon, *height),
        _ => Position::paper_site(),
    };
    let (rows, summary) = replay::replay(&cap.frames, site);
    println!("capture          {}", args.file.display());
    println!("{cap}");
    println!("raw frames       {}", summary.raw_frames);
    println!("degraded samples {}", summary.degraded);
    println!("probe solutions  {}", summary.probe_solutions);
    println!(
        "replay parity    {} identical, {} different",
        summary.matched, summary.mismatched
    );
    if let Some(last) = rows.last() {
        let [r, p, h] = last.solution.attitude.map(|a| f64::from(a).to_degrees());
        let h_std = f64::from(last.solution.attitude_std[2]).to_degrees();
        println!(
            "last attitude    roll {r:.3} pitch {p:.3} heading {h:.2} (+/- {h_std:.2} deg 1-sigma)"
        );
    }
    if let Some(out) = &args.csv {
        let file = File::create(out).with_context(|| format!("creating {}", out.display()))?;
        replay::write_csv(&rows, BufWriter::new(file))
            .with_context(|| format!("writing {}", out.display()))?;
        println!("csv              {} ({} rows)", out.display(), rows.len());
    }
    if summary.mismatched > 0 {
        anyhow::bail!(
            "{} replayed solutions differ from the probe's",
            summary.mismatched
        );
    }
    Ok(())
}
