//! OFF (ASCII) reading.

use std::path::Path;

use super::{capped, data_lines, parse_index, parse_xyz_tokens, shown, text_of, RawShape};
use crate::error::{Error, Result};
use crate::progress::Cancel;

/// Parses ASCII OFF: a keyword line (`OFF`, `COFF`, `NOFF`, `CNOFF`, `STOFF`, ...), the counts
/// `n_vertices n_faces [n_edges]` (on the keyword line or the next data line), one vertex per
/// line (first 3 numbers; extra columns such as normals, colours or texture coordinates are
/// ignored), then one face per line, `n i1 .. in` (0-based), possibly followed by colour values
/// (ignored). `#` starts a comment. The numbers of vertices and faces must match the header,
/// and nothing but comments may follow the faces. Binary OFF is rejected.
pub fn parse_off(bytes: &[u8], name: &Path) -> Result<RawShape> {
    off(bytes, &Cancel::default()).map_err(|reason| Error::file(name, reason))
}

pub(super) fn off(bytes: &[u8], cancel: &Cancel) -> Result<RawShape, String> {
    let text = text_of(bytes);
    let mut lines = data_lines(&text, cancel);
    let Some((first, header)) = lines.next() else {
        return Err(if bytes.is_empty() {
            "empty file (expected an OFF header)".to_string()
        } else {
            "no OFF header: the file holds only comments or blank lines".to_string()
        });
    };
    let mut tokens = header.split_ascii_whitespace();
    let keyword = tokens.next().unwrap_or_default();
    check_off_keyword(keyword, first)?;
    let mut counts: Vec<&str> = tokens.collect();
    if counts
        .first()
        .is_some_and(|t| t.eq_ignore_ascii_case("BINARY"))
    {
        return Err(format!(
            "line {first}: binary OFF is not supported; convert the file to ASCII OFF or PLY"
        ));
    }
    let mut counts_line = first;
    if counts.is_empty() {
        let Some((n, line)) = lines.next() else {
            return Err("truncated header: the vertex and face counts are missing".to_string());
        };
        counts = line.split_ascii_whitespace().collect();
        counts_line = n;
    }
    let count = |k: usize, what: &str| -> Result<usize, String> {
        let Some(token) = counts.get(k) else {
            return Err(format!(
                "line {counts_line}: expected the counts 'n_vertices n_faces [n_edges]', found {} number(s)",
                counts.len()
            ));
        };
        token.parse::<usize>().map_err(|_| {
            format!(
                "line {counts_line}: invalid {what} count '{}'",
                shown(token)
            )
        })
    };
    let n_vertices = count(0, "vertex")?;
    let n_faces = count(1, "face")?;

    let mut vertices = Vec::with_capacity(capped(n_vertices, bytes.len(), 6));
    for found in 0..n_vertices {
        let Some((line, content)) = lines.next() else {
            return Err(format!(
                "truncated file: expected {n_vertices} vertices, file ends after {found}"
            ));
        };
        vertices.push(parse_xyz_tokens(content.split_ascii_whitespace(), line)?);
    }
    let mut polygons = Vec::with_capacity(capped(n_faces, bytes.len(), 8));
    for found in 0..n_faces {
        let Some((line, content)) = lines.next() else {
            return Err(format!(
                "truncated file: expected {n_faces} faces, file ends after {found} (after the {n_vertices} vertices)"
            ));
        };
        polygons.push(off_face(content, line)?);
    }
    if let Some((line, _)) = lines.next() {
        return Err(format!(
            "line {line}: unexpected data after the {n_vertices} vertices and {n_faces} faces the header declares"
        ));
    }
    Ok(RawShape { vertices, polygons })
}

/// Accepts `[ST][C][N]OFF`; rejects the 4D and n-dimensional variants with a clear message.
fn check_off_keyword(keyword: &str, line: usize) -> Result<(), String> {
    let rest = keyword.strip_prefix("ST").unwrap_or(keyword);
    let rest = rest.strip_prefix('C').unwrap_or(rest);
    let rest = rest.strip_prefix('N').unwrap_or(rest);
    if rest == "OFF" {
        Ok(())
    } else if rest.ends_with("OFF") && (rest.starts_with('4') || rest.starts_with('n')) {
        Err(format!(
            "line {line}: {keyword} (4D or n-dimensional OFF) is not supported; only 3D OFF is"
        ))
    } else {
        Err(format!(
            "line {line}: expected the OFF keyword (OFF, COFF, NOFF, CNOFF, STOFF), found '{}'",
            shown(keyword)
        ))
    }
}

/// `n i1 .. in [colour ...]`.
fn off_face(content: &str, line: usize) -> Result<Vec<u32>, String> {
    let mut tokens = content.split_ascii_whitespace();
    let first = tokens.next().unwrap_or_default();
    let n = first
        .parse::<usize>()
        .map_err(|_| format!("line {line}: invalid face corner count '{}'", shown(first)))?;
    let mut face = Vec::with_capacity(capped(n, content.len(), 2));
    for found in 0..n {
        let Some(token) = tokens.next() else {
            return Err(format!(
                "line {line}: face declares {n} corners but lists {found}"
            ));
        };
        face.push(parse_index(token, line)?);
    }
    Ok(face)
}
