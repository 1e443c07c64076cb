//! Frames the link repeated, swapped or dropped, as `decode`, `replay`
//! and `survey` count them: a duplicate is dropped and counted (no loss,
//! no restart), a late frame counted reordered and its loss taken back,
//! a dropped frame lost (`decode` exits 2, written but incomplete); a
//! station frame the probe sent again is taken once, another station under
//! the same number refused.
mod common;

use common::{capture_frames, run, s, scratch, simulate_tied_in, Run};
use mwd_core::protocol::{encode_frame, Payload, MAX_WIRE_LEN};
use std::path::{Path, PathBuf};

/// The capture's chunks (frame with its delimiter) rearranged by
/// `arrange` (given the chunks and each one's payload), written beside it
/// as `name`.
fn rearranged(
    capture: &Path,
    name: &str,
    arrange: impl Fn(&mut Vec<(Vec<u8>, Option<Payload>)>),
) -> PathBuf {
    let bytes = std::fs::read(capture).unwrap();
    let mut chunks: Vec<_> = capture_frames(&bytes)
        .into_iter()
        .map(|(chunk, frame)| (chunk, frame.map(|f| f.payload)))
        .collect();
    arrange(&mut chunks);
    let out = capture.with_file_name(name);
    let bytes: Vec<u8> = chunks.iter().flat_map(|(chunk, _)| chunk.clone()).collect();
    std::fs::write(&out, bytes).unwrap();
    out
}

/// Index of the `n`th chunk (from 0) whose payload `pick` takes.
fn nth(chunks: &[(Vec<u8>, Option<Payload>)], n: usize, pick: fn(&Payload) -> bool) -> usize {
    chunks
        .iter()
        .enumerate()
        .filter(|(_, (_, p))| p.as_ref().is_some_and(pick))
        .nth(n)
        .map(|(k, _)| k)
        .unwrap()
}

fn is_nav(p: &Payload) -> bool {
    matches!(p, Payload::Nav(_))
}

fn is_raw(p: &Payload) -> bool {
    matches!(p, Payload::Raw(_))
}

fn is_station(p: &Payload) -> bool {
    matches!(p, Payload::Station(_))
}

/// The frames renumbered from 0 after `arrange` changed them (the probe
/// numbers what it sends): every chunk must be a frame.
fn renumbered(chunks: &mut [(Vec<u8>, Option<Payload>)]) {
    let mut seq = 0u16;
    for (chunk, payload) in chunks.iter_mut() {
        let Some(p) = payload else {
            assert!(chunk.iter().all(|&b| b == 0), "only frames to renumber");
            continue;
        };
        let mut buf = [0u8; MAX_WIRE_LEN];
        let n = encode_frame(seq, p, &mut buf).unwrap();
        *chunk = buf[..n].to_vec();
        seq = seq.wrapping_add(1);
    }
}

/// `decode` of `capture`: exit `code`, and its gaps line reads `gaps`.
fn decodes_to(capture: &Path, code: i32, gaps: &str) -> Run {
    runs_to(
        &["decode", s(capture)],
        code,
        &format!("sequence gaps    {gaps}"),
    )
}

/// `host-sim args`: exit `code`, and `said` on its standard output or
/// error.
fn runs_to(args: &[&str], code: i32, said: &str) -> Run {
    let out = run(args);
    assert_eq!(out.code, Some(code), "{}{}", out.stdout, out.stderr);
    assert!(
        out.stdout.contains(said) || out.stderr.contains(said),
        "{said}: {}{}",
        out.stdout,
        out.stderr
    );
    out
}

/// The listing's station lines (a number, then MD).
fn station_lines(listing: &str) -> Vec<String> {
    listing
        .lines()
        .filter(|l| {
            let mut words = l.split_whitespace();
            words.next().is_some_and(|w| w.parse::<u16>().is_ok())
                && words.next().is_some_and(|w| w.parse::<f64>().is_ok())
        })
        .map(String::from)
        .collect()
}

#[test]
fn duplicated_reordered_and_dropped_frames_are_counted_apart() {
    let dir = scratch("frame-order", "counts");
    let (bin, depth, job) = simulate_tied_in(&dir);
    let whole = decodes_to(
        &bin,
        0,
        "0 frames lost, 0 restarts, 0 duplicated, 0 reordered",
    );
    let whole_survey = run(&["survey", s(&bin), "--depth", s(&depth), "--job", s(&job)]);
    assert_eq!(whole_survey.code, Some(0), "{}", whole_survey.stderr);

    // the 100th navigation frame and the first station frame twice each,
    // the second right after the first (the link repeated them)
    let twice = rearranged(&bin, "twice.bin", |chunks| {
        let nav = nth(chunks, 100, is_nav);
        let station = nth(chunks, 0, is_station);
        for k in [station, nav] {
            let again = chunks[k].clone();
            chunks.insert(k + 1, again);
        }
    });
    let out = decodes_to(
        &twice,
        0,
        "0 frames lost, 0 restarts, 2 duplicated, 0 reordered",
    );
    let head = |t: &str| t.lines().nth(2).map(String::from);
    assert_eq!(head(&out.stdout), head(&whole.stdout), "the same frames");
    // the replay sees each frame once: parity, as the whole capture
    let replay = run(&["replay", s(&twice), "--job", s(&job)]);
    assert_eq!(replay.code, Some(0), "{}{}", replay.stdout, replay.stderr);
    assert!(replay.stdout.contains("2 duplicated"), "{}", replay.stdout);
    let survey = run(&["survey", s(&twice), "--depth", s(&depth), "--job", s(&job)]);
    assert_eq!(survey.code, Some(0), "{}", survey.stderr);
    assert!(
        survey.stdout.contains(
            "capture: 0 bad frames skipped, 0 frames lost in sequence gaps, 2 repeated frames \
             taken once (0 station frames), 0 reordered frames"
        ),
        "{}",
        survey.stdout
    );
    assert_eq!(
        station_lines(&survey.stdout),
        station_lines(&whole_survey.stdout)
    );

    // a navigation frame after the raw frame of the next sample: reordered,
    // nothing lost, nothing out of step
    let swapped = rearranged(&bin, "swapped.bin", |chunks| {
        let nav = nth(chunks, 200, is_nav);
        let raw = nth(chunks, 201, is_raw);
        assert!(raw > nav, "the next sample's raw frame");
        chunks.swap(nav, raw);
    });
    decodes_to(
        &swapped,
        0,
        "0 frames lost, 0 restarts, 0 duplicated, 1 reordered",
    );
    let args = ["replay", s(&swapped), "--job", s(&job)];
    let replay = runs_to(&args, 0, "identical, 0 different, 0 not compared");
    assert!(!replay.stdout.contains("out of step"), "{}", replay.stdout);

    // a raw frame after the next raw frame: reordered for the decoder; the
    // replay steps its samples in the order received and, when the later
    // one came, could not tell a late frame from a lost one: it stops
    // comparing from there and says so under "out of step" (with the job's
    // tie-in the replay is post-processing: exit 0 all the same)
    let late_raw = rearranged(&bin, "late-raw.bin", |chunks| {
        let raw = nth(chunks, 300, is_raw);
        let next = nth(chunks, 301, is_raw);
        let moved = chunks.remove(raw);
        chunks.insert(next, moved);
    });
    decodes_to(
        &late_raw,
        0,
        "0 frames lost, 0 restarts, 0 duplicated, 1 reordered",
    );
    let args = ["replay", s(&late_raw), "--job", s(&job)];
    let out_of_step = "out of step      run 0: not compared from sample 301 on";
    let replay = runs_to(&args, 0, out_of_step);
    assert!(replay.stdout.contains("1 reordered"), "{}", replay.stdout);

    // a frame dropped: lost, written but incomplete
    let dropped = rearranged(&bin, "dropped.bin", |chunks| {
        chunks.remove(nth(chunks, 50, is_nav));
    });
    let out = decodes_to(
        &dropped,
        2,
        "1 frames lost, 0 restarts, 0 duplicated, 0 reordered",
    );
    assert!(
        out.stderr
            .contains("warning: the capture is incomplete: 1 frames lost"),
        "{}",
        out.stderr
    );
}

#[test]
fn a_station_sent_again_is_taken_once_and_another_under_its_number_refused() {
    let dir = scratch("frame-order", "stations");
    let (bin, depth, job) = simulate_tied_in(&dir);
    let survey = |capture: &Path, code: i32, said: &str| {
        let args = ["survey", s(capture), "--depth", s(&depth), "--job", s(&job)];
        runs_to(&args, code, said)
    };
    let whole = survey(&bin, 0, "station links");

    // the probe sent the first station again a few frames later (its own
    // number in the sequence)
    let again = |changed: bool| {
        move |chunks: &mut Vec<(Vec<u8>, Option<Payload>)>| {
            let station = nth(chunks, 0, is_station);
            let mut copy = chunks[station].clone();
            if let (true, Some(Payload::Station(st))) = (changed, copy.1.as_mut()) {
                st.angles[0] += 0.01;
            }
            chunks.insert(station + 5, copy);
            renumbered(chunks);
        }
    };
    let sent_again = rearranged(&bin, "sent-again.bin", again(false));
    decodes_to(
        &sent_again,
        0,
        "0 frames lost, 0 restarts, 0 duplicated, 0 reordered",
    );
    let out = survey(
        &sent_again,
        0,
        "1 repeated frames taken once (1 station frames)",
    );
    assert_eq!(station_lines(&out.stdout), station_lines(&whole.stdout));

    let other = rearranged(&bin, "other-station.bin", again(true));
    survey(&other, 1, "two different station frames numbered 1");
}
