//! `shapecorr batch` end to end (issue 22): the same answer per pair as `match` and `p2p`,
//! each eigenbasis computed once, a killed run resumed without recomputing, bad entries
//! recorded as failed pairs.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::common;

use common::shapecorr;

fn ok(out: std::process::Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("batch", name)
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// Generated humanoids: poses 0-3, each with two bodies (limbs 1 and 1.25 times as long).
fn figures(dir: &Path, count: usize) -> Vec<PathBuf> {
    (0..count)
        .map(|i| {
            let path = dir.join(format!("fig{i}.ply"));
            let (pose, limbs) = ((i / 2).to_string(), if i % 2 == 0 { "1" } else { "1.25" });
            ok(shapecorr(&[
                "synth",
                "--pose",
                &pose,
                "--limb-length",
                limbs,
                "--vertices",
                "1200",
                "--out",
                s(&path),
                "--quiet",
            ]));
            path
        })
        .collect()
}

fn lines(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap_or_default()
        .lines()
        .map(|l| serde_json::from_str(l).expect("whole JSON lines"))
        .collect()
}

#[test]
fn a_killed_batch_resumes_and_every_pair_is_the_answer_of_match() {
    let dir = scratch("resume");
    let shapes = dir.join("shapes");
    std::fs::create_dir_all(&shapes).unwrap();
    let paths = figures(&shapes, 8);
    let out = dir.join("out");

    // Killed (SIGKILL) once 8 of the 28 pairs are in the log.
    let mut child = Command::new(env!("CARGO_BIN_EXE_shapecorr"))
        .args([
            "batch",
            s(&shapes),
            "--out",
            s(&out),
            "--jobs",
            "2",
            "--quiet",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while lines(&out.join("pairs.jsonl")).len() < 8 {
        assert!(child.try_wait().unwrap().is_none(), "the batch ended early");
        assert!(started.elapsed() < Duration::from_secs(300));
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let before = std::fs::read_to_string(out.join("pairs.jsonl"))
        .unwrap()
        .matches('\n')
        .count();
    assert!(before < 28, "killed after the end: {before} pairs");

    let summary = ok(shapecorr(&[
        "batch",
        s(&shapes),
        "--out",
        s(&out),
        "--quiet",
    ]));
    assert!(
        summary.contains(&format!(
            "28 pairs ({} now, {before} from an earlier run), 0 failed now",
            28 - before
        )),
        "{summary}"
    );
    let pairs = lines(&out.join("pairs.jsonl"));
    assert_eq!(pairs.len(), 28, "no pair lost or computed twice");
    let names: BTreeSet<(String, String)> = pairs
        .iter()
        .map(|p| {
            (
                p["a"].as_str().unwrap().into(),
                p["b"].as_str().unwrap().into(),
            )
        })
        .collect();
    assert_eq!(names.len(), 28);

    // Each eigenbasis computed exactly once, over both runs.
    let shape_lines = lines(&out.join("shapes.jsonl"));
    let computed: Vec<&str> = shape_lines
        .iter()
        .filter(|r| r["computed"].as_bool().unwrap())
        .map(|r| r["name"].as_str().unwrap())
        .collect();
    assert_eq!(computed.len(), 8, "{computed:?}");
    assert_eq!(computed.iter().collect::<BTreeSet<_>>().len(), 8);
    assert!(summary.contains("(0 eigenbases computed, "), "{summary}");

    // Every pair as `shapecorr match` answers it alone: the same regions, byte for byte.
    for pair in &pairs {
        assert_eq!(pair["ok"], true, "{pair}");
        let (a, b) = (pair["a"].as_str().unwrap(), pair["b"].as_str().unwrap());
        let path = |name: &str| {
            paths
                .iter()
                .find(|p| p.file_stem().unwrap() == name)
                .unwrap()
        };
        let alone = dir.join("alone");
        ok(shapecorr(&[
            "match",
            s(path(a)),
            s(path(b)),
            "--out",
            s(&alone),
            "--quiet",
        ]));
        let result: Value =
            serde_json::from_str(&std::fs::read_to_string(alone.join("result.json")).unwrap())
                .unwrap();
        for key in [
            "k",
            "regions_a",
            "regions_b",
            "matches",
            "matches_one_to_one",
            "confidence",
        ] {
            assert_eq!(pair[key], result[key], "{a} - {b}: {key}");
        }
    }
}

#[test]
fn bad_entries_are_failed_pairs_and_maps_are_those_of_p2p() {
    let dir = scratch("bad");
    let shapes = dir.join("shapes");
    std::fs::create_dir_all(&shapes).unwrap();
    let good = figures(&shapes, 3);
    let unreadable = shapes.join("broken.ply");
    std::fs::write(&unreadable, b"ply\nformat nonsense\n").unwrap();
    let tiny = shapes.join("tiny.off");
    let mut off = String::from("OFF\n10 8 0\n");
    for i in 0..10 {
        off += &format!(
            "{} {} {}\n",
            i as f64 * 0.1,
            (i % 3) as f64 * 0.2,
            (i % 2) as f64
        );
    }
    for i in 0..8 {
        off += &format!("3 {} {} {}\n", i, i + 1, i + 2);
    }
    std::fs::write(&tiny, off).unwrap();
    let pair_file = dir.join("pairs.txt");
    std::fs::write(
        &pair_file,
        "# source\ttarget\nfig0\tfig1\tgood\nfig0\tbroken\tbad\ntiny\tfig2\tbad\nfig2\tfig1\tgood\n",
    )
    .unwrap();
    let out = dir.join("out");
    let summary = ok(shapecorr(&[
        "batch",
        s(&shapes),
        "--pairs",
        s(&pair_file),
        "--maps",
        "--out",
        s(&out),
        "--quiet",
    ]));
    assert!(
        summary.contains("4 pairs (4 now, 0 from an earlier run), 2 failed now"),
        "{summary}"
    );
    let pairs = lines(&out.join("pairs.jsonl"));
    let shape_lines = lines(&out.join("shapes.jsonl"));
    let reason = |name: &str| {
        shape_lines
            .iter()
            .find(|r| r["name"] == name)
            .and_then(|r| r["error"].as_str())
            .unwrap_or_else(|| panic!("{name} failed with a reason"))
            .to_string()
    };
    for pair in &pairs {
        let (a, b) = (pair["a"].as_str().unwrap(), pair["b"].as_str().unwrap());
        match (a, b) {
            ("fig0", "broken") => {
                assert_eq!(pair["ok"], false);
                assert_eq!(pair["error"], format!("shape broken: {}", reason("broken")));
                assert!(
                    reason("broken").contains("broken.ply"),
                    "{}",
                    reason("broken")
                );
            }
            ("tiny", "fig2") => {
                assert_eq!(pair["ok"], false);
                assert_eq!(pair["error"], format!("shape tiny: {}", reason("tiny")));
            }
            _ => {
                assert_eq!(pair["ok"], true, "{pair}");
                // The map and regions `shapecorr p2p` gives on the pair alone.
                let path = |name: &str| {
                    good.iter()
                        .find(|p| p.file_stem().unwrap() == name)
                        .unwrap()
                };
                let alone = dir.join("alone");
                ok(shapecorr(&[
                    "p2p",
                    s(path(a)),
                    s(path(b)),
                    "--out",
                    s(&alone),
                    "--quiet",
                ]));
                let expected: Vec<u32> = std::fs::read_to_string(alone.join("map_b_to_a.txt"))
                    .unwrap()
                    .split_whitespace()
                    .map(|v| v.parse().unwrap())
                    .collect();
                let map = shapecorr::collection::read_map(&out.join(pair["map"].as_str().unwrap()))
                    .unwrap();
                assert_eq!(map, expected, "{a} - {b}");
                let result: Value = serde_json::from_str(
                    &std::fs::read_to_string(alone.join("result.json")).unwrap(),
                )
                .unwrap();
                for key in ["regions_a", "regions_b", "matches_one_to_one", "confidence"] {
                    assert_eq!(pair[key], result[key], "{a} - {b}: {key}");
                }
            }
        }
    }
    assert_eq!(pairs.len(), 4);

    // Another option in the same folder is refused, not mixed in.
    let out2 = shapecorr(&[
        "batch",
        s(&shapes),
        "--out",
        s(&out),
        "--quiet",
        "--k-max",
        "8",
    ]);
    assert!(!out2.status.success());
    assert!(
        String::from_utf8_lossy(&out2.stderr).contains("other settings or options"),
        "{}",
        String::from_utf8_lossy(&out2.stderr)
    );
}
