//! The `lightquad` command line: thin parsing over the library.

use std::io::{BufWriter, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use lightquad::experiment::{core_study, volume_study};
use lightquad::quadrature::{PRODUCT_RULE, RULES, gauss_legendre};

/// How accurate is each numerical approximation of a light-transport integral,
/// and what does it cost?
#[derive(Parser)]
#[command(name = "lightquad", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the quadrature rules, one line each.
    Rules,
    /// Print a rule's nodes and weights on [-1, 1] as JSON
    /// `{"nodes": [...], "weights": [...]}`, every digit needed to round-trip an f64.
    Nodes {
        /// Rule name: `gauss-legendre` or `trapezoid` (rules with a fixed node set).
        rule: String,
        /// Number of nodes (Gauss–Legendre: 1..=100000000; trapezoid: >= 2).
        n: usize,
    },
    /// Run the built-in studies: every rule on integrals with closed forms, over a
    /// budget sweep, and the volume equations (audit of the printed V-Lp, V-E and
    /// V-L nested and cumulative); prints a Markdown report of error, cost and
    /// fitted order.
    Run {
        /// Largest budget is 4^max_power evaluations.
        #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=11))]
        max_power: u32,
        /// Seed of the randomised rules.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(command: Command) -> Result<(), Box<dyn std::error::Error>> {
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    match command {
        Command::Rules => {
            for (name, about) in RULES.iter().chain([&PRODUCT_RULE]) {
                writeln!(out, "{name:<16} {about}")?;
            }
        }
        Command::Nodes { rule, n } => {
            let (x, w) = match rule.as_str() {
                "gauss-legendre" => {
                    let t = gauss_legendre::table(n)?;
                    (t.x, t.w)
                }
                "trapezoid" => {
                    if n < 2 {
                        return Err(lightquad::QuadError::invalid(
                            "n",
                            n,
                            "at least 2 trapezoid nodes",
                        )
                        .into());
                    }
                    let h = 2.0 / (n - 1) as f64;
                    let x = (0..n).map(|i| -1.0 + i as f64 * h).collect();
                    let w = (0..n)
                        .map(|i| if i == 0 || i == n - 1 { 0.5 * h } else { h })
                        .collect();
                    (x, w)
                }
                other => {
                    lightquad::quadrature::AnyRule::by_name(other)?;
                    return Err(format!(
                        "rule `{other}` has no fixed node set to print: expected gauss-legendre or trapezoid"
                    )
                    .into());
                }
            };
            write_json_array(&mut out, "{\"nodes\": [", &x)?;
            write_json_array(&mut out, "], \"weights\": [", &w)?;
            writeln!(out, "]}}")?;
        }
        Command::Run { max_power, seed } => {
            let rows = core_study::run(max_power, seed);
            write!(out, "{}", core_study::markdown(&rows))?;
            write!(out, "{}", volume_study::markdown())?;
        }
    }
    out.flush()?;
    Ok(())
}

/// Writes `prefix` then the numbers comma-separated; `{:?}` prints the shortest
/// decimal that round-trips an f64 and is valid JSON.
fn write_json_array(out: &mut impl Write, prefix: &str, xs: &[f64]) -> std::io::Result<()> {
    out.write_all(prefix.as_bytes())?;
    for (i, x) in xs.iter().enumerate() {
        if i > 0 {
            out.write_all(b", ")?;
        }
        write!(out, "{x:?}")?;
    }
    Ok(())
}
