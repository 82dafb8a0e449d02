//! Wavefront OBJ reading.

use std::path::Path;

use super::{data_lines, is_integer, parse_xyz_tokens, shown, text_of, RawShape};
use crate::error::{Error, Result};
use crate::progress::Cancel;

/// OBJ statements that carry nothing a shape needs; they are skipped. Any other statement is
/// an error (it usually means the file is not an OBJ file).
const OBJ_IGNORED: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "l",
    "p",
    "o",
    "g",
    "s",
    "mg",
    "usemtl",
    "mtllib",
    "maplib",
    "usemap",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "call",
    "csh",
];

/// Parses Wavefront OBJ: `v x y z [w | r g b]` vertices in file order, and `f` (or `fo`) faces
/// whose corners are `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based or negative (relative to the
/// vertices read so far). Faces keep their corner count. Objects and groups are merged into
/// one shape indexing the file's global vertex list. A file with `v` lines only is a point
/// cloud. Texture coordinates, normals, lines, points, groups and materials are ignored; an
/// unknown statement is an error. Line continuations (`\`) are not supported.
pub fn parse_obj(bytes: &[u8], name: &Path) -> Result<RawShape> {
    obj(bytes, &Cancel::default()).map_err(|reason| Error::file(name, reason))
}

pub(super) fn obj(bytes: &[u8], cancel: &Cancel) -> Result<RawShape, String> {
    let text = text_of(bytes);
    let mut shape = RawShape::default();
    for (line, content) in data_lines(&text, cancel) {
        let mut tokens = content.split_ascii_whitespace();
        let keyword = tokens.next().unwrap_or_default();
        match keyword {
            "v" => shape.vertices.push(parse_xyz_tokens(tokens, line)?),
            "f" | "fo" => {
                let n = shape.vertices.len();
                let face = tokens
                    .map(|t| obj_corner(t, n, line))
                    .collect::<Result<Vec<u32>, String>>()?;
                shape.polygons.push(face);
            }
            k if OBJ_IGNORED.contains(&k) => {}
            other => {
                return Err(format!(
                    "line {line}: unknown OBJ statement '{}'",
                    shown(other)
                ))
            }
        }
    }
    if shape.vertices.is_empty() {
        return Err(if bytes.is_empty() {
            "empty file (no vertices)".to_string()
        } else {
            "no vertices ('v' lines) found".to_string()
        });
    }
    Ok(shape)
}

/// One face corner `v[/vt][/vn]` to a 0-based vertex index; `n_so_far` resolves negative ones.
fn obj_corner(token: &str, n_so_far: usize, line: usize) -> Result<u32, String> {
    let v = token.split('/').next().unwrap_or_default();
    let index = match v.parse::<i64>() {
        Ok(0) => {
            return Err(format!(
                "line {line}: vertex index 0 is invalid (OBJ indices start at 1)"
            ))
        }
        Ok(k) if k > 0 => k - 1,
        Ok(k) => {
            let n = i64::try_from(n_so_far).unwrap_or(i64::MAX);
            let i = n.saturating_add(k);
            if i < 0 {
                return Err(format!(
                    "line {line}: relative vertex index {k} points before the first vertex ({n_so_far} read so far)"
                ));
            }
            i
        }
        Err(_) if is_integer(v) => {
            return Err(format!(
                "line {line}: vertex index {} does not fit in 32 bits",
                shown(v)
            ));
        }
        Err(_) => {
            return Err(format!(
                "line {line}: invalid face corner '{}'",
                shown(token)
            ))
        }
    };
    u32::try_from(index)
        .map_err(|_| format!("line {line}: vertex index {v} does not fit in 32 bits"))
}
