//! Seeded variation of development pairs: a per-pair seed and a turn drawn at random, so
//! that a rule which relies on the benchmarks' shared frame is tested against shapes turned
//! as a user's may be.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A rotation drawn uniformly (a normalised random quaternion), from `seed`.
pub fn random_rotation(seed: u64) -> [[f64; 3]; 3] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let gauss = |rng: &mut ChaCha8Rng| {
        let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let q: [f64; 4] = std::array::from_fn(|_| gauss(&mut rng));
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// FNV-1a of a text: a per-pair seed that does not depend on the run.
pub fn fnv(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// `vertices` turned by `rotation`.
pub fn turned(vertices: &[[f64; 3]], rotation: &[[f64; 3]; 3]) -> Vec<[f64; 3]> {
    vertices
        .iter()
        .map(|p| std::array::from_fn(|i| (0..3).map(|j| rotation[i][j] * p[j]).sum()))
        .collect()
}
