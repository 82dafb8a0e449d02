//! The pair job, written once (docs/design.md, "The whole job"): the parameters checked,
//! the job's memory and time estimated and held to the budget, dense shapes replaced by
//! their proxies, the eigenbases computed (or taken from a collection's prepared shapes),
//! the regions and, when asked, the point-to-point map, and the answers brought back to
//! every input vertex. `match`, `p2p`, symmetry detection and every pair of a batch run
//! through [`run_pair`].

use std::time::Instant;

use crate::maps::landmarks::check_landmarks;
use crate::maps::partial;
use crate::maps::pointwise::{pin_landmarks, PointwiseMap, PointwiseParams, Refinement};
use crate::pipeline::budget::{regions_job, Budget, Estimate, Job};
use crate::pipeline::correspondence::Correspondence;
use crate::pipeline::multiresolution::{lift_map, lift_regions, working, Working};
use crate::pipeline::pointwise::{basis_params, regions_and_map};
use crate::pipeline::Params;
use crate::progress::{Progress, Stage};
use crate::shape::io::declared_size;
use crate::shape::proxy::Proxy;
use crate::shape::{ObjectsLeftOut, Shape};
use crate::spectral::eigen::{EigenParams, Eigenbasis, ShapeBasis};
use crate::{Error, Result};

/// What a pair job computes and with which parameters.
#[derive(Debug, Clone, Copy)]
pub struct PairJob<'a> {
    /// The method's parameters (regions, budget, proxies).
    pub params: &'a Params,
    /// The point-to-point map's parameters; `None` computes the regions only.
    pub map: Option<&'a PointwiseParams>,
}

/// A shape with its per-shape work done: its proxy when it is dense and the eigenbasis of
/// the shape the pipeline runs on (the proxy, or the shape itself).
#[derive(Debug, Clone, Copy)]
pub struct ReadyShape<'a> {
    /// The shape as given.
    pub shape: &'a Shape,
    /// Its proxy ([`crate::pipeline::multiresolution`]).
    pub proxy: Option<&'a Proxy>,
    /// The eigenbasis of the working shape, with [`PairJob::eigen_params`]'s eigenpairs.
    pub basis: &'a Eigenbasis,
}

impl<'a> ReadyShape<'a> {
    /// The shape the pipeline runs on: the proxy, or the shape itself.
    pub fn working(&self) -> &'a Shape {
        self.proxy.map_or(self.shape, |p| &p.shape)
    }
}

/// The shapes of a pair job.
#[derive(Debug, Clone, Copy)]
pub enum PairShapes<'a> {
    /// Two shapes: their proxies and eigenbases are computed here.
    Two(&'a Shape, &'a Shape),
    /// One shape matched to itself (symmetry detection): one proxy and one eigenbasis.
    Itself(&'a Shape),
    /// Two shapes prepared beforehand (a collection's cache): nothing per shape is computed.
    Ready(ReadyShape<'a>, ReadyShape<'a>),
}

/// What a pair job gives.
#[derive(Debug, Clone)]
pub struct PairResult {
    /// The region correspondence, on every input vertex.
    pub regions: Correspondence,
    /// The map from B to A on every input vertex, when [`PairJob::map`] asked for it.
    pub map: Option<PointwiseMap>,
    /// The estimate the budget accepted.
    pub estimate: Estimate,
    /// Seconds of A's and B's eigenbases (0 for shapes prepared beforehand).
    pub eigenbasis_s: [f64; 2],
    /// Seconds of building the proxies and bringing the answers back to every input vertex.
    pub proxies_s: f64,
    /// Seconds of the whole job.
    pub total_s: f64,
}

impl PairJob<'_> {
    /// Checks every parameter's range.
    pub fn validate(&self) -> Result<()> {
        self.params.validate()?;
        self.map.map_or(Ok(()), |m| m.validate())
    }

    /// The eigensolver's parameters: the regions' eigenpairs, or the map's when it has more.
    pub fn eigen_params(&self) -> EigenParams {
        match self.map {
            Some(map) => basis_params(self.params, map),
            None => self.params.eigen.clone(),
        }
    }

    /// The job's work on shapes of these sizes (active vertices), for the budget: the
    /// regions' eigensolves and the full-resolution conversions of maps (up to three when
    /// the hypotheses are verified: the answer and a close call's rival).
    pub fn budget_job(&self, [a, b]: [&Shape; 2]) -> Job {
        self.budget_job_of_sizes([a, b].map(|s| s.active_vertices().len()))
    }

    /// Refuses, before anything is read, a job on these two shape files that the budget
    /// cannot hold ([`crate::pipeline::budget::Budget::check_with_reading`], from the counts
    /// the files declare).
    pub fn check_files(&self, [a, b]: [&std::path::Path; 2]) -> Result<Estimate> {
        let size_a = declared_size(a).map_err(|e| e.in_shape('A'))?;
        let size_b = declared_size(b).map_err(|e| e.in_shape('B'))?;
        let job = self.budget_job_of_sizes([size_a.vertices, size_b.vertices]);
        self.params
            .budget
            .check_with_reading(&job, [&size_a, &size_b])
    }

    /// [`PairJob::budget_job`] on shapes of `inputs` active vertices (or an upper bound, such
    /// as the counts a file declares).
    pub fn budget_job_of_sizes(&self, inputs: [usize; 2]) -> Job {
        let sizes = inputs.map(|n| self.params.multiresolution.working_size_of(n));
        let params = self.params;
        match self.map {
            None => {
                let verify = params.verify_hypotheses && !params.skip_one_to_one;
                Job {
                    inputs,
                    ..regions_job(sizes, &params.eigen, verify)
                }
            }
            Some(map) => {
                let eigen = self.eigen_params();
                let size = match &map.refinement {
                    Refinement::ZoomOut(z) => z.k_end,
                    _ => map.fmap_size,
                };
                Job {
                    conversions: if params.verify_hypotheses { 3 } else { 1 },
                    conversion_size: size.min(eigen.n_eigenpairs),
                    inputs,
                    ..regions_job(sizes, &eigen, false)
                }
            }
        }
    }
}

/// The pair job: see the module docs. A job the budget refuses fails before any work; the
/// time limit stops it while it runs.
pub fn run_pair(
    shapes: PairShapes<'_>,
    job: PairJob<'_>,
    progress: &mut dyn Progress,
) -> Result<PairResult> {
    job.validate()?;
    let [a, b] = match shapes {
        PairShapes::Two(a, b) => [a, b],
        PairShapes::Itself(a) => [a, a],
        PairShapes::Ready(a, b) => [a.shape, b.shape],
    };
    if !matches!(shapes, PairShapes::Itself(_)) {
        check_landmarks(&job.params.landmarks, a, b)?;
    }
    let objects_tried = match shapes {
        PairShapes::Two(a, b) => [a, b].map(Shape::may_have_touching_objects),
        PairShapes::Itself(_) | PairShapes::Ready(..) => [false; 2],
    };
    let budget_job = Job {
        objects_tried,
        ..job.budget_job([a, b])
    };
    let estimate = job.params.budget.check(&budget_job)?;
    // The clock started once, so that the tries stop at the job's own deadline.
    let budget = Budget {
        started: Some(job.params.budget.started.unwrap_or_else(Instant::now)),
        ..job.params.budget.clone()
    };
    let deadline = budget.deadline(Instant::now());
    budget.run(progress, |progress| {
        let started = Instant::now();
        let mut answers = match shapes {
            PairShapes::Ready(a, b) => on_ready(a, b, job, progress)?,
            PairShapes::Two(a, b) => prepare_and_run([a, b], job, deadline, progress)?,
            PairShapes::Itself(a) => prepare_itself_and_run(a, job, progress)?,
        };
        let total_s = started.elapsed().as_secs_f64();
        let timings = &mut answers.regions.timings;
        [timings.eigenbasis_a, timings.eigenbasis_b] = answers.eigenbasis_s;
        timings.proxies = answers.proxies_s;
        timings.total = total_s;
        answers.regions.estimate = Some(estimate);
        Ok(PairResult {
            regions: answers.regions,
            map: answers.map,
            estimate,
            eigenbasis_s: answers.eigenbasis_s,
            proxies_s: answers.proxies_s,
            total_s,
        })
    })
}

/// What the steps of [`run_pair`] give it to assemble the result.
struct Answers {
    regions: Correspondence,
    map: Option<PointwiseMap>,
    eigenbasis_s: [f64; 2],
    proxies_s: f64,
}

/// A shape's proxy (when it needs one) and the eigenbasis of the shape the pipeline runs on.
struct Prepared {
    proxy: Option<Proxy>,
    basis: Eigenbasis,
}

impl Prepared {
    fn ready<'a>(&'a self, shape: &'a Shape) -> ReadyShape<'a> {
        ReadyShape {
            shape,
            proxy: self.proxy.as_ref(),
            basis: &self.basis,
        }
    }
}

/// What preparing shapes took: the eigenbases' seconds per side, the proxies' seconds.
#[derive(Default, Clone, Copy)]
struct PrepareTimes {
    eigenbasis_s: [f64; 2],
    proxies_s: f64,
}

/// Two shapes: proxies, then both eigenbases (side by side when small).
fn prepare_two(
    [a, b]: [&Shape; 2],
    job: PairJob<'_>,
    progress: &mut dyn Progress,
) -> Result<([Prepared; 2], PrepareTimes)> {
    let eigen = job.eigen_params();
    let started = Instant::now();
    let [proxy_a, proxy_b] = job
        .params
        .multiresolution
        .proxies([a, b], &eigen, progress)?;
    let built = started.elapsed().as_secs_f64();
    let working_pair = (working(a, &proxy_a), working(b, &proxy_b));
    let ([basis_a, basis_b], eigenbasis_s) = Eigenbasis::pair(working_pair, &eigen, progress)?;
    let has_proxy = proxy_a.is_some() || proxy_b.is_some();
    let prepared = [
        Prepared {
            proxy: proxy_a,
            basis: basis_a,
        },
        Prepared {
            proxy: proxy_b,
            basis: basis_b,
        },
    ];
    let proxies_s = if has_proxy { built } else { 0.0 };
    Ok((
        prepared,
        PrepareTimes {
            eigenbasis_s,
            proxies_s,
        },
    ))
}

/// One shape: its proxy, then its eigenbasis.
fn prepare_one(
    shape: &Shape,
    job: PairJob<'_>,
    progress: &mut dyn Progress,
) -> Result<(Prepared, f64, f64)> {
    let eigen = job.eigen_params();
    let started = Instant::now();
    let proxy = job
        .params
        .multiresolution
        .proxy_polled(shape, &eigen, progress)?;
    let built = if proxy.is_some() {
        started.elapsed().as_secs_f64()
    } else {
        0.0
    };
    let t = Instant::now();
    let basis = Eigenbasis::compute(working(shape, &proxy), &eigen, progress)?;
    Ok((Prepared { proxy, basis }, t.elapsed().as_secs_f64(), built))
}

/// The pair on prepared shapes, with what preparing them took.
fn run_prepared(
    [a, b]: [ReadyShape<'_>; 2],
    times: PrepareTimes,
    job: PairJob<'_>,
    progress: &mut dyn Progress,
) -> Result<Answers> {
    let mut answers = on_ready(a, b, job, progress)?;
    answers.eigenbasis_s = times.eigenbasis_s;
    answers.proxies_s += times.proxies_s;
    Ok(answers)
}

/// Two shapes: prepared, matched, then tried again without the objects touching them
/// until `deadline` (the job's time limit).
fn prepare_and_run(
    [a, b]: [&Shape; 2],
    job: PairJob<'_>,
    deadline: Option<Instant>,
    progress: &mut dyn Progress,
) -> Result<Answers> {
    let (prepared, times) = prepare_two([a, b], job, progress)?;
    let ready = [prepared[0].ready(a), prepared[1].ready(b)];
    let answers = run_prepared(ready, times, job, progress)?;
    let mut optional = OptionalWork {
        inner: progress,
        deadline,
        out_of_time: false,
    };
    without_touching_objects([a, b], &prepared, answers, job, &mut optional)
}

/// A pair without the objects touching a figure is kept only when its chosen hypothesis
/// costs at most this share of the answer's ([`without_touching_objects`]): a clear gain,
/// not a tie. A round value, not tuned: the box's measured shares are 0.15-0.6
/// (docs/scans.md, "Props").
pub const TOUCHING_OBJECTS_GAIN: f64 = 0.8;

/// The cost of the hypothesis the answer chose: the map's verdict when there is a map.
fn chosen_cost(answers: &Answers) -> Option<f64> {
    let of_map = answers.map.as_ref().and_then(|m| m.verdict.as_ref());
    let verdict = of_map.or(answers.regions.verdict.as_ref())?;
    Some(verdict.chosen().energy.cost())
}

/// Whether an error ends the whole job rather than one try of it: a cancel or a limit.
fn ends_the_job(error: &Error) -> bool {
    matches!(
        error.innermost(),
        Error::Cancelled | Error::ResourceLimit { .. }
    )
}

/// The progress of work the job may give up (a try without the objects touching a figure):
/// once `deadline` has passed it stops that work, not the job, which keeps the answer it
/// has. A cancel from `inner` (the user's) still ends the job.
struct OptionalWork<'a> {
    inner: &'a mut dyn Progress,
    deadline: Option<Instant>,
    /// Whether the deadline stopped the work.
    out_of_time: bool,
}

impl OptionalWork<'_> {
    fn past_deadline(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }
}

impl Progress for OptionalWork<'_> {
    fn report(&mut self, stage: Stage, fraction: f32) -> bool {
        if self.past_deadline() {
            self.out_of_time = true;
            return false;
        }
        let go_on = self.inner.report(stage, fraction);
        // The job's own time limit ([`Budget::run`], the same deadline) may have passed
        // since the check above: that stop is the deadline's too.
        if !go_on && self.past_deadline() {
            self.out_of_time = true;
        }
        go_on
    }
}

/// The pair tried again without the closed objects joined to either figure
/// ([`Shape::without_touching_objects`]: A's, B's, and both when both have some); the try
/// whose chosen hypothesis costs least is kept when it costs at most
/// [`TOUCHING_OBJECTS_GAIN`] times the answer's. A box touching a foot spoils every
/// hypothesis (cost 1.7-6x, docs/scans.md, "Props"). Needs the verified hypotheses' costs
/// ([`Params::verify_hypotheses`]); costs one more pair job per try, only for shapes
/// with such objects, and the side a try leaves as it is keeps its proxy and eigenbasis.
/// A try that fails (a trimmed shape too small, a numerical failure) is skipped; a cancel
/// or a memory limit ends the job. The time limit ends the tries, not the job: the answer
/// so far is kept and says which side's objects were not tried
/// ([`crate::pipeline::multiresolution::Working::objects_not_tried`]).
fn without_touching_objects(
    [a, b]: [&Shape; 2],
    prepared: &[Prepared; 2],
    answers: Answers,
    job: PairJob<'_>,
    progress: &mut OptionalWork<'_>,
) -> Result<Answers> {
    let Some(cost) = chosen_cost(&answers) else {
        return Ok(answers);
    };
    let trimmed = [a, b].map(|s| s.without_touching_objects());
    let keeps_landmarks = |side: usize, trimmed: &Shape| {
        job.params
            .landmarks
            .iter()
            .all(|l| trimmed.active_vertices().binary_search(&l[side]).is_ok())
    };
    let usable: Vec<Option<&(Shape, ObjectsLeftOut)>> = trimmed
        .iter()
        .enumerate()
        .map(|(side, t)| t.as_ref().filter(|(s, _)| keeps_landmarks(side, s)))
        .collect();
    let tries: Vec<[bool; 2]> = [[true, false], [false, true], [true, true]]
        .into_iter()
        .filter(|&[on_a, on_b]| (!on_a || usable[0].is_some()) && (!on_b || usable[1].is_some()))
        .collect();
    let mut best: Option<(f64, Answers)> = None;
    // Which sides' objects a try that ran to its end (an answer or a failure) was without.
    let mut tried_without = [false; 2];
    for [on_a, on_b] in tries {
        let trim = |side: usize, on: bool| usable[side].filter(|_| on).map(|(s, l)| (s, *l));
        let sides = [trim(0, on_a), trim(1, on_b)];
        let shapes = [
            sides[0].map_or(a, |(s, _)| s),
            sides[1].map_or(b, |(s, _)| s),
        ];
        let left = sides.map(|side| side.map_or(ObjectsLeftOut::default(), |(_, l)| l));
        let tried = match sides {
            [None, None] => continue,
            [Some(_), Some(_)] => prepare_two(shapes, job, progress).and_then(|(both, times)| {
                let ready = [both[0].ready(shapes[0]), both[1].ready(shapes[1])];
                run_prepared(ready, times, job, progress)
            }),
            // One side trimmed: the other keeps its proxy and eigenbasis.
            _ => {
                let side = usize::from(sides[0].is_none());
                prepare_one(shapes[side], job, progress).and_then(|(one, eigen_s, proxies_s)| {
                    let mut times = PrepareTimes {
                        proxies_s,
                        ..Default::default()
                    };
                    times.eigenbasis_s[side] = eigen_s;
                    let mut ready = [prepared[0].ready(a), prepared[1].ready(b)];
                    ready[side] = one.ready(shapes[side]);
                    run_prepared(ready, times, job, progress)
                })
            }
        };
        if tried.is_err() && progress.out_of_time {
            break;
        }
        tried_without[0] |= on_a;
        tried_without[1] |= on_b;
        let mut tried = match tried {
            Ok(tried) => tried,
            Err(e) if ends_the_job(&e) => return Err(e),
            Err(_) => continue,
        };
        let Some(tried_cost) = chosen_cost(&tried) else {
            continue;
        };
        if tried_cost <= TOUCHING_OBJECTS_GAIN * cost
            && best.as_ref().is_none_or(|(c, _)| tried_cost < *c)
        {
            [
                tried.regions.working[0].objects_left_out,
                tried.regions.working[1].objects_left_out,
            ] = left;
            best = Some((tried_cost, tried));
        }
    }
    let mut kept = best.map_or(answers, |(_, tried)| tried);
    if progress.out_of_time {
        for (side, working) in kept.regions.working.iter_mut().enumerate() {
            if let (Some((_, left)), false) = (usable[side], tried_without[side]) {
                working.objects_not_tried = left.pieces;
            }
        }
    }
    Ok(kept)
}

/// One shape matched to itself: one proxy and one eigenbasis, used on both sides (the
/// descriptors are then computed once too).
fn prepare_itself_and_run(
    shape: &Shape,
    job: PairJob<'_>,
    progress: &mut dyn Progress,
) -> Result<Answers> {
    let (prepared, eigen_s, proxies_s) = prepare_one(shape, job, progress)?;
    let ready = prepared.ready(shape);
    let times = PrepareTimes {
        eigenbasis_s: [eigen_s, 0.0],
        proxies_s,
    };
    run_prepared([ready, ready], times, job, progress)
}

/// The pair on prepared shapes: the regions (verified by maps on the regions' bases,
/// [`Correspondence::from_bases`]), or
/// the regions and the map (verified once, by the map), then the answers on every input
/// vertex.
fn on_ready(
    a: ReadyShape<'_>,
    b: ReadyShape<'_>,
    job: PairJob<'_>,
    progress: &mut dyn Progress,
) -> Result<Answers> {
    let (working_a, working_b) = (
        ShapeBasis::new(a.working(), a.basis),
        ShapeBasis::new(b.working(), b.basis),
    );
    // The landmarks as vertices of the shapes the stages run on.
    let on_working =
        |v: u32, proxy: Option<&Proxy>| proxy.map_or(v, |p| p.location[v as usize].nearest());
    let params = Params {
        landmarks: job
            .params
            .landmarks
            .iter()
            .map(|&[la, lb]| [on_working(la, a.proxy), on_working(lb, b.proxy)])
            .collect(),
        ..job.params.clone()
    };
    let (mut regions, mut map) = match job.map {
        Some(pointwise) => {
            let (regions, map) =
                regions_and_map(working_a, working_b, &params, pointwise, progress)?;
            (regions, Some(map))
        }
        None => (
            Correspondence::from_bases(working_a, working_b, &params, progress)?,
            None,
        ),
    };
    let t = Instant::now();
    lift_regions(&mut regions, [a.proxy, b.proxy]);
    regions.working = [Working::of(a.shape, a.proxy), Working::of(b.shape, b.proxy)];
    if let Some(map) = &mut map {
        let lift = |p2p: &[u32], progress: &mut dyn Progress| {
            lift_map((a.shape, a.proxy), (b.shape, b.proxy), p2p, progress)
        };
        map.p2p_ba = lift(&map.p2p_ba, progress)?;
        if let Some(other) = &map.other_p2p_ba {
            map.other_p2p_ba = Some(lift(other, progress)?);
        }
        for p2p in std::iter::once(&mut map.p2p_ba).chain(map.other_p2p_ba.as_mut()) {
            pin_landmarks(p2p, &job.params.landmarks);
        }
        // The masks of the working shapes, again on the input ones when proxies stood in:
        // A's from the lifted map, B's from each input vertex's nearest working vertex.
        if a.proxy.is_some() || b.proxy.is_some() {
            let n_b = b.shape.active_vertices().len();
            let on_input = |coverage: &mut partial::Coverage, p2p_ba: &[u32]| {
                coverage.a = partial::covered(a.shape, a.basis.input_area, p2p_ba, n_b);
                if let Some(proxy) = b.proxy {
                    coverage.b = (proxy.location.iter())
                        .map(|at| coverage.b[at.nearest() as usize])
                        .collect();
                }
            };
            on_input(&mut map.coverage, &map.p2p_ba);
            if let (Some(coverage), Some(p2p_ba)) = (&mut map.other_coverage, &map.other_p2p_ba) {
                on_input(coverage, p2p_ba);
            }
        }
    }
    let proxies_s = if a.proxy.is_some() || b.proxy.is_some() {
        t.elapsed().as_secs_f64()
    } else {
        0.0
    };
    Ok(Answers {
        regions,
        map,
        eigenbasis_s: [0.0; 2],
        proxies_s,
    })
}
