//! The files around a job: values files read strictly and exactly, outputs that never
//! replace an input and are written whole or not at all, standard output that cannot be
//! written. Each ends with a clear one-line error (or works), never a panic or a hang.
//! Unix only: /dev/full, FIFOs, hard and symbolic links.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{self, assert_clean_failure, shapecorr, shapecorr_within, stderr};

/// Vertices of the figures: `synth --vertices 800` gives 776.
const VERTICES: &str = "800";

fn scratch(name: &str) -> PathBuf {
    common::scratch("files", name)
}

/// Figures A (pose 0) and B (pose 3) in `dir`, and A's vertex count.
fn pair(dir: &Path) -> (PathBuf, PathBuf, usize) {
    let (a, b) = (dir.join("a.ply"), dir.join("b.ply"));
    common::synth_figure("humanoid", "0", VERTICES, &a);
    common::synth_figure("humanoid", "3", VERTICES, &b);
    let info = shapecorr(&["info", a.to_str().unwrap(), "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    (a, b, info["n_vertices"].as_u64().unwrap() as usize)
}

/// A values file at `path`: `row` repeated `rows` times.
fn values_file(path: &Path, row: &str, rows: usize) -> PathBuf {
    std::fs::write(path, format!("{row}\n").repeat(rows)).unwrap();
    path.to_path_buf()
}

fn transfer(a: &Path, b: &Path, values: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "transfer",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--values",
        values.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ];
    args.extend(extra);
    shapecorr_within(&args, Duration::from_secs(120)).expect("transfer ends")
}

#[test]
fn a_full_standard_output_is_a_one_line_error_not_a_panic() {
    let dir = scratch("devfull");
    let (a, _, _) = pair(&dir);
    let a = a.to_str().unwrap();
    let out = dir.join("m");
    let runs: [&[&str]; 4] = [
        &["info", a],
        &["info", a, "--json"],
        &["eigen", a, "--k", "10"],
        &["match", a, a, "--out", out.to_str().unwrap(), "--quiet"],
    ];
    for args in runs {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let run = Command::new(env!("CARGO_BIN_EXE_shapecorr"))
            .args(args)
            .stdout(full)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(1), "{args:?}: {}", stderr(&run));
        assert_clean_failure(&run, &["standard output: cannot write", "No space left"]);
        assert_eq!(stderr(&run).lines().count(), 1, "{}", stderr(&run));
    }
}

#[test]
fn values_with_an_empty_field_or_a_non_ascii_separator_are_refused() {
    let dir = scratch("parsing");
    let (a, b, n) = pair(&dir);
    let out = dir.join("o.txt");
    for (name, row, needle) in [
        (
            "empty.txt",
            "0.5,,0.25",
            "line 1: column 2 is empty (between two commas)",
        ),
        (
            "trailing.txt",
            "0.5,0.25,",
            "line 1: column 3 is empty (after the last comma)",
        ),
        (
            "nbsp.txt",
            "1\u{a0}2 3",
            "line 1: byte 2 is U+00A0 (a non-breaking space)",
        ),
    ] {
        let values = values_file(&dir.join(name), row, n);
        let run = transfer(&a, &b, &values, &out, &[]);
        assert_clean_failure(&run, &[name, needle]);
        assert!(!out.exists(), "{name}: an output was written");
    }
}

#[test]
fn integers_beyond_2_pow_53_are_carried_exactly_by_nearest_and_refused_by_averaging() {
    let dir = scratch("ids");
    let (a, b, n) = pair(&dir);
    // Every vertex of A has the same two ids, so every vertex of B must get them.
    let values = values_file(
        &dir.join("ids.txt"),
        "9007199254740993 18446744073709551615",
        n,
    );
    let out = dir.join("o.txt");
    let run = transfer(&a, &b, &values, &out, &["--mode", "nearest"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.lines().count() > 0);
    for line in text.lines() {
        assert_eq!(line, "9007199254740993 18446744073709551615");
    }
    std::fs::remove_file(&out).unwrap();
    let run = transfer(&a, &b, &values, &out, &[]);
    assert_clean_failure(&run, &["is the integer 9007199254740993", "`nearest` mode"]);
    assert!(!out.exists());
}

#[test]
fn a_negative_max_influences_is_refused_with_the_reason() {
    let dir = scratch("influences");
    let (a, b, n) = pair(&dir);
    let values = values_file(&dir.join("w.txt"), "0.5 0.5", n);
    let run = transfer(
        &a,
        &b,
        &values,
        &dir.join("o.txt"),
        &["--max-influences", "-1"],
    );
    assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
    assert_clean_failure(&run, &["--max-influences", "-1 is negative"]);
}

#[test]
fn a_special_values_file_is_refused_at_once() {
    let dir = scratch("special");
    let (a, b, _) = pair(&dir);
    let fifo = dir.join("fifo.txt");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for values in [Path::new("/dev/zero"), &fifo, &dir] {
        let started = Instant::now();
        let run = transfer(&a, &b, values, &dir.join("o.txt"), &[]);
        assert!(started.elapsed() < Duration::from_secs(20));
        assert_clean_failure(&run, &[values.to_str().unwrap(), "not a regular file"]);
    }
}

#[test]
fn an_output_over_an_input_is_refused_and_nothing_is_written() {
    let dir = scratch("overwrite");
    let (a, b, n) = pair(&dir);
    let values = values_file(&dir.join("v.txt"), "1 2 3", n);
    let before = |p: &Path| std::fs::read(p).unwrap();
    let (mesh_a, mesh_b, text) = (before(&a), before(&b), before(&values));
    let hard = dir.join("hard.ply");
    std::fs::hard_link(&a, &hard).unwrap();
    let soft = dir.join("soft.txt");
    std::os::unix::fs::symlink(&b, &soft).unwrap();
    for (out, input) in [
        (&a, &a),
        (&b, &b),
        (&values, &values),
        (&hard, &a),
        (&soft, &b),
    ] {
        let run = transfer(&a, &b, &values, out, &[]);
        assert_clean_failure(&run, &["is the input", input.to_str().unwrap()]);
    }
    let sm = ["--surface-map", a.to_str().unwrap()];
    let run = transfer(&a, &b, &values, &dir.join("o.txt"), &sm);
    assert_clean_failure(&run, &["is the input"]);
    let o = dir.join("o.txt");
    let sm = ["--surface-map", o.to_str().unwrap()];
    let run = transfer(&a, &b, &values, &o, &sm);
    assert_clean_failure(&run, &["named for two outputs"]);
    assert_eq!(before(&a), mesh_a);
    assert_eq!(before(&b), mesh_b);
    assert_eq!(before(&values), text);
    assert!(!o.exists());
}

#[test]
fn a_failed_transfer_leaves_an_existing_output_as_it_was() {
    let dir = scratch("failed");
    let (a, b, n) = pair(&dir);
    let out = dir.join("o.txt");
    std::fs::write(&out, "earlier result\n").unwrap();
    // One row short: refused after the shapes are read, before anything is written.
    let values = values_file(&dir.join("v.txt"), "1 2", n - 1);
    let run = transfer(&a, &b, &values, &out, &[]);
    assert_clean_failure(&run, &["rows of values"]);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "earlier result\n");
    // The job runs, the second output cannot be written: the first is not replaced either.
    let values = values_file(&dir.join("v.txt"), "1 2", n);
    let run = transfer(&a, &b, &values, &out, &["--surface-map", "/dev/full"]);
    assert_clean_failure(&run, &["/dev/full: cannot write"]);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "earlier result\n");
    let leftovers = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with(".shapecorr-")
        })
        .count();
    assert_eq!(leftovers, 0);
}

#[test]
fn match_out_naming_a_file_or_an_input_says_what_to_do() {
    let dir = scratch("match-out");
    let (a, b, _) = pair(&dir);
    let file = dir.join("file");
    std::fs::write(&file, "x").unwrap();
    let run = shapecorr(&[
        "match",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        file.to_str().unwrap(),
    ]);
    assert_clean_failure(&run, &["`--out` names the folder", "remove the file"]);
    // A is the file `match` would write its colours of A to.
    let a_there = dir.join("a_regions.ply");
    std::fs::copy(&a, &a_there).unwrap();
    let run = shapecorr(&[
        "match",
        a_there.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_clean_failure(&run, &["is the input"]);
}
