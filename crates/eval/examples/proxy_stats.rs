//! The quality of the proxies the library would make (docs/decisions.md, "Dense shapes:
//! proxies"): for every shape file given,
//! the time to read and to simplify it, the proxy's size, pieces and repairs, its smallest
//! triangle angles (1st and 10th percentile) and its area against the input's.
//!
//!     cargo run --release -p shapecorr-eval --example proxy_stats -- A.ply B.ply ...

use shapecorr::pipeline::multiresolution::DEFAULT_PROXY_VERTICES;
use shapecorr::shape::proxy::Proxy;
use shapecorr::{ReadAs, Shape};
fn main() {
    for path in std::env::args().skip(1) {
        let t = std::time::Instant::now();
        let shape = Shape::read(std::path::Path::new(&path), ReadAs::Auto).unwrap();
        let t_read = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let proxy = Proxy::build(&shape, DEFAULT_PROXY_VERTICES).unwrap();
        let p = &proxy.shape;
        let mut angles: Vec<f64> = Vec::new();
        for tri in p.triangles() {
            let v = tri.map(|i| p.vertices()[i as usize]);
            for k in 0..3 {
                let (a, b, c) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let d = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
                let n = (u.iter().map(|x| x * x).sum::<f64>()
                    * w.iter().map(|x| x * x).sum::<f64>())
                .sqrt();
                angles.push((d / n).clamp(-1.0, 1.0).acos().to_degrees());
            }
        }
        angles.sort_by(|a, b| a.total_cmp(b));
        println!(
            "{path}: read {t_read:.2} s, proxy {:.2} s: {} vertices ({} active), {} triangles, {} pieces, warnings {:?}; min angle p1 {:.1} p10 {:.1}; area ratio {:.4}",
            t.elapsed().as_secs_f64(),
            p.n_vertices(),
            p.active_vertices().len(),
            p.triangles().len(),
            p.n_pieces(),
            p.warnings(),
            angles[angles.len() / 100],
            angles[angles.len() / 10],
            p.mesh_area() / shape.mesh_area()
        );
    }
}
