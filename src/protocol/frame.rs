//! Framing: CRC-32 and COBS, and a byte-at-a-time frame reader. Nothing here allocates or
//! panics, whatever the input.
//!
//! A frame on the wire is `COBS(payload ++ crc32_le(payload)) ++ [0x00]`.

/// CRC-32/ISO-HDLC (the zlib / Ethernet CRC: reflected polynomial `0xEDB88320`, initial value and
/// final xor `0xFFFF_FFFF`). Bitwise, table-less: a few hundred bytes of code, ~8 shifts a byte.
pub fn crc32(data: &[u8]) -> u32 {
    !data.iter().fold(CRC32_INIT, |crc, &b| crc32_step(crc, b))
}

/// The CRC register before the first byte (the result is `!register` after the last one).
pub(crate) const CRC32_INIT: u32 = !0;

/// Feed one byte into the CRC register: [`crc32`] a byte at a time.
pub(crate) fn crc32_step(mut crc: u32, b: u8) -> u32 {
    crc ^= u32::from(b);
    for _ in 0..8 {
        crc = (crc >> 1) ^ (0xEDB8_8320 & 0u32.wrapping_sub(crc & 1));
    }
    crc
}

/// Most bytes COBS adds to `len` payload bytes (one code byte, plus one per 254 bytes).
pub const fn cobs_overhead(len: usize) -> usize {
    (len / 254).wrapping_add(1) // at most usize::MAX / 254 + 1: no wrap
}

/// Largest complete frame on the wire (with its delimiter) for a payload of `len` bytes, CRC
/// included. Saturates at `usize::MAX` for absurd lengths (no buffer is that large).
pub const fn wire_len(len: usize) -> usize {
    len.saturating_add(cobs_overhead(len)).saturating_add(1)
}

/// COBS-encode `buf[src..src + len]` into `buf[0..]`, in place. `src` must be at least
/// [`cobs_overhead`]`(len)`, so the writes never overtake the reads. Returns the encoded length
/// (no delimiter), or `None` if the buffer is too short.
pub(crate) fn cobs_encode_in_place(buf: &mut [u8], src: usize, len: usize) -> Option<usize> {
    if src < cobs_overhead(len) || src.checked_add(len)? > buf.len() {
        return None;
    }
    // No `wrapping_` here wraps: `src + i < src + len <= buf.len()`, `out <= src + i + 1` (the
    // writes never overtake the reads) and `code <= 0xFE` before it is incremented.
    let mut code_at = 0usize;
    let mut out = 1usize;
    let mut code: u8 = 1;
    for i in 0..len {
        let b = *buf.get(src.wrapping_add(i))?;
        if b == 0 {
            *buf.get_mut(code_at)? = code;
            code_at = out;
            out = out.wrapping_add(1);
            code = 1;
        } else {
            *buf.get_mut(out)? = b;
            out = out.wrapping_add(1);
            code = code.wrapping_add(1);
            if code == 0xFF {
                *buf.get_mut(code_at)? = code;
                code_at = out;
                out = out.wrapping_add(1);
                code = 1;
            }
        }
    }
    *buf.get_mut(code_at)? = code;
    Some(out)
}

/// COBS-decode `buf` (one frame, without its delimiter) in place. Returns the decoded length, or
/// `None` if `buf` is not valid COBS (a zero byte, or a code byte pointing past the end).
pub(crate) fn cobs_decode_in_place(buf: &mut [u8]) -> Option<usize> {
    let n = buf.len();
    let (mut r, mut w) = (0usize, 0usize);
    while r < n {
        let code = *buf.get(r)?;
        if code == 0 {
            return None;
        }
        // No `wrapping_` in this loop wraps: `r < n` here, `code >= 1`, and `w <= r <= end <= n`.
        r = r.wrapping_add(1);
        let run = usize::from(code.wrapping_sub(1));
        let end = r.checked_add(run)?;
        if end > n || buf.get(r..end)?.contains(&0) {
            return None;
        }
        // `w <= r` always (each block loses its code byte), so this only moves bytes left. Byte
        // by byte rather than `copy_within`, which keeps a panic path the compiler cannot drop.
        for i in r..end {
            let b = *buf.get(i)?;
            *buf.get_mut(w.wrapping_add(i.wrapping_sub(r)))? = b;
        }
        w = w.wrapping_add(run);
        r = end;
        if code != 0xFF && r < n {
            *buf.get_mut(w)? = 0;
            w = w.wrapping_add(1);
        }
    }
    Some(w)
}

/// What [`FrameReader::push`] saw.
#[derive(Debug, PartialEq, Eq)]
pub enum Feed<'a> {
    /// Nothing complete yet (also returned for empty frames: a lone `0x00` only resynchronises).
    Pending,
    /// A complete frame, still COBS-encoded and without its delimiter: pass it to
    /// [`super::decode_request`] or [`super::decode_reply`].
    Frame(&'a mut [u8]),
    /// A frame longer than the reader's buffer ended here; it was dropped. `len` is its length on
    /// the wire without the delimiter (saturating).
    TooLarge {
        /// Bytes the dropped frame had.
        len: usize,
    },
}

/// Splits a byte stream into frames at `0x00` delimiters, in a fixed buffer of `N` bytes: the
/// largest encoded frame it accepts, without the delimiter. Longer frames are dropped whole and
/// reported as [`Feed::TooLarge`] when their delimiter arrives.
#[derive(Debug)]
pub struct FrameReader<const N: usize> {
    buf: [u8; N],
    len: usize,
    overflow: bool,
}

impl<const N: usize> FrameReader<N> {
    /// An empty reader.
    pub const fn new() -> Self {
        FrameReader {
            buf: [0; N],
            len: 0,
            overflow: false,
        }
    }

    /// Forget any partial frame.
    pub fn clear(&mut self) {
        self.len = 0;
        self.overflow = false;
    }

    /// Bytes of the current partial frame.
    pub fn pending(&self) -> usize {
        self.len
    }

    /// Feed one byte from the stream.
    pub fn push(&mut self, byte: u8) -> Feed<'_> {
        if byte == 0 {
            let len = core::mem::take(&mut self.len);
            if core::mem::take(&mut self.overflow) {
                return Feed::TooLarge { len };
            }
            return match self.buf.get_mut(..len) {
                Some(f) if !f.is_empty() => Feed::Frame(f),
                _ => Feed::Pending,
            };
        }
        match self.buf.get_mut(self.len) {
            Some(slot) if !self.overflow => *slot = byte,
            _ => self.overflow = true,
        }
        self.len = self.len.saturating_add(1);
        Feed::Pending
    }
}

impl<const N: usize> Default for FrameReader<N> {
    fn default() -> Self {
        Self::new()
    }
}
