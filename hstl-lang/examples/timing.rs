//! Times parse and check of a file (CPU-bound; use `perf stat` for CPU time).
fn main() {
    let path = std::env::args().nth(1).unwrap_or_default();
    let src = std::fs::read_to_string(&path).unwrap_or_default();
    let t = std::time::Instant::now();
    for _ in 0..10 {
        std::hint::black_box(hstl_lang::parse(&src));
    }
    eprintln!("parse {:?}", t.elapsed() / 10);
    let t = std::time::Instant::now();
    for _ in 0..10 {
        std::hint::black_box(hstl_lang::check(&src));
    }
    eprintln!("check {:?}", t.elapsed() / 10);
}
