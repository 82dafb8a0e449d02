//! `shape::io::parse_off` on any bytes, then the shape built from what it accepts.
#![no_main]

use libfuzzer_sys::fuzz_target;
use shapecorr::shape::io::parse_off;
use shapecorr_fuzz::{name, read_and_build};

fuzz_target!(|data: &[u8]| read_and_build(parse_off(data, name())));
