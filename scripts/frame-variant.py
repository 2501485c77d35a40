#!/usr/bin/env python3
# Rewrite the working tree into one of the framing variants measured in BENCHMARKS.md section 9
# (issue 29, item 6): python3 scripts/frame-variant.py notable|table1|table16|postcard, then
# build and measure (scripts/firmware-size.sh, scripts/build-stm32.sh, scripts/panic-sites.sh);
# `git checkout Cargo.toml Cargo.lock src/protocol` undoes it. Measurement only: never commit the result.
import sys,re
kind=sys.argv[1]  # notable|table1|table16|postcard
impl={'notable':'crc::NoTable','table1':'crc::Table<1>','table16':'crc::Table<16>','postcard':'crc::Table<1>'}[kind]
p='src/protocol/frame.rs'
s=open(p).read()
i=s.index('pub fn crc32(data'); i=s.rindex('\n\n',0,i)+2
j=s.index('/// Most bytes COBS adds')
s=s[:i]+f'''pub(crate) static CRC: crc::Crc<u32, {impl}> = crc::Crc::<u32, {impl}>::new(&crc::CRC_32_ISO_HDLC);
/// CRC-32/ISO-HDLC through the `crc` crate (measurement variant).
pub fn crc32(data: &[u8]) -> u32 {{
    CRC.checksum(data)
}}
/// The CRC register before the first byte.
pub(crate) const CRC32_INIT: u32 = !0;
/// One byte into the register, through the crate's digest.
pub(crate) fn crc32_step(crc: u32, b: u8) -> u32 {{
    let mut d = CRC.digest_with_initial(crc.reverse_bits());
    d.update(&[b]);
    !d.finalize()
}}

'''+s[j:]
if kind=='postcard':
    i=s.index('pub(crate) fn cobs_decode_in_place'); j=s.index('/// What [`FrameReader::push`] saw.')
    s=s[:i]+'''pub(crate) fn cobs_decode_in_place(buf: &mut [u8]) -> Option<usize> {
    if buf.is_empty() { return Some(0); }
    cobs::decode_in_place(buf).ok()
}

'''+s[j:]
open(p,'w').write(s)
if kind=='postcard':
    p='src/protocol/mod.rs'
    s=open(p).read()
    i=s.index('    // Serialize at an offset that leaves room for COBS'); j=s.index('/// Undo COBS in place')
    s=s[:i]+'''    let cobs = postcard::ser_flavors::Cobs::try_new(postcard::ser_flavors::Slice::new(out))
        .map_err(|_| too_small)?;
    let f = postcard::ser_flavors::crc::CrcModifier::new(cobs, frame::CRC.digest());
    let n = postcard::serialize_with_flavor(&value, f).map_err(|_| too_small)?.len();
    Ok(n)
}

'''+s[j:]
    s=s.replace('pub use frame::{cobs_overhead, crc32, wire_len, Feed, FrameReader};','pub use frame::{cobs_overhead, crc32, wire_len, Feed, FrameReader};\n#[allow(unused_imports)]\nuse frame::cobs_encode_in_place as _;')
    open(p,'w').write(s)
p='Cargo.toml'
s=open(p).read()
dep='crc = { version = "3.4", default-features = false }\n'
if kind=='postcard':
    s=s.replace('postcard = { version = "1.1.3", default-features = false, optional = true }','postcard = { version = "1.1.3", default-features = false, optional = true, features = ["use-crc"] }\ncobs = { version = "0.3", default-features = false }')
s=s.replace('libm = "0.2.16"\n','libm = "0.2.16"\n'+dep)
open(p,'w').write(s)
