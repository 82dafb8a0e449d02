//! `shapecorr`: the command-line front end. Every command exits non-zero with a one-line
//! reason on bad input: status 2 for a usage error (clap's, an option out of its range),
//! 1 for a failed job, whose reason is the library's error (`resource limit `NAME`: ...` for
//! a job too big for its limits, docs/design.md, "Errors and status codes").
//!
//! One module per command under `commands/`; the method's options are generated from the
//! library's option table (`options.rs`); the files every command writes are `output.rs`'s.

mod commands;
mod input;
mod landmarks;
mod options;
mod output;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use commands::batch::BatchArgs;
use commands::bench::BenchCommand;
use commands::demo::DemoArgs;
use commands::eigen::EigenArgs;
use commands::info::InfoArgs;
use commands::p2p::P2pArgs;
use commands::regions::{MatchArgs, SymmetryArgs};
use commands::synth::SynthArgs;
use commands::transfer::TransferArgs;

#[derive(Parser)]
#[command(
    name = "shapecorr",
    version,
    about = "Region correspondences between 3D shapes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// No progress on stderr. Otherwise progress is a line redrawn on a terminal, or a line
    /// `shapecorr: progress: STAGE NN% (T s)` at most once a second when stderr is a file
    /// or a pipe.
    #[arg(long, global = true)]
    quiet: bool,
}

// Parsed once per run: the size difference between variants does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Counts, area, connected pieces and warnings of a shape file.
    Info(InfoArgs),
    /// Laplacian eigenvalues of a shape (unit-area normalised), with time and peak memory.
    Eigen(EigenArgs),
    /// Make an articulated test figure (ground truth: the vertex order is shared by every
    /// pose and proportion of a kind and resolution).
    Synth(SynthArgs),
    /// Region correspondence between two shapes: writes DIR/result.json and
    /// DIR/a_regions.ply, DIR/b_regions.ply (matched regions share a colour, unmatched ones
    /// are dark grey). result.json has the answer's confidence (in [0, 1]; null when not
    /// verified), the hypotheses it was chosen from, the chosen one and what decided it, and
    /// the runner-up, whose answer is written in DIR/other/ (the same files); a doubtful
    /// answer is also warned about on stderr, with what to do. `--landmarks FILE` and
    /// `--placement` say what you know (docs/placement.md).
    Match(MatchArgs),
    /// Symmetric regions of one shape (the shape matched to itself): DIR/result.json and a
    /// PLY coloured by symmetry group.
    Symmetry(SymmetryArgs),
    /// Point-to-point map from B to A (regions, functional map, ZoomOut): writes
    /// DIR/map_b_to_a.txt (for every vertex of B, the 0-based index of its vertex on A),
    /// DIR/result.json (the regions as `match`, plus timings), DIR/a_colors.ply (A coloured
    /// by its normalised coordinates) and DIR/b_mapped.ply (B with A's colours carried over
    /// by the map). The confidence, warning and runner-up as `match`'s, for the map's answer:
    /// the runner-up's map and colours in DIR/other/.
    P2p(P2pArgs),
    /// Values on A's vertices (a text file, a row per vertex) carried to B's vertices
    /// through the point-to-point map, interpolated on A's surface (`--mode interpolate`),
    /// by nearest vertex (`nearest`: labels) or as skin weights (`weights`). The map's
    /// confidence and warning as `p2p`'s. See docs/transfer.md.
    Transfer(TransferArgs),
    /// Many pairs of a shape collection (all pairs, one template against every shape, or a
    /// pair file): each shape's eigenbasis computed once and cached, pairs in parallel, a
    /// line per pair in OUT/pairs.jsonl as it finishes; a failed pair is a line with its
    /// reason; running again resumes. See docs/collections.md.
    Batch(BatchArgs),
    /// Benchmarks on the research datasets.
    Bench {
        #[command(subcommand)]
        which: BenchCommand,
    },
    /// The main job: two generated humanoids in different poses, one of them a noisy point
    /// cloud, matched; coloured PLYs and the region accuracy against the known ground truth.
    Demo(DemoArgs),
}

fn main() -> ExitCode {
    quit_quietly_on_closed_pipe();
    let cli = Cli::parse();
    output::QUIET.store(cli.quiet, std::sync::atomic::Ordering::Relaxed);
    // Before any thread: under `ulimit -v`, one allocator arena instead of one per thread.
    shapecorr::system::fit_allocator_to_address_space_limit();
    // The whole command runs on a worker of one rayon pool: parallel loops called from
    // inside it start without handing work over from a foreign thread, which with many
    // small loops (k-means, Lanczos) cost measurable time in thread wake-ups. Threads come
    // from RAYON_NUM_THREADS or the CPU count, as before; results do not depend on them.
    match rayon::ThreadPoolBuilder::new().build() {
        Ok(pool) => pool.install(|| run(&cli)),
        Err(_) => run(&cli),
    }
}

/// `shapecorr info F | head -1`: when the reader closes the pipe, end as every Unix tool
/// does (killed by SIGPIPE, no message) instead of panicking in `println!`. Rust ignores
/// SIGPIPE by default, which turns the closed pipe into a panic.
fn quit_quietly_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: restoring a signal's default disposition at start-up, before any thread.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn run(cli: &Cli) -> ExitCode {
    let result = match &cli.command {
        Command::Info(args) => args.run(),
        Command::Eigen(args) => args.run(),
        Command::Synth(args) => args.run(),
        Command::Match(args) => args.run(),
        Command::Symmetry(args) => args.run(),
        Command::P2p(args) => args.run(),
        Command::Transfer(args) => args.run(),
        Command::Batch(args) => args.run(),
        Command::Bench { which } => which.run(),
        Command::Demo(args) => args.run(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            output::errln!("shapecorr: {e}");
            ExitCode::FAILURE
        }
    }
}
