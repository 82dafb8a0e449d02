//! The generated rig transfer pairs of `tests/it/transfer.rs` (A in the rest pose at 4,000
//! vertices, B at 8,000 in poses 1-6 with a thicker, longer body): every verified
//! hypothesis with its cost and implied turn, the choice and what decided it, for each
//! `placement` (docs/placement.md).
//!
//!     cargo run --release -p shapecorr-eval --example rig_placement

use shapecorr::maps::placement::Placement;
use shapecorr::synth::{self, FigureKind, Proportions};
use shapecorr::{NoProgress, Params, PointwiseCorrespondence, PointwiseParams, Shape};

fn main() -> shapecorr::Result<()> {
    let rig_a = synth::rig(FigureKind::Humanoid, 4000)?;
    let rig_b = synth::rig(FigureKind::Humanoid, 8000)?;
    let shape_a = Shape::mesh(rig_a.rest.vertices.clone(), &rig_a.rest.triangles)?;
    let body = Proportions {
        limb_length: 1.1,
        limb_thickness: 1.2,
        ..Default::default()
    };
    for pose in 1..7 {
        let posed = rig_b.deform(&rig_b.weights, body, pose)?;
        let shape_b = Shape::mesh(posed, &rig_b.rest.triangles)?;
        for placement in Placement::ALL {
            let params = Params {
                placement,
                ..Params::default()
            };
            let result = PointwiseCorrespondence::compute(
                &shape_a,
                &shape_b,
                &params,
                &PointwiseParams::default(),
                &mut NoProgress,
            )?;
            let Some(verdict) = result.verdict() else {
                continue;
            };
            let hypotheses: Vec<String> = verdict
                .scores
                .iter()
                .enumerate()
                .map(|(h, s)| {
                    format!(
                        "{}{} {:.3} {:.0}deg",
                        if h == verdict.chosen { "*" } else { "" },
                        s.kind.name(),
                        s.energy.cost(),
                        s.turn_degrees
                    )
                })
                .collect();
            println!(
                "pose {pose} {}: decided by {}, confidence {:.2}: {}",
                placement.name(),
                verdict.decided_by.name(),
                verdict.confidence,
                hypotheses.join(", ")
            );
        }
    }
    Ok(())
}
