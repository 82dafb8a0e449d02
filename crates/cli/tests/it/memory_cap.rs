//! Under an address-space limit (`ulimit -v`, as clusters and containers set), a 5K-vertex
//! `match`, `p2p` and `batch` run to the end under 1 GB, and under 300 MB fail with the
//! resource-limit error (exit 1, a one-line reason), never an abort. Before the fix every job
//! aborted there: faer's matrix-product scratch reserved twice the machine's L3 cache per
//! thread and glibc an arena of 64 MiB per thread (docs/decisions.md, "Address space").
//! Two threads (RAYON_NUM_THREADS), so that the limits mean the same on every machine.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::{scratch, synth_figure};

/// 1 GB and 300 MB, in KiB as `ulimit -v` takes them.
const ROOMY_KIB: u64 = 1_048_576;
const TIGHT_KIB: u64 = 307_200;

/// Runs the tool with `args` under an address-space limit of `kib` KiB.
fn capped(kib: u64, args: &[&str]) -> Output {
    std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_shapecorr"))
        .args(args)
        .env("RAYON_NUM_THREADS", "2")
        .output()
        .expect("sh runs")
}

/// Two 5K-vertex figures in two poses, made once per test.
fn pair(name: &str) -> (PathBuf, [String; 2]) {
    let dir = scratch("memory-cap", name);
    let files = ["a", "b"].map(|s| dir.join(format!("{s}.ply")));
    synth_figure("humanoid", "0", "5000", &files[0]);
    synth_figure("humanoid", "3", "5000", &files[1]);
    (dir, files.map(|f| f.to_str().unwrap().to_string()))
}

fn text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn assert_ran(out: &Output, what: &str) {
    assert!(
        out.status.success(),
        "{what} under 1 GB: {:?}\n{}",
        out.status,
        text(out)
    );
}

/// Exit 1 (not a signal, not a panic's 101) with the address-space reason.
fn assert_refused(out: &Output, what: &str) {
    let stderr = text(out);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{what} under 300 MB: {:?}\n{stderr}",
        out.status
    );
    assert!(
        stderr.contains("resource limit `address_space`") && stderr.contains("ulimit -v"),
        "{what} under 300 MB: {stderr}"
    );
    assert!(
        !stderr.contains("panicked") && !stderr.contains("memory allocation"),
        "{stderr}"
    );
}

fn out_arg(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().unwrap().to_string()
}

#[test]
fn match_and_p2p_run_under_1_gb_and_are_refused_under_300_mb() {
    let (dir, [a, b]) = pair("jobs");
    for command in ["match", "p2p"] {
        for (kib, name) in [(ROOMY_KIB, "roomy"), (TIGHT_KIB, "tight")] {
            let out_dir = out_arg(&dir, &format!("{command}-{name}"));
            let out = capped(kib, &[command, &a, &b, "--out", &out_dir, "--quiet"]);
            if kib == ROOMY_KIB {
                assert_ran(&out, command);
            } else {
                assert_refused(&out, command);
            }
        }
    }
}

#[test]
fn batch_runs_under_1_gb_and_fails_its_pair_under_300_mb() {
    let (dir, [a, b]) = pair("batch");
    let roomy = out_arg(&dir, "roomy");
    assert_ran(
        &capped(ROOMY_KIB, &["batch", &a, &b, "--out", &roomy, "--quiet"]),
        "batch",
    );
    let tight = out_arg(&dir, "tight");
    let out = capped(TIGHT_KIB, &["batch", &a, &b, "--out", &tight, "--quiet"]);
    let stderr = text(&out);
    assert!(
        out.status.code().is_some(),
        "batch under 300 MB killed by a signal: {stderr}"
    );
    assert!(
        !stderr.contains("panicked") && !stderr.contains("memory allocation"),
        "{stderr}"
    );
    let log = std::fs::read_to_string(Path::new(&tight).join("pairs.jsonl")).unwrap_or_default();
    assert!(
        log.contains("address_space"),
        "the pair's record names the limit: {log}\n{stderr}"
    );
}
