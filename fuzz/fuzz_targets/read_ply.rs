//! `shape::io::parse_ply` on any bytes (seeds: ASCII PLY), then the shape built from what it accepts.
#![no_main]

use libfuzzer_sys::fuzz_target;
use shapecorr::shape::io::parse_ply;
use shapecorr_fuzz::{name, read_and_build};

fuzz_target!(|data: &[u8]| read_and_build(parse_ply(data, name())));
