//! What the user knows beyond the shapes, on the command line: `--placement`, `--landmarks
//! FILE` (read, checked by the library, each landmark of B mapped to its partner), and how
//! the answer was chosen (result.json's `chosen`, `runner_up`, `placement`, the summary
//! line, the runner-up's answer in `OUT/other/`).

use std::path::{Path, PathBuf};

use crate::common;

use common::{assert_clean_failure, shapecorr, stderr, synth_figure};

fn scratch(name: &str) -> PathBuf {
    common::scratch("guidance", name)
}

/// Two generated humanoids in different poses, in one frame, sharing their vertex order (the
/// ground truth of vertex `v` of B is vertex `v` of A).
fn humanoids(dir: &Path) -> (PathBuf, PathBuf) {
    let (a, b) = (dir.join("a.ply"), dir.join("b.ply"));
    synth_figure("humanoid", "0", "2000", &a);
    synth_figure("humanoid", "3", "2000", &b);
    (a, b)
}

fn run(args: &[&Path], extra: &[&str]) -> std::process::Output {
    let mut all: Vec<&std::ffi::OsStr> = args.iter().map(|p| p.as_os_str()).collect();
    all.extend(extra.iter().map(std::ffi::OsStr::new));
    shapecorr(&all)
}

fn result_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("result.json")).unwrap()).unwrap()
}

fn read_map(path: &Path) -> Vec<u32> {
    shapecorr_eval::bench_pointwise::read_map(path).unwrap()
}

/// The keys on how the answer was chosen are there and agree with each other and with
/// `hypotheses`; the summary line on stdout names the same choice. Returns the runner-up.
fn check_choice(result: &serde_json::Value, stdout: &str, mode: &str) -> Option<String> {
    assert_eq!(result["placement"]["mode"], mode);
    let chosen = &result["chosen"];
    let hypotheses = result["hypotheses"].as_array().unwrap();
    let picked: Vec<_> = hypotheses.iter().filter(|h| h["chosen"] == true).collect();
    assert_eq!(picked.len(), 1, "{hypotheses:?}");
    for key in ["kind", "cost", "turn_degrees", "landmark_error"] {
        assert_eq!(chosen[key], picked[0][key], "{key}");
    }
    for h in hypotheses {
        let turn = h["turn_degrees"].as_f64().unwrap();
        assert!((0.0..=180.0).contains(&turn), "{h}");
        assert!(h["ruled_out"].is_boolean(), "{h}");
    }
    let decided_by = chosen["decided_by"].as_str().unwrap();
    assert!(
        ["cost", "close call", "placement", "landmarks"].contains(&decided_by),
        "{decided_by}"
    );
    assert_eq!(result["placement"]["used"], decided_by == "placement");
    let kind = chosen["kind"].as_str().unwrap();
    let line = stdout
        .lines()
        .find(|l| l.starts_with("chosen: "))
        .unwrap_or_else(|| panic!("no summary line: {stdout}"));
    assert!(
        line.starts_with(&format!("chosen: `{kind}` hypothesis")),
        "{line}"
    );
    assert!(line.contains(&format!("decided by {decided_by}")), "{line}");
    let runner_up = &result["runner_up"];
    if runner_up.is_null() {
        assert!(result["other_answer"].is_null());
        assert!(line.contains("no runner-up"), "{line}");
        return None;
    }
    let other = hypotheses
        .iter()
        .find(|h| h["chosen"] == false && h["kind"] == runner_up["kind"])
        .unwrap_or_else(|| panic!("runner-up {runner_up} among {hypotheses:?}"));
    assert_eq!(other["cost"], runner_up["cost"]);
    assert_eq!(result["other_answer"], "other");
    let cost = runner_up["cost"].as_f64().unwrap();
    assert!(
        line.contains(&format!(
            "runner-up: `{}` (cost {cost:.4}",
            runner_up["kind"].as_str().unwrap()
        )),
        "{line}"
    );
    Some(runner_up["kind"].as_str().unwrap().to_string())
}

#[test]
fn a_malformed_or_wrong_landmarks_file_fails_naming_it_and_writes_nothing() {
    let dir = scratch("bad");
    let (a, b) = humanoids(&dir);
    let shape_b = shapecorr::Shape::read(&b, shapecorr::ReadAs::Auto).unwrap();
    let n_b = shape_b.n_vertices();
    let out = dir.join("out");
    let file = dir.join("landmarks.txt");
    for (text, needles) in [
        (
            "# hand, foot\n10 12\n7 x9\n".to_string(),
            vec!["landmarks.txt: line 3, column 3: B's vertex `x9`"],
        ),
        ("10 12 13\n".into(), vec!["line 1, column 7: a third value"]),
        ("10,,12\n".into(), vec!["line 1, column 4: a second comma"]),
        (
            format!("10 12\n20 {n_b}\n"),
            vec![
                "landmarks.txt: invalid parameter `landmarks`",
                &format!("vertex {n_b} is not a vertex of B (it has {n_b} vertices"),
            ],
        ),
        (
            "10 12\n10 13\n".into(),
            vec!["landmarks.txt", "contradict each other"],
        ),
        (
            (0..101).map(|v| format!("{v} {v}\n")).collect(),
            vec!["landmarks.txt", "101 pairs given, at most 100"],
        ),
    ] {
        std::fs::write(&file, &text).unwrap();
        for command in ["p2p", "match"] {
            std::fs::remove_dir_all(&out).ok();
            let done = run(
                &[Path::new(command), &a, &b, Path::new("--out"), &out],
                &["--landmarks", file.to_str().unwrap(), "--quiet"],
            );
            assert_clean_failure(&done, &needles);
            assert_eq!(done.status.code(), Some(1), "{text:?}: {}", stderr(&done));
            let written: Vec<_> = std::fs::read_dir(&out)
                .map(|d| d.map(|e| e.unwrap().file_name()).collect())
                .unwrap_or_default();
            assert!(written.is_empty(), "{text:?}, {command}: wrote {written:?}");
        }
    }
    // A vertex the repairs leave out (no face uses it) is refused, not silently moved.
    let shape_a = shapecorr::Shape::read(&a, shapecorr::ReadAs::Auto).unwrap();
    let mut obj = String::new();
    for p in shape_a.vertices() {
        obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    obj.push_str("v 0 0 0\n");
    for t in shape_a.triangles() {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let loose = dir.join("loose.obj");
    std::fs::write(&loose, obj).unwrap();
    std::fs::write(&file, format!("{} 5\n", shape_a.n_vertices())).unwrap();
    let done = run(
        &[Path::new("p2p"), &loose, &b, Path::new("--out"), &out],
        &["--landmarks", file.to_str().unwrap(), "--quiet"],
    );
    assert_clean_failure(&done, &["landmarks.txt", "not used by the computation"]);
    // The landmarks file is an input: never an output.
    let done = run(
        &[
            Path::new("transfer"),
            &a,
            &b,
            Path::new("--values"),
            &dir.join("values.txt"),
        ],
        &[
            "--out",
            file.to_str().unwrap(),
            "--landmarks",
            file.to_str().unwrap(),
        ],
    );
    assert_clean_failure(&done, &["is the input", "landmarks.txt"]);
    assert_eq!(
        std::fs::read_to_string(&file).unwrap(),
        format!("{} 5\n", shape_a.n_vertices())
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn placement_is_an_option_with_three_values() {
    let dir = scratch("placement");
    let (a, b) = humanoids(&dir);
    let out = dir.join("out");
    let done = run(
        &[Path::new("p2p"), &a, &b, Path::new("--out"), &out],
        &["--placement", "bogus"],
    );
    assert_clean_failure(&done, &["--placement", "auto (0), ignore (1), trust (2)"]);
    assert_eq!(done.status.code(), Some(2));
    assert!(!out.exists());
    // `ignore`: the frame never decides; `trust`: it does (no landmarks to overrule it). The
    // flag and `--set` are one option.
    for (args, mode, used) in [
        (&["--placement", "ignore"][..], "ignore", false),
        (&["--set", "placement=trust"], "trust", true),
    ] {
        let done = run(
            &[Path::new("match"), &a, &b, Path::new("--out"), &out],
            &[args, &["--quiet"]].concat(),
        );
        assert!(done.status.success(), "{}", stderr(&done));
        let result = result_json(&out);
        check_choice(&result, &String::from_utf8_lossy(&done.stdout), mode);
        assert_eq!(result["placement"]["used"], used, "{mode}");
        // The runner-up's one-to-one regions, written beside the answer.
        if !result["runner_up"].is_null() {
            let other = result_json(&out.join("other"));
            assert_eq!(other["chosen"]["kind"], result["runner_up"]["kind"]);
            assert_eq!(other["chosen"]["decided_by"], "other answer");
            assert_ne!(other["matches_one_to_one"], result["matches_one_to_one"]);
            assert_eq!(other["regions_b"], result["regions_b"]);
            assert!(out.join("other/b_regions.ply").is_file());
        }
        let expected = ["auto", "ignore", "trust"].iter().position(|m| *m == mode);
        assert_eq!(
            result["options"]["placement"].as_u64(),
            expected.map(|i| i as u64)
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn two_landmarks_map_to_their_partners_and_the_other_answer_is_written() {
    let dir = scratch("landmarks");
    let (a, b) = humanoids(&dir);
    let plain = dir.join("plain");
    let done = run(
        &[Path::new("p2p"), &a, &b, Path::new("--out"), &plain],
        &["--quiet"],
    );
    assert!(done.status.success(), "{}", stderr(&done));
    let stdout = String::from_utf8_lossy(&done.stdout).into_owned();
    let result = result_json(&plain);
    assert_eq!(result["landmarks"], serde_json::json!([]));
    let runner_up = check_choice(&result, &stdout, "auto");
    let map = read_map(&plain.join("map_b_to_a.txt"));
    // The other answer: the runner-up's map, a different one, with its own result.json.
    if let Some(kind) = &runner_up {
        let other = read_map(&plain.join("other/map_b_to_a.txt"));
        assert_eq!(other.len(), map.len());
        let differ = map.iter().zip(&other).filter(|(x, y)| x != y).count();
        assert!(differ * 20 > map.len(), "{differ} of {} differ", map.len());
        let other_result = result_json(&plain.join("other"));
        assert_eq!(other_result["chosen"]["kind"], kind.as_str());
        assert_eq!(other_result["chosen"]["decided_by"], "other answer");
        for ply in [
            "a_colors.ply",
            "b_mapped.ply",
            "a_regions.ply",
            "b_regions.ply",
        ] {
            assert!(plain.join("other").join(ply).is_file(), "{ply}");
        }
    } else {
        assert!(!plain.join("other").exists());
    }
    // Two landmarks where the plain map misses the truth (the shared vertex order), the
    // highest and the lowest such vertex of B: a hand and a foot.
    let shape_b = shapecorr::Shape::read(&b, shapecorr::ReadAs::Auto).unwrap();
    let missed: Vec<usize> = (0..map.len()).filter(|&v| map[v] as usize != v).collect();
    assert!(missed.len() > 10, "{} missed", missed.len());
    let height = |v: &usize| shape_b.vertices()[*v][1];
    let top = *missed
        .iter()
        .max_by(|x, y| height(x).total_cmp(&height(y)))
        .unwrap();
    let bottom = *missed
        .iter()
        .min_by(|x, y| height(x).total_cmp(&height(y)))
        .unwrap();
    let file = dir.join("landmarks.txt");
    std::fs::write(
        &file,
        format!("# A's vertex, B's vertex\n{top} {top}\n{bottom},{bottom}\n"),
    )
    .unwrap();
    let guided = dir.join("guided");
    let done = run(
        &[Path::new("p2p"), &a, &b, Path::new("--out"), &guided],
        &["--landmarks", file.to_str().unwrap(), "--quiet"],
    );
    assert!(done.status.success(), "{}", stderr(&done));
    let map = read_map(&guided.join("map_b_to_a.txt"));
    assert_eq!((map[top], map[bottom]), (top as u32, bottom as u32));
    let result = result_json(&guided);
    assert_eq!(
        result["landmarks"],
        serde_json::json!([[top, top], [bottom, bottom]])
    );
    assert!(result["chosen"]["landmark_error"].as_f64().unwrap() >= 0.0);
    check_choice(&result, &String::from_utf8_lossy(&done.stdout), "auto");
    if !result["runner_up"].is_null() {
        let other = read_map(&guided.join("other/map_b_to_a.txt"));
        assert_eq!((other[top], other[bottom]), (top as u32, bottom as u32));
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_run_without_a_runner_up_removes_an_earlier_other_answer_only() {
    let dir = scratch("stale");
    let (a, b) = humanoids(&dir);
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("other")).unwrap();
    std::fs::write(out.join("other/map_b_to_a.txt"), "0\n").unwrap();
    std::fs::write(out.join("other/notes.txt"), "mine\n").unwrap();
    // Not verified: no hypotheses, so no runner-up.
    let done = run(
        &[Path::new("p2p"), &a, &b, Path::new("--out"), &out],
        &[
            "--verify-hypotheses",
            "false",
            "--p2p-hypotheses",
            "false",
            "--quiet",
        ],
    );
    assert!(done.status.success(), "{}", stderr(&done));
    let result = result_json(&out);
    assert!(result["runner_up"].is_null() && result["other_answer"].is_null());
    assert!(!out.join("other/map_b_to_a.txt").exists());
    assert_eq!(
        std::fs::read_to_string(out.join("other/notes.txt")).unwrap(),
        "mine\n"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn transfer_takes_landmarks_and_the_other_answer() {
    let dir = scratch("transfer");
    let (a, b) = humanoids(&dir);
    let n_a = shapecorr::Shape::read(&a, shapecorr::ReadAs::Auto)
        .unwrap()
        .n_vertices();
    let values = dir.join("values.txt");
    let text: String = (0..n_a).map(|v| format!("{v}\n")).collect();
    std::fs::write(&values, text).unwrap();
    let mut outputs: Vec<(String, String)> = Vec::new();
    for (name, extra) in [("first", &[][..]), ("other", &["--other-answer"][..])] {
        let out = dir.join(format!("{name}.txt"));
        let done = run(
            &[
                Path::new("transfer"),
                &a,
                &b,
                Path::new("--values"),
                &values,
            ],
            &[
                &[
                    "--out",
                    out.to_str().unwrap(),
                    "--mode",
                    "nearest",
                    "--quiet",
                ],
                extra,
            ]
            .concat(),
        );
        let stdout = String::from_utf8_lossy(&done.stdout).into_owned();
        if name == "other" && !done.status.success() {
            // No runner-up: refused, and said so.
            assert_clean_failure(&done, &["other_answer", "no other hypothesis"]);
            assert!(outputs[0].1.contains("no runner-up"), "{}", outputs[0].1);
            return;
        }
        assert!(done.status.success(), "{}", stderr(&done));
        let line = stdout
            .lines()
            .find(|l| l.starts_with("chosen: "))
            .unwrap()
            .to_string();
        outputs.push((std::fs::read_to_string(&out).unwrap(), line));
    }
    assert!(
        outputs[1].1.contains("decided by other answer"),
        "{}",
        outputs[1].1
    );
    assert_ne!(
        outputs[0].0, outputs[1].0,
        "the other answer carries other values"
    );
    std::fs::remove_dir_all(&dir).ok();
}
