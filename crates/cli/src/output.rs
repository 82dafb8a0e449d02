//! What the commands write: standard output (errors returned, never a panic), JSON files,
//! coloured PLYs, map files, output files written whole or not at all, and the progress line.

use std::path::{Path, PathBuf};

use serde_json::json;
use shapecorr::colors::{coordinate_colors, region_colors};
use shapecorr::maps::hypotheses::{Decision, HypothesisScore, Verdict};
use shapecorr::maps::placement::Placement;
use shapecorr::options::{OptionGroup, OptionValue, Options, OPTIONS};
use shapecorr::pipeline::multiresolution::Working;
use shapecorr::pipeline::Correspondence;
use shapecorr::progress::{Progress, Stage};
use shapecorr::regions::graph::ShapeGraph;
use shapecorr::{Error, Params, Shape};

/// `println!` that returns an error instead of panicking when standard output cannot be
/// written (`> /dev/full`, a full disk). A closed pipe (`| head`) ends the tool quietly
/// (SIGPIPE, main.rs).
macro_rules! outln {
    () => {
        $crate::output::write_stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}
pub(crate) use outln;

/// `print!` as [`outln`].
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!($($arg)*))
    };
}
pub(crate) use out;

/// `eprintln!` that never panics: when standard error cannot be written, nothing can be
/// said there, and the exit status still tells.
macro_rules! errln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}
pub(crate) use errln;

/// Writes to standard output and flushes: what [`outln`] and [`out`] call.
pub fn write_stdout(args: std::fmt::Arguments) -> Result<(), Error> {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_fmt(args)
        .and_then(|()| stdout.flush())
        .map_err(|e| Error::file("standard output", format!("cannot write: {e}")))
}

/// No progress at all (`--quiet`).
pub static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// How often progress is written as lines when stderr is not a terminal.
const LINE_INTERVAL: std::time::Duration = std::time::Duration::from_secs(1);

/// Stage progress on stderr: on a terminal one line redrawn in place; otherwise (a log
/// file, a pipe, CI) a line `shapecorr: progress: STAGE NN% (T s)` at most once a second,
/// the first after a second of work (so a quick command prints none). `--quiet`: nothing.
pub struct TerminalProgress {
    started: std::time::Instant,
    last_line: Option<std::time::Instant>,
}

impl Default for TerminalProgress {
    fn default() -> Self {
        Self::new()
    }
}

impl TerminalProgress {
    pub fn new() -> Self {
        TerminalProgress {
            started: std::time::Instant::now(),
            last_line: None,
        }
    }
}

impl Progress for TerminalProgress {
    fn report(&mut self, stage: Stage, fraction: f32) -> bool {
        use std::io::{IsTerminal, Write};
        if QUIET.load(std::sync::atomic::Ordering::Relaxed) {
            return true;
        }
        let mut stderr = std::io::stderr();
        let stage = format!("{stage:?}");
        if stderr.is_terminal() {
            let _ = write!(stderr, "\r{stage:<16} {:>3.0}%", 100.0 * fraction);
            let _ = stderr.flush();
            return true;
        }
        let since = self.last_line.unwrap_or(self.started).elapsed();
        if since >= LINE_INTERVAL {
            self.last_line = Some(std::time::Instant::now());
            let elapsed = self.started.elapsed().as_secs_f64();
            let _ = writeln!(
                stderr,
                "shapecorr: progress: {stage} {:.0}% ({elapsed:.0} s)",
                100.0 * fraction
            );
        }
        true
    }
}

/// Ends the progress line, if one was drawn.
pub fn end_progress_line() {
    use std::io::IsTerminal;
    if std::io::stderr().is_terminal() && !QUIET.load(std::sync::atomic::Ordering::Relaxed) {
        errln!();
    }
}

/// Creates the output folder `out` (`--out`); says what to do when `out` is a file.
pub fn create_dir(out: &Path) -> Result<(), Error> {
    if out.exists() && !out.is_dir() {
        return Err(Error::file(
            out,
            "`--out` names the folder the results are written into, and this is a file: \
             choose a folder (created if missing), or remove the file",
        ));
    }
    std::fs::create_dir_all(out)
        .map_err(|e| Error::file(out, format!("cannot create the output folder: {e}")))
}

/// [`create_dir`] for the files `names`, after checking that none of them is one of
/// `inputs` ([`refuse_inputs`]): a result never replaces an input.
pub fn create_out_dir(out: &Path, names: &[&str], inputs: &[&Path]) -> Result<(), Error> {
    let files: Vec<PathBuf> = names.iter().map(|n| out.join(n)).collect();
    refuse_inputs(
        &files.iter().map(PathBuf::as_path).collect::<Vec<_>>(),
        inputs,
    )?;
    create_dir(out)
}

/// Refuses when an output is one of the inputs, or two outputs are one file: the same file
/// also through a hard or symbolic link (`same-file` compares device and inode, or the
/// Windows file index).
pub fn refuse_inputs(outputs: &[&Path], inputs: &[&Path]) -> Result<(), Error> {
    for (k, output) in outputs.iter().enumerate() {
        for input in inputs {
            if same_file::is_same_file(output, input).unwrap_or(false) {
                return Err(Error::file(
                    output,
                    format!(
                        "is the input {}: an output never replaces an input; write it \
                         elsewhere",
                        input.display()
                    ),
                ));
            }
        }
        let twice = outputs[..k]
            .iter()
            .any(|o| o == output || same_file::is_same_file(o, output).unwrap_or(false));
        if twice {
            return Err(Error::file(
                output,
                "named for two outputs; give each its own file",
            ));
        }
    }
    Ok(())
}

/// Checks that `path` can be an output file: not a folder, in a folder that exists.
/// Done before the work, so that a wrong path fails at once.
pub fn check_output_file(path: &Path) -> Result<(), Error> {
    if path.is_dir() {
        return Err(Error::file(path, "is a folder; name the file to write"));
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        return Err(Error::file(
            path,
            format!("the folder {} does not exist", parent.display()),
        ));
    }
    Ok(())
}

/// Writes every file of `files` whole, or none of them where it can: each is first written
/// to a temporary file in its destination's folder, and the temporary files replace the
/// destinations only when all are written. An existing destination that is not a regular
/// file (`/dev/null`, a FIFO) is written in place, before the others are renamed; a
/// symbolic link is followed.
pub fn write_files(files: &[(&Path, &[u8])]) -> Result<(), Error> {
    let mut staged = Vec::with_capacity(files.len());
    for &(path, bytes) in files {
        staged.push(Staged::write(path, bytes)?);
    }
    // Files written in place first: they are the ones whose writing can still fail.
    staged.sort_by_key(|file| matches!(file, Staged::Temporary(..)));
    for file in staged {
        file.commit()?;
    }
    Ok(())
}

/// A file of [`write_files`] written but not yet in place.
enum Staged<'a> {
    Temporary(tempfile::NamedTempFile, PathBuf),
    InPlace(&'a Path, &'a [u8]),
}

impl<'a> Staged<'a> {
    fn write(path: &'a Path, bytes: &'a [u8]) -> Result<Staged<'a>, Error> {
        use std::io::Write;
        let cannot = |e: std::io::Error| Error::file(path, format!("cannot write: {e}"));
        match std::fs::metadata(path) {
            Ok(meta) if meta.is_dir() => {
                return Err(Error::file(path, "is a folder; name the file to write"))
            }
            Ok(meta) if !meta.is_file() => return Ok(Staged::InPlace(path, bytes)),
            _ => {}
        }
        let target = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let folder = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let mut builder = tempfile::Builder::new();
        builder.prefix(".shapecorr-");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // As a file created in place: read-write for all, less the umask.
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let mut temp = builder.tempfile_in(folder).map_err(cannot)?;
        temp.write_all(bytes)
            .and_then(|()| temp.as_file().sync_all())
            .map_err(cannot)?;
        Ok(Staged::Temporary(temp, target))
    }

    fn commit(self) -> Result<(), Error> {
        match self {
            Staged::Temporary(temp, target) => temp
                .persist(&target)
                .map(drop)
                .map_err(|e| Error::file(&target, format!("cannot write: {}", e.error))),
            Staged::InPlace(path, bytes) => std::fs::write(path, bytes)
                .map_err(|e| Error::file(path, format!("cannot write: {e}"))),
        }
    }
}

pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), Error> {
    let text = serde_json::to_string_pretty(value).unwrap_or_default();
    std::fs::write(path, text).map_err(|e| Error::file(path, e.to_string()))
}

/// The value of every option used, by name (the region options, and with `pointwise` the
/// pointwise map's too): what `result.json` records as `options`.
pub fn options_json(options: &Options, pointwise: bool) -> serde_json::Value {
    let values: serde_json::Map<String, serde_json::Value> = OPTIONS
        .iter()
        .filter(|o| pointwise || o.group == OptionGroup::Regions)
        .filter_map(|o| {
            let value = match options.option(o.name).ok()? {
                OptionValue::Int(v) => json!(v),
                OptionValue::Float(v) => json!(v),
                OptionValue::Bool(v) => json!(v),
            };
            Some((o.name.to_string(), value))
        })
        .collect();
    serde_json::Value::Object(values)
}

pub fn graph_json(graph: &ShapeGraph) -> serde_json::Value {
    json!({
        "n_nodes": graph.n_nodes(),
        "node_area": graph.node_area,
        "node_cluster": graph.node_cluster,
        "node_descriptor": graph.node_descriptor,
        "edges": graph.edges,
    })
}

/// Peak resident memory of this process (Linux `VmHWM`), in MiB.
pub fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// `result.json`'s `budget`: the job's estimated peak memory and time (what the memory
/// ceiling and the time limit were checked against) and the process's measured peak.
pub fn budget_json(estimate: &shapecorr::pipeline::budget::Estimate) -> serde_json::Value {
    json!({
        "memory_estimate_mib": estimate.mib(),
        "time_estimate_s": estimate.seconds,
        "peak_memory_mib": peak_memory_mib(),
    })
}

/// A shape's warnings and the pair's about it (objects touching the figure left out or
/// not tried).
fn warnings_of(shape: &Shape, working: &Working) -> Vec<String> {
    let pair = working.pair_warnings();
    (shape.warnings().iter().chain(&pair))
        .map(|w| w.to_string())
        .collect()
}

/// Prints on stderr the pair job's warnings about either shape: objects touching a figure
/// that the pair matched better without, or that the time limit kept it from trying.
pub fn print_pair_warnings(working: &[Working; 2], [a, b]: [&std::path::Path; 2]) {
    for ((side, path), w) in [('A', a), ('B', b)].into_iter().zip(working) {
        for warning in w.pair_warnings() {
            let what = if warning.is_repair() {
                "repaired"
            } else {
                "warning:"
            };
            errln!("shapecorr: {what} {side} ({}): {warning}", path.display());
        }
    }
}

/// What `result.json` records of a region correspondence, with [`set_verdict_json`]'s keys.
pub fn correspondence_json(a: &Shape, b: &Shape, result: &Correspondence) -> serde_json::Value {
    let mut value = json!({
        "version": env!("CARGO_PKG_VERSION"),
        "n_vertices_a": a.n_vertices(),
        "n_vertices_b": b.n_vertices(),
        "kind_a": a.kind(),
        "kind_b": b.kind(),
        "working_a": result.working[0],
        "working_b": result.working[1],
        "k": result.k,
        "regions_a": result.regions_a(),
        "regions_b": result.regions_b(),
        "matches": result.matches,
        "matches_one_to_one": result.matches_one_to_one,
        "graph_a": graph_json(&result.graph_a),
        "graph_b": graph_json(&result.graph_b),
        "timings_s": result.timings,
        "warnings_a": warnings_of(a, &result.working[0]),
        "warnings_b": warnings_of(b, &result.working[1]),
    });
    set_verdict_json(&mut value, result.verdict.as_ref());
    value
}

/// Sets the keys of `result.json` that say how sure the answer is: `confidence` (in [0, 1],
/// null when the answer was not verified), `doubtful`, `warning` (the verdict's sentence
/// when doubtful, else null), `hypotheses` (every hypothesis verified, with its map's
/// energy, the turn it implies, whether it was chosen and whether the placement or the
/// landmarks ruled it out; empty when not verified), `chosen` (the chosen hypothesis and
/// what decided it) and `runner_up` (the cheapest other hypothesis giving a different map:
/// the other answer); the last two are null when not verified, `runner_up` also when no
/// other hypothesis gives a different map.
pub fn set_verdict_json(value: &mut serde_json::Value, verdict: Option<&Verdict>) {
    let hypotheses: Vec<serde_json::Value> = verdict
        .map(|v| {
            v.scores
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    let mut h = hypothesis_json(s);
                    h["chosen"] = json!(i == v.chosen);
                    h["ruled_out"] = json!(v.ruled_out.get(i).copied().unwrap_or(false));
                    h["distortion"] = json!(s.energy.distortion);
                    h["coverage"] = json!(s.energy.coverage);
                    h["orientation"] = json!(s.energy.orientation);
                    h["residual"] = json!(s.energy.residual);
                    h
                })
                .collect()
        })
        .unwrap_or_default();
    value["confidence"] = json!(verdict.map(|v| v.confidence));
    value["doubtful"] = json!(verdict.is_some_and(Verdict::doubtful));
    value["warning"] = json!(verdict.and_then(Verdict::warning));
    value["hypotheses"] = json!(hypotheses);
    value["chosen"] = verdict.map_or(serde_json::Value::Null, |v| {
        let mut chosen = hypothesis_json(v.chosen());
        chosen["decided_by"] = json!(v.decided_by.name());
        chosen
    });
    value["runner_up"] = verdict
        .and_then(|v| Some(hypothesis_json(&v.scores[v.runner_up()?])))
        .unwrap_or_default();
}

/// A hypothesis as `result.json` names it: its kind, cost ([`MapEnergy::cost`], lower is
/// better), the rigid turn its map implies between B and A (degrees) and how far it carries
/// the landmarks from their partners (null without landmarks).
///
/// [`MapEnergy::cost`]: shapecorr::maps::hypotheses::MapEnergy::cost
fn hypothesis_json(score: &HypothesisScore) -> serde_json::Value {
    json!({
        "kind": score.kind.name(),
        "cost": score.energy.cost(),
        "turn_degrees": score.turn_degrees,
        "landmark_error": score.landmark_error,
    })
}

/// Sets the keys of `result.json` on what the user gave beyond the shapes:
/// `placement` (`mode`: `auto`, `ignore` or `trust`; `used`: whether the shapes' placement
/// decided the answer) and `landmarks` (the pairs, A's vertex then B's).
pub fn set_guidance_json(
    value: &mut serde_json::Value,
    params: &Params,
    verdict: Option<&Verdict>,
) {
    value["placement"] = json!({
        "mode": params.placement.name(),
        "used": verdict.is_some_and(|v| v.decided_by == Decision::Placement),
    });
    value["landmarks"] = json!(params.landmarks);
}

/// The folder of a command's output folder where the runner-up's answer is written, with
/// the same files as the answer.
pub const OTHER_DIR: &str = "other";

/// `names` in [`OTHER_DIR`], for [`create_out_dir`].
pub fn other_names(names: &[&str]) -> Vec<String> {
    names.iter().map(|n| format!("{OTHER_DIR}/{n}")).collect()
}

/// Removes the files `names` of [`OTHER_DIR`] in `out` (and the folder when that leaves it
/// empty): a result without a runner-up must not sit next to an earlier run's other answer.
pub fn clear_other(out: &Path, names: &[&str]) -> Result<(), Error> {
    let dir = out.join(OTHER_DIR);
    if !dir.is_dir() {
        return Ok(());
    }
    for name in names {
        let path = dir.join(name);
        if path.is_file() {
            std::fs::remove_file(&path).map_err(|e| {
                Error::file(&path, format!("cannot remove an earlier run's file: {e}"))
            })?;
        }
    }
    // Only when empty: a file the user put there stays.
    let _ = std::fs::remove_dir(&dir);
    Ok(())
}

/// The summary line on how the answer was chosen (None when it was not verified): the
/// hypothesis, its cost and turn, what decided it, the placement mode, and the runner-up's
/// cost and turn, with `other` (where its answer is, or how to get it) when there is one.
pub fn choice_summary(verdict: Option<&Verdict>, params: &Params, other: &str) -> Option<String> {
    let v = verdict?;
    let chosen = v.chosen();
    let placement = match (params.placement, v.decided_by) {
        (_, Decision::Placement) => format!("--placement {}: used", params.placement.name()),
        (mode, _) => format!("--placement {}: not used", mode.name()),
    };
    let other = if other.is_empty() {
        String::new()
    } else {
        format!(" {other}")
    };
    let runner_up = match v.runner_up().map(|h| &v.scores[h]) {
        Some(r) => format!(
            "runner-up: `{}` (cost {:.4}, turn {:.0} degrees){other}",
            r.kind.name(),
            r.energy.cost(),
            r.turn_degrees
        ),
        None => "no runner-up (every other hypothesis gives the same map)".to_string(),
    };
    Some(format!(
        "chosen: `{}` hypothesis (cost {:.4}, turn {:.0} degrees), decided by {} ({placement}); \
         {runner_up}",
        chosen.kind.name(),
        chosen.energy.cost(),
        chosen.turn_degrees,
        v.decided_by.name(),
    ))
}

/// Prints the verdict's warning on stderr when the answer is doubtful ([`print_warning`]),
/// then a line on what to do about it: `look` (where the runner-up's answer is, or how to
/// get it) when there is a runner-up, landmarks, and `--placement trust` unless it was.
pub fn print_doubtful(verdict: Option<&Verdict>, params: &Params, look: &str) {
    print_warning(verdict);
    let Some(v) = verdict.filter(|v| v.doubtful()) else {
        return;
    };
    let mut steps = Vec::new();
    if v.runner_up().is_some() {
        steps.push(look.to_string());
    }
    steps.push(if params.landmarks.is_empty() {
        "give two landmark pairs with --landmarks FILE (say a left hand and a left foot, a \
         vertex of A then its partner on B)"
            .to_string()
    } else {
        "give more landmark pairs in the --landmarks file".to_string()
    });
    if params.placement != Placement::Trust {
        steps.push("use --placement trust when the shapes stand alike".to_string());
    }
    let last = steps.pop().unwrap_or_default();
    let steps = if steps.is_empty() {
        last
    } else {
        format!("{}, or {last}", steps.join(", "))
    };
    errln!("shapecorr: to check or correct it: {steps} (docs/placement.md)");
}

/// How sure the answer is, for the one-line summary: `confidence 0.93`, `confidence 0.31,
/// doubtful` or `not verified` (no confidence).
pub fn confidence_summary(verdict: Option<&Verdict>) -> String {
    match verdict {
        Some(v) if v.doubtful() => format!("confidence {:.2}, doubtful", v.confidence),
        Some(v) => format!("confidence {:.2}", v.confidence),
        None => "not verified".to_string(),
    }
}

/// Prints the verdict's warning on stderr, one line, when the answer is doubtful.
pub fn print_warning(verdict: Option<&Verdict>) {
    if let Some(warning) = verdict.and_then(Verdict::warning) {
        errln!("shapecorr: warning: {}", warning.replace(['\n', '\r'], " "));
    }
}

/// Writes the coloured PLYs of a correspondence; colours by the one-to-one matches when
/// there are any, else by the symmetric groups.
pub fn write_colored(
    out: &Path,
    a: &Shape,
    b: &Shape,
    result: &Correspondence,
) -> Result<(), Error> {
    let pairs = if result.matches_one_to_one.is_empty() {
        &result.matches
    } else {
        &result.matches_one_to_one
    };
    let (colors_a, colors_b) = region_colors(
        result.regions_a(),
        result.graph_a.n_nodes(),
        result.regions_b(),
        result.graph_b.n_nodes(),
        pairs,
    );
    shapecorr::shape::io::write_ply(
        &out.join("a_regions.ply"),
        a.vertices(),
        a.triangles(),
        Some(&colors_a),
    )?;
    shapecorr::shape::io::write_ply(
        &out.join("b_regions.ply"),
        b.vertices(),
        b.triangles(),
        Some(&colors_b),
    )
}

/// Writes `a_colors.ply` (A coloured by its normalised coordinates) and `b_mapped.ply` (B
/// with A's colours carried over by the map), to look at a map.
pub fn write_map_colors(out: &Path, a: &Shape, b: &Shape, p2p_ba: &[u32]) -> Result<(), Error> {
    let colors_a = coordinate_colors(a.vertices());
    let colors_b: Vec<[u8; 3]> = p2p_ba.iter().map(|&v| colors_a[v as usize]).collect();
    shapecorr::shape::io::write_ply(
        &out.join("a_colors.ply"),
        a.vertices(),
        a.triangles(),
        Some(&colors_a),
    )?;
    shapecorr::shape::io::write_ply(
        &out.join("b_mapped.ply"),
        b.vertices(),
        b.triangles(),
        Some(&colors_b),
    )
}

/// Writes a map file: one 0-based vertex index per line.
pub fn write_map(path: &Path, map: &[u32]) -> Result<(), Error> {
    let mut text = String::with_capacity(map.len() * 6);
    for v in map {
        text.push_str(&v.to_string());
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|e| Error::file(path, e.to_string()))
}
