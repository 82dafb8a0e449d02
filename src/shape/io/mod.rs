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
//!
//! Layout: this module holds [`RawShape`], [`Format`] (the choice of reader by extension),
//! the `read_*` entry points and the text helpers the readers share; each format has its own
//! file (`off.rs`, `obj.rs`, `ply.rs` with the PLY writers, `xyz.rs` for `.xyz` / `.pts`).

use std::borrow::Cow;
use std::path::Path;

use crate::error::{Error, Result};

mod obj;
mod off;
mod ply;
mod xyz;

pub use obj::parse_obj;
pub use off::parse_off;
pub use ply::{encode_ply, parse_ply, write_ply, write_ply_ascii, PlyEncoding};
pub use xyz::parse_xyz;

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

/// Largest shape file read: 4 GiB, about 20 million vertices of ASCII PLY with faces (some
/// 200 bytes a vertex), ten times the default `max_vertices`. A larger file is refused
/// before anything is read.
pub const MAX_FILE_BYTES: u64 = 4 << 30;

/// The bytes of a regular file of at most [`MAX_FILE_BYTES`]. FIFOs, devices (`/dev/zero`,
/// also through a symbolic link), sockets and directories are refused before the file is
/// opened, so reading never blocks or runs unbounded.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read;
    let cannot = |e: std::io::Error| Error::file(path, format!("cannot read the file: {e}"));
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a directory"
        } else {
            "a special file (a FIFO, a device or a socket)"
        };
        return Err(Error::file(
            path,
            format!("is {what}, not a regular file; shapecorr reads regular files only"),
        ));
    }
    let too_large = |size: u64| {
        Error::file(
            path,
            format!(
                "the file has {size} bytes, more than the {MAX_FILE_BYTES} bytes (4 GiB) \
                 shapecorr reads; simplify the shape"
            ),
        )
    };
    if meta.len() > MAX_FILE_BYTES {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .map_err(cannot)?
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
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
        let line = line
            .split('#')
            .next()
            .unwrap_or_default()
            .trim_matches(|c: char| c.is_ascii_whitespace());
        (!line.is_empty()).then_some((i + 1, line))
    })
}

/// A token for an error message, cut to a readable length.
/// Characters other than printable ASCII are written as `\u{85}`, so an invisible one
/// (a Unicode space inside a number) shows.
fn shown(token: &str) -> String {
    const MAX: usize = 40;
    let visible = |c: char| {
        if c.is_ascii_graphic() || c == ' ' {
            c.to_string()
        } else {
            c.escape_unicode().to_string()
        }
    };
    let cut: String = token.chars().take(MAX).map(visible).collect();
    if token.chars().count() <= MAX {
        cut
    } else {
        format!("{cut}...")
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

#[cfg(test)]
mod tests;
