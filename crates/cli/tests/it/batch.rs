//! `shapecorr batch` end to end (docs/collections.md): the same answer per pair as `match`
//! and `p2p`, each eigenbasis computed once, a killed run resumed without recomputing, bad
//! entries recorded as failed pairs.

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
    let run = || {
        shapecorr(&[
            "batch",
            s(&shapes),
            "--pairs",
            s(&pair_file),
            "--maps",
            "--out",
            s(&out),
            "--quiet",
        ])
    };
    // Failed pairs make the exit status non-zero, now and in a resumed run that skips them.
    for (i, summary) in [
        "4 pairs (4 now, 0 from an earlier run), 2 failed now, 0 failed in an earlier run",
        "4 pairs (0 now, 4 from an earlier run), 0 failed now, 2 failed in an earlier run",
    ]
    .into_iter()
    .enumerate()
    {
        let output = run();
        assert!(!output.status.success(), "run {i}");
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(stdout.contains(summary), "{stdout}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains("2 of 4 pairs failed"), "{stderr}");
    }
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

/// A copy of `figures` under new names.
fn named(dir: &Path, figures: &[PathBuf], names: &[&str]) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir).unwrap();
    figures
        .iter()
        .zip(names)
        .map(|(from, name)| {
            let to = dir.join(format!("{name}.ply"));
            std::fs::copy(from, &to).unwrap();
            to
        })
        .collect()
}

fn pair_answers(out: &Path) -> Vec<(String, String, Value, Value)> {
    let mut answers: Vec<_> = lines(&out.join("pairs.jsonl"))
        .into_iter()
        .map(|r| {
            assert_eq!(r["ok"], true, "{r}");
            (
                r["a"].as_str().unwrap().to_string(),
                r["b"].as_str().unwrap().to_string(),
                r["regions_b"].clone(),
                r["matches_one_to_one"].clone(),
            )
        })
        .collect();
    answers.sort_by(|x, y| (&x.0, &x.1).cmp(&(&y.0, &y.1)));
    answers
}

fn files_named(dir: &Path, part: &str) -> Vec<String> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(files_named(&path, part));
        } else if path.to_string_lossy().contains(part) {
            found.push(path.display().to_string());
        }
    }
    found
}

#[test]
fn damaged_foreign_or_unstorable_cache_entries_give_the_answers_of_a_fresh_run() {
    let dir = scratch("cache");
    let shapes = dir.join("shapes");
    std::fs::create_dir_all(&shapes).unwrap();
    figures(&shapes, 3);
    let batch = |out: &Path, cache: &Path| {
        shapecorr(&[
            "batch",
            s(&shapes),
            "--out",
            s(out),
            "--cache",
            s(cache),
            "--quiet",
        ])
    };
    let reference = dir.join("ref");
    ok(batch(&reference, &dir.join("cache0")));
    let expected = pair_answers(&reference);
    // Shape i's key (the log's lines come in the order the shapes finished).
    let mut named: Vec<(String, String)> = lines(&reference.join("shapes.jsonl"))
        .iter()
        .map(|r| {
            let text = |field: &str| r[field].as_str().unwrap().to_string();
            (text("name"), text("key"))
        })
        .collect();
    named.sort();
    let keys: Vec<String> = named.into_iter().map(|(_, key)| key).collect();
    let entry = |cache: &Path, i: usize| cache.join(format!("{}.basis", keys[i]));

    // fig0's entry with flipped exponent bits, fig1's holding fig2's valid entry.
    let bad = dir.join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    for i in 0..3 {
        std::fs::copy(entry(&dir.join("cache0"), i), entry(&bad, i)).unwrap();
    }
    let mut bytes = std::fs::read(entry(&bad, 0)).unwrap();
    for i in 0..200 {
        let at = 32 + 8 * (1000 + i * 700) + 7;
        if at < bytes.len() {
            bytes[at] ^= 0x10;
        }
    }
    std::fs::write(entry(&bad, 0), bytes).unwrap();
    std::fs::copy(entry(&bad, 2), entry(&bad, 1)).unwrap();
    let out = dir.join("out_bad");
    let output = batch(&out, &bad);
    let stdout = ok(output.clone());
    assert!(
        stdout.contains("2 eigenbases computed, 1 from the cache"),
        "{stdout}"
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("fig0: cache entry") && stderr.contains("fig1: cache entry"),
        "{stderr}"
    );
    assert_eq!(pair_answers(&out), expected);
    let warned = lines(&out.join("shapes.jsonl"))
        .iter()
        .filter(|r| {
            r["warning"]
                .as_str()
                .is_some_and(|w| w.contains("computed again"))
        })
        .count();
    assert_eq!(warned, 2);
    // Replaced: the next run takes all three from the cache.
    let again = ok(batch(&dir.join("out_again"), &bad));
    assert!(
        again.contains("0 eigenbases computed, 3 from the cache"),
        "{again}"
    );

    // A cache where nothing can be stored (a folder in each entry's place; chmod would not
    // stop root): every pair computed, a warning per shape, no temporary file left.
    let stuck = dir.join("stuck");
    for i in 0..3 {
        std::fs::create_dir_all(entry(&stuck, i)).unwrap();
    }
    let out = dir.join("out_stuck");
    let output = batch(&out, &stuck);
    let stdout = ok(output.clone());
    assert!(
        stdout.contains("0 failed now, 0 failed in an earlier run"),
        "{stdout}"
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(
        stderr.matches("could not be stored in the cache").count(),
        3,
        "{stderr}"
    );
    assert_eq!(pair_answers(&out), expected);
    assert_eq!(files_named(&dir, ".tmp"), Vec::<String>::new());
}

#[test]
fn names_with_separators_or_spaces_get_maps_of_their_own() {
    let dir = scratch("names");
    std::fs::create_dir_all(dir.join("made")).unwrap();
    let made = figures(&dir.join("made"), 4);
    let shapes = dir.join("shapes");
    named(&shapes, &made, &["x--y", "z", "x", "y--z left"]);
    let pair_file = dir.join("pairs.txt");
    std::fs::write(&pair_file, "x--y\tz\nx\ty--z left\tspaced\n").unwrap();
    let out = dir.join("out");
    ok(shapecorr(&[
        "batch",
        s(&shapes),
        "--pairs",
        s(&pair_file),
        "--maps",
        "--out",
        s(&out),
        "--quiet",
    ]));
    let records = lines(&out.join("pairs.jsonl"));
    assert_eq!(records.len(), 2);
    let maps: BTreeSet<&str> = records.iter().map(|r| r["map"].as_str().unwrap()).collect();
    assert_eq!(maps.len(), 2, "{maps:?}");
    for r in &records {
        let map = shapecorr::collection::read_map(&out.join(r["map"].as_str().unwrap())).unwrap();
        assert_eq!(map.len(), r["regions_b"].as_array().unwrap().len(), "{r}");
    }
    assert_eq!(std::fs::read_dir(out.join("maps")).unwrap().count(), 2);

    // A line that is not a pair names its line.
    std::fs::write(&pair_file, "x\tz\nlonely\n").unwrap();
    let output = shapecorr(&[
        "batch",
        s(&shapes),
        "--pairs",
        s(&pair_file),
        "--out",
        s(&out),
    ]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("line 2: expected `A<TAB>B`"), "{stderr}");
}

#[test]
fn a_held_folder_or_other_settings_are_refused_and_a_negative_jobs_is_explained() {
    let dir = scratch("held");
    let shapes = dir.join("shapes");
    std::fs::create_dir_all(&shapes).unwrap();
    figures(&shapes, 2);
    let out = dir.join("out");
    // What the Python package does through the C API: the library opens the folder with
    // its settings (k_max 6 here) and holds it while its batch runs.
    let mut options = shapecorr::options::Options::default();
    options
        .set_option("k_max", shapecorr::options::OptionValue::Int(6))
        .unwrap();
    let settings = shapecorr::collection::BatchSettings {
        options,
        reading: Default::default(),
        outputs: shapecorr::collection::Outputs::Regions,
        cache_dir: dir.join("cache"),
        memory_bytes: shapecorr::collection::DEFAULT_MEMORY_BYTES,
    };
    let held = shapecorr::collection::OutputFolder::open(&out, &settings).unwrap();
    let batch = |more: &[&str]| {
        let mut args = vec!["batch", s(&shapes), "--out", s(&out), "--quiet"];
        args.extend_from_slice(more);
        shapecorr(&args)
    };
    let output = batch(&["--k-max", "6"]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("another batch is running"), "{stderr}");
    assert!(!out.join("pairs.jsonl").exists());
    drop(held);
    let output = batch(&[]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("other settings or options"), "{stderr}");
    ok(batch(&["--k-max", "6"]));

    for jobs in ["-1", "two"] {
        let output = batch(&["--k-max", "6", "--jobs", jobs]);
        assert!(!output.status.success());
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains("pairs at once") && !stderr.contains("unexpected argument"),
            "{stderr}"
        );
    }
}
