//! A capture file replayed as it is read (`host-sim replay FILE`): every
//! item through a [`Replayer`] configured as the probe was, the replayed
//! solutions written to the CSV as their comparison settles, so that a
//! capture of any length keeps only its [`Replayed`] summary.

use crate::formats::capture::{CaptureSummary, ProbeCaptureFile};
use crate::formats::files::create_buffered;
use crate::replay::report::Replayed;
use crate::replay::{Replayer, CSV_HEADER, FILE_BATCH_ITEMS};
use mwd_core::calibration::ProbeCalibration;
use mwd_core::earth::Position;
use mwd_core::probe::TieIn;
use mwd_core::protocol::uplink::{Command as UplinkCommand, StillSettings};
use std::io::Write;
use std::path::Path;

/// The probe the replay stands for: its site, calibration, still settings
/// and tie-in.
#[derive(Clone, Copy, Debug)]
pub struct ReplayedProbe {
    pub site: Position,
    pub calibration: ProbeCalibration,
    pub still: StillSettings,
    pub tie_in: Option<TieIn>,
}

/// Replays the capture `file` as it is read, with the commands the host
/// `sent` (from an uplink log: what the probe's replies do not carry),
/// writing the replayed solutions to `csv` as the rows settle.
pub fn replay_file(
    file: &Path,
    probe: ReplayedProbe,
    sent: &[(u16, UplinkCommand)],
    csv: Option<&Path>,
) -> anyhow::Result<Replayed> {
    let mut capture = ProbeCaptureFile::open(file)?;
    let mut out = csv.map(create_buffered).transpose()?;
    let csv_error = |e: std::io::Error| {
        let path = csv.map(|p| p.display().to_string()).unwrap_or_default();
        anyhow::Error::new(e).context(format!("writing {path}"))
    };
    if let Some(w) = out.as_mut() {
        writeln!(w, "{CSV_HEADER}").map_err(csv_error)?;
    }
    let mut replayer = Replayer::with_settings(probe.site, probe.calibration, probe.still)
        .with_tie_in(probe.tie_in);
    for (seq, command) in sent {
        replayer.knows_sent_command(*seq, command);
    }
    let mut summary = CaptureSummary::default();
    let mut items = 0usize;
    while let Some(item) = capture.next_item()? {
        summary.note(item.received());
        replayer.push_received(item.received());
        items += 1;
        if items % FILE_BATCH_ITEMS == 0 {
            let sink = out.as_mut().map(|w| w as &mut dyn Write);
            replayer.write_settled(sink, false).map_err(csv_error)?;
        }
    }
    summary.stats = *capture.stats();
    let (station_rows, station_summary) = replayer.stations();
    let stations = Some((station_rows.to_vec(), station_summary));
    let sink = out.as_mut().map(|w| w as &mut dyn Write);
    replayer.write_settled(sink, true).map_err(csv_error)?;
    // The header alone (no raw frame) was never flushed with rows.
    if let Some(w) = out {
        w.finish()?;
    }
    let step_losses = replayer.step_losses().to_vec();
    let commands = replayer.commands().to_vec();
    let rows = replayer.rows_replayed();
    let last_row = replayer.last_row().copied();
    let (_, replay_summary) = replayer.finish();
    Ok(Replayed {
        source: file.display().to_string(),
        capture: summary,
        rows,
        last_row,
        summary: replay_summary,
        step_losses,
        commands,
        stations,
    })
}
