//! The drilling run's sensor stream (feature `qemu-drilling`): a host file
//! read through ARM semihosting (SYS_OPEN, SYS_READ, SYS_ERRNO; QEMU's
//! `-semihosting-config enable=on,target=native`), chunk by chunk into the
//! player's fixed buffer; no heap.
//!
//! The file is `sensor-stream.bin` in QEMU's working directory, or the
//! path compiled in from `PROBE_QEMU_SENSOR_STREAM`.

use cortex_m_semihosting::{nr, syscall};
use hil_mock::{StreamError, StreamRead};

/// The stream's path, NUL-terminated for SYS_OPEN.
const PATH: &str = match option_env!("PROBE_QEMU_SENSOR_STREAM") {
    Some(path) => path,
    None => "sensor-stream.bin",
};

/// The path as given (for messages).
pub const fn path() -> &'static str {
    PATH
}

/// An open host file.
pub struct HostFile {
    handle: usize,
}

/// The host's errno after a failed call.
fn host_errno() -> i32 {
    // SAFETY: SYS_ERRNO takes no argument block and only returns a value.
    #[allow(unsafe_code)]
    let errno = unsafe { syscall!(ERRNO) };
    errno as i32
}

impl HostFile {
    /// Opens the stream file for binary reading.
    pub fn open() -> Result<Self, StreamError> {
        // SYS_OPEN wants a NUL-terminated name and its length without the
        // NUL: copy into a small buffer (no heap).
        let mut name = [0u8; 256];
        let bytes = PATH.as_bytes();
        if bytes.len() >= name.len() || bytes.contains(&0) {
            return Err(StreamError::Io(-1));
        }
        name[..bytes.len()].copy_from_slice(bytes);
        // SAFETY: the argument block is (pointer to a NUL-terminated name
        // that outlives the call, mode, length): what SYS_OPEN reads.
        #[allow(unsafe_code)]
        let handle = unsafe { syscall!(OPEN, name.as_ptr(), nr::open::R_BINARY, bytes.len()) };
        if handle as isize == -1 {
            return Err(StreamError::Io(host_errno()));
        }
        Ok(Self { handle })
    }
}

impl StreamRead for HostFile {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, StreamError> {
        if buf.is_empty() {
            return Ok(0);
        }
        // SAFETY: the argument block is (handle, pointer to `buf.len()`
        // writable bytes that outlive the call, length): SYS_READ writes
        // at most that many bytes there.
        #[allow(unsafe_code)]
        let not_read = unsafe { syscall!(READ, self.handle, buf.as_mut_ptr(), buf.len()) };
        // SYS_READ returns the number of bytes *not* read (0: all read;
        // the length: end of file); anything larger is an error.
        if not_read > buf.len() {
            return Err(StreamError::Io(host_errno()));
        }
        Ok(buf.len() - not_read)
    }
}
