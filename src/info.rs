//! `bnsview info`: describe a molecule file or a built-in scene.

use clap::Args;
use scene::{Description, EstimateFor};

use crate::input::InputArgs;

/// Arguments of `bnsview info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Voxels per Å for the volume memory estimate.
    #[arg(long, default_value_t = 4.0)]
    pub voxels_per_angstrom: f32,
    /// Image size of the memory estimate, WIDTHxHEIGHT pixels (as `render --size`).
    #[arg(long, default_value = "1024x1024", value_parser = scene::text::parse_size)]
    pub size: (u32, u32),
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
}

/// Print to stdout; a closed pipe (`| head`) is not an error.
fn emit(s: &str) {
    use std::io::Write as _;
    let _ = std::io::stdout().lock().write_all(s.as_bytes());
}

/// Run `bnsview info`.
pub fn run(args: InfoArgs) -> anyhow::Result<()> {
    if args.input.file.is_none() && args.input.scene.is_none() {
        anyhow::bail!("give a molecule FILE or --scene NAME (nanobowl, ns90k, ns740k, sio2, anp3)");
    }
    let l = args.input.load(true, true)?;
    let bond_settings = args.input.bond_settings()?;
    let target = EstimateFor {
        size: args.size,
        voxels_per_angstrom: args.voxels_per_angstrom,
    };
    let d = Description::new(&l, &bond_settings, target)?;
    if args.json {
        emit(&(serde_json::to_string_pretty(&d.json()).unwrap_or_default() + "\n"));
    } else {
        emit(&d.text());
    }
    Ok(())
}
