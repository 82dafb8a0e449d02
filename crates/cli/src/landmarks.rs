//! `--landmarks FILE`: landmark pairs (a vertex of A, then the vertex of B it corresponds
//! to) read from a text file, one pair a line (docs/placement.md, "Landmarks"). The two
//! 0-based vertex indices are separated by spaces, tabs or one comma; `#` starts a comment;
//! blank lines are skipped. A malformed line is an error naming the file, the line and the
//! column; the pairs themselves are checked by the library when the job starts (a vertex
//! out of range or left out by the repairs, one vertex with two partners).

use std::io::Read;
use std::path::Path;

use shapecorr::maps::landmarks::{Landmark, MAX_LANDMARKS};
use shapecorr::Error;

/// Largest landmarks file read: far more than [`MAX_LANDMARKS`] commented lines, and a
/// shape file given by mistake is refused before it is read.
const MAX_BYTES: u64 = 1 << 20;

/// The landmark pairs of the file at `path`, in the file's order.
pub fn read_landmarks(path: &Path) -> Result<Vec<Landmark>, Error> {
    let cannot = |e: std::io::Error| Error::file(path, format!("cannot read the file: {e}"));
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        return Err(Error::file(
            path,
            "is not a regular file; `--landmarks` names a text file of vertex pairs",
        ));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(cannot)?
        .take(MAX_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > MAX_BYTES {
        return Err(Error::file(
            path,
            format!(
                "more than {MAX_BYTES} bytes: not a landmarks file (at most {MAX_LANDMARKS} \
                 pairs, two vertex indices a line)"
            ),
        ));
    }
    parse_landmarks(&bytes).map_err(|reason| Error::file(path, reason))
}

/// The pairs of a landmarks file's bytes, or why they are not: `line L, column C: ...`
/// (columns count the line's characters from 1).
pub fn parse_landmarks(bytes: &[u8]) -> Result<Vec<Landmark>, String> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut pairs = Vec::new();
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let line = match line.iter().position(|&b| b == b'#') {
            Some(k) => &line[..k],
            None => line,
        };
        let at =
            |column: usize, reason: String| format!("line {}, column {column}: {reason}", i + 1);
        if let Some(k) = line
            .iter()
            .position(|&b| !(b == b'\t' || (b' '..=b'~').contains(&b)))
        {
            return Err(at(
                k + 1,
                "a character that is not a digit, a space, a tab or a comma".into(),
            ));
        }
        // Only printable ASCII and tabs are left: byte offsets are columns.
        let line = std::str::from_utf8(line).unwrap_or_default();
        if let Some(pair) = parse_line(line).map_err(|(column, reason)| at(column, reason))? {
            pairs.push(pair);
        }
    }
    Ok(pairs)
}

/// A field of a line: its text and its 1-based column.
type Field<'a> = (&'a str, usize);

/// The pair on one line (comment removed), None for a blank line, or the column and reason
/// of what is wrong.
fn parse_line(line: &str) -> Result<Option<Landmark>, (usize, String)> {
    let blank = |c: char| c == ' ' || c == '\t';
    let fields: Vec<Field<'_>> = line
        .split(|c: char| blank(c) || c == ',')
        .scan(0, |start, piece| {
            let column = *start + 1;
            *start += piece.len() + 1;
            Some((piece, column))
        })
        .filter(|(piece, _)| !piece.is_empty())
        .collect();
    let commas: Vec<usize> = line.match_indices(',').map(|(k, _)| k + 1).collect();
    if fields.is_empty() {
        return match commas.first() {
            None => Ok(None),
            Some(&column) => Err((column, "a comma with no vertex index".into())),
        };
    }
    if let Some(&column) = commas.get(1) {
        return Err((
            column,
            "a second comma: a line is two vertex indices separated by spaces, tabs or one \
             comma"
                .into(),
        ));
    }
    if let Some(&(text, column)) = fields.get(2) {
        return Err((
            column,
            format!(
                "a third value `{text}`: a line is two vertex indices, A's then B's (a \
                 comment starts with `#`)"
            ),
        ));
    }
    let [a, b] = fields[..] else {
        let end = line.trim_end_matches(|c: char| blank(c) || c == ',').len() + 1;
        return Err((
            end,
            "B's vertex is missing: a line is two vertex indices, A's then B's".into(),
        ));
    };
    if let Some(&comma) = commas.first() {
        if !(a.1 < comma && comma < b.1) {
            return Err((
                comma,
                "a comma that is not between the two vertex indices".into(),
            ));
        }
    }
    Ok(Some([vertex(a, "A")?, vertex(b, "B")?]))
}

/// A vertex index of shape `side`.
fn vertex((text, column): Field<'_>, side: &str) -> Result<u32, (usize, String)> {
    if let Some(k) = text.find(|c: char| !c.is_ascii_digit()) {
        let reason = if text.starts_with('-') && text[1..].bytes().all(|b| b.is_ascii_digit()) {
            format!("{side}'s vertex `{text}` is negative: vertex indices start at 0")
        } else {
            format!(
                "{side}'s vertex `{text}` is not a vertex index (a whole number from 0, \
                 written with digits only)"
            )
        };
        return Err((column + if text.starts_with('-') { 0 } else { k }, reason));
    }
    text.parse::<u32>().map_err(|_| {
        (
            column,
            format!(
                "{side}'s vertex `{text}` is larger than any vertex index ({})",
                u32::MAX
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(text: &str) -> String {
        parse_landmarks(text.as_bytes()).unwrap_err()
    }

    #[test]
    fn spaces_tabs_one_comma_comments_and_blank_lines() {
        let text = "\u{feff}# A B\n12 40\n\n  7\t9  # left hand\r\n3,4\n5 , 6\n\t\n100000 0\n";
        assert_eq!(
            parse_landmarks(text.as_bytes()).unwrap(),
            vec![[12, 40], [7, 9], [3, 4], [5, 6], [100_000, 0]]
        );
        assert_eq!(parse_landmarks(b"").unwrap(), Vec::<Landmark>::new());
        assert_eq!(
            parse_landmarks(b"# nothing\n\n").unwrap(),
            Vec::<Landmark>::new()
        );
    }

    #[test]
    fn a_malformed_line_names_its_line_and_column() {
        for (text, expected) in [
            ("1 2\n3\n", "line 2, column 2: B's vertex is missing"),
            ("1 2 3\n", "line 1, column 5: a third value `3`"),
            ("1,2,3\n", "line 1, column 4: a second comma"),
            ("1,,2\n", "line 1, column 3: a second comma"),
            (",1 2\n", "line 1, column 1: a comma that is not between"),
            ("1 2,\n", "line 1, column 4: a comma that is not between"),
            ("1,\n", "line 1, column 2: B's vertex is missing"),
            (" ,\n", "line 1, column 2: a comma with no vertex index"),
            (
                "\n\n  4 x9\n",
                "line 3, column 5: B's vertex `x9` is not a vertex index",
            ),
            ("4 9x\n", "line 1, column 4: B's vertex `9x`"),
            (
                "1.5 2\n",
                "line 1, column 2: A's vertex `1.5` is not a vertex index",
            ),
            ("-1 2\n", "line 1, column 1: A's vertex `-1` is negative"),
            (
                "1 4294967296\n",
                "line 1, column 3: B's vertex `4294967296` is larger",
            ),
            ("1 2\n3 4é\n", "line 2, column 4: a character that is not"),
        ] {
            let e = error(text);
            assert!(e.contains(expected), "{text:?}: {e}");
        }
        // The largest index parses (the library checks it against the shape).
        assert_eq!(
            parse_landmarks(b"4294967295 0").unwrap(),
            vec![[u32::MAX, 0]]
        );
    }

    #[test]
    fn a_file_that_is_not_a_landmarks_file_is_refused() {
        let dir = std::env::temp_dir().join(format!("shapecorr-landmarks-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let e = read_landmarks(&dir).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let big = dir.join("big.txt");
        std::fs::write(&big, "1 2\n".repeat(300_000)).unwrap();
        let e = read_landmarks(&big).unwrap_err().to_string();
        assert!(e.contains("not a landmarks file"), "{e}");
        let e = read_landmarks(&dir.join("missing.txt"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.txt: cannot read the file"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
