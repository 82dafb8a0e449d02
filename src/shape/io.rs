//! Reading and writing shape files.
//!
//! Readers: OFF ([`read_off`]), OBJ ([`read_obj`]), PLY ([`read_ply`]) and point lists
//! ([`read_xyz`], also `.pts`); [`read_shape`] dispatches on the extension. Each has an
//! in-memory twin (`parse_*`) taking the bytes and a name used only in error messages.
//! Writers: [`write_ply`] (binary little-endian) and [`write_ply_ascii`].
//!
//! Readers return a [`RawShape`]: vertices and polygons exactly as the file holds them, in the
//! file's vertex order. They check the *file* (syntax, declared counts, truncation, indices
//! that are negative or do not fit `u32`) and leave the *shape* (indices out of range, faces
//! with fewer than 3 corners, non-finite coordinates) to `shape::Shape`:
//! - a coordinate written as `nan` or `inf` is read as that value, not rejected here;
//! - a face index beyond the vertex count is kept as read;
//! - a well-formed OFF or PLY file declaring zero vertices gives an empty [`RawShape`].
//!
//! Every problem is an [`Error::File`] naming the file and the problem. No input, however
//! malformed, makes a reader panic, and declared counts never drive an allocation beyond what
//! the file size can hold.
//!
//! Crates: PLY headers and binary bodies are read with `ply-rs-bw`; PLY ASCII bodies are read
//! here because that crate's ASCII number grammar rejects `nan`, `inf`, `.5` and `5.`. OBJ is
//! read here and not with `tobj`, because `tobj` renumbers vertices per object in order of
//! first use and drops vertices no face uses (so an OBJ point cloud comes back empty), which
//! would break the vertex order that ground-truth correspondences rely on.

use std::borrow::Cow;
use std::path::Path;

use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use crate::error::{Error, Result};

/// A shape as read from a file, before validation (that is `shape::Shape`'s job).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RawShape {
    /// Vertex positions in the file's order. May contain NaN or infinities if the file does.
    pub vertices: Vec<[f64; 3]>,
    /// Polygons as read (triangles, quads, n-gons), 0-based indices, NOT validated against
    /// `vertices.len()` (out-of-range indices are kept as read so the shape layer can report
    /// them). Empty for a point cloud. An index that is negative or does not fit `u32` in the
    /// file is a file error.
    pub polygons: Vec<Vec<u32>>,
}

/// The shape file formats the readers know.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// ASCII OFF (`.off`), with the COFF/NOFF/CNOFF/STOFF variants.
    Off,
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// PLY (`.ply`), ASCII or binary.
    Ply,
    /// Point list (`.xyz`, `.pts`).
    Xyz,
}

const SUPPORTED: &str = "supported: .off .obj .ply .xyz .pts";

impl Format {
    /// The format named by a path's extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format> {
        let Some(ext) = path.extension() else {
            return Err(Error::file(
                path,
                format!("no file extension ({SUPPORTED})"),
            ));
        };
        let ext = ext.to_string_lossy().to_ascii_lowercase();
        match ext.as_str() {
            "off" => Ok(Format::Off),
            "obj" => Ok(Format::Obj),
            "ply" => Ok(Format::Ply),
            "xyz" | "pts" => Ok(Format::Xyz),
            _ => Err(Error::file(
                path,
                format!("unsupported extension .{ext} ({SUPPORTED})"),
            )),
        }
    }

    /// Parses `bytes` in this format; `name` is only used in error messages.
    pub fn parse(self, bytes: &[u8], name: &Path) -> Result<RawShape> {
        match self {
            Format::Off => parse_off(bytes, name),
            Format::Obj => parse_obj(bytes, name),
            Format::Ply => parse_ply(bytes, name),
            Format::Xyz => parse_xyz(bytes, name),
        }
    }
}

/// Reads a shape file, choosing the reader from the extension (case-insensitive):
/// `.off`, `.obj`, `.ply`, `.xyz`, `.pts`.
pub fn read_shape(path: &Path) -> Result<RawShape> {
    let format = Format::from_path(path)?;
    format.parse(&read_bytes(path)?, path)
}

/// Parses shape bytes, choosing the reader from the extension of `name`.
pub fn parse_shape(bytes: &[u8], name: &Path) -> Result<RawShape> {
    Format::from_path(name)?.parse(bytes, name)
}

/// Reads an ASCII OFF file (see [`parse_off`]).
pub fn read_off(path: &Path) -> Result<RawShape> {
    parse_off(&read_bytes(path)?, path)
}

/// Reads a Wavefront OBJ file (see [`parse_obj`]).
pub fn read_obj(path: &Path) -> Result<RawShape> {
    parse_obj(&read_bytes(path)?, path)
}

/// Reads a PLY file, ASCII or binary (see [`parse_ply`]).
pub fn read_ply(path: &Path) -> Result<RawShape> {
    parse_ply(&read_bytes(path)?, path)
}

/// Reads a point list, `.xyz` or `.pts` (see [`parse_xyz`]).
pub fn read_xyz(path: &Path) -> Result<RawShape> {
    parse_xyz(&read_bytes(path)?, path)
}

fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::file(path, format!("cannot read the file: {e}")))
}

// ---------------------------------------------------------------------------------------------
// Shared text helpers

/// The bytes as text; invalid UTF-8 (say in a comment) becomes U+FFFD and fails only where a
/// number was expected. A UTF-8 byte order mark is dropped.
fn text_of(bytes: &[u8]) -> Cow<'_, str> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    String::from_utf8_lossy(bytes)
}

/// The lines that hold data: `(1-based line number, content)`, with `#` comments removed,
/// surrounding white space trimmed and empty lines skipped.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split('\n').enumerate().filter_map(|(i, line)| {
        let line = line.split('#').next().unwrap_or_default().trim();
        (!line.is_empty()).then_some((i + 1, line))
    })
}

/// A token for an error message, cut to a readable length.
fn shown(token: &str) -> String {
    const MAX: usize = 40;
    if token.chars().count() <= MAX {
        token.to_string()
    } else {
        format!("{}...", token.chars().take(MAX).collect::<String>())
    }
}

/// Parses the first three tokens as coordinates. `nan` and `inf` are accepted (the shape layer
/// rejects them); extra tokens are ignored.
fn parse_xyz_tokens<'a>(
    mut tokens: impl Iterator<Item = &'a str>,
    line: usize,
) -> Result<[f64; 3], String> {
    let mut p = [0.0; 3];
    for (k, c) in p.iter_mut().enumerate() {
        let Some(token) = tokens.next() else {
            return Err(format!("line {line}: expected 3 coordinates, found {k}"));
        };
        *c = token
            .parse::<f64>()
            .map_err(|_| format!("line {line}: invalid coordinate '{}'", shown(token)))?;
    }
    Ok(p)
}

/// Parses a 0-based vertex index that must be non-negative and fit `u32`.
fn parse_index(token: &str, line: usize) -> Result<u32, String> {
    match token.parse::<i64>() {
        Ok(v) if v < 0 => Err(format!("line {line}: negative vertex index {v}")),
        Ok(v) => u32::try_from(v)
            .map_err(|_| format!("line {line}: vertex index {v} does not fit in 32 bits")),
        Err(_) if is_integer(token) => Err(format!(
            "line {line}: vertex index {} does not fit in 32 bits",
            shown(token)
        )),
        Err(_) => Err(format!(
            "line {line}: invalid vertex index '{}'",
            shown(token)
        )),
    }
}

fn is_integer(token: &str) -> bool {
    let digits = token.strip_prefix(['-', '+']).unwrap_or(token);
    !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
}

/// How many items of at least `min_bytes` bytes each `available` bytes can hold: the cap on
/// any reservation driven by a count declared in a file.
fn capped(declared: usize, available: usize, min_bytes: usize) -> usize {
    declared.min(available / min_bytes.max(1))
}

// ---------------------------------------------------------------------------------------------
// OFF

/// Parses ASCII OFF: a keyword line (`OFF`, `COFF`, `NOFF`, `CNOFF`, `STOFF`, ...), the counts
/// `n_vertices n_faces [n_edges]` (on the keyword line or the next data line), one vertex per
/// line (first 3 numbers; extra columns such as normals, colours or texture coordinates are
/// ignored), then one face per line, `n i1 .. in` (0-based), possibly followed by colour values
/// (ignored). `#` starts a comment. The numbers of vertices and faces must match the header,
/// and nothing but comments may follow the faces. Binary OFF is rejected.
pub fn parse_off(bytes: &[u8], name: &Path) -> Result<RawShape> {
    off(bytes).map_err(|reason| Error::file(name, reason))
}

fn off(bytes: &[u8]) -> Result<RawShape, String> {
    let text = text_of(bytes);
    let mut lines = data_lines(&text);
    let Some((first, header)) = lines.next() else {
        return Err(if bytes.is_empty() {
            "empty file (expected an OFF header)".to_string()
        } else {
            "no OFF header: the file holds only comments or blank lines".to_string()
        });
    };
    let mut tokens = header.split_whitespace();
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
        counts = line.split_whitespace().collect();
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
        vertices.push(parse_xyz_tokens(content.split_whitespace(), line)?);
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
    let mut tokens = content.split_whitespace();
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

// ---------------------------------------------------------------------------------------------
// OBJ

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
    obj(bytes).map_err(|reason| Error::file(name, reason))
}

fn obj(bytes: &[u8]) -> Result<RawShape, String> {
    let text = text_of(bytes);
    let mut shape = RawShape::default();
    for (line, content) in data_lines(&text) {
        let mut tokens = content.split_whitespace();
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

// ---------------------------------------------------------------------------------------------
// XYZ / PTS

/// Parses a point list (`.xyz`, `.pts`): one point per line, numbers separated by white space
/// or commas; the first 3 are x y z and extra columns (normals, colours, ...) are ignored.
/// `#` starts a comment; blank lines are skipped. An optional first data line holding a single
/// integer is the point count (the common `.pts` convention) and must then match the number of
/// points. A file without points is an error.
pub fn parse_xyz(bytes: &[u8], name: &Path) -> Result<RawShape> {
    xyz(bytes).map_err(|reason| Error::file(name, reason))
}

/// The numbers of a point-list line: separated by white space or commas.
fn split_xyz(line: &str) -> Vec<&str> {
    line.split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .collect()
}

fn xyz(bytes: &[u8]) -> Result<RawShape, String> {
    let text = text_of(bytes);
    let mut lines = data_lines(&text).peekable();
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

// ---------------------------------------------------------------------------------------------
// PLY reading

/// Parses PLY (`ascii`, `binary_little_endian` or `binary_big_endian`): element `vertex` with
/// scalar properties `x`, `y`, `z` of any type (other properties ignored), and optionally
/// element `face` with an integer list property `vertex_indices` (or `vertex_index`). Without
/// a face element the shape is a point cloud. Other elements are skipped. A body shorter than
/// the header declares is an error, and so is data after the last element (it means the
/// header does not describe the data), except trailing white space.
pub fn parse_ply(bytes: &[u8], name: &Path) -> Result<RawShape> {
    ply(bytes).map_err(|reason| Error::file(name, reason))
}

/// Collapses `ply-rs-bw`'s multi-line messages onto one line.
fn ply_message(e: impl std::fmt::Display) -> String {
    e.to_string()
        .split(['\n', '\t'])
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

/// A header error: the offending line for a syntax error, else the library's first line.
fn ply_header_error(e: &ParseError, bytes: &[u8]) -> String {
    let message = e.to_string();
    match e.line() {
        Some(n) if message.contains("Couldn't parse line") => {
            let line = n
                .checked_sub(1)
                .and_then(|i| bytes.split(|&b| b == b'\n').nth(i))
                .unwrap_or_default();
            format!(
                "invalid header, line {n}: cannot parse '{}'",
                shown(String::from_utf8_lossy(line).trim())
            )
        }
        _ => format!(
            "invalid header: {}",
            message.lines().next().unwrap_or_default().trim()
        ),
    }
}

fn ply(bytes: &[u8]) -> Result<RawShape, String> {
    if bytes.is_empty() {
        return Err("empty file (expected a PLY header)".to_string());
    }
    if !bytes.starts_with(b"ply") {
        return Err("not a PLY file (it does not start with 'ply')".to_string());
    }
    let mut reader = Reader::new(bytes);
    let header = Parser::<Skip>::new()
        .read_header(&mut reader)
        .map_err(|e| ply_header_error(&e, bytes))?;
    let body = reader.into_inner();
    let header_len = bytes.len().saturating_sub(body.len());
    check_ply_header(&header, bytes.get(..header_len).unwrap_or_default())?;

    let first_body_line = bytes
        .get(..header_len)
        .unwrap_or_default()
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1;
    let mut body = Body {
        encoding: header.encoding,
        rest: body,
        line: first_body_line,
    };
    let mut shape = RawShape::default();
    for def in header.elements.values() {
        match def.name.as_str() {
            "vertex" => {
                shape.vertices.reserve(capped(
                    def.count,
                    body.rest.len(),
                    min_element_size(def, &header),
                ));
                body.read_all(def, |_, v: PlyVertex| {
                    shape.vertices.push(v.p);
                    Ok(())
                })?;
            }
            "face" => {
                shape.polygons.reserve(capped(
                    def.count,
                    body.rest.len(),
                    min_element_size(def, &header),
                ));
                body.read_all(def, |i, f: PlyFace| {
                    if let Some(v) = f.negative {
                        return Err(format!("face {i}: negative vertex index {v}"));
                    }
                    shape.polygons.push(f.indices);
                    Ok(())
                })?;
            }
            _ => body.read_all(def, |_, _: Skip| Ok(()))?,
        }
    }
    body.finish()?;
    Ok(shape)
}

fn plural(def: &ElementDef) -> String {
    match def.name.as_str() {
        "vertex" => "vertices".to_string(),
        "face" => "faces".to_string(),
        other => format!("'{other}' elements"),
    }
}

/// Checks what `ply-rs-bw` accepts but this reader cannot use, before reading the body.
fn check_ply_header(header: &Header, header_bytes: &[u8]) -> Result<(), String> {
    // `ply-rs-bw` keys elements and properties by name, so a repeated name silently replaces
    // the first one and the body would be misread: count the declarations ourselves.
    let text = String::from_utf8_lossy(header_bytes);
    let declared = |word: &str| {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(word))
            .count()
    };
    let properties: usize = header.elements.values().map(|e| e.properties.len()).sum();
    if declared("element") != header.elements.len() || declared("property") != properties {
        return Err("invalid header: an element or property name is declared twice".to_string());
    }
    let Some(vertex) = header.elements.get("vertex") else {
        return Err("the header declares no 'vertex' element".to_string());
    };
    for c in ["x", "y", "z"] {
        match vertex.properties.get(c).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            Some(PropertyType::List(..)) => {
                return Err(format!(
                    "vertex property '{c}' is a list, expected a number"
                ))
            }
            None => return Err(format!("the vertex element has no property '{c}'")),
        }
    }
    if let Some(face) = header.elements.get("face") {
        match face_index_property(face) {
            Some(PropertyType::List(_, t)) if is_integer_type(t) => {}
            Some(PropertyType::List(_, t)) => {
                return Err(format!(
                    "face vertex indices have type {t:?}; an integer type is needed"
                ));
            }
            Some(PropertyType::Scalar(_)) => {
                return Err("face property 'vertex_indices' is not a list".to_string())
            }
            None if face.count == 0 => {}
            None => {
                return Err(
                    "the face element has no list property 'vertex_indices' (or 'vertex_index')"
                        .to_string(),
                )
            }
        }
    }
    for def in header.elements.values() {
        if def.count > 0 && def.properties.is_empty() {
            return Err(format!("element '{}' has no properties", def.name));
        }
        for p in def.properties.values() {
            if let PropertyType::List(count_type, _) = &p.data_type {
                if !is_integer_type(count_type) {
                    return Err(format!(
                        "list property '{}' has a non-integer count type {count_type:?}",
                        p.name
                    ));
                }
            }
        }
    }
    Ok(())
}

fn face_index_property(face: &ElementDef) -> Option<&PropertyType> {
    face.properties
        .get("vertex_indices")
        .or_else(|| face.properties.get("vertex_index"))
        .map(|p| &p.data_type)
}

fn is_integer_type(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The fewest body bytes one element can take (lists counted as empty); for ASCII, 2 bytes
/// per property (a digit and a separator).
fn min_element_size(def: &ElementDef, header: &Header) -> usize {
    def.properties
        .values()
        .map(|p| match (&header.encoding, &p.data_type) {
            (Encoding::Ascii, _) => 2,
            (_, PropertyType::Scalar(t)) | (_, PropertyType::List(t, _)) => scalar_size(t),
        })
        .sum()
}

/// The not yet read part of a PLY body.
struct Body<'a> {
    encoding: Encoding,
    rest: &'a [u8],
    /// 1-based line number of `rest`'s first line (ASCII only).
    line: usize,
}

impl Body<'_> {
    /// Reads the `def.count` elements of `def`, handing each with its index to `each`.
    fn read_all<E: PropertyAccess>(
        &mut self,
        def: &ElementDef,
        mut each: impl FnMut(usize, E) -> Result<(), String>,
    ) -> Result<(), String> {
        let parser = Parser::<E>::new();
        for i in 0..def.count {
            let element = match self.encoding {
                Encoding::Ascii => self.ascii_element(def, i)?,
                Encoding::BinaryLittleEndian | Encoding::BinaryBigEndian => {
                    self.binary_element(&parser, def, i)?
                }
            };
            each(i, element)?;
        }
        Ok(())
    }

    fn binary_element<E: PropertyAccess>(
        &mut self,
        parser: &Parser<E>,
        def: &ElementDef,
        i: usize,
    ) -> Result<E, String> {
        let mut rest = self.rest;
        let read = if self.encoding == Encoding::BinaryBigEndian {
            parser.read_big_endian_element(&mut rest, def)
        } else {
            parser.read_little_endian_element(&mut rest, def)
        };
        self.rest = rest;
        read.map_err(|e| {
            if e.kind() == std::io::ErrorKind::UnexpectedEof {
                format!(
                    "truncated binary body: expected {} {}, file ends after {i}",
                    def.count,
                    plural(def)
                )
            } else {
                format!("binary body, {} {i}: {}", def.name, ply_message(e))
            }
        })
    }

    /// The next non-blank line, or `None` at the end of the body.
    fn next_line(&mut self) -> Option<(usize, &[u8])> {
        loop {
            if self.rest.is_empty() {
                return None;
            }
            let end = self
                .rest
                .iter()
                .position(|&b| b == b'\n')
                .unwrap_or(self.rest.len());
            let (line, rest) = self.rest.split_at(end);
            self.rest = rest.get(1..).unwrap_or_default();
            let number = self.line;
            self.line += 1;
            if !line.trim_ascii().is_empty() {
                return Some((number, line));
            }
        }
    }

    fn ascii_element<E: PropertyAccess>(
        &mut self,
        def: &ElementDef,
        i: usize,
    ) -> Result<E, String> {
        let Some((line, bytes)) = self.next_line() else {
            return Err(format!(
                "truncated body: expected {} {}, file ends after {i}",
                def.count,
                plural(def)
            ));
        };
        let text =
            std::str::from_utf8(bytes).map_err(|_| format!("line {line}: not valid text"))?;
        let mut tokens = text.split_whitespace();
        let mut element = E::new();
        for p in def.properties.values() {
            let result = match &p.data_type {
                PropertyType::Scalar(t) => {
                    let token = tokens.next().ok_or_else(|| {
                        format!("line {line}: missing value for property '{}'", p.name)
                    })?;
                    set_scalar(&mut element, &p.name, t, token)
                }
                PropertyType::List(_, t) => {
                    let token = tokens.next().ok_or_else(|| {
                        format!("line {line}: missing list length for property '{}'", p.name)
                    })?;
                    let n = token.parse::<usize>().map_err(|_| {
                        format!("line {line}: invalid list length '{}'", shown(token))
                    })?;
                    set_list(&mut element, &p.name, t, &mut tokens, n)
                }
            }
            .map_err(|e| format!("line {line}: {e}"))?;
            if result == PropertyAccessResult::UnsupportedType {
                return Err(format!(
                    "line {line}: property '{}' has an unsupported type",
                    p.name
                ));
            }
        }
        if let Some(extra) = tokens.next() {
            return Err(format!(
                "line {line}: unexpected value '{}' after the {} properties of a {} element",
                shown(extra),
                def.properties.len(),
                def.name
            ));
        }
        Ok(element)
    }

    /// Checks that nothing but white space follows the last element.
    fn finish(mut self) -> Result<(), String> {
        match self.encoding {
            Encoding::Ascii => match self.next_line() {
                Some((line, _)) => Err(format!("line {line}: unexpected data after the last element the header declares")),
                None => Ok(()),
            },
            _ if self.rest.trim_ascii().is_empty() => Ok(()),
            _ => Err(format!(
                "{} bytes of data after the last element: the header's counts or types do not match the body",
                self.rest.len()
            )),
        }
    }
}

fn parse_token<T: std::str::FromStr>(token: &str, what: &str) -> Result<T, String> {
    token
        .parse::<T>()
        .map_err(|_| format!("invalid {what} value '{}'", shown(token)))
}

fn set_scalar<E: PropertyAccess>(
    e: &mut E,
    name: &str,
    t: &ScalarType,
    token: &str,
) -> Result<PropertyAccessResult, String> {
    Ok(match t {
        ScalarType::Char => e.set_char(name, parse_token(token, "char")?),
        ScalarType::UChar => e.set_uchar(name, parse_token(token, "uchar")?),
        ScalarType::Short => e.set_short(name, parse_token(token, "short")?),
        ScalarType::UShort => e.set_ushort(name, parse_token(token, "ushort")?),
        ScalarType::Int => e.set_int(name, parse_token(token, "int")?),
        ScalarType::UInt => e.set_uint(name, parse_token(token, "uint")?),
        ScalarType::Float => e.set_float(name, parse_token(token, "float")?),
        ScalarType::Double => e.set_double(name, parse_token(token, "double")?),
    })
}

fn parse_list<'a, T: std::str::FromStr>(
    tokens: &mut impl Iterator<Item = &'a str>,
    n: usize,
    what: &str,
) -> Result<Vec<T>, String> {
    let mut list = Vec::new();
    for found in 0..n {
        let token = tokens
            .next()
            .ok_or_else(|| format!("list declares {n} values but the line holds {found}"))?;
        list.push(parse_token(token, what)?);
    }
    Ok(list)
}

fn set_list<'a, E: PropertyAccess>(
    e: &mut E,
    name: &str,
    t: &ScalarType,
    tokens: &mut impl Iterator<Item = &'a str>,
    n: usize,
) -> Result<PropertyAccessResult, String> {
    Ok(match t {
        ScalarType::Char => e.set_list_char(name, parse_list(tokens, n, "char")?),
        ScalarType::UChar => e.set_list_uchar(name, parse_list(tokens, n, "uchar")?),
        ScalarType::Short => e.set_list_short(name, parse_list(tokens, n, "short")?),
        ScalarType::UShort => e.set_list_ushort(name, parse_list(tokens, n, "ushort")?),
        ScalarType::Int => e.set_list_int(name, parse_list(tokens, n, "int")?),
        ScalarType::UInt => e.set_list_uint(name, parse_list(tokens, n, "uint")?),
        ScalarType::Float => e.set_list_float(name, parse_list(tokens, n, "float")?),
        ScalarType::Double => e.set_list_double(name, parse_list(tokens, n, "double")?),
    })
}

/// A PLY element whose content is not needed.
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

/// A PLY vertex: `x`, `y`, `z` of any scalar type; everything else ignored.
struct PlyVertex {
    p: [f64; 3],
}

impl PlyVertex {
    fn set(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        match name {
            "x" => self.p[0] = value,
            "y" => self.p[1] = value,
            "z" => self.p[2] = value,
            _ => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex { p: [0.0; 3] }
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set(name, value.into())
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set(name, value)
    }
}

/// A PLY face: the `vertex_indices` (or `vertex_index`) list of any integer type. A negative
/// index is remembered and reported by the reader (it knows the face number).
struct PlyFace {
    indices: Vec<u32>,
    negative: Option<i64>,
}

impl PlyFace {
    fn is_index_list(name: &str) -> bool {
        name == "vertex_indices" || name == "vertex_index"
    }

    fn set_signed<T: Copy + Into<i64>>(
        &mut self,
        name: &str,
        values: &[T],
    ) -> PropertyAccessResult {
        if !Self::is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        self.indices.clear();
        for &v in values {
            match u32::try_from(v.into()) {
                Ok(i) => self.indices.push(i),
                Err(_) => {
                    self.negative = Some(v.into());
                    break;
                }
            }
        }
        PropertyAccessResult::Set
    }

    fn set_unsigned<T: Copy + Into<u32>>(
        &mut self,
        name: &str,
        values: &[T],
    ) -> PropertyAccessResult {
        if !Self::is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        self.indices = values.iter().map(|&v| v.into()).collect();
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace {
            indices: Vec::new(),
            negative: None,
        }
    }
    fn set_list_char(&mut self, name: &str, value: Vec<i8>) -> PropertyAccessResult {
        self.set_signed(name, &value)
    }
    fn set_list_uchar(&mut self, name: &str, value: Vec<u8>) -> PropertyAccessResult {
        self.set_unsigned(name, &value)
    }
    fn set_list_short(&mut self, name: &str, value: Vec<i16>) -> PropertyAccessResult {
        self.set_signed(name, &value)
    }
    fn set_list_ushort(&mut self, name: &str, value: Vec<u16>) -> PropertyAccessResult {
        self.set_unsigned(name, &value)
    }
    fn set_list_int(&mut self, name: &str, value: Vec<i32>) -> PropertyAccessResult {
        self.set_signed(name, &value)
    }
    fn set_list_uint(&mut self, name: &str, value: Vec<u32>) -> PropertyAccessResult {
        if Self::is_index_list(name) {
            self.indices = value;
            PropertyAccessResult::Set
        } else {
            PropertyAccessResult::Ignored
        }
    }
}

// ---------------------------------------------------------------------------------------------
// PLY writing

/// The encodings [`encode_ply`] can write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    /// `format ascii 1.0`.
    Ascii,
    /// `format binary_little_endian 1.0`.
    BinaryLittleEndian,
}

/// Writes a binary little-endian PLY: `float x y z`, `uchar red green blue` when `colors` is
/// given (one per vertex, else [`Error::InvalidParameter`]), and a `face` element
/// (`list uchar int vertex_indices`) when `triangles` is not empty (else a point cloud).
/// Coordinates are stored as `f32`. A triangle index out of range is
/// [`Error::FaceIndexOutOfRange`].
pub fn write_ply(
    path: &Path,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: Option<&[[u8; 3]]>,
) -> Result<()> {
    let bytes = encode_ply(vertices, triangles, colors, PlyEncoding::BinaryLittleEndian)?;
    write_bytes(path, &bytes)
}

/// [`write_ply`] in ASCII, handy for debugging and tests. Coordinates are written with the
/// shortest text that reads back as the same `f32`.
pub fn write_ply_ascii(
    path: &Path,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: Option<&[[u8; 3]]>,
) -> Result<()> {
    let bytes = encode_ply(vertices, triangles, colors, PlyEncoding::Ascii)?;
    write_bytes(path, &bytes)
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes)
        .map_err(|e| Error::file(path, format!("cannot write the file: {e}")))
}

/// The bytes [`write_ply`] / [`write_ply_ascii`] write.
pub fn encode_ply(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: Option<&[[u8; 3]]>,
    encoding: PlyEncoding,
) -> Result<Vec<u8>> {
    if let Some(c) = colors {
        if c.len() != vertices.len() {
            return Err(Error::InvalidParameter {
                name: "colors",
                reason: format!(
                    "{} colours for {} vertices; give one colour per vertex",
                    c.len(),
                    vertices.len()
                ),
            });
        }
    }
    for (face, t) in triangles.iter().enumerate() {
        if let Some(&index) = t
            .iter()
            .find(|&&i| usize::try_from(i).map_or(true, |i| i >= vertices.len()))
        {
            return Err(Error::FaceIndexOutOfRange {
                face,
                index: index.into(),
                n_vertices: vertices.len(),
            });
        }
    }
    // Indices are below vertices.len(); the `int` type needs them below 2^31.
    if vertices.len() > i32::MAX as usize && !triangles.is_empty() {
        return Err(Error::InvalidParameter {
            name: "vertices",
            reason: format!(
                "{} vertices do not fit PLY `int` face indices",
                vertices.len()
            ),
        });
    }

    let format = match encoding {
        PlyEncoding::Ascii => "ascii",
        PlyEncoding::BinaryLittleEndian => "binary_little_endian",
    };
    let mut header = format!(
        "ply\nformat {format} 1.0\ncomment written by shapecorr\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        vertices.len()
    );
    if colors.is_some() {
        header.push_str("property uchar red\nproperty uchar green\nproperty uchar blue\n");
    }
    if !triangles.is_empty() {
        header.push_str(&format!(
            "element face {}\nproperty list uchar int vertex_indices\n",
            triangles.len()
        ));
    }
    header.push_str("end_header\n");

    let color = |i: usize| colors.and_then(|c| c.get(i));
    let mut out = header.into_bytes();
    match encoding {
        PlyEncoding::BinaryLittleEndian => {
            let per_vertex = 12 + if colors.is_some() { 3 } else { 0 };
            out.reserve(vertices.len() * per_vertex + triangles.len() * 13);
            for (i, v) in vertices.iter().enumerate() {
                for &c in v {
                    out.extend_from_slice(&(c as f32).to_le_bytes());
                }
                if let Some(rgb) = color(i) {
                    out.extend_from_slice(rgb);
                }
            }
            for t in triangles {
                out.push(3);
                for &i in t {
                    out.extend_from_slice(&i.to_le_bytes()); // below 2^31: same bytes as `int`
                }
            }
        }
        PlyEncoding::Ascii => {
            use std::fmt::Write as _;
            let mut s = String::new();
            for (i, v) in vertices.iter().enumerate() {
                let _ = write!(s, "{} {} {}", v[0] as f32, v[1] as f32, v[2] as f32);
                if let Some([r, g, b]) = color(i) {
                    let _ = write!(s, " {r} {g} {b}");
                }
                s.push('\n');
            }
            for [a, b, c] in triangles {
                let _ = writeln!(s, "3 {a} {b} {c}");
            }
            out.extend_from_slice(s.as_bytes());
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name() -> &'static Path {
        Path::new("mem.test")
    }

    fn off_s(s: &str) -> Result<RawShape> {
        parse_off(s.as_bytes(), name())
    }

    fn err(r: Result<RawShape>) -> String {
        match r {
            Ok(s) => panic!("expected an error, got {s:?}"),
            Err(e) => {
                let m = e.to_string();
                assert!(
                    m.contains("mem.test"),
                    "message does not name the file: {m}"
                );
                m
            }
        }
    }

    #[test]
    fn off_counts_on_keyword_line_and_comments() {
        let s = off_s("# a comment\nOFF 4 2 0 # counts here\n0 0 0\n1 0 0 # v1\n\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 2 3 255 0 0\n")
            .unwrap();
        assert_eq!(
            s.vertices,
            vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]]
        );
        assert_eq!(s.polygons, vec![vec![0, 1, 2, 3], vec![0, 2, 3]]);
    }

    #[test]
    fn off_variants_ignore_extra_columns() {
        let noff = off_s("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n").unwrap();
        let coff = off_s(
            "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n",
        )
        .unwrap();
        let cnoff = off_s(
            "CNOFF 3 1 0\n0 0 0 0 0 1 1 1 1\n1 0 0 0 0 1 1 1 1\n0 1 0 0 0 1 1 1 1\n3 0 1 2\n",
        )
        .unwrap();
        let stoff = off_s("STOFF\n3 1\n0 0 0 0.5 0.5\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n").unwrap();
        for s in [&noff, &coff, &cnoff, &stoff] {
            assert_eq!(s.vertices, vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
            assert_eq!(s.polygons, vec![vec![0, 1, 2]]);
        }
    }

    #[test]
    fn off_errors() {
        assert!(err(off_s("OFF\n3 1 0\n0 0 0\n1 0\n"))
            .contains("line 4: expected 3 coordinates, found 2"));
        assert!(err(off_s("OFF\n3 1 0\n0 0 0\n1 0 0\n"))
            .contains("expected 3 vertices, file ends after 2"));
        assert!(err(off_s("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"))
            .contains("expected 2 faces, file ends after 1"));
        assert!(err(off_s("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n"))
            .contains("negative vertex index -2"));
        assert!(
            err(off_s("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 4294967296\n"))
                .contains("does not fit in 32 bits")
        );
        assert!(err(off_s("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n"))
            .contains("face declares 4 corners but lists 3"));
        assert!(
            err(off_s("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n"))
                .contains("unexpected data")
        );
        assert!(err(off_s("OFF BINARY\n3 1 0\n")).contains("binary OFF is not supported"));
        assert!(err(off_s("4OFF\n3 1 0\n")).contains("not supported"));
        assert!(err(off_s("PLY\n3 1 0\n")).contains("expected the OFF keyword"));
        assert!(err(off_s("OFF\n3\n")).contains("expected the counts"));
        assert!(err(off_s("OFF\n")).contains("counts are missing"));
        assert!(err(off_s("")).contains("empty file"));
        assert!(err(off_s("OFF\n4000000000 1 0\n0 0 0\n"))
            .contains("expected 4000000000 vertices, file ends after 1"));
        assert!(err(off_s("OFF\n1 0 0\n0 zero 0\n")).contains("invalid coordinate 'zero'"));
    }

    #[test]
    fn off_keeps_out_of_range_and_nan() {
        let s = off_s("OFF\n3 1 0\nnan 0 0\n1 inf 0\n0 1 -inf\n3 0 1 7\n").unwrap();
        assert!(s.vertices[0][0].is_nan());
        assert_eq!(s.vertices[1][1], f64::INFINITY);
        assert_eq!(s.vertices[2][2], f64::NEG_INFINITY);
        assert_eq!(s.polygons, vec![vec![0, 1, 7]]);
        // zero declared vertices: a well-formed empty shape
        assert_eq!(off_s("OFF\n0 0 0\n").unwrap(), RawShape::default());
    }

    #[test]
    fn obj_forms_and_relative_indices() {
        let src = "# cube corner\nmtllib x.mtl\no first\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\nvt 0 0\nvn 0 0 1\n\
                   g a\nusemtl m\ns off\nf 1/1/1 2/1/1 3/1/1 4/1/1\no second\nv 0 0 1 0.5 0.5 0.5\nf -5//1 -4//1 -1//1\nf 2/1 3/1 5/1\nl 1 2\n";
        let s = parse_obj(src.as_bytes(), name()).unwrap();
        assert_eq!(
            s.vertices,
            vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [1., 1., 0.],
                [0., 1., 0.],
                [0., 0., 1.]
            ]
        );
        assert_eq!(
            s.polygons,
            vec![vec![0, 1, 2, 3], vec![0, 1, 4], vec![1, 2, 4]]
        );
        // only v lines: a point cloud
        let pc = parse_obj(b"v 1 2 3\nv 4 5 6\n", name()).unwrap();
        assert_eq!(pc.vertices, vec![[1., 2., 3.], [4., 5., 6.]]);
        assert!(pc.polygons.is_empty());
    }

    #[test]
    fn obj_errors() {
        let e = |s: &str| err(parse_obj(s.as_bytes(), name()));
        assert!(e("v 0 0 0\nf 0 1 1\n").contains("index 0 is invalid"));
        assert!(e("v 0 0 0\nf -2 1 1\n").contains("points before the first vertex"));
        assert!(e("v 0 0\n").contains("line 1: expected 3 coordinates, found 2"));
        assert!(e("v 0 0 0\nf 1 a 1\n").contains("invalid face corner 'a'"));
        assert!(e("v 0 0 0\nf 1 99999999999 1\n").contains("does not fit in 32 bits"));
        assert!(e("OFF\n3 1 0\n").contains("unknown OBJ statement 'OFF'"));
        assert!(e("# nothing\n").contains("no vertices"));
        assert!(e("").contains("empty file"));
    }

    #[test]
    fn xyz_columns_commas_count_line() {
        let s = parse_xyz(
            b"# x y z nx ny nz\n1 2 3 0 0 1\n4,5,6,0,0,1\n\n7 8 9 1 0 0\n",
            name(),
        )
        .unwrap();
        assert_eq!(s.vertices, vec![[1., 2., 3.], [4., 5., 6.], [7., 8., 9.]]);
        assert!(s.polygons.is_empty());
        let pts = parse_xyz(b"2\n1 2 3 10 20\n4 5 6 10 20\n", name()).unwrap();
        assert_eq!(pts.vertices, vec![[1., 2., 3.], [4., 5., 6.]]);
        let e = |s: &str| err(parse_xyz(s.as_bytes(), name()));
        assert!(e("3\n1 2 3\n4 5 6\n").contains("declares 3 points, file ends after 2"));
        assert!(e("1\n1 2 3\n4 5 6\n").contains("declares 1 points but the file holds 2"));
        assert!(e("1 2 3\n4 5\n").contains("line 2: expected 3 coordinates, found 2"));
        assert!(e("-5\n1 2 3\n").contains("invalid point count"));
        assert!(e("abc\n").contains("expected 3 coordinates or a point count"));
        assert!(e("").contains("empty file"));
        assert!(e("4000000000\n1 2 3\n").contains("declares 4000000000 points"));
        let nan = parse_xyz(b"NaN 0 0\n", name()).unwrap();
        assert!(nan.vertices[0][0].is_nan());
    }

    #[test]
    fn ply_ascii_double_and_extra_properties() {
        let src = "ply\r\nformat ascii 1.0\r\ncomment hi\r\nelement vertex 4\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\n\
                   property uchar red\r\nproperty float confidence\r\nelement face 2\r\nproperty uchar flags\r\nproperty list uchar uint vertex_indices\r\n\
                   element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n\
                   0.5 0 0 255 .5\r\n1 0 0 0 1\r\n1 1 0 0 1\r\n0 1 1e-3 0 nan\r\n7 4 0 1 2 3\r\n0 3 0 2 3\r\n0 1\r\n";
        let s = parse_ply(src.as_bytes(), name()).unwrap();
        assert_eq!(
            s.vertices,
            vec![[0.5, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 1e-3]]
        );
        assert_eq!(s.polygons, vec![vec![0, 1, 2, 3], vec![0, 2, 3]]);
    }

    #[test]
    fn ply_errors() {
        let h = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
        let e = |s: String| err(parse_ply(s.as_bytes(), name()));
        assert!(
            e(format!("{h}0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n")).contains("negative vertex index -1")
        );
        assert!(e(format!("{h}0 0 0\n1 0 0\n")).contains("expected 3 vertices, file ends after 2"));
        assert!(e(format!("{h}0 0 0\n1 0 0\n0 1 0\n3 0 1\n"))
            .contains("list declares 3 values but the line holds 2"));
        assert!(
            e(format!("{h}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n")).contains("unexpected data")
        );
        assert!(e(format!("{h}0 0 0 0\n")).contains("unexpected value"));
        assert!(e(h.replace("property float z\n", "")).contains("no property 'z'"));
        assert!(e(h.replace("property float z\n", "property float x\n")).contains("declared twice"));
        assert!(
            e(h.replace("vertex_indices", "corners")).contains("no list property 'vertex_indices'")
        );
        assert!(e(h.replace("int vertex_indices", "float vertex_indices")).contains("integer type"));
        assert!(
            e(h.replace("vertex 3", "vertex 4000000000")).contains("expected 4000000000 vertices")
        );
        assert!(e("ply\nformat ascii 1.0\nend_header\n".into()).contains("no 'vertex' element"));
        assert!(e("ply\nformat ascii 1.0\nelement vertex 1\n".into()).contains("invalid header"));
        assert!(e("OFF\n".into()).contains("not a PLY file"));
        assert!(e(String::new()).contains("empty file"));
        // 4 billion vertices in a binary header: fails at once, no huge allocation
        let b = h
            .replace("ascii", "binary_little_endian")
            .replace("vertex 3", "vertex 4000000000");
        assert!(e(format!("{b}\u{0}\u{0}"))
            .contains("truncated binary body: expected 4000000000 vertices, file ends after 0"));
        // an element with no properties cannot make the binary reader spin
        let z = "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement nothing 1000000000000\nend_header\n";
        assert!(e(z.into()).contains("has no properties"));
    }

    #[test]
    fn ply_nan_coordinates_are_kept() {
        let src = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\nnan -inf 0\n1 2 3\n";
        let s = parse_ply(src.as_bytes(), name()).unwrap();
        assert!(s.vertices[0][0].is_nan());
        assert_eq!(s.vertices[0][1], f64::NEG_INFINITY);
        assert!(s.polygons.is_empty());
    }

    #[test]
    fn dispatch_on_extension() {
        let off = b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        assert_eq!(
            parse_shape(off, Path::new("a.OfF")).unwrap().polygons,
            vec![vec![0, 1, 2]]
        );
        let m = parse_shape(off, Path::new("dir/a.stl"))
            .unwrap_err()
            .to_string();
        assert!(
            m.contains("a.stl")
                && m.contains("unsupported extension .stl (supported: .off .obj .ply .xyz .pts)"),
            "{m}"
        );
        assert!(parse_shape(off, Path::new("noext"))
            .unwrap_err()
            .to_string()
            .contains("no file extension"));
        assert_eq!(Format::from_path(Path::new("x.PTS")).unwrap(), Format::Xyz);
    }

    #[test]
    fn encode_checks_parameters() {
        let v = [[0.0; 3]; 3];
        let r = encode_ply(&v, &[[0, 1, 2]], Some(&[[0, 0, 0]; 2]), PlyEncoding::Ascii);
        assert!(matches!(
            r,
            Err(Error::InvalidParameter { name: "colors", .. })
        ));
        let r = encode_ply(&v, &[[0, 1, 3]], None, PlyEncoding::BinaryLittleEndian);
        assert!(matches!(
            r,
            Err(Error::FaceIndexOutOfRange {
                face: 0,
                index: 3,
                n_vertices: 3
            })
        ));
    }
}
