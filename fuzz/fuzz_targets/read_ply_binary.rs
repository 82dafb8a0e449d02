//! `shape::io::parse_ply` on binary PLY: a valid header built from the first 11 bytes
//! ([`PlySpec`]: byte order, property and list types, counts), the rest is the body.
#![no_main]

use libfuzzer_sys::fuzz_target;
use shapecorr::shape::io::parse_ply;
use shapecorr_fuzz::{name, read_and_build, Bytes, PlySpec};

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let mut bytes = PlySpec::decode(&mut b).header().into_bytes();
    bytes.extend_from_slice(b.rest());
    read_and_build(parse_ply(&bytes, name()));
});
