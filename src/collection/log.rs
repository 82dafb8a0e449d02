//! A resumable JSON-lines log: results appended one line each as they finish, read back on
//! the next run so finished work is skipped.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::{Error, Result};

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
