//! `shapecorr bench all --quick` end to end (what CI runs): every section of the results
//! page is produced from the generated dataset, with figures in range, and a second run
//! resumes from the logs without computing again.

use std::path::Path;
use std::process::Command;

fn run(work: &Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_shapecorr"))
        .args(["bench", "all", "--quick", "--work"])
        .arg(work)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "bench all --quick failed:\n{stderr}");
    std::fs::read_to_string(work.join("results.md")).unwrap()
}

/// The numbers of the table row whose first cells are `prefix`.
fn row(page: &str, prefix: &str) -> Vec<f64> {
    let line = page
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no row {prefix:?} in\n{page}"));
    line.split('|')
        .filter_map(|c| c.trim().parse::<f64>().ok())
        .collect()
}

fn log_lines(work: &Path) -> Vec<(String, usize)> {
    let mut logs: Vec<(String, usize)> = std::fs::read_dir(work.join("logs"))
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let text = std::fs::read_to_string(e.path()).unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                text.lines().count(),
            )
        })
        .collect();
    logs.sort();
    logs
}

#[test]
fn quick_mode_writes_every_table_and_resumes() {
    let work = std::env::temp_dir().join(format!("shapecorr-bench-all-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    let page = run(&work);
    for section in [
        "## Region accuracy (paper Table 1)",
        "## Point-to-point maps (paper Table 2)",
        "## Point clouds, quick",
        "## Timing (paper Table 3)",
    ] {
        assert!(page.contains(section), "missing {section}:\n{page}");
    }
    for png in [
        "images/quick_p2p_curves.png",
        "images/quick_pointclouds.png",
    ] {
        let bytes = std::fs::read(work.join(png)).unwrap();
        assert_eq!(&bytes[1..4], b"PNG", "{png}");
    }
    // Table 1, all pairs: pairs, ours, Reeb, one-to-one, regions A/B (split), Reeb nodes, s/pair.
    let all = row(&page, "| quick | all |");
    let (pairs, ours, reeb) = (all[0], all[1], all[2]);
    assert_eq!(pairs, 8.0);
    assert!(ours > 0.85 && ours <= 1.0, "our accuracy {ours}");
    assert!((0.0..=1.0).contains(&reeb), "Reeb accuracy {reeb}");
    assert!(
        ours > reeb,
        "the Mapper-style graphs should beat the Reeb baseline"
    );
    // Table 2: regions + ZoomOut beats descriptors alone by a wide margin.
    let zoomout = row(&page, "| quick | regions+zoomout |");
    let wks = row(&page, "| quick | wks |");
    for method in ["wks+icp", "regions+icp"] {
        let refined = row(&page, &format!("| quick | {method} |"));
        assert!(refined[2] < 0.5, "{method} error {}", refined[2]);
    }
    assert!(zoomout[2] < 0.03, "regions+zoomout error {}", zoomout[2]);
    assert!(wks[2] > 2.0 * zoomout[2]);
    // Point clouds: accuracies in [0, 1] for both modes.
    for mode in ["| mesh-to-cloud | 0% |", "| cloud-to-cloud | 2% |"] {
        let cells = row(&page, mode);
        assert!(
            !cells.is_empty() && cells.iter().all(|a| (0.0..=1.0).contains(a)),
            "{mode} {cells:?}"
        );
    }
    // Timing: positive seconds.
    let total = row(&page, "| **total, regions** |");
    assert!(total[0] > 0.0);

    // Second run: everything comes from the logs; the accuracy tables are unchanged.
    let before = log_lines(&work);
    assert_eq!(before.len(), 5, "{before:?}");
    let again = run(&work);
    assert_eq!(
        log_lines(&work),
        before,
        "a resumed run must not compute again"
    );
    let tables = |p: &str| -> Vec<String> {
        p.lines()
            .filter(|l| l.starts_with("| quick |"))
            .map(str::to_string)
            .collect()
    };
    assert_eq!(tables(&page), tables(&again));
    let _ = std::fs::remove_dir_all(&work);
}
