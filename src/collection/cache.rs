//! Eigenbases on disk (`DIR/<key>.basis`), keyed by the SHA-256 of the shape file's bytes,
//! how it was read and the eigensolver's parameters: an interrupted or repeated run, or
//! another process of the same collection, does not solve again. Written to a temporary
//! name and renamed into place, so two processes writing one entry are safe.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::time::Instant;

use sha2::{Digest, Sha256};

use crate::shape::Shape;
use crate::spectral::eigen::{EigenParams, Eigenbasis};
use crate::{Error, Result};

/// Version of the cache file format and of the eigensolver's output: bump it when either
/// changes, so old cache files are not used.
const BASIS_FORMAT: u32 = 2;
const BASIS_MAGIC: &[u8; 8] = b"SCBASIS\0";

/// Eigenbases stored on disk (`DIR/<key>.basis`); `None` = no disk cache.
#[derive(Debug, Clone, Default)]
pub struct BasisCache {
    /// The cache's folder.
    pub dir: Option<PathBuf>,
}

/// An eigenbasis with the seconds its computation took (measured when it was computed, also
/// when it now comes from the disk cache) and whether it came from the cache.
#[derive(Debug, Clone)]
pub struct TimedBasis {
    /// The eigenbasis.
    pub basis: Eigenbasis,
    /// Seconds its computation took.
    pub seconds: f64,
    /// Whether it came from the cache.
    pub from_cache: bool,
}

impl BasisCache {
    /// The cache key: SHA-256 over the file's bytes, `reading` (how the file became the shape
    /// the basis is of: mesh or points, repairs, proxy), the solver parameters that change
    /// the result (not the thread count), [`BASIS_FORMAT`] and the library's version.
    pub fn key(file_bytes: &[u8], reading: &str, params: &EigenParams) -> String {
        let mut hash = Sha256::new();
        hash.update(file_bytes);
        hash.update(
            format!(
                "|{reading}|k={}|shift={:e}|tol={:e}|block={}|seed={}|format={BASIS_FORMAT}|v={}",
                params.n_eigenpairs,
                params.shift,
                params.tolerance,
                params.block_size,
                params.seed,
                env!("CARGO_PKG_VERSION")
            )
            .as_bytes(),
        );
        hash.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// [`BasisCache::key`] of the file at `path`.
    pub fn file_key(path: &Path, reading: &str, params: &EigenParams) -> Result<String> {
        let bytes = std::fs::read(path).map_err(|e| Error::file(path, e.to_string()))?;
        Ok(Self::key(&bytes, reading, params))
    }

    /// The eigenbasis of `shape` (read from `path` as `reading` says): from the cache when
    /// present and valid, else computed and stored. A damaged cache file is recomputed and
    /// replaced.
    pub fn basis(
        &self,
        path: &Path,
        shape: &Shape,
        reading: &str,
        params: &EigenParams,
    ) -> Result<TimedBasis> {
        let key = match &self.dir {
            Some(_) => Some(Self::file_key(path, reading, params)?),
            None => None,
        };
        self.basis_for_key(key.as_deref(), shape, params)
    }

    /// The eigenbasis of `shape` stored under `key` (None: not cached), else computed and
    /// stored under it.
    pub fn basis_for_key(
        &self,
        key: Option<&str>,
        shape: &Shape,
        params: &EigenParams,
    ) -> Result<TimedBasis> {
        let file = match (&self.dir, key) {
            (Some(dir), Some(key)) => Some(dir.join(format!("{key}.basis"))),
            _ => None,
        };
        if let Some(file) = &file {
            if let Some((basis, seconds)) = read_basis(file, shape.n_vertices()) {
                return Ok(TimedBasis {
                    basis,
                    seconds,
                    from_cache: true,
                });
            }
        }
        let t = Instant::now();
        let basis = Eigenbasis::compute(shape, params, &mut crate::NoProgress)?;
        let seconds = t.elapsed().as_secs_f64();
        if let Some(file) = &file {
            write_basis(file, &basis, seconds)?;
        }
        Ok(TimedBasis {
            basis,
            seconds,
            from_cache: false,
        })
    }
}

/// Writes a basis atomically (a temporary file renamed into place): magic, format, n, k,
/// seconds, input area, eigenvalues, masses, eigenvectors column by column, all little endian.
fn write_basis(path: &Path, basis: &Eigenbasis, seconds: f64) -> Result<()> {
    let dir = path.parent().expect("cache files live in a folder");
    std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, e.to_string()))?;
    let (n, k) = (basis.vectors.nrows(), basis.vectors.ncols());
    let mut bytes = Vec::with_capacity(48 + 8 * (k + n + n * k));
    bytes.extend_from_slice(BASIS_MAGIC);
    bytes.extend_from_slice(&(BASIS_FORMAT as u64).to_le_bytes());
    bytes.extend_from_slice(&(n as u64).to_le_bytes());
    bytes.extend_from_slice(&(k as u64).to_le_bytes());
    bytes.extend_from_slice(&seconds.to_le_bytes());
    bytes.extend_from_slice(&basis.input_area.to_le_bytes());
    for v in basis.values.iter().chain(&basis.mass) {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    for j in 0..k {
        for &v in basis.vectors.col(j).iter() {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    let tmp = path.with_extension(format!(
        "tmp{}-{}",
        std::process::id(),
        super::thread_number()
    ));
    std::fs::write(&tmp, &bytes).map_err(|e| Error::file(&tmp, e.to_string()))?;
    std::fs::rename(&tmp, path).map_err(|e| Error::file(path, e.to_string()))
}

/// Reads a basis written by [`write_basis`]; None when missing, damaged or for another
/// vertex count.
fn read_basis(path: &Path, n_expected: usize) -> Option<(Eigenbasis, f64)> {
    let mut bytes = Vec::new();
    File::open(path).ok()?.read_to_end(&mut bytes).ok()?;
    let word = |i: usize| -> Option<[u8; 8]> { bytes.get(i * 8..i * 8 + 8)?.try_into().ok() };
    if word(0)? != *BASIS_MAGIC || u64::from_le_bytes(word(1)?) != BASIS_FORMAT as u64 {
        return None;
    }
    let n = u64::from_le_bytes(word(2)?) as usize;
    let k = u64::from_le_bytes(word(3)?) as usize;
    if n != n_expected || bytes.len() != 8 * (6 + k + n + n * k) {
        return None;
    }
    let f = |i: usize| f64::from_le_bytes(word(i).expect("length checked"));
    let seconds = f(4);
    let input_area = f(5);
    let values: Vec<f64> = (0..k).map(|i| f(6 + i)).collect();
    let mass: Vec<f64> = (0..n).map(|i| f(6 + k + i)).collect();
    let start = 6 + k + n;
    let vectors = faer::Mat::from_fn(n, k, |i, j| f(start + j * n + i));
    if values.iter().chain(&mass).any(|v| !v.is_finite()) {
        return None;
    }
    Some((
        Eigenbasis {
            values,
            vectors,
            mass,
            input_area,
        },
        seconds,
    ))
}
