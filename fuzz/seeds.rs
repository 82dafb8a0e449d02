//! Writes the seed corpus: `seeds <dir>` fills `<dir>/<target>/` for every fuzz target with
//! small valid inputs made here: a generated figure (`shapecorr::synth`, written with the
//! library's PLY writer and with the small OFF/OBJ/XYZ writers below), a tetrahedron, a cube
//! of quads, a grid, its triangle soup, a sampled point cloud, and the edge cases the readers
//! accept (comments, CRLF, polygons, negative OBJ indices, colours and normals, other
//! elements, both byte orders, every PLY type), and values files (`read_values`: blanks,
//! commas, comments, wide integers, and the refused empty field and non-ASCII separator).

use std::fmt::Write as _;
use std::path::Path;

use shapecorr::shape::io::{encode_ply, PlyEncoding, RawShape};
use shapecorr::synth::{self, FigureKind, FigureSpec, Proportions};
use shapecorr_fuzz::{encode_shape, PlySpec, PLY_TYPES};

type Shape = (Vec<[f64; 3]>, Vec<Vec<u32>>);

fn tetrahedron() -> Shape {
    let v = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let f = vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]];
    (v, f)
}

fn cube() -> Shape {
    let v = (0..8)
        .map(|i| [(i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64])
        .collect();
    let f = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    (v, f.iter().map(|q| q.to_vec()).collect())
}

/// A `k` x `k` grid of quads (`quads`) or triangles on a bumpy sheet.
fn grid(k: u32, quads: bool) -> Shape {
    let v = (0..k * k)
        .map(|i| {
            let (x, y) = (f64::from(i % k), f64::from(i / k));
            [x / 8.0, y / 8.0, ((x + y) * 0.7).sin() / 16.0]
        })
        .collect();
    let mut f = Vec::new();
    for y in 0..k - 1 {
        for x in 0..k - 1 {
            let [a, b, c, d] = [
                y * k + x,
                y * k + x + 1,
                (y + 1) * k + x + 1,
                (y + 1) * k + x,
            ];
            if quads {
                f.push(vec![a, b, c, d]);
            } else {
                f.extend([vec![a, b, c], vec![a, c, d]]);
            }
        }
    }
    (v, f)
}

/// Every triangle with its own three vertices (what welding repairs).
fn soup((v, f): &Shape) -> Shape {
    let vertices = f.iter().flatten().map(|&i| v[i as usize]).collect();
    let faces = (0..f.len() as u32)
        .map(|t| vec![3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    (vertices, faces)
}

fn figure() -> Shape {
    let spec = FigureSpec {
        kind: FigureKind::Star { limbs: 3 },
        pose: 1,
        target_vertices: 500,
        proportions: Proportions::default(),
        ..Default::default()
    };
    let mesh = synth::figure(&spec).expect("a valid figure");
    let faces = mesh.triangles.iter().map(|t| t.to_vec()).collect();
    (mesh.vertices, faces)
}

fn cloud() -> Vec<[f64; 3]> {
    let (v, f) = figure();
    let triangles: Vec<[u32; 3]> = f.iter().map(|t| [t[0], t[1], t[2]]).collect();
    let mesh = synth::FigureMesh {
        vertices: v,
        triangles,
    };
    synth::sample_points(&mesh, 300, 0.001, 7)
        .expect("sampled")
        .points
}

fn off((v, f): &Shape, keyword: &str, newline: &str) -> String {
    let mut s = format!("{keyword}{newline}# made by fuzz/seeds.rs{newline}");
    let _ = write!(s, "{} {} 0{newline}", v.len(), f.len());
    for p in v {
        let _ = write!(s, "{} {} {}{newline}", p[0], p[1], p[2]);
    }
    for p in f {
        let idx: Vec<String> = p.iter().map(u32::to_string).collect();
        let _ = write!(s, "{} {}{newline}", p.len(), idx.join(" "));
    }
    s
}

/// OBJ with faces as `style`: 0 `f 1 2 3`, 1 `f 1/1/1 ...`, 2 negative (relative) indices
/// (each face written right after its vertices would need reordering, so relative to the
/// end of the vertex list).
fn obj((v, f): &Shape, style: u8, newline: &str) -> String {
    let mut s = format!("# made by fuzz/seeds.rs{newline}o seed{newline}");
    for p in v {
        let _ = write!(s, "v {} {} {}{newline}", p[0], p[1], p[2]);
    }
    let _ = write!(s, "vt 0 0{newline}vn 0 0 1{newline}s off{newline}");
    for p in f {
        s += "f";
        for &i in p {
            let _ = match style {
                0 => write!(s, " {}", i + 1),
                1 => write!(s, " {}/1/1", i + 1),
                _ => write!(s, " {}", i as i64 - v.len() as i64),
            };
        }
        s += newline;
    }
    s
}

fn xyz(v: &[[f64; 3]], count: bool, sep: &str, extra: &str) -> String {
    let mut s = String::from("# made by fuzz/seeds.rs\n");
    if count {
        let _ = writeln!(s, "{}", v.len());
    }
    for p in v {
        let _ = writeln!(s, "{}{sep}{}{sep}{}{extra}", p[0], p[1], p[2]);
    }
    s
}

fn triangles(f: &[Vec<u32>]) -> Vec<[u32; 3]> {
    f.iter().map(|t| [t[0], t[1], t[2]]).collect()
}

/// One PLY value of type `ty` (a [`PLY_TYPES`] name).
fn put(out: &mut Vec<u8>, ty: &str, v: f64, big: bool) {
    macro_rules! bytes {
        ($t:ty) => {{
            let x = v as $t;
            out.extend(if big {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            })
        }};
    }
    match ty {
        "char" | "int8" => bytes!(i8),
        "uchar" | "uint8" => bytes!(u8),
        "short" | "int16" => bytes!(i16),
        "ushort" | "uint16" => bytes!(u16),
        "int" | "int32" => bytes!(i32),
        "uint" | "uint32" => bytes!(u32),
        "float" | "float32" => bytes!(f32),
        _ => bytes!(f64),
    }
}

/// A `read_ply_binary` input: the spec's bytes and a body it describes.
fn ply_binary((v, f): &Shape, spec: PlySpec) -> Vec<u8> {
    let spec = PlySpec {
        vertices: v.len() as u16,
        faces: f.len() as u16,
        ..spec
    };
    let ty = |t: u8| PLY_TYPES[t as usize % 16];
    let big = spec.flags & 1 != 0;
    let mut out = spec.encode();
    for p in v {
        for (c, t) in p.iter().zip(spec.xyz) {
            put(&mut out, ty(t), *c, big);
        }
        if spec.flags & 8 != 0 {
            put(&mut out, ty(spec.extra), 200.0, big);
        }
    }
    if spec.flags & 2 != 0 {
        for p in f {
            put(&mut out, ty(spec.count), p.len() as f64, big);
            for &i in p {
                put(&mut out, ty(spec.index), f64::from(i), big);
            }
        }
    }
    if spec.flags & 16 != 0 {
        put(&mut out, "int", 0.0, big);
        put(&mut out, "int", 1.0, big);
    }
    out
}

fn write(dir: &Path, target: &str, name: &str, bytes: impl AsRef<[u8]>) {
    let dir = dir.join(target);
    std::fs::create_dir_all(&dir).expect("corpus directory");
    std::fs::write(dir.join(name), bytes).expect("seed written");
}

fn readers(dir: &Path) {
    let (tet, cube, fig, grid) = (tetrahedron(), cube(), figure(), grid(6, true));
    let w = |t: &str, n: &str, b: Vec<u8>| write(dir, t, n, b);
    w("read_off", "tetrahedron.off", off(&tet, "OFF", "\n").into());
    w(
        "read_off",
        "cube-crlf.off",
        off(&cube, "OFF", "\r\n").into(),
    );
    w("read_off", "grid-quads.off", off(&grid, "OFF", "\n").into());
    w("read_off", "figure.off", off(&fig, "OFF", "\n").into());
    w("read_off", "empty.off", b"OFF\n0 0 0\n".to_vec());
    let coff = "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n\
                3 0 1 2 128 128 128\n";
    w("read_off", "colours.off", coff.into());
    w(
        "read_off",
        "counts-on-keyword-line.off",
        b"OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec(),
    );
    w("read_obj", "tetrahedron.obj", obj(&tet, 0, "\n").into());
    w(
        "read_obj",
        "cube-slashes-crlf.obj",
        obj(&cube, 1, "\r\n").into(),
    );
    w("read_obj", "cube-negative.obj", obj(&cube, 2, "\n").into());
    w("read_obj", "figure.obj", obj(&fig, 0, "\n").into());
    w(
        "read_obj",
        "points.obj",
        obj(&(fig.0.clone(), vec![]), 0, "\n").into(),
    );
    for (name, enc) in [
        ("ascii", PlyEncoding::Ascii),
        ("binary", PlyEncoding::BinaryLittleEndian),
    ] {
        let bytes = |s: &Shape, colours: bool| {
            let c = vec![[10u8, 20, 30]; s.0.len()];
            encode_ply(&s.0, &triangles(&s.1), colours.then_some(&c[..]), enc).expect("encoded")
        };
        w(
            "read_ply",
            &format!("tetrahedron-{name}.ply"),
            bytes(&tet, true),
        );
        w(
            "read_ply",
            &format!("figure-{name}.ply"),
            bytes(&fig, false),
        );
        w(
            "read_ply",
            &format!("points-{name}.ply"),
            bytes(&(cloud(), vec![]), false),
        );
    }
    let quads = "ply\r\nformat ascii 1.0\r\ncomment made by fuzz/seeds.rs\r\nelement vertex 4\r\n\
                 property double x\r\nproperty double y\r\nproperty double z\r\n\
                 property uchar red\r\nelement face 1\r\nproperty list uchar int vertex_index\r\n\
                 element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n\
                 0 0 0 1\r\n1 0 0 2\r\n1 1 0 3\r\n0 1 0 4\r\n4 0 1 2 3\r\n0 1\r\n";
    w("read_ply", "quad-crlf-edge.ply", quads.into());
    // Crashes found before, kept as seeds so that every run (with overflow checks, unlike
    // the release tests) replays them: tests/it/fuzz_regressions.rs has each one too.
    let far = "ply\nformat ascii 1.0\nelement vertex 32\nproperty float x\nproperty float y\n\
               property float z\nend_header\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n0 1 0\n1 1 0\n2 1 0\n\
               3 1 0\n0 2 0\n1 2 0\n2 2 0\n3 2 0\n0 3 0\n1 3 0\n2 3 0\n3 3 0\n0 0 1\n1 0 1\n\
               2 0 1\n3 0 1\n0 1 1\n1 1 1\n2 1 1\n3 1 1\n0 2 1\n1 2 1\n2 2 1\n3 2 1\n0 3 1\n\
               1 3 1\n1e+20 0 0\n1e+30 0 0\n";
    w("read_ply", "regression-weld-far-point.ply", far.into());
    let spec = |flags, xyz, count, index, extra| PlySpec {
        flags,
        xyz: [xyz; 3],
        count,
        index,
        extra,
        vertices: 0,
        faces: 0,
    };
    let specs = [
        ("float-uchar-int", spec(2, 6, 1, 4, 0)),
        ("double-be-uint", spec(3, 7, 1, 5, 0)),
        ("short-ushort-index", spec(2 | 4 | 8, 2, 3, 11, 1)),
        ("float64-edge", spec(2 | 16, 15, 9, 12, 0)),
        ("char-points", spec(8, 0, 0, 0, 7)),
        ("int-be-int16", spec(1 | 2 | 8, 4, 10, 10, 6)),
    ];
    for (name, s) in specs {
        let shape = if name.contains("char") || name.contains("short") {
            &cube
        } else {
            &tet
        };
        w(
            "read_ply_binary",
            &format!("{name}.bin"),
            ply_binary(shape, s),
        );
    }
    w(
        "read_ply_binary",
        "figure.bin",
        ply_binary(&fig, spec(2, 6, 1, 4, 0)),
    );
    let c = cloud();
    w("read_xyz", "cloud.xyz", xyz(&c, false, " ", "").into());
    w(
        "read_xyz",
        "cloud-count-commas.pts",
        xyz(&c, true, ",", "").into(),
    );
    w(
        "read_xyz",
        "tetrahedron-normals.xyz",
        xyz(&tet.0, false, "\t", " 0 0 1").into(),
    );
    w(
        "read_xyz",
        "crlf.xyz",
        b"0 0 0\r\n1 0 0\r\n0 1 0\r\n# end\r\n".to_vec(),
    );
}

/// The shapes the shape targets start from: `(name, shape, point cloud)`.
fn shapes() -> Vec<(&'static str, Shape)> {
    let grid = grid(7, false);
    let mut far = grid.clone();
    far.0.push([100.0, 0.0, 0.0]);
    let last = far.0.len() as u32 - 1;
    far.1.push(vec![0, 1, last]);
    let mut debris = grid.clone();
    let n = debris.0.len() as u32;
    debris
        .0
        .extend([[5.0, 5.0, 5.0], [5.1, 5.0, 5.0], [5.0, 5.1, 5.0]]);
    debris.1.push(vec![n, n + 1, n + 2]);
    vec![
        ("figure", figure()),
        ("grid", grid.clone()),
        ("soup", soup(&grid)),
        ("far-vertex", far),
        ("debris", debris),
        ("cloud", (cloud(), vec![])),
    ]
}

fn shape_targets(dir: &Path) {
    for (name, (v, f)) in shapes() {
        let cloud = f.is_empty();
        let raw = RawShape {
            vertices: v,
            polygons: f,
        };
        for coords in [1u8, 3] {
            // shape_new: Shape::mesh / point_cloud_with / from_raw_with (repairs switched by
            // a byte), default repairs.
            let mut bytes = vec![if cloud { 2u8 } else { 0 }];
            bytes.extend(encode_shape(&raw, coords, false));
            write(dir, "shape_new", &format!("{name}-{coords}"), bytes);
            let mut bytes = vec![0x23, 0b011];
            bytes.extend(encode_shape(&raw, coords, true));
            write(dir, "shape_new", &format!("{name}-{coords}-raw"), bytes);
            // ffi_shape_new: the mesh or point-cloud constructor, f64 and f32.
            for how in if cloud { [3u8, 4, 5] } else { [0, 1, 2] } {
                let mut bytes = vec![how, 0, 0];
                bytes.extend(7u32.to_le_bytes());
                bytes.extend(encode_shape(&raw, coords, false));
                write(
                    dir,
                    "ffi_shape_new",
                    &format!("{name}-{coords}-{how}"),
                    bytes,
                );
            }
        }
    }
}

/// `ffi_params`: every option set to a value in range, read back; an unknown name.
fn params(dir: &Path) {
    let mut all = Vec::new();
    for i in 0..shapecorr::ffi::sc_option_count() {
        let (op, value) = match shapecorr::ffi::sc_option_type(i) {
            shapecorr::ffi::SC_OPTION_INT => (0u8, vec![0u8, 5]),
            shapecorr::ffi::SC_OPTION_DOUBLE => (1, vec![0, 2]),
            _ => (2, vec![1]),
        };
        let mut one = vec![op, i as u8];
        one.extend(value);
        one.push(i as u8);
        write(dir, "ffi_params", &format!("option-{i}"), &one);
        all.extend(one);
        all.extend([op + 3, i as u8, i as u8]);
    }
    write(dir, "ffi_params", "all-options", &all);
    write(
        dir,
        "ffi_params",
        "unknown",
        b"\x00\xe0\x05k_mix\x00\x05\x00",
    );
}

/// `read_pairs`: tab- and space-separated pair files, names with spaces, categories,
/// comments, CRLF, a byte order mark, and malformed lines.
fn pair_files(dir: &Path) {
    let files: [(&str, &[u8]); 7] = [
        ("tabs", b"# source\ttarget\tcategory\ntr_reg_000\ttr_reg_009\tsame_person\n"),
        ("spaces", b"a b\nc d category\n\n  # comment\n"),
        ("names-with-spaces", b"left arm\tright arm\nx--y\tz\tsplit\n"),
        ("crlf-bom", b"\xEF\xBB\xBFa\tb\r\nc\td\r\n"),
        ("one-field", b"a\tb\nlonely\n"),
        ("empty-name", b"\tb\n"),
        ("four-fields", b"a\tb\tc\td\n"),
    ];
    for (name, bytes) in files {
        write(dir, "read_pairs", name, bytes);
    }
}

/// Values files (`read_values`): the first byte is the row count, the rest the file.
fn values(dir: &Path) {
    let w = |n: &str, rows: u8, text: &str| {
        let mut bytes = vec![rows];
        bytes.extend_from_slice(text.as_bytes());
        write(dir, "read_values", n, bytes);
    };
    w("blanks.txt", 3, "1 2 3\n4\t5 6\n7 8 9\n");
    w("commas-crlf.txt", 2, "0.5, 0.25,1e-3\r\n-2,3.5,+4\r\n");
    w("comments.txt", 2, "\u{feff}# weights\n\n0.1 0.9 # first\n  1 0\n");
    w("wide-integers.txt", 3, "9007199254740993\n18446744073709551615\n-9223372036854775808\n");
    w("floats.txt", 2, "1e20 4e16 -1e300\n1e-300 .5 5.\n");
    w("empty-field.txt", 1, "0.5,,0.25\n");
    w("nbsp.txt", 1, "1\u{a0}2 3\n");
    w("ragged.txt", 2, "1 2\n3\n");
}

fn main() {
    let dir = std::env::args().nth(1).unwrap_or_else(|| "corpus".into());
    let dir = Path::new(&dir);
    readers(dir);
    values(dir);
    shape_targets(dir);
    params(dir);
    pair_files(dir);
}
