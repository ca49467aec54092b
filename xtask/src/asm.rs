//! Disassembly check of the SPMD entry points (`cargo xtask matrix`, `cargo xtask asm-check`)
//! and `cargo xtask asm <pattern>` to print a function's disassembly.
//!
//! Every kernel runs through `spmd::x86::<isa>::entry::<K>` (`#[inline(never)]`,
//! `#[target_feature]`), so one instance per (kernel, backend) is a named function whose
//! body holds the whole kernel once the generic code is inlined. The binaries are built
//! into `target/asm` with `-C symbol-mangling-version=v0`, so the demangled names carry the
//! kernel type (`spmd::x86::avx2::entry::<volume::grid::SplatSlab>`), and disassembled with
//! `objdump -d -C`.
//!
//! ## Updating the table
//! [`RULES`] lists what is checked. When a kernel is renamed or added, run
//! `cargo xtask asm entry::<` to list the entry instances by name, then edit or add a row:
//! `symbol` is a substring of the demangled function header (`{isa}` stands for the backend
//! module `sse41`, `avx2` or `avx512`), `binary` the executable holding it. `must` and
//! `must_not` are line patterns (`*` matches anything, `{reg}` the backend's vector
//! register prefix `%xmm`, `%ymm` or `%zmm`): every `must` pattern has to match some line of
//! each matching function and no `must_not` pattern may match any line. A row whose symbol
//! matches nothing fails (a stale row must be updated, not silently pass).

use std::path::PathBuf;
use std::process::Command;

use anyhow::{bail, Context, Result};

/// An executable the check disassembles: a bin or a bench target of the workspace.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Binary {
    /// The `bnsview` CLI (the real render, density and light-volume paths).
    Bnsview,
    /// `benches/kernels.rs` (SPMD-layer kernels).
    KernelsBench,
    /// `crates/volume/benches/volume.rs` (the marcher's batch entry points).
    VolumeBench,
}

impl Binary {
    const ALL: [Binary; 3] = [Binary::Bnsview, Binary::KernelsBench, Binary::VolumeBench];

    /// Cargo's kind of the target.
    fn kind(self) -> &'static str {
        match self {
            Binary::Bnsview => "bin",
            Binary::KernelsBench | Binary::VolumeBench => "bench",
        }
    }

    /// Cargo target name.
    fn target(self) -> &'static str {
        match self {
            Binary::Bnsview => "bnsview",
            Binary::KernelsBench => "kernels",
            Binary::VolumeBench => "volume",
        }
    }
}

/// One row of the check.
pub struct Rule {
    /// What the row covers (printed).
    pub what: &'static str,
    /// Executable holding the functions.
    pub binary: Binary,
    /// Substring of the demangled function header; `{isa}` = backend module.
    pub symbol: &'static str,
    /// Line patterns that must each match somewhere in every matching function.
    pub must: &'static [&'static str],
    /// Line patterns that must match nowhere in a matching function.
    pub must_not: &'static [&'static str],
}

/// Calls that mean a vector op or a hot helper was not inlined into the entry point.
const NO_OUT_OF_LINE: &[&str] = &[
    "call*core_arch",
    "call*<spmd::x86",
    "call*as spmd::Simd",
    "call*spmd::math",
    "call*<spmd::v3",
];

/// As [`NO_OUT_OF_LINE`], plus calls into the volume crate (every volume helper on a
/// per-sample path is `#[inline(always)]`).
const NO_OUT_OF_LINE_VOLUME: &[&str] = &[
    "call*core_arch",
    "call*<spmd::x86",
    "call*as spmd::Simd",
    "call*spmd::math",
    "call*<spmd::v3",
    "call*<volume::",
];

/// As [`NO_OUT_OF_LINE_VOLUME`] for the entry points that also hold the grid-free marcher
/// (render tiles, the march batch): its per-ray bookkeeping may stay out of line (the thread-local scratch taken and set back,
/// the sort of a window's spheres, the scratch's drop on unwinding), never its per-sample
/// code nor the grid marcher's.
const NO_OUT_OF_LINE_MARCH: &[&str] = &[
    "call*core_arch",
    "call*<spmd::x86",
    "call*as spmd::Simd",
    "call*spmd::math",
    "call*<spmd::v3",
    "call*<volume::march",
    "call*<volume::sampler",
    "call*<volume::scene",
    "call*<volume::shadow",
    "call*<volume::tau",
    "call*<volume::light",
    "call*<volume::medium",
    "call*<volume::tf",
    "call*<volume::particle_march::march",
    "call*<volume::particle_march::density_at",
    "call*<volume::particle_march::classify",
    "call*<volume::particle_march::Stream*::peek>",
    "call*<bvh::wide::WideBvh>::sphere_spans",
];

/// The checked entry points. Edit here when kernels are renamed (see the module docs).
pub const RULES: &[Rule] = &[
    Rule {
        what: "kernels bench",
        binary: Binary::KernelsBench,
        symbol: "spmd::x86::{isa}::entry::<",
        must: &["{reg}"],
        must_not: NO_OUT_OF_LINE,
    },
    Rule {
        what: "density build",
        binary: Binary::Bnsview,
        symbol: "spmd::x86::{isa}::entry::<volume::grid::SplatSlab",
        must: &["{reg}"],
        must_not: NO_OUT_OF_LINE_VOLUME,
    },
    Rule {
        what: "light volume",
        binary: Binary::Bnsview,
        symbol: "spmd::x86::{isa}::entry::<volume::light::PlaneKernel",
        must: &["{reg}"],
        must_not: NO_OUT_OF_LINE_VOLUME,
    },
    Rule {
        what: "march tile kernel",
        binary: Binary::VolumeBench,
        symbol: "spmd::x86::{isa}::entry::<volume::march::MarchBatch",
        must: &["{reg}"],
        must_not: NO_OUT_OF_LINE_MARCH,
    },
    Rule {
        what: "render tiles (headlight, sampled)",
        binary: Binary::Bnsview,
        symbol: "spmd::x86::{isa}::entry::<render::integrator::",
        must: &["{reg}"],
        must_not: NO_OUT_OF_LINE_MARCH,
    },
];

/// Backends with their module name and vector register prefix.
const BACKENDS: [(&str, &str, &str); 3] = [
    ("sse4.1", "sse41", "%xmm"),
    ("avx2", "avx2", "%ymm"),
    ("avx512", "avx512", "%zmm"),
];

/// One (rule, backend) result.
pub struct AsmRow {
    /// The rule's `what`.
    pub what: &'static str,
    /// Backend name.
    pub isa: &'static str,
    /// Matching functions.
    pub entries: usize,
    /// Lines on the backend's vector registers.
    pub wide: usize,
    /// Offending lines (a `must_not` match or a missing `must`), first few.
    pub bad: Vec<String>,
    /// Passed.
    pub ok: bool,
}

/// `*`-glob over one line: the parts appear in this order.
fn line_matches(line: &str, pattern: &str) -> bool {
    let mut rest = line;
    for part in pattern.split('*') {
        match rest.find(part) {
            Some(i) => rest = &rest[i + part.len()..],
            None => return false,
        }
    }
    true
}

/// Functions of an objdump listing as (header, body lines).
fn functions(dump: &str) -> Vec<(&str, Vec<&str>)> {
    let mut out: Vec<(&str, Vec<&str>)> = Vec::new();
    for line in dump.lines() {
        if line.ends_with(">:") {
            out.push((line, Vec::new()));
        } else if let Some(f) = out.last_mut() {
            if !line.trim().is_empty() {
                f.1.push(line);
            }
        }
    }
    out
}

/// Builds the three executables into `target/asm` with v0 mangling and returns their
/// paths.
fn build() -> Result<Vec<(Binary, PathBuf)>> {
    let mut c = super::cargo();
    c.args([
        // The whole workspace's binaries and benches: the same feature set as `cargo test
        // --workspace` (dev-dependencies' features included), so the test build is reused.
        "build",
        "--release",
        "--workspace",
        "--bins",
        "--bench",
        "*",
        "--message-format=json-render-diagnostics",
    ])
    // v0 mangling comes from .cargo/config.toml, which RUSTFLAGS would override.
    .env_remove("RUSTFLAGS");
    eprintln!("xtask: cargo build --release --workspace --bins --bench '*' (for the disassembly)");
    let out = c
        .stderr(std::process::Stdio::inherit())
        .output()
        .context("running cargo build for the disassembly")?;
    if !out.status.success() {
        bail!("building the binaries to disassemble failed");
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut found = Vec::new();
    for line in text.lines() {
        let Some(exe) = json_str_after(line, "\"executable\":\"") else {
            continue;
        };
        let Some(name) = line
            .find("\"target\":{")
            .and_then(|i| json_str_after(&line[i..], "\"name\":\""))
        else {
            continue;
        };
        // Only binaries and benches (a library's test harness has the crate's name too).
        let kind_ok = |b: Binary| line.contains(&format!("\"kind\":[\"{}\"]", b.kind()));
        if let Some(b) = Binary::ALL
            .into_iter()
            .find(|&b| b.target() == name && kind_ok(b))
        {
            found.push((b, PathBuf::from(exe)));
        }
    }
    for b in Binary::ALL {
        if !found.iter().any(|(f, _)| *f == b) {
            bail!("cargo did not report the executable of {}", b.target());
        }
    }
    Ok(found)
}

/// The JSON string value after `key` (no escapes expected in paths and target names).
fn json_str_after<'a>(text: &'a str, key: &str) -> Option<&'a str> {
    let rest = &text[text.find(key)? + key.len()..];
    Some(&rest[..rest.find('"')?])
}

fn objdump(exe: &std::path::Path) -> Result<String> {
    let out = Command::new("objdump")
        .args(["-d", "--no-show-raw-insn", "-C"])
        .arg(exe)
        .output()
        .context("running objdump (Debian package binutils)")?;
    if !out.status.success() {
        bail!("objdump {} failed", exe.display());
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Runs [`RULES`] for every backend.
pub fn check() -> Result<Vec<AsmRow>> {
    let bins = build()?;
    let mut dumps = Vec::new();
    for (b, exe) in &bins {
        dumps.push((*b, objdump(exe)?));
    }
    let mut rows = Vec::new();
    for rule in RULES {
        let dump = &dumps.iter().find(|(b, _)| *b == rule.binary).unwrap().1;
        let funcs = functions(dump);
        for (isa, module, reg) in BACKENDS {
            let subst = |p: &str| p.replace("{isa}", module).replace("{reg}", reg);
            let symbol = subst(rule.symbol);
            let (mut entries, mut wide, mut bad) = (0, 0, Vec::new());
            for (header, body) in funcs.iter().filter(|(h, _)| h.contains(&symbol)) {
                entries += 1;
                wide += body.iter().filter(|l| l.contains(reg)).count();
                for p in rule.must.iter().map(|p| subst(p)) {
                    if !body.iter().any(|l| line_matches(l, &p)) {
                        bad.push(format!("{header} lacks {p:?}"));
                    }
                }
                for p in rule.must_not.iter().map(|p| subst(p)) {
                    for l in body.iter().filter(|l| line_matches(l, &p)) {
                        bad.push(format!("{header} {}", l.trim()));
                    }
                }
            }
            for b in &bad {
                eprintln!("xtask asm: {}: {b}", rule.what);
            }
            rows.push(AsmRow {
                what: rule.what,
                isa,
                entries,
                wide,
                ok: entries > 0 && bad.is_empty(),
                bad,
            });
        }
    }
    Ok(rows)
}

/// Prints the table of [`check`].
pub fn print_rows(rows: &[AsmRow]) {
    println!(
        "{:<20} {:<8} {:>7} {:>9} {:>5}  asm of spmd entry points (xtask/src/asm.rs RULES)",
        "entry", "isa", "entries", "reg insns", "bad"
    );
    for r in rows {
        println!(
            "{:<20} {:<8} {:>7} {:>9} {:>5}  {}",
            r.what,
            r.isa,
            r.entries,
            r.wide,
            r.bad.len(),
            if r.ok { "ok" } else { "FAILED" }
        );
    }
}

/// `cargo xtask asm <pattern>`: the disassembly of every function whose demangled header
/// contains `pattern`, from all checked executables.
pub fn print_matching(pattern: &str) -> Result<()> {
    let bins = build()?;
    let mut n = 0;
    for (b, exe) in &bins {
        let dump = objdump(exe)?;
        for (header, body) in functions(&dump) {
            if header.contains(pattern) {
                n += 1;
                println!("# {} ({} lines)", b.target(), body.len());
                println!("{header}");
                for l in body {
                    println!("{l}");
                }
                println!();
            }
        }
    }
    if n == 0 {
        bail!("no function header contains {pattern:?}");
    }
    eprintln!("xtask asm: {n} functions");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glob_matches_in_order() {
        let l = "  4010: call   4020 <<spmd::x86::avx2::Avx2 as spmd::Simd>::gather>";
        assert!(line_matches(l, "call*as spmd::Simd"));
        assert!(line_matches(l, "call*<spmd::x86"));
        assert!(!line_matches(l, "as spmd::Simd*call"));
        assert!(!line_matches(l, "call*core_arch"));
    }

    #[test]
    fn splits_functions() {
        let d = "0000 <a>:\n  1: ret\n\n0010 <b::c>:\n  11: call x\n  12: ret\n";
        let f = functions(d);
        assert_eq!(f.len(), 2);
        assert_eq!(f[1].0, "0010 <b::c>:");
        assert_eq!(f[1].1.len(), 2);
    }

    #[test]
    fn every_rule_names_a_backend_entry() {
        for r in RULES {
            assert!(r.symbol.contains("{isa}"), "{}", r.what);
        }
    }
}
