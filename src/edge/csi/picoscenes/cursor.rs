//! A bounds-checked reader over one PicoScenes frame or segment: every read names the frame
//! and the field it was reading when the bytes ran out.

use alloc::format;
use alloc::string::String;

use crate::error::{Error, Result};

/// Little-endian reads from a frame's bytes whose errors name the frame and the field.
pub(super) struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// The frame (0-based, file order).
    pub frame: usize,
    prefix: String,
}

impl<'a> Cursor<'a> {
    /// A cursor over `bytes` of `frame`; fields are named `<segment>.<field>`.
    pub fn new(bytes: &'a [u8], frame: usize, segment: &str) -> Self {
        let prefix = if segment.is_empty() {
            String::new()
        } else {
            format!("{segment}.")
        };
        Cursor {
            bytes,
            pos: 0,
            frame,
            prefix,
        }
    }

    /// The error of `field`.
    pub fn bad(&self, field: &str, reason: String) -> Error {
        Error::InvalidFile {
            field: format!("frame {}: {}{field}", self.frame, self.prefix),
            reason,
        }
    }

    /// The next `n` bytes.
    pub fn take(&mut self, field: &str, n: usize) -> Result<&'a [u8]> {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let out = rest.get(..n).ok_or_else(|| {
            self.bad(
                field,
                format!("truncated: {n} bytes needed, {} remain", rest.len()),
            )
        })?;
        self.pos += n;
        Ok(out)
    }

    fn array<const N: usize>(&mut self, field: &str) -> Result<[u8; N]> {
        let b = self.take(field, N)?;
        let mut a = [0u8; N];
        a.copy_from_slice(b);
        Ok(a)
    }

    /// A u8.
    pub fn u8(&mut self, field: &str) -> Result<u8> {
        Ok(self.array::<1>(field)?[0])
    }

    /// A u16.
    pub fn u16(&mut self, field: &str) -> Result<u16> {
        self.array(field).map(u16::from_le_bytes)
    }

    /// A u32.
    pub fn u32(&mut self, field: &str) -> Result<u32> {
        self.array(field).map(u32::from_le_bytes)
    }

    /// A u64.
    pub fn u64(&mut self, field: &str) -> Result<u64> {
        self.array(field).map(u64::from_le_bytes)
    }

    /// The bytes not read yet.
    pub fn rest(&self) -> &'a [u8] {
        self.bytes.get(self.pos..).unwrap_or_default()
    }
}
