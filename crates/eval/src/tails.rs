//! The tails of a benchmark: not only the mean but the median, the worst pair and how many
//! pairs failed (failures are reported, not averaged away).

use std::fmt::Write as _;

/// The mean pointwise error above which a pair counts as failed (the two thresholds every
/// table reports).
pub const FAILED_ERRORS: [f64; 2] = [0.05, 0.10];

/// Summary of one score over the pairs of a dataset.
#[derive(Debug, Clone, PartialEq)]
pub struct Tails {
    pub pairs: usize,
    pub mean: f64,
    pub median: f64,
    /// The worst value and its pair (`source -> target`).
    pub worst: (f64, String),
}

impl Tails {
    /// The tails of `values` (score, pair name); `higher_is_worse` for errors, not for
    /// accuracies. None when there is no value.
    pub fn of(values: &[(f64, String)], higher_is_worse: bool) -> Option<Tails> {
        if values.is_empty() {
            return None;
        }
        let mut sorted: Vec<f64> = values.iter().map(|v| v.0).collect();
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let median = if n % 2 == 1 {
            sorted[n / 2]
        } else {
            0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
        };
        let worst = values
            .iter()
            .reduce(|w, v| {
                let worse = if higher_is_worse {
                    v.0 > w.0
                } else {
                    v.0 < w.0
                };
                if worse {
                    v
                } else {
                    w
                }
            })
            .cloned()
            .expect("not empty");
        Some(Tails {
            pairs: n,
            mean: sorted.iter().sum::<f64>() / n as f64,
            median,
            worst,
        })
    }

    /// How many values are above `threshold`.
    pub fn count_above(values: &[(f64, String)], threshold: f64) -> usize {
        values.iter().filter(|v| v.0 > threshold).count()
    }
}

/// A markdown table of pointwise errors: one row per (dataset or method) label with the mean,
/// median, worst pair and the count of pairs above each of [`FAILED_ERRORS`].
pub fn error_tails_table(rows: &[(String, Vec<(f64, String)>)]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| | pairs | mean | median | worst pair | above 0.05 | above 0.10 |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|");
    for (label, values) in rows {
        let Some(t) = Tails::of(values, true) else {
            continue;
        };
        let _ = writeln!(
            out,
            "| {label} | {} | {:.4} | {:.4} | {:.4} ({}) | {} | {} |",
            t.pairs,
            t.mean,
            t.median,
            t.worst.0,
            t.worst.1,
            Tails::count_above(values, FAILED_ERRORS[0]),
            Tails::count_above(values, FAILED_ERRORS[1]),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tails_name_the_worst_pair_and_count_failures() {
        let v: Vec<(f64, String)> = [0.01, 0.2, 0.03, 0.07]
            .iter()
            .enumerate()
            .map(|(i, &e)| (e, format!("p{i}")))
            .collect();
        let t = Tails::of(&v, true).unwrap();
        assert_eq!(t.pairs, 4);
        assert!((t.median - 0.05).abs() < 1e-12);
        assert!((t.mean - 0.0775).abs() < 1e-12);
        assert_eq!(t.worst, (0.2, "p1".to_string()));
        assert_eq!(Tails::count_above(&v, 0.05), 2);
        assert_eq!(Tails::count_above(&v, 0.1), 1);
        let accuracy = Tails::of(&v, false).unwrap();
        assert_eq!(accuracy.worst.1, "p0");
        let table = error_tails_table(&[("m".into(), v)]);
        assert!(
            table.contains("| m | 4 | 0.0775 | 0.0500 | 0.2000 (p1) | 2 | 1 |"),
            "{table}"
        );
    }
}
