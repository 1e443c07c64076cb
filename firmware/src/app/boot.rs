//! What the boot event tells the host about the boot (docs/protocol.md,
//! "Event codes"): its `value` packs the reset cause, where the
//! configuration came from, and the configuration's version, so one frame
//! says both why the probe restarted and what it will survey with.

/// Why the MCU restarted (from the MCU's reset flags). Codes as
/// sent in the boot event's low byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResetCause {
    /// The board cannot tell (0: also what older firmware sent).
    NotReported = 0,
    PowerOn = 1,
    Watchdog = 2,
    /// The firmware asked for it (the uplink's reboot command).
    Software = 3,
    /// The reset pin (on QEMU: the monitor's `system_reset`).
    Pin = 4,
    BrownOut = 5,
}

/// Where the configuration in use came from: the boot event's second byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConfigSource {
    NotReported = 0,
    /// No valid record in either flash slot.
    Defaults = 1,
    /// A valid record in flash.
    Flash = 2,
}

/// The largest configuration version the boot event can carry; a higher
/// one is sent as this (65,535 accepted changes would wear the flash out
/// long before).
pub const BOOT_VERSION_MAX: u32 = 0xFFFF;

/// The boot event's `value`: bits 0-7 the reset cause, 8-15 the
/// configuration's source, 16-31 its version (saturated at
/// [`BOOT_VERSION_MAX`]). 0 is "nothing reported", as older firmware sent.
pub fn boot_event_value(cause: ResetCause, source: ConfigSource, config_version: u32) -> u32 {
    cause as u32 | (source as u32) << 8 | config_version.min(BOOT_VERSION_MAX) << 16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fields_stay_in_their_bytes() {
        assert_eq!(
            boot_event_value(ResetCause::NotReported, ConfigSource::NotReported, 0),
            0
        );
        assert_eq!(
            boot_event_value(ResetCause::Software, ConfigSource::Flash, 3),
            0x0003_0203
        );
        assert_eq!(
            boot_event_value(ResetCause::BrownOut, ConfigSource::Defaults, u32::MAX),
            0xFFFF_0105
        );
    }
}
