//! A configuration write cut half way on the QEMU probe (issue 15 item 5):
//! the probe built with the feature `power-cut-test` cuts its flash writes
//! as `firmware::app::power_cut::POWER_CUT_PLAN` says (so many bytes
//! programmed, then a reset that the next boot reports as power-on), and
//! this test drives one write per step of the plan over the pty:
//!
//! 1. fresh RAM: power-on, the defaults; a site set whole (version 1);
//! 2. each cut write (a new site): no reply, a boot event saying power-on
//!    and the configuration from flash at the version stored before, and
//!    the probe still answers with it; the cut after the record's last
//!    byte instead loads the new version (committed, never acknowledged:
//!    the control that the cut writes do reach the flash);
//! 3. past the plan, a whole write is acknowledged, and after the reboot
//!    command the boot event says software reset, flash, that version.
//!
//! One QEMU run, at the probe's real pace: a boot per step, then the last
//! boot's [`RUN_SECONDS`]. qemu-system-arm must be installed: without it
//! this test fails, it does not skip. Linux only (ptys of /dev/pts).
#![cfg(target_os = "linux")]

mod qemu_link;

use firmware::app::boot::{boot_event_value, ConfigSource, ResetCause};
use firmware::app::power_cut::POWER_CUT_PLAN;
use mwd_core::config::record::RECORD_LEN;
use mwd_core::earth::Position;
use mwd_core::protocol::uplink::Command as Uplink;
use qemu_link::{acked, Link, QemuOnPty};
use system_tests::{build_firmware_for, require_qemu, summary_value};

/// Simulated seconds each boot streams before the probe ends its run
/// (the QEMU pty test's build length: the same dependencies' build).
const RUN_SECONDS: u32 = 10;

/// A different site for each write, so each is a change (a new version).
fn site(write: usize) -> Position {
    Position::new(0.5 + 0.01 * write as f64, -1.0, 100.0 * write as f64)
}

#[test]
fn a_configuration_write_cut_part_way_leaves_the_previous_configuration() {
    require_qemu();
    let elf = build_firmware_for("board-qemu,power-cut-test", "power-cut", Some(RUN_SECONDS));
    let mut qemu = QemuOnPty::start(&elf, None);
    let mut link = Link::open(&qemu.pty_path);
    qemu.monitor("cont");

    let power_on = |version| {
        let source = match version {
            0 => ConfigSource::Defaults,
            _ => ConfigSource::Flash,
        };
        boot_event_value(ResetCause::PowerOn, source, version)
    };
    assert_eq!(link.boot_value(), power_on(0));
    let mut stored = 0;
    let mut cuts = 0;
    for (write, planned) in POWER_CUT_PLAN.iter().enumerate() {
        let command = Uplink::SetSite(site(write));
        let Some(keep) = *planned else {
            stored += 1;
            acked(&link.send(&command), stored);
            continue;
        };
        cuts += 1;
        let seq = link.send_once(&command);
        if keep >= RECORD_LEN {
            stored += 1;
        }
        let (boot, replies) = link.boot_value_after();
        assert!(
            replies.iter().all(|r| r.command_seq != seq),
            "the cut write was answered: {replies:?}"
        );
        assert_eq!(
            boot,
            power_on(stored),
            "cut after {keep} of {RECORD_LEN} bytes: boot event {boot:#010x}"
        );
        acked(&link.send(&Uplink::ReportConfig), stored);
        println!("cut after {keep:3} bytes: boot event power-on, flash, version {stored}");
    }
    assert!(cuts >= 4, "the plan cuts {cuts} writes");

    // Past the plan: whole writes again, kept across the reboot command.
    stored += 1;
    acked(
        &link.send(&Uplink::SetSite(site(POWER_CUT_PLAN.len()))),
        stored,
    );
    acked(&link.send(&Uplink::Reboot), stored);
    let software = boot_event_value(ResetCause::Software, ConfigSource::Flash, stored);
    assert_eq!(link.boot_value(), software);
    acked(&link.send(&Uplink::ReportConfig), stored);

    let status = qemu.wait();
    assert!(status.success(), "probe-qemu failed: {}", qemu.out);
    // The last boot's run went as any other.
    assert_eq!(
        summary_value(&qemu.out, "samples"),
        u64::from(RUN_SECONDS) * 20,
        "{}",
        qemu.out
    );
    assert_eq!(
        summary_value(&qemu.out, "frames_dropped"),
        0,
        "{}",
        qemu.out
    );
}
