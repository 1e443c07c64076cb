//! Little-endian field writer and reader over a byte slice. Every access is
//! bounds-checked and reports running out of room instead of panicking, so
//! a frame body of the wrong length is an error, never a crash.

/// The slice ended before the field did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutOfRoom;

impl core::fmt::Display for OutOfRoom {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("the buffer ended before the field did")
    }
}

impl core::error::Error for OutOfRoom {}

/// Writes fields one after another into `buf`.
pub struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl<'a> Writer<'a> {
    pub fn new(buf: &'a mut [u8]) -> Self {
        Self { buf, pos: 0 }
    }

    /// Bytes written so far.
    pub fn len(&self) -> usize {
        self.pos
    }

    pub fn is_empty(&self) -> bool {
        self.pos == 0
    }

    pub fn bytes(&mut self, data: &[u8]) -> Result<(), OutOfRoom> {
        let end = self.pos.checked_add(data.len()).ok_or(OutOfRoom)?;
        let dest = self.buf.get_mut(self.pos..end).ok_or(OutOfRoom)?;
        dest.copy_from_slice(data);
        self.pos = end;
        Ok(())
    }

    pub fn u8(&mut self, v: u8) -> Result<(), OutOfRoom> {
        self.bytes(&[v])
    }
    pub fn u16(&mut self, v: u16) -> Result<(), OutOfRoom> {
        self.bytes(&v.to_le_bytes())
    }
    pub fn i16(&mut self, v: i16) -> Result<(), OutOfRoom> {
        self.bytes(&v.to_le_bytes())
    }
    pub fn u32(&mut self, v: u32) -> Result<(), OutOfRoom> {
        self.bytes(&v.to_le_bytes())
    }
    pub fn u64(&mut self, v: u64) -> Result<(), OutOfRoom> {
        self.bytes(&v.to_le_bytes())
    }
    pub fn f32(&mut self, v: f32) -> Result<(), OutOfRoom> {
        self.bytes(&v.to_le_bytes())
    }
    pub fn f64(&mut self, v: f64) -> Result<(), OutOfRoom> {
        self.bytes(&v.to_le_bytes())
    }
    pub fn f32s<const N: usize>(&mut self, v: &[f32; N]) -> Result<(), OutOfRoom> {
        v.iter().try_for_each(|x| self.f32(*x))
    }
}

/// Reads fields one after another from `buf`.
pub struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    pub fn new(buf: &'a [u8]) -> Self {
        Self { buf, pos: 0 }
    }

    /// Bytes not read yet.
    pub fn remaining(&self) -> usize {
        self.buf.len().saturating_sub(self.pos)
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N], OutOfRoom> {
        let end = self.pos.checked_add(N).ok_or(OutOfRoom)?;
        let src = self.buf.get(self.pos..end).ok_or(OutOfRoom)?;
        let mut out = [0u8; N];
        out.copy_from_slice(src);
        self.pos = end;
        Ok(out)
    }

    pub fn u8(&mut self) -> Result<u8, OutOfRoom> {
        self.take::<1>().map(|b| b[0])
    }
    pub fn u16(&mut self) -> Result<u16, OutOfRoom> {
        self.take().map(u16::from_le_bytes)
    }
    pub fn i16(&mut self) -> Result<i16, OutOfRoom> {
        self.take().map(i16::from_le_bytes)
    }
    pub fn u32(&mut self) -> Result<u32, OutOfRoom> {
        self.take().map(u32::from_le_bytes)
    }
    pub fn u64(&mut self) -> Result<u64, OutOfRoom> {
        self.take().map(u64::from_le_bytes)
    }
    pub fn f32(&mut self) -> Result<f32, OutOfRoom> {
        self.take().map(f32::from_le_bytes)
    }
    pub fn f64(&mut self) -> Result<f64, OutOfRoom> {
        self.take().map(f64::from_le_bytes)
    }
    pub fn f32s<const N: usize>(&mut self) -> Result<[f32; N], OutOfRoom> {
        let mut out = [0.0; N];
        for slot in out.iter_mut() {
            *slot = self.f32()?;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn little_endian_round_trip() {
        let mut buf = [0u8; 19];
        let mut w = Writer::new(&mut buf);
        w.u8(0xAB).unwrap();
        w.u16(0x1234).unwrap();
        w.i16(-2).unwrap();
        w.u32(0xDEAD_BEEF).unwrap();
        w.f64(1.5).unwrap();
        w.u16(7).unwrap();
        assert_eq!(w.len(), 19);
        assert_eq!(w.u8(0), Err(OutOfRoom));
        assert_eq!(&buf[..7], &[0xAB, 0x34, 0x12, 0xFE, 0xFF, 0xEF, 0xBE]);
        let mut r = Reader::new(&buf);
        assert_eq!(r.u8(), Ok(0xAB));
        assert_eq!(r.u16(), Ok(0x1234));
        assert_eq!(r.i16(), Ok(-2));
        assert_eq!(r.u32(), Ok(0xDEAD_BEEF));
        assert_eq!(r.f64(), Ok(1.5));
        assert_eq!(r.remaining(), 2);
        assert_eq!(r.u32(), Err(OutOfRoom));
        assert_eq!(r.u16(), Ok(7));
    }
}
