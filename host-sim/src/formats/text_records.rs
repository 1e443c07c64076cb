//! Reading a text table record by record with the `csv` crate, so that a
//! file of any length is read in constant memory beyond what is kept, and
//! a file that is not a table is refused early:
//!
//! - no line may be longer than [`MAX_LINE_BYTES`] (a table row of the
//!   probe's is ~150 bytes), so a one-line or binary file stops after that
//!   many bytes, not after the whole file is in memory;
//! - a NUL byte means binary data, refused at once;
//! - a UTF-8 byte-order mark is skipped; quoted fields are unquoted;
//! - the separator is that of the first line that is not a `#` comment:
//!   comma, else semicolon, else runs of spaces and tabs
//!   ([`for_each_record_tab_aware`]: else tab, else runs of spaces).
//!
//! Errors quote at most [`EXCERPT_CHARS`] characters of the input.

use anyhow::{bail, Result};
use std::io::{self, Read};

/// The longest line accepted, in bytes.
pub const MAX_LINE_BYTES: usize = 64 * 1024;
/// The most characters of the input an error message quotes.
pub const EXCERPT_CHARS: usize = 40;

/// At most [`EXCERPT_CHARS`] characters of `text`, control characters
/// escaped, `...` when cut: enough to find the spot, never a whole line.
pub fn excerpt(text: &str) -> String {
    let mut out: String = text
        .chars()
        .take(EXCERPT_CHARS)
        .flat_map(char::escape_default)
        .collect();
    if text.chars().nth(EXCERPT_CHARS).is_some() {
        out.push_str("...");
    }
    out
}

/// The largest JSON file (calibration, AR models, sensor model) read: the
/// real ones are a few kB.
pub const MAX_JSON_BYTES: u64 = 1 << 20;

/// The text of a small file, refused unread when larger than `MAX_JSON_BYTES`.
pub fn read_small_file(path: &std::path::Path) -> Result<String> {
    let file = std::fs::File::open(path)?;
    let size = file.metadata()?.len();
    if size > MAX_JSON_BYTES {
        bail!("{size} bytes, more than the {MAX_JSON_BYTES} such a file can be");
    }
    let mut text = String::new();
    file.take(MAX_JSON_BYTES)
        .read_to_string(&mut text)
        .map_err(|_| anyhow::anyhow!("not UTF-8 text"))?;
    Ok(text)
}

/// At most the first ten of `names`, then how many there are in all.
pub fn name_list(names: &[String]) -> String {
    let shown: Vec<String> = names.iter().take(10).map(|n| excerpt(n)).collect();
    if names.len() > shown.len() {
        format!("{}, ... ({} in all)", shown.join(", "), names.len())
    } else {
        shown.join(", ")
    }
}

/// A reader that fails on a line longer than [`MAX_LINE_BYTES`] or a NUL
/// byte, and turns every blank or `#` comment line into a line holding
/// `#` alone: the `csv` reader skips empty lines without counting them,
/// and its line numbers must stay those of the file.
struct LineLimit<R> {
    inner: R,
    input: Box<[u8]>,
    pos: usize,
    len: usize,
    /// A newline still to be given out.
    pending: Option<u8>,
    line: u64,
    run: usize,
    /// Only blanks so far on this line.
    at_start: bool,
    in_comment: bool,
}

impl<R> LineLimit<R> {
    fn new(inner: R) -> Self {
        Self {
            inner,
            input: vec![0; 8192].into_boxed_slice(),
            pos: 0,
            len: 0,
            pending: None,
            line: 0,
            run: 0,
            at_start: true,
            in_comment: false,
        }
    }

    fn refuse(&self, why: &str) -> io::Error {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("line {}: {why}", self.line + 1),
        )
    }
}

/// What a blank or comment line becomes.
const SKIPPED_LINE: &str = "#";

impl<R: Read> Read for LineLimit<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        let mut n = 0;
        while n < out.len() {
            if let Some(byte) = self.pending.take() {
                out[n] = byte;
                n += 1;
                continue;
            }
            if self.pos == self.len {
                if n > 0 {
                    break;
                }
                self.len = self.inner.read(&mut self.input)?;
                self.pos = 0;
                if self.len == 0 {
                    break;
                }
            }
            let byte = self.input[self.pos];
            self.pos += 1;
            match byte {
                b'\n' => {
                    if self.at_start || self.in_comment {
                        out[n] = b'#';
                        n += 1;
                        self.pending = Some(b'\n');
                    } else {
                        out[n] = b'\n';
                        n += 1;
                    }
                    self.line += 1;
                    self.run = 0;
                    self.at_start = true;
                    self.in_comment = false;
                }
                0 => return Err(self.refuse("a NUL byte: binary data, not a text table")),
                _ => {
                    self.run += 1;
                    if self.run > MAX_LINE_BYTES {
                        return Err(self.refuse(&format!(
                            "longer than {MAX_LINE_BYTES} bytes: not a text table of samples"
                        )));
                    }
                    if self.at_start && byte == b'#' {
                        self.in_comment = true;
                    }
                    let bom = self.line == 0 && matches!(byte, 0xEF | 0xBB | 0xBF);
                    if !(byte.is_ascii_whitespace() || bom) {
                        self.at_start = false;
                    }
                    if !self.in_comment {
                        out[n] = byte;
                        n += 1;
                    }
                }
            }
        }
        Ok(n)
    }
}

/// How fields are separated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Separator {
    Byte(u8),
    /// Runs of spaces and tabs.
    Whitespace,
}

impl Separator {
    /// The separator of `line`; with `tab_aware`, a tab (after comma and
    /// semicolon) is one too, so that fields may hold spaces.
    fn of(line: &[u8], tab_aware: bool) -> Self {
        let bytes: &[u8] = if tab_aware { b",;\t" } else { b",;" };
        bytes
            .iter()
            .copied()
            .find(|s| line.contains(s))
            .map_or(Self::Whitespace, Self::Byte)
    }
}

/// Reads the lines up to and including the first that has content (not
/// blank, not a `#` comment); returns those bytes, BOM removed, and that
/// line's separator.
fn first_content<R: Read>(
    input: &mut LineLimit<R>,
    tab_aware: bool,
) -> io::Result<(Vec<u8>, Separator)> {
    let mut prefix = Vec::new();
    let mut byte = [0u8; 1];
    let mut line_start = 0;
    loop {
        if input.read(&mut byte)? == 0 {
            return Ok((prefix, Separator::Whitespace));
        }
        prefix.push(byte[0]);
        if prefix.starts_with(b"\xEF\xBB\xBF") {
            prefix.clear();
        }
        if byte[0] == b'\n' {
            let line = prefix[line_start..].trim_ascii();
            if line != SKIPPED_LINE.as_bytes() {
                let separator = Separator::of(line, tab_aware);
                return Ok((prefix, separator));
            }
            line_start = prefix.len();
        }
    }
}

/// Calls `row(line, fields)` for every record of `input` (blank lines and
/// `#` comments skipped, fields trimmed), stopping at the first error.
pub fn for_each_record<R: Read>(
    input: R,
    row: impl FnMut(u64, &[&str]) -> Result<()>,
) -> Result<()> {
    records(input, false, row)
}

/// As [`for_each_record`], but a first line with a tab (and no comma or
/// semicolon) makes the tab the separator: a table whose header names
/// hold spaces (`MD (m)`), as spreadsheets export them.
pub fn for_each_record_tab_aware<R: Read>(
    input: R,
    row: impl FnMut(u64, &[&str]) -> Result<()>,
) -> Result<()> {
    records(input, true, row)
}

fn records<R: Read>(
    input: R,
    tab_aware: bool,
    mut row: impl FnMut(u64, &[&str]) -> Result<()>,
) -> Result<()> {
    let mut limited = LineLimit::new(io::BufReader::new(input));
    let (prefix, separator) = first_content(&mut limited, tab_aware)?;
    let delimiter = match separator {
        Separator::Byte(b) => b,
        Separator::Whitespace => b' ',
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .delimiter(delimiter)
        .trim(csv::Trim::All)
        .from_reader(io::Cursor::new(prefix).chain(limited));
    let mut record = csv::ByteRecord::new();
    loop {
        match reader.read_byte_record(&mut record) {
            Ok(false) => return Ok(()),
            Ok(true) => {}
            Err(e) => bail!("{}", describe(&e)),
        }
        let line = record.position().map_or(0, csv::Position::line);
        let mut fields: Vec<&str> = Vec::with_capacity(record.len());
        for field in record.iter() {
            let text = std::str::from_utf8(field).map_err(|_| {
                anyhow::anyhow!(
                    "line {line}: `{}` is not UTF-8 text",
                    excerpt(&String::from_utf8_lossy(field))
                )
            })?;
            // Whitespace-separated: a tab inside, or empty fields between
            // repeated spaces, are more separators.
            if separator == Separator::Whitespace {
                fields.extend(text.split_whitespace());
            } else {
                fields.push(unquoted(text));
            }
        }
        if fields.iter().all(|f| f.is_empty()) || fields == [SKIPPED_LINE] {
            continue;
        }
        row(line, &fields)?;
    }
}

/// A field quoted after a blank (`a, "b"`), which the `csv` reader leaves
/// quoted, without its quotes.
fn unquoted(field: &str) -> &str {
    field
        .strip_prefix('"')
        .and_then(|f| f.strip_suffix('"'))
        .unwrap_or(field)
}

/// A `csv` error as a sentence without the input's bytes.
fn describe(e: &csv::Error) -> String {
    match e.kind() {
        csv::ErrorKind::Io(io) => io.to_string(),
        _ => format!("unreadable table: {}", excerpt(&e.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(text: &[u8]) -> Result<Vec<(u64, Vec<String>)>> {
        let mut out = Vec::new();
        for_each_record(text, |line, f| {
            out.push((line, f.iter().map(|s| s.to_string()).collect()));
            Ok(())
        })?;
        Ok(out)
    }

    #[test]
    fn separators_comments_bom_and_quotes() {
        let r = rows(b"\xEF\xBB\xBF# c\n\"time_s\", \"gx\"\n1, 2\n\n3,4\n").unwrap();
        assert_eq!(r[0], (2, vec!["time_s".into(), "gx".into()]));
        assert_eq!(r[2], (5, vec!["3".into(), "4".into()]));
        let r = rows(b"1   2\t 3\n4 5 6\n").unwrap();
        assert_eq!(r[0].1, ["1", "2", "3"]);
        let r = rows(b"a;b\n1;2\n").unwrap();
        assert_eq!(r[1].1, ["1", "2"]);
        let r = rows(b"a\tb\n1\t2\n").unwrap();
        assert_eq!(r[1], (2, vec!["1".into(), "2".into()]));
    }

    #[test]
    fn tab_aware_tables_keep_spaces_and_empty_fields() {
        let mut out = Vec::new();
        for_each_record_tab_aware(&b"MD (m)\tInc (deg)\n1\t\t2\n"[..], |_, f| {
            out.push(f.iter().map(|s| s.to_string()).collect::<Vec<_>>());
            Ok(())
        })
        .unwrap();
        assert_eq!(out, [vec!["MD (m)", "Inc (deg)"], vec!["1", "", "2"]]);
        // without a tab, as before: runs of blanks
        let mut out = Vec::new();
        for_each_record_tab_aware(&b"a  b\n1 2\n"[..], |_, f| {
            out.push(f.len());
            Ok(())
        })
        .unwrap();
        assert_eq!(out, [2, 2]);
    }

    #[test]
    fn long_lines_and_binary_are_refused_with_a_short_message() {
        let long = vec![b'1'; MAX_LINE_BYTES + 10];
        let e = rows(&long).unwrap_err().to_string();
        assert!(e.contains("line 1: longer than 65536 bytes"), "{e}");
        assert!(e.len() < 200, "{e}");
        let e = rows(b"1,2\n3,\0\0\0\n").unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("NUL"), "{e}");
        assert_eq!(excerpt(&"x".repeat(100)).len(), EXCERPT_CHARS + 3);
        assert_eq!(excerpt("a\u{1}"), "a\\u{1}");
    }
}
