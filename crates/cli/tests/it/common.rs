//! What the command line's end-to-end tests share: running the tool, a scratch folder and a
//! generated figure. Each test file uses part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs the `shapecorr` binary of this build and waits for it.
pub fn shapecorr<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shapecorr"))
        .args(args)
        .output()
        .expect("the shapecorr binary runs")
}

/// A folder of this test process under the temporary folder, `shapecorr-SUITE-PID-NAME`.
pub fn scratch(suite: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("shapecorr-{suite}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes a generated figure (`shapecorr synth`) to `path` and checks that it worked.
pub fn synth_figure(kind: &str, pose: &str, vertices: &str, path: &Path) {
    let out = shapecorr(&[
        "synth",
        "--kind",
        kind,
        "--pose",
        pose,
        "--vertices",
        vertices,
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs shapecorr, killing it after `limit`; `None` when it had to be killed.
pub fn shapecorr_within<S: AsRef<std::ffi::OsStr>>(args: &[S], limit: Duration) -> Option<Output> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_shapecorr"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while started.elapsed() < limit {
        if child.try_wait().unwrap().is_some() {
            return Some(child.wait_with_output().unwrap());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    None
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Fails with one line on stderr (no panic) that contains every one of `needles`.
pub fn assert_clean_failure(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert!(!out.status.success(), "{err}");
    assert_ne!(out.status.code(), Some(101), "panicked: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for needle in needles {
        assert!(err.contains(needle), "`{needle}` not in: {err}");
    }
}
