//! `bnsview isa`: the backends, their support on this CPU, and the selection.

use anyhow::Result;
use spmd::Isa;

/// Prints one line per backend; `selected` is the one [`Isa::select`] chose.
pub fn run(selected: Isa) -> Result<()> {
    println!("{:<8} {:>5}  {:<9}  selected", "isa", "lanes", "supported");
    for isa in Isa::ALL {
        println!(
            "{:<8} {:>5}  {:<9}  {}",
            isa.name(),
            isa.lanes(),
            if isa.is_supported() { "yes" } else { "no" },
            if isa == selected { "*" } else { "" }
        );
    }
    Ok(())
}
