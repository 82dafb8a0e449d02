//! `collection::parse_pairs` (the batch's pair-file reader) on any bytes: a list of pairs
//! whose names are non-empty and hold no tab, or an error naming a line; never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use shapecorr::collection::parse_pairs;

fuzz_target!(|data: &[u8]| {
    if let Ok(pairs) = parse_pairs(data) {
        assert!(!pairs.is_empty());
        for pair in &pairs {
            for name in [&pair.a, &pair.b] {
                assert!(!name.is_empty() && !name.contains('\t') && !name.contains('\n'));
                assert_eq!(name.trim(), name.as_str());
            }
            assert!(pair.line >= 1);
        }
    }
});
