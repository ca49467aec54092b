//! bnsview command-line interface.

use clap::{Parser, Subcommand};

mod generate;
mod info;

/// SPMD ray tracer for ball-and-stick and volume rendering of large molecular-dynamics data.
#[derive(Parser)]
#[command(name = "bnsview", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Describe a molecule file or a built-in scene: atoms, frames, elements, bounds, bonds,
    /// memory estimates.
    Info(info::InfoArgs),
    /// Write a built-in reference scene to a file (.xyz or .lammpstrj, optionally .gz).
    Generate(generate::GenerateArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Info(args) => info::run(args),
        Command::Generate(args) => generate::run(args),
    }
}
