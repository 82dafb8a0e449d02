//! `transfer::parse_values` on any bytes: the first byte is the row count expected, the rest
//! the file. What it accepts is written back as text and must read back the same (exact
//! integers included), and its rows picked in reverse must be the rows reversed.
#![no_main]

use libfuzzer_sys::fuzz_target;
use shapecorr::transfer::parse_values;
use shapecorr_fuzz::name;

fuzz_target!(|data: &[u8]| {
    let Some((&rows, file)) = data.split_first() else {
        return;
    };
    let rows = rows as usize;
    let Ok(values) = parse_values(file, rows, name()) else {
        return;
    };
    assert_eq!(values.rows(), rows);
    let mut text = Vec::new();
    values.write_text(&mut text).unwrap();
    let again = parse_values(&text, rows, name()).expect("written values read back");
    assert_eq!(again, values);
    let reversed: Vec<u32> = (0..rows as u32).rev().collect();
    let picked = values.pick_rows(&reversed).unwrap();
    let c = values.channels();
    for (i, &r) in reversed.iter().enumerate() {
        for k in 0..c {
            let (from, to) = (r as usize * c + k, i * c + k);
            assert_eq!(picked.exact(to), values.exact(from));
            assert_eq!(picked.as_f64()[to].to_bits(), values.as_f64()[from].to_bits());
        }
    }
});
