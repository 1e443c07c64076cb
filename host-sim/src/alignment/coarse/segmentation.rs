//! Splitting a recorded run into static segments (toolface positions) on
//! the physics: a 1 s block belongs to the current segment unless its mean
//! specific force or rates differ from the segment's by more than the
//! noise of a block mean allows, or its samples scatter more than the
//! sensors' noise (the tool is moving within it). A toolface change moves
//! the specific force across the tool by g sin(inclination) times the roll
//! change, so the test on the specific force is the roll test scaled by
//! the tilt's observability: near vertical a roll change the noise hides
//! is no change at all (the old fixed 2 deg roll test cut
//! a 5 deg-inclination run with 6 mg of noise into 8 pieces and dropped
//! most of it). The noise of a block mean is measured from the run itself
//! (robustly, from the differences of consecutive blocks), so coloured
//! noise and any sensor are covered. Every sample left out is reported
//! with its reason.
use crate::formats::samples_csv::Record;
use mwd_core::alignment::MAX_SEGMENTS;
use std::ops::Range;

/// Samples per block (1 s at 20 Hz).
pub const BLOCK: usize = 20;
/// Shortest static segment worth keeping (blocks).
pub const MIN_SEGMENT_BLOCKS: usize = 3;
/// A block whose mean differs from its segment's by more than this many
/// block-noise sigmas on any channel starts a new segment: 6 sigma, so a
/// static run of an hour (3600 blocks, 5 channels) is split by noise with
/// a probability of about 1e-5.
const CHANGE_SIGMAS: f64 = 6.0;
/// A block whose samples scatter more than this many times the typical
/// block's (in standard deviation) is moving.
const SCATTER_FACTOR: f64 = 3.0;
/// Smallest noise assumed for a block mean, so noise-free (simulated) data
/// still have a scale: specific force (m/s^2, 1 micro-g) and rate (rad/s,
/// 0.002 deg/h).
const FLOOR_ACCEL: f64 = 1e-5;
const FLOOR_RATE: f64 = 1e-8;
/// Median absolute deviation to standard deviation for normal noise.
const MAD_TO_SIGMA: f64 = 1.4826;

/// Why samples were left out of the alignment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeftOutReason {
    /// The tool moved (a toolface change or other motion): samples scatter
    /// beyond the noise, or a stretch between changes too short to keep.
    Moving,
    /// The last samples, fewer than a 1 s block.
    PartialBlock,
    /// Static, but beyond the [`MAX_SEGMENTS`] longest segments an
    /// alignment takes.
    TooManySegments,
}

impl LeftOutReason {
    pub fn text(self) -> &'static str {
        match self {
            Self::Moving => "moving (toolface change or other motion, or static for under 3 s)",
            Self::PartialBlock => "the last samples, fewer than a 1 s block",
            Self::TooManySegments => "static, but beyond the 8 longest segments an alignment takes",
        }
    }
}

/// The static segments of a run and every sample left out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Segmentation {
    /// Sample ranges of the static segments, in time order.
    pub spans: Vec<Range<usize>>,
    /// Sample ranges left out, in time order, with the reason.
    pub left_out: Vec<(Range<usize>, LeftOutReason)>,
}

/// Channels of a block: specific force x y z, rate x z.
const CHANNELS: usize = 5;

struct Block {
    mean: [f64; CHANNELS],
    /// Root-mean-square scatter of the specific-force samples about the
    /// block mean (m/s^2, all axes).
    scatter: f64,
}

fn channels(r: &Record) -> [f64; CHANNELS] {
    let f = &r.sample.specific_force;
    [f.x, f.y, f.z, r.sample.gyro[0], r.sample.gyro[1]]
}

fn block(records: &[Record]) -> Block {
    let n = records.len() as f64;
    let mut mean = [0.0; CHANNELS];
    for r in records {
        for (m, v) in mean.iter_mut().zip(channels(r)) {
            *m += v / n;
        }
    }
    let spread: f64 = records
        .iter()
        .map(|r| {
            let c = channels(r);
            (0..3).map(|k| (c[k] - mean[k]).powi(2)).sum::<f64>()
        })
        .sum();
    Block {
        mean,
        scatter: (spread / n).sqrt(),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The noise of a block mean per channel: the median absolute deviation of
/// consecutive blocks' differences (robust to the few blocks of a turn),
/// over sqrt(2), with a floor.
fn block_sigmas(blocks: &[Block]) -> [f64; CHANNELS] {
    let mut sigma = [0.0; CHANNELS];
    for (c, s) in sigma.iter_mut().enumerate() {
        let diffs: Vec<f64> = blocks
            .windows(2)
            .map(|w| w[1].mean[c] - w[0].mean[c])
            .collect();
        let centre = median(diffs.clone());
        let mad = median(diffs.iter().map(|d| (d - centre).abs()).collect());
        let floor = if c < 3 { FLOOR_ACCEL } else { FLOOR_RATE };
        *s = (MAD_TO_SIGMA * mad / std::f64::consts::SQRT_2).max(floor);
    }
    sigma
}

/// Splits a run into static segments; see the module documentation.
pub fn segment_run(records: &[Record]) -> Segmentation {
    let count = records.len() / BLOCK;
    let blocks: Vec<Block> = (0..count)
        .map(|b| block(&records[b * BLOCK..(b + 1) * BLOCK]))
        .collect();
    let sigma = block_sigmas(&blocks);
    let typical_scatter = median(blocks.iter().map(|b| b.scatter).collect());
    let scatter_limit = SCATTER_FACTOR * typical_scatter.max(FLOOR_ACCEL);

    // Runs of blocks, each either static (one toolface) or moving.
    let mut runs: Vec<(Range<usize>, bool)> = Vec::new();
    let mut sums = [0.0; CHANNELS];
    let mut start = 0;
    for (b, blk) in blocks.iter().enumerate() {
        // NaN (a broken sample) counts as moving.
        let moving = blk.scatter.is_nan() || blk.scatter > scatter_limit;
        let in_run = b - start;
        let changed = in_run > 0 && {
            let scale = (1.0 + 1.0 / in_run as f64).sqrt();
            (0..CHANNELS).any(|c| {
                let d = blk.mean[c] - sums[c] / in_run as f64;
                d.is_nan() || d.abs() > CHANGE_SIGMAS * sigma[c] * scale
            })
        };
        if moving || changed {
            if b > start {
                runs.push((start..b, false));
            }
            start = b;
            sums = [0.0; CHANNELS];
        }
        if moving {
            runs.push((b..b + 1, true));
            start = b + 1;
            continue;
        }
        for (s, v) in sums.iter_mut().zip(blk.mean) {
            *s += v;
        }
    }
    if count > start {
        runs.push((start..count, false));
    }

    let mut statics: Vec<Range<usize>> = runs
        .iter()
        .filter(|(r, moving)| !moving && r.len() >= MIN_SEGMENT_BLOCKS)
        .map(|(r, _)| r.clone())
        .collect();
    // Keep the longest MAX_SEGMENTS, in time order.
    let mut by_length = statics.clone();
    by_length.sort_by_key(|r| std::cmp::Reverse(r.len()));
    let kept: Vec<Range<usize>> = by_length.into_iter().take(MAX_SEGMENTS).collect();
    statics.retain(|r| kept.contains(r));

    let mut left_out: Vec<(Range<usize>, LeftOutReason)> = Vec::new();
    let mut push = |range: Range<usize>, reason: LeftOutReason| match left_out.last_mut() {
        Some((last, r)) if *r == reason && last.end == range.start => last.end = range.end,
        _ => left_out.push((range, reason)),
    };
    for (run, moving) in &runs {
        let samples = run.start * BLOCK..run.end * BLOCK;
        if *moving || run.len() < MIN_SEGMENT_BLOCKS {
            push(samples, LeftOutReason::Moving);
        } else if !statics.contains(run) {
            push(samples, LeftOutReason::TooManySegments);
        }
    }
    if records.len() > count * BLOCK {
        push(count * BLOCK..records.len(), LeftOutReason::PartialBlock);
    }
    Segmentation {
        spans: statics
            .into_iter()
            .map(|r| r.start * BLOCK..r.end * BLOCK)
            .collect(),
        left_out,
    }
}
