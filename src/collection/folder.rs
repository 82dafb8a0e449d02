//! A batch's output folder, held by one run at a time: a lock on `OUT/batch.lock` (an OS
//! file lock, released when the run ends, also when it is killed), and the settings in
//! `OUT/batch.json`, written by the first run and compared by every later one. The command
//! line and the Python package (through the C API) both open the folder here, so a folder
//! made by one is resumed by the other only with the same settings (docs/collections.md).

use std::fs::{File, OpenOptions, TryLockError};
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::{BatchSettings, Outputs};
use crate::options::{OptionGroup, OptionValue, OPTIONS};
use crate::{Error, Result};

/// Version of `batch.json`'s content.
const SETTINGS_FORMAT: u64 = 2;

/// The output folder of a batch, locked for as long as this value lives.
#[derive(Debug)]
pub struct OutputFolder {
    dir: PathBuf,
    _lock: File,
}

impl OutputFolder {
    /// Creates (if needed) and locks the folder `dir` for a batch with `settings`: refused
    /// when another run holds it, or when it holds a run with other settings; the settings
    /// are recorded on a first run.
    pub fn open(dir: &Path, settings: &BatchSettings) -> Result<OutputFolder> {
        std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, e.to_string()))?;
        let lock_path = dir.join("batch.lock");
        let lock = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&lock_path)
            .map_err(|e| Error::file(&lock_path, e.to_string()))?;
        match lock.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                return Err(Error::file(
                    dir,
                    "another batch is running on this folder (batch.lock is held); wait for \
                     it to end or use another output folder",
                ))
            }
            Err(TryLockError::Error(e)) => {
                return Err(Error::file(
                    &lock_path,
                    format!("cannot lock the folder: {e}"),
                ))
            }
        }
        check_settings(dir, &settings_json(settings))?;
        Ok(OutputFolder {
            dir: dir.to_path_buf(),
            _lock: lock,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

/// What `batch.json` records: what changes a pair's answer (the outputs, how files are
/// read, every option the outputs use), not where the cache is nor the thread count.
pub fn settings_json(settings: &BatchSettings) -> Value {
    let maps = settings.outputs == Outputs::RegionsAndMaps;
    let options: serde_json::Map<String, Value> = OPTIONS
        .iter()
        .filter(|o| maps || o.group == OptionGroup::Regions)
        .filter_map(|o| {
            let value = match settings.options.option(o.name).ok()? {
                OptionValue::Int(v) => json!(v),
                OptionValue::Float(v) => json!(v),
                OptionValue::Bool(v) => json!(v),
            };
            Some((o.name.to_string(), value))
        })
        .collect();
    json!({
        "format": SETTINGS_FORMAT,
        "outputs": if maps { "regions+maps" } else { "regions" },
        "points": settings.reading.points,
        "repair": settings.reading.repair,
        "options": options,
    })
}

fn check_settings(dir: &Path, settings: &Value) -> Result<()> {
    let path = dir.join("batch.json");
    let refuse = |why: &str| {
        Err(Error::file(
            &path,
            format!(
                "{why}; use another output folder (or delete this one to start over) so that \
                 two answers are never mixed"
            ),
        ))
    };
    match std::fs::read_to_string(&path) {
        Ok(text) => {
            let earlier: Value = match serde_json::from_str(&text) {
                Ok(value) => value,
                Err(e) => return refuse(&format!("unreadable settings ({e})")),
            };
            if earlier.get("format") != settings.get("format") {
                return refuse("this folder holds a batch run by an earlier version of shapecorr");
            }
            if &earlier != settings {
                return refuse("this folder holds a batch run with other settings or options");
            }
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if dir.join("batch-python.json").exists() {
                return refuse(
                    "this folder holds a batch run by an earlier version of shapecorr's Python \
                     package",
                );
            }
            let text = serde_json::to_string_pretty(settings)
                .map_err(|e| Error::file(&path, e.to_string()))?;
            std::fs::write(&path, text + "\n").map_err(|e| Error::file(&path, e.to_string()))
        }
        Err(e) => Err(Error::file(&path, e.to_string())),
    }
}
