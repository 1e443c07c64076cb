//! `host-sim`: the host tool of the gyro MWD probe. Each subcommand lives in
//! its own module under `commands/`.
use std::process::ExitCode;

mod commands;

fn main() -> ExitCode {
    let cli = match commands::parse() {
        Ok(cli) => cli,
        // A bad command line is an error (1): 2 says "written but
        // incomplete" (`commands::status`). Help and version are not errors.
        Err(err) => {
            let _ = err.print();
            let status = if err.use_stderr() {
                commands::status::ERROR
            } else {
                commands::status::COMPLETE
            };
            return ExitCode::from(status);
        }
    };
    match commands::run(cli) {
        // Its output not whole: an error, whatever the command thought.
        Ok(_) if commands::output::failed() => ExitCode::from(commands::status::ERROR),
        Ok(status) => status,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
