//! PLY reading (ASCII and binary) and writing.

use std::path::Path;

use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use super::{capped, shown, RawShape, CHECK_EVERY};
use crate::error::{Error, Result};
use crate::progress::Cancel;

// ---------------------------------------------------------------------------------------------
// PLY reading

/// Parses PLY (`ascii`, `binary_little_endian` or `binary_big_endian`): element `vertex` with
/// scalar properties `x`, `y`, `z` of any type (other properties ignored), and optionally
/// element `face` with an integer list property `vertex_indices` (or `vertex_index`). Without
/// a face element the shape is a point cloud. Other elements are skipped. A body shorter than
/// the header declares is an error, and so is data after the last element (it means the
/// header does not describe the data), except trailing white space.
pub fn parse_ply(bytes: &[u8], name: &Path) -> Result<RawShape> {
    ply(bytes, &Cancel::default()).map_err(|reason| Error::file(name, reason))
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

pub(super) fn ply(bytes: &[u8], cancel: &Cancel) -> Result<RawShape, String> {
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
        total: bytes.len(),
        cancel,
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
            .filter(|l| l.split_ascii_whitespace().next() == Some(word))
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
    /// Bytes of the whole file, for the fraction read.
    total: usize,
    /// Looked at every [`CHECK_EVERY`] elements; once set, reading stops.
    cancel: &'a Cancel,
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
            if i % CHECK_EVERY == 0 {
                let read = self.total.saturating_sub(self.rest.len());
                self.cancel
                    .set_fraction(read as f32 / self.total.max(1) as f32);
                if self.cancel.check().is_err() {
                    return Err("cancelled".to_string());
                }
            }
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
        let mut tokens = text.split_ascii_whitespace();
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
