//! Pair files: which pairs a batch matches, one pair a line (docs/collections.md, "Pair
//! files"). One reader for every front end (the command line, and Python through the C
//! API).
//!
//! A line is `A<TAB>B` or `A<TAB>B<TAB>CATEGORY`: with tabs, a name may hold spaces. A line
//! without a tab is split at runs of spaces instead (`A B [CATEGORY]`). Fields are trimmed
//! of surrounding white space; blank lines and lines starting with `#` are skipped; a
//! trailing carriage return and a UTF-8 byte order mark are dropped.

use std::path::Path;

use serde::Serialize;

use crate::{Error, Result};

/// A pair of a pair file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct PairLine {
    /// Shape A's name (the map goes from B to A).
    pub a: String,
    /// Shape B's name.
    pub b: String,
    /// The third field; empty when the line has two.
    pub category: String,
    /// The line's number in the file, from 1.
    pub line: usize,
}

/// Reads the pair file at `path` (a regular file; see [`parse_pairs`]).
pub fn read_pairs(path: &Path) -> Result<Vec<PairLine>> {
    let bytes = crate::shape::io::read_bytes(path)?;
    parse_pairs(&bytes).map_err(|reason| Error::file(path, reason))
}

/// The pairs of a pair file's bytes, or why they are not one: a line with fewer than two
/// or more than three fields, an empty name, text that is not UTF-8, no pair at all.
pub fn parse_pairs(bytes: &[u8]) -> std::result::Result<Vec<PairLine>, String> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = std::str::from_utf8(bytes).map_err(|e| {
        format!(
            "not UTF-8 text (byte {} is not valid UTF-8)",
            e.valid_up_to()
        )
    })?;
    let mut pairs = Vec::new();
    for (i, line) in text.split('\n').enumerate() {
        let line = line.strip_suffix('\r').unwrap_or(line);
        let content = line.trim();
        if content.is_empty() || content.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = if line.contains('\t') {
            line.split('\t').map(str::trim).collect()
        } else {
            content.split_whitespace().collect()
        };
        let number = i + 1;
        if !(2..=3).contains(&fields.len()) || fields[..2].iter().any(|f| f.is_empty()) {
            return Err(format!(
                "line {number}: expected `A<TAB>B` or `A<TAB>B<TAB>CATEGORY` (names may hold \
                 spaces when the fields are separated by tabs), got {content:?}"
            ));
        }
        pairs.push(PairLine {
            a: fields[0].to_string(),
            b: fields[1].to_string(),
            category: fields.get(2).unwrap_or(&"").to_string(),
            line: number,
        });
    }
    if pairs.is_empty() {
        return Err("no pair in the file (a line is `A<TAB>B[<TAB>CATEGORY]`)".into());
    }
    Ok(pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(text: &str) -> Vec<(String, String, String)> {
        parse_pairs(text.as_bytes())
            .unwrap()
            .into_iter()
            .map(|p| (p.a, p.b, p.category))
            .collect()
    }

    #[test]
    fn tabs_allow_spaces_in_names_and_spaces_split_otherwise() {
        let pairs = names("# a\tb\n\nleft arm\tright arm\tlimbs\r\nx y\n  u\t v \n");
        let own = |a: &str, b: &str, c: &str| (a.to_string(), b.to_string(), c.to_string());
        assert_eq!(
            pairs,
            [
                own("left arm", "right arm", "limbs"),
                own("x", "y", ""),
                own("u", "v", ""),
            ]
        );
    }

    #[test]
    fn malformed_lines_are_refused_with_their_number() {
        for (text, line) in [
            ("a\tb\nonly\n", 2),
            ("a\t\tb\n", 1),
            ("a\tb\tc\td\n", 1),
            ("a b c d\n", 1),
            ("\tb\n", 1),
        ] {
            let e = parse_pairs(text.as_bytes()).unwrap_err();
            assert!(e.starts_with(&format!("line {line}:")), "{text:?}: {e}");
        }
        assert!(parse_pairs(b"# nothing\n").unwrap_err().contains("no pair"));
        assert!(parse_pairs(b"a\t\xff\n").unwrap_err().contains("UTF-8"));
    }
}
