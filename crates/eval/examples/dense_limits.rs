//! How soon a cancel lands in each stage of a dense pair (docs/decisions.md, "Dense shapes:
//! limits"): for every stage, the pair is read and matched with a progress that asks to stop
//! `DELAY` seconds after the stage's first report, and the time from that request to the
//! call's return is printed. Run by tests/bench/dense_limits.sh on a 1.9M-vertex figure.
//!
//!     cargo run --release -p shapecorr-eval --example dense_limits -- A.ply B.ply [DELAY]

use std::path::Path;
use std::time::Instant;

use shapecorr::pipeline::{Correspondence, Params};
use shapecorr::{Error, Progress, ReadAs, Repairs, Shape, Stage};

/// Asks to stop `delay` seconds after the first report of `stage` at or past `from`, and
/// remembers when.
struct CancelIn {
    stage: Stage,
    from: f32,
    delay: f64,
    seen: Option<Instant>,
    asked: Option<Instant>,
    largest_gap: f64,
    last: Instant,
}

impl Progress for CancelIn {
    fn report(&mut self, stage: Stage, fraction: f32) -> bool {
        let now = Instant::now();
        if self.asked.is_none() {
            self.largest_gap = self.largest_gap.max((now - self.last).as_secs_f64());
        }
        self.last = now;
        if self.asked.is_some() {
            return false;
        }
        if stage == self.stage && fraction >= self.from {
            let seen = *self.seen.get_or_insert(now);
            if (now - seen).as_secs_f64() >= self.delay {
                self.asked = Some(now);
                return false;
            }
        }
        true
    }
}

/// Reads A (the reading stages) or matches the pair (read once, outside the clock).
fn run(
    stage: Stage,
    (a, b): (&Path, &Path),
    repairs: &Repairs,
    shapes: &mut Option<(Shape, Shape)>,
    progress: &mut CancelIn,
) -> Result<(), Error> {
    if stage == Stage::Reading {
        Shape::read_watched(a, ReadAs::Auto, repairs, progress)?;
        return Ok(());
    }
    if shapes.is_none() {
        *shapes = Some((
            Shape::read_with(a, ReadAs::Auto, repairs)?,
            Shape::read_with(b, ReadAs::Auto, repairs)?,
        ));
    }
    let (sa, sb) = shapes.as_ref().expect("read above");
    Correspondence::compute(sa, sb, &Params::default(), progress)?;
    Ok(())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (a, b) = (Path::new(&args[0]), Path::new(&args[1]));
    let delay: f64 = args
        .get(2)
        .map_or(0.3, |d| d.parse().expect("DELAY in seconds"));
    let repairs = Repairs::default();
    let cases = [
        ("reading", Stage::Reading, 0.0),
        ("repair", Stage::Reading, 0.5),
        ("proxy", Stage::Proxy, 0.0),
        ("eigenbasis", Stage::Eigenbasis, 0.0),
        ("matching", Stage::Matching, 0.0),
    ];
    let mut shapes = None;
    for (name, stage, from) in cases {
        let mut progress = CancelIn {
            stage,
            from,
            delay,
            seen: None,
            asked: None,
            largest_gap: 0.0,
            last: Instant::now(),
        };
        let started = Instant::now();
        let result = run(stage, (a, b), &repairs, &mut shapes, &mut progress);
        let returned = Instant::now();
        let latency = progress.asked.map(|t| (returned - t).as_secs_f64());
        println!(
            "{name:<10} cancel asked {:>6} s after start, returned {:>6} later ({}); \
             largest gap between reports before it {:.2} s",
            progress.asked.map_or("-".to_string(), |t| format!(
                "{:.2}",
                (t - started).as_secs_f64()
            )),
            latency.map_or("-".to_string(), |l| format!("{l:.3} s")),
            match result {
                Err(Error::Cancelled) => "cancelled".to_string(),
                Err(e) => format!("error: {e}"),
                Ok(()) => "finished".to_string(),
            },
            progress.largest_gap
        );
    }
}
