//! Writes the benchmark walk (1,000,000 steps on the 15 x 15 grid) as CSV with a header
//! `x,y`, for the peers' benchmark script: `cargo run --release -p hstl-robustness
//! --example walk -- out.csv`.

#[path = "../benches/walk.rs"]
#[allow(dead_code)]
mod walk;

use std::io::{BufWriter, Write};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: walk OUT.csv")?;
    let trace = walk::walk(walk::STEPS, &mut walk::SplitMix64(walk::SEED));
    let mut out = BufWriter::new(std::fs::File::create(&path)?);
    writeln!(out, "x,y")?;
    for (x, y) in trace.column(0).iter().zip(trace.column(1)) {
        writeln!(out, "{x},{y}")?;
    }
    out.flush()?;
    Ok(())
}
