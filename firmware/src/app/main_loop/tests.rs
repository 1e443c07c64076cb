//! The main loop against a fake board: hil-mock parts on a simulated
//! clock, a timer that ticks each time the loop sleeps, a UART that sends
//! everything within the period, a watchdog that notes when it is fed and
//! an uplink line that brings commands at given periods.

extern crate std;

use core::cell::RefCell;

use super::*;
use crate::app::boot::ConfigSource;
use crate::app::ram_flash::{RamNorFlash, RAM_FLASH_ERASE_SIZE};
use crate::app::test_support::{drain, take_wire, TestUart};
use crate::app::uplink_rx::{InboxWriter, UplinkInbox};
use crate::app::{BoardBasics, SamplePeriods};
use crate::scc1300::Part;
use hil_mock::{
    AccelSpi, GyroSpi, MountedSource, Scc1300, SimClock, SimDelay, StillProbe, TimeSource,
    SAMPLE_PERIOD_NS,
};
use mwd_core::protocol::frame::nav_mode;
use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::{encode_command, Command, ReplyStatus, MAX_COMMAND_WIRE_LEN};
use mwd_core::protocol::{Decoder, EventKind, Payload};
use mwd_core::sensor_units::PART_MOUNTINGS;
use mwd_core::timing::ALIGNMENT_SAMPLES;
use std::vec::Vec;

type Mock<'a> = Scc1300<&'a SimClock, MountedSource<StillProbe>>;
type Gyro<'a> = GyroSpi<'a, &'a SimClock, MountedSource<StillProbe>>;
type Accel<'a> = AccelSpi<'a, &'a SimClock, MountedSource<StillProbe>>;
type Probe<'a> = SharedProbe<Gyro<'a>, Accel<'a>, TestUart>;

/// Notes the simulated time of each feed.
struct FakeWatchdog<'a> {
    clock: &'a SimClock,
    fed_at_ns: Vec<u64>,
}

impl Watchdog for FakeWatchdog<'_> {
    fn feed(&mut self) {
        self.fed_at_ns.push(self.clock.now_ns());
    }
}

struct FakeBoard<'a> {
    clock: &'a SimClock,
    probe: &'a Probe<'a>,
    basics: BoardBasics<SimDelay<'a>, FakeWatchdog<'a>>,
    /// Counts a period each time the loop sleeps.
    periods: &'static SamplePeriods,
    /// The timer stops sampling after this many samples (as QEMU's does).
    samples_to_run: u32,
    /// Each period's commands arrive on the uplink at its tick.
    commands: Vec<(u32, Vec<u8>)>,
    uplink: InboxWriter<'a>,
    /// Each pass and the watchdog's feeds by its end.
    passes: Vec<(Pass, usize)>,
}

impl<'a> Board for FakeBoard<'a> {
    type Gyro = Gyro<'a>;
    type Accel = Accel<'a>;
    type Uart = TestUart;
    type Flash = RamNorFlash<'a>;
    type Delay = SimDelay<'a>;
    type Watchdog = FakeWatchdog<'a>;
    /// The samples taken.
    type Stop = u32;

    fn basics(&mut self) -> &mut BoardBasics<SimDelay<'a>, FakeWatchdog<'a>> {
        &mut self.basics
    }

    /// One sample period: the timer's interrupt, the uplink's bytes of the
    /// period, then the UART's interrupts until the queue is empty.
    fn wait_for_interrupt(&mut self) {
        self.clock.advance_ns(SAMPLE_PERIOD_NS);
        self.periods.begin();
        let tick = self.periods.count();
        let samples_to_run = self.samples_to_run;
        self.probe.with(|shared| {
            if shared.probe().cycle().samples() < samples_to_run {
                shared.acquire();
            }
        });
        for (_, bytes) in self.commands.iter().filter(|(at, _)| *at == tick) {
            bytes.iter().for_each(|b| self.uplink.push(*b));
        }
        drain(self.probe);
    }

    fn reboot(&mut self) -> ! {
        panic!("no reboot was asked for")
    }

    fn end_of_pass(
        &mut self,
        probe: &Probe<'a>,
        _uplink: &UplinkService<RamNorFlash<'a>>,
        pass: &Pass,
    ) -> ControlFlow<u32> {
        self.passes
            .push((*pass, self.basics.watchdog.fed_at_ns.len()));
        let (samples, idle) = probe.with(|s| {
            let p = s.probe();
            let idle = p.queue().is_empty() && s.transmitter().is_idle();
            (p.cycle().samples(), idle && p.nav_inbox().is_empty())
        });
        if samples >= self.samples_to_run && idle {
            return ControlFlow::Break(samples);
        }
        ControlFlow::Continue(())
    }
}

fn command(seq: u16, command: &Command) -> Vec<u8> {
    let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
    let n = encode_command(seq, command, &mut wire).unwrap();
    wire[..n].to_vec()
}

/// Boot, start-up, a pass per period with a navigation frame for each raw
/// one, the commands answered (a re-alignment restarts the navigation),
/// the watchdog fed in every pass and never a period apart, the loop's
/// one mode change (the coarse alignment's end) told to the board.
#[test]
fn the_loop_streams_navigates_answers_and_feeds_the_watchdog() {
    const SAMPLES: u32 = ALIGNMENT_SAMPLES + 20;
    const REALIGN_AT: u32 = ALIGNMENT_SAMPLES + 10;
    let clock = SimClock::new();
    let mocks: [RefCell<Mock>; 2] = [0, 1].map(|i| {
        let source = MountedSource {
            body: StillProbe::paper_test(1 + i as u64),
            mounting: PART_MOUNTINGS[i],
        };
        RefCell::new(Scc1300::new(&clock, source, 1 + i as u32))
    });
    let sensors = [0, 1].map(|i| Part::new(GyroSpi::new(&mocks[i]), AccelSpi::new(&mocks[i])));
    let probe: Probe = SharedProbe::new(TestUart::default());
    let mut memory = [0u8; 2 * RAM_FLASH_ERASE_SIZE];
    let mut inbox = UplinkInbox::new();
    let (writer, mut reader) = inbox.split();
    // This test's own count (a static, as a board's is).
    static PERIODS: SamplePeriods = SamplePeriods::new();
    let mut board = FakeBoard {
        clock: &clock,
        probe: &probe,
        basics: BoardBasics::new(
            SimDelay::new(&clock),
            FakeWatchdog {
                clock: &clock,
                fed_at_ns: Vec::new(),
            },
            &PERIODS,
        ),
        periods: &PERIODS,
        samples_to_run: SAMPLES,
        commands: std::vec![
            (10, command(1, &Command::ReportConfig)),
            (REALIGN_AT, command(2, &Command::Realign)),
        ],
        uplink: writer,
        passes: Vec::new(),
    };
    let samples = run(
        &mut board,
        &probe,
        sensors,
        RamNorFlash::new(&mut memory),
        ResetCause::PowerOn,
        &mut reader,
    );
    assert_eq!(samples, SAMPLES);

    let wire = take_wire(&probe);
    let mut decoder = Decoder::new();
    let (mut boot, mut raws, mut navs, mut replies) = (Vec::new(), 0, Vec::new(), Vec::new());
    for byte in wire {
        match decoder.push(byte).map(|f| f.payload) {
            Some(Payload::Event(e)) if e.kind == EventKind::Boot => boot.push(e.value),
            Some(Payload::Event(e)) => panic!("unexpected event {e:?}"),
            Some(Payload::Raw(_)) => raws += 1,
            Some(Payload::Nav(n)) => navs.push(n),
            _ => {}
        }
        if let Some(Ok((_, reply))) = decoder.unknown_body().map(decode_reply_body) {
            replies.push((reply.command_seq, reply.status));
        }
    }
    assert_eq!((decoder.stats().corrupt(), decoder.stats().lost), (0, 0));
    let version = mwd_core::config::ProbeConfig::default().version;
    assert_eq!(
        boot,
        [boot_event_value(
            ResetCause::PowerOn,
            ConfigSource::Defaults,
            version
        )]
    );
    assert_eq!(raws, SAMPLES);
    assert_eq!(navs.len(), SAMPLES as usize);
    assert!(navs
        .iter()
        .enumerate()
        .all(|(n, nav)| nav.sample_counter as usize == n));
    assert_eq!(replies, [(1, ReplyStatus::Ack), (2, ReplyStatus::Ack)]);
    // Fine alignment after the coarse one, then coarse again from the
    // re-alignment on (its samples navigated by the new navigator).
    let modes: Vec<u8> = navs.iter().map(|n| n.mode).collect();
    assert_eq!(
        modes[ALIGNMENT_SAMPLES as usize + 5],
        nav_mode::FINE_ALIGNMENT
    );
    assert_eq!(modes[SAMPLES as usize - 1], nav_mode::COARSE_ALIGNMENT);

    // One pass per period (the first right after the start-up, at tick 0),
    // each feeding the watchdog at least twice (before and after the
    // navigation), and the watchdog never a period unfed once streaming.
    let passes = &board.passes;
    assert!(passes
        .iter()
        .enumerate()
        .all(|(i, (pass, _))| pass.tick == i as u32));
    assert!(passes.windows(2).all(|w| w[1].1 >= w[0].1 + 2));
    let streaming_from = board.basics.watchdog.fed_at_ns[passes[0].1 - 1];
    let fed = &board.basics.watchdog.fed_at_ns;
    assert!(fed
        .windows(2)
        .filter(|w| w[0] >= streaming_from)
        .all(|w| w[1] - w[0] <= SAMPLE_PERIOD_NS));
    // The coarse alignment's end is the one mode change the board hears
    // of (a re-alignment starts over without one).
    let changes: Vec<u32> = passes
        .iter()
        .filter(|(p, _)| p.mode_changed)
        .map(|(p, _)| p.tick)
        .collect();
    assert_eq!(changes.len(), 1, "{changes:?}");
}
