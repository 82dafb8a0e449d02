//! `shapecorr batch`: many pairs of a shape collection, each shape's eigenbasis computed once
//! and cached on disk, pairs in parallel, every result appended to a resumable log
//! (the library's [`shapecorr::collection`]; docs/collections.md).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use shapecorr::collection::{
    read_pairs, Batch, BatchSettings, OutputFolder, Outputs, PairRecord, Prepared, Reading,
    ResultLog, ShapeRecord, DEFAULT_MEMORY_BYTES,
};
use shapecorr::Error;
use shapecorr_eval::bench_store::ProgressBar;

use crate::options::PointwiseOptions;
use crate::output::QUIET;

/// Shape files a folder contributes.
const SHAPE_EXTENSIONS: [&str; 3] = ["ply", "off", "obj"];

#[derive(clap::Args)]
pub struct BatchArgs {
    /// Shape files and folders (a folder: every .ply, .off and .obj file in it).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Output folder: pairs.jsonl (a line per pair), shapes.jsonl (a line per shape
    /// prepared), maps/ (with --maps), batch.json (the settings), batch.lock (held while a
    /// run uses the folder) and cache/ (eigenbases, unless --cache). Running again with the
    /// same folder and settings resumes: finished pairs are skipped.
    #[arg(long)]
    out: PathBuf,
    /// Which pairs: `all` (every unordered pair once, A before B in input order),
    /// `one-to-many:NAME` (the template NAME as A against every other shape: consistent
    /// labels), or a pair file (`A<TAB>B[<TAB>CATEGORY]` per line, names may hold spaces; a
    /// line without a tab is split at spaces; `#` comments; names as in shapes.jsonl or file
    /// stems).
    #[arg(long, default_value = "all")]
    pairs: String,
    /// Region correspondences (the default; as `shapecorr match`).
    #[arg(long)]
    regions: bool,
    /// Point-to-point maps too (as `shapecorr p2p`; its regions come with it), each written
    /// to maps/A--B.u32 (names escaped, docs/collections.md): a vertex of A for every
    /// vertex of B, little-endian u32.
    #[arg(long)]
    maps: bool,
    /// Eigenbasis cache folder (default OUT/cache); several runs and processes may share it.
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Pairs computed at once (0: one per core). Results do not depend on it.
    #[arg(long, default_value_t = 0, allow_negative_numbers = true, value_parser = parse_jobs)]
    jobs: usize,
    /// Compute again the pairs a previous run recorded as failed.
    #[arg(long)]
    retry_failed: bool,
    /// Treat every file as a point cloud even if it has faces.
    #[arg(long)]
    points: bool,
    /// Use the shapes as given (no repairs).
    #[arg(long)]
    no_repair: bool,
    #[command(flatten)]
    options: PointwiseOptions,
}

/// A shape of the batch: its name (unique) and file.
struct Input {
    name: String,
    path: PathBuf,
}

impl BatchArgs {
    pub fn run(&self) -> Result<(), Error> {
        let (options, _) = self.options.pointwise()?;
        let outputs = if self.maps {
            Outputs::RegionsAndMaps
        } else {
            Outputs::Regions
        };
        let inputs = self.inputs()?;
        let pairs = self.pairs(&inputs)?;
        let settings = BatchSettings {
            options,
            reading: Reading {
                points: self.points,
                repair: !self.no_repair,
                ..Default::default()
            },
            outputs,
            cache_dir: self.cache.clone().unwrap_or_else(|| self.out.join("cache")),
            memory_bytes: DEFAULT_MEMORY_BYTES,
        };
        // Held until the run ends: a second run on this folder is refused.
        let _folder = OutputFolder::open(&self.out, &settings)?;
        let batch = Batch::new(settings)?;

        let (mut log, done) = ResultLog::open::<PairRecord>(&self.out.join("pairs.jsonl"))?;
        let wanted: BTreeSet<(&str, &str)> = pairs
            .iter()
            .map(|&(i, j)| (inputs[i].name.as_str(), inputs[j].name.as_str()))
            .collect();
        // The latest record of each pair of this run (a pair retried later has two).
        let mut earlier: BTreeMap<(String, String), bool> = BTreeMap::new();
        for r in done
            .iter()
            .filter(|r| wanted.contains(&(r.a.as_str(), r.b.as_str())))
        {
            earlier.insert((r.a.clone(), r.b.clone()), r.ok);
        }
        let finished: BTreeSet<(String, String)> = earlier
            .iter()
            .filter(|(_, &ok)| ok || !self.retry_failed)
            .map(|(pair, _)| pair.clone())
            .collect();
        let failed_before = earlier
            .iter()
            .filter(|(pair, &ok)| !ok && finished.contains(pair))
            .count();
        let todo: Vec<(usize, usize)> = pairs
            .into_iter()
            .filter(|&(i, j)| !finished.contains(&(inputs[i].name.clone(), inputs[j].name.clone())))
            .collect();
        let total = todo.len() + finished.len();
        let jobs = if self.jobs == 0 {
            rayon::current_num_threads()
        } else {
            self.jobs
        };
        let started = Instant::now();

        // Per-shape work first, once for every shape a remaining pair needs.
        let needed: Vec<usize> = todo
            .iter()
            .flat_map(|&(i, j)| [i, j])
            .collect::<BTreeSet<_>>()
            .into_iter()
            .collect();
        let (mut shape_log, _) = ResultLog::open::<ShapeRecord>(&self.out.join("shapes.jsonl"))?;
        let shape_bar = Mutex::new(self.bar("shapes", needed.len(), 0));
        let mut prepared: BTreeMap<usize, Prepared> = BTreeMap::new();
        let records = parallel(&needed, jobs, |&i| {
            let (shape, record) = batch.prepare(&inputs[i].name, &inputs[i].path);
            step(&shape_bar, &record.name);
            (i, shape, record)
        });
        let (mut computed, mut unusable) = (0, 0);
        for (i, shape, record) in records {
            if let Some(warning) = &record.warning {
                crate::output::errln!("shapecorr: warning: shape {}: {warning}", record.name);
            }
            computed += usize::from(record.computed);
            unusable += usize::from(!record.ok);
            shape_log.append(&record)?;
            prepared.insert(i, shape);
        }
        finish(&shape_bar);
        let shape_seconds = started.elapsed().as_secs_f64();

        // Then the pairs, each appended to the log as it finishes.
        let log_lock = Mutex::new((&mut log, 0usize, None::<Error>));
        let pair_bar = Mutex::new(self.bar("pairs", total, finished.len()));
        parallel(&todo, jobs, |&(i, j)| {
            let record = batch.match_pair(
                (&inputs[i].name, &prepared[&i]),
                (&inputs[j].name, &prepared[&j]),
                &self.out,
            );
            let mut guard = log_lock.lock().unwrap_or_else(|e| e.into_inner());
            let (log, failed, error) = &mut *guard;
            *failed += usize::from(!record.ok);
            if let Err(e) = log.append(&record) {
                error.get_or_insert(e);
            }
            drop(guard);
            step(&pair_bar, &format!("{} - {}", record.a, record.b));
        });
        finish(&pair_bar);
        let (_, failed, error) = log_lock.into_inner().unwrap_or_else(|e| e.into_inner());
        if let Some(e) = error {
            return Err(e);
        }
        crate::output::outln!(
            "{} pairs ({} now, {} from an earlier run), {failed} failed now, {failed_before} \
             failed in an earlier run; {} shapes ({computed} eigenbases computed, {} from the \
             cache, {unusable} unusable) in {:.1} s; pairs {:.1} s; total {:.1} s -> {}",
            total,
            todo.len(),
            finished.len(),
            needed.len(),
            needed.len() - computed - unusable,
            shape_seconds,
            started.elapsed().as_secs_f64() - shape_seconds,
            started.elapsed().as_secs_f64(),
            self.out.join("pairs.jsonl").display()
        )?;
        if failed + failed_before > 0 {
            return Err(Error::file(
                self.out.join("pairs.jsonl"),
                format!(
                    "{} of {total} pairs failed ({failed} now, {failed_before} in an earlier \
                     run); their lines say why, and --retry-failed computes them again",
                    failed + failed_before
                ),
            ));
        }
        Ok(())
    }

    /// The shapes: files as given, folders expanded (sorted), each named by its file stem,
    /// or by its path relative to the inputs' common folder when stems repeat.
    fn inputs(&self) -> Result<Vec<Input>, Error> {
        let mut paths = Vec::new();
        for input in &self.inputs {
            if input.is_dir() {
                let entries =
                    std::fs::read_dir(input).map_err(|e| Error::file(input, e.to_string()))?;
                let mut files: Vec<PathBuf> = entries
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.is_file() && has_shape_extension(p))
                    .collect();
                files.sort();
                if files.is_empty() {
                    return Err(Error::file(
                        input,
                        "no .ply, .off or .obj file in this folder",
                    ));
                }
                paths.extend(files);
            } else {
                paths.push(input.clone());
            }
        }
        let mut seen = BTreeSet::new();
        paths.retain(|p| seen.insert(p.clone()));
        let stem = |p: &Path| {
            p.file_stem()
                .map_or(String::new(), |s| s.to_string_lossy().into_owned())
        };
        let stems: Vec<String> = paths.iter().map(|p| stem(p)).collect();
        let unique = stems.iter().collect::<BTreeSet<_>>().len() == stems.len();
        let names = if unique {
            stems
        } else {
            let common = common_folder(&paths);
            paths
                .iter()
                .map(|p| {
                    let relative = p.strip_prefix(&common).unwrap_or(p);
                    relative.with_extension("").to_string_lossy().into_owned()
                })
                .collect()
        };
        Ok(names
            .into_iter()
            .zip(paths)
            .map(|(name, path)| Input { name, path })
            .collect())
    }

    /// The pairs as indices into `inputs`.
    fn pairs(&self, inputs: &[Input]) -> Result<Vec<(usize, usize)>, Error> {
        let n = inputs.len();
        if self.pairs == "all" {
            if n < 2 {
                return Err(Error::InvalidParameter {
                    name: "pairs",
                    reason: format!("`all` needs two or more shapes, got {n}"),
                });
            }
            return Ok((0..n)
                .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
                .collect());
        }
        if let Some(template) = self.pairs.strip_prefix("one-to-many:") {
            let t = find(inputs, template).map_err(|reason| Error::InvalidParameter {
                name: "pairs",
                reason,
            })?;
            return Ok((0..n).filter(|&j| j != t).map(|j| (t, j)).collect());
        }
        let file = Path::new(&self.pairs);
        if !file.is_file() {
            return Err(Error::InvalidParameter {
                name: "pairs",
                reason: format!(
                    "expected `all`, `one-to-many:NAME` or a pair file, got {:?} (no such file)",
                    self.pairs
                ),
            });
        }
        read_pairs(file)?
            .iter()
            .map(|pair| {
                let at = |name: &str| {
                    find(inputs, name).map_err(|reason| {
                        Error::file(file, format!("line {}: {reason}", pair.line))
                    })
                };
                Ok((at(&pair.a)?, at(&pair.b)?))
            })
            .collect()
    }

    fn bar(&self, label: &str, total: usize, already: usize) -> Option<ProgressBar> {
        (!QUIET.load(Ordering::Relaxed)).then(|| ProgressBar::new(label, total, already))
    }
}

fn step(bar: &Mutex<Option<ProgressBar>>, message: &str) {
    if let Some(bar) = bar.lock().unwrap_or_else(|e| e.into_inner()).as_mut() {
        bar.step(message);
    }
}

fn finish(bar: &Mutex<Option<ProgressBar>>) {
    if let Some(bar) = bar.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
        bar.finish();
    }
}

/// `work` on every item, `jobs` items at a time, on threads of their own outside the rayon
/// pool: each item's parallel loops run on the global pool, as a single `match` call's do
/// (the library's progress polling then needs no pool of its own per stage). Results in
/// the order the items finished.
fn parallel<T: Sync, R: Send>(items: &[T], jobs: usize, work: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::with_capacity(items.len()));
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, items.len().max(1)) {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(item) = items.get(i) else { break };
                let result = work(item);
                results
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(result);
            });
        }
    });
    results.into_inner().unwrap_or_else(|e| e.into_inner())
}

/// `--jobs`: 0 or a positive count (a negative one is refused with this message rather than
/// taken for an option).
fn parse_jobs(text: &str) -> Result<usize, String> {
    let value: i64 = text.trim().parse().map_err(|_| {
        format!("expected a whole number of pairs at once (0: one per core), got {text:?}")
    })?;
    usize::try_from(value).map_err(|_| {
        format!("expected 0 (one per core) or a positive number of pairs at once, got {value}")
    })
}

fn has_shape_extension(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| SHAPE_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// The deepest folder holding every path.
fn common_folder(paths: &[PathBuf]) -> PathBuf {
    let mut common: PathBuf = paths
        .first()
        .and_then(|p| p.parent())
        .map(Path::to_path_buf)
        .unwrap_or_default();
    for path in paths {
        while !path.starts_with(&common) {
            if !common.pop() {
                return PathBuf::new();
            }
        }
    }
    common
}

/// The input named `name`: by its name, else by its file stem when one input has it.
fn find(inputs: &[Input], name: &str) -> Result<usize, String> {
    if let Some(i) = inputs.iter().position(|s| s.name == name) {
        return Ok(i);
    }
    let by_stem: Vec<usize> = (0..inputs.len())
        .filter(|&i| inputs[i].path.file_stem().is_some_and(|s| s == name))
        .collect();
    match by_stem[..] {
        [i] => Ok(i),
        [] => Err(format!("no shape named {name:?} among the inputs")),
        _ => Err(format!(
            "{name:?} names {} shapes; use the names of shapes.jsonl",
            by_stem.len()
        )),
    }
}
