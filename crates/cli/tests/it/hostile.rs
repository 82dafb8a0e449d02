//! Robustness on the command line: odd file names, special files, extreme option values and
//! bad shapes in a pair end with a clear one-line error (or work), never a panic or a hang.
//! Unix only: it names files with non-UTF-8 bytes and links to /dev/zero.
#![cfg(unix)]

use std::ffi::OsString;
use std::os::unix::ffi::OsStringExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common;

use common::{assert_clean_failure, shapecorr, shapecorr_within, stderr};

fn scratch(name: &str) -> PathBuf {
    common::scratch("hostile", name)
}

fn synth(path: &Path, pose: &str) {
    common::synth_figure("humanoid", pose, "800", path);
}

#[test]
fn a_non_utf8_file_name_works_with_json() {
    let dir = scratch("utf8");
    let plain = dir.join("a.ply");
    synth(&plain, "0");
    let mut odd = dir.clone().into_os_string().into_vec();
    odd.extend_from_slice(b"/bad\xffname.ply");
    let odd = PathBuf::from(OsString::from_vec(odd));
    std::fs::rename(&plain, &odd).unwrap();
    for args in [
        vec![
            OsString::from("info"),
            OsString::from("--json"),
            odd.clone().into(),
        ],
        vec![
            "eigen".into(),
            "--json".into(),
            "--k".into(),
            "5".into(),
            odd.clone().into(),
        ],
    ] {
        let out = shapecorr(&args);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let file = value["file"].as_str().unwrap();
        assert!(file.ends_with("bad\u{fffd}name.ply"), "{file}");
    }
}

#[test]
fn a_fifo_or_a_device_is_refused_at_once() {
    let dir = scratch("special");
    let fifo = dir.join("f.ply");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let zero = dir.join("z.ply");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    for path in [&fifo, &zero, &dir.join("folder.ply")] {
        if !path.exists() {
            std::fs::create_dir(path).unwrap();
        }
        let started = Instant::now();
        let out = shapecorr_within(
            &["info".as_ref(), path.as_os_str()],
            Duration::from_secs(20),
        )
        .unwrap_or_else(|| panic!("{} hung", path.display()));
        assert!(started.elapsed() < Duration::from_secs(5));
        assert_clean_failure(&out, &["not a regular file", path.to_str().unwrap()]);
    }
}

#[test]
fn extreme_option_values_are_refused_naming_the_option_and_its_range() {
    let dir = scratch("options");
    let (a, b) = (dir.join("a.ply"), dir.join("b.ply"));
    synth(&a, "0");
    synth(&b, "3");
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let out_dir = dir.join("out");
    let out_dir = out_dir.to_str().unwrap();
    for (flag, value, needles) in [
        ("--k-min", "-1", ["k_min", "[2, 100]"]),
        ("--hks-times", "100000000", ["hks_times", "[1, 100]"]),
        (
            "--histogram-bins",
            "1000000000000",
            ["histogram_bins", "[1, 1000]"],
        ),
        ("--threads", "1000000000000", ["threads", "[0, 1024]"]),
        ("--sigma", "1e300", ["sigma", "[0.001, 100]"]),
        (
            "--p2p-eigenpairs",
            "1000000",
            ["p2p_eigenpairs", "[2, 1000]"],
        ),
    ] {
        let out = shapecorr(&["p2p", a, b, "--out", out_dir, flag, value]);
        assert_clean_failure(&out, &needles);
        assert_eq!(
            out.status.code(),
            Some(2),
            "a usage error: {}",
            stderr(&out)
        );
    }
    // eigen's own --threads: clamped to the cores, it works at once.
    let out = shapecorr_within(
        &["eigen", a, "--k", "5", "--threads", "1000000000000"],
        Duration::from_secs(60),
    )
    .expect("eigen --threads 1e12 hung");
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_bad_shape_in_a_pair_names_its_side_and_file() {
    let dir = scratch("pair");
    let good = dir.join("good.ply");
    synth(&good, "0");
    let bad = dir.join("bad.off");
    let mut text = String::from("OFF\n40 1 0\n");
    for i in 0..40 {
        text.push_str(&format!("{} {} {}\n", i, i * i, 1));
    }
    text.push_str("3 0 1 99\n");
    std::fs::write(&bad, text).unwrap();
    let out_dir = dir.join("out");
    for command in ["match", "p2p"] {
        let out = shapecorr(&[
            command,
            good.to_str().unwrap(),
            bad.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
        ]);
        assert_clean_failure(&out, &["shape B", bad.to_str().unwrap(), "vertex 99"]);
        let out = shapecorr(&[
            command,
            bad.to_str().unwrap(),
            good.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
        ]);
        assert_clean_failure(&out, &["shape A", bad.to_str().unwrap()]);
    }
}

/// Stderr that is not a terminal gets progress lines (at most one a
/// second), `--quiet` none.
#[test]
fn progress_is_written_as_lines_when_stderr_is_not_a_terminal() {
    let dir = scratch("progress");
    let (a, b) = (dir.join("a.ply"), dir.join("b.ply"));
    synth(&a, "0");
    synth(&b, "3");
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let out_dir = dir.join("out");
    // 1000 k-means restarts (the most allowed): about 5 s of segmentation on 800 vertices
    // (400 took about 2 s, once too close to the first line at 1 s in CI).
    let args = [
        "match",
        a,
        b,
        "--out",
        out_dir.to_str().unwrap(),
        "--kmeans-restarts",
        "1000",
    ];
    let out = shapecorr(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let lines: Vec<String> = stderr(&out)
        .lines()
        .filter(|l| l.starts_with("shapecorr: progress: "))
        .map(str::to_string)
        .collect();
    assert!(!lines.is_empty(), "no progress lines: {}", stderr(&out));
    assert!(
        lines.iter().any(|l| l.contains("Segmentation")),
        "{lines:?}"
    );
    let quiet = shapecorr(&[&args[..], &["--quiet"]].concat());
    assert!(quiet.status.success());
    assert!(!stderr(&quiet).contains("progress"), "{}", stderr(&quiet));
}

#[test]
fn a_closed_pipe_ends_the_tool_quietly() {
    let dir = scratch("pipe");
    let shape = dir.join("h.ply");
    synth(&shape, "0");
    let mut child = Command::new(env!("CARGO_BIN_EXE_shapecorr"))
        .args(["eigen", shape.to_str().unwrap(), "--k", "20"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The reader goes away before the tool prints (as `| head -0`): every line it then
    // writes meets a closed pipe.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(out.status.code(), Some(101), "panicked: {err}");
}

fn result_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("result.json")).unwrap()).unwrap()
}

/// A memory ceiling below the job's estimate is refused before any work,
/// naming `memory_limit_mib`; at a ceiling the estimate fits, the job runs and its measured
/// peak stays within 10% of the ceiling (`result.json`'s `budget`).
#[test]
fn the_memory_ceiling_refuses_at_once_and_holds() {
    let dir = scratch("ceiling");
    let (a, b) = (dir.join("a.ply"), dir.join("b.ply"));
    synth(&a, "0");
    synth(&b, "3");
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    for command in ["match", "p2p"] {
        let out_dir = dir.join(command);
        let out = out_dir.to_str().unwrap();
        let free = shapecorr(&[command, a, b, "--out", out, "--quiet"]);
        assert!(free.status.success(), "{}", stderr(&free));
        let estimate = result_json(&out_dir)["budget"]["memory_estimate_mib"]
            .as_f64()
            .unwrap();
        let below = format!("{}", estimate.floor() as u64 - 1);
        let started = Instant::now();
        let refused = shapecorr(&[
            command,
            a,
            b,
            "--out",
            out,
            "--quiet",
            "--memory-limit-mib",
            &below,
        ]);
        assert_clean_failure(&refused, &["memory_limit_mib", "MiB", "raise"]);
        assert!(started.elapsed() < Duration::from_secs(2), "not at once");
        let ceiling = estimate.ceil() as u64;
        let at = format!("{ceiling}");
        let fits = shapecorr(&[
            command,
            a,
            b,
            "--out",
            out,
            "--quiet",
            "--memory-limit-mib",
            &at,
        ]);
        assert!(fits.status.success(), "{}", stderr(&fits));
        let peak = result_json(&out_dir)["budget"]["peak_memory_mib"]
            .as_f64()
            .unwrap();
        println!("{command}: ceiling {ceiling} MiB, peak {peak:.1} MiB");
        assert!(
            peak <= 1.1 * ceiling as f64,
            "{peak} MiB over {ceiling} MiB"
        );
    }
}

/// A time limit the job's estimate exceeds is refused at once, naming `time_limit_s`.
#[test]
fn a_time_limit_below_the_estimate_is_refused_at_once() {
    let dir = scratch("time-limit");
    let (a, b) = (dir.join("a.ply"), dir.join("b.ply"));
    synth(&a, "0");
    synth(&b, "3");
    let out = dir.join("out");
    let started = Instant::now();
    let refused = shapecorr(&[
        "p2p",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--time-limit-s",
        "0.001",
    ]);
    assert_clean_failure(&refused, &["time_limit_s", "would take about"]);
    assert!(started.elapsed() < Duration::from_secs(2), "not at once");
}

/// A job too big for its limits fails with the resource limit's one-line reason, told apart
/// from a bad value: `--memory-limit-mib 1` refuses every job at once with
/// `shapecorr: resource limit `memory_limit_mib`: ...` (exit status 1, as every failed
/// job), `--max-vertices` below a shape's size names the limit and the file, while a value
/// out of the option's range is a usage error (status 2) that names the option.
#[test]
fn a_job_over_its_limits_fails_with_a_resource_limit_line() {
    let dir = scratch("resource-limit");
    let (a, b) = (dir.join("a.ply"), dir.join("b.ply"));
    synth(&a, "0");
    synth(&b, "3");
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    for (command, files) in [("match", &[a, b][..]), ("symmetry", &[a]), ("p2p", &[a, b])] {
        let mut args = vec![command];
        args.extend_from_slice(files);
        args.extend_from_slice(&["--out", out, "--quiet", "--memory-limit-mib", "1"]);
        let started = Instant::now();
        let refused = shapecorr(&args);
        assert!(started.elapsed() < Duration::from_secs(2), "not at once");
        let err = stderr(&refused);
        assert_eq!(refused.status.code(), Some(1), "{command}: {err}");
        assert_eq!(err.lines().count(), 1, "{command}: one line: {err}");
        assert!(
            err.starts_with("shapecorr: resource limit `memory_limit_mib`: "),
            "{command}: {err}"
        );
        assert_clean_failure(&refused, &["needs about", "raise memory_limit_mib"]);
    }
    let refused = shapecorr(&["match", a, b, "--out", out, "--max-vertices", "100"]);
    assert_eq!(refused.status.code(), Some(1));
    assert_clean_failure(&refused, &["a.ply", "resource limit `max_vertices`"]);
    let bad = shapecorr(&["match", a, b, "--out", out, "--memory-limit-mib=-1"]);
    assert_eq!(bad.status.code(), Some(2), "{}", stderr(&bad));
    assert_clean_failure(&bad, &["memory_limit_mib"]);
    assert!(!stderr(&bad).contains("resource limit"), "{}", stderr(&bad));
}
