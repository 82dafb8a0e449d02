//! Benchmark datasets on disk: pair lists and ground truth, in the layouts of
//! `shared/data/README.md` (FAUST registrations, TOSCA, remeshed TOSCA with `.vts` files).
//! The data is research-only and never part of the repository: a root folder is given on
//! the command line or by `SHAPECORR_DATA`.

use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// One line of a pair list: source, target, category.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pair {
    pub source: String,
    pub target: String,
    pub category: String,
}

/// Reads a tab-separated pair list (`#` comments and blank lines skipped).
pub fn read_pairs(path: &Path) -> Result<Vec<Pair>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e.to_string()))?;
    let mut pairs = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.len() < 2 {
            return Err(Error::file(
                path,
                format!(
                    "line {}: expected `source<TAB>target[<TAB>category]`",
                    number + 1
                ),
            ));
        }
        pairs.push(Pair {
            source: fields[0].to_string(),
            target: fields[1].to_string(),
            category: fields.get(2).unwrap_or(&"all").to_string(),
        });
    }
    Ok(pairs)
}

/// Ground-truth vertex pairs `(vertex of source, vertex of target)`.
pub type VertexPairs = Vec<(u32, u32)>;

/// How a dataset stores shapes and ground truth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// `faust/NAME.ply`, one shared vertex order, mirror map `faust/template_mirror.txt`.
    Faust,
    /// `tosca/NAME.ply`, shared vertex order within a class, mirror `tosca/CLASS_mirror.txt`.
    Tosca,
    /// `tosca_r/off/NAME.off` with `tosca_r/corres/NAME.vts` and `NAME.sym.vts`.
    ToscaRemeshed,
}

impl Layout {
    /// The layout a pair list belongs to, from its file name (`faust.txt`, `tosca.txt`,
    /// `tosca_r.txt`).
    pub fn from_pairs_file(path: &Path) -> Result<Layout> {
        match path.file_stem().and_then(|s| s.to_str()) {
            Some("faust") => Ok(Layout::Faust),
            Some("tosca") => Ok(Layout::Tosca),
            Some("tosca_r") => Ok(Layout::ToscaRemeshed),
            _ => Err(Error::file(
                path,
                "unknown pair list: name it faust.txt, tosca.txt or tosca_r.txt (the layout follows the name)",
            )),
        }
    }

    /// The shape file of `name` under `root`.
    pub fn shape_path(&self, root: &Path, name: &str) -> PathBuf {
        match self {
            Layout::Faust => root.join("faust").join(format!("{name}.ply")),
            Layout::Tosca => root.join("tosca").join(format!("{name}.ply")),
            Layout::ToscaRemeshed => root.join("tosca_r").join("off").join(format!("{name}.off")),
        }
    }

    /// Ground-truth vertex pairs `(vertex of source, vertex of target)`, and the same with
    /// the target mirrored (for flip-tolerant scores) when a mirror map exists.
    pub fn ground_truth(
        &self,
        root: &Path,
        source: &str,
        target: &str,
        n_source: usize,
        n_target: usize,
    ) -> Result<(VertexPairs, Option<VertexPairs>)> {
        match self {
            Layout::Faust | Layout::Tosca => {
                if n_source != n_target {
                    return Err(Error::InvalidParameter {
                        name: "pair",
                        reason: format!(
                            "{source} and {target} should share their vertex order but have {n_source} and {n_target} vertices"
                        ),
                    });
                }
                let identity: Vec<(u32, u32)> = (0..n_source as u32).map(|v| (v, v)).collect();
                let mirror_path = match self {
                    Layout::Faust => root.join("faust").join("template_mirror.txt"),
                    _ => root
                        .join("tosca")
                        .join(format!("{}_mirror.txt", class_of(target))),
                };
                let flipped = if mirror_path.exists() {
                    let mirror = read_indices(&mirror_path, 0)?;
                    check_range(&mirror_path, &mirror, n_target)?;
                    if mirror.len() != n_target {
                        return Err(Error::file(
                            &mirror_path,
                            format!("{} entries for {n_target} vertices", mirror.len()),
                        ));
                    }
                    Some(
                        identity
                            .iter()
                            .map(|&(x, y)| (x, mirror[y as usize]))
                            .collect(),
                    )
                } else {
                    None
                };
                Ok((identity, flipped))
            }
            Layout::ToscaRemeshed => {
                let corres = root.join("tosca_r").join("corres");
                let a = read_indices(&corres.join(format!("{source}.vts")), 1)?;
                let b = read_indices(&corres.join(format!("{target}.vts")), 1)?;
                check_range(&corres.join(format!("{source}.vts")), &a, n_source)?;
                check_range(&corres.join(format!("{target}.vts")), &b, n_target)?;
                let truth: Vec<(u32, u32)> = a.iter().copied().zip(b.iter().copied()).collect();
                let sym_path = corres.join(format!("{target}.sym.vts"));
                let flipped = if sym_path.exists() {
                    let b_sym = read_indices(&sym_path, 1)?;
                    check_range(&sym_path, &b_sym, n_target)?;
                    Some(a.iter().copied().zip(b_sym).collect())
                } else {
                    None
                };
                Ok((truth, flipped))
            }
        }
    }
}

/// The class of a TOSCA shape name: the name without its trailing digits.
pub fn class_of(name: &str) -> &str {
    name.trim_end_matches(|c: char| c.is_ascii_digit())
}

/// One integer per line, minus `base` (1 for the 1-based `.vts` files).
fn read_indices(path: &Path, base: u32) -> Result<Vec<u32>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e.to_string()))?;
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(number, line)| {
            line.split_whitespace()
                .next()
                .and_then(|t| t.parse::<u32>().ok())
                .filter(|&v| v >= base)
                .map(|v| v - base)
                .ok_or_else(|| {
                    Error::file(
                        path,
                        format!("line {}: expected an index >= {base}", number + 1),
                    )
                })
        })
        .collect()
}

fn check_range(path: &Path, indices: &[u32], n: usize) -> Result<()> {
    match indices.iter().find(|&&v| v as usize >= n) {
        Some(v) => Err(Error::file(
            path,
            format!("index {v} is out of range for a shape with {n} vertices"),
        )),
        None => Ok(()),
    }
}

/// The benchmark data root: `SHAPECORR_DATA`, else `../shared/data` next to the crate.
pub fn default_data_root() -> PathBuf {
    std::env::var_os("SHAPECORR_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"))
}
