//! What the fuzz targets share: a byte reader that never fails (missing bytes read as 0), the
//! decoding of fuzz input into vertices and polygons (with its inverse, for the seeds), and
//! the binary PLY header built from fuzz input.
//!
//! Encodings (all integers little-endian):
//! - shape: `coords: u8, n: u16, n` vertices, `m: u16, m` polygons. Coordinates by
//!   `coords & 3`: 0 an `i8`, 1 an `i16` / 1024, 2 an `f32`, 3 an `f64`; with `coords & 4`
//!   each vertex starts with its own mode byte. A polygon is `corners: u8` (only when
//!   polygons of any size are decoded; else 3) and `corners` indices of 2 bytes each: `r`
//!   gives `r % n`, except `0xFFFE` (the index `n`, just past the end) and `0xFFFF` (the next
//!   4 bytes, any `u32`).
//! - binary PLY: see [`PlySpec`].

use std::path::Path;

use shapecorr::shape::io::RawShape;
use shapecorr::{ReadAs, Shape};

/// Most vertices and polygons decoded (keeps one execution short).
pub const MAX_VERTICES: usize = 200;
/// Most polygons decoded.
pub const MAX_POLYGONS: usize = 400;

/// Reads fuzz input; past the end every read gives 0.
pub struct Bytes<'a>(pub &'a [u8]);

impl Bytes<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0; N];
        let n = N.min(self.0.len());
        out[..n].copy_from_slice(&self.0[..n]);
        self.0 = &self.0[n..];
        out
    }
    pub fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.take())
    }
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    pub fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    pub fn f64(&mut self) -> f64 {
        f64::from_bits(self.u64())
    }
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
    /// Up to `max` bytes, the count given by the next byte.
    pub fn bytes(&mut self, max: usize) -> &[u8] {
        let n = (self.u8() as usize).min(max).min(self.0.len());
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        head
    }
    /// The rest of the input.
    pub fn rest(&mut self) -> &[u8] {
        std::mem::take(&mut self.0)
    }
}

/// Decodes a shape (see the module docs); `any_size`: polygons of 0 to 8 corners, else
/// triangles.
pub fn decode_shape(b: &mut Bytes, any_size: bool) -> RawShape {
    let coords = b.u8();
    let n = b.u16() as usize % (MAX_VERTICES + 1);
    let mut vertices = Vec::with_capacity(n);
    for _ in 0..n {
        let mode = if coords & 4 != 0 { b.u8() } else { coords };
        vertices.push([(); 3].map(|_| coordinate(b, mode)));
    }
    let m = b.u16() as usize % (MAX_POLYGONS + 1);
    let polygons = (0..m)
        .map(|_| {
            let corners = if any_size { b.u8() % 9 } else { 3 };
            (0..corners).map(|_| index(b, n)).collect()
        })
        .collect();
    RawShape { vertices, polygons }
}

fn coordinate(b: &mut Bytes, mode: u8) -> f64 {
    match mode & 3 {
        0 => f64::from(b.u8() as i8),
        1 => f64::from(b.u16() as i16) / 1024.0,
        2 => f64::from(f32::from_bits(b.u32())),
        _ => b.f64(),
    }
}

fn index(b: &mut Bytes, n: usize) -> u32 {
    match b.u16() {
        0xFFFF => b.u32(),
        0xFFFE => n as u32,
        r if n > 0 => (r as usize % n) as u32,
        r => r.into(),
    }
}

/// The bytes [`decode_shape`] reads back as `shape` (coordinates in mode `coords`, 0 to 3;
/// indices below 0xFFFE; polygons of at most 8 corners when `any_size`).
pub fn encode_shape(shape: &RawShape, coords: u8, any_size: bool) -> Vec<u8> {
    let mut out = vec![coords];
    out.extend((shape.vertices.len() as u16).to_le_bytes());
    for c in shape.vertices.iter().flatten() {
        match coords & 3 {
            0 => out.push(*c as i8 as u8),
            1 => out.extend(((c * 1024.0).round() as i16).to_le_bytes()),
            2 => out.extend((*c as f32).to_le_bytes()),
            _ => out.extend(c.to_le_bytes()),
        }
    }
    out.extend((shape.polygons.len() as u16).to_le_bytes());
    for p in &shape.polygons {
        if any_size {
            out.push(p.len() as u8);
        }
        for &i in p {
            out.extend((i as u16).to_le_bytes());
        }
    }
    out
}

/// After a reader accepted the bytes: the shape built from them, as `sc_shape_read` does
/// (small files only, to keep executions short), must not panic.
pub fn read_and_build(raw: shapecorr::Result<RawShape>) {
    if let Ok(raw) = raw {
        if raw.vertices.len() <= MAX_VERTICES && raw.polygons.len() <= MAX_POLYGONS {
            let _ = Shape::from_raw(raw, ReadAs::Auto);
        }
    }
}

/// The name the readers put in their error messages.
pub fn name() -> &'static Path {
    Path::new("fuzz-input")
}

/// PLY scalar type names, with the aliases.
pub const PLY_TYPES: [&str; 16] = [
    "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "int16",
    "uint16", "int32", "uint32", "float32", "float64",
];

/// A binary PLY header from 11 bytes: `flags, x, y, z, count, index, extra: u8` (types are
/// indices into [`PLY_TYPES`], mod 16), `vertices, faces: u16`. Flags: 1 big-endian, 2 a
/// face element, 4 `vertex_index` instead of `vertex_indices`, 8 an extra vertex property
/// (`red`, of type `extra`), 16 an extra element `edge` (2 ints) after the faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlySpec {
    pub flags: u8,
    pub xyz: [u8; 3],
    pub count: u8,
    pub index: u8,
    pub extra: u8,
    pub vertices: u16,
    pub faces: u16,
}

impl PlySpec {
    pub fn decode(b: &mut Bytes) -> PlySpec {
        PlySpec {
            flags: b.u8(),
            xyz: [b.u8(), b.u8(), b.u8()],
            count: b.u8(),
            index: b.u8(),
            extra: b.u8(),
            vertices: b.u16(),
            faces: b.u16(),
        }
    }

    pub fn encode(&self) -> Vec<u8> {
        let mut out = vec![self.flags];
        out.extend(self.xyz);
        out.extend([self.count, self.index, self.extra]);
        out.extend(self.vertices.to_le_bytes());
        out.extend(self.faces.to_le_bytes());
        out
    }

    /// The header text, `ply` to `end_header\n`.
    pub fn header(&self) -> String {
        let ty = |t: u8| PLY_TYPES[t as usize % 16];
        let endian = if self.flags & 1 != 0 { "big" } else { "little" };
        let mut h = format!(
            "ply\nformat binary_{endian}_endian 1.0\nelement vertex {}\n",
            self.vertices
        );
        for (axis, t) in ["x", "y", "z"].iter().zip(self.xyz) {
            h += &format!("property {} {axis}\n", ty(t));
        }
        if self.flags & 8 != 0 {
            h += &format!("property {} red\n", ty(self.extra));
        }
        if self.flags & 2 != 0 {
            let name = if self.flags & 4 != 0 {
                "vertex_index"
            } else {
                "vertex_indices"
            };
            h += &format!(
                "element face {}\nproperty list {} {} {name}\n",
                self.faces,
                ty(self.count),
                ty(self.index)
            );
        }
        if self.flags & 16 != 0 {
            h += "element edge 1\nproperty int vertex1\nproperty int vertex2\n";
        }
        h + "end_header\n"
    }
}
