//! `bnsview`: ray tracing of large molecular-dynamics data on CPUs (see README.md).

use anyhow::Result;
use clap::{Parser, Subcommand};
use spmd::Isa;

mod bench_cmd;
mod generate;
mod info;
mod input;
mod look;
mod pipeline;
mod progress;
mod render_cmd;
mod series_cmd;
mod view_cmd;

/// Ray traces ball-and-stick and volume renderings of molecular-dynamics data on the CPU,
/// with SIMD kernels compiled for SSE4.1, AVX2 and AVX-512 and chosen at run time.
#[derive(Parser, Debug)]
#[command(name = "bnsview", disable_version_flag = true)]
struct Cli {
    /// Print the version and the instruction set that would be used, then exit.
    #[arg(short = 'V', long)]
    version: bool,

    /// SIMD backend: scalar, sse4.1, avx2 or avx512 (default: BNS_ISA, else the widest the
    /// CPU supports); `bench` also takes `all` (every backend the CPU supports).
    #[arg(long, global = true, value_name = "ISA", value_parser = parse_isa_arg)]
    isa: Option<IsaArg>,

    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// List the SIMD backends, whether this CPU supports each, and which one is selected.
    Isa,
    /// Describe a molecule file or a built-in scene: atoms, frames, elements, bounds, bonds,
    /// memory estimates.
    Info(info::InfoArgs),
    /// Render a molecule file or a built-in scene (default: nanobowl) to a PNG.
    Render(Box<render_cmd::RenderArgs>),
    /// Open a window on a molecule file or a built-in scene: fly with the mouse, switch modes
    /// and lighting with keys (h lists them), play the time steps; --script drives it headless.
    View(Box<view_cmd::ViewArgs>),
    /// Write a built-in reference scene to a file (.xyz or .lammpstrj, optionally .gz).
    Generate(generate::GenerateArgs),
    /// Reproduce the paper's Tables 1-3 on this machine: preprocessing figures and fps per
    /// scene, mode, view, frame size, thread count and ISA, beside the paper's.
    Bench(Box<bench_cmd::BenchArgs>),
}

/// `--isa`: one backend, or (for `bench`) all the CPU supports.
#[derive(Clone, Copy, Debug)]
enum IsaArg {
    One(Isa),
    All,
}

fn parse_isa_arg(s: &str) -> Result<IsaArg, spmd::IsaError> {
    if s.trim().eq_ignore_ascii_case("all") {
        Ok(IsaArg::All)
    } else {
        s.parse().map(IsaArg::One)
    }
}

fn main() {
    let cli = Cli::parse();
    let ok = match cluster::Ranks::from_launch() {
        // Under mpirun: every rank ends with the first failing rank's error, which rank 0
        // prints.
        Ok(Some(ranks)) => {
            let result = run(cli, Some(&ranks)).map_err(|e| format!("{e:#}"));
            ranks.conclude(result, |e| eprintln!("error: {e}"))
        }
        Ok(None) => report(run(cli, None)),
        Err(e) => report(Err(e.into())),
    };
    if !ok {
        std::process::exit(1);
    }
}

/// Prints the error of a process that is not an MPI rank; returns whether it succeeded. Copies
/// launched by mpirun without MPI in the build leave the message to rank 0 and exit quietly
/// with success, since mpirun would kill rank 0 as soon as one of them failed.
fn report(result: Result<()>) -> bool {
    let Err(e) = result else { return true };
    match cluster::Launch::from_env() {
        Some(l) if l.rank != 0 => true,
        _ => {
            eprintln!("error: {e:#}");
            false
        }
    }
}

fn run(cli: Cli, ranks: Option<&cluster::Ranks>) -> Result<()> {
    let requested = match cli.isa {
        Some(IsaArg::One(i)) => Some(i),
        Some(IsaArg::All) if !matches!(cli.command, Some(Command::Bench(_))) => {
            anyhow::bail!("--isa all is only for `bnsview bench`; name one ISA")
        }
        _ => None,
    };
    let isa = Isa::select(requested)?;
    if cli.version {
        println!(
            "bnsview {} (isa: {isa}, {} lanes)",
            env!("CARGO_PKG_VERSION"),
            isa.lanes()
        );
        return Ok(());
    }
    if let Some(r) = ranks.filter(|_| !matches!(cli.command, Some(Command::Render(_)))) {
        anyhow::bail!("under mpirun ({} ranks) only `bnsview render` is shared out; run this command as one process", r.size());
    }
    match cli.command {
        Some(Command::Isa) => {
            print!("{}", Isa::table(isa));
            Ok(())
        }
        Some(Command::Info(args)) => info::run(args),
        Some(Command::Render(args)) => render_cmd::run(*args, isa, ranks),
        Some(Command::View(args)) => view_cmd::run(*args, isa),
        Some(Command::Generate(args)) => generate::run(args),
        Some(Command::Bench(args)) => {
            let isas = match cli.isa {
                Some(IsaArg::All) => Isa::supported(),
                _ => vec![isa],
            };
            bench_cmd::run(*args, isas)
        }
        None => {
            use clap::CommandFactory;
            Cli::command().print_help()?;
            Ok(())
        }
    }
}

/// The `-v` line of the backend and the threads rendering.
fn isa_line(isa: spmd::Isa) -> String {
    let threads = rayon::current_num_threads();
    format!("isa:     {isa} ({} lanes), {threads} threads", isa.lanes())
}
