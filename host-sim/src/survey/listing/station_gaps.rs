//! Stations the probe sent whose frames were not received: their
//! numbers found from the ones received (the probe numbers its stations
//! from 1 since boot, one by one), and how a listing names them.

use anyhow::{bail, Result};
use mwd_core::protocol::StationSurvey;
use std::collections::BTreeSet;

/// The number of the probe's first station since boot
/// (`StationSurvey::station`).
pub const FIRST_STATION: u16 = 1;

/// The station numbers from `first_number` to the last received that no
/// station in `stations` has, as ranges `first..=last`.
pub fn lost_numbers(first_number: u16, stations: &[StationSurvey]) -> Vec<(u16, u16)> {
    let received: BTreeSet<u16> = stations.iter().map(|s| s.station).collect();
    let mut lost = Vec::new();
    let mut next = first_number;
    for &n in received.range(first_number..) {
        if n > next {
            lost.push((next, n - 1));
        }
        next = n.saturating_add(1);
    }
    lost
}

/// The tie-on is the first usable station: with stations `lost` before
/// `first_kept` (the first usable one received), which station it is is
/// not known. A tie-on `given` (its MD or position) is then refused rather
/// than put on a later station, which would move every station by a
/// stand; without one the stations are placed from the surface anyway.
pub fn tie_on_station_known(lost: &[(u16, u16)], first_kept: u16, given: bool) -> Result<()> {
    match lost.first() {
        Some(&(from, to)) if given && from < first_kept => bail!(
            "{} lost (frame not received) before station {first_kept}, the first usable one \
             received: the tie-on belongs to the probe's first usable station, so it cannot be \
             placed, and putting it on station {first_kept} would move every station (survey a \
             capture that holds the lost station)",
            numbers_text(from, to)
        ),
        _ => Ok(()),
    }
}

/// "station 3" or "stations 3 to 5".
pub fn numbers_text(first: u16, last: u16) -> String {
    if first == last {
        format!("station {first}")
    } else {
        format!("stations {first} to {last}")
    }
}

/// The line a listing gives lost stations: "station 3 lost (frame not
/// received)".
pub fn lost_line(first: u16, last: u16) -> String {
    let frames = if first == last { "frame" } else { "frames" };
    format!("{} lost ({frames} not received)", numbers_text(first, last))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::protocol::{example, Payload};

    fn numbered(numbers: &[u16]) -> Vec<StationSurvey> {
        let Payload::Station(s) = example::station_survey() else {
            unreachable!("the example station is a station")
        };
        numbers
            .iter()
            .map(|&station| StationSurvey { station, ..s })
            .collect()
    }

    #[test]
    fn gaps_from_the_first_number_to_the_last_received() {
        assert_eq!(lost_numbers(1, &numbered(&[1, 2, 3])), vec![]);
        assert_eq!(lost_numbers(1, &numbered(&[2, 3])), vec![(1, 1)]);
        assert_eq!(
            lost_numbers(1, &numbered(&[1, 3, 7, 7, 6])),
            vec![(2, 2), (4, 5)]
        );
        // a display that forgot stations before 5
        assert_eq!(lost_numbers(5, &numbered(&[5, 6, 8])), vec![(7, 7)]);
        assert_eq!(lost_numbers(1, &numbered(&[])), vec![]);
        assert_eq!(
            lost_numbers(1, &numbered(&[u16::MAX])),
            vec![(1, u16::MAX - 1)]
        );
    }

    #[test]
    fn a_gap_is_named_by_its_numbers() {
        assert_eq!(lost_line(1, 1), "station 1 lost (frame not received)");
        assert_eq!(
            lost_line(3, 5),
            "stations 3 to 5 lost (frames not received)"
        );
    }
}
