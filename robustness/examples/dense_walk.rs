//! Writes the dense-time benchmark walk (the `dense` bench's data: 1,000,000 rows of the
//! walk, stamped 1 to 20 ms apart, in seconds) as CSV with a header `t,x,y`, for the peers'
//! script: `cargo run --release -p hstl-robustness --example dense_walk -- out.csv`.

#[path = "../benches/walk.rs"]
#[allow(dead_code)]
mod walk;

use std::io::{BufWriter, Write};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: dense_walk OUT.csv")?;
    let mut rng = walk::SplitMix64(walk::SEED);
    let trace = walk::walk(walk::STEPS, &mut rng);
    let stamps = walk::stamps(walk::STEPS, &mut rng);
    let mut out = BufWriter::new(std::fs::File::create(&path)?);
    writeln!(out, "t,x,y")?;
    // `{}` prints the shortest text that reads back as the same double.
    for ((t, x), y) in stamps.iter().zip(trace.column(0)).zip(trace.column(1)) {
        writeln!(out, "{t},{x},{y}")?;
    }
    out.flush()?;
    Ok(())
}
