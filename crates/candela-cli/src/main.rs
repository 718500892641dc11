//! `candela`: render scenes from the command line.
//!
//! Exit codes: 0 success, 2 bad input or a failed write (one line on stderr naming the
//! file and what is wrong), 130 interrupted by Ctrl-C and 143 by
//! SIGTERM (the partial image is still written), 101 an
//! internal bug.

mod footprint;
mod ies;
mod info;
mod layers;
mod passes;
mod render;

use candela_cli::{merge, output, part, tonemap, UserError};

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "candela", version, about = "A physically based path tracer")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image (.exr and .pfm linear, .png sRGB).
    Render(render::RenderArgs),
    /// Print what a scene contains: shapes, triangles, lights, materials, camera, bounds.
    Info {
        /// Scene file (.toml, Mitsuba 3 .xml, glTF .gltf or .glb).
        scene: PathBuf,
        #[command(flatten)]
        load: render::LoadArgs,
    },
    /// Print an IES LM-63 photometric profile's header, integrated lumens, peak intensity
    /// and beam angle.
    Ies {
        /// Profile (.ies).
        file: PathBuf,
        /// Also draw its polar intensity curves (C0–C180 and C90–C270) into this PNG.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Merge film parts (renders of disjoint --samples ranges of one scene) into one
    /// image, bit for bit the render of their union.
    Merge(MergeArgs),
}

#[derive(clap::Args)]
struct MergeArgs {
    /// Part files (.exr written by `render --samples` or by `merge`).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Output: .exr (a part holding the union, mergeable again), .pfm or .png.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    display: render::DisplayArgs,
}

impl MergeArgs {
    fn run(&self) -> Result<(), UserError> {
        merge::run(&self.parts, &self.output, &self.display.transform())
    }
}

fn main() -> ExitCode {
    std::panic::set_hook(Box::new(|info| {
        eprintln!("candela: internal error: {info}");
        eprintln!(
            "candela: this is a bug in Candela; please report it with the scene that caused it"
        );
    }));
    // Lets the tests see a panic take the path above: the message and exit code 101.
    if std::env::var_os("CANDELA_TEST_INTERNAL_ERROR").is_some() {
        panic!("CANDELA_TEST_INTERNAL_ERROR is set");
    }
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render::run(args),
        Command::Info { scene, load } => info::run(&scene, &load).map(|()| ExitCode::SUCCESS),
        Command::Merge(args) => args.run().map(|()| ExitCode::SUCCESS),
        Command::Ies { file, plot } => ies::run(&file, plot.as_deref()).map(|()| ExitCode::SUCCESS),
    };
    match result {
        Ok(code) => code,
        Err(UserError(message)) => {
            eprintln!("candela: {message}");
            ExitCode::from(2)
        }
    }
}
