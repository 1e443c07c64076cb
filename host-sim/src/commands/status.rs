//! The exit statuses every command tells by (README, each `--help`): a
//! leaf of `commands/`, like [`super::output`].

use std::process::ExitCode;

/// Everything done, nothing left out.
pub const COMPLETE: u8 = 0;
/// An error: nothing claimed (a bad argument, an unreadable input, an
/// output that could not be written).
pub const ERROR: u8 = 1;
/// Written, but incomplete: frames lost, or stations or solutions that
/// could not be compared.
pub const INCOMPLETE: u8 = 2;
/// `replay`: the replayed solutions or stations differ from the probe's.
pub const DIFFERENT: u8 = 3;

/// The tool's `--help`: every status.
pub const HELP_ALL: &str =
    "Exit status: 0 complete; 1 error (nothing claimed, no partial file left); 2 written but \
     incomplete (frames lost, or stations or solutions not compared); 3 replay differs from \
     the probe. Each command's --help says which it uses.";

/// The `--help` text of a command's exit statuses: 0 and 1.
pub const HELP_COMPLETE_OR_ERROR: &str =
    "Exit status: 0 complete; 1 error (bad argument, unreadable input, an output that could \
     not be written: no success is claimed, no partial file is left).";

/// `survey`'s: a capture survey with losses is incomplete.
pub const HELP_SURVEY: &str =
    "Exit status: 0 complete; 1 error (bad argument, unreadable input, an output that could \
     not be written, the tie-on's station lost: no success is claimed, no partial file is \
     left); 2 written but incomplete: a capture's frames were lost (their count said on \
     standard error; a lost station is listed as lost, the others keep their MD).";

/// `decode`'s: a capture with lost frames is incomplete; duplicated and
/// reordered frames are not (nothing is missing).
pub const HELP_DECODE: &str =
    "Exit status: 0 complete; 1 error (bad argument, unreadable input, not a probe capture, a \
     CSV that could not be written: no success is claimed, no partial file is left); 2 written \
     but incomplete: frames were lost in the capture (their count said on standard error). \
     Duplicated and reordered frames are counted and printed but miss nothing: 0.";

/// A command's status: complete, or incomplete with `why` said on
/// standard error as a warning.
pub fn complete_unless(incomplete: Option<String>) -> ExitCode {
    match incomplete {
        None => ExitCode::from(COMPLETE),
        Some(why) => {
            eprintln!("warning: {why}");
            ExitCode::from(INCOMPLETE)
        }
    }
}
