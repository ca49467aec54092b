//! Project chores: `cargo xtask matrix [--quick]` runs the test suite once per ISA the CPU
//! has (with `BNS_ISA` forced), the criterion kernel benches, the disassembly check of the
//! SPMD entry points ([`asm`]), and portable builds for
//! `-C target-cpu=x86-64 / x86-64-v3 / x86-64-v4`, then prints one table. `cargo xtask bench
//! [ARGS]` runs `bnsview bench ARGS` built in release mode. `cargo xtask asm-check` runs only
//! the disassembly check; `cargo xtask asm <pattern>` prints the disassembly of the functions
//! whose demangled name contains `pattern` (e.g. `entry::<volume::march::MarchBatch`).

mod asm;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use anyhow::{bail, Context, Result};

const ISAS: [&str; 4] = ["scalar", "sse4.1", "avx2", "avx512"];
const CPUS: [&str; 3] = ["x86-64", "x86-64-v3", "x86-64-v4"];

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("matrix") => matrix(args[1..].iter().any(|a| a == "--quick")),
        Some("bench") => bench(&args[1..]),
        Some("asm-check") => {
            let rows = asm::check()?;
            asm::print_rows(&rows);
            if !rows.iter().all(|r| r.ok) {
                bail!("asm-check: some entry points failed (see above)");
            }
            Ok(())
        }
        Some("asm") if args.len() == 2 => asm::print_matching(&args[1]),
        Some("fuzz") => fuzz(&args[1..]),
        _ => {
            eprintln!("usage: cargo xtask matrix [--quick] | cargo xtask bench [BENCH ARGS]");
            eprintln!("       cargo xtask asm-check | cargo xtask asm <PATTERN>");
            eprintln!("       cargo xtask fuzz [--cases N]");
            eprintln!("  matrix   tests per ISA, kernel benches with speedups over scalar,");
            eprintln!("           builds for target-cpu x86-64 / x86-64-v3 / x86-64-v4");
            eprintln!("  --quick  short bench runs (criterion --quick), one wider baseline: the");
            eprintln!("           widest this CPU runs (x86-64-v4 with AVX-512, else v3)");
            eprintln!("  bench    `bnsview bench` in release mode (the paper's Tables 1-3);");
            eprintln!("           e.g. cargo xtask bench --quick --json out.json");
            eprintln!("  asm-check  disassembly check of the SPMD entry points (table RULES in");
            eprintln!("           xtask/src/asm.rs; built into target/asm with v0 mangling)");
            eprintln!("  fuzz     the readers' mutation fuzz test, long: cargo test --release -p");
            eprintln!("           molecule --test fuzz with BNS_FUZZ_CASES=N per reader (default");
            eprintln!("           {FUZZ_CASES}; CI runs 10,000)");
            eprintln!("  asm      print the disassembly of functions whose name contains PATTERN,");
            eprintln!("           e.g. cargo xtask asm 'avx2::entry::<volume::march::MarchBatch'");
            std::process::exit(2)
        }
    }
}

/// `cargo xtask bench ARGS` = `cargo run --release -p bnsview -- bench ARGS`; a global
/// `--isa X` among ARGS is passed through (clap accepts it after the subcommand).
fn bench(args: &[String]) -> Result<()> {
    let status = cargo()
        .args([
            "run",
            "--release",
            "-p",
            "bnsview",
            "--bin",
            "bnsview",
            "--",
            "bench",
        ])
        .args(args)
        .status()
        .context("running cargo run --release -- bench")?;
    if !status.success() {
        bail!("bnsview bench failed ({status})");
    }
    Ok(())
}

/// Mutated inputs per reader of `cargo xtask fuzz` without `--cases` (CI runs 10,000).
const FUZZ_CASES: u64 = 200_000;

/// `cargo xtask fuzz [--cases N]`: `cargo test --release -p molecule --test fuzz` with
/// `BNS_FUZZ_CASES=N` (default [`FUZZ_CASES`]), the nightly-style long run of issue #20.
fn fuzz(args: &[String]) -> Result<()> {
    let cases = match args {
        [] => FUZZ_CASES,
        [flag, n] if flag == "--cases" => n
            .parse::<u64>()
            .ok()
            .filter(|&n| n > 0 && n <= u32::MAX as u64)
            .with_context(|| format!("--cases {n}: expected a whole number from 1 to 2^32 - 1"))?,
        _ => bail!("usage: cargo xtask fuzz [--cases N]"),
    };
    let cmd = ["test", "--release", "-p", "molecule", "--test", "fuzz"];
    eprintln!("xtask: BNS_FUZZ_CASES={cases} cargo {}", cmd.join(" "));
    let status = cargo()
        .args(cmd)
        .env("BNS_FUZZ_CASES", cases.to_string())
        .status()
        .context("running cargo test --release -p molecule --test fuzz")?;
    if !status.success() {
        bail!("fuzz test failed ({status})");
    }
    Ok(())
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(root());
    c
}

/// Runs a command, echoing stdout/stderr to our stderr, and returns stdout + stderr.
fn run_logged(mut cmd: Command, what: &str) -> Result<(bool, String)> {
    eprintln!("xtask: {what}");
    let out = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .output()
        .with_context(|| what.to_string())?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprint!("{text}");
    Ok((out.status.success(), text))
}

/// Sums "test result: … N passed; M failed" lines of `cargo test` output.
fn count_tests(text: &str) -> (u64, u64) {
    let mut passed = 0;
    let mut failed = 0;
    for line in text.lines().filter(|l| l.starts_with("test result:")) {
        let num_before = |word: &str| -> u64 {
            line.split(';')
                .find(|part| part.trim_end().ends_with(word))
                .and_then(|part| part.split_whitespace().rev().nth(1))
                .and_then(|n| n.parse().ok())
                .unwrap_or(0)
        };
        passed += num_before("passed");
        failed += num_before("failed");
    }
    (passed, failed)
}

fn supported_isas() -> Result<Vec<String>> {
    // Ask the product itself, so the matrix agrees with what users see.
    let out = cargo()
        .args([
            "run",
            "--release",
            "--quiet",
            "--bin",
            "bnsview",
            "--",
            "isa",
        ])
        .env_remove("BNS_ISA")
        .output()
        .context("running bnsview isa")?;
    if !out.status.success() {
        bail!(
            "bnsview isa failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    Ok(text
        .lines()
        .skip(1)
        .filter_map(|l| {
            let cols: Vec<&str> = l.split_whitespace().collect();
            (cols.get(2) == Some(&"yes")).then(|| cols[0].to_string())
        })
        .collect())
}

/// Median times (ns) of every criterion benchmark, keyed by (group, isa), read from
/// `target/criterion/<group>/<isa>/new/estimates.json`.
fn bench_medians() -> Result<BTreeMap<(String, String), f64>> {
    let dir = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"));
    let crit = dir.join("criterion");
    let mut out = BTreeMap::new();
    let Ok(groups) = std::fs::read_dir(&crit) else {
        return Ok(out);
    };
    for g in groups.flatten() {
        for isa in ISAS {
            let f = g.path().join(isa).join("new").join("estimates.json");
            if let Ok(text) = std::fs::read_to_string(&f) {
                if let Some(ns) = json_number_after(&text, "\"median\"", "\"point_estimate\"") {
                    out.insert(
                        (
                            g.file_name().to_string_lossy().into_owned(),
                            isa.to_string(),
                        ),
                        ns,
                    );
                }
            }
        }
    }
    Ok(out)
}

/// The number following `key2` after the first `key1` in a JSON text (enough for
/// criterion's flat estimates file, without a JSON dependency in xtask).
fn json_number_after(text: &str, key1: &str, key2: &str) -> Option<f64> {
    let rest = &text[text.find(key1)?..];
    let rest = &rest[rest.find(key2)? + key2.len()..];
    let rest = rest.trim_start().strip_prefix(':')?.trim_start();
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || "+-.eE".contains(c)))
        .unwrap_or(rest.len());
    rest[..end].parse().ok()
}

/// Can this CPU run code compiled for `-C target-cpu=cpu`?
fn cpu_can_run(cpu: &str) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        let v3 = is_x86_feature_detected!("avx2")
            && is_x86_feature_detected!("fma")
            && is_x86_feature_detected!("bmi1")
            && is_x86_feature_detected!("bmi2")
            && is_x86_feature_detected!("lzcnt")
            && is_x86_feature_detected!("movbe");
        match cpu {
            "x86-64" => true,
            "x86-64-v3" => v3,
            "x86-64-v4" => {
                v3 && is_x86_feature_detected!("avx512f")
                    && is_x86_feature_detected!("avx512bw")
                    && is_x86_feature_detected!("avx512cd")
                    && is_x86_feature_detected!("avx512dq")
                    && is_x86_feature_detected!("avx512vl")
            }
            _ => false,
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        cpu == "x86-64"
    }
}

fn matrix(quick: bool) -> Result<()> {
    let t0 = Instant::now();
    let isas = supported_isas()?;
    eprintln!("xtask: supported ISAs: {}", isas.join(", "));

    // 1. The whole test suite once per ISA, that ISA forced.
    let mut test_rows = Vec::new();
    let mut all_ok = true;
    for isa in &isas {
        let mut c = cargo();
        c.args(["test", "--release", "--workspace"])
            .env("BNS_ISA", isa);
        let (ok, text) = run_logged(
            c,
            &format!("cargo test --release --workspace (BNS_ISA={isa})"),
        )?;
        let (p, f) = count_tests(&text);
        all_ok &= ok && f == 0;
        test_rows.push((isa.clone(), p, f, ok));
    }

    // 2. Criterion kernel benches; each bench covers every supported ISA.
    let mut c = cargo();
    // The release profile (not `bench`, which would compile the workspace a second time).
    c.args([
        "bench",
        "--profile",
        "release",
        "--workspace",
        "--bench",
        "*",
        "--",
        "--noplot",
    ]);
    if quick {
        c.arg("--quick");
    }
    c.env_remove("BNS_ISA");
    let (bench_ok, _) = run_logged(c, "cargo bench --workspace (criterion)")?;
    all_ok &= bench_ok;
    let medians = bench_medians()?;

    // 3. Code generation: every backend's entry points listed in `asm::RULES` must use that
    //    backend's registers and call no vector op or hot helper out of line (a generic op
    //    that was not inlined into the `#[target_feature]` entry point would be a call).
    let asm_rows = asm::check()?;
    all_ok &= asm_rows.iter().all(|r| r.ok);

    // 4. Portable builds: the same binary must select the widest backend at run time
    //    whatever the compile-time baseline (each target-cpu gets its own target dir).
    //    `--quick` (CI) builds only the widest baseline this CPU can run besides x86-64: each
    //    extra baseline rebuilds every dependency (~5 min on 2 cores). A baseline the CPU
    //    cannot run (x86-64-v4 without AVX-512) is built but not run.
    let widest_runnable = CPUS
        .into_iter()
        .rev()
        .find(|c| cpu_can_run(c))
        .unwrap_or("x86-64");
    let mut cpu_rows = Vec::new();
    for cpu in CPUS
        .into_iter()
        .filter(|&c| !quick || c == "x86-64" || c == widest_runnable)
    {
        // The default build is the x86-64 baseline; the others get their own target dir
        // because RUSTFLAGS rebuild every dependency.
        let mut c = cargo();
        c.args(["build", "--release", "--bin", "bnsview", "--target-dir"]);
        let dir = if cpu == "x86-64" {
            // The default build: .cargo/config.toml's flags, which RUSTFLAGS would override.
            c.env_remove("RUSTFLAGS");
            root().join("target")
        } else {
            c.env(
                "RUSTFLAGS",
                format!("-C target-cpu={cpu} -C symbol-mangling-version=v0"),
            );
            root().join(format!("target-cpu-{cpu}"))
        };
        c.arg(&dir);
        let (ok, _) = run_logged(c, &format!("cargo build --release (target-cpu={cpu})"))?;
        let runnable = cpu_can_run(cpu);
        let selected = if ok && runnable {
            let out = Command::new(dir.join("release").join("bnsview"))
                .arg("--version")
                .env_remove("BNS_ISA")
                .output()?;
            String::from_utf8_lossy(&out.stdout).trim().to_string()
        } else if ok {
            "built; not run (this CPU lacks the baseline's instructions)".to_string()
        } else {
            "build failed".to_string()
        };
        let expect = isas.last().cloned().unwrap_or_default();
        let good = ok && (!runnable || selected.contains(&format!("isa: {expect},")));
        all_ok &= good;
        cpu_rows.push((cpu, selected, good));
    }

    // The table.
    println!();
    println!(
        "== cargo xtask matrix{} ({:.0} s) ==",
        if quick { " --quick" } else { "" },
        t0.elapsed().as_secs_f64()
    );
    println!("{:<8} {:>7} {:>7}  tests", "isa", "passed", "failed");
    for (isa, p, f, ok) in &test_rows {
        println!(
            "{:<8} {:>7} {:>7}  {}",
            isa,
            p,
            f,
            if *ok && *f == 0 { "ok" } else { "FAILED" }
        );
    }
    println!();
    let groups: Vec<String> = {
        let mut g: Vec<String> = medians.keys().map(|(g, _)| g.clone()).collect();
        g.dedup();
        g
    };
    print!("{:<24}", "bench (speedup vs scalar)");
    for isa in &isas {
        print!(" {isa:>14}");
    }
    println!();
    for g in &groups {
        print!("{g:<24}");
        let base = medians.get(&(g.clone(), "scalar".to_string())).copied();
        for isa in &isas {
            match (medians.get(&(g.clone(), isa.clone())), base) {
                (Some(&t), Some(b)) => print!(" {:>7.2}x {:>5}", b / t, fmt_ns(t)),
                (Some(&t), None) => print!(" {:>14}", fmt_ns(t)),
                _ => print!(" {:>14}", "-"),
            }
        }
        println!();
    }
    println!();
    asm::print_rows(&asm_rows);
    println!();
    println!("{:<10} {:<6} bnsview --version", "target-cpu", "ok");
    for (cpu, sel, good) in &cpu_rows {
        println!(
            "{:<10} {:<6} {}",
            cpu,
            if *good { "ok" } else { "FAILED" },
            sel
        );
    }
    if !all_ok {
        bail!("matrix: something failed (see above)");
    }
    Ok(())
}

fn fmt_ns(ns: f64) -> String {
    if ns >= 1e6 {
        format!("{:.1}ms", ns / 1e6)
    } else if ns >= 1e3 {
        format!("{:.0}us", ns / 1e3)
    } else {
        format!("{ns:.0}ns")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_cargo_test_summaries() {
        let text = "test result: ok. 12 passed; 0 failed; 1 ignored\nfoo\ntest result: FAILED. 3 passed; 2 failed; 0 ignored";
        assert_eq!(count_tests(text), (15, 2));
    }

    #[test]
    fn reads_criterion_median() {
        let j = r#"{"mean":{"point_estimate":5.0},"median":{"confidence_interval":{"lower_bound":1.0},"point_estimate":123.5e3,"standard_error":2.0}}"#;
        assert_eq!(
            json_number_after(j, "\"median\"", "\"point_estimate\""),
            Some(123500.0)
        );
    }
}
