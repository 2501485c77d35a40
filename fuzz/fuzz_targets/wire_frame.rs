#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ohaca_fuzz::wire_frame::fuzz_wire_frame(data));
