//! The values-file reader: what it accepts, exactly, and what it refuses with the line and
//! column named.

use std::path::Path;

use super::*;
use crate::shape::surface_point::SurfacePoint;

fn parse(text: &str, rows: usize) -> Result<Values> {
    parse_values(text.as_bytes(), rows, Path::new("v.txt"))
}

fn refused(text: &str, rows: usize) -> String {
    match parse(text, rows) {
        Ok(v) => panic!("{text:?} was read as {v:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn blanks_commas_comments_crlf_and_a_bom_are_read() {
    let text = "\u{feff}# header\r\n1 2\t3\r\n\n  4,5 , 6 # trailing comment é\n\t7,\t8  9\n";
    let v = parse(text, 3).unwrap();
    assert_eq!(v.channels(), 3);
    assert_eq!(v.rows(), 3);
    assert_eq!(v.as_f64(), &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
}

#[test]
fn an_empty_field_is_an_error_naming_line_and_column() {
    let e = refused("1,2,3\n0.5,,0.25\n", 2);
    assert!(
        e.contains("line 2: column 2 is empty (between two commas)"),
        "{e}"
    );
    let e = refused("0.5,0.25,\n", 1);
    assert!(
        e.contains("line 1: column 3 is empty (after the last comma)"),
        "{e}"
    );
    let e = refused(" ,1\n", 1);
    assert!(
        e.contains("line 1: column 1 is empty (before the first comma)"),
        "{e}"
    );
}

#[test]
fn a_non_ascii_separator_is_an_error_naming_the_character() {
    let e = refused("1\u{a0}2 3\n", 1);
    assert!(
        e.contains("line 1: byte 2 is U+00A0 (a non-breaking space)"),
        "{e}"
    );
    let e = refused("1 2\n3\u{2003}4\n", 2);
    assert!(e.contains("line 2: byte 2 is U+2003"), "{e}");
    let e = parse_values(b"1 \xff 2\n", 1, Path::new("v.txt"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("byte 3 is byte 0xFF (not UTF-8 text)"), "{e}");
    let e = refused("1\x0c2\n", 1);
    assert!(e.contains("control character U+000C"), "{e}");
}

#[test]
fn ragged_rows_and_wrong_row_counts_are_errors() {
    let e = refused("1 2\n3\n", 2);
    assert!(e.contains("line 2: 1 values, the first row has 2"), "{e}");
    let e = refused("1\n2\n", 3);
    assert!(
        e.contains("2 rows of values, but shape A has 3 vertices"),
        "{e}"
    );
    let e = refused("1\n2\n3\n", 2);
    assert!(e.contains("line 3: more than 2 rows"), "{e}");
}

#[test]
fn non_finite_and_non_numbers_are_refused() {
    for (token, why) in [
        ("nan", "not a finite number"),
        ("-inf", "not a finite number"),
        ("1e400", "not a finite number"),
        ("0x10", "not a number"),
        ("1.2.3", "not a number"),
    ] {
        let e = refused(&format!("1 {token}\n"), 1);
        assert!(
            e.contains(&format!("line 1: column 2: `{token}` is {why}")),
            "{e}"
        );
    }
}

#[test]
fn integers_are_exact_to_64_bits_and_refused_beyond() {
    let v = parse(
        "9007199254740993\n9007199254740992\n18446744073709551615\n-9223372036854775808\n",
        4,
    )
    .unwrap();
    assert_eq!(v.exact(0), Some(9007199254740993));
    assert_eq!(v.as_f64()[0], 9007199254740992.0);
    // 2^53 is an f64 exactly.
    assert_eq!(v.exact(1), None);
    assert_eq!(v.exact(2), Some(u64::MAX as i128));
    assert_eq!(v.exact(3), Some(i64::MIN as i128));
    for token in [
        "18446744073709551616",
        "-9223372036854775809",
        "123456789012345678901234567890123456789012345678901",
    ] {
        let e = refused(&format!("{token}\n"), 1);
        assert!(e.contains("does not fit 64 bits"), "{e}");
    }
}

#[test]
fn text_written_reads_back_the_same_values() {
    let text = "9007199254740993 0.1 -3\n1e-300 2.5 18446744073709551615\n1e20 4e16 -1e300\n";
    let v = parse(text, 3).unwrap();
    let mut out = Vec::new();
    v.write_text(&mut out).unwrap();
    let written = String::from_utf8(out).unwrap();
    assert!(
        written.starts_with("9007199254740993 0.1 -3\n"),
        "{written}"
    );
    // A float beyond 2^53 is written with an exponent, never as an integer.
    assert!(written.ends_with("\n1e20 4e16 -1e300\n"), "{written}");
    assert_eq!(parse(&written, 3).unwrap(), v);
}

fn onto_a(n_vertices_a: usize, points: &[([u32; 3], [f64; 3])]) -> SurfaceMap {
    SurfaceMap {
        points: points
            .iter()
            .map(|&(vertices, weights)| SurfacePoint { vertices, weights })
            .collect(),
        n_vertices_a,
        fingerprint_a: 0,
    }
}

#[test]
fn nearest_carries_wide_integers_exactly_and_averaging_refuses_them() {
    let v = parse("9007199254740993 1\n2 18446744073709551615\n5 6\n", 3).unwrap();
    let onto = onto_a(
        3,
        &[([1, 0, 2], [0.6, 0.3, 0.1]), ([0, 2, 1], [0.5, 0.5, 0.0])],
    );
    let b = v.transfer(&onto, TransferMode::Nearest).unwrap();
    assert_eq!(b.rows(), 2);
    assert_eq!(b.exact(1), Some(u64::MAX as i128));
    assert_eq!(b.exact(2), Some(9007199254740993));
    let mut out = Vec::new();
    b.write_text(&mut out).unwrap();
    assert_eq!(
        String::from_utf8(out).unwrap(),
        "2 18446744073709551615\n9007199254740993 1\n"
    );
    let e = v
        .transfer(&onto, TransferMode::Interpolate)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("vertex 0 channel 0 is the integer 9007199254740993"),
        "{e}"
    );
    // Without wide integers, averaging works as the surface map's own transfer.
    let small = parse("1 2\n3 4\n5 6\n", 3).unwrap();
    let b = small.transfer(&onto, TransferMode::Interpolate).unwrap();
    let direct = onto
        .transfer(small.as_f64(), 2, TransferMode::Interpolate)
        .unwrap();
    assert_eq!(b.as_f64(), &direct[..]);
    // An integer beyond 2^53 that an f64 holds exactly (2^60) can be averaged.
    let even = parse("1152921504606846976\n0\n0\n", 3).unwrap();
    assert_eq!(even.exact(0), Some(1 << 60));
    let b = even.transfer(&onto, TransferMode::Interpolate).unwrap();
    assert_eq!(b.as_f64()[1], 0.5 * (1u64 << 60) as f64);
}

#[test]
fn a_special_file_is_refused_before_reading() {
    let e = read_values(Path::new("/dev/zero"), 3)
        .unwrap_err()
        .to_string();
    assert!(e.contains("special file"), "{e}");
}
