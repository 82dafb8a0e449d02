//! Unit tests of the readers and the PLY encoder.

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
    let coff =
        off_s("COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n")
            .unwrap();
    let cnoff =
        off_s("CNOFF 3 1 0\n0 0 0 0 0 1 1 1 1\n1 0 0 0 0 1 1 1 1\n0 1 0 0 0 1 1 1 1\n3 0 1 2\n")
            .unwrap();
    let stoff = off_s("STOFF\n3 1\n0 0 0 0.5 0.5\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n").unwrap();
    for s in [&noff, &coff, &cnoff, &stoff] {
        assert_eq!(s.vertices, vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
        assert_eq!(s.polygons, vec![vec![0, 1, 2]]);
    }
}

#[test]
fn off_errors() {
    assert!(
        err(off_s("OFF\n3 1 0\n0 0 0\n1 0\n")).contains("line 4: expected 3 coordinates, found 2")
    );
    assert!(
        err(off_s("OFF\n3 1 0\n0 0 0\n1 0 0\n")).contains("expected 3 vertices, file ends after 2")
    );
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
    assert!(e(format!("{h}0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n")).contains("negative vertex index -1"));
    assert!(e(format!("{h}0 0 0\n1 0 0\n")).contains("expected 3 vertices, file ends after 2"));
    assert!(e(format!("{h}0 0 0\n1 0 0\n0 1 0\n3 0 1\n"))
        .contains("list declares 3 values but the line holds 2"));
    assert!(e(format!("{h}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n")).contains("unexpected data"));
    assert!(e(format!("{h}0 0 0 0\n")).contains("unexpected value"));
    assert!(e(h.replace("property float z\n", "")).contains("no property 'z'"));
    assert!(e(h.replace("property float z\n", "property float x\n")).contains("declared twice"));
    assert!(e(h.replace("vertex_indices", "corners")).contains("no list property 'vertex_indices'"));
    assert!(e(h.replace("int vertex_indices", "float vertex_indices")).contains("integer type"));
    assert!(e(h.replace("vertex 3", "vertex 4000000000")).contains("expected 4000000000 vertices"));
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

/// Only ASCII white space separates numbers. A U+0085 (next line),
/// U+00A0 (no-break space) or U+2003 (em space) inside or between numbers is an error
/// naming the file and the line, never two numbers.
#[test]
fn unicode_white_space_is_not_a_separator() {
    for odd in ['\u{85}', '\u{a0}', '\u{2003}'] {
        let cases: [(&str, String); 5] = [
            (
                "a.off",
                format!("OFF\n3 1 0\n0 0 0\n1 0{odd}5 0\n0 1 0\n3 0 1 2\n"),
            ),
            (
                "a.obj",
                format!("v 0 0 0\nv 1 0{odd}5 0\nv 0 1 0\nf 1 2 3\n"),
            ),
            ("a.xyz", format!("0 0 0\n1 0{odd}5 0\n0 1 0\n")),
            ("b.xyz", format!("0 0 0\n1{odd}0 0\n0 1 0\n")),
            (
                "a.ply",
                format!(
                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                     property float z\nend_header\n0 0 0\n1 0{odd}5 0\n0 1 0\n"
                ),
            ),
        ];
        for (file, text) in cases {
            let name = Path::new(file);
            let result = parse_shape(text.as_bytes(), name);
            let message = match result {
                Ok(s) => panic!("{file} with {odd:?}: read as {:?}", s.vertices),
                Err(e) => e.to_string(),
            };
            assert!(message.contains(file), "{message}");
            assert!(message.contains("line"), "{file}: {message}");
            let escaped = odd.escape_unicode().to_string();
            assert!(message.contains(&escaped), "{file}: {message}");
        }
    }
}
