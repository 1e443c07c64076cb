//! The probe's main loop, once for every board: start-up, then one pass
//! per sample period (the navigation of the waiting samples and the
//! recovery the acquisition asked for, [`SharedProbe::main_loop_pass`];
//! the tie-in once the navigator has levelled; the host's commands,
//! [`UplinkService::serve`]), the watchdog fed between the steps, asleep
//! otherwise.
//!
//! A board brings what differs ([`Board`]): its clock of sample periods,
//! its blocking delay and watchdog, how it sleeps and restarts, and what
//! it does at the end of each pass (the QEMU board: its measurements, its
//! end of run, its watchdog demo). Its interrupts (the acquisition timer,
//! the UART) and its peripherals' set-up stay in the board's binary.

use core::ops::ControlFlow;

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;
use embedded_storage::nor_flash::NorFlash;
use mwd_core::config::ProbeConfig;
use mwd_core::probe::Navigator;
use mwd_core::protocol::frame::nav_mode;

use super::board_basics::BoardBasics;
use super::boot::{boot_event_value, ResetCause};
use super::probe::Sensors;
use super::shared::SharedProbe;
use super::transmitter::Transmitter;
use super::uplink_rx::{InboxReader, UPLINK_QUEUE_LEN};
use super::uplink_service::{BoardAction, UplinkService};
use super::watchdog::Watchdog;

/// Uplink bytes the main loop takes per pass, once per sample period: the
/// inbox's capacity, more than the 576 B a period brings at 115200 baud,
/// so the line is drained as fast as it fills, while a flood costs each
/// period at most this.
pub const UPLINK_BYTES_PER_PASS: usize = UPLINK_QUEUE_LEN;

/// What the main loop needs of a board, besides the [`SharedProbe`] its
/// interrupts share with it.
pub trait Board {
    /// The parts' chip selects (the sensors' SPI).
    type Gyro: SpiDevice;
    type Accel: SpiDevice;
    /// The UART that sends the transmit queue.
    type Uart: Transmitter;
    /// The flash that keeps the configuration.
    type Flash: NorFlash;
    /// The blocking delay of the parts' start-up and recovery.
    type Delay: DelayNs;
    type Watchdog: Watchdog;
    /// What ends the loop ([`Board::end_of_pass`]): `Infallible` on a
    /// real board, whose loop never ends.
    type Stop;

    /// The delay, the watchdog (a recovery waits and feeds between its
    /// parts) and the sample periods begun since boot (the acquisition
    /// timer's interrupts).
    fn basics(&mut self) -> &mut BoardBasics<Self::Delay, Self::Watchdog>;

    /// Sleeps until the next interrupt.
    fn wait_for_interrupt(&mut self);

    /// Restarts the MCU (the reboot command), once its ACK and all queued
    /// before it have left the transmit queue and the transmitter says it
    /// is idle ([`Transmitter::is_idle`]).
    fn reboot(&mut self) -> !;

    /// The board's own work at the end of each pass, before the loop
    /// sleeps (e.g. measurements, the end of a test run);
    /// [`ControlFlow::Break`] ends the loop.
    fn end_of_pass(
        &mut self,
        probe: &SharedProbe<Self::Gyro, Self::Accel, Self::Uart>,
        uplink: &UplinkService<Self::Flash>,
        pass: &Pass,
    ) -> ControlFlow<Self::Stop> {
        let _ = (probe, uplink, pass);
        ControlFlow::Continue(())
    }

    /// Feeds the watchdog ([`Board::basics`]').
    fn feed_watchdog(&mut self) {
        self.basics().watchdog.feed();
    }
}

/// One pass of the main loop, as [`Board::end_of_pass`] sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pass {
    /// The sample periods begun ([`BoardBasics::ticks`]) when the pass
    /// began.
    pub tick: u32,
    /// The navigation changed mode in this pass (the once-only end of the
    /// coarse alignment and the filter's start: a far longer pass than
    /// the steady state's); not a (re-)start from initialising.
    pub mode_changed: bool,
}

/// The probe's main loop: loads the configuration from `flash`, sends the
/// boot event (with `reset_cause`), starts the parts and hands them to the
/// acquisition, then makes one pass per sample period until the board's
/// [`Board::end_of_pass`] stops it (on a real board: never). The host's
/// commands come from `uplink_inbox`, filled by the board's UART interrupt.
pub fn run<B: Board>(
    board: &mut B,
    probe: &SharedProbe<B::Gyro, B::Accel, B::Uart>,
    sensors: Sensors<B::Gyro, B::Accel>,
    flash: B::Flash,
    reset_cause: ResetCause,
    uplink_inbox: &mut InboxReader,
) -> B::Stop {
    let mut uplink = UplinkService::load(flash, 0);
    probe.announce_boot_with(boot_event_value(
        reset_cause,
        uplink.source(),
        uplink.config().version,
    ));
    board.feed_watchdog();
    {
        let basics = board.basics();
        probe.start_streaming(sensors, &mut basics.delay, &mut || basics.watchdog.feed());
    }
    #[cfg(feature = "defmt")]
    defmt::info!(
        "streaming at {=u32} Hz",
        mwd_core::timing::SAMPLE_RATE_HZ as u32
    );

    // The configured site and calibration (the defaults: the MGWD paper's
    // test site, uncorrected sensors).
    let mut navigator = navigator_for(uplink.config());
    navigator.apply_still_settings(&uplink.config().still);
    let mut tie_in_pending = uplink.config().tie_in;
    let mut mode = nav_mode::INITIALISING;
    let mut last_pass_tick = None;
    loop {
        let tick = board.basics().ticks();
        // One pass per sample period: every byte received wakes the main
        // loop (its interrupt), and a pass per byte would cost a stream of
        // them far more than the pass's work (all of which follows a new
        // sample); their bytes wait in the inbox for the next period.
        if last_pass_tick == Some(tick) {
            board.wait_for_interrupt();
            continue;
        }
        last_pass_tick = Some(tick);
        let mut mode_changed = false;
        {
            let basics = board.basics();
            probe.main_loop_pass(
                &mut basics.delay,
                &mut navigator,
                &mut || basics.watchdog.feed(),
                |part, code| {
                    #[cfg(feature = "defmt")]
                    defmt::warn!("part {=u8} recovered, code {=u16}", part, code);
                    let _ = (part, code);
                },
                |solution| {
                    mode_changed |= solution.mode != mode && mode != nav_mode::INITIALISING;
                    mode = solution.mode;
                },
            );
        }
        // A tie-in replaces the probe's own levelling as soon as it has
        // one (`Navigator::start_from_tie_in`).
        if let Some(tie_in) = tie_in_pending.filter(|_| navigator.is_navigating()) {
            navigator.start_from_tie_in(&tie_in);
            tie_in_pending = None;
        }
        board.feed_watchdog();
        match uplink.serve(probe, &mut navigator, uplink_inbox, UPLINK_BYTES_PER_PASS) {
            Some(BoardAction::Realign) => {
                #[cfg(feature = "defmt")]
                defmt::info!("re-aligning");
                realign(&mut navigator, uplink.config());
                tie_in_pending = uplink.config().tie_in;
                mode = nav_mode::INITIALISING;
            }
            Some(BoardAction::Reboot) => {
                #[cfg(feature = "defmt")]
                defmt::info!("rebooting");
                // Once the ACK (and all queued before it) has left.
                while !probe.with(|s| s.probe().queue().is_empty() && s.transmitter().is_idle()) {
                    board.feed_watchdog();
                    board.wait_for_interrupt();
                }
                board.reboot()
            }
            None => {}
        }
        let pass = Pass { tick, mode_changed };
        if let ControlFlow::Break(stop) = board.end_of_pass(probe, &uplink, &pass) {
            return stop;
        }
        board.wait_for_interrupt();
    }
}

/// The navigator the configuration asks for (site, calibration and still
/// settings; its tie-in is applied once the navigator levels, in the main
/// loop).
fn navigator_for(config: &ProbeConfig) -> Navigator {
    Navigator::with_calibration(config.site, config.calibration)
}

/// Starts the navigation over from `config`. Not inlined: the new
/// navigator (~9 KiB, most of it the filter's covariance) is built in this
/// call's frame, not in a second navigator-sized slot of the main loop's
/// frame, which would stay on the stack under every navigation step (the
/// stack high-water mark rose by 9 KiB when it did; docs/budgets.md).
#[inline(never)]
fn realign(navigator: &mut Navigator, config: &ProbeConfig) {
    *navigator = navigator_for(config);
    navigator.apply_still_settings(&config.still);
}

#[cfg(test)]
mod tests;
