//! Collections (docs/collections.md): many pairs of a set of shapes, each shape's work done
//! once.
//!
//! The data flow of a batch:
//! - a shape file -> [`Batch::prepare`]: read (and repaired), its proxy when dense
//!   ([`crate::pipeline::multiresolution`]), its eigenbasis from the disk cache or computed and stored
//!   ([`BasisCache`]) -> a [`PreparedShape`] and a [`ShapeRecord`];
//! - two prepared shapes -> [`Batch::match_pair`]: the regions (and the map) of the pair ->
//!   a [`PairRecord`], one line of the batch log ([`ResultLog`]); a map is a binary file
//!   beside the log. A failure is a record with the library's message, never an abort.
//!
//! A pair's regions and map are those [`crate::Correspondence::compute`] (or
//! [`crate::PointwiseCorrespondence::compute`]) gives on the same files and options: the
//! same proxies, the same eigenbases (bit for bit from the cache), the same pair job
//! ([`run_pair`]).
//! The command line's `shapecorr batch` and the Python package's `shapecorr.batch` (locally
//! or on a Dask cluster) both run through here.

pub mod cache;
pub mod folder;
pub mod log;
pub mod pairs;

use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use serde::{Deserialize, Serialize};

pub use cache::{BasisCache, TimedBasis};
pub use folder::{settings_json, OutputFolder};
pub use log::ResultLog;
pub use pairs::{parse_pairs, read_pairs, PairLine};

use crate::options::Options;
use crate::pipeline::multiresolution::working;
use crate::pipeline::{run_pair, PairJob, PairShapes, ReadyShape};
use crate::shape::proxy::{Proxy, ProxyKind};
use crate::spectral::eigen::{EigenParams, Eigenbasis};
use crate::{Error, NoProgress, ReadAs, Repairs, Result, Shape};

/// How shape files are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reading {
    /// As point clouds, even files with faces.
    pub points: bool,
    /// With the default repairs ([`Repairs::default`]); else as given.
    pub repair: bool,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for Reading {
    fn default() -> Self {
        Reading {
            points: false,
            repair: true,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

impl Reading {
    /// The shape in the file at `path`.
    pub fn read(&self, path: &Path) -> Result<Shape> {
        let repairs = if self.repair {
            Repairs::default()
        } else {
            Repairs::none()
        };
        Shape::read_with(path, ReadAs::point_cloud_when(self.points), &repairs)
    }
}

/// What a batch computes for each pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outputs {
    /// The region correspondence ([`crate::Correspondence::compute`]).
    Regions,
    /// The regions and the point-to-point map from B to A
    /// ([`crate::PointwiseCorrespondence::compute`]; its regions are those of `shapecorr p2p`).
    RegionsAndMaps,
}

/// Everything a batch needs besides its shapes and pairs.
#[derive(Debug, Clone)]
pub struct BatchSettings {
    /// The method's options (regions and map).
    pub options: Options,
    /// How the shape files are read.
    pub reading: Reading,
    /// Regions, or regions and maps.
    pub outputs: Outputs,
    /// The folder of the eigenbasis cache, shared by every process of the batch.
    pub cache_dir: PathBuf,
    /// Prepared shapes kept in memory by one process (least recently prepared dropped
    /// first); a dropped shape is read again and its eigenbasis loaded from the cache.
    pub memory_bytes: usize,
}

/// Default [`BatchSettings::memory_bytes`]: 2 GiB, 350 FAUST-sized shapes with 100
/// eigenpairs.
pub const DEFAULT_MEMORY_BYTES: usize = 2 << 30;

/// A shape with its per-shape work done: what every pair it is in starts from.
#[derive(Debug)]
pub struct PreparedShape {
    /// The shape as read from its file.
    pub shape: Shape,
    /// Its proxy when it is dense ([`crate::pipeline::multiresolution`]).
    pub proxy: Option<Proxy>,
    /// The eigenbasis of the working shape (the proxy's, or the shape's).
    pub basis: Eigenbasis,
    /// Its cache key.
    pub basis_key: String,
    /// Seconds the eigenbasis took when it was computed.
    pub eigenbasis_s: f64,
}

impl PreparedShape {
    /// The shape the pipeline runs on: the proxy, or the shape itself.
    pub fn working(&self) -> &Shape {
        working(&self.shape, &self.proxy)
    }

    /// The shape as the pair job takes it.
    pub fn ready(&self) -> ReadyShape<'_> {
        ReadyShape {
            shape: &self.shape,
            proxy: self.proxy.as_ref(),
            basis: &self.basis,
        }
    }

    fn bytes(&self) -> usize {
        let basis = self.basis.vectors.nrows() * (self.basis.vectors.ncols() + 1);
        8 * basis + 64 * (self.shape.n_vertices() + self.working().n_vertices())
    }
}

/// One line of a batch's shape log: a shape's per-shape work.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ShapeRecord {
    /// The shape's name in the batch.
    pub name: String,
    /// Its file.
    pub path: String,
    /// Whether it was read and prepared.
    pub ok: bool,
    /// Why not, in the library's words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Vertices of the file.
    pub vertices: usize,
    /// Vertices the pipeline runs on (a proxy's, or the same).
    pub working_vertices: usize,
    /// The cache key of its eigenbasis.
    pub key: String,
    /// Whether its eigenbasis was computed now (false: loaded from the cache).
    pub computed: bool,
    /// Seconds its eigenbasis took when it was computed.
    pub eigenbasis_s: f64,
    /// Seconds of this preparation (reading, proxy, eigenbasis or its loading).
    pub seconds: f64,
    /// What went wrong with the cache (a damaged entry computed again, an entry that could
    /// not be stored); the shape's work is right either way.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
}

/// One line of a batch's pair log: the result of a pair, or why there is none.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PairRecord {
    /// Shape A's name (the map goes from B to A).
    pub a: String,
    /// Shape B's name.
    pub b: String,
    /// Whether the pair was computed.
    pub ok: bool,
    /// Why not, in the library's words (naming the shape when it was a shape's failure).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The number of joint clusters chosen.
    pub k: usize,
    /// Regions of A.
    pub n_regions_a: usize,
    /// Regions of B.
    pub n_regions_b: usize,
    /// The region of every vertex of A (indexed by the file's vertices).
    pub regions_a: Vec<u32>,
    /// The region of every vertex of B.
    pub regions_b: Vec<u32>,
    /// Symmetric matches (region of A, region of B).
    pub matches: Vec<[u32; 2]>,
    /// One-to-one matches.
    pub matches_one_to_one: Vec<[u32; 2]>,
    /// The answer's confidence in [0, 1] (None when nothing was verified).
    pub confidence: Option<f64>,
    /// Whether the confidence is below [`crate::maps::hypotheses::DOUBTFUL_BELOW`].
    pub doubtful: bool,
    /// The map's file, relative to the log's folder: a vertex of A for every vertex of B,
    /// little-endian u32 ([`write_map`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map: Option<String>,
    /// Seconds of the pair's own work (the eigenbases were the shapes').
    pub seconds: f64,
    /// Seconds per stage: `descriptors`, `segmentation`, `matching`, `one_to_one`, `proxies`
    /// and, with maps, `map` (the functional map, its refinement and verification).
    pub stages: BTreeMap<String, f64>,
}

/// A shape of a batch as [`Batch::prepare`] left it: prepared, or the reason it is not.
pub type Prepared = std::result::Result<Arc<PreparedShape>, String>;

/// Runs the per-shape and per-pair jobs of a collection; one per process, shared by its
/// threads.
#[derive(Debug)]
pub struct Batch {
    settings: BatchSettings,
    cache: BasisCache,
    eigen: EigenParams,
    /// Prepared shapes by path, the most recently prepared last.
    kept: Mutex<VecDeque<(PathBuf, Arc<PreparedShape>)>>,
}

impl Batch {
    /// A batch with these settings (checked here, before any work). Landmarks name vertices
    /// of one pair, so a batch with landmarks is [`crate::Error::InvalidParameter`].
    pub fn new(settings: BatchSettings) -> Result<Batch> {
        settings.options.validate()?;
        let params = &settings.options.params;
        if !params.landmarks.is_empty() {
            return Err(crate::Error::InvalidParameter {
                name: "landmarks",
                reason: format!(
                    "{} given to a batch: landmarks name vertices of one pair; give them to \
                     that pair's match instead",
                    params.landmarks.len()
                ),
            });
        }
        let job = PairJob {
            params,
            map: match settings.outputs {
                Outputs::Regions => None,
                Outputs::RegionsAndMaps => Some(settings.options.pointwise()),
            },
        };
        let eigen = job.eigen_params();
        // A folder that cannot be made is reported by each shape's record (the cache is an
        // optimisation: the batch runs without it).
        let _ = std::fs::create_dir_all(&settings.cache_dir);
        Ok(Batch {
            cache: BasisCache {
                dir: Some(settings.cache_dir.clone()),
            },
            eigen,
            settings,
            kept: Mutex::new(VecDeque::new()),
        })
    }

    /// The settings.
    pub fn settings(&self) -> &BatchSettings {
        &self.settings
    }

    /// The shape at `path` with its per-shape work done (kept in memory, else read and its
    /// eigenbasis loaded from the cache, else computed and stored), and the record of what
    /// was done.
    pub fn prepare(&self, name: &str, path: &Path) -> (Prepared, ShapeRecord) {
        let started = Instant::now();
        let mut record = ShapeRecord {
            name: name.to_string(),
            path: path.display().to_string(),
            ..Default::default()
        };
        if let Some(shape) = self.kept(path) {
            record.ok = true;
            record.vertices = shape.shape.n_vertices();
            record.working_vertices = shape.working().n_vertices();
            record.key = shape.basis_key.clone();
            record.eigenbasis_s = shape.eigenbasis_s;
            return (Ok(shape), record);
        }
        let prepared = self.prepare_file(path, &mut record).map(Arc::new);
        record.seconds = started.elapsed().as_secs_f64();
        match prepared {
            Ok(shape) => {
                record.ok = true;
                self.keep(path, &shape);
                (Ok(shape), record)
            }
            Err(e) => {
                let reason = e.to_string();
                record.error = Some(reason.clone());
                (Err(reason), record)
            }
        }
    }

    fn prepare_file(&self, path: &Path, record: &mut ShapeRecord) -> Result<PreparedShape> {
        let shape = self.settings.reading.read(path)?;
        record.vertices = shape.n_vertices();
        let multiresolution = &self.settings.options.params.multiresolution;
        crate::spectral::eigen::check_max_vertices(&shape, &self.eigen)?;
        let proxy = multiresolution.proxy(&shape)?;
        let working = working(&shape, &proxy);
        record.working_vertices = working.n_vertices();
        // The working shape's recipe: its basis in the cache is that shape's.
        let reading = match proxy.as_ref().map(|p| p.kind) {
            None => format!("{:?}|proxy=0", self.settings.reading),
            Some(ProxyKind::Smoothed) => format!("{:?}|proxy=0", self.settings.reading),
            Some(ProxyKind::Simplified) => format!(
                "{:?}|proxy={}",
                self.settings.reading, multiresolution.proxy_vertices
            ),
            Some(ProxyKind::Refined) => format!(
                "{:?}|refined={}",
                self.settings.reading, multiresolution.refine_below
            ),
        } + if proxy.as_ref().is_some_and(|p| p.smoothed) {
            "|smoothed"
        } else {
            ""
        };
        record.key = BasisCache::file_key(path, &reading, &self.eigen)?;
        let timed = self
            .cache
            .basis_for_key(Some(&record.key), working, &self.eigen)?;
        record.computed = !timed.from_cache;
        record.warning = timed.warning;
        record.eigenbasis_s = timed.seconds;
        Ok(PreparedShape {
            shape,
            proxy,
            basis: timed.basis,
            basis_key: record.key.clone(),
            eigenbasis_s: timed.seconds,
        })
    }

    fn kept(&self, path: &Path) -> Option<Arc<PreparedShape>> {
        let kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.iter().find(|(p, _)| p == path).map(|(_, s)| s.clone())
    }

    fn keep(&self, path: &Path, shape: &Arc<PreparedShape>) {
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.retain(|(p, _)| p != path);
        kept.push_back((path.to_path_buf(), shape.clone()));
        let mut total: usize = kept.iter().map(|(_, s)| s.bytes()).sum();
        while total > self.settings.memory_bytes && kept.len() > 1 {
            if let Some((_, dropped)) = kept.pop_front() {
                total -= dropped.bytes();
            }
        }
    }

    /// The pair (`a`, `b`): its regions (and map, written under `out_dir/maps/`) as a log
    /// record. A failure, of the pair or of one of its shapes, is a record with the reason.
    pub fn match_pair(
        &self,
        (name_a, a): (&str, &Prepared),
        (name_b, b): (&str, &Prepared),
        out_dir: &Path,
    ) -> PairRecord {
        let started = Instant::now();
        let mut record = PairRecord {
            a: name_a.to_string(),
            b: name_b.to_string(),
            ..Default::default()
        };
        let outcome = match (a, b) {
            (Err(e), _) => Err(format!("shape {name_a}: {e}")),
            (_, Err(e)) => Err(format!("shape {name_b}: {e}")),
            (Ok(a), Ok(b)) => self
                .compute_pair(a, b, &mut record, out_dir)
                .map_err(|e| e.to_string()),
        };
        match outcome {
            Ok(()) => record.ok = true,
            Err(reason) => {
                record = PairRecord {
                    a: record.a,
                    b: record.b,
                    error: Some(reason),
                    ..Default::default()
                }
            }
        }
        record.seconds = started.elapsed().as_secs_f64();
        record
    }

    fn compute_pair(
        &self,
        a: &PreparedShape,
        b: &PreparedShape,
        record: &mut PairRecord,
        out_dir: &Path,
    ) -> Result<()> {
        let options = &self.settings.options;
        let job = PairJob {
            params: &options.params,
            map: match self.settings.outputs {
                Outputs::Regions => None,
                Outputs::RegionsAndMaps => Some(options.pointwise()),
            },
        };
        let pair = run_pair(
            PairShapes::Ready(a.ready(), b.ready()),
            job,
            &mut NoProgress,
        )?;
        let regions = pair.regions;
        let map = pair.map.map(|map| {
            record
                .stages
                .insert("map".into(), map.timings.fmap + map.timings.refinement);
            map.p2p_ba
        });
        let t = &regions.timings;
        for (stage, seconds) in [
            ("descriptors", t.descriptors),
            ("segmentation", t.segmentation),
            ("matching", t.matching),
            ("one_to_one", t.one_to_one),
            ("proxies", t.proxies),
        ] {
            record.stages.insert(stage.into(), seconds);
        }
        record.k = regions.k;
        record.n_regions_a = regions.graph_a.n_nodes();
        record.n_regions_b = regions.graph_b.n_nodes();
        record.regions_a = regions.graph_a.labels;
        record.regions_b = regions.graph_b.labels;
        record.matches = regions.matches.iter().map(|&(i, j)| [i, j]).collect();
        record.matches_one_to_one = regions
            .matches_one_to_one
            .iter()
            .map(|&(i, j)| [i, j])
            .collect();
        record.confidence = regions.verdict.as_ref().map(|v| v.confidence);
        record.doubtful = regions.verdict.as_ref().is_some_and(|v| v.doubtful());
        if let Some(map) = map {
            let file = map_file(&record.a, &record.b);
            write_map(&out_dir.join(&file), &map)?;
            record.map = Some(file);
        }
        Ok(())
    }
}

/// Where the map of pair (`a`, `b`) is written, relative to the log's folder:
/// `maps/A--B.u32` with each name escaped ([`escape_name`]), so that distinct pairs never
/// share a file.
pub fn map_file(a: &str, b: &str) -> String {
    format!("maps/{}--{}.u32", escape_name(a), escape_name(b))
}

/// A shape name as a part of a file name, one-to-one: `%` and the characters a file name
/// cannot hold (`/`, `\`, NUL, control characters) are written `%XX` (their UTF-8 bytes
/// in hexadecimal), and so is a `-` next to another `-` or at either end. An escaped name
/// then never holds `--` nor starts or ends with `-`, so `A--B` splits one way only.
pub fn escape_name(name: &str) -> String {
    let chars: Vec<char> = name.chars().collect();
    let mut escaped = String::with_capacity(name.len());
    for (i, &c) in chars.iter().enumerate() {
        let lone_dash =
            c == '-' && i > 0 && i + 1 < chars.len() && chars[i - 1] != '-' && chars[i + 1] != '-';
        if matches!(c, '%' | '/' | '\\') || c.is_control() || (c == '-' && !lone_dash) {
            let mut utf8 = [0u8; 4];
            for byte in c.encode_utf8(&mut utf8).bytes() {
                escaped.push_str(&format!("%{byte:02X}"));
            }
        } else {
            escaped.push(c);
        }
    }
    escaped
}

/// Writes a map as little-endian u32, one per vertex of B, atomically (a temporary file
/// renamed into place; removed when either step fails).
pub fn write_map(path: &Path, map: &[u32]) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, e.to_string()))?;
    }
    let bytes: Vec<u8> = map.iter().flat_map(|v| v.to_le_bytes()).collect();
    write_whole(path, &bytes)
}

/// Writes `bytes` to `path` whole or not at all: a temporary file next to it (named by
/// process and thread) renamed into place, removed when either step fails.
pub(crate) fn write_whole(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension(format!("tmp{}-{}", std::process::id(), thread_number()));
    let written = std::fs::write(&tmp, bytes)
        .map_err(|e| Error::file(&tmp, e.to_string()))
        .and_then(|()| std::fs::rename(&tmp, path).map_err(|e| Error::file(path, e.to_string())));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// Reads a map written by [`write_map`].
pub fn read_map(path: &Path) -> Result<Vec<u32>> {
    let bytes = std::fs::read(path).map_err(|e| Error::file(path, e.to_string()))?;
    if bytes.len() % 4 != 0 {
        return Err(Error::file(path, "not a map: length not a multiple of 4"));
    }
    Ok(bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// A number for this thread, for temporary file names unique across threads.
pub(crate) fn thread_number() -> u64 {
    use std::hash::{Hash, Hasher};
    let mut hash = std::collections::hash_map::DefaultHasher::new();
    std::thread::current().id().hash(&mut hash);
    hash.finish()
}
