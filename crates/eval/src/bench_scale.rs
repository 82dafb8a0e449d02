//! `shapecorr bench scale` (docs/scale.md): time, peak memory and accuracy of `match` and `p2p`
//! on generated humanoid pairs from 5K to 1M vertices, each command a fresh process of the
//! `shapecorr` tool (so its peak memory is its own), with the full-resolution path and
//! pyFM (WKS + ZoomOut) as references where they finish.
//!
//! The pairs are the generated humanoid in pose 0 and pose 3 (limb thickness 1.2, as in the
//! issue). `synth` makes up to 200K vertices; larger pairs are smaller figures split 1:4 at
//! edge midpoints: 250K and 500K once (62.5K, 125K), 1M twice (62.5K). Both poses split the
//! same way, so the ground truth stays the identity at every size.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use shapecorr::synth::{self, FigureKind, FigureMesh, FigureSpec, Proportions};
use shapecorr::{Error, ReadAs, Result, Shape};

use crate::bench_store::ResultLog;
use crate::plot::{line_chart_png, Chart, Series};

/// Largest figure `synth` makes directly.
const SYNTH_MAX: usize = 200_000;

/// Vertices of B whose map is scored (a seeded sample).
const SCORED_VERTICES: usize = 500;

/// One command on one size.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ScaleRecord {
    /// Vertices per shape.
    pub vertices: usize,
    /// `match`, `p2p`, `match full`, `p2p full` (proxies off) or `pyfm`.
    pub command: String,
    /// Wall seconds of the process (file reading and writing included).
    pub seconds: Option<f64>,
    /// The process's peak resident memory (MiB).
    pub peak_mib: Option<f64>,
    /// Seconds per stage as the tool reports them (`timings_s`).
    pub stages: serde_json::Value,
    /// Mean geodesic error of the map on A over sqrt(area) (p2p and pyFM only).
    pub error: Option<f64>,
    /// The answer's confidence as the tool reports it (ours only; below 0.45: doubtful).
    #[serde(default)]
    pub confidence: Option<f64>,
    /// Why there is no figure (a time-out, a failure).
    pub note: Option<String>,
}

/// What to run.
pub struct ScaleSettings {
    /// Vertices per shape.
    pub sizes: Vec<usize>,
    /// The `shapecorr` binary.
    pub exe: PathBuf,
    /// Generated pairs, outputs and the log `scale.jsonl`.
    pub work: PathBuf,
    /// Run the full-resolution path too up to this size.
    pub full_up_to: usize,
    /// A Python with pyFM (pyfmaps) installed, for the reference; None: no pyFM.
    pub pyfm_python: Option<PathBuf>,
    /// The script that runs pyFM on one pair.
    pub pyfm_script: PathBuf,
    /// pyFM is run at larger sizes only while it finished within this time.
    pub pyfm_limit: Duration,
}

/// Runs every size (resuming from `work/scale.jsonl`) and returns the records.
pub fn run_scale(settings: &ScaleSettings) -> Result<Vec<ScaleRecord>> {
    std::fs::create_dir_all(&settings.work)
        .map_err(|e| Error::file(&settings.work, e.to_string()))?;
    let (mut log, mut records) =
        ResultLog::open::<ScaleRecord>(&settings.work.join("scale.jsonl"))?;
    let mut pyfm_alive = settings.pyfm_python.is_some();
    for &n in &settings.sizes {
        let (a, b) = pair_files(&settings.work, n)?;
        let mut commands = vec!["match", "p2p"];
        if n <= settings.full_up_to {
            commands.extend(["match full", "p2p full"]);
        }
        if pyfm_alive {
            commands.push("pyfm");
        }
        for command in commands {
            if records
                .iter()
                .any(|r| r.vertices == n && r.command == command)
            {
                continue;
            }
            let record = run_one(settings, command, n, (&a, &b))?;
            eprintln!(
                "[scale {n}] {command}: {} s, {} MiB, error {}{}",
                fmt(record.seconds, 2),
                fmt(record.peak_mib, 0),
                fmt(record.error, 4),
                record
                    .note
                    .as_deref()
                    .map_or(String::new(), |n| format!(" ({n})"))
            );
            log.append(&record)?;
            records.push(record);
        }
        if let Some(r) = records
            .iter()
            .find(|r| r.vertices == n && r.command == "pyfm")
        {
            pyfm_alive &= r.seconds.is_some();
        }
    }
    Ok(records)
}

fn fmt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// The pair's PLY files (made once): pose 0 and pose 3 with `n` vertices or about.
fn pair_files(work: &Path, n: usize) -> Result<(PathBuf, PathBuf)> {
    let dir = work.join(format!("pair_{n}"));
    let (a, b) = (dir.join("a.ply"), dir.join("b.ply"));
    if a.exists() && b.exists() {
        return Ok((a, b));
    }
    std::fs::create_dir_all(&dir).map_err(|e| Error::file(&dir, e.to_string()))?;
    let (splits, base) = if n <= SYNTH_MAX {
        (0, n)
    } else if n / 4 <= SYNTH_MAX {
        (1, n / 4)
    } else {
        (2, n / 16)
    };
    for (pose, path) in [(0, &a), (3, &b)] {
        let mut mesh = synth::figure(&FigureSpec {
            kind: FigureKind::Humanoid,
            pose,
            target_vertices: base,
            proportions: Proportions {
                limb_thickness: 1.2,
                ..Default::default()
            },
            ..Default::default()
        })?;
        for _ in 0..splits {
            mesh = midpoint_split(&mesh);
        }
        shapecorr::shape::io::write_ply(path, &mesh.vertices, &mesh.triangles, None)?;
    }
    Ok((a, b))
}

/// Every triangle split into four at its edge midpoints; a midpoint's index is given at its
/// first use in triangle order, so two poses of one figure split the same way.
pub fn midpoint_split(mesh: &FigureMesh) -> FigureMesh {
    let mut vertices = mesh.vertices.clone();
    let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
    let mut mid = |i: u32, j: u32, vertices: &mut Vec<[f64; 3]>| -> u32 {
        *midpoint.entry((i.min(j), i.max(j))).or_insert_with(|| {
            let (p, q) = (vertices[i as usize], vertices[j as usize]);
            vertices.push([0, 1, 2].map(|c| 0.5 * (p[c] + q[c])));
            (vertices.len() - 1) as u32
        })
    };
    let mut triangles = Vec::with_capacity(4 * mesh.triangles.len());
    for &[a, b, c] in &mesh.triangles {
        let (ab, bc, ca) = (
            mid(a, b, &mut vertices),
            mid(b, c, &mut vertices),
            mid(c, a, &mut vertices),
        );
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    FigureMesh {
        vertices,
        triangles,
    }
}

fn run_one(
    settings: &ScaleSettings,
    command: &str,
    n: usize,
    (a, b): (&Path, &Path),
) -> Result<ScaleRecord> {
    let out = settings
        .work
        .join(format!("out_{n}_{}", command.replace(' ', "_")));
    let mut record = ScaleRecord {
        vertices: n,
        command: command.to_string(),
        seconds: None,
        peak_mib: None,
        stages: serde_json::Value::Null,
        error: None,
        confidence: None,
        note: None,
    };
    let mut process = if command == "pyfm" {
        let mut p = Command::new(settings.pyfm_python.as_ref().expect("pyfm is asked for"));
        p.arg(&settings.pyfm_script).arg(a).arg(b).arg(&out);
        p
    } else {
        let mut p = Command::new(&settings.exe);
        p.arg(command.split(' ').next().expect("a command"))
            .arg("--quiet")
            .arg("--out")
            .arg(&out)
            .arg(a)
            .arg(b);
        if command.ends_with("full") {
            p.args(["--proxy-above", "0"]);
        }
        p
    };
    let started = Instant::now();
    let mut child = process
        .stdout(std::process::Stdio::null())
        .spawn()
        .map_err(|e| Error::file(&settings.exe, e.to_string()))?;
    let limit = if command == "pyfm" {
        settings.pyfm_limit
    } else {
        Duration::from_secs(3600)
    };
    let status = loop {
        if let Some(status) = child
            .try_wait()
            .map_err(|e| Error::file(&settings.exe, e.to_string()))?
        {
            break Some(status);
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let seconds = started.elapsed().as_secs_f64();
    match status {
        None => {
            record.note = Some(format!("stopped after {:.0} s", limit.as_secs_f64()));
            return Ok(record);
        }
        Some(s) if !s.success() => {
            record.note = Some(format!("failed ({s})"));
            return Ok(record);
        }
        Some(_) => {}
    }
    record.seconds = Some(seconds);
    let result_path = out.join("result.json");
    if let Ok(text) = std::fs::read_to_string(&result_path) {
        let json: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| Error::file(&result_path, e.to_string()))?;
        record.peak_mib = json["budget"]["peak_memory_mib"]
            .as_f64()
            .or(json["peak_memory_mib"].as_f64());
        record.stages = json["timings_s"].clone();
        record.confidence = json["confidence"].as_f64();
    }
    if command.starts_with("p2p") || command == "pyfm" {
        let map_path = out.join("map_b_to_a.txt");
        let map = read_map(&map_path)?;
        record.error = Some(map_error(a, &map)?);
    }
    Ok(record)
}

fn read_map(path: &Path) -> Result<Vec<u32>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e.to_string()))?;
    text.split_whitespace()
        .map(|t| {
            t.parse::<u32>()
                .map_err(|e| Error::file(path, format!("{t:?}: {e}")))
        })
        .collect()
}

/// Mean geodesic error (edge-graph distance on A over sqrt(area of A)) of `SCORED_VERTICES`
/// seeded vertices of B: the truth is the same vertex of A.
fn map_error(a_path: &Path, p2p_ba: &[u32]) -> Result<f64> {
    let a = Shape::read(a_path, ReadAs::Auto)?;
    if p2p_ba.len() != a.n_vertices() {
        return Err(Error::file(
            a_path,
            format!("a map of {} vertices for {}", p2p_ba.len(), a.n_vertices()),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    let graph = Neighbours::new(&a);
    let scale = 1.0 / a.mesh_area().sqrt();
    let total: f64 = (0..SCORED_VERTICES)
        .map(|_| {
            let v = rng.random_range(0..a.n_vertices()) as u32;
            graph.distance(v, p2p_ba[v as usize]) * scale
        })
        .sum();
    Ok(total / SCORED_VERTICES as f64)
}

/// Edge graph of a mesh, for a Dijkstra search that stops at its target (cost grows with
/// the error, not with the mesh).
struct Neighbours {
    positions: Vec<[f64; 3]>,
    adjacency: Vec<Vec<u32>>,
}

impl Neighbours {
    fn new(shape: &Shape) -> Neighbours {
        let mut adjacency = vec![Vec::new(); shape.n_vertices()];
        for (i, j) in shape.edges() {
            adjacency[i as usize].push(j);
            adjacency[j as usize].push(i);
        }
        Neighbours {
            positions: shape.vertices().to_vec(),
            adjacency,
        }
    }

    fn distance(&self, from: u32, to: u32) -> f64 {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        let length = |i: u32, j: u32| {
            let (p, q) = (self.positions[i as usize], self.positions[j as usize]);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let mut best: HashMap<u32, f64> = HashMap::from([(from, 0.0)]);
        let mut heap = BinaryHeap::from([Reverse((Ordered(0.0), from))]);
        while let Some(Reverse((Ordered(d), v))) = heap.pop() {
            if v == to {
                return d;
            }
            if d > best[&v] {
                continue;
            }
            for &w in &self.adjacency[v as usize] {
                let dw = d + length(v, w);
                if best.get(&w).is_none_or(|&old| dw < old) {
                    best.insert(w, dw);
                    heap.push(Reverse((Ordered(dw), w)));
                }
            }
        }
        f64::INFINITY
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Ordered(f64);
impl Eq for Ordered {}
impl PartialOrd for Ordered {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Ordered {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The processor's model name (Linux), or "unknown processor".
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown processor".into())
}

/// Slope of log(seconds) against log(vertices) by least squares over the sizes from `from`.
pub fn log_log_slope(points: &[(usize, f64)], from: usize) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(n, _)| *n >= from)
        .map(|&(n, t)| ((n as f64).ln(), t.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let m = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / m,
        pts.iter().map(|p| p.1).sum::<f64>() / m,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    Some(sxy / sxx)
}

/// The page: one row per size, the slopes, the machine; and the log-log PNG beside it.
pub fn scale_page(records: &[ScaleRecord], command: &str, png: &Path) -> Result<String> {
    let mut sizes: Vec<usize> = records.iter().map(|r| r.vertices).collect();
    sizes.sort_unstable();
    sizes.dedup();
    let get = |n: usize, c: &str| records.iter().find(|r| r.vertices == n && r.command == c);
    let cell = |n: usize, c: &str| -> String {
        match get(n, c) {
            Some(r) => match (r.seconds, &r.note) {
                (Some(s), _) => format!(
                    "{s:.2} s, {} MiB{}{}",
                    fmt(r.peak_mib, 0),
                    r.error.map_or(String::new(), |e| format!(", error {e:.4}")),
                    r.confidence
                        .filter(|&c| c < shapecorr::maps::hypotheses::DOUBTFUL_BELOW)
                        .map_or(String::new(), |c| format!(" (doubtful: confidence {c:.2})"))
                ),
                (None, Some(note)) => note.clone(),
                (None, None) => "-".into(),
            },
            None => "-".into(),
        }
    };
    let mut s = String::new();
    s.push_str("# Dense meshes: time, memory and accuracy against size\n\n");
    s.push_str(&format!(
        "Made by `{command}` on {} ({} cores, {}). Generated humanoid pairs (pose 0 -> pose 3, \
         limb thickness 1.2; above 200K vertices the figure split 1:4 at edge midpoints); \
         each command a fresh process of the tool, wall time with file reading and writing, \
         peak resident memory of that process. `match` and `p2p` run as shipped (proxies of \
         about 8K vertices above 12K); `full` is the full-resolution path (`--proxy-above 0`); \
         pyFM is WKS + ZoomOut (tests/bench/scale_pyfm.py, its README recipe). Error: mean \
         geodesic error (edge graph) of 500 seeded vertices over sqrt(area); the truth is \
         exact at every size.\n\n",
        std::env::consts::ARCH,
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        cpu_model()
    ));
    s.push_str(
        "| vertices | match | p2p | match full | p2p full | pyFM |\n|---|---|---|---|---|---|\n",
    );
    for &n in &sizes {
        s.push_str(&format!(
            "| {n} | {} | {} | {} | {} | {} |\n",
            cell(n, "match"),
            cell(n, "p2p"),
            cell(n, "match full"),
            cell(n, "p2p full"),
            cell(n, "pyfm")
        ));
    }
    let series_of = |c: &str| -> Vec<(usize, f64)> {
        sizes
            .iter()
            .filter_map(|&n| get(n, c).and_then(|r| r.seconds).map(|t| (n, t)))
            .collect()
    };
    s.push_str("\nLog-log slope of time against vertices from 50K up:");
    for c in ["match", "p2p", "match full", "p2p full"] {
        if let Some(slope) = log_log_slope(&series_of(c), 50_000) {
            s.push_str(&format!(" {c} {slope:.2};"));
        }
    }
    s.push('\n');
    let mut series = Vec::new();
    for c in ["match", "p2p", "match full", "p2p full", "pyfm"] {
        let points: Vec<(f64, f64)> = series_of(c)
            .into_iter()
            .map(|(n, t)| ((n as f64).log10(), t.log10()))
            .collect();
        if !points.is_empty() {
            series.push(Series {
                label: format!("{c} (time)"),
                points,
            });
        }
    }
    let memory: Vec<(f64, f64)> = sizes
        .iter()
        .filter_map(|&n| get(n, "p2p").and_then(|r| r.peak_mib).map(|m| (n, m)))
        .map(|(n, m)| ((n as f64).log10(), (m / 1024.0).log10()))
        .collect();
    if !memory.is_empty() {
        series.push(Series {
            label: "p2p peak memory (GiB)".into(),
            points: memory,
        });
    }
    if !series.is_empty() {
        let xs = series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
        let ys: Vec<f64> = series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .collect();
        let (x_min, x_max) = xs.fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
        let y_min = ys.iter().copied().fold(f64::MAX, f64::min);
        let y_max = ys.iter().copied().fold(f64::MIN, f64::max);
        line_chart_png(
            png,
            &Chart {
                title: "Time and memory against vertices (log10-log10)",
                x_label: "log10 vertices per shape",
                y_label: "log10 seconds / log10 GiB",
                x_range: (x_min - 0.1, x_max + 0.1),
                y_range: (y_min.floor(), y_max.ceil()),
            },
            &series,
        )?;
        s.push_str(&format!(
            "\n![time and memory against vertices]({})\n",
            png.file_name()
                .map_or("scale.png".into(), |f| f.to_string_lossy())
        ));
    }
    Ok(s)
}
