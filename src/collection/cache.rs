//! Eigenbases on disk (`DIR/<key>.basis`), keyed by the SHA-256 of the shape file's bytes,
//! how it was read and the eigensolver's parameters: an interrupted or repeated run, or
//! another process of the same collection, does not solve again. Written to a temporary
//! name and renamed into place, so two processes writing one entry are safe. An entry holds
//! its key and the SHA-256 of its bytes, both checked on loading: a damaged entry, or
//! another shape's entry under this name, is computed again and replaced. The cache is an
//! optimisation: an entry that cannot be stored (a full or read-only folder) is a warning,
//! and the basis is used without it (docs/collections.md).

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
const BASIS_FORMAT: u32 = 3;
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
    /// What went wrong with the cache, if anything (a damaged entry computed again, an
    /// entry that could not be stored); the basis is right either way.
    pub warning: Option<String>,
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
        let mut warning = None;
        if let (Some(file), Some(key)) = (&file, key) {
            match read_basis(file, key, shape.n_vertices()) {
                Ok(Some((basis, seconds))) => {
                    return Ok(TimedBasis {
                        basis,
                        seconds,
                        from_cache: true,
                        warning: None,
                    })
                }
                Ok(None) => {}
                Err(reason) => {
                    warning = Some(format!(
                        "cache entry {} is damaged ({reason}): computed again and replaced",
                        file.display()
                    ))
                }
            }
        }
        let t = Instant::now();
        let basis = Eigenbasis::compute(shape, params, &mut crate::NoProgress)?;
        let seconds = t.elapsed().as_secs_f64();
        if let (Some(file), Some(key)) = (&file, key) {
            if let Err(e) = write_basis(file, key, &basis, seconds) {
                warning = Some(format!(
                    "the eigenbasis could not be stored in the cache ({e}); computed without it"
                ));
            }
        }
        Ok(TimedBasis {
            basis,
            seconds,
            from_cache: false,
            warning,
        })
    }
}

/// Bytes of a basis file before the eigenvalues: magic, format, n, k, seconds, input area
/// (8 bytes each), the key (64 hexadecimal digits).
const HEADER_BYTES: usize = 48 + KEY_BYTES;
const KEY_BYTES: usize = 64;
/// Bytes of the SHA-256 that ends a basis file.
const CHECKSUM_BYTES: usize = 32;

/// Writes a basis atomically (a temporary file renamed into place; removed when either
/// step fails): magic, format, n, k, seconds, input area, the key, eigenvalues, masses,
/// eigenvectors column by column (numbers little endian), then the SHA-256 of all of that.
fn write_basis(path: &Path, key: &str, basis: &Eigenbasis, seconds: f64) -> Result<()> {
    let dir = path.parent().expect("cache files live in a folder");
    std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, e.to_string()))?;
    if key.len() != KEY_BYTES {
        return Err(Error::file(path, "a cache key is 64 hexadecimal digits"));
    }
    let (n, k) = (basis.vectors.nrows(), basis.vectors.ncols());
    let mut bytes = Vec::with_capacity(HEADER_BYTES + 8 * (k + n + n * k) + CHECKSUM_BYTES);
    bytes.extend_from_slice(BASIS_MAGIC);
    bytes.extend_from_slice(&(BASIS_FORMAT as u64).to_le_bytes());
    bytes.extend_from_slice(&(n as u64).to_le_bytes());
    bytes.extend_from_slice(&(k as u64).to_le_bytes());
    bytes.extend_from_slice(&seconds.to_le_bytes());
    bytes.extend_from_slice(&basis.input_area.to_le_bytes());
    bytes.extend_from_slice(key.as_bytes());
    for v in basis.values.iter().chain(&basis.mass) {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    for j in 0..k {
        for &v in basis.vectors.col(j).iter() {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    let checksum = Sha256::digest(&bytes);
    bytes.extend_from_slice(&checksum);
    super::write_whole(path, &bytes)
}

/// Reads a basis written by [`write_basis`] under `key`: None when there is no entry (or
/// it cannot be opened), the reason when it is damaged, of another key, or for another
/// vertex count.
fn read_basis(
    path: &Path,
    key: &str,
    n_expected: usize,
) -> std::result::Result<Option<(Eigenbasis, f64)>, String> {
    let Ok(mut file) = File::open(path) else {
        return Ok(None);
    };
    let mut bytes = Vec::new();
    if let Err(e) = file.read_to_end(&mut bytes) {
        return Err(format!("unreadable: {e}"));
    }
    let word = |i: usize| -> Option<[u8; 8]> { bytes.get(i * 8..i * 8 + 8)?.try_into().ok() };
    let header = (|| Some((word(0)?, word(1)?, word(2)?, word(3)?)))();
    let Some((magic, format, n, k)) = header else {
        return Err("shorter than its header".into());
    };
    if magic != *BASIS_MAGIC {
        return Err("not a basis file".into());
    }
    if u64::from_le_bytes(format) != BASIS_FORMAT as u64 {
        return Err(format!(
            "format {}, not {BASIS_FORMAT}",
            u64::from_le_bytes(format)
        ));
    }
    let (n, k) = (u64::from_le_bytes(n), u64::from_le_bytes(k));
    let expected_len = (k as u128 + n as u128 + n as u128 * k as u128) * 8
        + (HEADER_BYTES + CHECKSUM_BYTES) as u128;
    if bytes.len() as u128 != expected_len {
        return Err(format!(
            "{} bytes, not the {expected_len} of its header",
            bytes.len()
        ));
    }
    let (body, checksum) = bytes.split_at(bytes.len() - CHECKSUM_BYTES);
    if Sha256::digest(body).as_slice() != checksum {
        return Err("its checksum does not match its bytes".into());
    }
    if &body[48..HEADER_BYTES] != key.as_bytes() {
        return Err("it holds another entry's key".into());
    }
    let (n, k) = (n as usize, k as usize);
    if n != n_expected {
        return Err(format!("{n} vertices, not {n_expected}"));
    }
    let f = |i: usize| {
        let at = HEADER_BYTES + 8 * i;
        f64::from_le_bytes(body[at..at + 8].try_into().expect("length checked"))
    };
    let seconds = f64::from_le_bytes(word(4).expect("length checked"));
    let input_area = f64::from_le_bytes(word(5).expect("length checked"));
    let values: Vec<f64> = (0..k).map(f).collect();
    let mass: Vec<f64> = (0..n).map(|i| f(k + i)).collect();
    let start = k + n;
    let vectors = faer::Mat::from_fn(n, k, |i, j| f(start + j * n + i));
    if values.iter().chain(&mass).any(|v| !v.is_finite()) {
        return Err("values that are not finite".into());
    }
    Ok(Some((
        Eigenbasis {
            values,
            vectors,
            mass,
            input_area,
        },
        seconds,
    )))
}
