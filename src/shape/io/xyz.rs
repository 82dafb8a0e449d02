//! Point lists (`.xyz`, `.pts`) reading.

use std::path::Path;

use super::{capped, data_lines, is_integer, parse_xyz_tokens, shown, text_of, RawShape};
use crate::error::{Error, Result};
use crate::progress::Cancel;

/// Parses a point list (`.xyz`, `.pts`): one point per line, numbers separated by white space
/// or commas; the first 3 are x y z and extra columns (normals, colours, ...) are ignored.
/// `#` starts a comment; blank lines are skipped. An optional first data line holding a single
/// integer is the point count (the common `.pts` convention) and must then match the number of
/// points. A file without points is an error.
pub fn parse_xyz(bytes: &[u8], name: &Path) -> Result<RawShape> {
    xyz(bytes, &Cancel::default()).map_err(|reason| Error::file(name, reason))
}

/// The numbers of a point-list line: separated by white space or commas.
fn split_xyz(line: &str) -> Vec<&str> {
    line.split(|c: char| c.is_ascii_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .collect()
}

pub(super) fn xyz(bytes: &[u8], cancel: &Cancel) -> Result<RawShape, String> {
    let text = text_of(bytes);
    let mut lines = data_lines(&text, cancel).peekable();
    let mut declared = None;
    if let Some((line, content)) = lines.peek() {
        if let [single] = split_xyz(content)[..] {
            if !is_integer(single) {
                return Err(format!(
                    "line {line}: expected 3 coordinates or a point count, found '{}'",
                    shown(single)
                ));
            }
            let n = single
                .parse::<u64>()
                .map_err(|_| format!("line {line}: invalid point count '{}'", shown(single)))?;
            declared = Some(n);
            lines.next();
        }
    }
    let reserve = declared.map_or(0, |n| {
        capped(usize::try_from(n).unwrap_or(usize::MAX), bytes.len(), 6)
    });
    let mut vertices = Vec::with_capacity(reserve);
    for (line, content) in lines {
        vertices.push(parse_xyz_tokens(split_xyz(content).into_iter(), line)?);
    }
    if let Some(n) = declared {
        if u64::try_from(vertices.len()).ok() != Some(n) {
            return Err(
                if u64::try_from(vertices.len()).is_ok_and(|found| found < n) {
                    format!(
                        "truncated file: the count line declares {n} points, file ends after {}",
                        vertices.len()
                    )
                } else {
                    format!(
                        "the count line declares {n} points but the file holds {}",
                        vertices.len()
                    )
                },
            );
        }
    }
    if vertices.is_empty() {
        return Err(if bytes.is_empty() {
            "empty file (no points)"
        } else {
            "no points found"
        }
        .to_string());
    }
    Ok(RawShape {
        vertices,
        polygons: Vec::new(),
    })
}
