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
use crate::progress::Cancel;

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
        self.parse_cancellable(bytes, name, &Cancel::default())
    }

    /// [`Format::parse`], stopping with [`Error::Cancelled`] within [`CHECK_EVERY`] lines or
    /// elements of a cancel, and publishing the fraction of the bytes parsed.
    pub(crate) fn parse_cancellable(
        self,
        bytes: &[u8],
        name: &Path,
        cancel: &Cancel,
    ) -> Result<RawShape> {
        let parsed = match self {
            Format::Off => off::off(bytes, cancel),
            Format::Obj => obj::obj(bytes, cancel),
            Format::Ply => ply::ply(bytes, cancel),
            Format::Xyz => xyz::xyz(bytes, cancel),
        };
        // A cancel ends the parse early, as if the file ended there: say why.
        cancel.check()?;
        parsed.map_err(|reason| Error::file(name, reason))
    }
}

/// Lines or elements a reader parses between two looks at its cancel flag: about 1 ms of
/// parsing (1-2 M lines a second here).
pub(crate) const CHECK_EVERY: usize = 4096;

/// Reads a shape file as [`read_shape`], stopping with [`Error::Cancelled`] soon after
/// `cancel` is set (between [`READ_CHUNK`] bytes while reading, every [`CHECK_EVERY`]
/// lines or elements while parsing); the fraction published runs from 0 to 1 over the
/// parse.
pub(crate) fn read_shape_cancellable(path: &Path, cancel: &Cancel) -> Result<RawShape> {
    let format = Format::from_path(path)?;
    let bytes = read_bytes_cancellable(path, cancel)?;
    format.parse_cancellable(&bytes, path, cancel)
}

/// Reads a shape file, choosing the reader from the extension (case-insensitive):
/// `.off`, `.obj`, `.ply`, `.xyz`, `.pts`.
pub fn read_shape(path: &Path) -> Result<RawShape> {
    read_shape_cancellable(path, &Cancel::default())
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
    read_bytes_cancellable(path, &Cancel::default())
}

/// Bytes read between two looks at the cancel flag: a few milliseconds from the page cache,
/// about 0.1 s from a slow disk (80 MB/s).
const READ_CHUNK: usize = 8 << 20;

/// [`read_bytes`], checking `cancel` between chunks of [`READ_CHUNK`] bytes.
fn read_bytes_cancellable(path: &Path, cancel: &Cancel) -> Result<Vec<u8>> {
    use std::io::Read;
    let cannot = |e: std::io::Error| Error::file(path, format!("cannot read the file: {e}"));
    let size = regular_file_size(path)?;
    let mut bytes = Vec::with_capacity(size as usize);
    let mut file = std::fs::File::open(path)
        .map_err(cannot)?
        .take(MAX_FILE_BYTES + 1);
    loop {
        cancel.check()?;
        let read = (&mut file)
            .take(READ_CHUNK as u64)
            .read_to_end(&mut bytes)
            .map_err(cannot)?;
        if read == 0 {
            break;
        }
    }
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(path, bytes.len() as u64));
    }
    Ok(bytes)
}

/// What a shape file holds, known before its body is read: its size and the vertices and
/// faces it declares (PLY, OFF: from the header; OBJ, XYZ: by counting the lines that start
/// with `v ` and `f `, or the lines, without parsing them). Counts are capped by what the
/// file's bytes can hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeclaredSize {
    /// Bytes of the file.
    pub bytes: u64,
    /// Vertices declared.
    pub vertices: usize,
    /// Faces declared.
    pub faces: usize,
}

/// The [`DeclaredSize`] of a shape file, read cheaply: the header, or one pass counting
/// lines through a small buffer. The file gets the readers' checks (a regular file of at
/// most [`MAX_FILE_BYTES`]); a header this cannot make sense of gives counts of 0 (the
/// reader then says what is wrong).
pub fn declared_size(path: &Path) -> Result<DeclaredSize> {
    use std::io::{BufRead, Read};
    let format = Format::from_path(path)?;
    let bytes = regular_file_size(path)?;
    let cannot = |e: std::io::Error| Error::file(path, format!("cannot read the file: {e}"));
    let file = std::fs::File::open(path).map_err(cannot)?;
    let mut reader = std::io::BufReader::with_capacity(1 << 16, file);
    let (mut vertices, mut faces) = (0usize, 0usize);
    let count = |t: Option<&str>| t.and_then(|t| t.parse::<usize>().ok()).unwrap_or(0);
    match format {
        Format::Ply | Format::Off => {
            let mut head = Vec::new();
            reader
                .by_ref()
                .take(1 << 16)
                .read_to_end(&mut head)
                .map_err(cannot)?;
            let text = String::from_utf8_lossy(&head);
            let mut lines = text
                .lines()
                .map(|l| l.split('#').next().unwrap_or("").trim());
            if format == Format::Ply {
                for line in lines.by_ref().take_while(|l| *l != "end_header") {
                    let mut t = line.split_ascii_whitespace();
                    match (t.next(), t.next()) {
                        (Some("element"), Some("vertex")) => vertices = count(t.next()),
                        (Some("element"), Some("face")) => faces = count(t.next()),
                        _ => {}
                    }
                }
            } else {
                let mut data = lines.filter(|l| !l.is_empty());
                let keyword = data.next().unwrap_or("");
                let mut t: Vec<&str> = keyword.split_ascii_whitespace().skip(1).collect();
                if t.is_empty() {
                    t = data.next().unwrap_or("").split_ascii_whitespace().collect();
                }
                vertices = count(t.first().copied());
                faces = count(t.get(1).copied());
            }
        }
        Format::Obj | Format::Xyz => {
            let mut line = Vec::new();
            loop {
                line.clear();
                if reader.read_until(b'\n', &mut line).map_err(cannot)? == 0 {
                    break;
                }
                let l = line.trim_ascii_start();
                match format {
                    Format::Obj if l.starts_with(b"v ") || l.starts_with(b"v\t") => vertices += 1,
                    Format::Obj if l.starts_with(b"f ") || l.starts_with(b"f\t") => faces += 1,
                    Format::Xyz if !l.is_empty() && !l.starts_with(b"#") => vertices += 1,
                    _ => {}
                }
            }
        }
    }
    // A vertex takes at least 3 bytes (binary `char` coordinates), a face 4.
    let room = usize::try_from(bytes).unwrap_or(usize::MAX);
    Ok(DeclaredSize {
        bytes,
        vertices: capped(vertices, room, 3),
        faces: capped(faces, room, 4),
    })
}

/// The size of a regular file of at most [`MAX_FILE_BYTES`] (the checks of [`read_bytes`]).
fn regular_file_size(path: &Path) -> Result<u64> {
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
    if meta.len() > MAX_FILE_BYTES {
        return Err(too_large(path, meta.len()));
    }
    Ok(meta.len())
}

fn too_large(path: &Path, size: u64) -> Error {
    Error::file(
        path,
        format!(
            "the file has {size} bytes, more than the {MAX_FILE_BYTES} bytes (4 GiB) \
             shapecorr reads; simplify the shape"
        ),
    )
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
/// surrounding white space trimmed and empty lines skipped. Once `cancel` is set the lines
/// end (within [`CHECK_EVERY`] lines), and the fraction of the text gone through is
/// published as they go.
fn data_lines<'a>(text: &'a str, cancel: &'a Cancel) -> impl Iterator<Item = (usize, &'a str)> {
    let total = text.len().max(1) as f32;
    let start = text.as_ptr() as usize;
    let watched = text.split('\n').enumerate().take_while(move |(i, line)| {
        if i % CHECK_EVERY != 0 {
            return true;
        }
        cancel.set_fraction((line.as_ptr() as usize - start) as f32 / total);
        cancel.check().is_ok()
    });
    watched.filter_map(|(i, line)| {
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
