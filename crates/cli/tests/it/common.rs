//! What the command line's end-to-end tests share: running the tool, a scratch folder and a
//! generated figure. Each test file uses part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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
