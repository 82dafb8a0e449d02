//! Benchmark datasets on disk: one registry for the standard layouts (`shared/data/README.md`),
//! their pair lists and their ground truth.
//!
//! The data is research-only and never part of the repository: a root folder is given on
//! the command line or by `SHAPECORR_DATA`. Under it, dataset `NAME` lives in `NAME/` and its
//! pair list in `pairs/NAME.txt` (tab separated: source, target, category). The layout of a
//! dataset follows its name when the name is a known one ([`Layout::for_name`]), else its
//! folder's contents ([`Layout::detect`]):
//!
//! | layout | shapes | ground truth | mirror map (flip-tolerant scores) |
//! |---|---|---|---|
//! | [`Layout::SharedOrder`] (FAUST `tr_reg_XXX`, SCAPE `meshXXX`) | `NAME/X.{ply,off,obj}` | identity by vertex index | `NAME/template_mirror.txt` |
//! | [`Layout::SharedOrderPerClass`] (TOSCA `cat0`, `david13`) | `NAME/X.{ply,off,obj}` | identity within a class (name without trailing digits) | `NAME/CLASS_mirror.txt` |
//! | [`Layout::Vts`] (FAUST_r, SCAPE_r, TOSCA_r) | `NAME/off/X.off` or `NAME/shapes/X.*` | `NAME/corres/X.vts`: row k of A's file matches row k of B's (1-based) | `NAME/corres/X.sym.vts` |
//! | [`Layout::TemplateIndex`] (remeshed shapes) | `NAME/shapes/X.*` | `NAME/template/X.txt`: the 0-based template vertex of every vertex | `NAME/template_mirror.txt` on the template |
//! | [`Layout::VertexMaps`] (camel gallop, lion/cat) | `FOLDER/X.off` | a map file per pair: the 0-based target vertex of every source vertex (vertex 0 as a placeholder left out, [`zero_placeholder`]) | none (meshes: orientation is known) |
//!
//! The vertex-map datasets come without a pair list; their pairs are their map files
//! ([`VERTEX_MAP_DATASETS`]): `camel_gallop` is `nonisometric/camel_gallop` with
//! `maps/i_to_j` for frames `camel-gallop-0i` -> `camel-gallop-0j` (30 pairs), `lion_cat` is
//! `nonisometric` with `lion2cat` for `lion-00` -> `cat-00`.
//!
//! Mirror maps give, per vertex (of the template), the vertex at the mirrored position. Every
//! missing or malformed file is an [`Error::File`] naming the path and what was expected.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use shapecorr::{Error, Result};

/// One line of a pair list: source, target, category.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
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

/// How a dataset stores shapes and ground truth (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Layout {
    /// Every shape has the same vertex order (FAUST registrations, SCAPE).
    SharedOrder,
    /// Shapes of a class share a vertex order (TOSCA).
    SharedOrderPerClass,
    /// Independently remeshed shapes with `.vts` correspondence files.
    Vts,
    /// Independently remeshed shapes with a per-vertex template index.
    TemplateIndex,
    /// A vertex map file per pair (the pairs are the map files).
    VertexMaps,
}

/// The vertex-map datasets: name and folder under the data root.
pub const VERTEX_MAP_DATASETS: [(&str, &str); 2] = [
    ("camel_gallop", "nonisometric/camel_gallop"),
    ("lion_cat", "nonisometric"),
];

impl Layout {
    /// The layout of a dataset with a known name: `faust`, `scape` share one vertex order,
    /// `tosca` per class, `*_r` (`faust_r`, `scape_r`, `tosca_r`, `shrec19_r`, ...) use `.vts`.
    pub fn for_name(name: &str) -> Option<Layout> {
        match name {
            "faust" | "scape" => Some(Layout::SharedOrder),
            "tosca" => Some(Layout::SharedOrderPerClass),
            n if n.ends_with("_r") => Some(Layout::Vts),
            n if VERTEX_MAP_DATASETS.iter().any(|(d, _)| *d == n) => Some(Layout::VertexMaps),
            _ => None,
        }
    }

    /// The layout of a dataset folder from its contents: `corres/` holds `.vts` files,
    /// `template/` template indices, files `*_mirror.txt` other than `template_mirror.txt`
    /// mean per-class mirror maps (TOSCA), anything else with shapes one shared order.
    pub fn detect(folder: &Path) -> Result<Layout> {
        if !folder.is_dir() {
            return Err(Error::file(folder, "dataset folder not found"));
        }
        if folder.join("corres").is_dir() {
            return Ok(Layout::Vts);
        }
        if folder.join("template").is_dir() {
            return Ok(Layout::TemplateIndex);
        }
        let entries = std::fs::read_dir(folder).map_err(|e| Error::file(folder, e.to_string()))?;
        let names: Vec<String> = entries
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        if names
            .iter()
            .any(|n| n.ends_with("_mirror.txt") && n != "template_mirror.txt")
        {
            return Ok(Layout::SharedOrderPerClass);
        }
        if names.iter().any(|n| shape_extension(n)) {
            return Ok(Layout::SharedOrder);
        }
        Err(Error::file(
            folder,
            "cannot tell the dataset's layout: no corres/ (.vts), no template/ and no shape files (.ply, .off, .obj)",
        ))
    }
}

fn shape_extension(file_name: &str) -> bool {
    [".ply", ".off", ".obj"]
        .iter()
        .any(|e| file_name.to_ascii_lowercase().ends_with(e))
}

/// A dataset: its name, folder and layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Dataset {
    pub name: String,
    /// `root/name` (for [`Layout::VertexMaps`], the folder of [`VERTEX_MAP_DATASETS`]).
    pub folder: PathBuf,
    pub layout: Layout,
    /// [`Layout::VertexMaps`]: every pair with its map file (source vertex -> target vertex).
    pub vertex_maps: Vec<(Pair, PathBuf)>,
}

impl Dataset {
    /// Dataset `name` under `root` (`root/name/`, or the folder of [`VERTEX_MAP_DATASETS`]),
    /// its layout from its name or contents.
    pub fn open(root: &Path, name: &str) -> Result<Dataset> {
        let folder = match VERTEX_MAP_DATASETS.iter().find(|(d, _)| *d == name) {
            Some((_, sub)) => root.join(sub),
            None => root.join(name),
        };
        if !folder.is_dir() {
            return Err(Error::file(
                &folder,
                format!(
                    "dataset folder not found (give the data root with --data or SHAPECORR_DATA; looked under {})",
                    root.display()
                ),
            ));
        }
        let layout = match Layout::for_name(name) {
            Some(layout) => layout,
            None => Layout::detect(&folder)?,
        };
        let vertex_maps = match layout {
            Layout::VertexMaps => vertex_map_pairs(name, &folder)?,
            _ => Vec::new(),
        };
        Ok(Dataset {
            name: name.to_string(),
            folder,
            layout,
            vertex_maps,
        })
    }

    /// The dataset's pairs: `root/pairs/NAME.txt`, or for [`Layout::VertexMaps`] (which
    /// have no pair list) its map files' pairs.
    pub fn pairs(&self, root: &Path) -> Result<Vec<Pair>> {
        match self.layout {
            Layout::VertexMaps => Ok(self.vertex_maps.iter().map(|(p, _)| p.clone()).collect()),
            _ => read_pairs(&self.pairs_file(root)),
        }
    }

    /// The dataset a pair list belongs to: `pairs/NAME.txt` belongs to `NAME` under `root`.
    pub fn for_pairs_file(root: &Path, pairs_file: &Path) -> Result<Dataset> {
        let name = pairs_file
            .file_stem()
            .and_then(|s| s.to_str())
            .ok_or_else(|| Error::file(pairs_file, "a pair list is named NAME.txt"))?;
        Dataset::open(root, name)
    }

    /// The pair list `root/pairs/NAME.txt`.
    pub fn pairs_file(&self, root: &Path) -> PathBuf {
        root.join("pairs").join(format!("{}.txt", self.name))
    }

    /// The shape file of `name`: the first of `NAME.ply`, `.off`, `.obj` found in the
    /// dataset folder (or its `off/` and `shapes/` subfolders for remeshed layouts).
    pub fn shape_path(&self, name: &str) -> Result<PathBuf> {
        let folders: Vec<PathBuf> = match self.layout {
            Layout::SharedOrder | Layout::SharedOrderPerClass | Layout::VertexMaps => {
                vec![self.folder.clone()]
            }
            Layout::Vts | Layout::TemplateIndex => vec![
                self.folder.join("off"),
                self.folder.join("shapes"),
                self.folder.clone(),
            ],
        };
        let candidates: Vec<PathBuf> = folders
            .iter()
            .flat_map(|f| ["ply", "off", "obj"].map(|e| f.join(format!("{name}.{e}"))))
            .collect();
        candidates
            .iter()
            .find(|p| p.is_file())
            .cloned()
            .ok_or_else(|| {
                Error::file(
                    &candidates[0],
                    format!(
                        "shape {name:?} of dataset {} not found (tried .ply, .off and .obj in {})",
                        self.name,
                        folders
                            .iter()
                            .map(|f| f.display().to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })
    }

    /// Ground-truth vertex pairs `(vertex of source, vertex of target)`, and the same with
    /// the target mirrored (for flip-tolerant scores) when a mirror map exists.
    pub fn ground_truth(
        &self,
        source: &str,
        target: &str,
        n_source: usize,
        n_target: usize,
    ) -> Result<(VertexPairs, Option<VertexPairs>)> {
        match self.layout {
            Layout::SharedOrder | Layout::SharedOrderPerClass => {
                if self.layout == Layout::SharedOrderPerClass
                    && class_of(source) != class_of(target)
                {
                    return Err(Error::InvalidParameter {
                        name: "pair",
                        reason: format!(
                            "{source} and {target} are of different classes of {}: no ground truth",
                            self.name
                        ),
                    });
                }
                if n_source != n_target {
                    return Err(Error::InvalidParameter {
                        name: "pair",
                        reason: format!(
                            "{source} and {target} should share their vertex order but have {n_source} and {n_target} vertices"
                        ),
                    });
                }
                let identity: Vec<(u32, u32)> = (0..n_source as u32).map(|v| (v, v)).collect();
                let flipped = self.mirror_map(target, n_target)?.map(|mirror| {
                    identity
                        .iter()
                        .map(|&(x, y)| (x, mirror[y as usize]))
                        .collect()
                });
                Ok((identity, flipped))
            }
            Layout::Vts => {
                let corres = self.folder.join("corres");
                let a = read_indices(&corres.join(format!("{source}.vts")), 1)?;
                let b = read_indices(&corres.join(format!("{target}.vts")), 1)?;
                check_range(&corres.join(format!("{source}.vts")), &a, n_source)?;
                check_range(&corres.join(format!("{target}.vts")), &b, n_target)?;
                if a.len() != b.len() {
                    return Err(Error::file(
                        corres.join(format!("{target}.vts")),
                        format!(
                            "{} rows, but {source}.vts has {}: row k of one must match row k of the other",
                            b.len(),
                            a.len()
                        ),
                    ));
                }
                let truth: Vec<(u32, u32)> = a.iter().copied().zip(b.iter().copied()).collect();
                let sym_path = corres.join(format!("{target}.sym.vts"));
                let flipped = if sym_path.exists() {
                    let b_sym = read_indices(&sym_path, 1)?;
                    check_range(&sym_path, &b_sym, n_target)?;
                    if b_sym.len() != a.len() {
                        return Err(Error::file(
                            &sym_path,
                            format!("{} rows, expected {}", b_sym.len(), a.len()),
                        ));
                    }
                    Some(a.iter().copied().zip(b_sym).collect())
                } else {
                    None
                };
                Ok((truth, flipped))
            }
            Layout::TemplateIndex => {
                let template = self.folder.join("template");
                let read = |name: &str, n: usize| -> Result<Vec<u32>> {
                    let path = template.join(format!("{name}.txt"));
                    let t = read_indices(&path, 0)?;
                    if t.len() != n {
                        return Err(Error::file(
                            &path,
                            format!("{} entries for a shape with {n} vertices", t.len()),
                        ));
                    }
                    Ok(t)
                };
                let (t_a, t_b) = (read(source, n_source)?, read(target, n_target)?);
                let n_template = t_a.iter().chain(&t_b).map(|&t| t as usize + 1).max();
                let n_template = n_template.unwrap_or(0);
                // The first vertex of A standing for each template vertex.
                let mut a_of_template = vec![u32::MAX; n_template];
                for (x, &t) in t_a.iter().enumerate().rev() {
                    a_of_template[t as usize] = x as u32;
                }
                let pairs_with = |map_b: &dyn Fn(u32) -> u32| -> VertexPairs {
                    t_b.iter()
                        .enumerate()
                        .filter_map(|(y, &t)| {
                            let x = *a_of_template.get(map_b(t) as usize)?;
                            (x != u32::MAX).then_some((x, y as u32))
                        })
                        .collect()
                };
                let truth = pairs_with(&|t| t);
                if truth.is_empty() {
                    return Err(Error::InvalidParameter {
                        name: "pair",
                        reason: format!("{source} and {target} share no template vertex"),
                    });
                }
                let mirror_path = self.folder.join("template_mirror.txt");
                let flipped = if mirror_path.exists() {
                    let mirror = read_indices(&mirror_path, 0)?;
                    check_range(&mirror_path, &mirror, mirror.len())?;
                    Some(pairs_with(&|t| {
                        mirror.get(t as usize).copied().unwrap_or(u32::MAX)
                    }))
                } else {
                    None
                };
                Ok((truth, flipped))
            }
            Layout::VertexMaps => Ok((
                self.vertex_map_truth(source, target, n_source, n_target)?,
                None,
            )),
        }
    }

    /// [`Layout::VertexMaps`]: the map file's pairs `(x, map[x])`, checked against both sizes.
    fn vertex_map_truth(
        &self,
        source: &str,
        target: &str,
        n_source: usize,
        n_target: usize,
    ) -> Result<VertexPairs> {
        let (_, path) = self
            .vertex_maps
            .iter()
            .find(|(p, _)| p.source == source && p.target == target)
            .ok_or_else(|| Error::InvalidParameter {
                name: "pair",
                reason: format!(
                    "{source} -> {target} has no map file in {}",
                    self.folder.display()
                ),
            })?;
        let map = read_indices(path, 0)?;
        if map.len() != n_source {
            return Err(Error::file(
                path,
                format!(
                    "{} entries for the {n_source} vertices of {source}",
                    map.len()
                ),
            ));
        }
        check_range(path, &map, n_target)?;
        let placeholder = zero_placeholder(&map);
        Ok(map
            .into_iter()
            .enumerate()
            .filter(|&(_, y)| !(placeholder && y == 0))
            .map(|(x, y)| (x as u32, y))
            .collect())
    }

    /// The mirror map of a shared-order dataset (per class for TOSCA), checked against the
    /// number of vertices; None when the dataset has none.
    fn mirror_map(&self, target: &str, n_target: usize) -> Result<Option<Vec<u32>>> {
        let path = match self.layout {
            Layout::SharedOrderPerClass => {
                self.folder.join(format!("{}_mirror.txt", class_of(target)))
            }
            _ => self.folder.join("template_mirror.txt"),
        };
        if !path.exists() {
            return Ok(None);
        }
        let mirror = read_indices(&path, 0)?;
        check_range(&path, &mirror, n_target)?;
        if mirror.len() != n_target {
            return Err(Error::file(
                &path,
                format!("{} entries for {n_target} vertices", mirror.len()),
            ));
        }
        Ok(Some(mirror))
    }
}

/// Whether target vertex 0 of a vertex map is a placeholder for "no correspondence": it is
/// hit more than 4 times as often as any other vertex and by more than 20 sources. 27 of the
/// 30 camel gallop maps send 430-910 vertices (spread over the whole animal, 0.4-0.5 away
/// from vertex 0) to vertex 0, while no other vertex is hit more than 8 times; scoring those
/// as pairs would count a correct map as wrong on 10-18% of the shape.
pub fn zero_placeholder(map: &[u32]) -> bool {
    let n = map.iter().map(|&y| y as usize + 1).max().unwrap_or(0);
    let mut hits = vec![0usize; n];
    for &y in map {
        hits[y as usize] += 1;
    }
    let others = hits.iter().skip(1).copied().max().unwrap_or(0);
    hits.first()
        .is_some_and(|&zero| zero > 20 && zero > 4 * others)
}

/// The pairs of a vertex-map dataset (see [`VERTEX_MAP_DATASETS`]): `maps/i_to_j` between
/// the shapes whose names end in the numbers i and j, or `lion2cat` for `lion-00` ->
/// `cat-00`; sorted by source then target.
fn vertex_map_pairs(name: &str, folder: &Path) -> Result<Vec<(Pair, PathBuf)>> {
    if name == "lion_cat" {
        let pair = Pair {
            source: "lion-00".into(),
            target: "cat-00".into(),
            category: "lion_to_cat".into(),
        };
        return Ok(vec![(pair, folder.join("lion2cat"))]);
    }
    let maps = folder.join("maps");
    let entries = std::fs::read_dir(&maps).map_err(|e| Error::file(&maps, e.to_string()))?;
    let mut shapes: Vec<(u32, String)> = std::fs::read_dir(folder)
        .map_err(|e| Error::file(folder, e.to_string()))?
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let file = e.file_name().to_string_lossy().into_owned();
            let stem = file.rsplit_once('.').filter(|_| shape_extension(&file))?.0;
            let digits = &stem[class_of(stem).len()..];
            Some((digits.parse().ok()?, stem.to_string()))
        })
        .collect();
    shapes.sort();
    let shape_of = |frame: &str| -> Option<String> {
        let frame: u32 = frame.parse().ok()?;
        shapes
            .iter()
            .find(|(n, _)| *n == frame)
            .map(|(_, s)| s.clone())
    };
    let mut pairs = Vec::new();
    for entry in entries.filter_map(|e| e.ok()) {
        let file = entry.file_name().to_string_lossy().into_owned();
        let Some((i, j)) = file.split_once("_to_") else {
            continue;
        };
        let (Some(source), Some(target)) = (shape_of(i), shape_of(j)) else {
            return Err(Error::file(
                entry.path(),
                format!("no shape numbered {i} and {j} in {}", folder.display()),
            ));
        };
        let pair = Pair {
            source,
            target,
            category: name.to_string(),
        };
        pairs.push((pair, entry.path()));
    }
    if pairs.is_empty() {
        return Err(Error::file(&maps, "no map file named i_to_j"));
    }
    pairs.sort_by(|(p, _), (q, _)| (&p.source, &p.target).cmp(&(&q.source, &q.target)));
    Ok(pairs)
}

/// A pair list given as a file (`pairs/NAME.txt`, of the dataset `NAME` under `root`) or as
/// the name of a dataset: the dataset and its pairs (the first `limit`).
pub fn pair_list(root: &Path, list: &Path, limit: Option<usize>) -> Result<(Dataset, Vec<Pair>)> {
    let (dataset, mut pairs) = if list.is_file() {
        (Dataset::for_pairs_file(root, list)?, read_pairs(list)?)
    } else {
        let name = list.to_string_lossy();
        let dataset = Dataset::open(root, &name)?;
        let pairs = dataset.pairs(root)?;
        (dataset, pairs)
    };
    pairs.truncate(limit.unwrap_or(usize::MAX));
    Ok((dataset, pairs))
}

/// The datasets under `root` that have both a folder and a pair list `pairs/NAME.txt`, and
/// the vertex-map datasets whose folders exist, sorted by name. Folders without a pair list
/// (and pair lists without a folder) are skipped: they are listed in the second value with
/// the reason.
pub fn discover(root: &Path) -> Result<(Vec<Dataset>, Vec<String>)> {
    let pairs_dir = root.join("pairs");
    let entries = std::fs::read_dir(&pairs_dir).map_err(|e| {
        Error::file(
            &pairs_dir,
            format!("{e} (the data root needs a pairs/ folder of NAME.txt pair lists)"),
        )
    })?;
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            name.strip_suffix(".txt").map(str::to_string)
        })
        .collect();
    names.extend(
        VERTEX_MAP_DATASETS
            .iter()
            .filter(|(_, folder)| root.join(folder).is_dir())
            .map(|(name, _)| name.to_string()),
    );
    names.sort();
    names.dedup();
    let (mut found, mut skipped) = (Vec::new(), Vec::new());
    for name in names {
        match Dataset::open(root, &name) {
            Ok(d) => found.push(d),
            Err(e) => skipped.push(format!("{name}: {e}")),
        }
    }
    Ok((found, skipped))
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

/// The benchmark data root: `SHAPECORR_DATA`, else `../shared/data` next to the repository.
pub fn default_data_root() -> PathBuf {
    std::env::var_os("SHAPECORR_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}
