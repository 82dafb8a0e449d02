//! A dense shape for the limits benchmark (tests/bench/dense_limits.sh): every triangle of a
//! mesh split into four at its edges' midpoints, `times` times (a 120K-vertex figure becomes
//! 1.9M vertices after two), written as binary PLY.
//!
//!     cargo run --release -p shapecorr-eval --example subdivide -- IN.ply OUT.ply TIMES

use std::collections::HashMap;
use std::path::Path;

use shapecorr::shape::io::{read_shape, write_ply};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, output, times] = args.as_slice() else {
        eprintln!("usage: subdivide IN.ply OUT.ply TIMES");
        std::process::exit(2);
    };
    let raw = read_shape(Path::new(input)).unwrap_or_else(|e| panic!("{e}"));
    let mut vertices = raw.vertices;
    let mut triangles: Vec<[u32; 3]> = raw.polygons.iter().map(|p| [p[0], p[1], p[2]]).collect();
    for _ in 0..times.parse::<usize>().expect("TIMES is a count") {
        let mut midpoint = HashMap::with_capacity(triangles.len() * 3 / 2);
        let mut split = Vec::with_capacity(triangles.len() * 4);
        for t in &triangles {
            let mut mid = |a: u32, b: u32| -> u32 {
                *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    let (p, q) = (vertices[a as usize], vertices[b as usize]);
                    vertices.push([0, 1, 2].map(|c| 0.5 * (p[c] + q[c])));
                    (vertices.len() - 1) as u32
                })
            };
            let [a, b, c] = *t;
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            split.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        triangles = split;
    }
    write_ply(Path::new(output), &vertices, &triangles, None).unwrap_or_else(|e| panic!("{e}"));
    println!(
        "{output}: {} vertices, {} triangles",
        vertices.len(),
        triangles.len()
    );
}
