//! What long benchmark runs keep between pairs and between runs:
//! - [`ShapeStore`]: each shape of a dataset read once, with its eigenbasis and geodesic
//!   solver made once;
//! - [`BasisCache`] (the library's, shared with `shapecorr batch`): eigenbases on disk, so an
//!   interrupted or repeated run does not solve again;
//! - [`ResultLog`] (the library's): results appended to a JSON-lines file as each finishes,
//!   read back on the next run so finished work is skipped;
//! - [`ProgressBar`]: a bar with an ETA on a terminal, a line per step otherwise.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use crate::datasets::Dataset;
pub use shapecorr::collection::{BasisCache, ResultLog, TimedBasis};
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::shape::Shape;
use shapecorr::spectral::eigen::EigenParams;
use shapecorr::ReadAs;
use shapecorr::Result;

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
            entry.basis = Some(self.cache.basis(
                &entry.path,
                &entry.shape,
                "points=false|repair=true",
                &self.eigen,
            )?);
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
