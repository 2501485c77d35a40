#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| ohaca_fuzz::maps::fuzz_map_parsers(data));
