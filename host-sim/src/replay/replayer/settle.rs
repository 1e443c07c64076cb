//! Rows settled and forgotten: a row is settled once its comparison is
//! known (compared, out of step, or left without the probe's solution for
//! [`SETTLE_AFTER_SAMPLES`] later samples); a live replay writes its rows
//! out as they settle and forgets them, so that a replay of any length
//! keeps only the rows still settling.

use std::io::{self, Write};

use super::state::Awaiting;
use super::{Replayer, SETTLE_AFTER_SAMPLES};
use crate::replay::rows::ReplayRow;
use crate::replay::rows_csv::write_csv_rows;

impl Replayer {
    /// Rows not handed out before whose comparison is settled (compared,
    /// out of step, or left without the probe's solution for
    /// [`SETTLE_AFTER_SAMPLES`] samples), in order: what a live replay can
    /// write now. `all` settles every row (the stream ended).
    pub fn settled_rows(&mut self, all: bool) -> &[ReplayRow] {
        let from = self.settled - self.rows_forgotten;
        // Held raw frames count as later samples.
        let newest = self.rows.len() + self.held.len();
        let settled = self.rows[from..]
            .iter()
            .enumerate()
            .take_while(|(i, row)| {
                all || row.matches_probe.is_some()
                    || !row.in_step
                    || newest - (from + i) > SETTLE_AFTER_SAMPLES
            })
            .count();
        self.settled += settled;
        &self.rows[from..from + settled]
    }

    /// Forgets the rows [`settled_rows`](Self::settled_rows) handed out, so
    /// that a replay of any length (a live session, a day and a half of
    /// drilling) keeps only the rows still settling. A forgotten row whose
    /// probe solution has not come keeps its place in the comparison.
    pub fn forget_settled(&mut self) {
        let n = self.settled - self.rows_forgotten;
        for (k, row) in self.rows.drain(..n).enumerate() {
            let number = self.rows_forgotten + k;
            let counter = row.solution.sample_counter;
            if let Some(a) = self.awaiting_probe.get_mut(&counter) {
                if matches!(*a, Awaiting::Row(i) if i == number) {
                    *a = Awaiting::Forgotten { number, row };
                }
            }
        }
        self.rows_forgotten += n;
    }

    /// Writes the settled rows (all of them when `all`: the stream ended)
    /// to `csv` as CSV rows, flushed, and forgets them: a replay streaming
    /// its rows out keeps only the ones still settling.
    pub fn write_settled(
        &mut self,
        csv: Option<&mut (dyn Write + '_)>,
        all: bool,
    ) -> io::Result<()> {
        let rows = self.settled_rows(all);
        if let Some(out) = csv {
            if !rows.is_empty() {
                write_csv_rows(rows, &mut *out)?;
                out.flush()?;
            }
        }
        self.forget_settled();
        Ok(())
    }
}
