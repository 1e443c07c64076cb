//! Standard output for the commands: `outln!` and `out!`, `println!` and
//! `print!` that a closed pipe (`| head -1`) does not turn into a panic.
//! A leaf of `commands/`: every command prints through it, it uses none
//! of them.

/// `println!` for command output that a closed pipe (`| head -1`) does not
/// turn into a panic: see [`print_out`].
macro_rules! outln {
    () => { $crate::commands::output::print_line(format_args!("")) };
    ($($arg:tt)*) => { $crate::commands::output::print_line(format_args!($($arg)*)) };
}

/// `print!` through [`print_out`], as [`outln!`].
macro_rules! out {
    ($($arg:tt)*) => { $crate::commands::output::print_text(format_args!($($arg)*)) };
}

/// Prints to stdout; a closed pipe (`| head`) ends the output quietly: the
/// command goes on (files it writes are still written, its exit status
/// still tells), only what nobody reads is dropped.
pub fn print_out(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => Ok(other?),
    }
}

/// Set when standard output could not be written (another error than a
/// closed pipe): the command then fails ([`failed`]) whatever it did.
static FAILED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Whether writing standard output failed (a full disk behind a
/// redirection, `> /dev/full`): the command's output is not whole, so it
/// must not exit as if it were (`main` exits 1).
pub fn failed() -> bool {
    FAILED.load(std::sync::atomic::Ordering::Relaxed)
}

/// What [`outln!`] calls: one line through [`print_out`]. Another write
/// error than a closed pipe (a full disk behind a redirection) is said on
/// stderr once, rather than panicking as `println!` would, and makes the
/// command fail ([`failed`]).
pub fn print_line(args: std::fmt::Arguments<'_>) {
    print_text(format_args!("{args}\n"));
}

/// What [`out!`] calls.
pub fn print_text(args: std::fmt::Arguments<'_>) {
    if let Err(e) = print_out(&args.to_string()) {
        if !FAILED.swap(true, std::sync::atomic::Ordering::Relaxed) {
            eprintln!("error: writing to standard output: {e:#}");
        }
    }
}

/// Standard output as a stream of lines (a survey of a million stations
/// written as it is made), buffered; a closed pipe ends the output
/// quietly, as [`print_out`] does, and another write error is an error.
pub struct StdoutStream {
    out: std::io::BufWriter<std::io::Stdout>,
    closed: bool,
}

impl Default for StdoutStream {
    fn default() -> Self {
        Self {
            out: std::io::BufWriter::new(std::io::stdout()),
            closed: false,
        }
    }
}

impl StdoutStream {
    fn quiet_if_closed(&mut self, r: std::io::Result<()>) -> std::io::Result<()> {
        match r {
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
                self.closed = true;
                Ok(())
            }
            other => other,
        }
    }
}

impl std::io::Write for StdoutStream {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if !self.closed {
            let r = self.out.write_all(buf);
            self.quiet_if_closed(r)?;
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if self.closed {
            return Ok(());
        }
        let r = self.out.flush();
        self.quiet_if_closed(r)
    }
}
