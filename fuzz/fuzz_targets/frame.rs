#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ohaca_fuzz::frame::fuzz_frame(data));
