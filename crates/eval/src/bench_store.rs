//! What long benchmark runs keep between pairs and between runs:
//! - [`ShapeStore`]: each shape of a dataset read once, with its eigenbasis and geodesic
//!   solver made once;
//! - [`BasisCache`]: eigenbases on disk, keyed by the SHA-256 of the shape file's bytes and
//!   the eigensolver's parameters, so an interrupted or repeated run does not solve again;
//! - [`ResultLog`]: results appended to a JSON-lines file as each finishes, read back on the
//!   next run so finished work is skipped;
//! - [`ProgressBar`]: a bar with an ETA on a terminal, a line per step otherwise.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::de::DeserializeOwned;
use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::datasets::Dataset;
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::shape::Shape;
use shapecorr::spectral::eigen::{EigenParams, Eigenbasis};
use shapecorr::ReadAs;
use shapecorr::{Error, Result};

/// Version of the cache file format and of the eigensolver's output: bump it when either
/// changes, so old cache files are not used.
const BASIS_FORMAT: u32 = 1;
const BASIS_MAGIC: &[u8; 8] = b"SCBASIS\0";

/// Eigenbases stored on disk (`DIR/<key>.basis`); `None` = no disk cache.
#[derive(Debug, Clone, Default)]
pub struct BasisCache {
    pub dir: Option<PathBuf>,
}

/// An eigenbasis with the seconds its computation took (measured when it was computed, also
/// when it now comes from the disk cache) and whether it came from the cache.
#[derive(Debug, Clone)]
pub struct TimedBasis {
    pub basis: Eigenbasis,
    pub seconds: f64,
    pub from_cache: bool,
}

impl BasisCache {
    /// The cache key: SHA-256 over the file's bytes, the way it is read (mesh or points),
    /// the solver parameters that change the result (not the thread count) and
    /// [`BASIS_FORMAT`].
    pub fn key(file_bytes: &[u8], as_points: bool, params: &EigenParams) -> String {
        let mut hash = Sha256::new();
        hash.update(file_bytes);
        hash.update(
            format!(
                "|points={as_points}|k={}|shift={:e}|tol={:e}|block={}|seed={}|format={BASIS_FORMAT}|v={}",
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

    /// The eigenbasis of `shape` (read from `path`): from the cache when present and valid,
    /// else computed and stored. A damaged cache file is recomputed and replaced.
    pub fn basis(
        &self,
        path: &Path,
        shape: &Shape,
        as_points: bool,
        params: &EigenParams,
    ) -> Result<TimedBasis> {
        let file = match &self.dir {
            Some(dir) => {
                let bytes = std::fs::read(path).map_err(|e| Error::file(path, e.to_string()))?;
                Some(dir.join(format!("{}.basis", Self::key(&bytes, as_points, params))))
            }
            None => None,
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
        let basis = Eigenbasis::compute(shape, params)?;
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
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
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

/// A shape of a dataset with what has been made for it so far.
pub struct StoredShape {
    pub shape: Shape,
    pub path: PathBuf,
    pub basis: Option<TimedBasis>,
    pub heat: Option<HeatGeodesics>,
}

/// The shapes of one dataset, each read once; eigenbases (with `eigen`) and heat-method
/// geodesic solvers made on demand, eigenbases through `cache`.
pub struct ShapeStore {
    pub dataset: Dataset,
    pub eigen: EigenParams,
    pub cache: BasisCache,
    shapes: BTreeMap<String, StoredShape>,
}

impl ShapeStore {
    pub fn new(dataset: Dataset, eigen: EigenParams, cache: BasisCache) -> ShapeStore {
        ShapeStore {
            dataset,
            eigen,
            cache,
            shapes: BTreeMap::new(),
        }
    }

    /// Reads shape `name` if not read yet, and makes its eigenbasis and geodesic solver when
    /// asked for and not made yet.
    pub fn load(&mut self, name: &str, basis: bool, heat: bool) -> Result<&StoredShape> {
        if !self.shapes.contains_key(name) {
            let path = self.dataset.shape_path(name)?;
            let shape = Shape::read(&path, ReadAs::Auto)?;
            self.shapes.insert(
                name.to_string(),
                StoredShape {
                    shape,
                    path,
                    basis: None,
                    heat: None,
                },
            );
        }
        let entry = self.shapes.get_mut(name).expect("inserted above");
        if basis && entry.basis.is_none() {
            entry.basis = Some(
                self.cache
                    .basis(&entry.path, &entry.shape, false, &self.eigen)?,
            );
        }
        if heat && entry.heat.is_none() {
            entry.heat = Some(HeatGeodesics::new(&entry.shape)?);
        }
        Ok(entry)
    }

    /// A shape loaded before (panics otherwise: call [`ShapeStore::load`] first).
    pub fn get(&self, name: &str) -> &StoredShape {
        &self.shapes[name]
    }

    /// The eigenbasis of a shape loaded with one.
    pub fn basis(&self, name: &str) -> &TimedBasis {
        self.shapes[name]
            .basis
            .as_ref()
            .expect("load(name, basis = true) first")
    }

    /// Forgets every shape but `keep` (memory: a 52K-vertex shape with 100 eigenpairs and a
    /// geodesic solver takes about 100 MB).
    pub fn retain(&mut self, keep: &[&str]) {
        self.shapes.retain(|name, _| keep.contains(&name.as_str()));
    }
}

/// Results of one kind appended to a JSON-lines file as they finish.
pub struct ResultLog {
    path: PathBuf,
    file: File,
}

impl ResultLog {
    /// Opens (creating if needed) the log at `path` and returns the results already in it.
    /// A last line cut short by an interruption is dropped, and the file truncated to the
    /// lines that were whole; an unreadable line elsewhere is an error naming it.
    pub fn open<T: DeserializeOwned>(path: &Path) -> Result<(ResultLog, Vec<T>)> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, e.to_string()))?;
        }
        let mut results = Vec::new();
        let mut whole_bytes = 0u64;
        if path.exists() {
            let file = File::open(path).map_err(|e| Error::file(path, e.to_string()))?;
            let lines: Vec<String> = BufReader::new(file)
                .split(b'\n')
                .map(|l| l.map(|l| String::from_utf8_lossy(&l).into_owned()))
                .collect::<std::io::Result<_>>()
                .map_err(|e| Error::file(path, e.to_string()))?;
            let text_len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
            // Only the last line can be cut short (no newline, or not whole JSON).
            for (i, line) in lines.iter().enumerate() {
                let end = whole_bytes + line.len() as u64 + 1;
                let last = i + 1 == lines.len();
                match serde_json::from_str::<T>(line) {
                    Ok(r) if end <= text_len => {
                        results.push(r);
                        whole_bytes = end;
                    }
                    Err(e) if !last => {
                        return Err(Error::file(
                            path,
                            format!("line {}: {e} (delete the file to start over)", i + 1),
                        ))
                    }
                    _ => break,
                }
            }
        }
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(|e| Error::file(path, e.to_string()))?;
        file.set_len(whole_bytes)
            .map_err(|e| Error::file(path, e.to_string()))?;
        Ok((
            ResultLog {
                path: path.to_path_buf(),
                file,
            },
            results,
        ))
    }

    /// Appends one result as a line and flushes it to the file.
    pub fn append<T: Serialize>(&mut self, result: &T) -> Result<()> {
        let mut line =
            serde_json::to_string(result).map_err(|e| Error::file(&self.path, e.to_string()))?;
        line.push('\n');
        self.file
            .write_all(line.as_bytes())
            .and_then(|_| self.file.flush())
            .map_err(|e| Error::file(&self.path, e.to_string()))
    }
}

/// Progress of a long run: an indicatif bar with the ETA on a terminal; otherwise (CI logs,
/// pipes) one line per finished step with the same figures.
pub struct ProgressBar {
    bar: Option<indicatif::ProgressBar>,
    label: String,
    total: u64,
    done: u64,
    /// Steps done by an earlier run (not counted in the ETA's time per step).
    already: u64,
    start: Instant,
}

impl ProgressBar {
    /// A bar for `total` steps of which `already` were done in an earlier run.
    pub fn new(label: &str, total: usize, already: usize) -> ProgressBar {
        use std::io::IsTerminal;
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = indicatif::ProgressBar::new(total as u64);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "{prefix} [{bar:30}] {pos}/{len} {elapsed} (ETA {eta}) {msg}",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar.set_prefix(label.to_string());
            bar.set_position(already as u64);
            bar.reset_eta();
            bar
        });
        ProgressBar {
            bar,
            label: label.to_string(),
            total: total as u64,
            done: already as u64,
            already: already as u64,
            start: Instant::now(),
        }
    }

    /// One more step done, `message` describing it.
    pub fn step(&mut self, message: &str) {
        self.done += 1;
        match &self.bar {
            Some(bar) => {
                bar.set_message(message.to_string());
                bar.inc(1);
            }
            None => {
                let computed = self.done.saturating_sub(self.already).max(1) as f64;
                let per_step = self.start.elapsed().as_secs_f64() / computed;
                let eta = per_step * (self.total - self.done) as f64;
                eprintln!(
                    "{} [{}/{}] {message} ({:.0} s elapsed, ETA {:.0} s)",
                    self.label,
                    self.done,
                    self.total,
                    self.start.elapsed().as_secs_f64(),
                    eta
                );
            }
        }
    }

    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish();
        }
    }
}
